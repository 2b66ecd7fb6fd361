// The shared test fixture make_random_model() (tests/support) builds what it promises.
#include <gtest/gtest.h>

#include <limits>
#include <set>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"

namespace {

using caliper::test::make_random_model;

// Row sums of weights and regressor are computed from ~10 doubles: rounding only.
constexpr double kSumTol = 1e-12;

double signed_volume(const smpl::Vertices& v, const smpl::Faces& f) {
  double vol = 0.0;
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    const Eigen::Vector3d a = v.row(f(i, 0)), b = v.row(f(i, 1)), c = v.row(f(i, 2));
    vol += a.dot(b.cross(c)) / 6.0;
  }
  return vol;
}

TEST(RandomModel, HasSmplSizesAndIsClosed) {
  const auto m = make_random_model(10);
  EXPECT_EQ(m.num_vertices(), 6890);
  EXPECT_EQ(m.num_faces(), 13776);
  EXPECT_EQ(m.num_joints(), 24);
  EXPECT_EQ(m.num_betas(), 10);
  EXPECT_EQ(m.num_pose_features(), 207);
  EXPECT_EQ(m.parents, smpl::smpl_parents());
  std::set<std::pair<int, int>> edges;
  std::set<std::pair<int, int>> directed;
  for (Eigen::Index i = 0; i < m.faces.rows(); ++i) {
    for (int e = 0; e < 3; ++e) {
      const int a = m.faces(i, e), b = m.faces(i, (e + 1) % 3);
      edges.insert({std::min(a, b), std::max(a, b)});
      EXPECT_TRUE(directed.insert({a, b}).second) << "edge used twice in one direction";
    }
  }
  // Closed and consistently oriented: every directed edge has its reverse.
  for (const auto& [a, b] : directed) ASSERT_TRUE(directed.count({b, a})) << a << "-" << b;
  EXPECT_EQ(m.num_vertices() - static_cast<int>(edges.size()) + m.num_faces(), 2);
  EXPECT_EQ(edges.size(), 20664u);
  // Outward winding and a body-like volume (ellipsoid 0.36 x 1.72 x 0.24 m: 0.078 m^3).
  EXPECT_NEAR(signed_volume(m.v_template, m.faces), 0.078, 0.002);
  EXPECT_NEAR(m.v_template.col(1).minCoeff(), -1.12, 0.01);
}

TEST(RandomModel, WeightsAndRegressorRowsSumToOne) {
  for (int K : {24, 55, 16, 5}) {
    caliper::test::RandomModelOptions o;
    o.num_betas = 4;
    o.num_joints = K;
    o.pose_blend_shapes = K == 16;
    o.seed = 7;
    if (K != 24) o.rings = o.segments = 30;  // full size only where it matters: keeps this fast
    const auto m = make_random_model(o);
    EXPECT_EQ(m.num_joints(), K);
    EXPECT_NO_THROW(smpl::validate(m, "random"));
    const Eigen::VectorXd ws = m.weights * Eigen::VectorXd::Ones(K);
    const Eigen::VectorXd rs = m.j_regressor * Eigen::VectorXd::Ones(m.num_vertices());
    EXPECT_MATRIX_NEAR(ws, Eigen::VectorXd::Ones(m.num_vertices()), kSumTol);
    EXPECT_MATRIX_NEAR(rs, Eigen::VectorXd::Ones(K), kSumTol);
    for (Eigen::Index v = 0; v < m.weights.rows(); ++v) {
      EXPECT_LE(m.weights.row(v).nonZeros(), 4);
    }
    EXPECT_GE(m.weights.coeffs().minCoeff(), 0.0);
  }
}

TEST(RandomModel, DeterministicAndSeedDependent) {
  caliper::test::RandomModelOptions o;
  o.rings = o.segments = 40;
  o.seed = 3;
  const auto a = make_random_model(o);
  const auto b = make_random_model(o);
  o.seed = 4;
  const auto c = make_random_model(o);
  EXPECT_MATRIX_NEAR(a.v_template, b.v_template, 0.0);
  EXPECT_MATRIX_NEAR(a.posedirs, b.posedirs, 0.0);
  EXPECT_FALSE(caliper::test::matrices_near(a.shapedirs, c.shapedirs, 1e-6));
}

TEST(RandomModel, HasEveryVocabularyLandmarkAndAMirror) {
  const auto m = make_random_model(2, 24, false);
  for (const char* name :
       {"head_top",      "left_fingertip", "right_fingertip", "left_wrist",   "right_wrist",
        "left_shoulder", "right_shoulder", "left_elbow",      "right_elbow",  "crotch",
        "left_hip",      "right_hip",      "left_nipple",     "right_nipple", "navel",
        "left_waist",    "right_waist",    "left_chest",      "right_chest",  "torso_back",
        "left_heel",     "right_heel",     "left_sole",       "right_sole"}) {
    ASSERT_TRUE(m.landmarks.count(name)) << name;
  }
  EXPECT_EQ(m.v_template(m.landmarks.at("head_top")[0], 1), m.v_template.col(1).maxCoeff());
  EXPECT_GT(m.v_template(m.landmarks.at("left_sole")[0], 0), 0.0);
  EXPECT_LT(m.v_template(m.landmarks.at("right_sole")[0], 0), 0.0);
  ASSERT_EQ(m.mirror.size(), 6890u);
  for (int v = 0; v < 6890; ++v) {
    const int w = m.mirror[static_cast<size_t>(v)];
    EXPECT_EQ(m.mirror[static_cast<size_t>(w)], v);
    EXPECT_NEAR(m.v_template(w, 0), -m.v_template(v, 0), 0.01);  // up to the radial noise
  }
}

TEST(MatrixCompare, NamesTheFirstFailingEntry) {
  Eigen::Matrix2d a = Eigen::Matrix2d::Identity(), b = a;
  b(1, 0) = 0.5;
  const auto r = caliper::test::matrices_near(a, b, 1e-3);
  EXPECT_FALSE(r);
  EXPECT_NE(std::string(r.message()).find("(1, 0)"), std::string::npos) << r.message();
  EXPECT_FALSE(caliper::test::matrices_near(a, Eigen::Matrix3d::Identity(), 1.0));
  b(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(caliper::test::matrices_near(a, b, 1e9));
  EXPECT_TRUE(caliper::test::matrices_near(a, a, 0.0));
}

}  // namespace
