/// \file evaluate.hpp
/// The SMPL forward pass (Loper et al. 2015, eqs. 1-4): shape blend shapes, joint regression,
/// pose blend shapes, Rodrigues, kinematic chain and linear blend skinning.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "smpl/body_model.hpp"

namespace smpl {

/// A posed (or rest-pose) body.
struct Body {
  Vertices vertices;  ///< V x 3, metres, posed and translated.
  Joints joints;      ///< K x 3 posed joint positions (translation included), metres.
  /// K world transforms G_j of the joints (rotation and posed joint position), translation
  /// included; the skinning transform of joint j is G_j * translation(-J_rest_j).
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> transforms;
};

/// Rest-pose body for `betas`: v_shaped = v_template + shapedirs * betas and J = J_regressor *
/// v_shaped. `betas` may be shorter than model.num_betas() (missing ones are 0); longer throws
/// std::invalid_argument. transforms are pure translations to the joints. Cost: one 3V x |betas|
/// matrix-vector product plus the sparse regression.
Body shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas);

/// Same as shape(), writing into `out` (allocation-free once `out` has the model's sizes).
void shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas, Body& out);

/// Full forward pass. `pose`: 3K axis-angle values (joint 0 = global orientation) or empty for the
/// rest pose; `translation` is added last. Pose blend shapes are applied when the model has them;
/// the 9 features of a joint whose rotation is exactly the identity are zero and their columns are
/// skipped. Throws std::invalid_argument when betas are longer than the model's or pose is neither
/// empty nor 3K long.
Body evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose,
              const Eigen::Vector3d& translation = Eigen::Vector3d::Zero());

/// Caller-owned scratch memory for allocation-free per-frame evaluation. Reuse one Workspace (and
/// one Body) per thread and per model: the first call sizes every buffer, later calls with the same
/// model allocate nothing.
struct Workspace {
  Vertices v_shaped;             ///< V x 3 shaped (then pose-corrected) rest vertices.
  Eigen::VectorXd pose_feature;  ///< P = 9 (K - 1) pose-blend-shape features.
  std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>> rotations;  ///< K local.
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> skinning;   ///< K A_j.
  Joints rest_joints;                ///< K x 3 joints regressed from v_shaped.
  std::vector<double> skinning_3x4;  ///< K row-major 3 x 4 blocks of the skinning transforms.

  /// Opt-in single-precision pose blend shapes: when true, evaluate() keeps a float copy of
  /// model.posedirs here (17 MB for SMPL) and streams it instead of the double matrix, halving the
  /// memory traffic of the (memory-bound) posed evaluation. Per block of rows the products are
  /// summed in float, then added to the double vertices; the result is within 1e-7 m of the double
  /// path for SMPL-sized correctives (tested against 1e-6 m). The copy is made on the first call
  /// and again whenever posedirs.data() or its size differs from the last call's; since models are
  /// immutable after loading, do not modify a model's posedirs in place while a workspace uses it.
  bool single_precision_pose_blend_shapes = false;
  Eigen::MatrixXf posedirs_f;                 ///< float copy of posedirs (when enabled).
  const double* posedirs_f_source = nullptr;  ///< posedirs.data() the copy was made from.
  Eigen::VectorXf pose_feature_f;             ///< float pose features (when enabled).
};

/// Same as evaluate(), writing into `out` and using `ws`; allocates nothing once `out` and `ws`
/// have been used with the same model.
void evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation,
              Workspace& ws, Body& out);

/// Rotation matrix of an axis-angle vector (angle = norm, radians; right-handed about the axis):
/// R = I + (sin t / t) K + ((1 - cos t) / t^2) K^2 with K = [axis_angle]x. Exact and finite at zero
/// angle: below t = 1e-3 the two coefficients come from their Taylor series (error < 1e-19), and
/// (1 - cos t) is computed as 2 sin^2(t / 2) to avoid cancellation. Any angle is accepted
/// (t and t + 2 pi give the same matrix).
Eigen::Matrix3d rodrigues(const Eigen::Vector3d& axis_angle);

}  // namespace smpl
