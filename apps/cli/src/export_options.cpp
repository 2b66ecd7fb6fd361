#include "export_options.hpp"

#include <cmath>

#include "caliper/json.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/npz.hpp"

namespace caliper::cli {

const std::vector<OptionSpec>& export_option_specs() {
  static const std::vector<OptionSpec> specs = {
      {"shape-keys", "", "N",
       "glTF/VRM: morph targets beta_00.. for the first N shape components (default 0)", false},
      {"bone-names", "", "NAMES",
       "smplx (default: pelvis, left_hip, ...) or smpl (m_avg_Pelvis, m_avg_L_Hip, ...)", false},
      {"pose", "", "FILE", "pose the avatar: 72 SMPL axis-angle numbers (.json or .npy)", false},
      {"up", "", "AXIS", "OBJ/PLY: y (default) or z (+Z up, facing -Y: Blender, PLY tools)", false},
      {"licence", "", "TEXT",
       "VRM: the body model's licence (URL or name) when --model is your own file", false},
  };
  return specs;
}

Eigen::VectorXd read_pose_file(const std::string& path, int num_joints) {
  if (!file_exists(path)) throw RuntimeError(path + ": pose file not found");
  const size_t n = 3 * static_cast<size_t>(num_joints);
  std::vector<double> values;
  if (extension_of(path) == ".npy") {
    try {
      values = smpl::read_npy(path).to_double();
    } catch (const std::exception& e) {
      throw RuntimeError(std::string(e.what()));
    }
  } else {
    Json j;
    try {
      j = read_json_file(path);
    } catch (const std::exception& e) {
      throw RuntimeError(std::string(e.what()) + " (a pose file is .npy or JSON)");
    }
    if (j.is_object()) {
      const Json* p = j.find("pose");
      if (!p) throw RuntimeError(path + ": the JSON object has no \"pose\" member");
      j = *p;
    }
    if (!j.is_array()) throw RuntimeError(path + ": the pose must be a JSON array of numbers");
    for (size_t i = 0; i < j.size(); ++i) {
      const Json& e = j[i];
      if (e.is_number()) {
        values.push_back(e.as_number());
      } else if (e.is_array() && e.size() == 3) {
        for (size_t c = 0; c < 3; ++c) {
          if (!e[c].is_number())
            throw RuntimeError(path + ": pose entry " + std::to_string(i) +
                               " is not three numbers");
          values.push_back(e[c].as_number());
        }
      } else {
        throw RuntimeError(path + ": pose entry " + std::to_string(i) +
                           " is neither a number nor an [x, y, z] triple");
      }
    }
  }
  if (values.size() != n) {
    throw RuntimeError(path + ": the pose has " + std::to_string(values.size()) +
                       " numbers; the model's " + std::to_string(num_joints) + " joints need " +
                       std::to_string(n) + " (axis-angle radians, joint 0 = global orientation)");
  }
  for (double v : values) {
    if (!std::isfinite(v)) throw RuntimeError(path + ": the pose contains NaN or infinity");
  }
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(n));
}

smpl::ExportOptions read_export_options(const ParsedArgs& args, const std::string& out,
                                        const smpl::BodyModel& model) {
  smpl::ExportOptions o;
  const smpl::ExportFormat* format = smpl::export_format_of(out);
  const std::string ext = format ? format->extension : extension_of(out);
  const bool gltf_like = ext == ".glb" || ext == ".gltf" || ext == ".vrm";
  if (auto v = args.get("shape-keys")) {
    if (!gltf_like) throw UsageError("--shape-keys: only .glb, .gltf and .vrm have shape keys");
    char* end = nullptr;
    const long n = std::strtol(v->c_str(), &end, 10);
    if (v->empty() || *end != '\0' || n < 0 || n > model.num_betas()) {
      throw UsageError("--shape-keys " + *v + ": expected a whole number from 0 to " +
                       std::to_string(model.num_betas()) + " (the model's shape components)");
    }
    o.shape_keys = static_cast<int>(n);
  }
  if (auto v = args.get("bone-names")) {
    if (*v == "smpl") {
      o.bone_names = smpl::BoneNames::Smpl;
    } else if (*v != "smplx") {
      throw UsageError("--bone-names " + *v + ": expected smpl (m_avg_Pelvis, ...) or smplx " +
                       "(pelvis, left_hip, ...)");
    }
    if (format && !format->rigged) {
      throw UsageError("--bone-names: " + ext + " files have no skeleton");
    }
  }
  if (auto v = args.get("up")) {
    if (*v == "z" || *v == "Z") {
      o.up = smpl::UpAxis::Z;
    } else if (*v != "y" && *v != "Y") {
      throw UsageError("--up " + *v + ": expected y or z");
    }
    if (ext != ".obj" && ext != ".ply") {
      throw UsageError("--up applies to .obj and .ply (" + ext +
                       " has its own axis convention: +Y up, facing +Z)");
    }
  }
  if (auto v = args.get("pose")) {
    if (ext == ".vrm") {
      throw UsageError("--pose: a VRM's rest must be the T-pose; export .glb or .fbx for a pose");
    }
    o.pose = read_pose_file(*v, model.num_joints());
  }
  if (auto v = args.get("licence")) {
    if (ext != ".vrm") throw UsageError("--licence applies to .vrm files");
    o.licence = *v;
  }
  return o;
}

}  // namespace caliper::cli
