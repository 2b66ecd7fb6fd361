// Protocol arithmetic: ISAK takes, floor calibration (plane fit), pivot calibration.
#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "caliper/errors.hpp"
#include "caliper/protocol.hpp"
#include "caliper_test/matrix_compare.hpp"

namespace caliper {
namespace {

constexpr double kIsakExactTol = 1e-12;

TEST(Isak, TwoTakesWithinTolerance) {
  // 1.000 and 1.014: difference 0.014 relative to the mean 1.007 = 1.39 % < 1.5 %: their mean.
  const IsakResult r = isak_combine({1.000, 1.014});
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.takes_used, 2);
  EXPECT_NEAR(r.value, 1.007, kIsakExactTol);
  EXPECT_NEAR(r.relative_difference, 0.014 / 1.007, kIsakExactTol);
  EXPECT_FALSE(isak_needs_third(1.000, 1.014));
}

TEST(Isak, ThirdTakeAndMedian) {
  // 1.000 and 1.016: 1.587 % >= 1.5 %: a third take is needed; the median of three is used.
  EXPECT_TRUE(isak_needs_third(1.000, 1.016));
  const IsakResult two = isak_combine({1.000, 1.016});
  EXPECT_FALSE(two.complete);
  EXPECT_TRUE(std::isnan(two.value));
  const IsakResult three = isak_combine({1.000, 1.016, 1.010});
  EXPECT_TRUE(three.complete);
  EXPECT_EQ(three.takes_used, 3);
  EXPECT_DOUBLE_EQ(three.value, 1.010);
  EXPECT_DOUBLE_EQ(isak_combine({1.0, 1.2, 0.5}).value, 1.0);
  // A third take given although the first two agree is ignored.
  EXPECT_NEAR(isak_combine({1.0, 1.01, 5.0}).value, 1.005, kIsakExactTol);
}

TEST(Isak, BoundaryAndDefinition) {
  // Exactly 1.5 % needs a third take ("below 1.5 %" gives the mean).
  const double a = 1.0, b = a * (1 + 0.015 / 2) / (1 - 0.015 / 2);  // |a-b| / mean = 0.015
  EXPECT_NEAR(isak_relative_difference(a, b), 0.015, 1e-15);
  EXPECT_TRUE(isak_needs_third(a, b * (1 + 1e-12)));
  EXPECT_FALSE(isak_needs_third(a, b * (1 - 1e-12)));
  EXPECT_EQ(isak_relative_difference(0.0, 0.0), 0.0);
  EXPECT_TRUE(isak_combine({0.3, 0.5}, 0.6).complete);  // custom tolerance: 60 % > 50 %
}

TEST(Isak, BadInput) {
  EXPECT_THROW(isak_combine({}), InvalidInputError);
  EXPECT_THROW(isak_combine({1.0}), InvalidInputError);
  EXPECT_THROW(isak_combine({1.0, 1.0, 1.0, 1.0}), InvalidInputError);
  EXPECT_THROW(isak_combine({1.0, std::nan("")}), InvalidInputError);
  EXPECT_THROW(isak_combine({1.0, -1.0}), InvalidInputError);
  EXPECT_THROW(isak_relative_difference(INFINITY, 1.0), InvalidInputError);
}

TEST(FloorCalibration, LevelFloor) {
  const std::vector<Eigen::Vector3d> p = {{0.0, 0.010, 0.0},
                                          {0.5, 0.012, 0.0},
                                          {0.0, 0.009, 0.5},
                                          {-0.5, 0.011, 0.0},
                                          {0.0, 0.030, -0.5}};
  const FloorCalibration f = calibrate_floor(p);
  EXPECT_DOUBLE_EQ(f.floor_height, 0.011);  // the median, robust to the 3 cm outlier
  EXPECT_EQ(f.num_samples, 5);
  EXPECT_NEAR(f.height_spread, 0.021, kIsakExactTol);
  EXPECT_GE(f.plane_normal.y(), 0.0);
  EXPECT_NEAR(f.plane_normal.norm(), 1.0, kIsakExactTol);
}

TEST(FloorCalibration, KnownTiltedPlane) {
  // The plane y = 0.02 + tan(3 deg) x through five points: tilt 3 degrees, zero residual.
  const double t = std::tan(3.0 * M_PI / 180.0);
  std::vector<Eigen::Vector3d> p;
  for (const auto& xz :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.4, 0.1), Eigen::Vector2d(-0.3, 0.4),
        Eigen::Vector2d(0.2, -0.5), Eigen::Vector2d(-0.4, -0.2)}) {
    p.emplace_back(xz.x(), 0.02 + t * xz.x(), xz.y());
  }
  const FloorCalibration f = calibrate_floor(p);
  EXPECT_NEAR(f.tilt_degrees, 3.0, 1e-9);
  EXPECT_LT(f.rms_residual, 1e-12);
  EXPECT_LT(f.max_residual, 1e-12);
  EXPECT_NEAR(f.floor_height, 0.02, kIsakExactTol);  // median of y: the x = 0 sample
  EXPECT_MATRIX_NEAR(f.plane_normal, Eigen::Vector3d(-t, 1, 0).normalized(), 1e-12);
}

