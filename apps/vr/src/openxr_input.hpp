/// \file openxr_input.hpp
/// The input unit of the live path: one action set ("measuring") with the trigger (take a
/// sample, held), menu (end the session), squeeze, the grip pose and a haptic output, suggested
/// bindings for the four controllers of controller_config.hpp (kProfiles), one grip space per
/// hand, and per frame the controllers' poses and buttons as DevicePoses.
#pragma once

#include <openxr/openxr.h>

#include <array>
#include <string>
#include <vector>

#include "caliper/pose_log.hpp"
#include "caliper/protocol_file.hpp"

namespace caliper::vr {

/// One suggested binding: an action of the set and its input path after /user/hand/<side>.
struct XrBindingSpec {
  std::string action;  ///< "take_sample", "menu", "squeeze", "grip_pose" or "confirm_haptic"
  std::string input;   ///< e.g. "/input/trigger/value"
  bool left = true, right = true;  ///< the hands that have it
};

/// The bindings suggested for `profile` (one of kProfiles; empty for any other): the trigger's
/// value (select/click on the simple controller), menu/click (Index: b/click; Touch: left hand
/// only), squeeze, the grip pose and the haptic output.
std::vector<XrBindingSpec> suggested_bindings(const std::string& profile);

/// A located space as a pose: valid only when position and orientation are valid and the
/// position is tracked; the orientation normalised.
DevicePose device_pose(const XrSpaceLocation& location);

class XrInput {
 public:
  /// Creates the action set and actions, suggests the bindings of every profile in kProfiles,
  /// creates the grip spaces and attaches the set to `session`. Throws std::runtime_error.
  XrInput(XrInstance instance, XrSession session);
  ~XrInput();
  XrInput(const XrInput&) = delete;
  XrInput& operator=(const XrInput&) = delete;

  /// Syncs the action set (once per frame, after xrBeginFrame).
  void sync();
  /// The controllers' grip poses in `base` at `time`, and their trigger, menu and squeeze.
  void read(XrSpace base, XrTime time, PoseFrame& frame) const;
  /// Vibrates a controller.
  void haptic_pulse(Tip hand, double amplitude, double seconds);
  /// The right hand's current interaction profile path; "" while the runtime has bound none.
  std::string current_profile() const;

 private:
  XrAction action(const std::string& name) const;
  void create_actions();
  void suggest(const char* profile);

  XrInstance instance_;
  XrSession session_;
  XrActionSet set_ = XR_NULL_HANDLE;
  XrAction trigger_ = XR_NULL_HANDLE, menu_ = XR_NULL_HANDLE, squeeze_ = XR_NULL_HANDLE;
  XrAction grip_pose_ = XR_NULL_HANDLE, haptic_ = XR_NULL_HANDLE;
  std::array<XrPath, 2> hand_paths_{};    ///< /user/hand/left, /user/hand/right
  std::array<XrSpace, 2> grip_spaces_{};  ///< per hand
};

}  // namespace caliper::vr
