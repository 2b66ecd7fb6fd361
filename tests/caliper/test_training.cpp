// Training sets: corner and Gaussian betas, and the fast exact ShapeMeasurer checked against
// direct evaluation of the full mesh.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/training.hpp"
#include "caliper/volume.hpp"
#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"

namespace caliper {
namespace {

// Volume via the expanded cubic vs the direct face sum: both sum ~14k terms of size ~1e-3 m^3;
// rounding differs, 1e-12 m^3 is ~1e-11 relative.
constexpr double kVolumeTol = 1e-12;
// Landmark points via precomputed affine maps vs v_template + shapedirs * betas: 1e-13 m.
constexpr double kLengthTol = 1e-12;

TEST(CornerBetas, AllCornersOnce) {
  const Eigen::MatrixXd b = corner_betas(10, 2.0);
  ASSERT_EQ(b.rows(), 1024);
  ASSERT_EQ(b.cols(), 10);
  EXPECT_TRUE((b.array().abs() == 2.0).all());
  std::set<long> codes;
  for (int r = 0; r < 1024; ++r) {
    long code = 0;
    for (int i = 0; i < 10; ++i) code |= (b(r, i) > 0 ? 1L : 0L) << i;
    codes.insert(code);
  }
  EXPECT_EQ(codes.size(), 1024u);
  // Balanced design: every column has mean 0 and the columns are orthogonal.
  EXPECT_MATRIX_NEAR(b.colwise().sum(), Eigen::RowVectorXd::Zero(10), 0.0);
  EXPECT_MATRIX_NEAR(b.transpose() * b, 4.0 * 1024 * Eigen::MatrixXd::Identity(10, 10), 0.0);
  EXPECT_THROW(corner_betas(0), InvalidInputError);
  EXPECT_THROW(corner_betas(21), InvalidInputError);
  EXPECT_THROW(corner_betas(3, -1.0), InvalidInputError);
}

TEST(GaussianBetas, DeterministicAndStandardNormal) {
  const Eigen::MatrixXd a = gaussian_betas(20000, 10, 42);
  const Eigen::MatrixXd b = gaussian_betas(20000, 10, 42);
  const Eigen::MatrixXd c = gaussian_betas(20000, 10, 43);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a == c);
  // 200k samples: the mean's SD is 1/sqrt(200000) = 0.0022, the variance's 0.0032; 5 SD bounds.
  EXPECT_NEAR(a.mean(), 0.0, 0.011);
  EXPECT_NEAR(a.array().square().mean(), 1.0, 0.016);
  // Odd total size works too.
  EXPECT_EQ(gaussian_betas(3, 3, 1).size(), 9);
  EXPECT_TRUE(gaussian_betas(3, 3, 1).allFinite());
  EXPECT_THROW(gaussian_betas(0, 10, 1), InvalidInputError);
}

class ShapeMeasurerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = test::make_random_model(16, 24, false, 7);
    landmarks_ = landmarks_for(model_);
  }
  smpl::BodyModel model_;
  LandmarkTable landmarks_;
};

TEST_F(ShapeMeasurerTest, MatchesTheFullMeshExactly) {
  const ShapeMeasurer sm(model_, landmarks_);
  EXPECT_EQ(sm.num_betas(), 10);
  const Eigen::MatrixXd betas = gaussian_betas(20, 10, 9) * 1.5;
  for (int r = 0; r < betas.rows(); ++r) {
    const Eigen::VectorXd b = betas.row(r).transpose();
    const smpl::Vertices v = shaped_vertices(model_, b);
    EXPECT_NEAR(sm.volume(b), mesh_volume(v, model_.faces), kVolumeTol) << r;
    EXPECT_NEAR(sm.floor(b), v.col(1).minCoeff(), kLengthTol) << r;
    const Eigen::VectorXd m = sm.measure(b);
    for (std::size_t d = 0; d < sm.definitions().size(); ++d) {
      EXPECT_NEAR(m(static_cast<Eigen::Index>(d)), measure(v, landmarks_, sm.definitions()[d]),
                  kLengthTol)
          << sm.definitions()[d].id;
    }
  }
}

