// export_avatar(): the writer for a file's extension, and the list of formats.
#include "smpl/avatar_export.hpp"

#include <algorithm>
#include <cctype>

#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"
#include "smpl/text.hpp"

namespace smpl {

const std::vector<ExportFormat>& export_formats() {
  static const std::vector<ExportFormat> formats = {
      {".glb", "glTF 2.0 binary: rigged, skinned (Blender, three.js, Unity with glTFast)", true},
      {".gltf", "glTF 2.0 JSON with an embedded buffer: rigged, skinned", true},
      {".vrm", "VRM 1.0: glTF with a humanoid bone map and licence (VR platforms, VTubing)", true},
      {".fbx", "FBX 7.5 binary: rigged, skinned, metres (Unity, Unreal, Maya, Blender)", true},
      {".obj", "Wavefront OBJ: mesh with normals (UVs when the model has them)", false},
      {".ply", "PLY binary: mesh with normals", false},
  };
  return formats;
}

const ExportFormat* export_format_of(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find_first_of("/\\", dot) != std::string::npos) {
    return nullptr;
  }
  const std::string ext = to_lower(path.substr(dot));
  for (const auto& f : export_formats()) {
    if (f.extension == ext) return &f;
  }
  return nullptr;
}

void export_avatar(const std::string& path, const BodyModel& model,
                   const Eigen::Ref<const Eigen::VectorXd>& betas, const ExportOptions& options) {
  const ExportFormat* format = export_format_of(path);
  if (!format) {
    std::string known;
    for (const auto& f : export_formats()) known += (known.empty() ? "" : ", ") + f.extension;
    throw ModelError(path + ": unknown avatar file extension; use one of " + known);
  }
  const std::string& ext = format->extension;
  if (ext == ".glb" || ext == ".gltf") {
    write_gltf(path, model, betas, options);
  } else if (ext == ".vrm") {
    write_vrm(path, model, betas, options);
  } else if (ext == ".fbx") {
    write_fbx(path, model, betas, options);
  } else {
    write_mesh_avatar(path, model, betas, options);
  }
}

}  // namespace smpl
