/// \file mesh_io.hpp
/// Avatar files for the `caliper` command: writing an avatar by the output's extension (.glb and
/// .gltf through smpl::gltf, .obj and .ply through smpl/export.hpp) and reading a rest-pose
/// avatar mesh back (.glb/.gltf through smpl::read_gltf; OBJ and PLY through smpl/mesh_read.hpp:
/// Wavefront OBJ `v`/`f` lines; PLY ascii or binary little-endian with x, y, z and a face index
/// list).
#pragma once

#include <map>
#include <string>

#include <Eigen/Core>

#include "smpl/body_model.hpp"

namespace caliper::cli {

/// A mesh read from a file.
struct MeshFile {
  smpl::Vertices vertices;
  smpl::Faces faces;
  std::map<std::string, std::string> extras;  ///< .glb/.gltf asset.extras strings (else empty)
};

/// Reads .glb, .gltf, .obj or .ply (by extension). Throws RuntimeError (unknown extension,
/// missing file, no vertices) or smpl::ModelError (unreadable, malformed line, unsupported PLY
/// property, counts or indices out of range) naming the file and the problem.
MeshFile read_mesh(const std::string& path);

/// Writes the avatar of `model` with `betas` standing on the floor (min y = 0): .glb / .gltf
/// (rigged, with `extras` in asset.extras), .obj or .ply (the rest-pose mesh). Throws
/// UsageError for another extension; smpl::ModelError for write failures.
void write_avatar(const std::string& path, const smpl::BodyModel& model,
                  const Eigen::VectorXd& betas, const smpl::Vertices& rest_vertices,
                  const std::map<std::string, std::string>& extras);

/// True when `path` has an extension write_avatar() accepts.
bool is_avatar_extension(const std::string& path);

}  // namespace caliper::cli
