/// \file openxr_system.hpp
/// The live path: OpenXR 1.0 through the Khronos loader (Debian libopenxr-dev 1.0.20), an OpenGL
/// session with the Xlib binding (XR_KHR_opengl_enable) on a GLFW/GLX context, stereo projection
/// layers drawn by the shared renderer, action bindings for the HTC Vive wand, Valve Index,
/// Oculus Touch and the KHR simple controller, and haptics. The operator's desktop window
/// (ImGui) mirrors the left eye and issues start/redo/skip and typed weight and sex.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "audio.hpp"
#include "vr_app.hpp"

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

/// What run_openxr() needs from main.
struct LiveOptions {
  std::string role = "self";
  bool operator_window = false;
  std::string record_path;       ///< "" = no recording
  std::string calibrate_tip;     ///< "left"/"right": pivot calibration instead of a session
  std::string controllers_path;  ///< written by the pivot calibration
  std::function<VrAppOptions(const std::string& profile)> make_app_options;
  std::function<std::unique_ptr<Audio>()> open_audio;
  std::function<int(VrApp&, Audio&, const std::string& journal)> finish;
  std::function<void(VrApp&)> write_outputs;  ///< once, when the session is complete
  std::optional<double> weight;               ///< --weight, kept in the recording's header
  std::string sex;                            ///< --sex, kept in the recording's header
};

/// Runs a live session (or a pivot calibration) until the user ends the completed session (menu
/// button), the runtime quits, or the runtime is lost (XR_ERROR_SESSION_LOST, ..._INSTANCE_LOST,
/// a loss-pending event: said in plain words, then options.finish as at the end of a pose
/// source). Throws NoRuntimeError when no runtime is available, std::runtime_error for other
/// failures.
int run_openxr(const LiveOptions& options);

}  // namespace caliper::vr
