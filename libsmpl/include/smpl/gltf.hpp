/// \file gltf.hpp
/// glTF 2.0 export of a rigged, skinned avatar (Khronos glTF 2.0 specification): one skinned mesh
/// (POSITION, NORMAL, JOINTS_0, WEIGHTS_0 with at most 4 renormalised influences), the joint
/// hierarchy with joint names, inverse bind matrices, the shape baked in, optional pose-corrective
/// morph targets. Only this target includes tiny_gltf.h.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "smpl/atomic_file.hpp"
#include "smpl/body_model.hpp"

namespace smpl {

struct GltfOptions {
  bool stand_on_floor = true;     ///< translate so that the mesh's min y is 0.
  bool pose_correctives = false;  ///< add posedirs as morph targets (P targets).
  std::string name = "avatar";    ///< mesh and scene name.
  /// Extra key/values written to asset.extras (e.g. measurements, betas); never personal data
  /// beyond what the caller passes.
  std::map<std::string, std::string> extras;
};

/// Exports the avatar of `model` with `betas` baked in (rest T-pose). The file holds one skinned
/// mesh: POSITION and NORMAL (float), JOINTS_0 (unsigned short) and WEIGHTS_0 (float, the 4
/// largest skinning weights of each vertex renormalised to sum 1), uint32 indices; one node per
/// joint named from model.joint_names, translated relative to its parent; inverse bind matrices
/// translation(-J_shaped); with options.pose_correctives, 9 (K - 1) morph targets (posedirs
/// columns, named in mesh.extras.targetNames; target weight = (R_k - I)(r, c), may be negative).
/// `.glb` writes binary glTF, `.gltf` writes JSON with an embedded buffer, atomically
/// (write_file_atomic). Throws ModelError for an unknown extension or a model that cannot be
/// serialised, WriteError when writing fails (the previous file is then unchanged).
void write_gltf(const std::string& path, const BodyModel& model,
                const Eigen::Ref<const Eigen::VectorXd>& betas, const GltfOptions& options = {});

/// The same avatar as GLB bytes in memory (no disk I/O).
std::vector<std::uint8_t> glb_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const GltfOptions& options = {});

/// What read_gltf() gives back: the baked mesh and its skin.
struct GltfAvatar {
  Vertices vertices;
  Faces faces;
  Joints joints;  ///< rest joint positions from the node hierarchy.
  std::vector<std::string> joint_names;
  std::vector<int> parents;
  Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor> joint_ids;         ///< V x 4 JOINTS_0
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> joint_weights;  ///< V x 4 WEIGHTS_0
  /// Position displacements (V x 3) of the mesh's morph targets, in order (empty when none).
  std::vector<Vertices> morph_targets;
  std::string generator;                      ///< asset.generator
  std::map<std::string, std::string> extras;  ///< asset.extras entries that are strings
  std::vector<std::string> warnings;          ///< tinygltf's warnings on a file that still loaded.
};

/// Reads back a GLB/glTF written by write_gltf() (or any single-skinned-mesh glTF). Throws
/// ModelError naming the file and the problem; tinygltf warnings are reported in the message.
GltfAvatar read_gltf(const std::string& path);

}  // namespace smpl
