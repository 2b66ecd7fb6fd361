/// \file protocol_mapping.cpp
/// NHANES's upper arm length on ANSUR II's acromion-radiale scale (protocol_mapping.hpp).
/// Least squares through Eigen's Householder QR, and the cube root through
/// caliper/portable_math.hpp, so that the mapping has the same bits on every CPU (the fit it
/// feeds is checked byte for byte).
#include "protocol_mapping.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/QR>

#include "caliper/portable_math.hpp"

namespace modelgen {

namespace {

void check_table(const Eigen::MatrixXd& t, Eigen::Index columns, const char* name) {
  if (t.cols() != columns) {
    throw std::invalid_argument(std::string("protocol mapping: the ") + name + " table has " +
                                std::to_string(t.cols()) + " columns, expected " +
                                std::to_string(columns));
  }
  for (Eigen::Index r = 0; r < t.rows(); ++r) {
    for (Eigen::Index c = 0; c < t.cols(); ++c) {
      if (!(std::isfinite(t(r, c)) && t(r, c) > 0.0)) {
        throw std::invalid_argument(std::string("protocol mapping: ") + name + " row " +
                                    std::to_string(r + 1) + " column " + std::to_string(c + 1) +
                                    " is not a positive number");
      }
    }
  }
}

/// [1, stature, cube root of weight] of rows (stature, weight, ...).
Eigen::RowVector3d features(const Eigen::MatrixXd& t, Eigen::Index r) {
  return {1.0, t(r, 0), caliper::portable::cbrt(t(r, 1))};
}

}  // namespace

ProtocolOffset protocol_offset(const Eigen::MatrixXd& ansur, const Eigen::MatrixXd& nhanes,
                               double max_bmi) {
  check_table(ansur, 3, "ANSUR II");
  check_table(nhanes, 3, "NHANES");
  const Eigen::Index n = ansur.rows();
  if (n < 10) {
    throw std::invalid_argument("protocol offset: ANSUR II has " + std::to_string(n) +
                                " rows; at least 10 are needed for the fit");
  }
  Eigen::MatrixXd x(n, 3);
  for (Eigen::Index r = 0; r < n; ++r) x.row(r) = features(ansur, r);
  const Eigen::Vector3d predict = x.householderQr().solve(ansur.col(2));
  ProtocolOffset out;
  double sum = 0.0;
  for (Eigen::Index r = 0; r < nhanes.rows(); ++r) {
    const double bmi = nhanes(r, 1) / (nhanes(r, 0) * nhanes(r, 0));
    if (bmi >= max_bmi) continue;
    sum += nhanes(r, 2) - features(nhanes, r).dot(predict);
    ++out.nhanes_people;
  }
  if (out.nhanes_people == 0) {
    throw std::invalid_argument("protocol offset: no NHANES person has a BMI under " +
                                std::to_string(max_bmi));
  }
  out.offset = sum / out.nhanes_people;
  return out;
}

UpperArmMapping upper_arm_mapping(const Eigen::MatrixXd& ansur, const Eigen::MatrixXd& nhanes,
                                  double max_bmi) {
  check_table(ansur, 4, "ANSUR II");  // the NHANES table: protocol_offset()
  const Eigen::Index n = ansur.rows();
  const ProtocolOffset step1 = protocol_offset(ansur.leftCols(3), nhanes, max_bmi);
  UpperArmMapping m;
  m.offset = step1.offset;
  m.nhanes_people = step1.nhanes_people;
  Eigen::MatrixXd y(n, 2);
  y.col(0).setOnes();
  y.col(1) = ansur.col(2);
  const Eigen::Vector2d arl = y.householderQr().solve(ansur.col(3));
  m.intercept = arl[0];
  m.slope = arl[1];
  m.residual_sd = std::sqrt((ansur.col(3) - y * arl).squaredNorm() / static_cast<double>(n - 2));
  return m;
}

}  // namespace modelgen
