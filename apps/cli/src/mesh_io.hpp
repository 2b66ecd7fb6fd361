/// \file mesh_io.hpp
/// Avatar files for the `caliper` command: writing an avatar by the output's extension
/// (smpl::export_avatar: .glb, .gltf, .vrm, .fbx, .obj, .ply) and reading a rest-pose avatar mesh
/// back (.glb/.gltf/.vrm through smpl::read_gltf, with beta_NN shape keys at their default
/// weights; .fbx through smpl::read_fbx; .obj and .ply through smpl::read_mesh_avatar, which
/// turns files written with `up: z` back to +Y up and reads their `caliper-metadata` comment
/// like a glTF's asset.extras).
#pragma once

#include <map>
#include <string>

#include <Eigen/Core>

#include "smpl/body_model.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"

namespace caliper::cli {

/// A mesh read from a file.
struct MeshFile {
  smpl::Vertices vertices;
  smpl::Faces faces;
  /// The avatar's metadata: .glb/.gltf/.vrm asset.extras strings, FBX scene metadata strings,
  /// OBJ/PLY `caliper-metadata` comment (else empty).
  std::map<std::string, std::string> extras;
  /// True when the vertex order is the file's own and may differ from the model's (FBX through
  /// Assimp; a glTF/VRM split at texture seams): put_in_model_order() maps it back through the
  /// faces.
  bool order_from_faces = false;
};

/// Reads .glb, .gltf, .vrm, .fbx, .obj or .ply (by extension). Throws RuntimeError (unknown
/// extension, missing file, no vertices) or smpl::ModelError (unreadable, malformed line,
/// unsupported PLY property, counts or indices out of range) naming the file and the problem.
MeshFile read_mesh(const std::string& path);

/// Puts `mesh`'s vertices in the order of a model with `faces` when the file kept the triangles'
/// order but not the vertices' (mesh.order_from_faces): vertex faces(f, i) of the model is
/// vertex mesh.faces(f, i) of the file. Throws RuntimeError naming `path` when the triangle
/// counts differ or a model vertex would get two different positions.
void put_in_model_order(MeshFile& mesh, const smpl::Faces& faces, const std::string& path);

/// Writes the avatar of `model` with `betas` standing on the floor (min y = 0) in the format of
/// the extension (smpl::export_avatar) with `options` (options.extras: the avatar's metadata).
/// Throws UsageError for an unknown extension; smpl::ModelError for what a format refuses and
/// write failures.
void write_avatar(const std::string& path, const smpl::BodyModel& model,
                  const Eigen::VectorXd& betas, const smpl::ExportOptions& options);

/// The same with default options and `extras` as metadata; `rest_vertices` are the avatar's
/// rest-pose vertices of `betas` (caliper::shaped_vertices: the exporters do not compute them
/// again, smpl::ExportOptions::rest_vertices).
/// `skin_weights`: smpl::gltf_skin_weights(model) computed once for many avatars of `model`, or
/// null.
void write_avatar(const std::string& path, const smpl::BodyModel& model,
                  const Eigen::VectorXd& betas, const smpl::Vertices& rest_vertices,
                  const std::map<std::string, std::string>& extras,
                  const smpl::GltfSkinWeights* skin_weights = nullptr);

/// True when `path` has an extension write_avatar() accepts.
bool is_avatar_extension(const std::string& path);

/// "--out FILE: use a .glb, .gltf, .vrm, .fbx, .obj or .ply file name" style list of the
/// extensions write_avatar() accepts: ".glb, .gltf, .vrm, .fbx, .obj or .ply".
std::string avatar_extensions_text();

}  // namespace caliper::cli
