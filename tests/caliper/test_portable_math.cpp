// caliper::portable (portable_math.hpp): agreement with libm to a couple of ulp over the ranges
// the model generator uses, exact special cases, and symmetry identities that hold bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "caliper/portable_math.hpp"

namespace {

namespace pm = caliper::portable;

// Distance in units in the last place between two finite doubles of the same sign.
std::int64_t ulps(double a, double b) {
  std::int64_t ia = 0, ib = 0;
  std::memcpy(&ia, &a, sizeof a);
  std::memcpy(&ib, &b, sizeof b);
  if ((ia < 0) != (ib < 0)) return a == b ? 0 : std::numeric_limits<std::int64_t>::max();
  return ia > ib ? ia - ib : ib - ia;
}

// libm is itself within about 1 ulp of the truth, ours within 2: 3 ulp apart at most.
constexpr std::int64_t kMaxUlps = 3;

// n points evenly spread over [lo, hi].
template <typename F>
void sweep(double lo, double hi, int n, F f) {
  for (int i = 0; i <= n; ++i) f(lo + (hi - lo) * i / n);
}

TEST(PortableMath, SinAndCosWithinAFewUlpOfLibm) {
  std::int64_t worst = 0;
  sweep(-100.0, 100.0, 200001, [&](double x) {
    // Near a zero the relative error of any method grows: compare absolutely there.
    const double s = pm::sin(x), c = pm::cos(x);
    if (std::fabs(std::sin(x)) > 1e-3)
      worst = std::max(worst, ulps(s, std::sin(x)));
    else
      EXPECT_NEAR(s, std::sin(x), 1e-16) << x;
    if (std::fabs(std::cos(x)) > 1e-3)
      worst = std::max(worst, ulps(c, std::cos(x)));
    else
      EXPECT_NEAR(c, std::cos(x), 1e-16) << x;
  });
  EXPECT_LE(worst, kMaxUlps);
  EXPECT_EQ(pm::sin(0.0), 0.0);
  EXPECT_EQ(pm::cos(0.0), 1.0);
  EXPECT_TRUE(std::isnan(pm::sin(std::numeric_limits<double>::infinity())));
}

TEST(PortableMath, SinIsOddAndCosEvenBitForBit) {
  sweep(0.0, 50.0, 5001, [&](double x) {
    EXPECT_EQ(pm::sin(-x), -pm::sin(x)) << x;
    EXPECT_EQ(pm::cos(-x), pm::cos(x)) << x;
  });
}

TEST(PortableMath, LogExpPowCbrtHypotWithinAFewUlpOfLibm) {
  std::int64_t worst_log = 0, worst_exp = 0, worst_cbrt = 0;
  sweep(1e-6, 1e6, 100001, [&](double x) {
    if (std::fabs(x - 1.0) > 1e-3) worst_log = std::max(worst_log, ulps(pm::log(x), std::log(x)));
    worst_cbrt = std::max(worst_cbrt, ulps(pm::cbrt(x), std::cbrt(x)));
    EXPECT_EQ(pm::cbrt(-x), -pm::cbrt(x));
  });
  sweep(-700.0, 700.0, 100001,
        [&](double x) { worst_exp = std::max(worst_exp, ulps(pm::exp(x), std::exp(x))); });
  EXPECT_LE(worst_log, kMaxUlps);
  EXPECT_LE(worst_exp, kMaxUlps);
  EXPECT_LE(worst_cbrt, kMaxUlps);
  // pow = exp(y log x): relative error ~ |y log x| ulp; the generator uses |y log x| < 10.
  constexpr double kPowRel = 1e-14;
  sweep(0.01, 3.0, 3001, [&](double x) {
    for (double y : {0.3, 0.5, 1.7, 2.0, 3.5}) {
      EXPECT_NEAR(pm::pow(x, y), std::pow(x, y), kPowRel * std::pow(x, y)) << x << "^" << y;
    }
  });
  EXPECT_EQ(pm::log(1.0), 0.0);
  EXPECT_EQ(pm::exp(0.0), 1.0);
  EXPECT_EQ(pm::pow(0.0, 2.0), 0.0);
  EXPECT_EQ(pm::pow(2.5, 0.0), 1.0);
  EXPECT_TRUE(std::isnan(pm::log(-1.0)));
  EXPECT_EQ(pm::log(0.0), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(pm::exp(1000.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(pm::hypot(3.0, 4.0), 5.0);
  EXPECT_EQ(pm::cbrt(27.0), 3.0);
}

}  // namespace
