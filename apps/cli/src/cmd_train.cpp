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

int cmd_train(const std::vector<std::string>& args, Io& io) {
  const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "the model (default: the open model of --sex)", false},
      {"sex", "s", "SEX", "female, male or neutral (default neutral)", false},
      {"betas", "", "K", "shape components to regress (default min(10, model's))", false},
      {"gaussian", "", "N", "train on N Gaussian bodies instead of the 2^K corners", false},
      {"seed", "", "S", "random seed for --gaussian (default 1)", false},
      {"corner-sd", "", "SD", "corner distance in SD (default 2, as the paper)", false},
      {"save", "", "FILE", "write the fitted regressors as JSON", false},
      {"json", "", "", "print the report as JSON", false},
  };
  const ParsedArgs a = parse_args(args, specs);
  if (a.flags.count("help")) {
    io.out << "usage: caliper train [--model FILE | --sex SEX] [--save regressors.json]\n\n"
              "Builds the training set (the paper's 2^10 bodies at +/-2 SD, or Gaussian samples),\n"
              "fits R2, R4, R5, R6 and the noise-aware regressor, and reports them.\n\n"
           << format_options(specs)
           << "\nexample:\n  caliper train --sex female --save female-regressors.json\n";
    return kExitOk;
  }
  if (!a.positional.empty()) throw UsageError("unexpected argument '" + a.positional[0] + "'");
  TrainOptions opt;
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
  const std::string sex = a.get("sex") ? normalise_sex(*a.get("sex")) : "neutral";
  const std::string path = resolve_model_path(a.get("model"), sex);
  const smpl::BodyModel model = smpl::load_model(path);

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
  const TrainingSet set = make_training_set(measurer, betas, weight_formula_for(model.meta.gender));
  const RegressorSet regs = train_regressors(set, ModelSignature::of(model, k), opt);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (auto s = a.get("save")) regs.save(*s);

  // Training-set statistics of the six inputs.
  std::vector<std::string> ids = regressor_inputs(RegressorKind::R6);
  Json stats = Json::object();
  std::ostringstream text;
  text << "model: " << path << " (" << (model.meta.gender.empty() ? "?" : model.meta.gender) << ", "
       << model.num_vertices() << " vertices, " << model.num_betas() << " betas)\n"
       << "training set: " << set.size() << " bodies ("
       << (opt.gaussian ? "Gaussian samples, seed " + std::to_string(opt.seed)
                        : "corners at +/-" + std::to_string(opt.corner_sd).substr(0, 4) + " SD")
       << ") over " << k << " betas; weight formula " << set.weight_formula.name << "\n\n";
  text << std::left << std::setw(26) << "input" << std::right << std::setw(11) << "mean"
       << std::setw(11) << "SD" << std::setw(11) << "min" << std::setw(11) << "max"
       << "\n";
  for (const auto& id : ids) {
    const Eigen::VectorXd c = set.column(id);
    const double mean = c.mean();
    const double sd =
        std::sqrt((c.array() - mean).square().sum() / std::max<Eigen::Index>(1, c.size() - 1));
    const auto [unit, f] = display_unit(id);
    char buf[160];
    std::snprintf(buf, sizeof buf, "%-26s%8.1f %-2s%8.1f %-2s%8.1f %-2s%8.1f %-2s\n",
                  label_of(id).c_str(), mean * f, unit.c_str(), sd * f, unit.c_str(),
                  c.minCoeff() * f, unit.c_str(), c.maxCoeff() * f, unit.c_str());
    text << buf;
    stats.set(id, json_object({{"mean", Json(mean)},
                               {"sd", Json(sd)},
                               {"min", Json(c.minCoeff())},
                               {"max", Json(c.maxCoeff())}}));
  }
  text << "\nfit residuals (RMS over the training set of each input when the avatar is re-measured "
          "linearly; mm, weight feature in mm of cube-root volume):\n";
  Json regs_json = Json::array();
  for (const auto& r : regs.linear) {
    text << "  " << std::left << std::setw(4) << r.name() << std::right;
    Json rj = Json::object();
    rj.set("name", r.name());
    Json res = Json::object();
    for (size_t i = 0; i < r.inputs().size(); ++i) {
      char buf[80];
      std::snprintf(buf, sizeof buf, "  %s %.3f", r.inputs()[i].c_str(),
                    r.training_rms()[static_cast<Eigen::Index>(i)] * 1000.0);
      text << buf;
      res.set(r.inputs()[i], r.training_rms()[static_cast<Eigen::Index>(i)]);
    }
    text << "\n";
    rj.set("training_rms", res);
    regs_json.push_back(rj);
  }
  Json na = Json::object();
  if (regs.noise_aware) {
    const auto& n = *regs.noise_aware;
    text << "  noise-aware: linearisation RMS (mm)";
    Json lin = Json::object(), noise = Json::object();
    for (size_t i = 0; i < n.inputs().size(); ++i) {
      char buf[80];
      std::snprintf(buf, sizeof buf, "  %s %.3f", n.inputs()[i].c_str(),
                    n.linearisation_rms()[static_cast<Eigen::Index>(i)] * 1000.0);
      text << buf;
      lin.set(n.inputs()[i], n.linearisation_rms()[static_cast<Eigen::Index>(i)]);
    }
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
  }
  char tbuf[80];
  std::snprintf(tbuf, sizeof tbuf, "\ntraining time: %.1f ms\n", seconds * 1e3);
  text << tbuf;
  if (auto s = a.get("save")) text << "wrote " << *s << "\n";

  if (a.flags.count("json")) {
    Json j = Json::object();
    j.set("command", "train");
    j.set("model", path);
    j.set("training_set", json_object({{"bodies", Json(set.size())},
                                       {"betas", Json(k)},
                                       {"kind", Json(opt.gaussian ? "gaussian" : "corners")},
                                       {"weight_formula", Json(set.weight_formula.name)},
                                       {"inputs", Json(stats)}}));
    j.set("linear", regs_json);
    if (regs.noise_aware) j.set("noise_aware", na);
    j.set("seconds", seconds);
    if (auto s = a.get("save")) j.set("saved", *s);
    io.out << j.dump(2) << "\n";
  } else {
    io.out << text.str();
  }
  return kExitOk;
}

}  // namespace caliper::cli
