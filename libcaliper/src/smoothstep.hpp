// Private to libcaliper: the easing curve the body IK and the session simulator share.
#pragma once

#include <algorithm>

namespace caliper::detail {

/// 0 below 0, 1 above 1, and 3x^2 - 2x^3 between: starts and ends with zero slope.
inline double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace caliper::detail
