/// \file export.hpp
/// Mesh export: OBJ and PLY (any mesh). glTF 2.0 export lives in gltf.hpp (target smpl::gltf).
#pragma once

#include <string>

#include "smpl/atomic_file.hpp"
#include "smpl/body_model.hpp"

namespace smpl {

/// Writes a Wavefront OBJ (v, vn, f lines; 1-based indices), atomically
/// (smpl/atomic_file.hpp). Throws ModelError for a bad mesh, WriteError when writing fails.
void write_obj(const std::string& path, const Vertices& vertices, const Faces& faces);

/// Writes a binary little-endian PLY (float xyz, int32 triangles), atomically.
/// Throws ModelError for a bad mesh, WriteError when writing fails.
void write_ply(const std::string& path, const Vertices& vertices, const Faces& faces);

/// Per-vertex unit normals (area-weighted face normals), V x 3.
Vertices vertex_normals(const Vertices& vertices, const Faces& faces);

}  // namespace smpl
