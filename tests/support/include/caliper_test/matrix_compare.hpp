/// \file matrix_compare.hpp
/// Eigen matrix comparison for GoogleTest that names the first failing (i, j), both values and
/// the worst difference, instead of dumping two huge matrices.
#pragma once

#include <cmath>
#include <cstring>
#include <sstream>

#include <gtest/gtest.h>
#include <Eigen/Core>

namespace caliper::test {

/// Succeeds when `a` and `b` have the same shape and every |a(i,j) - b(i,j)| <= tol (NaN in
/// either fails). Use as EXPECT_TRUE(matrices_near(a, b, kTol)) or EXPECT_MATRIX_NEAR.
template <typename A, typename B>
::testing::AssertionResult matrices_near(const Eigen::DenseBase<A>& a, const Eigen::DenseBase<B>& b,
                                         double tol) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) {
    return ::testing::AssertionFailure() << "shape mismatch: (" << a.rows() << ", " << a.cols()
                                         << ") vs (" << b.rows() << ", " << b.cols() << ")";
  }
  Eigen::Index fi = -1, fj = -1, wi = -1, wj = -1;
  double worst = 0.0;
  Eigen::Index failures = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      const double x = static_cast<double>(a(i, j));
      const double y = static_cast<double>(b(i, j));
      const double d = std::abs(x - y);
      const bool bad = !(d <= tol);  // NaN compares false: counted as a failure
      if (bad) {
        if (fi < 0) {
          fi = i;
          fj = j;
        }
        ++failures;
      }
      const double rank = std::isnan(d) ? HUGE_VAL : d;  // NaN is the worst difference
      if (rank > worst || wi < 0) {
        worst = rank;
        wi = i;
        wj = j;
      }
    }
  }
  if (failures == 0) return ::testing::AssertionSuccess() << "max |diff| " << worst;
  std::ostringstream s;
  s.precision(17);
  s << failures << " of " << a.size() << " entries differ by more than " << tol << "; first at ("
    << fi << ", " << fj << "): " << a(fi, fj) << " vs " << b(fi, fj) << "; worst at (" << wi << ", "
    << wj << "): " << a(wi, wj) << " vs " << b(wi, wj) << " (|diff| " << worst << ")";
  return ::testing::AssertionFailure() << s.str();
}

/// True when the n doubles at `a` and at `b` are the same bits (for results that must not
/// depend on the kernel variant or the batch size).
inline bool same_bits(const double* a, const double* b, Eigen::Index n) {
  return std::memcmp(a, b, static_cast<std::size_t>(n) * sizeof(double)) == 0;
}

/// The same for n floats.
inline bool same_bits(const float* a, const float* b, Eigen::Index n) {
  return std::memcmp(a, b, static_cast<std::size_t>(n) * sizeof(float)) == 0;
}

}  // namespace caliper::test

/// EXPECT_MATRIX_NEAR(a, b, tol): see caliper::test::matrices_near.
#define EXPECT_MATRIX_NEAR(a, b, tol) EXPECT_TRUE(::caliper::test::matrices_near((a), (b), (tol)))
/// ASSERT_MATRIX_NEAR(a, b, tol): see caliper::test::matrices_near.
#define ASSERT_MATRIX_NEAR(a, b, tol) ASSERT_TRUE(::caliper::test::matrices_near((a), (b), (tol)))
