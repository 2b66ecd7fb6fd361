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

// 1/n! for n = 0..20, exact quotients of exactly representable numbers rounded once, at compile
// time (IEEE division, so the same on every machine).
struct InverseFactorials {
  double c[21];
  constexpr InverseFactorials() : c() {
    double f = 1.0;
    for (int n = 0; n < 21; ++n) {
      if (n > 0) f *= n;  // n! is exact in double up to 22!
      c[n] = 1.0 / f;
    }
  }
};
constexpr InverseFactorials kInvFact;

// The Taylor coefficient of r^n in sin r or cos r: (-1)^(n/2) / n!.
constexpr double trig_coefficient(int n) {
  return (n / 2) % 2 == 1 ? -kInvFact.c[n] : kInvFact.c[n];
}

// sin(r) and cos(r) for |r| <= pi/4: Taylor series to r^19 and r^20 (the next terms are below
// 1e-19 relative), Horner's rule from the highest power.
double sin_kernel(double r) {
  // sin r = r + r^3 (-1/3! + r^2/5! - r^4/7! + ... - r^16/19!)
  const double r2 = r * r;
  double s = 0.0;
  for (int n = 19; n >= 3; n -= 2) s = s * r2 + trig_coefficient(n);
  return r + r * r2 * s;
}

double cos_kernel(double r) {
  // cos r = 1 + r^2 (-1/2! + r^2/4! - r^4/6! + ... + r^18/20!)
  const double r2 = r * r;
  double s = 0.0;
  for (int n = 20; n >= 2; n -= 2) s = s * r2 + trig_coefficient(n);
  return 1.0 + r2 * s;
}

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

// sin(q pi/2 + r) for |r| <= pi/4 (cos x is sin of the next quadrant).
double sin_quadrant(int q, double r) {
  switch (q & 3) {
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

}  // namespace

double sin(double x) {
  if (!std::isfinite(x)) return std::numeric_limits<double>::quiet_NaN();
  double r = 0.0;
  const int q = reduce(x, r);
  return sin_quadrant(q, r);
}

double cos(double x) {
  if (!std::isfinite(x)) return std::numeric_limits<double>::quiet_NaN();
  double r = 0.0;
  const int q = reduce(x, r);
  return sin_quadrant(q + 1, r);
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
