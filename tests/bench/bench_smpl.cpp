// libsmpl benchmarks on a full-size SMPL-shaped model (6890 vertices, 13776 faces, 24 joints,
// 10 betas, 207 pose features; tests/support make_random_model). Run on one core:
//   taskset -c 1 build/bin/bench_smpl --benchmark_repetitions=10
//     --benchmark_report_aggregates_only=true   (one line)
// Every kernel benchmark runs once per SIMD variant this CPU has (smpl::ScopedSimdLevel; the name
// ends in /baseline, /avx2 or /avx512), each next to the bare read of the same array with that
// variant's vector width (BM_StreamSum/...), so each variant is compared with its own bandwidth
// bound in the same run. The variants the CPU has are printed in the context ("simd_levels").
// BM_ShapeTraffic/<variant> is the shape kernel's whole memory traffic done bare, and
// BM_StreamSum/l2_edge_* the bare read from 1.65 to 3.3 MB: where this CPU's L2 ends.
// The pose blend shapes are a 20670 x 207 double matrix (34 MB) read once per posed evaluation.
// --write_model=PATH and --write_reference=PATH write the model and reference vertices for
// tools/bench_vs_smplx.py instead of running benchmarks (see write_files below).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"
#include "smpl/npz.hpp"
#include "smpl/simd.hpp"

