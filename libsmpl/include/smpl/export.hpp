/// \file export.hpp
/// Avatar export options shared by every format, and mesh export: OBJ and PLY (any mesh).
/// glTF 2.0 and VRM 1.0 export live in gltf.hpp (target smpl::gltf), FBX in fbx.hpp (target
/// smpl::fbx); smpl/avatar_export.hpp (target smpl::export) picks the writer by file extension.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "smpl/atomic_file.hpp"
#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"

namespace smpl {

/// Which axis is "up" in a file. The libraries work in +Y up, facing +Z (glTF's frame); `Z`
/// rotates the mesh by +90 degrees about X, (x, y, z) -> (x, -z, y): +Z up, facing -Y (Blender's
/// frame, and what PLY tools without an axis setting expect).
enum class UpAxis { Y, Z };

/// Names of the joints (bones) in rigged formats.
enum class BoneNames {
  Model,  ///< the model's own joint names (open models and SMPL files: "pelvis", "left_hip", ...)
  Smpl,   ///< SMPL's Unity and FBX names, "m_avg_Pelvis", "m_avg_L_Hip", ... (24-joint models only)
};

/// One set of options for every export format. Members a format cannot honour are either
/// ignored (documented per member) or refused with a ModelError naming the option.
struct GltfSkinWeights;  // smpl/gltf.hpp

struct ExportOptions {
  bool stand_on_floor = true;   ///< translate so that the rest mesh's min y is 0 (all formats).
  std::string name = "avatar";  ///< mesh, scene and (VRM) model name.
  /// Key/values stored with the avatar (model, sex, betas, measurements): glTF/VRM asset.extras,
  /// FBX scene metadata, OBJ/PLY one `caliper-metadata {json}` comment. Never personal data
  /// beyond what the caller passes.
  std::map<std::string, std::string> extras;
  /// SMPL axis-angle pose (3K values, joint 0 = global orientation) or empty for the rest pose.
  /// OBJ/PLY: the posed mesh is written; glTF: the joints are rotated, the bind pose stays the
  /// rest pose (the skin's inverse bind matrices); FBX: mesh and skeleton are posed and bound in
  /// that pose; VRM refuses a pose (its rest must be the T-pose). The posed body keeps the rest
  /// pose's floor offset.
  Eigen::VectorXd pose;
  BoneNames bone_names = BoneNames::Model;  ///< glTF, VRM, FBX joint names.
  /// glTF/VRM: morph targets (named beta_00, beta_01, ...) for the first `shape_keys` shape
  /// components, their default weights the avatar's betas, so that the file shows the avatar as
  /// made and a viewer's sliders reshape it. 0 = none; more than the model has is an error.
  int shape_keys = 0;
  bool pose_correctives = false;  ///< glTF: posedirs as morph targets (9 (K - 1) targets).
  UpAxis up = UpAxis::Y;          ///< OBJ and PLY only (glTF, VRM, FBX have their own frames).
  /// VRM: licence of the body model, written to VRMC_vrm.meta.otherLicenseUrl. Empty: the
  /// model's own `licence` metadata (the open models: MIT); a model without one (e.g. a user's
  /// SMPL file) is refused with a message asking for it.
  std::string licence;
  std::string author = "The Virtual Caliper user";  ///< VRM meta.authors[0].
  /// glTF/VRM: precomputed gltf_skin_weights() of the same model (not owned; must outlive the
  /// call), or null to compute them; other formats ignore it. Wrong sizes throw
  /// std::invalid_argument.
  const GltfSkinWeights* skin_weights = nullptr;
  /// The rest-pose vertices of `betas` when the caller already has them (shape(model,
  /// betas).vertices before any lift onto the floor; not owned, must outlive the call), so that
  /// the exporters do not compute them again; null to compute them. Wrong sizes throw
  /// std::invalid_argument.
  const Vertices* rest_vertices = nullptr;
};

/// Bone names of `model` under `naming`. Throws ModelError when `naming` is Smpl and the model
/// does not have SMPL's 24 joints (names and parents).
std::vector<std::string> bone_names(const BodyModel& model, BoneNames naming);

/// SMPL's Unity/FBX bone names ("m_avg_Pelvis", ...), in SMPL's joint order.
const std::vector<std::string>& smpl_fbx_bone_names();

/// Checks `options.pose` against the model (empty or 3K finite values); throws ModelError.
void check_pose(const BodyModel& model, const ExportOptions& options);
/// As check_pose(model, options), the ModelError's message prefixed with `context` (the file
/// being written) and ": ".
void check_pose(const BodyModel& model, const ExportOptions& options, const std::string& context);

/// The exported rest-pose body: shape(model, betas) (its vertices options.rest_vertices when
/// given, the joints regressed from them) lifted onto the floor when options.stand_on_floor.
/// Throws ModelError for too many betas.
Body export_rest_body(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                      const ExportOptions& options, const std::string& context);

/// Writes a Wavefront OBJ (v, vn, f lines; 1-based indices; `# up: z` when up is Z) atomically
/// (write_file_atomic). `metadata` (JSON text, one line) goes into a
/// `# caliper-metadata` comment when not empty. With texture coordinates (`uv_faces` F x 3
/// indexing the T x 2 `uvs`, as BodyModel::uvs / uv_faces), also `vt u v` lines (v up, OBJ's
/// convention and the model's) and `f v/t/n` corners: OBJ indexes texture coordinates per corner,
/// so no vertex is split. Without them (0 rows) the file is what it was before texture
/// coordinates existed. Throws ModelError for a bad mesh (also: `uv_faces` rows differ from the
/// faces', an index outside `uvs`, a non-finite coordinate), WriteError when writing fails (an
/// existing file is then untouched).
void write_obj(const std::string& path, const Vertices& vertices, const Faces& faces,
               UpAxis up = UpAxis::Y, const std::string& metadata = {},
               const TexCoords& uvs = TexCoords(), const Faces& uv_faces = Faces());

/// Writes a binary little-endian PLY (float xyz and normals, int32 triangles; `comment up: z`
/// when up is Z, `comment caliper-metadata ...` with `metadata`) atomically. PLY has one index per
/// vertex and no texture-coordinate element that tools agree on, so it carries no texture
/// coordinates: the mesh stays welded, one vertex per model vertex. Throws ModelError
/// for a bad mesh, WriteError when writing fails.
void write_ply(const std::string& path, const Vertices& vertices, const Faces& faces,
               UpAxis up = UpAxis::Y, const std::string& metadata = {});

/// Writes the avatar of `model` with `betas` (posed with options.pose, on the floor, options.up)
/// as OBJ or PLY by the extension of `path`, with options.extras as metadata; OBJ with the
/// model's texture coordinates when it has them. Throws ModelError.
void write_mesh_avatar(const std::string& path, const BodyModel& model,
                       const Eigen::Ref<const Eigen::VectorXd>& betas,
                       const ExportOptions& options = {});

/// The JSON of the `caliper-metadata` comment of OBJ and PLY files (write_mesh_avatar): one
/// compact line, a JSON object of the string `extras` in key order, made by nlohmann-json
/// (`{"model":"caliper-female","sex":"female"}`; control characters escaped, bytes that are not
/// UTF-8 replaced by U+FFFD). Empty `extras` give "" (no comment). read_mesh_avatar reads it.
std::string mesh_metadata_json(const std::map<std::string, std::string>& extras);

/// `vertices` mapped from the libraries' frame (+Y up) to `up`: identity for Y, (x, -z, y) for Z.
Vertices to_up_axis(const Vertices& vertices, UpAxis up);
/// The inverse of to_up_axis().
Vertices from_up_axis(const Vertices& vertices, UpAxis up);

/// Per-vertex unit normals (area-weighted face normals), V x 3.
Vertices vertex_normals(const Vertices& vertices, const Faces& faces);

/// A model's mesh split at its texture seams, for formats that index every attribute per vertex
/// (glTF, VRM, FBX through Assimp). A model vertex whose corners use several texture coordinates
/// becomes one output vertex per (vertex, texture coordinate) pair: vertex v keeps index v with
/// the texture coordinate of its first corner in face order, each further pair is appended after
/// the V model vertices in order of first use. A vertex no face uses keeps (0, 0).
struct SeamSplit {
  std::vector<int> source;  ///< model vertex of each output vertex; source[v] == v for v < V
  Faces faces;              ///< F x 3, the model's triangles re-indexed into the output vertices
  TexCoords uvs;            ///< one per output vertex (the model's convention, v up)
};

/// The seam split of `model` (BodyModel::has_uvs()); a model without texture coordinates gives
/// source = 0..V-1, its own faces and 0 rows of uvs. Every per-vertex attribute of the output is
/// that of its source vertex (positions, normals computed on the unsplit mesh so that seams stay
/// smooth, skinning weights, blend shapes). Throws ModelError naming `context` when uv_faces does
/// not have the faces' rows, indexes outside uvs, or uvs holds NaN or infinity.
SeamSplit split_at_seams(const BodyModel& model, const std::string& context);

/// A mesh read back from a file split at its texture seams (read_gltf(), read_fbx()) joined
/// again: every vertex at bit for bit the position of an earlier vertex is joined to that one (a
/// seam split copies positions exactly; two vertices of a body are never at one place).
struct SeamJoin {
  std::vector<int> kept;     ///< the input vertices kept, increasing (0..V-1 for a split model)
  std::vector<int> to_kept;  ///< every input vertex's row among `kept`
  Faces faces;               ///< the faces re-indexed into the kept vertices
};

/// Joins the seams of `vertices` / `faces`. Throws ModelError when a face names a vertex that
/// `vertices` does not have.
SeamJoin join_seams(const Vertices& vertices, const Faces& faces);

}  // namespace smpl
