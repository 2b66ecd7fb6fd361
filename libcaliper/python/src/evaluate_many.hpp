/// \file evaluate_many.hpp
/// The batch forward pass of the Python module's evaluate(): smpl::evaluate() (the single-body,
/// allocation-free workspace overload) in a loop over N bodies, writing straight into the
/// caller's output arrays. libsmpl has no batch API yet, so the loop lives here; the model's
/// arrays are read in place, never copied.
#pragma once

#include <algorithm>

#include <Eigen/Core>

#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"

namespace caliper::python {

/// Row-major input arrays of a batch of `count` bodies (pointers owned by the caller).
struct BatchInput {
  int count = 0;
  const double* betas = nullptr;         ///< count x num_betas
  int num_betas = 0;                     ///< <= model.num_betas()
  const double* poses = nullptr;         ///< count x 3K axis-angle, or null for the rest pose
  const double* translations = nullptr;  ///< count x 3, or null for none
};

/// Evaluates every body of `in` and writes its vertices to `vertices` (count x V x 3) and, when
/// `joints` is not null, its posed joints to `joints` (count x K x 3), converted to `Out`
/// (double or float). Sizes are the caller's contract (the module checks them); throws
/// std::invalid_argument from smpl::evaluate() for betas longer than the model's.
template <class Out>
void evaluate_many(const smpl::BodyModel& model, const BatchInput& in, Out* vertices, Out* joints) {
  smpl::Workspace ws;
  smpl::Body body;
  const Eigen::Index k3 = 3 * Eigen::Index{model.num_joints()};
  const Eigen::Index v3 = 3 * static_cast<Eigen::Index>(model.num_vertices());
  const Eigen::VectorXd rest_pose;
  for (Eigen::Index i = 0; i < in.count; ++i) {
    const Eigen::Map<const Eigen::VectorXd> betas(in.betas + i * Eigen::Index{in.num_betas},
                                                  in.num_betas);
    const Eigen::Vector3d t =
        in.translations ? Eigen::Vector3d(in.translations[3 * i], in.translations[3 * i + 1],
                                          in.translations[3 * i + 2])
                        : Eigen::Vector3d::Zero();
    if (in.poses) {
      const Eigen::Map<const Eigen::VectorXd> pose(in.poses + i * k3, k3);
      smpl::evaluate(model, betas, pose, t, ws, body);
    } else {
      smpl::evaluate(model, betas, rest_pose, t, ws, body);
    }
    std::copy(body.vertices.data(), body.vertices.data() + v3, vertices + i * v3);
    if (joints) std::copy(body.joints.data(), body.joints.data() + k3, joints + i * k3);
  }
}

}  // namespace caliper::python
