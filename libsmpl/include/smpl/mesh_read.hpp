/// \file mesh_read.hpp
/// Reading triangle meshes back: Wavefront OBJ (`v` and `f` lines; polygons fan-triangulated)
/// and PLY (ascii or binary little-endian; x, y, z of the `vertex` element, the
/// `vertex_indices` / `vertex_index` list of the `face` element). Both are readers of untrusted
/// files: sizes are bounded by the bytes present, every index is range-checked before it is
/// converted (docs/reliability.md, "Readers").
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "smpl/body_model.hpp"

namespace smpl {

/// A mesh read from a file: V x 3 vertex positions (the file's units) and F x 3 triangles.
struct MeshData {
  Vertices vertices;
  Faces faces;
  /// The text of every comment, in file order: an OBJ `#` line without the `#`, a PLY `comment`
  /// line without the keyword (smpl::write_obj / write_ply put the axis and metadata there).
  std::vector<std::string> comments;
};

/// Parses OBJ text. Face indices are 1-based or negative (relative to the vertices so far);
/// "i/t/n" takes i. Throws ModelError naming `context` and the line: malformed `v` line,
/// non-finite coordinate, bad or zero face index, a face of fewer than 3 vertices, an index
/// outside the vertices (never wrapped: 4294967298 is out of range, not vertex 1).
MeshData parse_obj(const std::string& text, const std::string& context);

/// Parses PLY bytes. Throws ModelError naming `context`: no "ply" magic or end_header, a format
/// other than ascii / binary_little_endian, unknown property types, a list count of a non-integer
/// type, element or list counts larger than the bytes left can hold (`element vertex 3000000000`
/// in a small file allocates nothing), truncated data, non-finite coordinates, face indices that
/// are not integers naming a vertex.
MeshData parse_ply(const std::uint8_t* bytes, std::size_t size, const std::string& context);

/// Reads and parses an OBJ file; errors name `path`.
MeshData read_obj(const std::string& path);
/// Reads and parses a PLY file; errors name `path`.
MeshData read_ply(const std::string& path);

}  // namespace smpl
