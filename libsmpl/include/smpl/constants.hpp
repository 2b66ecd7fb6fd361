/// \file constants.hpp
/// Mathematical constants shared by every layer (C++17 has no std::numbers, and M_PI is not
/// standard C++). The lowest library holds them so that libcaliper and every app use one value.
#pragma once

namespace smpl {

/// pi to double precision (the same literal as glibc's M_PI).
constexpr double kPi = 3.14159265358979323846;
/// pi rounded to float, for render-side code that works in float.
constexpr float kPiF = static_cast<float>(kPi);

}  // namespace smpl
