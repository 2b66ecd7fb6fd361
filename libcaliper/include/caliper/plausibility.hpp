/// \file plausibility.hpp
/// How plausible is a shape under the model's prior betas ~ N(0, I)? Per-component flags beyond
/// 2 and 3 SD and the Mahalanobis distance d = |beta| with its chi-square probability
/// (d^2 ~ chi^2 with k degrees of freedom). The regularised incomplete gamma function is our own
/// (series and continued fraction, Numerical-Recipes style algorithms, written from the
/// definitions).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace caliper {

/// Plausibility of one shape vector.
struct Plausibility {
  std::vector<int> beyond_2sd;  ///< indices b with |beta_b| > 2
  std::vector<int> beyond_3sd;  ///< indices b with |beta_b| > 3 (also listed in beyond_2sd)
  double mahalanobis = 0.0;     ///< sqrt(beta' beta)
  int dof = 0;                  ///< k = betas.size()
  /// P(chi^2_k <= d^2): the fraction of the population closer to the mean than this body.
  double cdf = 0.0;
  /// 1 - cdf: the probability that a random body is at least this far from the mean.
  double p_value = 1.0;
  /// No component beyond 3 SD and p_value >= 0.001.
  bool plausible = true;
};

/// Plausibility of `betas` (k >= 1 values, finite; else InvalidInputError).
Plausibility plausibility(const Eigen::VectorXd& betas);

/// Regularised lower incomplete gamma P(a, x) = gamma(a, x) / Gamma(a), a > 0, x >= 0
/// (InvalidInputError otherwise). Accurate to ~1e-14 relative.
double regularized_gamma_p(double a, double x);
/// Regularised upper incomplete gamma Q(a, x) = 1 - P(a, x), computed directly (no
/// cancellation in the tail).
double regularized_gamma_q(double a, double x);
/// Chi-square CDF P(X <= x) for k > 0 degrees of freedom: P(k/2, x/2); 0 for x <= 0.
double chi_square_cdf(double x, double k);
/// Chi-square survival function P(X > x) = Q(k/2, x/2); 1 for x <= 0.
double chi_square_sf(double x, double k);

}  // namespace caliper