namespace {

// The full-size random test model, or the model file named by CALIPER_BENCH_MODEL (as
// tools/bench_vs_smplx.py does to time the user's own SMPL file), with its first 10 betas.
const smpl::BodyModel& model() {
  static const smpl::BodyModel m = [] {
    if (const char* path = std::getenv("CALIPER_BENCH_MODEL")) {
      smpl::LoadOptions options;
      options.num_betas = 10;
      return smpl::load_model(path, options);
    }
    return caliper::test::make_random_model(10, 24, true, 1);
  }();
  return m;
}

// Plain sum over an array as large as posedirs (double) or its float copy, or as shapedirs: the
// bandwidth bound. Vectorised like the library's kernels (GCC/Clang vector extension, vectors of
// the variant's register width, 4 independent accumulators), one function per variant.
template <typename T, int kBytes>
inline __attribute__((always_inline)) T stream_sum_body(const T* a, size_t n) {
  typedef T V __attribute__((vector_size(kBytes)));
  constexpr size_t kLanes = kBytes / sizeof(T);
  V s0 = {}, s1 = {}, s2 = {}, s3 = {};
  size_t i = 0;
  for (; i + 4 * kLanes <= n; i += 4 * kLanes) {
    V x0, x1, x2, x3;
    std::memcpy(&x0, a + i, kBytes);
    std::memcpy(&x1, a + i + kLanes, kBytes);
    std::memcpy(&x2, a + i + 2 * kLanes, kBytes);
    std::memcpy(&x3, a + i + 3 * kLanes, kBytes);
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

// out[i] = a[i] + 1 with the same vectors: one read stream and one write stream.
template <typename T, int kBytes>
inline __attribute__((always_inline)) void stream_copy_body(const T* a, size_t n, T* out) {
  typedef T V __attribute__((vector_size(kBytes)));
  constexpr size_t kLanes = kBytes / sizeof(T);
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    V x;
    std::memcpy(&x, a + i, kBytes);
    x += T{1};
    std::memcpy(out + i, &x, kBytes);
  }
  for (; i < n; ++i) out[i] = a[i] + T{1};
}

template <typename T>
T stream_sum_baseline(const T* a, size_t n) {
  return stream_sum_body<T, 16>(a, n);
}
template <typename T>
void stream_copy_baseline(const T* a, size_t n, T* out) {
  stream_copy_body<T, 16>(a, n, out);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
template <typename T>
__attribute__((target("avx2"))) T stream_sum_avx2(const T* a, size_t n) {
  return stream_sum_body<T, 32>(a, n);
}
template <typename T>
__attribute__((target("avx512f"))) T stream_sum_avx512(const T* a, size_t n) {
  return stream_sum_body<T, 64>(a, n);
}
template <typename T>
__attribute__((target("avx2"))) void stream_copy_avx2(const T* a, size_t n, T* out) {
  stream_copy_body<T, 32>(a, n, out);
}
template <typename T>
__attribute__((target("avx512f"))) void stream_copy_avx512(const T* a, size_t n, T* out) {
  stream_copy_body<T, 64>(a, n, out);
}
#endif

template <typename T>
T stream_sum(smpl::SimdLevel level, const T* a, size_t n) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (level == smpl::SimdLevel::kAvx512) return stream_sum_avx512(a, n);
  if (level == smpl::SimdLevel::kAvx2) return stream_sum_avx2(a, n);
#endif
  (void)level;
  return stream_sum_baseline(a, n);
}

template <typename T>
void stream_copy(smpl::SimdLevel level, const T* a, size_t n, T* out) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (level == smpl::SimdLevel::kAvx512) return stream_copy_avx512(a, n, out);
  if (level == smpl::SimdLevel::kAvx2) return stream_copy_avx2(a, n, out);
#endif
  (void)level;
  stream_copy_baseline(a, n, out);
}

template <typename T>
void BM_StreamSum(benchmark::State& state, smpl::SimdLevel level, size_t columns) {
  const size_t n = 20670 * columns;
  std::vector<T> a(n);
  for (size_t i = 0; i < n; ++i) a[i] = static_cast<T>(i % 7);
  for (auto _ : state) {
    T sum = stream_sum(level, a.data(), n);
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(n * sizeof(T)));
}

// The shape kernel's own memory traffic without its arithmetic: read the model's shapedirs and
// v_template once and write a vertex array once (what smpl::shape cannot avoid; 1.98 MB on the
// full-size model). On a CPU whose L2 holds the 1.65 MB shapedirs but not these 1.98 MB, the bare
// read of shapedirs alone comes from L2 while the kernel's data cannot: this is the bound the
// kernel is compared with there as well (docs/performance.md).
void BM_ShapeTraffic(benchmark::State& state, smpl::SimdLevel level) {
  const auto& m = model();
  smpl::Vertices out(m.v_template.rows(), 3);
  const auto ns = static_cast<size_t>(m.shapedirs.size());
  const auto nt = static_cast<size_t>(m.v_template.size());
  for (auto _ : state) {
    double sum = stream_sum(level, m.shapedirs.data(), ns);
    stream_copy(level, m.v_template.data(), nt, out.data());
    benchmark::DoNotOptimize(sum);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>((ns + 2 * nt) * sizeof(double)));
}

void BM_Shape(benchmark::State& state, smpl::SimdLevel level) {
  const smpl::ScopedSimdLevel pin(level);
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 2);
  smpl::Body body;
  for (auto _ : state) {
    smpl::shape(m, betas, body);
    benchmark::DoNotOptimize(body.vertices.data());
    benchmark::ClobberMemory();
  }
}

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
void BM_Evaluate(benchmark::State& state, smpl::SimdLevel level) {
  const smpl::ScopedSimdLevel pin(level);
  const auto& m = model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 3);
  Eigen::VectorXd pose = caliper::test::random_pose(24, 1.0, 4);
  for (int k = 1 + static_cast<int>(state.range(1)); k < 24; ++k)
    pose.segment<3>(3 * Eigen::Index{k}).setZero();
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

// A model shaped like the open v2 models (13,322 vertices) whose correctives act near their
// joint only: each joint's 9 columns non-zero on a fifth of the rows (the v2 models: 21 % in
// all), a different fifth per joint.
const smpl::BodyModel& local_correctives_model() {
  static const smpl::BodyModel m = [] {
    caliper::test::RandomModelOptions o;
    o.rings = 120;
    o.segments = 111;
    smpl::BodyModel r = caliper::test::make_random_model(o);
    const Eigen::Index rows = r.posedirs.rows();
    for (Eigen::Index j = 0; j < 23; ++j) {
      const Eigen::Index first = j * rows / 23, length = rows / 5;
      for (Eigen::Index row = 0; row < rows; ++row) {
        if ((row - first + rows) % rows >= length) r.posedirs.block(row, 9 * j, 1, 9).setZero();
      }
    }
    return r;
  }();
  return m;
}

