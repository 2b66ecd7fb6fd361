// BodyModel validation and SMPL's skeleton constants (Loper et al. 2015).
#include "smpl/body_model.hpp"
#include "model_error.hpp"

#include <cmath>
#include <sstream>

namespace smpl {
namespace {

using detail::fail;

std::string shape_str(Eigen::Index r, Eigen::Index c) {
  std::ostringstream s;
  s << "(" << r << ", " << c << ")";
  return s.str();
}

template <typename M>
void check_finite(const M& m, const std::string& context, const char* key) {
  if (!m.allFinite()) fail(context, std::string("'") + key + "' contains NaN or infinity");
}

}  // namespace

void validate(const BodyModel& m, const std::string& context) {
  const Eigen::Index V = m.v_template.rows();
  const Eigen::Index K = static_cast<Eigen::Index>(m.parents.size());
  if (V == 0) fail(context, "'v_template' is empty: the model has no vertices");
  if (m.faces.rows() == 0) fail(context, "'f' is empty: the model has no faces");
  if (K == 0) fail(context, "the model has no joints ('kintree_table' is empty)");
  check_finite(m.v_template, context, "v_template");
  if (m.faces.minCoeff() < 0 || m.faces.maxCoeff() >= V) {
    fail(context, "'f' refers to vertex " + std::to_string(m.faces.maxCoeff()) +
                      " but the model has " + std::to_string(V) + " vertices");
  }
  if (m.shapedirs.rows() != 3 * V) {
    fail(context, "'shapedirs' has " + std::to_string(m.shapedirs.rows()) + " rows, expected 3 x " +
                      std::to_string(V) + " = " + std::to_string(3 * V));
  }
  check_finite(m.shapedirs, context, "shapedirs");
  if (m.posedirs.cols() != 0) {
    if (m.posedirs.rows() != 3 * V || m.posedirs.cols() != 9 * (K - 1)) {
      fail(context, "'posedirs' has shape " + shape_str(m.posedirs.rows(), m.posedirs.cols()) +
                        ", expected " + shape_str(3 * V, 9 * (K - 1)));
    }
    check_finite(m.posedirs, context, "posedirs");
  }
  if (m.j_regressor.rows() != K || m.j_regressor.cols() != V) {
    fail(context, "'J_regressor' has shape " +
                      shape_str(m.j_regressor.rows(), m.j_regressor.cols()) + ", expected " +
                      shape_str(K, V));
  }
  if (m.weights.rows() != V || m.weights.cols() != K) {
    fail(context, "'weights' has shape " + shape_str(m.weights.rows(), m.weights.cols()) +
                      ", expected " + shape_str(V, K));
  }
  for (int k = 0; k < m.j_regressor.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(m.j_regressor, k); it; ++it) {
      if (!std::isfinite(it.value())) fail(context, "'J_regressor' contains NaN or infinity");
    }
  }
  for (int v = 0; v < m.weights.outerSize(); ++v) {
    for (SparseMatrix::InnerIterator it(m.weights, v); it; ++it) {
      if (!std::isfinite(it.value())) fail(context, "'weights' contains NaN or infinity");
    }
  }
  if (m.parents[0] != -1) fail(context, "joint 0 must be the root (parent -1)");
  for (Eigen::Index k = 1; k < K; ++k) {
    const int p = m.parents[static_cast<size_t>(k)];
    if (p < 0 || p >= k) {
      fail(context, "joint " + std::to_string(k) + " has parent " + std::to_string(p) +
                        ": parents must precede their children");
    }
  }
  if (!m.joint_names.empty() && static_cast<Eigen::Index>(m.joint_names.size()) != K) {
    fail(context, "there are " + std::to_string(m.joint_names.size()) + " joint names for " +
                      std::to_string(K) + " joints");
  }
  for (const auto& [name, ids] : m.landmarks) {
    for (int id : ids) {
      if (id < 0 || id >= V) {
        fail(context, "landmark '" + name + "' refers to vertex " + std::to_string(id) +
                          " but the model has " + std::to_string(V) + " vertices");
      }
    }
  }
  if (m.uv_faces.rows() > 0 || m.uvs.rows() > 0) {
    if (m.uv_faces.rows() != m.faces.rows()) {
      fail(context, "'ft' has " + std::to_string(m.uv_faces.rows()) +
                        " rows, expected one per face (" + std::to_string(m.faces.rows()) + ")");
    }
    if (!m.uvs.allFinite()) fail(context, "'vt' holds NaN or infinity");
    for (Eigen::Index i = 0; i < m.uv_faces.size(); ++i) {
      const int t = m.uv_faces.data()[i];
      if (t < 0 || t >= m.uvs.rows()) {
        fail(context, "'ft' refers to texture coordinate " + std::to_string(t) + " but 'vt' has " +
                          std::to_string(m.uvs.rows()));
      }
    }
  }
  if (!m.mirror.empty()) {
    if (static_cast<Eigen::Index>(m.mirror.size()) != V) {
      fail(context, "'vert_sym_idxs' has " + std::to_string(m.mirror.size()) +
                        " entries, expected " + std::to_string(V));
    }
    for (int id : m.mirror) {
      if (id < 0 || id >= V) fail(context, "'vert_sym_idxs' has an index out of range");
    }
  }
}

const std::vector<std::string>& smpl_joint_names() {
  static const std::vector<std::string> names = {
      "pelvis",     "left_hip",    "right_hip",    "spine1",      "left_knee",     "right_knee",
      "spine2",     "left_ankle",  "right_ankle",  "spine3",      "left_foot",     "right_foot",
      "neck",       "left_collar", "right_collar", "head",        "left_shoulder", "right_shoulder",
      "left_elbow", "right_elbow", "left_wrist",   "right_wrist", "left_hand",     "right_hand"};
  return names;
}

const std::vector<int>& smpl_parents() {
  static const std::vector<int> parents = {-1, 0, 0, 0,  1,  2,  3,  4,  5,  6,  7,  8,
                                           9,  9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21};
  return parents;
}

}  // namespace smpl
