// libsmpl benchmarks on a full-size SMPL-shaped model (6890 vertices, 13776 faces, 24 joints,
// 10 betas, 207 pose features; tests/support make_random_model). Run on one core:
//   taskset -c 1 build/bin/bench_smpl --benchmark_repetitions=10
//     --benchmark_report_aggregates_only=true   (one line)
// The pose blend shapes are a 20670 x 207 double matrix (34 MB) read once per posed evaluation;
// BM_StreamSum measures how fast this machine reads an array of that size in the same run, so the
// posed evaluation can be compared with the memory (or last-level cache) bandwidth.
#include <benchmark/benchmark.h>

#include <cstring>
#include <string>
#include <vector>

#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/gltf.hpp"

namespace {

const smpl::BodyModel& model() {
  static const smpl::BodyModel m = caliper::test::make_random_model(10, 24, true, 1);
  return m;
}

// Plain sum over an array as large as posedirs (double) or its float copy, or as shapedirs: the
// bandwidth bound. Vectorised like the library's kernels (GCC/Clang vector extension, 64-byte
// vectors, 4 independent accumulators) and multi-versioned for AVX-512 / AVX2 / baseline.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define BENCH_MULTIVERSION __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define BENCH_MULTIVERSION
#endif
template <typename T>
BENCH_MULTIVERSION T stream_sum(const T* a, size_t n) {
  typedef T V __attribute__((vector_size(64)));
  constexpr size_t kLanes = 64 / sizeof(T);
  V s0 = {}, s1 = {}, s2 = {}, s3 = {};
  size_t i = 0;
  for (; i + 4 * kLanes <= n; i += 4 * kLanes) {
    V x0, x1, x2, x3;
    std::memcpy(&x0, a + i, 64);
    std::memcpy(&x1, a + i + kLanes, 64);
    std::memcpy(&x2, a + i + 2 * kLanes, 64);
    std::memcpy(&x3, a + i + 3 * kLanes, 64);
    s0 += x0;
    s1 += x1;
    s2 += x2;
    s3 += x3;
  }
  const V s = (s0 + s1) + (s2 + s3);
  T total = 0;
  for (size_t k = 0; k < kLanes; ++k) total += s[k];
  for (; i < n; ++i) total += a[i];
  return total;
}

template <typename T, size_t kColumns>
void BM_StreamSum(benchmark::State& state) {
  const size_t n = 20670 * kColumns;
  std::vector<T> a(n);
  for (size_t i = 0; i < n; ++i) a[i] = static_cast<T>(i % 7);
  for (auto _ : state) {
    T sum = stream_sum(a.data(), n);
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(n * sizeof(T)));
}
BENCHMARK_TEMPLATE(BM_StreamSum, double, 207)->Name("BM_StreamSum/posedirs_f64_34MB");
BENCHMARK_TEMPLATE(BM_StreamSum, float, 207)->Name("BM_StreamSum/posedirs_f32_17MB");
// The same for shapedirs with 10 betas (1.65 MB: stays in this machine's 2 MB per-core L2).
BENCHMARK_TEMPLATE(BM_StreamSum, double, 10)
    ->Name("BM_StreamSum/shapedirs_f64_1.65MB")
    ->Unit(benchmark::kMicrosecond);

void BM_Shape(benchmark::State& state) {
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 2);
  smpl::Body body;
  for (auto _ : state) {
    smpl::shape(m, betas, body);
    benchmark::DoNotOptimize(body.vertices.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Shape)->Unit(benchmark::kMicrosecond);

void BM_ShapeReturningBody(benchmark::State& state) {
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 2);
  for (auto _ : state) {
    smpl::Body body = smpl::shape(m, betas);
    benchmark::DoNotOptimize(body.vertices.data());
  }
}
BENCHMARK(BM_ShapeReturningBody)->Unit(benchmark::kMicrosecond);

// Full posed evaluation; range(0) = 1 for the single-precision pose blend shapes, range(1) = how
// many joints are rotated (23 = all but the root: every pose-blend-shape column is read).
void BM_Evaluate(benchmark::State& state) {
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 3);
  Eigen::VectorXd pose = caliper::test::random_pose(24, 1.0, 4);
  for (int k = 1 + static_cast<int>(state.range(1)); k < 24; ++k) pose.segment<3>(3 * k).setZero();
  smpl::Workspace ws;
  ws.single_precision_pose_blend_shapes = state.range(0) == 1;
  smpl::Body body;
  smpl::evaluate(m, betas, pose, Eigen::Vector3d::Zero(), ws, body);  // sizes the buffers
  for (auto _ : state) {
    smpl::evaluate(m, betas, pose, Eigen::Vector3d::Zero(), ws, body);
    benchmark::DoNotOptimize(body.vertices.data());
    benchmark::ClobberMemory();
  }
  const int64_t bytes =
      static_cast<int64_t>(m.posedirs.size()) * (state.range(0) == 1 ? 4 : 8) * state.range(1) / 23;
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * bytes);
  state.SetLabel(std::string(state.range(0) == 1 ? "float" : "double") + " posedirs, " +
                 std::to_string(state.range(1)) + " rotated joints");
}
BENCHMARK(BM_Evaluate)
    ->Args({0, 23})
    ->Args({1, 23})
    ->Args({0, 5})
    ->Args({0, 0})
    ->Unit(benchmark::kMicrosecond);

void BM_GlbExport(benchmark::State& state) {
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 5);
  size_t size = 0;
  for (auto _ : state) {
    const auto bytes = smpl::glb_bytes(m, betas);
    size = bytes.size();
    benchmark::DoNotOptimize(bytes.data());
  }
  state.SetLabel(std::to_string(size) + " bytes");
}
BENCHMARK(BM_GlbExport)->Unit(benchmark::kMillisecond);

void BM_GlbWriteFile(benchmark::State& state) {
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 5);
  for (auto _ : state) smpl::write_gltf("/tmp/caliper_bench_avatar.glb", m, betas);
}
BENCHMARK(BM_GlbWriteFile)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
