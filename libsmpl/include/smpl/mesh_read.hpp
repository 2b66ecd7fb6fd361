/// \file mesh_read.hpp
/// Reading triangle meshes back: Wavefront OBJ (`v` and `f` lines; polygons fan-triangulated)
/// and PLY (ascii or binary little-endian; x, y, z of the `vertex` element, the
/// `vertex_indices` / `vertex_index` list of the `face` element). Both are readers of untrusted
/// files: sizes are bounded by the bytes present, every index is range-checked before it is
/// converted (docs/reliability.md, "Readers").
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
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

/// An avatar read back from the OBJ or PLY file that write_mesh_avatar (or write_obj/write_ply
/// with metadata) wrote: +Y up, in metres, with its metadata.
struct MeshAvatar {
  Vertices vertices;  ///< V x 3, turned back to +Y up when the file says `up: z`
  Faces faces;        ///< F x 3, every index < V
  /// The string values of the `caliper-metadata {json}` comment (values of other JSON types are
  /// skipped); empty without that comment.
  std::map<std::string, std::string> extras;
};

/// Reads an .obj or .ply file (by extension, any case) through read_obj / read_ply and reads its
/// comments as the writers put them: "up: z ..." (the vertices are turned back to +Y up,
/// from_up_axis) and "caliper-metadata {json}" (a JSON object: mesh_metadata_json's output).
/// Other comments are ignored. Throws ModelError naming `path`: another extension, what
/// read_obj / read_ply throw, a metadata comment that is not a JSON object.
MeshAvatar read_mesh_avatar(const std::string& path);

/// Parses the JSON of a `caliper-metadata` comment into its string members (what mesh_metadata_json
/// wrote). Throws ModelError naming `context` when `json` is not a JSON object.
std::map<std::string, std::string> parse_mesh_metadata_json(const std::string& json,
                                                            const std::string& context);

}  // namespace smpl
