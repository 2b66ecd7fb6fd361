/// \file circumference.hpp
/// Circumferences by slicing the triangle mesh with a horizontal plane y = h: the crossing
/// segments are chained into loops (polylines) and a loop, or a group of loops, is measured as
/// the perimeter of its convex hull in the xz plane (a tape measure spans concavities) or as its
/// length. The paper does not use circumferences; the evaluation (ANSUR II) does.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "caliper/measurements.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// One chained polyline of a plane slice, points (x, z) in order.
struct SliceLoop {
  std::vector<Eigen::Vector2d> points;  ///< (x, z), metres
  bool closed = false;                  ///< false if the chain ended at a mesh boundary
  double length = 0.0;                  ///< polyline length (closing segment included if closed)
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();  ///< mean of the points
};

/// Slices the mesh with the plane y = `height`. Vertices exactly on the plane are nudged by
/// 1e-12 m up (so each edge crosses at most once). Returns every loop (possibly none).
std::vector<SliceLoop> slice_mesh(const smpl::Vertices& vertices, const smpl::Faces& faces,
                                  double height);

/// Perimeter of the convex hull of `points` (x, z); 0 for fewer than 2 points, twice the
/// length for colinear points.
double convex_hull_perimeter(const std::vector<Eigen::Vector2d>& points);

/// True if (x, z) `p` lies inside the closed polygon `loop` (even-odd rule).
bool loop_contains(const SliceLoop& loop, const Eigen::Vector2d& p);

/// The points of `loops` clipped to the half-plane x >= `mid` (x the first coordinate), with the
/// points where a segment crosses x = mid: the side of the body a tape around the left leg stays
/// on where the thighs touch (one loop for both legs).
std::vector<Eigen::Vector2d> clip_loops_left(const std::vector<SliceLoop>& loops, double mid);

/// Circumference of the loops at height `height` whose centroid x lies within [x_min, x_max]
/// (for the torso: between the two side landmarks, which excludes T-pose arms and hands).
/// `convex_hull` true: perimeter of the convex hull of all points of the selected loops; false:
/// the sum of their lengths. std::nullopt when no loop qualifies.
std::optional<double> circumference_between(const smpl::Vertices& vertices,
                                            const smpl::Faces& faces, double height, double x_min,
                                            double x_max, bool convex_hull = true);

/// The five circumferences, metres, for a rest-pose body (T-pose), each left out when its
/// landmarks are missing or no loop qualifies:
/// - chest_circumference at left_nipple height, loops between right_chest.x and left_chest.x,
///   but when the table has the acromia (left_shoulder, right_shoulder) every loop of the plane
///   clipped to the band between their x instead: in the T-pose the plane at the nipples can run
///   through the armpits' folds or along the underside of the arms (one loop round the torso and
///   both arms: 1.84 m on one registered ANSUR II man of the open male model), and a tape round
///   the chest takes none of the arm beyond the shoulders. The part of an arm under the plane
///   counts up to the band whether or not it has met the torso's loop, so that the girth does
///   not jump as the plane passes the armpit. A closed loop cut by the band is closed along the
///   cut (`convex_hull` false: the sum of the clipped loops' lengths);
/// - waist_circumference at navel height, loops between right_waist.x and left_waist.x;
/// - hip_circumference at left_hip height, loops between right_hip.x and left_hip.x
///   (both legs together when the plane is below the crotch);
/// - thigh_circumference: with a left_gluteal_fold landmark (ANSUR II's thigh circumference,
///   at the lowest point of the buttock's fold; not in the shared vocabulary, carried by the
///   open models' own tables), at thigh_fold_level() around the left leg: the convex hull of the
///   slice's points on the left of crotch.x (where the thighs touch, the tape stays on the
///   left one; with `convex_hull` false, the length of the loop below). Without it,
///   `thigh_drop` metres below the crotch, the loop whose centroid has the smallest x greater
///   than crotch.x (the left leg);
/// - waist_iliac_circumference (the waist of NHANES and the WHO: just above the uppermost
///   lateral border of the iliac crest) at left_iliac_crest height, loops between
///   right_iliac_crest.x and left_iliac_crest.x. These two landmarks are not in the shared
///   vocabulary: only a model whose own table (BodyModel::landmarks) carries them has this
///   girth (derive_iliac_crest_landmarks() places them by a rule, on request).
/// The thigh's level at the gluteal fold: the height of the left_gluteal_fold landmark, but at
/// least kThighBelowCrotch under the crotch. The fold is the vertex where the average body's
/// buttock profile bends most sharply; the average woman's lies 4.3 cm under her crotch, but the
/// average man's buttock has no crease there (its sharpest bend is 5 mm under the crotch), and
/// on a man with fuller thighs that vertex rises above the crotch, where a slice goes round the
/// pelvis, not the thigh (6.5 mm above on the open male model's mean ANSUR II man). The survey's
/// furrow lies under the ischial tuberosities, a few centimetres under the crotch. std::nullopt
/// without both landmarks. The open models' generator measures its survey subjects' thighs here
/// too (docs/models.md: the floor of 3 cm against 1 cm).
std::optional<double> thigh_fold_level(const smpl::Vertices& vertices,
                                       const LandmarkTable& landmarks);

/// How far under the crotch the thigh's level lies at least (thigh_fold_level()), metres.
inline constexpr double kThighBelowCrotch = 0.03;

/// The same rule on two heights (metres): the fold's, but at least kThighBelowCrotch under the
/// crotch's (for a measurer that has the fold as a vertex of its own rather than a landmark).
double thigh_fold_level(double fold_height, double crotch_height);

MeasurementMap circumferences(const smpl::Vertices& vertices, const smpl::Faces& faces,
                              const LandmarkTable& landmarks, bool convex_hull = true,
                              double thigh_drop = 0.02);

/// Ids of the four circumferences of the shared landmark vocabulary, in the order above
/// (chest, waist, hip, thigh; the columns of `caliper batch --circumferences`).
/// waist_iliac_circumference is not listed: it needs landmarks outside the vocabulary.
const std::vector<std::string>& circumference_ids();

}  // namespace caliper
