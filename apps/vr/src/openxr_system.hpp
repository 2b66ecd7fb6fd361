/// \file openxr_system.hpp
/// The live path: OpenXR 1.0 through the Khronos loader (Debian libopenxr-dev 1.0.20) in the
/// shape of Khronos hello_xr: the program (openxr_program.hpp: instance, session, frame loop),
/// a graphics plugin (openxr_graphics.hpp; here OpenGL with the Xlib binding on a GLFW/GLX
/// context, openxr_graphics_gl.hpp) and the input (openxr_input.hpp: actions for the HTC Vive
/// wand, Valve Index, Oculus Touch and the KHR simple controller, and haptics). This file runs
/// the app on them: a measuring session or a pivot calibration of a controller tip. The
/// operator's desktop window (ImGui) mirrors the left eye and issues start/redo/skip and typed
/// weight and sex.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "audio.hpp"
#include "openxr_errors.hpp"
#include "vr_app.hpp"

namespace caliper::vr {

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
