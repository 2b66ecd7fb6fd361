// The measuring protocol's arithmetic: Pujades et al., The Virtual Caliper, TVCG 2019,
// Sec. 3.1.1 (floor calibration) and Sec. 3.1.3 (ISAK takes); pivot calibration of the
// controller tip (see docs/regressors.md).
#include "caliper/protocol.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "caliper/errors.hpp"

namespace caliper {

namespace {
constexpr double kRadToDeg = 57.295779513082320876798;

void check_take(double v, int i) {
  if (!std::isfinite(v)) {
    throw InvalidInputError("ISAK take " + std::to_string(i + 1) + " is not a number");
  }
  if (v < 0.0) {
    throw InvalidInputError("ISAK take " + std::to_string(i + 1) + " = " + std::to_string(v) +
                            " is negative; takes are lengths in metres");
  }
}
}  // namespace

double isak_relative_difference(double a, double b) {
  check_take(a, 0);
  check_take(b, 1);
  const double mean = 0.5 * (a + b);
  return mean == 0.0 ? 0.0 : std::abs(a - b) / mean;
}

bool isak_needs_third(double a, double b, double tolerance) {
  return isak_relative_difference(a, b) >= tolerance;
}

IsakResult isak_combine(const std::vector<double>& takes, double tolerance) {
  if (takes.size() < 2 || takes.size() > 3) {
    throw InvalidInputError("ISAK needs 2 or 3 takes, got " + std::to_string(takes.size()));
  }
  for (std::size_t i = 0; i < takes.size(); ++i) check_take(takes[i], static_cast<int>(i));
  IsakResult r;
  r.relative_difference = isak_relative_difference(takes[0], takes[1]);
  if (r.relative_difference < tolerance) {
    r.complete = true;
    r.value = 0.5 * (takes[0] + takes[1]);
    r.takes_used = 2;
  } else if (takes.size() == 3) {
    std::vector<double> s = takes;
    std::sort(s.begin(), s.end());
    r.complete = true;
    r.value = s[1];
    r.takes_used = 3;
  } else {
    r.complete = false;
    r.value = std::numeric_limits<double>::quiet_NaN();
    r.takes_used = 0;
  }
  return r;
}

FloorCalibration calibrate_floor(const std::vector<Eigen::Vector3d>& p) {
  if (p.size() < 3) {
    throw CalibrationError(
        "floor calibration needs at least 3 tip samples on the floor (the "
        "protocol takes 5), got " +
        std::to_string(p.size()));
  }
  const auto n = static_cast<double>(p.size());
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p[i].allFinite()) {
      throw CalibrationError("floor sample " + std::to_string(i + 1) +
                             " is NaN or infinite; was the controller tracked?");
    }
    c += p[i];
  }
  c /= n;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& q : p) cov += (q - c) * (q - c).transpose();
  cov /= n;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);  // ascending
  if (std::sqrt(lambda(1)) < 0.01) {
    throw CalibrationError(
        "floor samples are (nearly) colinear or all at one spot (spread "
        "below 1 cm across their main direction); place the tip at "
        "different points around the centre of the space");
  }
  Eigen::Vector3d normal = eig.eigenvectors().col(0).normalized();
  if (normal.y() < 0.0) normal = -normal;
  FloorCalibration f;
  f.num_samples = static_cast<int>(p.size());
  f.plane_point = c;
  f.plane_normal = normal;
  f.tilt_degrees = std::acos(std::clamp(normal.y(), -1.0, 1.0)) * kRadToDeg;
  std::vector<double> ys;
  double ss = 0.0;
  for (const auto& q : p) {
    const double r = std::abs((q - c).dot(normal));
    ss += r * r;
    f.max_residual = std::max(f.max_residual, r);
    ys.push_back(q.y());
  }
  f.rms_residual = std::sqrt(ss / n);
  std::sort(ys.begin(), ys.end());
  const std::size_t m = ys.size() / 2;
  f.floor_height = ys.size() % 2 ? ys[m] : 0.5 * (ys[m - 1] + ys[m]);
  f.height_spread = ys.back() - ys.front();
  return f;
}

PivotCalibration calibrate_pivot(const std::vector<Pose>& poses) {
  const int n = static_cast<int>(poses.size());
  if (n < 3) {
    throw CalibrationError("pivot calibration needs at least 3 poses, got " + std::to_string(n));
  }
  std::vector<Eigen::Matrix3d> rot(n);
  for (int i = 0; i < n; ++i) {
    const auto& q = poses[i].orientation;
    if (!q.coeffs().allFinite() || !poses[i].position.allFinite()) {
      throw CalibrationError("pivot pose " + std::to_string(i + 1) + " is NaN or infinite");
    }
    if (q.norm() < 1e-9) {
      throw CalibrationError("pivot pose " + std::to_string(i + 1) + " has a zero quaternion");
    }
    rot[i] = q.normalized().toRotationMatrix();
  }
  double max_angle = 0.0;
  for (int i = 1; i < n; ++i) {
    const Eigen::AngleAxisd d(rot[0].transpose() * rot[i]);
    max_angle = std::max(max_angle, std::abs(d.angle()));
  }
  if (max_angle * kRadToDeg < 5.0) {
    throw CalibrationError(
        "pivot poses are all rotated alike (less than 5 degrees apart); keep "
        "the tip on the point and tilt the controller in several directions");
  }
  Eigen::Matrix<double, Eigen::Dynamic, 6> A(3 * n, 6);
  Eigen::VectorXd b(3 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(i);
    A.block<3, 3>(row, 0) = rot[static_cast<std::size_t>(i)];
    A.block<3, 3>(row, 3) = -Eigen::Matrix3d::Identity();
    b.segment<3>(row) = -poses[static_cast<std::size_t>(i)].position;
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, 6>> svd(
      A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Matrix<double, 6, 1> s = svd.singularValues();
  if (s(5) < 1e-6 * s(0)) {
    throw CalibrationError(
        "pivot poses rotate about a single axis only, so the tip offset "
        "along it is undetermined; tilt the controller in two directions");
  }
  const Eigen::Matrix<double, 6, 1> x = svd.solve(b);
  PivotCalibration r;
  r.tip_offset = x.head<3>();
  r.pivot = x.tail<3>();
  r.num_samples = n;
  r.max_rotation_degrees = max_angle * kRadToDeg;
  double ss = 0.0;
  for (int i = 0; i < n; ++i) {
    const double e = (rot[i] * r.tip_offset + poses[i].position - r.pivot).norm();
    ss += e * e;
    r.max_residual = std::max(r.max_residual, e);
  }
  r.rms_residual = std::sqrt(ss / n);
  return r;
}

}  // namespace caliper
