// `caliper create`: measurements with units in, an avatar file and a report out.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "caliper/errors.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "export_options.hpp"
#include "inputs.hpp"
#include "mesh_io.hpp"
#include "render_bridge.hpp"
#include "report.hpp"

namespace caliper::cli {

namespace {

struct InputOption {
  const char* option;
  const char* id;
  bool mass;
};
constexpr InputOption kInputOptions[] = {
    {"height", "height", false},
    {"weight", "weight", true},
    {"arm-span", "arm_span_fingertips", false},
    {"inseam", "inseam_height", false},
    {"hip-width", "hip_width", false},
    {"arm-length", "arm_length", false},
};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

const std::vector<OptionSpec>& measurement_options() {
  static const std::vector<OptionSpec> specs = {
      {"height", "", "LENGTH", "overall height, e.g. 168cm, 1.68m, 66in, 5ft6in", false},
      {"weight", "", "MASS", "body weight, e.g. 62kg or 137lb", false},
      {"arm-span", "", "LENGTH", "arm span, fingertip to fingertip", false},
      {"inseam", "", "LENGTH", "inseam height (crotch above the floor)", false},
      {"hip-width", "", "LENGTH", "hip width (widest, at the trochanters)", false},
      {"arm-length", "", "LENGTH", "arm length, shoulder (acromion) to wrist", false},
  };
  return specs;
}

std::string option_of(const std::string& id) {
  for (const auto& o : kInputOptions)
    if (id == o.id) return std::string("--") + o.option;
  return id;
}

MeasurementMap read_measurement_options(const ParsedArgs& args) {
  MeasurementMap m;
  for (const auto& o : kInputOptions) {
    if (auto v = args.get(o.option)) {
      const std::string what = std::string("--") + o.option;
      m[o.id] = o.mass ? parse_mass(*v, what) : parse_length(*v, what);
    }
  }
  return m;
}

std::vector<std::string> check_inputs(const MeasurementMap& inputs, bool force) {
  std::vector<std::string> warnings;
  std::vector<std::string> errors;
  for (const auto& msg : validate_measurements(inputs)) {
    if (msg.severity == Severity::Error && !force) {
      errors.push_back(msg.message);
    } else {
      warnings.push_back(msg.message);
    }
  }
  if (!errors.empty()) {
    std::string all = errors.size() == 1 ? "implausible input: " : "implausible inputs: ";
    for (size_t i = 0; i < errors.size(); ++i) all += (i ? "; " : "") + errors[i];
    throw ImplausibleInput(all);
  }
  return warnings;
}

void require_inputs(const std::string& regressor, const MeasurementMap& inputs) {
  const auto kind = parse_regressor_kind(regressor);
  if (!kind) {
    if (inputs.empty())
      throw UsageError("no measurements given; give at least --height (and usually --weight)");
    return;
  }
  std::string missing;
  for (const auto& id : regressor_inputs(*kind)) {
    if (!inputs.count(id)) missing += (missing.empty() ? "" : ", ") + option_of(id);
  }
  if (!missing.empty()) {
    throw UsageError("regressor " + regressor + " needs " + missing +
                     " (or choose --regressor noise-aware, which takes any subset)");
  }
}

Avatar make_avatar(const ModelBundle& bundle, const std::string& regressor,
                   const MeasurementMap& inputs, const MeasurementMapping* mapping,
                   bool circumferences, bool exact_inputs, bool check_model) {
  AvatarOptions o;
  o.check_model = check_model;
  o.exact_inputs = exact_inputs;
  o.mapping = mapping;
  o.circumferences = circumferences;
  o.refuse_invalid = false;  // validation and --force are handled by check_inputs()
  if (regressor == "noise-aware") {
    if (!bundle.regressors.noise_aware) {
      throw RuntimeError(
          "the regressor set has no noise-aware regressor; retrain with "
          "caliper train --save FILE");
    }
    return create_avatar(bundle.model, *bundle.regressors.noise_aware, inputs, o);
  }
  const LinearRegressor* r = bundle.regressors.find(regressor);
  if (!r) throw RuntimeError("the regressor set has no regressor " + regressor);
  return create_avatar(bundle.model, *r, inputs, o);
}

MeasurementMapping load_mapping(const std::string& path) {
  if (!file_exists(path)) throw RuntimeError(path + ": mapping file not found");
  try {
    if (extension_of(path) == ".csv") return MeasurementMapping::fit(read_paired_csv(path));
    return MeasurementMapping::load(path);
  } catch (const std::exception& e) {
    const std::string what = e.what();
    throw RuntimeError(what.find(path) == std::string::npos ? path + ": " + what : what);
  }
}

int cmd_create(const std::vector<std::string>& args, Io& io) {
  std::vector<OptionSpec> specs = measurement_options();
  const std::vector<OptionSpec> more = {
      {"sex", "s", "SEX", "female, male or neutral (default neutral): picks the open model", false},
      {"regressor", "r", "NAME", "R2, R4, R5, R6 or noise-aware (default: see below)", false},
      {"model", "m", "FILE", "any SMPL-family model file (.npz/.pkl) instead of the open model",
       false},
      {"regressors", "", "FILE", "regressors saved by `caliper train --save` (else trained now)",
       false},
      {"mapping", "", "FILE", "real-to-virtual mapping (.json from training, or paired .csv)",
       false},
      {"out", "o", "FILE", "write the avatar: .glb, .gltf, .vrm, .fbx, .obj or .ply", false},
      {"png", "", "FILE", "render the avatar to a PNG (three-quarter view)", false},
      {"json", "", "", "print a machine-readable JSON report instead of the text report", false},
      {"exact-inputs", "", "",
       "refine R2-R6 betas so that every input (weight too) is reproduced exactly", false},
      {"force", "", "", "create the avatar even when an input is outside the hard limits", false},
      {"quiet", "q", "", "print nothing but errors and warnings", false},
  };
  specs.insert(specs.end(), more.begin(), more.end());
  specs.insert(specs.end(), export_option_specs().begin(), export_option_specs().end());
  const ParsedArgs a = parse_args(args, specs);
  if (a.flags.count("help")) {
    io.out << "usage: caliper create --height LENGTH [--weight MASS] [more measurements] "
              "[options]\n\n"
              "Creates an avatar from body measurements (units are required) and prints input\n"
              "vs achieved measurements, the betas and their plausibility.\n\n"
           << format_options(specs)
           << "\ndefault regressor: exactly the inputs of R2 (height, weight), R4 (+ arm span, "
              "inseam)\nor R5 (+ hip width) -> that regressor; all six inputs or any other "
              "subset ->\nnoise-aware (R6 reproduces every input but amplifies measurement "
              "noise).\n\nformats (by the --out extension): .glb/.gltf (rigged glTF 2.0), .vrm "
              "(VRM 1.0),\n.fbx (rigged, metres), .obj/.ply (mesh); every file records the "
              "model, sex, betas\nand measurements, which `caliper measure` reads back; all but "
              ".ply keep the model's\ntexture coordinates when it has them.\n\n"
              "examples:\n  caliper create --sex female --height 168cm --weight 62kg "
              "--out avatar.glb --png avatar.png\n  caliper create --sex male --height 181cm "
              "--weight 84kg --out me.glb --shape-keys 10\n  caliper create --sex male --height "
              "181cm --weight 84kg --out me.fbx --bone-names smpl --pose apose.json\n";
    return kExitOk;
  }
  if (!a.positional.empty())
    throw UsageError("unexpected argument '" + a.positional[0] +
                     "' (measurements are options, "
                     "e.g. --height 168cm)");
  const auto t_start = std::chrono::steady_clock::now();
  const MeasurementMap inputs = read_measurement_options(a);
  const std::string sex = a.get("sex") ? normalise_sex(*a.get("sex")) : "neutral";
  const std::string regressor = a.get("regressor") ? normalise_regressor_name(*a.get("regressor"))
                                                   : default_regressor(inputs);
  require_inputs(regressor, inputs);
  if (auto out = a.get("out"); out && !is_avatar_extension(*out))
    throw UsageError("--out " + *out + ": use a " + avatar_extensions_text() + " file name");
  if (!a.get("out")) {
    for (const auto& spec : export_option_specs()) {
      if (a.has(spec.name)) throw UsageError("--" + spec.name + " needs --out FILE");
    }
  }
  if (auto png = a.get("png"); png && extension_of(*png) != ".png")
    throw UsageError("--png " + *png + ": the file name must end in .png");
  std::vector<std::string> warnings = check_inputs(inputs, a.flags.count("force") > 0);
  for (const auto& w : warnings) io.err << "caliper: warning: " << w << "\n";

  const auto bundle = load_bundle(resolve_model_path(a.get("model"), sex), a.get("regressors"));
  if (!a.get("model") && !bundle->model.meta.gender.empty() && bundle->model.meta.gender != sex)
    io.err << "caliper: warning: the model's gender is " << bundle->model.meta.gender << "\n";
  std::optional<MeasurementMapping> mapping;
  if (auto m = a.get("mapping")) mapping = load_mapping(*m);
  // Export options are checked before the avatar is made, so a bad option costs no work.
  smpl::ExportOptions export_options;
  if (auto out = a.get("out")) export_options = read_export_options(a, *out, bundle->model);

  const auto t_create = std::chrono::steady_clock::now();
  const Avatar avatar = make_avatar(*bundle, regressor, inputs, mapping ? &*mapping : nullptr, true,
                                    a.flags.count("exact-inputs") > 0);
  const double create_s = seconds_since(t_create);
  if (!avatar.plausibility.plausible) {
    const std::string w =
        "unusual body shape: the avatar is outside the usual range (Mahalanobis distance " +
        format_number(avatar.plausibility.mahalanobis, 2) + ", " +
        std::to_string(avatar.plausibility.beyond_3sd.size()) +
        " components beyond 3 SD): check the measurements" +
        (regressor == "noise-aware" ? "" : " or try --regressor noise-aware");
    warnings.push_back(w);
    io.err << "caliper: warning: " << w << "\n";
  }

  const auto t_write = std::chrono::steady_clock::now();
  std::vector<std::string> written;
  if (auto out = a.get("out")) {
    std::map<std::string, std::string>& extras = export_options.extras;
    extras["generator"] = version_string();
    extras["regressor"] = regressor;
    extras["betas"] = betas_json(avatar.betas).dump();
    extras["measurements"] = measurements_json(avatar.achieved).dump();
    // Which model made the avatar, so that `caliper measure` picks it (and its weight formula)
    // without being told: the model's name, and for an open default model its sex.
    extras["model"] = bundle->model.meta.name;
    if (!a.get("model")) extras["open_model_sex"] = sex;
    if (export_options.pose.size() > 0)
      extras["pose"] =
          Json(std::vector<double>(export_options.pose.data(),
                                   export_options.pose.data() + export_options.pose.size()))
              .dump();
    write_avatar(*out, bundle->model, avatar.betas, export_options);
    written.push_back(*out);
  }
  const double write_s = seconds_since(t_write);
  if (auto png = a.get("png")) {
    render_png(avatar.vertices, bundle->model.faces, *png, "three_quarter", 600, 800);
    written.push_back(*png);
  }
  const double total_s = seconds_since(t_start);
  if (!a.get("out")) {
    io.err << "caliper create: no avatar file written (add --out avatar.glb, or .gltf, .obj, "
              ".ply, to write one)\n";
  }

  if (a.flags.count("json")) {
    Json j = Json::object();
    j.set("command", "create");
    j.set("version", version_string());
    Json model = Json::object();
    model.set("path", bundle->path);
    model.set("name", bundle->model.meta.name);
    model.set("gender", bundle->model.meta.gender);
    model.set("vertices", bundle->model.num_vertices());
    model.set("betas", bundle->model.num_betas());
    j.set("model", model);
    j.set("regressor", regressor);
    j.set("units",
          json_object({{"length", Json("m")}, {"weight", Json("kg")}, {"volume", Json("m3")}}));
    j.set("input", measurements_json(avatar.input));
    if (mapping) j.set("mapped_input", measurements_json(avatar.mapped));
    j.set("achieved", measurements_json(avatar.achieved));
    Json diff = Json::object();
    for (const auto& [id, v] : avatar.mapped) {
      auto it = avatar.achieved.find(id);
      if (it != avatar.achieved.end()) diff.set(id, it->second - v);
    }
    j.set("difference", diff);
    j.set("betas", betas_json(avatar.betas));
    if (avatar.covariance) {
      const Eigen::VectorXd sd = avatar.covariance->diagonal().cwiseSqrt();
      j.set("betas_sd", betas_json(sd));
    }
    j.set("plausibility", plausibility_json(avatar.plausibility));
    Json w = Json::array();
    for (const auto& s : warnings) w.push_back(s);
    j.set("warnings", w);
    Json files = Json::array();
    for (const auto& s : written) files.push_back(s);
    j.set("written", files);
    j.set("timing_seconds", json_object({{"load_model", Json(bundle->load_seconds)},
                                         {"train_regressors", Json(bundle->train_seconds)},
                                         {"create", Json(create_s)},
                                         {"write_avatar", Json(write_s)},
                                         {"total", Json(total_s)}}));
    io.out << j.dump(2) << "\n";
    return kExitOk;
  }
  if (a.flags.count("quiet")) return kExitOk;
  io.out << "model: " << (bundle->model.meta.name.empty() ? "(unnamed)" : bundle->model.meta.name)
         << " (" << (bundle->model.meta.gender.empty() ? "?" : bundle->model.meta.gender) << ", "
         << bundle->path << ")\n"
         << "regressor: " << regressor;
  if (mapping) io.out << " with mapping " << *a.get("mapping") << " (input column: mapped values)";
  // Inputs typed in imperial units get the report in inches and pounds too.
  bool imperial = false;
  for (const auto& o : kInputOptions) {
    if (auto v = a.get(o.option)) imperial = imperial || is_imperial_text(*v);
  }
  io.out << "\n\n"
         << measurement_table(mapping ? avatar.mapped : avatar.input, avatar.achieved, imperial);
  io.out << "\nbetas: " << format_betas(avatar.betas) << "\n";
  if (avatar.covariance) {
    io.out << "betas posterior SD: "
           << format_betas(avatar.covariance->diagonal().cwiseSqrt().eval()) << "\n";
  }
  io.out << "plausibility: " << format_plausibility(avatar.plausibility);
  for (const auto& f : written) io.out << "wrote " << f << "\n";
  std::ostringstream t;
  t << std::fixed << std::setprecision(1) << "time: load model " << bundle->load_seconds * 1e3
    << " ms, train regressors " << bundle->train_seconds * 1e3 << " ms, create " << create_s * 1e3
    << " ms, write " << write_s * 1e3 << " ms, total " << total_s * 1e3 << " ms\n";
  io.out << t.str();
  return kExitOk;
}

}  // namespace caliper::cli
