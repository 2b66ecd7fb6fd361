// Avatar export per format: the time from (model, betas) to the file on disk through
// smpl::export_avatar (shape, normals, skin, serialisation, atomic write), and for the rigged
// formats the in-memory bytes as well. Models: the open female model (13,380 vertices, 21 betas)
// and the SMPL-sized test model (6,890 vertices, 10 betas, 207 pose features, posedirs unused).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "caliper_test/random_model.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace {

const smpl::BodyModel& open_female() {
  static const smpl::BodyModel m =
      smpl::load_model(std::string(CALIPER_ASSETS_DIR) + "/models/caliper-female.npz");
  return m;
}

const smpl::BodyModel& smpl_sized() {
  static const smpl::BodyModel m = caliper::test::make_random_model(10, 24, true, 2);
  return m;
}

const smpl::BodyModel& model_of(int which) {
  return which == 0 ? open_female() : smpl_sized();
}

// The extras `caliper create` writes (a realistic size: 21 betas and 19 measurements as JSON).
smpl::ExportOptions create_like_options() {
  smpl::ExportOptions o;
  o.extras = {{"generator", "caliper 0.1.0"},       {"regressor", "R5"},
              {"model", "caliper-open-female"},     {"open_model_sex", "female"},
              {"betas", std::string(16 * 20, '1')}, {"measurements", std::string(19 * 40, '2')}};
  return o;
}

const char* const kExtensions[] = {".glb", ".gltf", ".vrm", ".fbx", ".obj", ".ply"};

void BM_ExportFile(benchmark::State& state) {
  const auto& m = model_of(static_cast<int>(state.range(1)));
  const std::string ext = kExtensions[state.range(0)];
  const Eigen::VectorXd betas = caliper::test::random_betas(m.num_betas(), 1.0, 5);
  smpl::ExportOptions o = create_like_options();
  o.licence = "MIT";  // the SMPL-sized test model states none (VRM needs one)
  const std::string path = "/tmp/caliper_bench_export" + ext;
  for (auto _ : state) smpl::export_avatar(path, m, betas, o);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  long size = 0;
  if (f) {
    std::fseek(f, 0, SEEK_END);
    size = std::ftell(f);
    std::fclose(f);
  }
  state.SetLabel(ext + (state.range(1) == 0 ? " open female " : " SMPL-sized ") +
                 std::to_string(size) + " bytes");
  std::remove(path.c_str());
}
BENCHMARK(BM_ExportFile)->ArgsProduct({{0, 1, 2, 3, 4, 5}, {0, 1}})->Unit(benchmark::kMillisecond);

// In memory (no disk): GLB, VRM and FBX bytes of the open female avatar.
void BM_ExportBytes(benchmark::State& state) {
  const auto& m = open_female();
  const Eigen::VectorXd betas = caliper::test::random_betas(m.num_betas(), 1.0, 5);
  const smpl::ExportOptions o = create_like_options();
  size_t size = 0;
  for (auto _ : state) {
    const auto bytes = state.range(0) == 0   ? smpl::glb_bytes(m, betas, o)
                       : state.range(0) == 1 ? smpl::vrm_bytes(m, betas, o)
                                             : smpl::fbx_bytes(m, betas, o);
    size = bytes.size();
    benchmark::DoNotOptimize(bytes.data());
  }
  state.SetLabel(std::string(state.range(0) == 0   ? "glb"
                             : state.range(0) == 1 ? "vrm"
                                                   : "fbx") +
                 " " + std::to_string(size) + " bytes");
}
BENCHMARK(BM_ExportBytes)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// Shape keys: 16 morph targets (every shape component) on the open female GLB.
void BM_ExportGlbShapeKeys(benchmark::State& state) {
  const auto& m = open_female();
  const Eigen::VectorXd betas = caliper::test::random_betas(m.num_betas(), 1.0, 5);
  smpl::ExportOptions o = create_like_options();
  o.shape_keys = m.num_betas();
  size_t size = 0;
  for (auto _ : state) {
    const auto bytes = smpl::glb_bytes(m, betas, o);
    size = bytes.size();
    benchmark::DoNotOptimize(bytes.data());
  }
  state.SetLabel(std::to_string(size) + " bytes");
}
BENCHMARK(BM_ExportGlbShapeKeys)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
