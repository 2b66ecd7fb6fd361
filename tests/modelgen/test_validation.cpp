// Unit tests of the validation's parts (validation.hpp): the RNG, the statistics table round trip
// and the hanging-arm length; and the arithmetic guard that keeps the generator's bytes the same
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

namespace {

// A three-vertex-per-side stand-in for a model: acromion (on the collar), wrist (on the
// elbow, which follows the shoulder) and a vertex that is the shoulder joint.
smpl::BodyModel hanging_arm_fixture() {
  smpl::BodyModel m;
  m.parents = smpl::smpl_parents();
  m.v_template.resize(6, 3);
  m.v_template << 0.20, 1.50, 0.0,  // 0 left acromion
      0.70, 1.50, 0.0,              // 1 left wrist
      0.17, 1.45, 0.0,              // 2 left shoulder joint
      -0.20, 1.50, 0.0,             // 3 right acromion
      -0.70, 1.50, 0.0,             // 4 right wrist
      -0.17, 1.45, 0.0;             // 5 right shoulder joint
  std::vector<Eigen::Triplet<double>> jr, w;
  for (int j = 0; j < 24; ++j) {
    jr.emplace_back(j, j == 17 ? 5 : 2, 1.0);
  }
  m.j_regressor.resize(24, 6);
  m.j_regressor.setFromTriplets(jr.begin(), jr.end());
  w.emplace_back(0, 13, 1.0);  // left_collar
  w.emplace_back(1, 18, 1.0);  // left_elbow
  w.emplace_back(2, 16, 1.0);
  w.emplace_back(3, 14, 1.0);  // right_collar
  w.emplace_back(4, 19, 0.5);  // right_elbow and right_wrist
  w.emplace_back(4, 21, 0.5);
  w.emplace_back(5, 17, 1.0);
  m.weights.resize(6, 24);
  m.weights.setFromTriplets(w.begin(), w.end());
  m.landmarks = {
      {"left_shoulder", {0}}, {"left_wrist", {1}}, {"right_shoulder", {3}}, {"right_wrist", {4}}};
  return m;
}

}  // namespace

// The hanging-arm length (ANSUR's protocol): the wrist swings down about the shoulder joint,
// the acromion stays. Joint (0.17, 1.45), wrist (0.70, 1.50): hanging wrist at (0.22, 0.92),
// 0.5803 m from the acromion (0.20, 1.50), against 0.50 m in the T-pose.
TEST(HangingArm, SwingsTheWristAboutTheShoulderJointAndKeepsTheAcromion) {
  const smpl::BodyModel m = hanging_arm_fixture();
  EXPECT_NEAR(modelgen::hanging_arm_length(m, m.v_template), std::hypot(0.02, 0.58), 1e-12);
  // A wrist weighted half on a joint that does not follow the shoulder moves half way.
  smpl::BodyModel half = m;
  std::vector<Eigen::Triplet<double>> w;
  for (int v = 0; v < 6; ++v) {
    for (smpl::SparseMatrix::InnerIterator it(m.weights, v); it; ++it) {
      if (v != 1) {
        w.emplace_back(v, static_cast<int>(it.col()), it.value());
      }
    }
  }
  w.emplace_back(1, 18, 0.5);
  w.emplace_back(1, 9, 0.5);  // spine3
  half.weights.setFromTriplets(w.begin(), w.end());
  const Eigen::Vector2d left =
      0.5 * Eigen::Vector2d(0.70, 1.50) + 0.5 * Eigen::Vector2d(0.22, 0.92);
  const double expected =
      0.5 * ((left - Eigen::Vector2d(0.20, 1.50)).norm() + std::hypot(0.02, 0.58));
  EXPECT_NEAR(modelgen::hanging_arm_length(half, half.v_template), expected, 1e-12);
  smpl::BodyModel missing = m;
  missing.landmarks.erase("right_wrist");
  EXPECT_THROW(modelgen::hanging_arm_length(missing, missing.v_template), std::invalid_argument);
  smpl::BodyModel few_joints = m;
  few_joints.parents.resize(16);
  EXPECT_THROW(modelgen::hanging_arm_length(few_joints, few_joints.v_template),
               std::invalid_argument);
}

// The acromion-radiale length swings the radiale as the arm length swings the wrist (the
// fixture's radiale placed on its wrist vertices gives the same length), and is NaN, not an
// error, for a model without radiale landmarks (SMPL files), which validation_measurements()
// then leaves out.
TEST(HangingArm, TheUpperArmSwingsTheRadialeAndIsMissingWithoutIt) {
  smpl::BodyModel m = hanging_arm_fixture();
  EXPECT_TRUE(std::isnan(modelgen::hanging_upper_arm_length(m, m.v_template)));
  m.landmarks["left_radiale"] = {1};
  m.landmarks["right_radiale"] = {4};
  EXPECT_NEAR(modelgen::hanging_upper_arm_length(m, m.v_template),
              modelgen::hanging_arm_length(m, m.v_template), 1e-15);
  const modelgen::HangingArms h = modelgen::hanging_arms(m, m.v_template);
  EXPECT_NEAR(h.radiale[0].x(), 0.22, 1e-12);
  EXPECT_NEAR(h.radiale[0].y(), 0.92, 1e-12);
}