// One body, every joint rotated, with local correctives: the workspace's map of the rows each
// joint touches (range(0) = 1) against none (0), double (range(1) = 0) or float posedirs.
void BM_EvaluateLocalCorrectives(benchmark::State& state, smpl::SimdLevel level) {
  const smpl::ScopedSimdLevel pin(level);
  const auto& m = local_correctives_model();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 3);
  const Eigen::VectorXd pose = caliper::test::random_pose(24, 1.0, 4);
  smpl::Workspace ws;
  ws.skip_zero_pose_rows = state.range(0) == 1;
  ws.single_precision_pose_blend_shapes = state.range(1) == 1;
  smpl::Body body;
  smpl::evaluate(m, betas, pose, Eigen::Vector3d::Zero(), ws, body);  // sizes, makes the map
  for (auto _ : state) {
    smpl::evaluate(m, betas, pose, Eigen::Vector3d::Zero(), ws, body);
    benchmark::DoNotOptimize(body.vertices.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(std::string(state.range(0) == 1 ? "map" : "no map") + ", " +
                 (state.range(1) == 1 ? "float" : "double") + " posedirs, 13,322 vertices");
}

// N random bodies' betas (and poses), as the batch API takes them.
smpl::RowMatrixXd batch_betas(int n) {
  smpl::RowMatrixXd b(n, 10);
  for (int i = 0; i < n; ++i)
    b.row(i) =
        caliper::test::random_betas(10, 1.0, 100 + static_cast<std::uint64_t>(i)).transpose();
  return b;
}

smpl::RowMatrixXd batch_poses(int n, int num_joints) {
  smpl::RowMatrixXd poses(n, 3 * num_joints);
  for (int i = 0; i < n; ++i)
    poses.row(i) = caliper::test::random_pose(num_joints, 1.0, 900 + static_cast<std::uint64_t>(i))
                       .transpose();
  return poses;
}

// smpl::shape_batch: range(0) = N bodies, range(1) = threads; kFloat: into float vertices and
// joints (BodyBatchF). "per_body" is the time per body (CPU time of the calling thread for 1
// thread; with more threads the benchmark uses wall time, and bodies_per_s is the throughput of
// all of them).
template <bool kFloat>
void BM_ShapeBatch(benchmark::State& state, smpl::SimdLevel level) {
  const smpl::ScopedSimdLevel pin(level);
  const auto& m = model();
  const int n = static_cast<int>(state.range(0)), threads = static_cast<int>(state.range(1));
  const smpl::RowMatrixXd betas = batch_betas(n);
  smpl::Workspace ws;
  std::conditional_t<kFloat, smpl::BodyBatchF, smpl::BodyBatch> out;
  const auto run = [&] {
    if constexpr (kFloat) {
      smpl::shape_batch(m, betas, ws, out, threads);
    } else {
      smpl::shape_batch(m, betas, out, threads);
    }
  };
  run();
  for (auto _ : state) {
    run();
    benchmark::DoNotOptimize(out.vertices.data());
    benchmark::ClobberMemory();
  }
  state.counters["bodies_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["per_body_us"] = benchmark::Counter(
      1e-6 * n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// smpl::evaluate_batch, every joint rotated: range(0) = N, range(1) = 1 for float posedirs,
// range(2) = threads.
void BM_EvaluateBatch(benchmark::State& state, smpl::SimdLevel level) {
  const smpl::ScopedSimdLevel pin(level);
  const auto& m = model();
  const int n = static_cast<int>(state.range(0)), threads = static_cast<int>(state.range(2));
  const smpl::RowMatrixXd betas = batch_betas(n);
  const smpl::RowMatrixXd poses = batch_poses(n, m.num_joints());
  smpl::Workspace ws;
  ws.single_precision_pose_blend_shapes = state.range(1) == 1;
  smpl::BodyBatch out;
  smpl::evaluate_batch(m, betas, poses, smpl::RowMatrixXd(0, 3), ws, out, threads);
  for (auto _ : state) {
    smpl::evaluate_batch(m, betas, poses, smpl::RowMatrixXd(0, 3), ws, out, threads);
    benchmark::DoNotOptimize(out.vertices.data());
    benchmark::ClobberMemory();
  }
  state.counters["bodies_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["per_body_us"] = benchmark::Counter(
      1e-6 * n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(state.range(1) == 1 ? "float posedirs" : "double posedirs");
}

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

// Every kernel benchmark once per variant this CPU has, named .../<variant>.
void register_per_variant() {
  std::vector<int> custom_batches;
  if (const char* sizes = std::getenv("CALIPER_BENCH_BATCH_SIZES")) {
    std::string list = sizes;
    for (size_t pos = 0; pos < list.size();) {
      const size_t comma = std::min(list.find(',', pos), list.size());
      const int n = std::atoi(list.substr(pos, comma - pos).c_str());
      if (n > 0) custom_batches.push_back(n);
      pos = comma + 1;
    }
  }
  // The bare read's bandwidth against the array's size (1.65 MB = shapedirs, 1.98 MB = the shape
  // kernel's traffic, up to 3.3 MB), best variant: where the L2 cache ends on this CPU.
  for (size_t columns : {10, 11, 12, 13, 14, 20}) {
    const std::string name = "BM_StreamSum/l2_edge_f64_" +
                             std::to_string(columns * 20670 * 8 / 1000) + "KB/" +
                             smpl::simd_level_name(smpl::default_simd_level());
    benchmark::RegisterBenchmark(name.c_str(), BM_StreamSum<double>, smpl::default_simd_level(),
                                 columns)
        ->Unit(benchmark::kMicrosecond);
  }
  std::string levels;
  for (smpl::SimdLevel level : smpl::supported_simd_levels()) {
    const std::string v = smpl::simd_level_name(level);
    levels += (levels.empty() ? "" : " ") + v;
    benchmark::RegisterBenchmark(("BM_StreamSum/shapedirs_f64_1.65MB/" + v).c_str(),
                                 BM_StreamSum<double>, level, size_t{10})
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_Shape/" + v).c_str(), BM_Shape, level)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_ShapeTraffic/" + v).c_str(), BM_ShapeTraffic, level)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_StreamSum/posedirs_f64_34MB/" + v).c_str(),
                                 BM_StreamSum<double>, level, size_t{207})
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_StreamSum/posedirs_f32_17MB/" + v).c_str(),
                                 BM_StreamSum<float>, level, size_t{207})
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_EvaluateLocalCorrectives/" + v).c_str(),
                                 BM_EvaluateLocalCorrectives, level)
        ->Args({0, 0})
        ->Args({1, 0})
        ->Args({0, 1})
        ->Args({1, 1})
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_Evaluate/" + v).c_str(), BM_Evaluate, level)
        ->Args({0, 23})
        ->Args({1, 23})
        ->Args({0, 5})
        ->Args({0, 0})
        ->Unit(benchmark::kMicrosecond);
    if (!custom_batches.empty()) {
      // CALIPER_BENCH_BATCH_SIZES (tools/bench_vs_smplx.py): these batch sizes, one thread
      // (CPU time), and shape only with two threads (wall time, .../2/real_time).
      for (int n : custom_batches) {
        benchmark::RegisterBenchmark(("BM_ShapeBatch/" + v).c_str(), BM_ShapeBatch<false>, level)
            ->Args({n, 1})
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("BM_ShapeBatch/" + v).c_str(), BM_ShapeBatch<false>, level)
            ->Args({n, 2})
            ->UseRealTime()
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("BM_ShapeBatchF/" + v).c_str(), BM_ShapeBatch<true>, level)
            ->Args({n, 1})
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("BM_EvaluateBatch/" + v).c_str(), BM_EvaluateBatch, level)
            ->Args({n, 0, 1})
            ->Args({n, 1, 1})
            ->Unit(benchmark::kMicrosecond);
      }
      continue;
    }
    benchmark::RegisterBenchmark(("BM_ShapeBatch/" + v).c_str(), BM_ShapeBatch<false>, level)
        ->Args({1, 1})
        ->Args({64, 1})
        ->Args({1024, 1})
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_ShapeBatchF/" + v).c_str(), BM_ShapeBatch<true>, level)
        ->Args({1, 1})
        ->Args({64, 1})
        ->Args({1024, 1})
        ->Unit(benchmark::kMicrosecond);
    // Two threads: N = 1024 writes 170 MB per pass (bound by writing it to memory); 64-256
    // bodies (10-42 MB of output, the smaller ones within the 32 MB L3) are what a caller
    // processing a large set in chunks would use.
    benchmark::RegisterBenchmark(("BM_ShapeBatch/" + v).c_str(), BM_ShapeBatch<false>, level)
        ->Args({64, 2})
        ->Args({128, 2})
        ->Args({256, 2})
        ->Args({1024, 2})
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_EvaluateBatch/" + v).c_str(), BM_EvaluateBatch, level)
        ->Args({1, 0, 1})
        ->Args({64, 0, 1})
        ->Args({256, 0, 1})
        ->Args({1, 1, 1})
        ->Args({64, 1, 1})
        ->Args({256, 1, 1})
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_EvaluateBatch/" + v).c_str(), BM_EvaluateBatch, level)
        ->Args({256, 0, 2})
        ->Args({256, 1, 2})
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::AddCustomContext("simd_levels", levels);
  benchmark::AddCustomContext("simd_default", smpl::simd_level_name(smpl::default_simd_level()));
}

