/// \file makehuman.hpp
/// Readers for MakeHuman's CC0 assets (the hm08 base mesh, targets, the default skeleton and its
/// skinning weights; ../shared/data/makehuman/README.md) and the selection of the skin mesh the
/// open body model is built on. Only the file formats are used here (plain OBJ; sparse
/// "index dx dy dz" target lines; JSON skeleton and weights); MakeHuman's program code is not.
///
/// Frames and units: the files are in decimetres, +Y up, the body faces +Z, subject's left +X,
/// A-pose. Everything this header returns keeps the file's values (decimetres) except where a
/// contract says metres (skin_vertices()).
#pragma once

#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"

namespace modelgen::mh {

/// Thrown for every MakeHuman file and format problem; the message names the file, the line or
/// key, and what was expected.
class AssetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Metres per file unit (MakeHuman works in decimetres).
constexpr double kMetresPerUnit = 0.1;

/// Row-major N x 3 positions in file units (decimetres).
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// Row-major N x 2 texture coordinates (u right, v up, as in OBJ).
using TexCoords = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// One polygon of the base mesh: 3 or 4 corners, 0-based vertex and texture-coordinate indices
/// (texcoord -1 when the face has none), and the index of its `g` group in BaseMesh::groups.
struct ObjFace {
  std::array<int, 4> v{{-1, -1, -1, -1}};
  std::array<int, 4> vt{{-1, -1, -1, -1}};
  int corners = 0;
  int group = -1;
};

/// The base mesh as stored: every vertex (skin, helpers and joint cubes), every texture
/// coordinate, every face with its group.
struct BaseMesh {
  Positions vertices;               ///< N x 3, decimetres (N = 19,158 for hm08)
  TexCoords uvs;                    ///< T x 2
  std::vector<ObjFace> faces;       ///< in file order
  std::vector<std::string> groups;  ///< distinct `g` names in order of first use
};

/// Reads an OBJ file with `v`, `vt`, `g` and `f` lines (faces of 3 or 4 corners written as
/// `v`, `v/vt`, `v//vn` or `v/vt/vn`; negative indices are not used by MakeHuman and are
/// rejected). Other lines are ignored. Throws AssetError naming the file and line for a missing
/// file, a malformed number, a face with fewer than 3 or more than 4 corners, or an index out of
/// range.
BaseMesh read_base_mesh(const std::string& path);

/// A sparse target: offsets (decimetres) of some vertices of the base mesh.
struct Target {
  std::vector<int> index;              ///< 0-based base-mesh vertex ids, in file order
  std::vector<Eigen::Vector3d> delta;  ///< same length as index
};

/// Reads a `.target` file: `#` comment lines and `index dx dy dz` lines. Throws AssetError
/// naming the file and line for a malformed line or an index outside [0, num_vertices).
Target read_target(const std::string& path, int num_vertices);

/// Adds `weight` times `target` to `positions` (N x 3 decimetres), in the file's line order.
void add_target(const Target& target, double weight, Positions& positions);

/// One bone of a MakeHuman skeleton: joint names (keys of Skeleton::joints) of its head and
/// tail, and its parent ("" for the root).
struct Bone {
  std::string name;
  std::string parent;
  std::string head;
  std::string tail;
};

/// A MakeHuman `.mhskel` skeleton.
struct Skeleton {
  std::vector<Bone> bones;                         ///< sorted so that parents precede children
  std::map<std::string, std::vector<int>> joints;  ///< joint name -> base-mesh vertex ids
  /// Index of the bone named `name` in `bones`; throws AssetError if there is none.
  int bone(const std::string& name) const;
};

/// Reads a `.mhskel` file (JSON: `bones` {name: {head, tail, parent}}, `joints` {name: [ids]}).
/// Throws AssetError for a missing file, invalid JSON, a missing key, an unknown parent or joint,
/// a parent cycle, or a vertex id outside [0, num_vertices).
Skeleton read_skeleton(const std::string& path, int num_vertices);

/// Joint position (decimetres): the mean of its vertex group in `positions`.
Eigen::Vector3d joint_position(const Skeleton& skeleton, const std::string& joint,
                               const Positions& positions);

/// Skinning weights per bone: (base-mesh vertex, weight) pairs, in file order.
using BoneWeights = std::map<std::string, std::vector<std::pair<int, double>>>;

/// Reads a `.mhw` file (JSON: `weights` {bone: [[vertex, weight], ...]}). Throws AssetError for a
/// missing file, invalid JSON, a missing key, a vertex outside [0, num_vertices) or a weight that
/// is negative or not finite.
BoneWeights read_weights(const std::string& path, int num_vertices);

/// The skin of the base mesh as a triangle mesh: the faces of group `body` only (no eyes, teeth,
/// tongue, eyelashes, hair, clothing or genital helpers, no joint cubes), re-indexed to the
/// vertices they use, each quad split along its shorter diagonal on the base mesh (so every body
/// made from the same base has the same triangles). Texture coordinates are kept per corner:
/// `uv_faces` indexes `uvs` as `faces` indexes the vertices (seams are where one vertex has
/// several texture coordinates; an exporter splits vertices there).
struct SkinMesh {
  std::vector<int> source_vertex;  ///< V: skin vertex -> base-mesh vertex, increasing
  std::vector<int> skin_vertex;    ///< N: base-mesh vertex -> skin vertex, or -1
  smpl::Faces faces;               ///< F x 3, counter-clockwise seen from outside
  smpl::Faces uv_faces;            ///< F x 3 indices into uvs
  TexCoords uvs;                   ///< T x 2, the texture coordinates the skin uses
  /// V: the skin vertex at the left/right mirror image (x -> -x) of each skin vertex on the base
  /// mesh (an involution; the vertices on the midline are their own image).
  std::vector<int> mirror;
};

/// Builds the skin mesh from `base`. Throws AssetError if there is no `body` group, a body
/// face has no texture coordinates or the skin is not exactly left/right symmetric on the base
/// mesh (MakeHuman's is: every skin vertex's mirror image is a skin vertex).
SkinMesh skin_mesh(const BaseMesh& base);

/// Skin vertex positions in metres (V x 3) taken from base-mesh `positions` (decimetres).
smpl::Vertices skin_vertices(const SkinMesh& skin, const Positions& positions);

/// Makes `v` (V x 3, or a V x 3 offset such as a shape component) exactly left/right symmetric
/// under `mirror`: each vertex and its mirror vertex get the mean of their positions with x
/// reflected (x = 0 on the midline). Removes the micrometre asymmetries that the T-pose bake and
/// the fitted targets leave, so that mirrored landmarks and measurements agree to rounding.
void symmetrize(Eigen::Ref<smpl::Vertices> v, const std::vector<int>& mirror);

}  // namespace modelgen::mh
