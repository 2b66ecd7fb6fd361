// The live path's input unit (see openxr_input.hpp).
#include "openxr_input.hpp"

#include <algorithm>
#include <cstring>
#include <iterator>

#include "controller_config.hpp"
#include "openxr_check.hpp"

namespace caliper::vr {

std::vector<XrBindingSpec> suggested_bindings(const std::string& profile) {
  // What differs between the profiles (kProfiles' order); every one also binds the grip pose and
  // the haptic output.
  struct ProfileInputs {
    const char* take_sample;
    const char* menu;
    bool menu_right;      ///< false: the menu button is on the left controller only
    const char* squeeze;  ///< nullptr: the controller has none
  };
  static const ProfileInputs kInputs[] = {
      {"/input/trigger/value", "/input/menu/click", true, "/input/squeeze/click"},   // Vive
      {"/input/trigger/value", "/input/b/click", true, "/input/squeeze/value"},      // Index
      {"/input/trigger/value", "/input/menu/click", false, "/input/squeeze/value"},  // Touch
      {"/input/select/click", "/input/menu/click", true, nullptr},                   // simple
  };
  static_assert(std::size(kInputs) == std::size(kProfiles));
  for (std::size_t i = 0; i < std::size(kProfiles); ++i) {
    if (profile != kProfiles[i]) continue;
    const ProfileInputs& in = kInputs[i];
    std::vector<XrBindingSpec> b = {{"take_sample", in.take_sample},
                                    {"menu", in.menu, true, in.menu_right}};
    if (in.squeeze != nullptr) b.push_back({"squeeze", in.squeeze});
    b.push_back({"grip_pose", "/input/grip/pose"});
    b.push_back({"confirm_haptic", "/output/haptic"});
    return b;
  }
  return {};
}

DevicePose device_pose(const XrSpaceLocation& loc) {
  const XrSpaceLocationFlags need = XR_SPACE_LOCATION_POSITION_VALID_BIT |
                                    XR_SPACE_LOCATION_ORIENTATION_VALID_BIT |
                                    XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
  DevicePose d;
  d.valid = (loc.locationFlags & need) == need;
  d.position = Eigen::Vector3d(loc.pose.position.x, loc.pose.position.y, loc.pose.position.z);
  d.orientation = Eigen::Quaterniond(loc.pose.orientation.w, loc.pose.orientation.x,
                                     loc.pose.orientation.y, loc.pose.orientation.z)
                      .normalized();
  return d;
}

XrInput::XrInput(XrInstance instance, XrSession session) : instance_(instance), session_(session) {
  create_actions();
  for (const char* p : kProfiles) suggest(p);
  for (size_t h = 0; h < 2; ++h) {
    XrActionSpaceCreateInfo sci =
        xr_struct<XrActionSpaceCreateInfo>(XR_TYPE_ACTION_SPACE_CREATE_INFO);
    sci.action = grip_pose_;
    sci.subactionPath = hand_paths_[h];
    sci.poseInActionSpace.orientation.w = 1.0f;
    CALIPER_XR(instance_, xrCreateActionSpace(session_, &sci, &grip_spaces_[h]));
  }
  XrSessionActionSetsAttachInfo at =
      xr_struct<XrSessionActionSetsAttachInfo>(XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO);
  at.countActionSets = 1;
  at.actionSets = &set_;
  CALIPER_XR(instance_, xrAttachSessionActionSets(session_, &at));
}

XrInput::~XrInput() {
  for (XrSpace s : grip_spaces_)
    if (s) xrDestroySpace(s);
  if (set_) xrDestroyActionSet(set_);
}

void XrInput::create_actions() {
  XrActionSetCreateInfo asi = xr_struct<XrActionSetCreateInfo>(XR_TYPE_ACTION_SET_CREATE_INFO);
  std::strcpy(asi.actionSetName, "measuring");
  std::strcpy(asi.localizedActionSetName, "Measuring");
  CALIPER_XR(instance_, xrCreateActionSet(instance_, &asi, &set_));
  CALIPER_XR(instance_, xrStringToPath(instance_, "/user/hand/left", &hand_paths_[0]));
  CALIPER_XR(instance_, xrStringToPath(instance_, "/user/hand/right", &hand_paths_[1]));
  const auto make = [&](XrAction& a, XrActionType type, const char* name, const char* label) {
    XrActionCreateInfo ai = xr_struct<XrActionCreateInfo>(XR_TYPE_ACTION_CREATE_INFO);
    ai.actionType = type;
    std::strcpy(ai.actionName, name);
    std::strcpy(ai.localizedActionName, label);
    ai.countSubactionPaths = 2;
    ai.subactionPaths = hand_paths_.data();
    CALIPER_XR(instance_, xrCreateAction(set_, &ai, &a));
  };
  make(trigger_, XR_ACTION_TYPE_FLOAT_INPUT, "take_sample", "Take a sample (hold)");
  make(menu_, XR_ACTION_TYPE_BOOLEAN_INPUT, "menu", "Menu");
  make(squeeze_, XR_ACTION_TYPE_BOOLEAN_INPUT, "squeeze", "Squeeze");
  make(grip_pose_, XR_ACTION_TYPE_POSE_INPUT, "grip_pose", "Controller pose");
  make(haptic_, XR_ACTION_TYPE_VIBRATION_OUTPUT, "confirm_haptic", "Confirmation vibration");
}

XrAction XrInput::action(const std::string& name) const {
  if (name == "take_sample") return trigger_;
  if (name == "menu") return menu_;
  if (name == "squeeze") return squeeze_;
  if (name == "grip_pose") return grip_pose_;
  if (name == "confirm_haptic") return haptic_;
  return XR_NULL_HANDLE;
}

void XrInput::suggest(const char* profile) {
  const auto path = [&](const std::string& s) {
    XrPath p = XR_NULL_PATH;
    CALIPER_XR(instance_, xrStringToPath(instance_, s.c_str(), &p));
    return p;
  };
  std::vector<XrActionSuggestedBinding> b;
  for (const XrBindingSpec& x : suggested_bindings(profile))
    for (int side = 0; side < 2; ++side) {
      if ((side == 0 && !x.left) || (side == 1 && !x.right)) continue;
      b.push_back(
          {action(x.action),
           path(std::string(side == 0 ? "/user/hand/left" : "/user/hand/right") + x.input)});
    }
  XrInteractionProfileSuggestedBinding sb = xr_struct<XrInteractionProfileSuggestedBinding>(
      XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING);
  sb.interactionProfile = path(profile);
  sb.suggestedBindings = b.data();
  sb.countSuggestedBindings = static_cast<uint32_t>(b.size());
  CALIPER_XR(instance_, xrSuggestInteractionProfileBindings(instance_, &sb));
}

void XrInput::sync() {
  const XrActiveActionSet active{set_, XR_NULL_PATH};
  XrActionsSyncInfo sync = xr_struct<XrActionsSyncInfo>(XR_TYPE_ACTIONS_SYNC_INFO);
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  CALIPER_XR(instance_, xrSyncActions(session_, &sync));
}

void XrInput::read(XrSpace base, XrTime time, PoseFrame& frame) const {
  for (size_t h = 0; h < 2; ++h) {
    DevicePose& d = frame.device(h == 0 ? Device::Left : Device::Right);
    XrSpaceLocation loc = xr_struct<XrSpaceLocation>(XR_TYPE_SPACE_LOCATION);
    CALIPER_XR(instance_, xrLocateSpace(grip_spaces_[h], base, time, &loc));
    const DevicePose located = device_pose(loc);
    d.valid = located.valid;
    d.position = located.position;
    d.orientation = located.orientation;
    XrActionStateGetInfo gi = xr_struct<XrActionStateGetInfo>(XR_TYPE_ACTION_STATE_GET_INFO);
    gi.subactionPath = hand_paths_[h];
    gi.action = trigger_;
    XrActionStateFloat fs = xr_struct<XrActionStateFloat>(XR_TYPE_ACTION_STATE_FLOAT);
    CALIPER_XR(instance_, xrGetActionStateFloat(session_, &gi, &fs));
    d.trigger = fs.isActive ? std::clamp(static_cast<double>(fs.currentState), 0.0, 1.0) : 0.0;
    XrActionStateBoolean bs = xr_struct<XrActionStateBoolean>(XR_TYPE_ACTION_STATE_BOOLEAN);
    gi.action = menu_;
    CALIPER_XR(instance_, xrGetActionStateBoolean(session_, &gi, &bs));
    d.menu = bs.isActive && bs.currentState;
    gi.action = squeeze_;
    CALIPER_XR(instance_, xrGetActionStateBoolean(session_, &gi, &bs));
    d.squeeze = bs.isActive && bs.currentState;
  }
}

void XrInput::haptic_pulse(Tip hand, double amplitude, double seconds) {
  XrHapticVibration v = xr_struct<XrHapticVibration>(XR_TYPE_HAPTIC_VIBRATION);
  v.amplitude = static_cast<float>(amplitude);
  v.duration = static_cast<XrDuration>(seconds * 1e9);
  v.frequency = XR_FREQUENCY_UNSPECIFIED;
  XrHapticActionInfo hi = xr_struct<XrHapticActionInfo>(XR_TYPE_HAPTIC_ACTION_INFO);
  hi.action = haptic_;
  hi.subactionPath = hand_paths_[hand == Tip::Left ? 0 : 1];
  CALIPER_XR(instance_,
             xrApplyHapticFeedback(session_, &hi, reinterpret_cast<XrHapticBaseHeader*>(&v)));
}

std::string XrInput::current_profile() const {
  XrInteractionProfileState st =
      xr_struct<XrInteractionProfileState>(XR_TYPE_INTERACTION_PROFILE_STATE);
  if (XR_FAILED(xrGetCurrentInteractionProfile(session_, hand_paths_[1], &st)) ||
      st.interactionProfile == XR_NULL_PATH)
    return "";
  char buf[XR_MAX_PATH_LENGTH] = {};
  uint32_t len = 0;
  if (XR_FAILED(xrPathToString(instance_, st.interactionProfile, sizeof buf, &len, buf))) return "";
  return buf;
}

}  // namespace caliper::vr