// --write_model=PATH: the benchmarks' model (the random one, or CALIPER_BENCH_MODEL's) as an
// SMPL-layout .npz (v_template, shapedirs, posedirs, J_regressor, weights, kintree_table, f), the
// file tools/bench_vs_smplx.py gives both sides. --write_reference=PATH: for that model, the
// betas and poses of the first 8 bodies of the batch benchmarks and libsmpl's vertices for them
// (shape_batch in double and float; evaluate_batch with double and float pose blend shapes), so
// that the script can check that smplx computes the same bodies before it times them.
void write_reference(const std::string& path) {
  const auto& m = model();
  constexpr int kBodies = 8;
  const smpl::RowMatrixXd betas = batch_betas(kBodies);
  const smpl::RowMatrixXd poses = batch_poses(kBodies, m.num_joints());
  smpl::NpzArchive out;
  out["betas"] = smpl::make_npy(betas);
  out["poses"] = smpl::make_npy(poses);
  smpl::BodyBatch batch;
  smpl::shape_batch(m, betas, batch);
  out["shape_vertices"] = smpl::make_npy(batch.vertices);
  out["shape_joints"] = smpl::make_npy(batch.joints);
  smpl::Workspace fws;
  smpl::BodyBatchF batch_f;
  smpl::shape_batch(m, betas, fws, batch_f);
  out["shape_vertices_float"] = smpl::make_npy(smpl::RowMatrixXd(batch_f.vertices.cast<double>()));
  out["shape_joints_float"] = smpl::make_npy(smpl::RowMatrixXd(batch_f.joints.cast<double>()));
  for (const bool single : {false, true}) {
    smpl::Workspace ws;
    ws.single_precision_pose_blend_shapes = single;
    smpl::evaluate_batch(m, betas, poses, smpl::RowMatrixXd(0, 3), ws, batch);
    out[single ? "posed_vertices_float" : "posed_vertices_double"] = smpl::make_npy(batch.vertices);
    out[single ? "posed_joints_float" : "posed_joints_double"] = smpl::make_npy(batch.joints);
  }
  smpl::write_npz(path, out);
}

// Handles --write_model= and --write_reference= (before the benchmark flags): returns the exit
// code when one was given, -1 otherwise.
int write_files(int argc, char** argv) {
  int done = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    for (const char* flag : {"--write_model=", "--write_reference="}) {
      if (arg.rfind(flag, 0) != 0) continue;
      const std::string path = arg.substr(std::strlen(flag));
      try {
        if (std::strcmp(flag, "--write_model=") == 0) {
          smpl::save_model(model(), path);
        } else {
          write_reference(path);
        }
        done = 0;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_smpl: %s: %s\n", flag, e.what());
        return 1;
      }
    }
  }
  return done;
}

}  // namespace

int main(int argc, char** argv) {
  if (const int code = write_files(argc, argv); code >= 0) return code;
  register_per_variant();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