TEST_F(ShapeMeasurerTest, LowestVertexChangesWithBetasAndIsFound) {
  // Far-out betas (|beta| ~ 30, beyond the prepared radius) move a different vertex lowest.
  const ShapeMeasurer sm(model_, landmarks_, paper_measurements(), 16);
  std::set<Eigen::Index> lowest;
  const Eigen::MatrixXd betas = gaussian_betas(30, 16, 11) * 8.0;
  for (int r = 0; r < betas.rows(); ++r) {
    const Eigen::VectorXd b = betas.row(r).transpose();
    const smpl::Vertices v = shaped_vertices(model_, b);
    Eigen::Index idx = 0;
    const double direct = v.col(1).minCoeff(&idx);
    lowest.insert(idx);
    EXPECT_NEAR(sm.floor(b), direct, kLengthTol);
  }
  EXPECT_GT(lowest.size(), 1u);  // the test exercises a changing lowest vertex
  Eigen::MatrixXd m;
  Eigen::VectorXd vol;
  sm.measure_batch(betas, m, vol);
  for (int r = 0; r < betas.rows(); ++r) {
    const Eigen::VectorXd b = betas.row(r).transpose();
    EXPECT_NEAR(m(r, 0), sm.measure(b)(0), kLengthTol);  // height uses the floor
  }
}

TEST_F(ShapeMeasurerTest, BatchEqualsSingle) {
  const ShapeMeasurer sm(model_, landmarks_);
  const Eigen::MatrixXd betas = corner_betas(10, 2.0).topRows(64);
  Eigen::MatrixXd m;
  Eigen::VectorXd vol;
  sm.measure_batch(betas, m, vol);
  ASSERT_EQ(m.rows(), 64);
  ASSERT_EQ(m.cols(), 13);
  for (int r = 0; r < 64; ++r) {
    const Eigen::VectorXd b = betas.row(r).transpose();
    EXPECT_MATRIX_NEAR(m.row(r), sm.measure(b).transpose(), kLengthTol);
    EXPECT_NEAR(vol(r), sm.volume(b), kVolumeTol);
  }
  // Fewer columns than num_betas: the rest are zero.
  Eigen::MatrixXd m3;
  Eigen::VectorXd v3;
  sm.measure_batch(betas.leftCols(3), m3, v3);
  Eigen::VectorXd b3 = Eigen::VectorXd::Zero(10);
  b3.head(3) = betas.row(5).head(3).transpose();
  EXPECT_NEAR(v3(5), sm.volume(b3), kVolumeTol);
}

TEST_F(ShapeMeasurerTest, BadInput) {
  EXPECT_THROW(ShapeMeasurer(model_, landmarks_, paper_measurements(), 17), InvalidInputError);
  LandmarkTable missing = landmarks_;
  missing.erase("crotch");
  EXPECT_THROW(ShapeMeasurer(model_, missing), LandmarkError);
  const ShapeMeasurer sm(model_, landmarks_);
  EXPECT_THROW(sm.measure(Eigen::VectorXd::Zero(11)), InvalidInputError);
  Eigen::VectorXd nan = Eigen::VectorXd::Zero(2);
  nan(0) = std::nan("");
  EXPECT_THROW(sm.volume(nan), InvalidInputError);
}

TEST_F(ShapeMeasurerTest, TrainingSetColumns) {
  const ShapeMeasurer sm(model_, landmarks_);
  const TrainingSet t = make_training_set(sm, corner_betas(10, 2.0), female_weight_formula());
  ASSERT_EQ(t.size(), 1024);
  EXPECT_EQ(t.ids.size(), 13u);
  EXPECT_MATRIX_NEAR(t.column("weight"), ((1001.44 * t.volumes).array() - 2.36).matrix(), 1e-10);
  EXPECT_NEAR(t.column("weight_feature")(3), std::cbrt(t.volumes(3)), 1e-15);
  EXPECT_MATRIX_NEAR(t.column("hip_width"), t.measurements.col(8), 0.0);
  EXPECT_THROW(t.column("shoe_size"), InvalidInputError);
  const TrainingSet p = paper_training_set(model_);
  EXPECT_EQ(p.size(), 1024);
  EXPECT_EQ(p.betas.cols(), 10);
}

}  // namespace
}  // namespace caliper
