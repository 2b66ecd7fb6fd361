// Benchmarks of issue 3 (docs/performance.md, "libcaliper and the caliper command"):
// - training all four regressors (1024 bodies, with volume): the open model and a full-size
//   (6,890-vertex) smooth test model;
// - `caliper create` compute from measurements to a GLB on disk (regressors trained once);
// - `caliper batch` over all 6,068 ANSUR II people without writing avatars (people per second).
// The open models are read from $CALIPER_ASSETS or <source>/assets; benchmarks that need them
// are skipped when they are missing.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "caliper/avatar.hpp"
#include "caliper/regressor.hpp"
#include "cli_fixture.hpp"
#include "commands.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace {

std::string assets_dir() {
  if (const char* env = std::getenv("CALIPER_ASSETS")) return env;
  return std::string(CALIPER_SOURCE_DIR) + "/assets";
}

std::string open_model_path(const std::string& sex) {
  return assets_dir() + "/models/caliper-" + sex + ".npz";
}

const smpl::BodyModel* open_model(const std::string& sex) {
  static std::map<std::string, smpl::BodyModel> cache;
  auto it = cache.find(sex);
  if (it != cache.end()) return &it->second;
  const std::string p = open_model_path(sex);
  if (!std::filesystem::exists(p)) return nullptr;
  return &cache.emplace(sex, smpl::load_model(p)).first->second;
}

const smpl::BodyModel& full_size_test_model() {
  static const smpl::BodyModel m = caliper::test::cli_test_model("female", 7, true);
  return m;
}

void BM_TrainRegressors_OpenFemale(benchmark::State& state) {
  const smpl::BodyModel* m = open_model("female");
  if (!m) {
    state.SkipWithError("open model missing");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(caliper::train_regressors(*m));
  state.counters["vertices"] = m->num_vertices();
}
BENCHMARK(BM_TrainRegressors_OpenFemale)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_CreateToGlb_OpenFemale(benchmark::State& state) {
  const smpl::BodyModel* m = open_model("female");
  if (!m) {
    state.SkipWithError("open model missing");
    return;
  }
  const caliper::RegressorSet regs = caliper::train_regressors(*m);
  const caliper::MeasurementMap in = {{"height", 1.68},
                                      {"weight", 62.0},
                                      {"arm_span_fingertips", 1.70},
                                      {"inseam_height", 0.78},
                                      {"hip_width", 0.36}};
  const std::string out =
      (std::filesystem::temp_directory_path() / "bench_caliper_avatar.glb").string();
  for (auto _ : state) {
    // What `caliper create` computes: validate, regress, shape, measure everything (with
    // circumferences), plausibility, GLB on disk.
    const caliper::Avatar a = caliper::create_avatar(*m, *regs.find("R5"), in);
    smpl::write_gltf(out, *m, a.betas);
    benchmark::DoNotOptimize(a.achieved);
  }
  std::filesystem::remove(out);
}
BENCHMARK(BM_CreateToGlb_OpenFemale)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The whole `caliper create` command in process: load the open model, load saved regressors
// (`caliper train --save`), validate, regress, measure, write the GLB.
void BM_CreateCommand_OpenFemale(benchmark::State& state) {
  const smpl::BodyModel* m = open_model("female");
  if (!m) {
    state.SkipWithError("open model missing");
    return;
  }
  const auto tmp = std::filesystem::temp_directory_path();
  const std::string regs = (tmp / "bench_caliper_regressors.json").string();
  caliper::train_regressors(*m).save(regs);
  const std::string out = (tmp / "bench_caliper_cmd.glb").string();
  const std::vector<std::string> args = {"create",       "--model",  open_model_path("female"),
                                         "--regressors", regs,       "--height",
                                         "168cm",        "--weight", "62kg",
                                         "--out",        out,        "-q"};
  for (auto _ : state) {
    std::ostringstream o, e;
    caliper::cli::Io io{o, e, false};
    if (caliper::cli::main_guarded(args, io) != 0) state.SkipWithError(e.str().c_str());
  }
  std::filesystem::remove(out);
  std::filesystem::remove(regs);
}
BENCHMARK(BM_CreateCommand_OpenFemale)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_BatchAnsur(benchmark::State& state) {
  const std::string dir = std::string(CALIPER_SOURCE_DIR) + "/../shared/data/ansur2";
  if (!open_model("male") || !std::filesystem::exists(dir + "/ANSUR_II_MALE_Public.csv")) {
    state.SkipWithError("open models or ANSUR II files missing");
    return;
  }
  setenv("CALIPER_ASSETS", assets_dir().c_str(), 1);
  const std::vector<std::string> args = {"batch",
                                         "--ansur",
                                         dir + "/ANSUR_II_MALE_Public.csv",
                                         "--ansur",
                                         dir + "/ANSUR_II_FEMALE_Public.csv",
                                         "-j",
                                         std::to_string(state.range(0)),
                                         "--force",
                                         "--out",
                                         "/dev/null"};
  std::string last;
  for (auto _ : state) {
    std::ostringstream out, err;
    caliper::cli::Io io{out, err, false};
    benchmark::DoNotOptimize(caliper::cli::main_guarded(args, io));
    last = err.str();
  }
  // The batch's own line: people per second over the avatar loop (models loaded and regressors
  // trained before it).
  const size_t pos = last.find("caliper batch:");
  state.SetLabel(pos == std::string::npos ? "" : last.substr(pos, last.find('\n', pos) - pos));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * 6068);
}
BENCHMARK(BM_BatchAnsur)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

void BM_TrainRegressors_FullSizeTestModel(benchmark::State& state) {
  const smpl::BodyModel& m = full_size_test_model();
  for (auto _ : state) benchmark::DoNotOptimize(caliper::train_regressors(m));
  state.counters["vertices"] = m.num_vertices();
}
BENCHMARK(BM_TrainRegressors_FullSizeTestModel)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
