// `caliper models`: lists the open default models and describes any given model file.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <ostream>

#include "caliper/assets.hpp"
#include "caliper/measurements.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "smpl/io.hpp"

namespace caliper::cli {

namespace {
const app::HelpText kModelsHelp{
    {"caliper models [FILE...] [--json]"},
    "Lists the open default models (assets/models/) and describes the given model\n"
    "files: name, gender, vertices, joints, betas, landmarks present.",
    "example:\n  caliper models ~/smpl/SMPL_FEMALE.npz"};
}  // namespace

namespace {

Json describe(const std::string& path, const smpl::BodyModel& m) {
  Json j = Json::object();
  j.set("path", path);
  j.set("name", m.meta.name);
  j.set("gender", m.meta.gender);
  j.set("vertices", m.num_vertices());
  j.set("faces", m.num_faces());
  j.set("joints", m.num_joints());
  j.set("betas", m.num_betas());
  j.set("pose_blend_shapes", m.has_pose_blend_shapes());
  const LandmarkTable table = landmarks_for(m);
  Json present = Json::array(), missing = Json::array();
  for (const auto& n : landmark_names()) {
    if (table.count(n)) {
      present.push_back(n);
    } else {
      missing.push_back(n);
    }
  }
  j.set("landmarks_present", present);
  j.set("landmarks_missing", missing);
  Json meas = Json::array();
  for (const auto& d : available_measurements(table)) meas.push_back(d.id);
  j.set("measurements", meas);
  return j;
}

}  // namespace

int cmd_models(const std::vector<std::string>& args, Io& io) {
  const std::vector<OptionSpec> specs = {
      {"json", "", "", "print JSON", false},
  };
  const std::optional<ParsedArgs> parsed = parse_args_or_help(args, specs, kModelsHelp, io.out);
  if (!parsed) return kExitOk;
  const ParsedArgs& a = *parsed;
  std::vector<std::string> paths;
  const auto assets = find_assets_dir();
  std::string note;
  if (assets) {
    const std::filesystem::path dir = std::filesystem::path(*assets) / "models";
    for (const char* sex : {"female", "male", "neutral"}) {
      const std::string p = default_model_path(dir.string(), sex);
      if (file_exists(p)) {
        paths.push_back(p);
      } else {
        note += "open model not found: " + p + "\n";
      }
    }
  } else {
    note = "no assets folder found (tried " + tried_assets_dirs() +
           "; set CALIPER_ASSETS or pass model files)\n";
  }
  for (const auto& p : a.positional) {
    if (!file_exists(p)) throw RuntimeError(p + ": model file not found");
    paths.push_back(p);
  }
  Json all = Json::array();
  for (const auto& p : paths) all.push_back(describe(p, smpl::load_model(p)));
  if (a.flags.count("json")) {
    Json j = Json::object();
    j.set("command", "models");
    j.set("assets", assets ? Json(*assets) : Json());
    j.set("models", all);
    io.out << j.dump(2) << "\n";
    return kExitOk;
  }
  if (!note.empty()) io.err << note;
  for (size_t i = 0; i < all.size(); ++i) {
    const Json& m = all[i];
    io.out << m.at("path").as_string() << "\n"
           << "  name: " << m.at("name").as_string() << "\n"
           << "  gender: " << m.at("gender").as_string() << "\n"
           << "  vertices: " << m.at("vertices").as_int() << ", faces: " << m.at("faces").as_int()
           << ", joints: " << m.at("joints").as_int() << ", betas: " << m.at("betas").as_int()
           << ", pose blend shapes: " << (m.at("pose_blend_shapes").as_bool() ? "yes" : "no")
           << "\n  landmarks: " << m.at("landmarks_present").size() << " of "
           << landmark_names().size() << " present";
    if (m.at("landmarks_missing").size() > 0) {
      io.out << " (missing:";
      for (size_t k = 0; k < m.at("landmarks_missing").size(); ++k)
        io.out << " " << m.at("landmarks_missing")[k].as_string();
      io.out << ")";
    }
    io.out << "\n  measurements: " << m.at("measurements").size() << " of "
           << paper_measurements().size() << " available\n";
  }
  if (all.size() == 0) io.out << "no models found\n";
  return kExitOk;
}

}  // namespace caliper::cli
