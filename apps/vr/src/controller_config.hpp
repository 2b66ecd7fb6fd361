/// \file controller_config.hpp
/// Controller tip offsets per OpenXR interaction profile (assets/protocol/controllers.json):
/// the point that touches the body is an offset in the grip frame, with a default per profile
/// and a pivot calibration (`caliper-vr --calibrate-tip`) that measures it.
#pragma once

#include <map>
#include <string>

#include <Eigen/Core>

#include "caliper/session.hpp"

namespace caliper::vr {

struct ControllerConfig {
  std::map<std::string, TipOffsets> profiles;  ///< interaction profile path -> offsets
  TipOffsets fallback;                         ///< for a profile that is not listed

  /// Offsets of `profile` (or the fallback).
  TipOffsets offsets(const std::string& profile) const;
};

/// Reads the config. Throws std::runtime_error naming the file and key.
ControllerConfig read_controller_config(const std::string& path);
/// Writes it (pretty JSON, atomically).
void write_controller_config(const std::string& path, const ControllerConfig& config);
/// The built-in defaults (same as the committed file).
ControllerConfig default_controller_config();

/// The four interaction profiles the app suggests bindings for.
inline const char* const kProfiles[] = {
    "/interaction_profiles/htc/vive_controller", "/interaction_profiles/valve/index_controller",
    "/interaction_profiles/oculus/touch_controller", "/interaction_profiles/khr/simple_controller"};

}  // namespace caliper::vr
