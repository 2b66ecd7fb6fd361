/// \file fbx.hpp
/// FBX export of a rigged, skinned avatar through Assimp (target smpl::fbx, the only code that
/// includes Assimp's headers), and FBX read-back for tests and `caliper measure`.
/// Binary FBX 7.5: one skinned mesh (control points, per-vertex normals, triangles; UV channel 0
/// per polygon corner when the model has texture coordinates), one LimbNode per joint (named by
/// options.bone_names, translated relative to its parent, rotated by options.pose), a Skin deformer
/// with one Cluster per joint holding every non-zero skinning weight (no 4-influence limit) and the
/// exported pose as the bind pose (the rest pose, or options.pose baked into mesh and skeleton: an
/// A-pose export is bound in the A-pose, as Assimp's writer takes the bind matrices from the
/// nodes). Units: metres, with GlobalSettings UnitScaleFactor = 100 (centimetres per file unit)
/// recorded so that Unity, Blender and the FBX SDK scale it right; axes: +Y up, front +Z, as glTF.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"
#include "smpl/export.hpp"

namespace smpl {

/// Writes `path` (.fbx, binary FBX 7.5) atomically. A model with texture coordinates is split at
/// its seams for Assimp (split_at_seams(), export.hpp; every copy has its vertex's position,
/// normal and weights); Assimp's writer welds the copies back into one control point per
/// position and writes the texture coordinates per polygon corner (LayerElementUV,
/// v up). Without texture coordinates the mesh is the model's. options: stand_on_floor, name,
/// extras (user string properties, "KString" with flag "U", of the mesh's Model node), pose,
/// bone_names; shape_keys, pose_correctives, up and the VRM fields are ignored. Throws ModelError
/// naming the file and the problem (Assimp's message included).
void write_fbx(const std::string& path, const BodyModel& model,
               const Eigen::Ref<const Eigen::VectorXd>& betas, const ExportOptions& options = {});

/// The same file as bytes in memory.
std::vector<std::uint8_t> fbx_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const ExportOptions& options = {});

/// What read_fbx() gives back (Assimp's import with identical vertices joined).
struct FbxAvatar {
  Vertices vertices;  ///< file units (metres for our files), in Assimp's order (not the model's).
  Faces faces;        ///< triangles in the file's polygon order.
  Vertices normals;   ///< per vertex, as `vertices`; 0 rows when the file has no normals.
  /// Texture coordinates (channel 0) per vertex, as `vertices`, in Assimp's convention (v up, as
  /// OBJ and the model; Assimp turns glTF's v back); 0 rows when the file has none.
  TexCoords uvs;
  /// Bone names and, per vertex, the sum of its weights over all bones (1 for a clean skin).
  std::vector<std::string> bone_names;
  Eigen::VectorXd weight_sums;
  /// Bind-pose joint positions (in bone_names order): the inverse of each bone's offset matrix,
  /// translation part.
  Joints bind_joints;
  double unit_scale_factor = 1.0;  ///< GlobalSettings UnitScaleFactor (cm per unit; 100 = metres)
  /// String metadata of the node holding the mesh (our files: ExportOptions::extras).
  std::map<std::string, std::string> metadata;
};

/// Reads an FBX file with Assimp. Throws ModelError naming the file (Assimp's message included)
/// when it cannot be read or has no mesh.
FbxAvatar read_fbx(const std::string& path);

/// Reads the first mesh of any file Assimp reads (OBJ, glTF/GLB, FBX, PLY, ...; by extension and
/// content) as read_fbx() does: an independent reader to check the project's own exports (tests).
/// Throws ModelError naming the file when Assimp cannot read it or it has no mesh.
FbxAvatar read_with_assimp(const std::string& path);

/// Rewrites binary FBX bytes with a null record closing every node that has children, and a
/// footer padded as the FBX SDK pads it. Assimp 5.2 (Debian 12) writes its binary FBX without
/// these nested null records (fixed upstream in Assimp 5.3, assimp PR 4824); Blender, the FBX
/// SDK and Assimp's own reader refuse such files. Bytes that already have them come out the same
/// (apart from the footer padding). Throws ModelError when `bytes` is not binary FBX 7.x.
std::string fix_fbx_null_records(const std::string& bytes);

}  // namespace smpl
