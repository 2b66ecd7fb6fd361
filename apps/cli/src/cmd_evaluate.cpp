// `caliper evaluate`: runs the evaluation studies of docs/evaluation.md on a model and prints
// markdown tables.
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>

#include "caliper/measurements.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "studies.hpp"

namespace caliper::cli {

namespace {
const app::HelpText kEvaluateHelp{
    {"caliper evaluate table1|simulation|ansur|nhanes [options]"},
    "  table1      the paper's Table 1: input vs avatar measurements per regressor\n"
    "  simulation  noisy inputs of bodies drawn from the model, vertex-to-vertex error\n"
    "  ansur       held-out ANSUR II subjects: avatar circumferences vs the survey\n"
    "  nhanes      NHANES adults per sex and BMI bin: R2 avatars' hip and iliac-crest waist\n"
    "              vs the survey and a cross-validated height+weight fit, weight from\n"
    "              volume, avatars beyond 3 SD (the models need the left/right_iliac_crest\n"
    "              landmarks, or --derive-iliac-crest)",
    "examples:\n  caliper evaluate ansur --ansur-dir ../shared/data/ansur2\n"
    "  caliper evaluate nhanes --nhanes-dir ../shared/data/nhanes --derive-iliac-crest"};
}  // namespace

namespace {

const std::vector<OptionSpec>& evaluate_options() {
  static const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "model file (table1, simulation); default: the open model", false},
      {"sex", "s", "SEX", "female, male or neutral (default neutral, as for every command)", false},
      {"regressors", "", "FILE", "regressors saved by caliper train (with --model)", false},
      {"bodies", "n", "N", "bodies drawn from the model (default 1000 / 500)", false},
      {"seed", "", "S", "random seed (default 1)", false},
      {"exact", "", "", "table1: exact measurements instead of noisy ones", false},
      {"exact-inputs", "", "", "table1: refine R2-R6 betas to reproduce the inputs exactly", false},
      {"ansur-dir", "", "DIR", "ansur: folder with the ANSUR II CSV files", false},
      {"male-model", "", "FILE", "ansur, nhanes: model for the men (default: the open male model)",
       false},
      {"female-model", "", "FILE",
       "ansur, nhanes: model for the women (default: the open female model)", false},
      {"every", "", "K", "ansur: hold out every K-th subject (default 5)", false},
      {"nhanes-dir", "", "DIR", "nhanes: folder with NHANES_2017_2020_{FEMALE,MALE}_dev.csv",
       false},
      {"folds", "", "K", "nhanes: folds of the cross-validated baseline (default 10)", false},
      {"no-shape-curve", "", "",
       "R2-R6 as in the paper: from the mean body, not from the general population's body of "
       "the height and weight (models that carry a shape curve)",
       false},
      {"derive-iliac-crest", "", "",
       "nhanes: place left/right_iliac_crest by the v2 generator's rule on models without them",
       false},
  };
  return specs;
}

/// Everything `caliper evaluate` is asked to do.
struct EvaluateCommand {
  std::string study;  ///< table1, simulation or ansur
  std::uint64_t seed = 1;
  std::string sex = "neutral";
  std::optional<std::string> model, regressors, male_model, female_model;
  std::optional<int> bodies;  ///< default 1000 (table1) / 500 (simulation)
  bool exact = false, exact_inputs = false;
  std::string ansur_dir, nhanes_dir;
  int every = 5;
  int folds = 10;
  bool derive_iliac_crest = false;
  bool shape_curve = true;  ///< false: --no-shape-curve
};

EvaluateCommand evaluate_command_from(const ParsedArgs& a) {
  EvaluateCommand c;
  c.study = a.positional[0];
  if (auto s = a.get("seed"))
    c.seed = static_cast<std::uint64_t>(parse_int(*s, "seed", 0, 2147483647));
  if (a.get("sex")) c.sex = normalise_sex(*a.get("sex"));
  c.model = a.get("model");
  c.regressors = a.get("regressors");
  c.male_model = a.get("male-model");
  c.female_model = a.get("female-model");
  if (auto n = a.get("bodies")) c.bodies = parse_int(*n, "bodies", 1, 1000000);
  c.exact = a.flags.count("exact") > 0;
  c.exact_inputs = a.flags.count("exact-inputs") > 0;
  c.ansur_dir = a.get_or("ansur-dir", "");
  if (auto e = a.get("every")) c.every = parse_int(*e, "every", 2, 1000);
  c.nhanes_dir = a.get_or("nhanes-dir", "");
  if (auto f = a.get("folds")) c.folds = parse_int(*f, "folds", 2, 1000);
  c.derive_iliac_crest = a.flags.count("derive-iliac-crest") > 0;
  c.shape_curve = a.flags.count("no-shape-curve") == 0;
  if (c.study != "table1" && c.study != "simulation" && c.study != "ansur" && c.study != "nhanes")
    throw UsageError("unknown study '" + c.study + "' (table1, simulation, ansur, nhanes)");
  if (c.study == "nhanes" && c.nhanes_dir.empty())
    throw UsageError("nhanes needs --nhanes-dir DIR (the NHANES CSV folder)");
  if (c.study == "ansur" && c.ansur_dir.empty())
    throw UsageError("ansur needs --ansur-dir DIR (the ANSUR II CSV folder)");
  return c;
}

