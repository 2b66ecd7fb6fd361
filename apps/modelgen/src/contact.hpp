/// \file contact.hpp
/// Separation of touching skin in a linear shape space (issue 11, "Must show" 2: no
/// self-intersection at the mean and at +/- 2 SD along the first 10 components).
///
/// The registered bodies are linear blends of MakeHuman targets, and where soft tissue meets
/// (inner thighs, the gluteal cleft, under the breasts, between the toes, the lips) the blend
/// pushes one sheet of skin through the other instead of flattening both against each other.
/// Real tissue flattens at a contact; this step does the same, as far as a linear model can.
/// Each round checks the mean and the bodies at +/- s SD along the first components
/// (self_intersections()); the vertices of each crossing triangle that lie behind the other
/// triangle's plane, and the vertices flooded from them over the mesh that stay behind that
/// plane within 2 cm and face it (normals more than 120 degrees apart; the skin wholly inside
/// the other sheet, whose triangles cross nothing), need to move back along their inward normal
/// (the mean body's; or out of the other sheet, ContactDirection) by half their depth plus a gap
/// (the other sheet moves too), spread to two rings at half strength each so that no one-vertex
/// dent folds, at most half the vertex's shortest edge per round. The moves go into the mean and
/// the components: along one component the need is p0 at the mean and p+, p- at +/- s SD; a linear
/// offset a + s b meets all three when a >= max(p0, (p+ + p-) / 2) and b = (p+ - p-) / (2 s), so
/// the mean takes half of what the far bodies need (a flatter contact on the mean body, which is
/// where the thighs of the average woman already touch). A round can make more crossings than it
/// removes (a crease pushed into a fold); the state with the fewest pairs over the check bodies is
/// kept. Measured on the v2 models in docs/models.md ("Touching skin").
#pragma once

#include <vector>

#include "smpl/body_model.hpp"

namespace modelgen {

/// Which way a vertex that went through the other sheet moves back.
enum class ContactDirection {
  InwardNormal,        ///< along its own inward normal on the mean body (flattens both sheets)
  OutOfTheOtherSheet,  ///< along the other sheet's normal where it went through (fixed at the
                       ///< first round that needs the vertex): where the sheets meet at an
                       ///< angle, as in the crease of the perineum, the inward normal folds it
};

/// What separate_contacts() did.
struct ContactReport {
  ContactDirection direction = ContactDirection::InwardNormal;  ///< the direction used
  int bodies = 0;                 ///< check bodies per round (1 + 2 x components)
  int rounds = 0;                 ///< rounds run (each: check every body, then move)
  int kept_round = 0;             ///< the state kept: after this many rounds (fewest pairs)
  std::vector<int> pairs_before;  ///< intersecting triangle pairs per check body, before
  std::vector<int> pairs_after;   ///< in the state kept (mean, then -s and +s per component)
  int moved_vertices = 0;         ///< vertices whose mean or components changed
  double largest_move = 0.0;      ///< largest move of a vertex on any check body, metres
};

/// Options of separate_contacts(). The defaults are the check (mean and +/- 2 SD along
/// the first 10 components).
struct ContactOptions {
  int components = 10;      ///< components checked (fewer if the model has fewer)
  double sd = 2.0;          ///< the check bodies' distance from the mean, in SD (betas)
  int max_rounds = 16;      ///< rounds before giving up (what is left is reported)
  double gap = 0.0005;      ///< metres each side moves beyond meeting the other sheet
  double max_step = 0.004;  ///< largest move of a vertex per round, metres, and at most half
                            ///< its shortest edge (deeper crossings take more rounds)
  double max_move = 0.03;   ///< largest move of a vertex over all rounds, metres (on its
                            ///< worst check body): a crease pushed on and on does not run away
  int threads = 1;          ///< check bodies tested at once (the result does not depend on it)
  ContactDirection direction = ContactDirection::InwardNormal;  ///< see ContactDirection
};

/// Moves the model's template and the first `components` shape components (left/right
/// symmetric under model.mirror when the model has one) until none of the check bodies
/// self-intersects, or `max_rounds` have run. Deterministic to the byte for a given model
/// (fixed order of every sum; threads only split independent bodies). `model` must be valid
/// (smpl::validate); posedirs, weights and the joint regressor are not changed (the moves are
/// a few millimetres, up to 2-3 cm in a crease, on the skin where sheets touch).
ContactReport separate_contacts(smpl::BodyModel& model, const ContactOptions& options = {});

/// separate_contacts() with each ContactDirection (options.direction is ignored); keeps the one
/// that leaves fewer intersecting pairs over the check bodies (the inward normal on a tie). On
/// the v2 models the way out of the other sheet clears the female's crease (0 pairs left against
/// 44) and the inward normal the neutral's toes (46 against 167; docs/models.md).
ContactReport separate_contacts_best(smpl::BodyModel& model, ContactOptions options = {});

/// What unfold_creases() did.
struct UnfoldReport {
  int bodies = 0;                 ///< check bodies (1 + 2 x components)
  int rounds = 0;                 ///< rounds run
  std::vector<int> pairs_before;  ///< intersecting pairs per check body, before
  std::vector<int> pairs_after;   ///< and after (mean, then -s and +s per component)
  int smoothed_vertices = 0;      ///< vertices whose template or components changed
};

/// Crumples left after separate_contacts(): an intersecting pair whose two triangles lie within
/// two 1-rings of each other is skin folded over itself (the male's perineum, the neutral's
/// toes, where the blend of targets squeezes a crease), which pushing two sheets apart cannot
/// undo. Each round, for every check body with such pairs, the vertices of their triangles and
/// two rings around them take five passes of averaging with their neighbours in what makes
/// that body: the template for the mean, component c's column for the bodies at +/- s SD along
/// c (v' = (v + mean of the 1-ring) / 2), so the crumple is smoothed out of the one component
/// that makes it; left/right symmetrised after each round. Up to `options.max_rounds` rounds,
/// until no check body has such a pair; pairs between triangles further apart are left alone.
/// Deterministic (fixed order of every sum). Measured in docs/models.md ("Touching skin").
UnfoldReport unfold_creases(smpl::BodyModel& model, const ContactOptions& options = {});

}  // namespace modelgen