TEST(FloorCalibration, KnownResiduals) {
  // A saddle no plane can explain: corners (1, 1) and (-1, -1) at height d, the other two at 0.
  // By symmetry the least-squares plane is level at y = d / 2 and every residual is d / 2.
  const double d = 0.004;
  const std::vector<Eigen::Vector3d> p = {{1, d, 1}, {-1, 0, 1}, {-1, d, -1}, {1, 0, -1}};
  const FloorCalibration f = calibrate_floor(p);
  EXPECT_NEAR(f.tilt_degrees, 0.0, 1e-9);
  EXPECT_NEAR(f.rms_residual, d / 2, 1e-12);
  EXPECT_NEAR(f.max_residual, d / 2, 1e-12);
  EXPECT_NEAR(f.floor_height, d / 2, kIsakExactTol);  // median of (0, 0, d, d)
}

TEST(FloorCalibration, BadSamples) {
  EXPECT_THROW(calibrate_floor({{0, 0, 0}, {1, 0, 0}}), CalibrationError);
  EXPECT_THROW(calibrate_floor({{0, 0, 0}, {0.5, 0, 0}, {1, 0, 0}, {1.5, 0.001, 0}}),
               CalibrationError);  // colinear
  EXPECT_THROW(calibrate_floor({{0, 0, 0}, {0, 0, 0.001}, {0.001, 0, 0}}), CalibrationError);
  EXPECT_THROW(calibrate_floor({{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 1}}), CalibrationError);
}

std::vector<Pose> pivot_poses(const Eigen::Vector3d& tip, const Eigen::Vector3d& pivot,
                              const std::vector<Eigen::Quaterniond>& qs) {
  std::vector<Pose> out;
  for (const auto& q : qs) {
    Pose p;
    p.orientation = q;
    p.position = pivot - q.toRotationMatrix() * tip;  // R t + p = q
    out.push_back(p);
  }
  return out;
}

TEST(PivotCalibration, RecoversAKnownOffset) {
  const Eigen::Vector3d tip(0.0, -0.02, -0.11), pivot(0.3, 0.9, -0.2);
  std::vector<Eigen::Quaterniond> qs;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d axis(std::cos(i * 0.9), 0.5 + 0.1 * i, std::sin(i * 1.3));
    qs.emplace_back(Eigen::AngleAxisd(0.2 + 0.08 * i, axis.normalized()));
  }
  const PivotCalibration c = calibrate_pivot(pivot_poses(tip, pivot, qs));
  EXPECT_MATRIX_NEAR(c.tip_offset, tip, 1e-12);
  EXPECT_MATRIX_NEAR(c.pivot, pivot, 1e-12);
  EXPECT_LT(c.rms_residual, 1e-12);
  EXPECT_EQ(c.num_samples, 8);
  EXPECT_GT(c.max_rotation_degrees, 5.0);
}

TEST(PivotCalibration, ResidualOfNoisyPositions) {
  const Eigen::Vector3d tip(0.01, 0.0, -0.1), pivot(0, 1, 0);
  std::vector<Eigen::Quaterniond> qs;
  qs.reserve(6);
  for (int i = 0; i < 6; ++i) {
    qs.emplace_back(
        Eigen::AngleAxisd(0.5, Eigen::Vector3d(std::cos(i), 1.0, std::sin(i)).normalized()));
  }
  std::vector<Pose> poses = pivot_poses(tip, pivot, qs);
  poses[2].position.x() += 0.002;  // 2 mm tracking error on one sample
  const PivotCalibration c = calibrate_pivot(poses);
  EXPECT_GT(c.rms_residual, 1e-4);
  EXPECT_LT(c.max_residual, 0.002);
  EXPECT_LT((c.tip_offset - tip).norm(), 0.01);
}

TEST(PivotCalibration, DegenerateSamples) {
  const Eigen::Vector3d tip(0, 0, -0.1), pivot(0, 1, 0);
  // Too few.
  EXPECT_THROW(calibrate_pivot(pivot_poses(
                   tip, pivot,
                   {Eigen::Quaterniond::Identity(),
                    Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()))})),
               CalibrationError);
  // All rotations equal.
  EXPECT_THROW(calibrate_pivot(pivot_poses(
                   tip, pivot, std::vector<Eigen::Quaterniond>(5, Eigen::Quaterniond::Identity()))),
               CalibrationError);
  // Rotations about a single axis.
  std::vector<Eigen::Quaterniond> one_axis;
  one_axis.reserve(5);
  for (int i = 0; i < 5; ++i)
    one_axis.emplace_back(Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitY()));
  EXPECT_THROW(calibrate_pivot(pivot_poses(tip, pivot, one_axis)), CalibrationError);
  // NaN and zero quaternion.
  std::vector<Eigen::Quaterniond> ok;
  ok.reserve(4);
  for (int i = 0; i < 4; ++i)
    ok.emplace_back(Eigen::AngleAxisd(0.4, Eigen::Vector3d(i, 1, 1 - i).normalized()));
  auto poses = pivot_poses(tip, pivot, ok);
  poses[1].position.y() = std::nan("");
  EXPECT_THROW(calibrate_pivot(poses), CalibrationError);
  poses = pivot_poses(tip, pivot, ok);
  poses[2].orientation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_THROW(calibrate_pivot(poses), CalibrationError);
}

}  // namespace
}  // namespace caliper
