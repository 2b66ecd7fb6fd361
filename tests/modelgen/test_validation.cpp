// Unit tests of the validation's parts (validation.hpp): the RNG and the statistics table round
// trip; and the arithmetic guard that keeps the generator's bytes the same
// whatever cache sizes Eigen detects on the CPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "ansur_stats.hpp"
#include "smpl/constants.hpp"
#include "validation.hpp"

namespace {

modelgen::SurveyStats committed_stats() {
  return modelgen::read_stats_table(std::string(CALIPER_MODELS_DIR) + "/ansur_stats.csv");
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) {
    return {};
  }
  const std::streamsize n = in.tellg();
  std::string out(static_cast<std::size_t>(n), '\0');
  in.seekg(0);
  in.read(out.data(), n);
  return out;
}

TEST(Rng, IsDeterministicAndStandardNormal) {
  modelgen::Rng a(42), b(42), c(43);
  EXPECT_EQ(a.next(), b.next());
  EXPECT_NE(a.next(), c.next());
  modelgen::Rng r(7);
  const int n = 200000;
  double sum = 0, sq = 0;
  for (int i = 0; i < n; ++i) {
    const double x = r.normal();
    sum += x;
    sq += x * x;
  }
  const double mean = sum / n, var = sq / n - mean * mean;
  constexpr double kTol = 0.01;  // about 4.5 standard errors at n = 200000
  EXPECT_NEAR(mean, 0.0, kTol);
  EXPECT_NEAR(var, 1.0, 2 * kTol);
}

}  // namespace

TEST(StatsTable, RoundTripsAndHoldsSurveyFigures) {
  const modelgen::SurveyStats st = committed_stats();
  EXPECT_EQ(st.female.count, 1986);
  EXPECT_EQ(st.male.count, 4082);
  EXPECT_NEAR(st.female.mean[modelgen::kStature], 1.6285, 0.001);
  EXPECT_NEAR(st.male.mean[modelgen::kWeight], 85.52, 0.05);
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/modelgen_stats_roundtrip.csv";
  modelgen::write_stats_table(st, path);
  const modelgen::SurveyStats back = modelgen::read_stats_table(path);
  EXPECT_TRUE(back.male.mean.isApprox(st.male.mean, 1e-8));
  EXPECT_TRUE(back.female.correlation.isApprox(st.female.correlation, 1e-5));
  modelgen::write_stats_table(back, path + "2");
  EXPECT_EQ(read_bytes(path), read_bytes(path + "2"));
}

// The guard pins Eigen's cache sizes (which size the blocks of its matrix products, and with them
// the order of the sums) for its lifetime and gives back the CPU's when it ends.
TEST(DeterministicNumerics, PinsEigensCacheSizesAndRestoresThem) {
  const std::ptrdiff_t l1 = Eigen::l1CacheSize(), l2 = Eigen::l2CacheSize(),
                       l3 = Eigen::l3CacheSize();
  constexpr std::ptrdiff_t kKiB = 1024;
  for (const std::ptrdiff_t small : {16 * kKiB, 48 * kKiB}) {
    Eigen::setCpuCacheSizes(small, 8 * small, 64 * small);  // a laptop core, a server core
    {
      const modelgen::DeterministicNumerics pinned;
      EXPECT_EQ(Eigen::l1CacheSize(), 32 * kKiB);
      EXPECT_EQ(Eigen::l2CacheSize(), 512 * kKiB);
      EXPECT_EQ(Eigen::l3CacheSize(), 4 * kKiB * kKiB);
    }
    EXPECT_EQ(Eigen::l1CacheSize(), small) << "the guard did not restore them";
  }
  Eigen::setCpuCacheSizes(l1, l2, l3);
}
