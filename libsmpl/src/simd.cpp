// Kernel variant selection (simd.hpp): CPU detection, the CALIPER_SIMD override and the
// per-thread scoped override used by tests and benchmarks.
#include "smpl/simd.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <stdexcept>

#include "smpl/enum_names.hpp"

namespace smpl {
namespace {

// -1: no scoped override on this thread; otherwise a SimdLevel value.
thread_local int t_override = -1;

bool cpu_has(SimdLevel level) {
  if (level == SimdLevel::kBaseline) return true;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  if (level == SimdLevel::kAvx2) return __builtin_cpu_supports("avx2") != 0;
  if (level == SimdLevel::kAvx512) return __builtin_cpu_supports("avx512f") != 0;
#endif
  return false;
}

SimdLevel detect() {
  SimdLevel best = SimdLevel::kBaseline;
  for (SimdLevel l : supported_simd_levels()) best = l;
  if (const char* env = std::getenv("CALIPER_SIMD")) {
    try {
      const SimdLevel asked = parse_simd_level(env);
      if (static_cast<int>(asked) < static_cast<int>(best)) best = asked;
    } catch (const std::invalid_argument&) {
      // Documented: an unknown value is ignored (a library never prints).
    }
  }
  return best;
}

}  // namespace

const char* simd_level_name(SimdLevel level) {
  static constexpr std::array<const char*, 3> kNames = {"baseline", "avx2", "avx512"};
  static_assert(kNames.size() == static_cast<std::size_t>(SimdLevel::kAvx512) + 1);
  return enum_name(level, kNames, "baseline");
}

SimdLevel parse_simd_level(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) {
    return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  });
  if (n == "baseline" || n == "sse2" || n == "default") return SimdLevel::kBaseline;
  if (n == "avx2") return SimdLevel::kAvx2;
  if (n == "avx512" || n == "avx512f") return SimdLevel::kAvx512;
  throw std::invalid_argument("unknown SIMD level '" + name + "': use baseline, avx2 or avx512");
}

std::vector<SimdLevel> supported_simd_levels() {
  std::vector<SimdLevel> out{SimdLevel::kBaseline};
  if (cpu_has(SimdLevel::kAvx2)) out.push_back(SimdLevel::kAvx2);
  if (cpu_has(SimdLevel::kAvx512)) out.push_back(SimdLevel::kAvx512);
  return out;
}

SimdLevel default_simd_level() {
  static const SimdLevel level = detect();
  return level;
}

SimdLevel simd_level() {
  return t_override >= 0 ? static_cast<SimdLevel>(t_override) : default_simd_level();
}

ScopedSimdLevel::ScopedSimdLevel(SimdLevel level) : previous_(t_override) {
  if (!cpu_has(level)) {
    throw std::invalid_argument(std::string("this CPU cannot run the ") + simd_level_name(level) +
                                " kernels");
  }
  t_override = static_cast<int>(level);
}

ScopedSimdLevel::~ScopedSimdLevel() {
  t_override = previous_;
}

}  // namespace smpl
