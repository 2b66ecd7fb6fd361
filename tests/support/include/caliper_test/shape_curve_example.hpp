/// \file shape_curve_example.hpp
/// A shape curve (caliper/shape_curve.hpp) for tests: adult heights and weights, the
/// coefficients given.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "caliper/shape_curve.hpp"

namespace caliper::test {

/// Centre 1.7 m / 70 kg, range 1.4-2.0 m and 40-150 kg, `coefficients` B x 6.
inline ShapeCurve example_shape_curve(const Eigen::MatrixXd& coefficients) {
  ShapeCurve c;
  c.population = "test";
  c.subjects = 100;
  c.center = {1.7, std::cbrt(70.0)};
  c.scale = {0.1, 0.3};
  c.lo = {1.4, std::cbrt(40.0)};
  c.hi = {2.0, std::cbrt(150.0)};
  c.coefficients = coefficients;
  return c;
}

}  // namespace caliper::test
