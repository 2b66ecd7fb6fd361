// Unit tests of the generator's parts: RNG, Catmull-Clark operator, cage invariants,
// statistics table round trip, and byte-identical output for identical settings.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "ansur_stats.hpp"
#include "cage.hpp"
#include "caliper/volume.hpp"
#include "generator.hpp"
#include "mesh_checks.hpp"
#include "smpl/io.hpp"
#include "smpl/simd.hpp"
#include "subdivision.hpp"

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

// A unit cube as 6 quads, counter-clockwise seen from outside.
std::vector<std::array<int, 4>> cube_quads() {
  return {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
}
Eigen::MatrixXd cube_points() {
  Eigen::MatrixXd p(8, 3);
  p << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  return p;
}

smpl::Faces triangulate(const std::vector<std::array<int, 4>>& q) {
  smpl::Faces f(static_cast<Eigen::Index>(2 * q.size()), 3);
  for (std::size_t i = 0; i < q.size(); ++i) {
    f.row(static_cast<Eigen::Index>(2 * i)) << q[i][0], q[i][1], q[i][2];
    f.row(static_cast<Eigen::Index>(2 * i + 1)) << q[i][0], q[i][2], q[i][3];
  }
  return f;
}

TEST(CatmullClark, CubeCountsRowsAndShrinkage) {
  const modelgen::Subdivision s1 = modelgen::catmull_clark(8, cube_quads(), 1);
  EXPECT_EQ(s1.s.rows(), 8 + 12 + 6);  // V + E + F
  EXPECT_EQ(s1.quads.size(), 24u);
  const modelgen::Subdivision s2 = modelgen::catmull_clark(8, cube_quads(), 2);
  EXPECT_EQ(s2.s.rows(), 98);
  EXPECT_EQ(s2.quads.size(), 96u);
  for (int r = 0; r < s2.s.rows(); ++r) {
    EXPECT_NEAR(s2.s.row(r).sum(), 1.0, 1e-12);  // affine: rows sum to 1
  }
  // known first-level positions: a corner goes to (F + 2R + (n-3)P)/n with n = 3
  const Eigen::MatrixXd p1 = s1.s * cube_points();
  // Q = mean of the face centres around (0,0,0) = (1/3,1/3,1/3); R = mean of the edge
  // midpoints = (1/6,1/6,1/6); (Q + 2R + 0 P) / 3 = (2/9, 2/9, 2/9)
  EXPECT_NEAR(p1(0, 0), 2.0 / 9.0, 1e-12);
  EXPECT_NEAR(p1(0, 1), 2.0 / 9.0, 1e-12);
  // closed, oriented, positive volume that shrinks with each level (the limit surface lies
  // inside the cage)
  smpl::Vertices v = s2.s * cube_points();
  const smpl::Faces f = triangulate(s2.quads);
  const auto rep = modelgen::topology_report(static_cast<int>(v.rows()), f);
  EXPECT_TRUE(rep.closed);
  EXPECT_TRUE(rep.oriented);
  EXPECT_EQ(rep.euler, 2);
  const double vol = caliper::mesh_volume(v, f);
  const smpl::Vertices v1 = s1.s * cube_points();
  const double vol1 = caliper::mesh_volume(v1, triangulate(s1.quads));
  EXPECT_LT(vol1, 1.0);
  EXPECT_LT(vol, vol1);
  EXPECT_GT(vol, 0.25);  // contains the sphere of radius 0.39 about the centre
  // face points: the first-level face point of face 1 (z = 1) is the centre of that face
  const Eigen::MatrixXd p2 = s2.s * cube_points();
  EXPECT_NEAR(p1(s1.face_point[1], 2), 1.0, 1e-12);
  EXPECT_NEAR(p2(s2.face_point[1], 0), 0.5, 1e-12);
}

TEST(Cage, TopologyIsTheSameForEveryBodyAndSymmetric) {
  const modelgen::SurveyStats st = committed_stats();
  const modelgen::Cage f = modelgen::build_cage(st.female.mean, true);
  Eigen::VectorXd big = st.male.mean + 2 * st.male.sd;
  const modelgen::Cage m = modelgen::build_cage(big, false, 1.3);
  ASSERT_EQ(f.quads, m.quads);
  ASSERT_EQ(f.positions.size(), m.positions.size());
  EXPECT_EQ(f.mirror, m.mirror);
  for (std::size_t v = 0; v < f.positions.size(); ++v) {
    const int w = f.mirror[v];
    ASSERT_EQ(f.mirror[static_cast<std::size_t>(w)], static_cast<int>(v));
    EXPECT_NEAR(f.positions[v].x(), -f.positions[static_cast<std::size_t>(w)].x(), 1e-12);
    EXPECT_NEAR(f.positions[v].y(), f.positions[static_cast<std::size_t>(w)].y(), 1e-12);
    double sum = 0;
    for (const auto& s : f.skin[v]) {
      sum += s.second;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
  ASSERT_EQ(f.joints.size(), 24u);
  for (const auto& j : f.joints) {
    double sum = 0;
    for (const auto& s : j) {
      sum += s.second;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
  // the refined cage is a closed oriented sphere
  const modelgen::Subdivision s =
      modelgen::catmull_clark(static_cast<int>(f.positions.size()), f.quads, 1);
  const auto rep = modelgen::topology_report(static_cast<int>(s.s.rows()), triangulate(s.quads));
  EXPECT_TRUE(rep.closed);
  EXPECT_TRUE(rep.oriented);
  EXPECT_TRUE(rep.vertex_manifold);
  EXPECT_EQ(rep.euler, 2);
}

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

TEST(Generator, SameSettingsGiveTheSameBytes) {
  const modelgen::SurveyStats st = committed_stats();
  modelgen::GeneratorOptions o;
  o.population = 120;
  o.components = 4;
  o.calibration_rounds = 1;
  o.calibration_bodies = 60;
  const std::string a = std::string(CALIPER_TEST_DATA_DIR) + "/modelgen_det_a.npz";
  const std::string b = std::string(CALIPER_TEST_DATA_DIR) + "/modelgen_det_b.npz";
  smpl::SaveOptions so;
  so.compress = true;
  smpl::save_model(modelgen::generate_model(st, "male", o, nullptr), a, so);
  smpl::save_model(modelgen::generate_model(st, "male", o, nullptr), b, so);
  const std::string ba = read_bytes(a);
  EXPECT_FALSE(ba.empty());
  EXPECT_EQ(ba, read_bytes(b));
  const smpl::BodyModel m = smpl::load_model(a);
  EXPECT_EQ(m.num_betas(), 4);
}

}  // namespace

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

namespace {

// Small settings for the determinism tests (a few seconds per model).
modelgen::GeneratorOptions small_options() {
  modelgen::GeneratorOptions o;
  o.population = 120;
  o.components = 4;
  o.calibration_rounds = 1;
  o.calibration_bodies = 60;
  return o;
}

std::string generated_bytes(const std::string& name) {
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/" + name;
  smpl::SaveOptions so;
  so.compress = true;
  smpl::save_model(modelgen::generate_model(committed_stats(), "female", small_options(), nullptr),
                   path, so);
  return read_bytes(path);
}

}  // namespace

// Issue 18: the generator's kernels run once forced to the baseline (SSE2) variant and once
// with the best variant this CPU has; the model files must be equal byte for byte.
TEST(GeneratorDeterminism, BaselineAndBestKernelVariantsGiveTheSameBytes) {
  std::string baseline;
  {
    const smpl::ScopedSimdLevel pin(smpl::SimdLevel::kBaseline);
    baseline = generated_bytes("modelgen_simd_baseline.npz");
  }
  const smpl::SimdLevel best = smpl::supported_simd_levels().back();
  const smpl::ScopedSimdLevel pin(best);
  const std::string fast = generated_bytes("modelgen_simd_best.npz");
  ASSERT_FALSE(baseline.empty());
  EXPECT_TRUE(baseline == fast) << "baseline and " << smpl::simd_level_name(best)
                                << " kernels give different model bytes";
  std::printf("[ determinism ] baseline vs %s: %zu bytes, identical: %s\n",
              smpl::simd_level_name(best), fast.size(), baseline == fast ? "yes" : "no");
}

// Eigen sizes the blocks of its matrix products from the cache sizes it detects on the CPU; two
// CPUs with different caches must still give the same model. Emulated here by setting Eigen's
// cache sizes to those of two different machines before each run.
TEST(GeneratorDeterminism, TheCpuCacheSizesDoNotChangeTheBytes) {
  const std::ptrdiff_t l1 = Eigen::l1CacheSize(), l2 = Eigen::l2CacheSize(),
                       l3 = Eigen::l3CacheSize();
  constexpr std::ptrdiff_t kKiB = 1024;
  Eigen::setCpuCacheSizes(16 * kKiB, 256 * kKiB, 1024 * kKiB);  // a small laptop core
  const std::string small = generated_bytes("modelgen_cache_small.npz");
  EXPECT_EQ(Eigen::l1CacheSize(), 16 * 1024) << "the generator's guard did not restore them";
  Eigen::setCpuCacheSizes(48 * kKiB, 2048 * kKiB, 32 * kKiB * kKiB);  // a server core
  const std::string large = generated_bytes("modelgen_cache_large.npz");
  Eigen::setCpuCacheSizes(l1, l2, l3);
  ASSERT_FALSE(small.empty());
  EXPECT_TRUE(small == large) << "the model depends on the cache sizes Eigen detects";
}
