/// \file random_model.hpp
/// Test fixtures: random but valid SMPL-shaped body models built in memory, so that no licensed
/// model file is ever needed. Deterministic for a given seed (std::mt19937_64 with our own
/// Box-Muller normals, so the numbers are the same on every standard library).
#pragma once

#include <cstdint>
#include <vector>

#include "smpl/body_model.hpp"

namespace caliper::test {

/// What make_random_model() builds.
struct RandomModelOptions {
  int num_betas = 10;             ///< B shape components (SMPL: 10 or 300).
  int num_joints = 24;            ///< K: 24 (SMPL parents), 55 (SMPL-X), 16 (MANO), or any >= 1.
  bool pose_blend_shapes = true;  ///< include 3V x 9(K-1) posedirs.
  std::uint64_t seed = 1;         ///< same seed, same model.
  /// Mesh resolution: a closed genus-0 surface with rings * segments + 2 vertices and
  /// 2 * rings * segments triangles. The defaults give SMPL's 6890 vertices / 13776 faces.
  int rings = 84;
  int segments = 82;
  double shape_scale = 0.01;  ///< standard deviation of shapedirs entries, metres per unit beta.
  double pose_scale = 0.002;  ///< standard deviation of posedirs entries, metres.
};

/// A valid BodyModel (passes smpl::validate) shaped like a standing person: a perturbed
/// ellipsoid 1.72 m tall with its feet at y = -1.12 and its origin near the pelvis, outward
/// winding, closed (V - E + F = 2). Joints: SMPL / SMPL-X / MANO parents and names for 24 / 55 /
/// 16 joints, otherwise a random tree with names "joint<k>". J_regressor: 10 positive entries per
/// row summing to 1. Skinning weights: the 4 nearest joints of each vertex (fewer for K < 4),
/// positive, summing to 1. Landmarks: every name of the shared vocabulary, mapped to plausible
/// vertices (extreme points of the ellipsoid). Mirror: the vertex mirrored in x (same ring).
smpl::BodyModel make_random_model(const RandomModelOptions& options = {});

/// Shorthand for the common cases.
inline smpl::BodyModel make_random_model(int num_betas, int num_joints = 24,
                                         bool pose_blend_shapes = true, std::uint64_t seed = 1) {
  RandomModelOptions o;
  o.num_betas = num_betas;
  o.num_joints = num_joints;
  o.pose_blend_shapes = pose_blend_shapes;
  o.seed = seed;
  return make_random_model(o);
}

/// SMPL-X's 55 parents (body 22, jaw, two eyes, 2 x 15 finger joints).
const std::vector<int>& smplx_parents();
/// SMPL-X's 55 joint names.
const std::vector<std::string>& smplx_joint_names();
/// MANO's 16 parents (wrist, then 5 fingers of 3 joints).
const std::vector<int>& mano_parents();

/// Random axis-angle pose (3K values), each joint's rotation angle uniform in [0, max_angle]
/// about a random axis. Deterministic for a given seed.
Eigen::VectorXd random_pose(int num_joints, double max_angle, std::uint64_t seed);
/// Random betas, standard normal entries scaled by `scale`.
Eigen::VectorXd random_betas(int num_betas, double scale, std::uint64_t seed);

}  // namespace caliper::test
