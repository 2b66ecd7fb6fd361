/// \file gltf.hpp
/// glTF 2.0 export of a rigged, skinned avatar (Khronos glTF 2.0 specification): one skinned mesh
/// (POSITION, NORMAL, JOINTS_0, WEIGHTS_0 with at most 4 renormalised influences, TEXCOORD_0 when
/// the model has texture coordinates, the mesh split at the seams at export time), the joint
/// hierarchy with joint names, inverse bind matrices, the shape baked in, optional shape-key and
/// pose-corrective morph targets, an optional pose on the joints; and VRM 1.0 (glTF 2.0 with the
/// VRMC_vrm extension: humanoid bone map, meta, first-person settings). Only this target includes
/// tiny_gltf.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "smpl/atomic_file.hpp"
#include "smpl/body_model.hpp"
#include "smpl/export.hpp"

namespace smpl {

/// The skin attributes of a model's avatars: the 4 largest skinning weights of each vertex
/// renormalised so that their float sum is 1 (JOINTS_0 / WEIGHTS_0, 4 V values each). They depend
/// on the model only (not on betas).
struct GltfSkinWeights {
  std::vector<std::uint16_t> joints;  ///< 4 V joint indices, unused slots 0
  std::vector<float> weights;         ///< 4 V weights, unused slots 0
};

/// What write_gltf() computes per call for `model`'s skin; compute it once and pass it in
/// GltfOptions::skin_weights to write many avatars of one model faster (same bytes).
GltfSkinWeights gltf_skin_weights(const BodyModel& model);

/// glTF export takes the options every format shares (smpl/export.hpp).
using GltfOptions = ExportOptions;

/// Exports the avatar of `model` with `betas` baked in (rest T-pose). The file holds one skinned
/// mesh: POSITION and NORMAL (float), JOINTS_0 (unsigned short) and WEIGHTS_0 (float, the 4
/// largest skinning weights of each vertex renormalised to sum 1), uint32 indices; one node per
/// joint named by options.bone_names, translated relative to its parent (and rotated by
/// options.pose); inverse bind matrices translation(-J_shaped). Morph targets, in this order:
/// with options.shape_keys = N, N targets beta_00 ... (shapedirs columns; POSITION holds the body
/// without them and their default weights are betas[0..N), so the default shape is the avatar);
/// with options.pose_correctives, 9 (K - 1) targets (posedirs columns, weight (R_k - I)(r, c),
/// may be negative; 0 in the rest pose). Names in mesh.extras.targetNames. When the model has
/// texture coordinates (BodyModel::has_uvs()), the mesh also has TEXCOORD_0 (float; glTF's
/// convention, v = 1 - the model's v) and is split at the seams (split_at_seams(), export.hpp):
/// vertices 0..V-1 are the model's, each further (vertex, texture coordinate) pair is a copy
/// appended after them with the same position, normal (of the unsplit mesh), JOINTS_0/WEIGHTS_0
/// and morph-target displacements; without texture coordinates the file is what it was before
/// they were exported (one glTF vertex per model vertex). `.glb` writes binary
/// glTF, `.gltf` JSON with an embedded buffer, atomically (write_file_atomic). Throws ModelError
/// for an unknown extension or a model that cannot be serialised, WriteError when writing fails
/// (the previous file is then unchanged).
void write_gltf(const std::string& path, const BodyModel& model,
                const Eigen::Ref<const Eigen::VectorXd>& betas, const GltfOptions& options = {});

/// Exports a VRM 1.0 avatar (`.vrm`: GLB with the VRMC_vrm extension, specVersion "1.0"): the
/// glTF avatar above (rest pose; the model's rest pose is its T-pose, facing +Z, on the floor)
/// plus the humanoid bone map from SMPL's joint names (hips, spine, chest, upperChest, neck,
/// head, shoulders, upper/lower arms, hands, upper/lower legs, feet, toes), meta (options.name,
/// options.author, the VRM Public Licence URL the specification requires, the body model's
/// licence as otherLicenseUrl / thirdPartyLicenses) and first-person settings (the mesh is
/// annotated `auto`: triangles weighted to the head are hidden in first person). Throws
/// ModelError when the model lacks a required humanoid joint, when options.pose is set, or when
/// the model's licence is unknown and options.licence is empty (the message says how to state
/// it).
void write_vrm(const std::string& path, const BodyModel& model,
               const Eigen::Ref<const Eigen::VectorXd>& betas, const ExportOptions& options = {});

/// The same VRM as bytes in memory.
std::vector<std::uint8_t> vrm_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const ExportOptions& options = {});

/// The VRM humanoid bone of each SMPL joint name ("pelvis" -> "hips", ...); joints without one
/// (SMPL's left_hand/right_hand) are absent.
const std::map<std::string, std::string>& vrm_humanoid_bones();

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
  /// V x 2 TEXCOORD_0 in the model's (and OBJ's) convention, v up (v = 1 - glTF's v); 0 rows when
  /// the file has none.
  TexCoords texcoords;
  std::vector<double> morph_weights;          ///< mesh.weights (default weights; 0 when absent)
  std::vector<std::string> morph_names;       ///< mesh.extras.targetNames ("" when absent)
  std::string generator;                      ///< asset.generator
  std::map<std::string, std::string> extras;  ///< asset.extras entries that are strings
  std::vector<std::string> warnings;          ///< tinygltf's warnings on a file that still loaded.
};

/// Reads back a GLB/glTF/VRM written by write_gltf() or write_vrm() (or any single-skinned-mesh
/// glTF); the format is chosen by content (GLB magic "glTF", else JSON). TEXCOORD_0, when present,
/// is read into GltfAvatar::texcoords (one per vertex: a file split at seams has more vertices
/// than the model; its faces name the split vertices). POSITION is the bind
/// (rest) pose whatever the joints' pose. Throws ModelError naming the file and the
/// problem; tinygltf warnings are reported in the message. Hostile files are refused, never
/// followed (docs/reliability.md, "Readers"):
/// - external buffers and images are read only from relative URIs inside the file's own folder:
///   "..", absolute paths, symbolic links leading out, and schemes other than data: (http:,
///   file:, ...) are refused with an error naming the URI; images are never decoded;
/// - JSON nested more than 128 levels deep is refused;
/// - accessors and bufferViews are bounds-checked without overflow (any byteOffset);
/// - JOINTS_0 must hold integer joint indices of the skin, indices must name vertices;
/// - the node hierarchy may be any depth (no recursion); cycles are refused;
/// - the arrays made may hold at most 16 times the bytes of the file and its buffers plus 16 MiB
///   (accessors shared by many morph targets are refused beyond that).
GltfAvatar read_gltf(const std::string& path);

/// read_gltf() on file bytes in memory; `context` starts every error message. No external file
/// is ever read: only GLB binary chunks and data: URIs are accepted.
GltfAvatar read_gltf_from_memory(const std::uint8_t* bytes, std::size_t size,
                                 const std::string& context);

}  // namespace smpl
