/// \file simd.hpp
/// Which instruction-set variant the evaluation kernels run. The hot loops of evaluate.cpp are
/// compiled once per x86-64 level (baseline SSE2, AVX2, AVX-512F) and dispatched explicitly at
/// each call, so a test or benchmark can run every variant the CPU has, and a user or CI can pin
/// one (`CALIPER_SIMD=baseline`) to reproduce what a machine without AVX2 computes.
///
/// Contract: every variant computes each output with the same operations in the same order (the
/// project compiles with -ffp-contract=off, the kernels vectorise across independent outputs
/// only and never reassociate a sum), so all variants give bit-identical results. The test
/// Simd.EveryVariantGivesTheSameBits checks it; the open models' byte-identical regeneration on
/// every CPU relies on it (docs/models.md).
#pragma once

#include <string>
#include <vector>

namespace smpl {

/// Kernel variants, lowest first. On architectures other than x86-64 only kBaseline exists.
enum class SimdLevel { kBaseline = 0, kAvx2 = 1, kAvx512 = 2 };

/// "baseline", "avx2" or "avx512".
const char* simd_level_name(SimdLevel level);

/// Parses "baseline", "sse2" (same), "avx2", "avx512"; throws std::invalid_argument naming the
/// accepted values otherwise.
SimdLevel parse_simd_level(const std::string& name);

/// The variants this CPU (and its operating system) can run, lowest first; always has kBaseline.
std::vector<SimdLevel> supported_simd_levels();

/// The best variant this CPU runs, lowered by the environment variable CALIPER_SIMD when it
/// names a lower level (read once, at the first call). An unknown value or a level the CPU
/// lacks is ignored: the variable can lower the level, never raise it.
SimdLevel default_simd_level();

/// The variant the kernels use on the calling thread: the innermost ScopedSimdLevel of this
/// thread, else default_simd_level().
SimdLevel simd_level();

/// Pins the kernels of the calling thread to `level` for the scope's lifetime (tests and
/// benchmarks that compare variants). Throws std::invalid_argument when the CPU lacks `level`.
class ScopedSimdLevel {
 public:
  explicit ScopedSimdLevel(SimdLevel level);
  ~ScopedSimdLevel();
  ScopedSimdLevel(const ScopedSimdLevel&) = delete;
  ScopedSimdLevel& operator=(const ScopedSimdLevel&) = delete;

 private:
  int previous_;
};

}  // namespace smpl
