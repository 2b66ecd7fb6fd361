// `caliper create`: measurements with units in, an avatar file and a report out.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "caliper/errors.hpp"
#include "caliper/mapping.hpp"
#include "caliper/population.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "export_options.hpp"
#include "inputs.hpp"
#include "mesh_io.hpp"
#include "render_bridge.hpp"
#include "report.hpp"

namespace caliper::cli {

namespace {
const app::HelpText kCreateHelp{
    {"caliper create --height LENGTH [--weight MASS] [more measurements] [options]"},
    "Creates an avatar from body measurements (units are required) and prints input\n"
    "vs achieved measurements, the betas and their plausibility.",
    "default regressor: exactly the inputs of R2 (height, weight), R4 (+ arm span, inseam)\n"
    "or R5 (+ hip width) -> that regressor; all six inputs or any other subset ->\n"
    "noise-aware (R6 reproduces every input but amplifies measurement noise).\n\n"
    "formats (by the --out extension): .glb/.gltf (rigged glTF 2.0), .vrm (VRM 1.0),\n"
    ".fbx (rigged, metres), .obj/.ply (mesh); every file records the model, sex, betas\n"
    "and measurements, which `caliper measure` reads back; all but .ply keep the model's\n"
    "texture coordinates when it has them.\n\n"
    "arm length: --arm-length is the paper's, taken with the arm out sideways; a tape on the\n"
    "relaxed hanging arm (shoulder tip over the elbow to the wrist) gives --arm-length-hanging,\n"
    "which the model's own map turns into its arm length (the report shows both).\n\n"
    "examples:\n"
    "  caliper create --sex female --height 168cm --weight 62kg --out avatar.glb --png avatar.png\n"
    "  caliper create --sex male --height 181cm --weight 84kg --out me.glb --shape-keys 10\n"
    "  caliper create --sex female --height 165cm --weight 64kg --population ansur2\n"
    "  caliper create --sex male --height 181cm --weight 84kg --out me.fbx --bone-names smpl "
    "--pose apose.json"};
}  // namespace

namespace {

/// The six measurement inputs: option, measurement id, whether the value is a mass (else a
/// length) and the option's help line.
struct InputOption {
  const char* option;
  const char* id;
  bool mass;
  const char* help;
};
constexpr InputOption kInputOptions[] = {
    {"height", "height", false, "overall height, e.g. 168cm, 1.68m, 66in, 5ft6in"},
    {"weight", "weight", true, "body weight, e.g. 62kg or 137lb"},
    {"arm-span", "arm_span_fingertips", false, "arm span, fingertip to fingertip"},
    {"inseam", "inseam_height", false, "inseam height (crotch above the floor)"},
    {"hip-width", "hip_width", false, "hip width (widest, at the trochanters)"},
    {"arm-length", "arm_length", false,
     "arm length, acromion to wrist, arm out sideways (hanging: ~7 cm more)"},
};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

const std::vector<OptionSpec>& measurement_options() {
  static const std::vector<OptionSpec> specs = [] {
    std::vector<OptionSpec> s;
    for (const auto& o : kInputOptions)
      s.push_back({o.option, "", o.mass ? "MASS" : "LENGTH", o.help});
    return s;
  }();
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
  bool forceable = true;
  for (const auto& msg : validate_measurements(inputs)) {
    // A value no body has (not a number, zero or negative) is refused even with --force.
    const auto it = inputs.find(msg.id);
    const bool impossible =
        msg.severity == Severity::Error && it != inputs.end() && !(it->second > 0.0);
    if (msg.severity == Severity::Error && (!force || impossible)) {
      errors.push_back(msg.message);
      forceable = forceable && !impossible;
    } else {
      warnings.push_back(msg.message);
    }
  }
  if (!errors.empty()) {
    std::string all = errors.size() == 1 ? "implausible input: " : "implausible inputs: ";
    for (size_t i = 0; i < errors.size(); ++i) all += (i ? "; " : "") + errors[i];
    throw ImplausibleInput(all, forceable);
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
                   bool circumferences, bool exact_inputs, bool check_model,
                   const ShapePrior* prior) {
  AvatarOptions o;
  o.prior = prior;
  o.check_model = check_model;
  o.exact_inputs = exact_inputs;
  o.shape_curve = bundle.curve.has_value();
  o.mapping = mapping;
  o.circumferences = circumferences;
  o.refuse_invalid = false;  // validation and --force are handled by check_inputs()
  if (bundle.measure_info) o.model_info = &*bundle.measure_info;
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

namespace {

std::vector<OptionSpec> create_options() {
  std::vector<OptionSpec> specs = measurement_options();
  const std::vector<OptionSpec> more = {
      {"arm-length-hanging", "", "LENGTH",
       "instead of --arm-length: a tape on the relaxed hanging arm, shoulder tip (acromion) over "
       "the elbow to the wrist's bony point on the thumb side (ANSUR II's acromion-radiale + "
       "radiale-stylion), mapped onto the model's arm length",
       false},
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
      {"population", "", "NAME",
       "the person is of this population the model carries (ansur2: US Army soldiers, nhanes: "
       "US adults): the noise-aware regressor with its shapes as the prior",
       false},
      {"exact-inputs", "", "",
       "refine the betas so that every input (weight too) is reproduced exactly", false},
      {"no-shape-curve", "", "",
       "plain regressors (R2-R6) as in the paper: from the mean body, not from the general "
       "population's body of the height and weight",
       false},
      {"force", "", "", "create the avatar even when an input is outside the hard limits", false},
      {"quiet", "q", "", "print nothing but errors and warnings", false},
  };
  specs.insert(specs.end(), more.begin(), more.end());
  specs.insert(specs.end(), export_option_specs().begin(), export_option_specs().end());
  return specs;
}

/// Everything `caliper create` is asked to do.
struct CreateOptions {
  ParsedArgs args;  ///< the export options are read once the model is loaded
  MeasurementMap inputs;
  bool imperial = false;  ///< an input was typed in imperial units: report in inches and pounds
  std::string sex = "neutral";
  std::string regressor;
  std::optional<std::string> model, regressors, mapping, out, png, population;
  bool json = false, exact_inputs = false, force = false, quiet = false;
  bool shape_curve = true;  ///< false: --no-shape-curve
  /// inputs' arm_length was given by --arm-length-hanging: map it onto the model's (the value
  /// is judged as measured, then caliper::hanging_arm_map() of the loaded model maps it).
  bool hanging_arm = false;
};

CreateOptions create_options_from(const ParsedArgs& a) {
  if (!a.positional.empty())
    throw UsageError("unexpected argument '" + a.positional[0] +
                     "' (measurements are options, "
                     "e.g. --height 168cm)");
  CreateOptions o;
  o.args = a;
  o.inputs = read_measurement_options(a);
  for (const auto& opt : kInputOptions) {
    if (auto v = a.get(opt.option)) o.imperial = o.imperial || is_imperial_text(*v);
  }
  if (auto v = a.get("arm-length-hanging")) {
    if (o.inputs.count("arm_length")) {
      throw UsageError(
          "give --arm-length (arm out sideways) or --arm-length-hanging (arm hanging), not "
          "both");
    }
    o.inputs["arm_length"] = parse_length(*v, "--arm-length-hanging");
    o.imperial = o.imperial || is_imperial_text(*v);
    o.hanging_arm = true;
  }
  if (a.get("sex")) o.sex = normalise_sex(*a.get("sex"));
  o.regressor = a.get("regressor") ? normalise_regressor_name(*a.get("regressor"))
                                   : default_regressor(o.inputs);
  o.population = a.get("population");
  if (o.population) {
    if (a.get("regressor") && o.regressor != "noise-aware") {
      throw UsageError(
          "--population takes the noise-aware regressor (the population is its "
          "prior); leave out --regressor " +
          o.regressor);
    }
    o.regressor = "noise-aware";
  }
  require_inputs(o.regressor, o.inputs);
  o.out = a.get("out");
  if (o.out && !is_avatar_extension(*o.out))
    throw UsageError("--out " + *o.out + ": use a " + avatar_extensions_text() + " file name");
  if (!o.out) {
    for (const auto& spec : export_option_specs()) {
      if (a.has(spec.name)) throw UsageError("--" + spec.name + " needs --out FILE");
    }
  }
  o.png = a.get("png");
  if (o.png && extension_of(*o.png) != ".png")
    throw UsageError("--png " + *o.png + ": the file name must end in .png");
  o.model = a.get("model");
  o.regressors = a.get("regressors");
  o.mapping = a.get("mapping");
  o.json = a.flags.count("json") > 0;
  o.exact_inputs = a.flags.count("exact-inputs") > 0;
  o.force = a.flags.count("force") > 0;
  o.quiet = a.flags.count("quiet") > 0;
  o.shape_curve = a.flags.count("no-shape-curve") == 0;
  return o;
}

/// What `caliper create` made.
struct CreateResult {
  std::shared_ptr<const ModelBundle> bundle;
  std::optional<MeasurementMapping> mapping;
  /// --arm-length-hanging: the model's map from the hanging arm to its arm length.
  std::optional<LinearMap> arm_map;
  double hanging_arm = 0.0;  ///< the value given, metres
  Avatar avatar;
  std::vector<std::string> warnings;
  std::vector<std::string> written;  ///< files written, in order
  double create_s = 0, write_s = 0, total_s = 0;
};

/// Writes the avatar file with the record `caliper measure` reads back.
void write_created_avatar(const CreateOptions& opt, const CreateResult& r,
                          smpl::ExportOptions export_options) {
  std::map<std::string, std::string>& extras = export_options.extras;
  extras["generator"] = version_string();
  extras["regressor"] = opt.regressor;
  extras["betas"] = betas_json(r.avatar.betas).dump();
  extras["measurements"] = measurements_json(r.avatar.achieved).dump();
  // Which model made the avatar, so that `caliper measure` picks it (and its weight formula)
  // without being told: the model's name, and for an open default model its sex.
  extras["model"] = r.bundle->model.meta.name;
  if (!opt.model) extras["open_model_sex"] = opt.sex;
  if (export_options.pose.size() > 0)
    extras["pose"] =
        Json(std::vector<double>(export_options.pose.data(),
                                 export_options.pose.data() + export_options.pose.size()))
            .dump();
  write_avatar(*opt.out, r.bundle->model, r.avatar.betas, export_options);
}

/// Makes the avatar and writes its files; warnings go to `warn` as they come.
CreateResult run_create(const CreateOptions& opt, std::ostream& warn) {
  const auto t_start = std::chrono::steady_clock::now();
  CreateResult r;
  r.warnings = check_inputs(opt.inputs, opt.force);
  for (const auto& w : r.warnings) warn << "caliper: warning: " << w << "\n";
  r.bundle =
      load_bundle(resolve_model_path(opt.model, opt.sex), opt.regressors, true, opt.shape_curve);
  const smpl::BodyModel& model = r.bundle->model;
  if (!opt.model && !model.meta.gender.empty() && model.meta.gender != opt.sex)
    warn << "caliper: warning: the model's gender is " << model.meta.gender << "\n";
  if (opt.mapping) r.mapping = load_mapping(*opt.mapping);
  // Export options are checked before the avatar is made, so a bad option costs no work.
  smpl::ExportOptions export_options;
  if (opt.out) export_options = read_export_options(opt.args, *opt.out, model);

  std::optional<ShapePrior> prior;
  if (opt.population) {
    if (!r.bundle->regressors.noise_aware) {
      throw RuntimeError(
          "--population needs the noise-aware regressor; retrain with "
          "caliper train --save FILE");
    }
    try {
      prior = population_prior(model, *opt.population);
    } catch (const InvalidInputError& e) {
      throw UsageError("--population " + *opt.population + ": " + e.what());
    }
  }
  const auto t_create = std::chrono::steady_clock::now();
  MeasurementMap inputs = opt.inputs;
  if (opt.hanging_arm) {
    try {
      r.arm_map = hanging_arm_map(model);
    } catch (const CaliperError& e) {
      throw RuntimeError(std::string("--arm-length-hanging: this model cannot swing its arms "
                                     "down to map the value (") +
                         e.what() + "); give --arm-length, taken with the arm out sideways");
    }
    r.hanging_arm = inputs.at("arm_length");
    inputs["arm_length"] = r.arm_map->apply(r.hanging_arm);
  }
  r.avatar = make_avatar(*r.bundle, opt.regressor, inputs, r.mapping ? &*r.mapping : nullptr, true,
                         opt.exact_inputs, true, prior ? &*prior : nullptr);
  r.create_s = seconds_since(t_create);
  if (!r.avatar.plausibility.plausible) {
    const std::string w =
        "unusual body shape: the avatar is outside the usual range (Mahalanobis distance " +
        format_number(r.avatar.plausibility.mahalanobis, 2) + ", " +
        std::to_string(r.avatar.plausibility.beyond_3sd.size()) +
        " components beyond 3 SD): check the measurements" +
        (opt.regressor == "noise-aware" ? "" : " or try --regressor noise-aware");
    r.warnings.push_back(w);
    warn << "caliper: warning: " << w << "\n";
  }
  const auto t_write = std::chrono::steady_clock::now();
  if (opt.out) {
    write_created_avatar(opt, r, export_options);
    r.written.push_back(*opt.out);
  }
  r.write_s = seconds_since(t_write);
  if (opt.png) {
    render_png(r.avatar.vertices, model.faces, *opt.png, "three_quarter", 600, 800);
    r.written.push_back(*opt.png);
  }
  r.total_s = seconds_since(t_start);
  return r;
}

Json create_report_json(const CreateResult& r, const std::string& regressor,
                        const std::optional<std::string>& population) {
  const Avatar& avatar = r.avatar;
  Json j = Json::object();
  j.set("command", "create");
  j.set("version", version_string());
  Json model = Json::object();
  model.set("path", r.bundle->path);
  model.set("name", r.bundle->model.meta.name);
  model.set("gender", r.bundle->model.meta.gender);
  model.set("vertices", r.bundle->model.num_vertices());
  model.set("betas", r.bundle->model.num_betas());
  j.set("model", model);
  j.set("regressor", regressor);
  // Whether the plain regressor started from the model's shape curve (docs/regressors.md).
  j.set("shape_curve", regressor != "noise-aware" && r.bundle->curve.has_value());
  if (population) j.set("population", *population);
  if (r.arm_map) {
    // --arm-length-hanging: the value given and the model's arm length it was mapped onto.
    j.set("hanging_arm", Json::object({{"measured", Json(r.hanging_arm)},
                                       {"arm_length", Json(r.arm_map->apply(r.hanging_arm))},
                                       {"slope", Json(r.arm_map->a)},
                                       {"intercept", Json(r.arm_map->b)},
                                       {"fit_rms", Json(r.arm_map->fit_rms)},
                                       {"bodies", Json(r.arm_map->count)}}));
  }
  j.set("units",
        Json::object({{"length", Json("m")}, {"weight", Json("kg")}, {"volume", Json("m3")}}));
  j.set("input", measurements_json(avatar.input));
  if (r.mapping) j.set("mapped_input", measurements_json(avatar.mapped));
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
  for (const auto& s : r.warnings) w.push_back(s);
  j.set("warnings", w);
  Json files = Json::array();
  for (const auto& s : r.written) files.push_back(s);
  j.set("written", files);
  j.set("timing_seconds", Json::object({{"load_model", Json(r.bundle->load_seconds)},
                                        {"train_regressors", Json(r.bundle->train_seconds)},
                                        {"create", Json(r.create_s)},
                                        {"write_avatar", Json(r.write_s)},
                                        {"total", Json(r.total_s)}}));
  return j;
}

void write_create_text(const CreateOptions& opt, const CreateResult& r, std::ostream& out) {
  const smpl::BodyModel& model = r.bundle->model;
  const Avatar& avatar = r.avatar;
  out << "model: " << (model.meta.name.empty() ? "(unnamed)" : model.meta.name) << " ("
      << (model.meta.gender.empty() ? "?" : model.meta.gender) << ", " << r.bundle->path << ")\n"
      << "regressor: " << opt.regressor;
  if (opt.population) out << ", prior: the model's population '" << *opt.population << "'";
  if (r.mapping) out << " with mapping " << *opt.mapping << " (input column: mapped values)";
  if (r.arm_map) {
    out << "\narm length taken hanging: " << format_value("arm_length", r.hanging_arm)
        << " -> the model's arm length (arm out sideways) "
        << format_value("arm_length", r.arm_map->apply(r.hanging_arm)) << " ("
        << format_number(r.arm_map->a, 3) << " x hanging " << (r.arm_map->b < 0 ? "- " : "+ ")
        << format_value("arm_length", std::abs(r.arm_map->b)) << ", RMS "
        << format_value("arm_length", r.arm_map->fit_rms) << " over " << r.arm_map->count
        << " bodies of the model)";
  }
  out << "\n\n"
      << measurement_table(r.mapping ? avatar.mapped : avatar.input, avatar.achieved, opt.imperial);
  out << "\nbetas: " << format_betas(avatar.betas) << "\n";
  if (avatar.covariance) {
    out << "betas posterior SD: " << format_betas(avatar.covariance->diagonal().cwiseSqrt().eval())
        << "\n";
  }
  out << "plausibility: " << format_plausibility(avatar.plausibility);
  for (const auto& f : r.written) out << "wrote " << f << "\n";
  std::ostringstream t;
  t << std::fixed << std::setprecision(1) << "time: load model " << r.bundle->load_seconds * 1e3
    << " ms, train regressors " << r.bundle->train_seconds * 1e3 << " ms, create "
    << r.create_s * 1e3 << " ms, write " << r.write_s * 1e3 << " ms, total " << r.total_s * 1e3
    << " ms\n";
  out << t.str();
}

/// Writes the report: JSON, text, or (--quiet) nothing.
int write_create_report(const CreateOptions& opt, const CreateResult& r, Io& io) {
  if (!opt.out) {
    io.err << "caliper create: no avatar file written (add --out FILE, a "
           << avatar_extensions_text() << " file, e.g. --out avatar.glb)\n";
  }
  if (opt.json) {
    io.out << create_report_json(r, opt.regressor, opt.population).dump(2) << "\n";
  } else if (!opt.quiet) {
    write_create_text(opt, r, io.out);
  }
  return kExitOk;
}

}  // namespace

int cmd_create(const std::vector<std::string>& args, Io& io) {
  return run_command(
      args, create_options(), kCreateHelp, io, create_options_from,
      [&io](const CreateOptions& opt) { return run_create(opt, io.err); }, write_create_report);
}

}  // namespace caliper::cli
