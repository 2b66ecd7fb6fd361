/// \file body_model.hpp
/// The SMPL-family body model as plain data (Loper et al., "SMPL: A Skinned Multi-Person Linear
/// Model", SIGGRAPH Asia 2015). One structure serves SMPL (24 joints), SMPL-H, SMPL-X (55),
/// MANO (16) and the project's own open models: only the sizes differ.
///
/// Conventions: metres, +Y up, the body faces +Z, the subject's left is +X (glTF's frame).
/// The model is immutable after loading and shared as `const&`.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace smpl {

/// #V x 3 vertex positions, metres, row-major so that `.data()` is interleaved xyz.
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #K x 3 joint positions, metres, row-major.
using Joints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #F x 3 triangle vertex indices (0-based, counter-clockwise seen from outside), row-major.
using Faces = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #T x 2 texture coordinates (u right, v up, OBJ's and SMPL's `vt` convention), row-major.
using TexCoords = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
/// Row-major sparse matrix (joint regressor K x V, skinning weights V x K).
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// Thrown for every file and format problem. The message names the file, the key, and the
/// expected and actual shape, in plain words.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Free-form description of where a model comes from.
struct ModelMetadata {
  std::string name;                          ///< e.g. "SMPL female v1.1.0", "caliper-open-female"
  std::string gender;                        ///< "female", "male" or "neutral" ("" when unknown)
  std::string source;                        ///< file path or generator that produced it
  std::map<std::string, std::string> extra;  ///< anything else worth keeping (licence, version)
};

/// An SMPL-family body model. Sizes: V vertices, F faces, K joints, B shape components,
/// P = 9 (K - 1) pose-blend-shape features.
struct BodyModel {
  Vertices v_template;  ///< V x 3 template (mean shape, rest T-pose), metres.
  Faces faces;          ///< F x 3 triangles.
  /// 3V x B shape blend shapes, row 3 v + c, column b (numpy's `shapedirs.reshape(-1, B)`).
  /// Column b displaces the template by one standard deviation of component b.
  Eigen::MatrixXd shapedirs;
  /// 3V x P pose blend shapes, row 3 v + c (numpy's `posedirs.reshape(-1, P)`); may have zero
  /// columns when the model has no pose correctives.
  Eigen::MatrixXd posedirs;
  SparseMatrix j_regressor;              ///< K x V, each row sums to 1: J = j_regressor * v_shaped.
  SparseMatrix weights;                  ///< V x K skinning weights, each row sums to 1.
  std::vector<int> parents;              ///< K, parents[0] == -1, parents[k] < k.
  std::vector<std::string> joint_names;  ///< K names ("pelvis", "left_hip", ...).
  std::map<std::string, std::vector<int>> landmarks;  ///< name -> vertex ids (0-based).
  std::vector<int> mirror;  ///< V left/right mirror vertex index, or empty.
  /// Texture coordinates per triangle corner: `uv_faces` row f indexes `uvs` as `faces` row f
  /// indexes the vertices. A vertex on a seam has several texture coordinates; exporters split
  /// it there. Both empty when the model has none (SMPL's own files).
  TexCoords uvs;   ///< T x 2
  Faces uv_faces;  ///< F x 3 (same rows as faces), or 0 rows
  ModelMetadata meta;

  int num_vertices() const { return static_cast<int>(v_template.rows()); }
  int num_faces() const { return static_cast<int>(faces.rows()); }
  int num_joints() const { return static_cast<int>(parents.size()); }
  int num_betas() const { return static_cast<int>(shapedirs.cols()); }
  int num_pose_features() const { return static_cast<int>(posedirs.cols()); }
  bool has_pose_blend_shapes() const { return posedirs.cols() > 0; }
  bool has_uvs() const { return uv_faces.rows() > 0; }
};

/// Checks every size and invariant (shapes agree, indices in range, parents precede children,
/// no NaN or infinity, posedirs has 0 or 9 (K - 1) columns). Throws ModelError naming `context`
/// (usually the file path) and the first problem found.
void validate(const BodyModel& model, const std::string& context);

/// SMPL's 24 joint names, in order.
const std::vector<std::string>& smpl_joint_names();
/// SMPL's 24 parents (parents[0] == -1).
const std::vector<int>& smpl_parents();

}  // namespace smpl
