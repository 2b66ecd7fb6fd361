/// \file openxr_errors.hpp
/// The live path's own error: no OpenXR runtime (kept free of OpenXR's headers, for main).
#pragma once

#include <stdexcept>

namespace caliper::vr {

/// No OpenXR runtime is installed or running; the message says how to fix it.
class NoRuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The plain-words message for a missing runtime.
inline const char* kNoRuntimeMessage =
    "No OpenXR runtime is running. Start SteamVR or Monado, or set XR_RUNTIME_JSON; "
    "to test without a headset use --replay FILE";

}  // namespace caliper::vr
