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
/// v_shaped. `betas` may be shorter than model.num_betas() (missing ones are 0); longer is a
/// precondition violation. transforms are pure translations to the joints.
Body shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas);

/// Full forward pass. `pose`: 3K axis-angle values (joint 0 = global orientation) or empty for the
/// rest pose; `translation` is added last.
Body evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose,
              const Eigen::Vector3d& translation = Eigen::Vector3d::Zero());

/// Caller-owned scratch memory for allocation-free per-frame evaluation.
struct Workspace {
  Vertices v_shaped;
  Eigen::VectorXd pose_feature;
  std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>> rotations;
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> skinning;
  Joints rest_joints;
};

/// Same as evaluate(), writing into `out` and using `ws`; allocates nothing once `out` and `ws`
/// have been used with the same model.
void evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation,
              Workspace& ws, Body& out);

/// Rotation matrix of an axis-angle vector; exact and finite at zero angle (uses a series
/// expansion for small angles).
Eigen::Matrix3d rodrigues(const Eigen::Vector3d& axis_angle);

}  // namespace smpl
