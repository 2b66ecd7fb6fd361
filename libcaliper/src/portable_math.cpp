// Deterministic elementary functions (portable_math.hpp). Each is a range reduction that is
// exact or nearly so (Cody-Waite splits of pi/2 and ln 2), then a truncated Taylor series whose
// first omitted term is below 1e-19 relative on the reduced range, evaluated by Horner's rule.
#include "caliper/portable_math.hpp"

#include <cmath>
#include <limits>

namespace caliper::portable {
namespace {

// pi/2 = kPio2a + kPio2b + kPio2c: the first two have 33 significant bits, so k * kPio2a and
// k * kPio2b are exact for |k| < 2^20.
constexpr double kPio2a = 1.5707963267341256;
constexpr double kPio2b = 6.077100506303966e-11;
constexpr double kPio2c = 2.0222662487959506e-21;
constexpr double kTwoOverPi = 0.6366197723675814;
// ln 2 = kLn2a + kLn2b, kLn2a with 32 significant bits.
constexpr double kLn2a = 0.6931471803691238;
constexpr double kLn2b = 1.9082149292705877e-10;
constexpr double kSqrtHalf = 0.70710678118654752440;

// sin(r) and cos(r) for |r| <= pi/4: Taylor series to r^19 and r^20 (the next terms are below
// 1e-19 relative), Horner's rule from the highest power.
double sin_kernel(double r) {
  // sin r = r + r^3 (-1/3! + r^2/5! - r^4/7! + ... - r^16/19!)
  constexpr double c[] = {-1.0 / 121645100408832000.0,
                          1.0 / 355687428096000.0,
                          -1.0 / 1307674368000.0,
                          1.0 / 6227020800.0,
                          -1.0 / 39916800.0,
                          1.0 / 362880.0,
                          -1.0 / 5040.0,
                          1.0 / 120.0,
                          -1.0 / 6.0};
  const double r2 = r * r;
  double s = 0.0;
  for (double k : c) s = s * r2 + k;
  return r + r * r2 * s;
}

double cos_kernel(double r) {
  // cos r = 1 + r^2 (-1/2! + r^2/4! - r^4/6! + ... + r^18/20!)
  constexpr double c[] = {1.0 / 2432902008176640000.0,
                          -1.0 / 6402373705728000.0,
                          1.0 / 20922789888000.0,
                          -1.0 / 87178291200.0,
                          1.0 / 479001600.0,
                          -1.0 / 3628800.0,
                          1.0 / 40320.0,
                          -1.0 / 720.0,
                          1.0 / 24.0,
                          -1.0 / 2.0};
  const double r2 = r * r;
  double s = 0.0;
  for (double k : c) s = s * r2 + k;
  return 1.0 + r2 * s;
}

// 1/n! for n = 0..17, exact quotients of exactly representable numbers rounded once, at compile
// time (IEEE division, so the same on every machine).
struct InverseFactorials {
  double c[18];
  constexpr InverseFactorials() : c() {
    double f = 1.0;
    for (int n = 0; n < 18; ++n) {
      if (n > 0) f *= n;  // n! is exact in double up to 18!
      c[n] = 1.0 / f;
    }
  }
};
constexpr InverseFactorials kInvFact;

// 1/(2k + 3) for k = 0..10 (log's atanh series, f^3/3 ... f^23/23).
struct InverseOdds {
  double c[11];
  constexpr InverseOdds() : c() {
    for (int k = 0; k < 11; ++k) c[k] = 1.0 / (2 * k + 3);
  }
};
constexpr InverseOdds kInvOdd;

// x = k * pi/2 + r with |r| <= pi/4 (a little more for huge x); returns k mod 4.
int reduce(double x, double& r) {
  const double k = std::rint(x * kTwoOverPi);
  r = ((x - k * kPio2a) - k * kPio2b) - k * kPio2c;
  if (std::fabs(k) < 4503599627370496.0) {  // 2^52: k is an exact integer in long long range
    return static_cast<int>(static_cast<long long>(k) & 3);
  }
  const long long q = static_cast<long long>(std::fmod(k, 4.0));
  return static_cast<int>((q + 4) % 4);
}

}  // namespace

double sin(double x) {
  if (!std::isfinite(x)) return std::numeric_limits<double>::quiet_NaN();
  double r = 0.0;
  switch (reduce(x, r)) {
    case 0:
      return sin_kernel(r);
    case 1:
      return cos_kernel(r);
    case 2:
      return -sin_kernel(r);
    default:
      return -cos_kernel(r);
  }
}

double cos(double x) {
  if (!std::isfinite(x)) return std::numeric_limits<double>::quiet_NaN();
  double r = 0.0;
  switch (reduce(x, r)) {
    case 0:
      return cos_kernel(r);
    case 1:
      return -sin_kernel(r);
    case 2:
      return -cos_kernel(r);
    default:
      return sin_kernel(r);
  }
}

double log(double x) {
  if (std::isnan(x) || x < 0.0) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return -std::numeric_limits<double>::infinity();
  if (std::isinf(x)) return x;
  int e = 0;
  double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  if (m < kSqrtHalf) {
    m *= 2.0;
    --e;
  }
  // log m = 2 atanh(f) = 2 (f + f^3/3 + f^5/5 + ...), f = (m - 1) / (m + 1), |f| <= 0.1716:
  // terms to f^23 (the next is below 1e-19 relative).
  const double f = (m - 1.0) / (m + 1.0);
  const double f2 = f * f;
  double s = 0.0;
  for (int k = 10; k >= 0; --k) s = (s + kInvOdd.c[k]) * f2;
  const double log_m = 2.0 * f + 2.0 * f * s;
  const double de = static_cast<double>(e);
  return (de * kLn2a + (de * kLn2b + log_m));
}

double exp(double x) {
  if (std::isnan(x)) return x;
  if (x > 709.78) return std::numeric_limits<double>::infinity();
  if (x < -745.2) return 0.0;
  constexpr double kInvLn2 = 1.4426950408889634;  // rounded 1/ln 2; any k near x/ln 2 works
  const double k = std::rint(x * kInvLn2);
  const double r = (x - k * kLn2a) - k * kLn2b;  // |r| <= 0.35
  // Taylor series to r^17 (the next term is below 1e-22).
  double s = kInvFact.c[17];
  for (int n = 16; n >= 0; --n) s = s * r + kInvFact.c[n];
  return std::ldexp(s, static_cast<int>(k));
}

double pow(double x, double y) {
  if (x < 0.0 || std::isnan(x) || std::isnan(y)) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return y > 0.0 ? 0.0 : (y == 0.0 ? 1.0 : std::numeric_limits<double>::infinity());
  if (y == 0.0 || x == 1.0) return 1.0;
  return exp(y * log(x));
}

double hypot(double a, double b) {
  return std::sqrt(a * a + b * b);
}

double cbrt(double x) {
  if (x == 0.0 || !std::isfinite(x)) return x;
  const double ax = std::fabs(x);
  double y = exp(log(ax) / 3.0);
  y = y - (y * y * y - ax) / (3.0 * y * y);  // one Newton step to within an ulp or so
  return x < 0 ? -y : y;
}

}  // namespace caliper::portable
