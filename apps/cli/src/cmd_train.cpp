// `caliper train`: fits R2, R4, R5, R6 and the noise-aware regressor for a model and reports
// the training set and the fit residuals.
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "caliper/training.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "report.hpp"
#include "smpl/io.hpp"

namespace caliper::cli {

namespace {
const app::HelpText kTrainHelp{
    {"caliper train [--model FILE | --sex SEX] [--save regressors.json]"},
    "Builds the training set (the paper's 2^10 bodies at +/-2 SD, or Gaussian samples),\n"
    "fits R2, R4, R5, R6 and the noise-aware regressor, and reports them.",
    "example:\n  caliper train --sex female --save female-regressors.json"};
}  // namespace

namespace {

const std::vector<OptionSpec>& train_options() {
  static const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "the model (default: the open model of --sex)", false},
      {"sex", "s", "SEX", "female, male or neutral (default neutral)", false},
      {"betas", "", "K", "shape components to regress (default min(10, model's))", false},
      {"gaussian", "", "N", "train on N Gaussian bodies instead of the 2^K corners", false},
      {"seed", "", "S", "random seed for --gaussian (default 1)", false},
      {"corner-sd", "", "SD", "corner distance in SD (default 2, as the paper)", false},
      {"paper-intercept", "", "",
       "the paper's least-squares intercept (default: the weight taken at the mean body)", false},
      {"save", "", "FILE", "write the fitted regressors as JSON", false},
      {"json", "", "", "print the report as JSON", false},
  };
  return specs;
}

/// Everything `caliper train` is asked to do.
struct TrainCommand {
  TrainOptions train;  ///< num_betas 0: min(10, the model's)
  std::string sex = "neutral";
  std::optional<std::string> model, save;
  bool json = false;
};

TrainCommand train_command_from(const ParsedArgs& a) {
  if (!a.positional.empty()) throw UsageError("unexpected argument '" + a.positional[0] + "'");
  TrainCommand c;
  TrainOptions& opt = c.train;
  if (auto v = a.get("betas")) opt.num_betas = parse_int(*v, "betas", 1, kMaxTrainingBetas);
  if (auto v = a.get("gaussian")) {
    opt.gaussian = true;
    opt.gaussian_count = parse_int(*v, "gaussian", 2, 10000000);
  }
  if (auto v = a.get("seed"))
    opt.seed = static_cast<std::uint64_t>(parse_int(*v, "seed", 0, 2147483647));
  if (auto v = a.get("corner-sd")) {
    opt.corner_sd = parse_number(*v, "--corner-sd");
    if (opt.corner_sd <= 0) throw UsageError("--corner-sd must be positive");
  }
  opt.intercept_at_mean = a.flags.count("paper-intercept") == 0;
  if (a.get("sex")) c.sex = normalise_sex(*a.get("sex"));
  c.model = a.get("model");
  c.save = a.get("save");
  c.json = a.flags.count("json") > 0;
  return c;
}

/// What `caliper train` fitted.
struct TrainResult {
  std::string path;  ///< the model file
  std::string gender;
  int vertices = 0, model_betas = 0;
  TrainOptions options;  ///< as used (num_betas set)
  TrainingSet set;
  RegressorSet regressors;
  double seconds = 0;  ///< training time
};

/// Builds the training set and fits the regressors (saved with --save).
TrainResult run_train(const TrainCommand& c) {
  TrainResult r;
  r.path = resolve_model_path(c.model, c.sex);
  const smpl::BodyModel model = smpl::load_model(r.path);
  r.gender = model.meta.gender;
  r.vertices = model.num_vertices();
  r.model_betas = model.num_betas();
  r.options = c.train;
  TrainOptions& opt = r.options;
  const auto t0 = std::chrono::steady_clock::now();
  const int k = opt.num_betas > 0 ? opt.num_betas : std::min(10, model.num_betas());
  if (k > model.num_betas())
    throw UsageError("--betas " + std::to_string(k) + ": the model has only " +
                     std::to_string(model.num_betas()) + " shape components");
  opt.num_betas = k;
  std::vector<MeasurementDef> defs;
  for (const auto& id : regressor_inputs(RegressorKind::R6))
    if (id != "weight") defs.push_back(measurement_def(id));
  const ShapeMeasurer measurer(model, landmarks_for(model), defs, k);
  const Eigen::MatrixXd betas = opt.gaussian ? gaussian_betas(opt.gaussian_count, k, opt.seed)
                                             : corner_betas(k, opt.corner_sd);
  r.set = make_training_set(measurer, betas, weight_formula_of(model));
  r.regressors = train_regressors(r.set, ModelSignature::of(model, k), opt);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (c.save) r.regressors.save(*c.save);
  return r;
}

