// libsmpl file I/O benchmarks on full-size SMPL-shaped model files (6890 vertices, 13776 faces,
// 24 joints, 207 pose features; 300 betas as .npz and protocol-4 .pkl, 10 betas as a Python-2
// protocol-2 .pkl with chumpy shapedirs and a csc J_regressor). Run on one core:
//   taskset -c 1 build/bin/bench_smpl_io --benchmark_repetitions=5
//     --benchmark_report_aggregates_only=true
// Files are read from the page cache after the first iteration: the figures are parse + convert
// + validate time, not disk time.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "smpl/io.hpp"

namespace {

const std::string& data_dir() {
  static const std::string dir = [] {
    std::string d = CALIPER_BENCH_DATA_DIR;
    if (!std::ifstream(d + "/STAMP")) {
      const std::string cmd = std::string("mkdir -p '") + d + "' && '" + CALIPER_SYSTEM_PYTHON +
                              "' '" + CALIPER_IO_FIXTURE_SCRIPT + "' '" + d + "'";
      if (std::system(cmd.c_str()) != 0) std::abort();
    }
    return d;
  }();
  return dir;
}

void BM_LoadModel(benchmark::State& state, const char* file, int num_betas, bool posedirs) {
  const std::string path = data_dir() + "/" + file;
  smpl::LoadOptions o;
  o.num_betas = num_betas;
  o.load_pose_blend_shapes = posedirs;
  for (auto _ : state) {
    smpl::BodyModel m = smpl::load_model(path, o);
    benchmark::DoNotOptimize(m.v_template.data());
  }
}
BENCHMARK_CAPTURE(BM_LoadModel, npz_300betas, "full300.npz", -1, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadModel, npz_10of300betas_no_posedirs, "full300.npz", 10, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadModel, pkl_p4_300betas, "full300_p4.pkl", -1, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadModel, pkl_py2_10betas, "full10_py2.pkl", -1, true)
    ->Unit(benchmark::kMillisecond);

void BM_SaveModel(benchmark::State& state, bool compress) {
  const smpl::BodyModel m = smpl::load_model(data_dir() + "/full300.npz");
  smpl::SaveOptions o;
  o.compress = compress;
  const std::string out =
      data_dir() + (compress ? "/bench_saved_deflated.npz" : "/bench_saved.npz");
  for (auto _ : state) smpl::save_model(m, out, o);
}
BENCHMARK_CAPTURE(BM_SaveModel, stored_300betas, false)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
