// `caliper evaluate`: runs the evaluation studies of docs/evaluation.md on a model and prints
// markdown tables.
#include <chrono>
#include <cstdio>
#include <ostream>

#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "studies.hpp"

namespace caliper::cli {

int cmd_evaluate(const std::vector<std::string>& args, Io& io) {
  const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "model file (table1, simulation); default: the open model", false},
      {"sex", "s", "SEX", "female, male or neutral (default neutral, as for every command)", false},
      {"regressors", "", "FILE", "regressors saved by caliper train (with --model)", false},
      {"bodies", "n", "N", "bodies drawn from the model (default 1000 / 500)", false},
      {"seed", "", "S", "random seed (default 1)", false},
      {"exact", "", "", "table1: exact measurements instead of noisy ones", false},
      {"exact-inputs", "", "", "table1: refine R2-R6 betas to reproduce the inputs exactly", false},
      {"ansur-dir", "", "DIR", "ansur: folder with the ANSUR II CSV files", false},
      {"male-model", "", "FILE", "ansur: model for the men (default: the open male model)", false},
      {"female-model", "", "FILE", "ansur: model for the women (default: the open female model)",
       false},
      {"every", "", "K", "ansur: hold out every K-th subject (default 5)", false},
  };
  const ParsedArgs a = parse_args(args, specs);
  if (a.flags.count("help") || a.positional.empty()) {
    io.out << "usage: caliper evaluate table1|simulation|ansur [options]\n\n"
              "  table1      the paper's Table 1: input vs avatar measurements per regressor\n"
              "  simulation  noisy inputs of bodies drawn from the model, vertex-to-vertex error\n"
              "  ansur       held-out ANSUR II subjects: avatar circumferences vs the survey\n\n"
           << format_options(specs)
           << "\nexample:\n  caliper evaluate ansur --ansur-dir ../shared/data/ansur2\n";
    return a.flags.count("help") ? kExitOk : kExitUsage;
  }
  const std::string study = a.positional[0];
  std::uint64_t seed = 1;
  if (auto s = a.get("seed"))
    seed = static_cast<std::uint64_t>(parse_int(*s, "seed", 0, 2147483647));
  const auto t0 = std::chrono::steady_clock::now();
  if (study == "table1" || study == "simulation") {
    const std::string sex = a.get("sex") ? normalise_sex(*a.get("sex")) : "neutral";
    const auto bundle = load_bundle(resolve_model_path(a.get("model"), sex), a.get("regressors"));
    io.out << "model: " << bundle->path << " (" << bundle->model.meta.name << ", "
           << bundle->model.num_vertices() << " vertices)\n\n";
    if (study == "table1") {
      const int n = a.get("bodies") ? parse_int(*a.get("bodies"), "bodies", 1, 1000000) : 1000;
      const bool exact = a.flags.count("exact") > 0;
      const Table1Result r =
          table1_study(*bundle, n, seed, !exact, a.flags.count("exact-inputs") > 0);
      io.out << n << " bodies; " << r.condition << "; cm, weight kg; bold: not an input\n\n"
             << table1_markdown(r, true);
    } else {
      const int n = a.get("bodies") ? parse_int(*a.get("bodies"), "bodies", 1, 1000000) : 500;
      io.out << simulation_markdown(simulation_study(*bundle, n, seed));
    }
  } else if (study == "ansur") {
    const std::string dir = a.get_or("ansur-dir", "");
    if (dir.empty()) throw UsageError("ansur needs --ansur-dir DIR (the ANSUR II CSV folder)");
    std::vector<std::pair<std::vector<Person>, const ModelBundle*>> groups;
    const auto male = load_bundle(resolve_model_path(a.get("male-model"), "male"), std::nullopt);
    const auto female =
        load_bundle(resolve_model_path(a.get("female-model"), "female"), std::nullopt);
    groups.emplace_back(read_ansur_csv(dir + "/ANSUR_II_MALE_Public.csv"), male.get());
    groups.emplace_back(read_ansur_csv(dir + "/ANSUR_II_FEMALE_Public.csv"), female.get());
    const int every = a.get("every") ? parse_int(*a.get("every"), "every", 2, 1000) : 5;
    io.out << "held out: every " << every
           << "th subject of each file; MAE in mm (mean signed "
              "error avatar - survey in brackets)\n\n"
           << ansur_markdown(ansur_study(groups, every));
  } else {
    throw UsageError("unknown study '" + study + "' (table1, simulation, ansur)");
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "\n(%.1f s)\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  io.out << buf;
  return kExitOk;
}

}  // namespace caliper::cli