/// The training-set statistics of the six inputs: a text table into `text`, JSON returned.
Json training_set_stats(const TrainResult& r, std::ostream& text) {
  Json stats = Json::object();
  text << std::left << std::setw(26) << "input" << std::right << std::setw(11) << "mean"
       << std::setw(11) << "SD" << std::setw(11) << "min" << std::setw(11) << "max"
       << "\n";
  for (const auto& id : regressor_inputs(RegressorKind::R6)) {
    const Eigen::VectorXd c = r.set.column(id);
    const double mean = c.mean();
    const double sd =
        std::sqrt((c.array() - mean).square().sum() / std::max<Eigen::Index>(1, c.size() - 1));
    const auto [unit, f] = display_unit(id);
    char buf[160];
    std::snprintf(buf, sizeof buf, "%-26s%8.1f %-2s%8.1f %-2s%8.1f %-2s%8.1f %-2s\n",
                  label_of(id).c_str(), mean * f, unit.c_str(), sd * f, unit.c_str(),
                  c.minCoeff() * f, unit.c_str(), c.maxCoeff() * f, unit.c_str());
    text << buf;
    stats.set(id, Json::object({{"mean", Json(mean)},
                                {"sd", Json(sd)},
                                {"min", Json(c.minCoeff())},
                                {"max", Json(c.maxCoeff())}}));
  }
  return stats;
}

/// Residuals per input (metres): "  <input> <millimetres>" each into `text`, {input: metres}
/// returned.
Json residuals_per_input(const std::vector<std::string>& inputs, const Eigen::VectorXd& rms,
                         std::ostream& text) {
  Json res = Json::object();
  for (size_t i = 0; i < inputs.size(); ++i) {
    const double metres = rms[static_cast<Eigen::Index>(i)];
    char buf[80];
    std::snprintf(buf, sizeof buf, "  %s %.3f", inputs[i].c_str(), metres * 1000.0);
    text << buf;
    res.set(inputs[i], metres);
  }
  return res;
}

/// The linear regressors' fit residuals: text lines into `text`, JSON returned.
Json linear_residuals(const RegressorSet& regs, std::ostream& text) {
  Json regs_json = Json::array();
  for (const auto& r : regs.linear) {
    text << "  " << std::left << std::setw(4) << r.name() << std::right;
    Json rj = Json::object();
    rj.set("name", r.name());
    rj.set("training_rms", residuals_per_input(r.inputs(), r.training_rms(), text));
    text << "\n";
    regs_json.push_back(rj);
  }
  return regs_json;
}

/// The noise-aware regressor's linearisation residuals and noise: text into `text`, JSON
/// returned.
Json noise_aware_report(const NoiseAwareRegressor& n, std::ostream& text) {
  Json na = Json::object();
  text << "  noise-aware: linearisation RMS (mm)";
  const Json lin = residuals_per_input(n.inputs(), n.linearisation_rms(), text);
  Json noise = Json::object();
  text << "\n  noise-aware: measurement noise SD";
  for (const auto& [id, sd] : n.noise()) {
    char buf[80];
    std::snprintf(buf, sizeof buf, "  %s %.2f %s", id.c_str(), id == "weight" ? sd : sd * 100.0,
                  id == "weight" ? "kg" : "cm");
    text << buf;
    noise.set(id, sd);
  }
  text << "\n";
  na.set("linearisation_rms", lin);
  na.set("noise_sd", noise);
  return na;
}

/// Prints the report: text, or JSON with --json.
int write_train_report(const TrainCommand& c, const TrainResult& r, Io& io) {
  const TrainOptions& opt = r.options;
  std::ostringstream text;
  text << "model: " << r.path << " (" << (r.gender.empty() ? "?" : r.gender) << ", " << r.vertices
       << " vertices, " << r.model_betas << " betas)\n"
       << "training set: " << r.set.size() << " bodies ("
       << (opt.gaussian ? "Gaussian samples, seed " + std::to_string(opt.seed)
                        : "corners at +/-" + std::to_string(opt.corner_sd).substr(0, 4) + " SD")
       << ") over " << opt.num_betas << " betas; weight formula " << r.set.weight_formula.name
       << "\nintercept: "
       << (opt.intercept_at_mean ? "least squares, the weight taken at the mean body"
                                 : "the paper's, least squares over the training set")
       << "\n\n";
  const Json stats = training_set_stats(r, text);
  text << "\nfit residuals (RMS over the training set of each input when the avatar is re-measured "
          "linearly; mm, weight feature in mm of cube-root volume):\n";
  const Json regs_json = linear_residuals(r.regressors, text);
  Json na = Json::object();
  if (r.regressors.noise_aware) na = noise_aware_report(*r.regressors.noise_aware, text);
  char tbuf[80];
  std::snprintf(tbuf, sizeof tbuf, "\ntraining time: %.1f ms\n", r.seconds * 1e3);
  text << tbuf;
  if (c.save) text << "wrote " << *c.save << "\n";
  if (!c.json) {
    io.out << text.str();
    return kExitOk;
  }
  Json j = Json::object();
  j.set("command", "train");
  j.set("model", r.path);
  j.set("training_set",
        Json::object(
            {{"bodies", Json(r.set.size())},
             {"betas", Json(opt.num_betas)},
             {"kind", Json(opt.gaussian ? "gaussian" : "corners")},
             {"weight_formula", Json(r.set.weight_formula.name)},
             {"intercept", Json(opt.intercept_at_mean ? "weight at the mean body" : "paper")},
             {"inputs", Json(stats)}}));
  j.set("linear", regs_json);
  if (r.regressors.noise_aware) j.set("noise_aware", na);
  j.set("seconds", r.seconds);
  if (c.save) j.set("saved", *c.save);
  io.out << j.dump(2) << "\n";
  return kExitOk;
}

}  // namespace

int cmd_train(const std::vector<std::string>& args, Io& io) {
  return run_command(args, train_options(), kTrainHelp, io, train_command_from, run_train,
                     write_train_report);
}

}  // namespace caliper::cli
