/// \file pose_correctives.hpp
/// Pose-corrective blend shapes (SMPL's `posedirs`) for the open models (issue 11, "Must show"
/// 2: no flipped triangles in the 10 test poses).
///
/// Linear blend skinning collapses fuller limbs at a bend: a vertex between two bones moves by
/// the average of their transforms, which is not a rotation, and the skin on the inner side of
/// an elbow, knee, armpit or groin folds over itself. SMPL answers with blend shapes driven by
/// the pose, learnt from scans of posed people. The open models have no posed scans, so the
/// target each corrective is fitted to is made: for one joint bent alone, the skin of the band
/// where the weights mix (the vertices with some but not all of their weight on the joint and
/// its descendants, and `rings` 1-rings beyond) is solved for the positions whose every edge
/// is its rest edge turned by the rotation the weights blend at that edge (a Poisson problem,
/// the skin outside the band held where skinning puts it), so the skin bends round the joint
/// instead of collapsing; where the band runs to the end of a limb (a foot, a hand), nothing
/// beyond it is held, so its skin is also pulled towards skinning, more the further from the
/// joint; the few folds left are smoothed out locally. The difference from
/// skinning, taken back through each vertex's blended transform into the rest pose, is what the
/// corrective must add; the 9 columns of each joint are the least-squares fit of those offsets
/// to the joint's pose features (R - I) over bends about each axis, both ways, by each of
/// `angles_deg` (a joint whose targets fold more than skinning alone keeps none; rounded to
/// 2^-20 m). Every joint is fitted on its own on the mean body, like SMPL's (the columns of
/// several bent joints add up). Deterministic to the byte (fixed order of every sum; threads only
/// split joints); measured in docs/models.md ("Pose correctives").
#pragma once

#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"

namespace modelgen {

/// Options of pose_correctives().
struct PoseCorrectiveOptions {
  int rings = 20;      ///< 1-rings the band grows beyond the mixing
  double band = 1e-3;  ///< mixing: weight in (band, 1 - band)
  std::vector<double> angles_deg = {45.0, 90.0, 110.0};  ///< bends fitted, each axis, both ways
  double anchor = 0.2;     ///< pull to skinning at the band's edge when it reaches a limb's end
  int cleanup_rounds = 8;  ///< local smoothing rounds for folds left
  int threads = 1;         ///< joints solved at once (same result)
};

/// What pose_correctives() did for one joint.
struct JointCorrective {
  int joint = 0;              ///< SMPL joint index (1..K-1)
  int band_vertices = 0;      ///< vertices solved for (the rest follow skinning)
  int samples = 0;            ///< bends fitted
  int folds_skinned = 0;      ///< folded triangles over the bends with skinning alone
  int folds_target = 0;       ///< folded triangles left in the targets fitted to
  double largest_offset = 0;  ///< largest corrective offset over the bends, metres
  double fit_rms = 0;         ///< RMS of target minus fit over the band and bends, metres
  bool kept = false;          ///< false: the targets folded more than skinning; columns left 0
};

/// The correctives of every joint (K - 1 entries, joint order).
struct PoseCorrectiveReport {
  std::vector<JointCorrective> joints;
};

/// Triangles folded with respect to a single-joint bend: `posed` against `rest` with joint k
/// rotated by the unit quaternion q (w, x, y, z) about `centre`, s the per-vertex weight on the
/// joint and its descendants (the rotation a triangle should follow: q blended by the mean of its
/// vertices' s). A triangle is folded when its normal turned more than 90 degrees against that
/// rotation or its area fell below kDegenerateArea (mesh_checks.hpp); the same test as
/// flipped_triangles() with the blended rotation taken from quaternions instead of a polar
/// decomposition. Sorted indices.
std::vector<int> folded_triangles(const smpl::Vertices& rest, const smpl::Vertices& posed,
                                  const smpl::Faces& faces, const Eigen::VectorXd& s,
                                  const Eigen::Vector4d& q);

/// The 3V x 9 (K - 1) posedirs of `model` (valid; its weights, joint regressor and template
/// are read, its posedirs ignored), fitted on the template (the mean body).
Eigen::MatrixXd pose_correctives(const smpl::BodyModel& model,
                                 const PoseCorrectiveOptions& options = {},
                                 PoseCorrectiveReport* report = nullptr);

}  // namespace modelgen
