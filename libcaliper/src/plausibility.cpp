// Shape plausibility under the prior betas ~ N(0, I); regularised incomplete gamma function
// (power series for x < a + 1, modified Lentz continued fraction otherwise).
#include "caliper/plausibility.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "caliper/errors.hpp"

namespace caliper {

namespace {

constexpr double kEps = 1e-16;
constexpr int kMaxIterations = 10000;

void check_args(double a, double x, const char* what) {
  if (!std::isfinite(a) || !(a > 0.0) || std::isnan(x) || x < 0.0) {
    throw InvalidInputError(std::string(what) + ": needs a > 0 and x >= 0, got a = " +
                            std::to_string(a) + ", x = " + std::to_string(x));
  }
}

// log of x^a e^-x / Gamma(a). lgamma_r, not std::lgamma: lgamma stores the sign of Gamma(a) in
// the global `signgam`, a data race when several threads judge plausibility at once (caliper
// batch; found by ThreadSanitizer). a > 0 here, so the sign is always +1.
double log_prefactor(double a, double x) {
  int sign = 0;
  return a * std::log(x) - x - ::lgamma_r(a, &sign);
}

double series_p(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEps) break;
  }
  return sum * std::exp(log_prefactor(a, x));
}

double continued_fraction_q(double a, double x) {
  const double tiny = std::numeric_limits<double>::min() / kEps;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return std::exp(log_prefactor(a, x)) * h;
}

}  // namespace

double regularized_gamma_p(double a, double x) {
  check_args(a, x, "regularized_gamma_p");
  if (x == 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  return x < a + 1.0 ? series_p(a, x) : 1.0 - continued_fraction_q(a, x);
}

double regularized_gamma_q(double a, double x) {
  check_args(a, x, "regularized_gamma_q");
  if (x == 0.0) return 1.0;
  if (std::isinf(x)) return 0.0;
  return x < a + 1.0 ? 1.0 - series_p(a, x) : continued_fraction_q(a, x);
}

double chi_square_cdf(double x, double k) {
  if (!(k > 0.0)) throw InvalidInputError("chi_square_cdf: degrees of freedom must be positive");
  if (std::isnan(x)) throw InvalidInputError("chi_square_cdf: x is NaN");
  return x <= 0.0 ? 0.0 : regularized_gamma_p(0.5 * k, 0.5 * x);
}

double chi_square_sf(double x, double k) {
  if (!(k > 0.0)) throw InvalidInputError("chi_square_sf: degrees of freedom must be positive");
  if (std::isnan(x)) throw InvalidInputError("chi_square_sf: x is NaN");
  return x <= 0.0 ? 1.0 : regularized_gamma_q(0.5 * k, 0.5 * x);
}

Plausibility plausibility(const Eigen::VectorXd& betas) {
  if (betas.size() == 0) throw InvalidInputError("plausibility: no betas given");
  if (!betas.allFinite()) throw InvalidInputError("plausibility: betas contain NaN or infinity");
  Plausibility p;
  for (Eigen::Index i = 0; i < betas.size(); ++i) {
    if (std::abs(betas(i)) > 2.0) p.beyond_2sd.push_back(static_cast<int>(i));
    if (std::abs(betas(i)) > 3.0) p.beyond_3sd.push_back(static_cast<int>(i));
  }
  const double d2 = betas.squaredNorm();
  p.mahalanobis = std::sqrt(d2);
  p.dof = static_cast<int>(betas.size());
  p.cdf = chi_square_cdf(d2, p.dof);
  p.p_value = chi_square_sf(d2, p.dof);
  p.plausible = p.beyond_3sd.empty() && p.p_value >= 1e-3;
  return p;
}

}  // namespace caliper