/// The bundle of `path`; with `derive`, a copy whose model carries left/right_iliac_crest placed
/// by caliper::derive_iliac_crest_landmarks() on its mean body when it had none. `note` gets a
/// line saying which landmarks were used.
std::shared_ptr<const ModelBundle> nhanes_bundle(const std::string& path, bool derive,
                                                 bool shape_curve, std::string& note) {
  auto loaded = load_bundle(path, std::nullopt, true, shape_curve);
  note += "- " + path + ": " +
          (loaded->curve ? "R2 from the model's shape curve (" + loaded->curve->population + ")"
                         : std::string("the paper's R2 (from the mean body)")) +
          "\n";
  LandmarkTable table = landmarks_for(loaded->model);
  const bool carried = table.count("left_iliac_crest") && table.count("right_iliac_crest");
  if (carried || !derive) {
    note +=
        "- " + path + ": iliac crest landmarks " + (carried ? "from the model" : "missing") + "\n";
    return loaded;
  }
  auto copy = std::make_shared<ModelBundle>(*loaded);
  derive_iliac_crest_landmarks(copy->model.v_template, table);
  for (const char* name : {"left_iliac_crest", "right_iliac_crest"})
    copy->model.landmarks[name] = table.at(name);
  copy->measure_info.emplace(copy->model);  // the loaded one predates the new landmarks
  note += "- " + path + ": iliac crest landmarks derived (--derive-iliac-crest: vertices " +
          std::to_string(table.at("left_iliac_crest").front()) + " / " +
          std::to_string(table.at("right_iliac_crest").front()) + ")\n";
  return copy;
}

/// Runs the study; returns its markdown report.
std::string run_evaluate(const EvaluateCommand& c) {
  std::ostringstream out;
  if (c.study == "nhanes") {
    std::string note;
    const auto female = nhanes_bundle(resolve_model_path(c.female_model, "female"),
                                      c.derive_iliac_crest, c.shape_curve, note);
    const auto male = nhanes_bundle(resolve_model_path(c.male_model, "male"), c.derive_iliac_crest,
                                    c.shape_curve, note);
    std::vector<NhanesGroup> groups(2);
    groups[0] = {"female", read_nhanes_csv(c.nhanes_dir + "/NHANES_2017_2020_FEMALE_dev.csv"),
                 female.get()};
    groups[1] = {"male", read_nhanes_csv(c.nhanes_dir + "/NHANES_2017_2020_MALE_dev.csv"),
                 male.get()};
    const std::vector<NhanesRow> rows = nhanes_study(groups, c.folds);
    out << "NHANES 2017-2020 adults (" << c.nhanes_dir
        << "); R2 avatars from height and weight; bias = mean of avatar - survey, MAE in mm; "
           "baseline: circumference ~ height + weight, "
        << c.folds
        << "-fold cross-validated; ratio = avatar MAE / baseline MAE; weight from the avatar's "
           "volume vs the measured weight\n"
        << note << "\n"
        << nhanes_markdown(rows);
    return out.str();
  }
  if (c.study == "ansur") {
    std::vector<std::pair<std::vector<Person>, const ModelBundle*>> groups;
    const auto male =
        load_bundle(resolve_model_path(c.male_model, "male"), std::nullopt, true, c.shape_curve);
    const auto female = load_bundle(resolve_model_path(c.female_model, "female"), std::nullopt,
                                    true, c.shape_curve);
    groups.emplace_back(read_ansur_csv(c.ansur_dir + "/ANSUR_II_MALE_Public.csv"), male.get());
    groups.emplace_back(read_ansur_csv(c.ansur_dir + "/ANSUR_II_FEMALE_Public.csv"), female.get());
    out << "held out: every " << c.every
        << "th subject of each file; MAE in mm (mean signed "
           "error avatar - survey in brackets)\n\n"
        << ansur_markdown(ansur_study(groups, c.every));
    return out.str();
  }
  const auto bundle =
      load_bundle(resolve_model_path(c.model, c.sex), c.regressors, true, c.shape_curve);
  out << "model: " << bundle->path << " (" << bundle->model.meta.name << ", "
      << bundle->model.num_vertices() << " vertices)\n\n";
  if (c.study == "table1") {
    const int n = c.bodies.value_or(1000);
    const Table1Result r = table1_study(*bundle, n, c.seed, !c.exact, c.exact_inputs);
    out << n << " bodies; " << r.condition << "; cm, weight kg; bold: not an input\n\n"
        << table1_markdown(r, true);
  } else {
    out << (bundle->curve ? "R2-R6 from the model's shape curve\n\n" : "")
        << simulation_markdown(simulation_study(*bundle, c.bodies.value_or(500), c.seed));
  }
  return out.str();
}

}  // namespace

int cmd_evaluate(const std::vector<std::string>& args, Io& io) {
  const ParsedArgs a = parse_args(args, evaluate_options(), kEvaluateHelp);
  if (a.flags.count("help")) {
    io.out << a.help;
    return kExitOk;
  }
  if (a.positional.empty()) {
    io.err << a.help;
    return kExitUsage;
  }
  const EvaluateCommand command = evaluate_command_from(a);
  const auto t0 = std::chrono::steady_clock::now();
  io.out << run_evaluate(command);
  char buf[64];
  std::snprintf(buf, sizeof buf, "\n(%.1f s)\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  io.out << buf;
  return kExitOk;
}

}  // namespace caliper::cli
