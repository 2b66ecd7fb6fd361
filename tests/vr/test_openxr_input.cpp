// The live path's input unit (apps/vr/src/openxr_input.hpp): the suggested bindings per
// controller and the conversion of located spaces. No runtime needed.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "controller_config.hpp"
#include "openxr_input.hpp"

namespace caliper::vr {
namespace {

std::set<std::string> actions_of(const std::vector<XrBindingSpec>& b, bool left) {
  std::set<std::string> out;
  for (const XrBindingSpec& x : b)
    if (left ? x.left : x.right) out.insert(x.action);
  return out;
}

TEST(OpenXrInput, EveryControllerBindsTriggerPoseAndHapticOnBothHands) {
  for (const char* profile : kProfiles) {
    const std::vector<XrBindingSpec> b = suggested_bindings(profile);
    ASSERT_FALSE(b.empty()) << profile;
    for (bool left : {true, false}) {
      const std::set<std::string> a = actions_of(b, left);
      for (const char* needed : {"take_sample", "grip_pose", "confirm_haptic"})
        EXPECT_TRUE(a.count(needed)) << profile << (left ? " left " : " right ") << needed;
    }
    for (const XrBindingSpec& x : b) {
      EXPECT_EQ(x.input.rfind('/', 0), 0u) << x.input;
      EXPECT_TRUE(x.left || x.right) << profile << " " << x.action;
    }
  }
  EXPECT_TRUE(suggested_bindings("/interaction_profiles/unknown").empty());
}

TEST(OpenXrInput, TheMenuActionIsWhereEachControllerHasIt) {
  const auto menu = [](const char* profile) {
    for (const XrBindingSpec& x : suggested_bindings(profile))
      if (x.action == "menu") return x;
    return XrBindingSpec{};
  };
  EXPECT_EQ(menu(kProfiles[0]).input, "/input/menu/click");  // Vive wand
  EXPECT_EQ(menu(kProfiles[1]).input, "/input/b/click");     // Index: B (docs/vr.md)
  const XrBindingSpec touch = menu(kProfiles[2]);            // Touch: the left hand only
  EXPECT_EQ(touch.input, "/input/menu/click");
  EXPECT_TRUE(touch.left);
  EXPECT_FALSE(touch.right);
  EXPECT_EQ(menu(kProfiles[3]).input, "/input/menu/click");  // simple controller
  // The simple controller has no squeeze and takes samples with select.
  const std::set<std::string> simple = actions_of(suggested_bindings(kProfiles[3]), true);
  EXPECT_FALSE(simple.count("squeeze"));
  EXPECT_EQ(suggested_bindings(kProfiles[3]).front().input, "/input/select/click");
}

XrSpaceLocation location(XrSpaceLocationFlags flags) {
  XrSpaceLocation l{};
  l.type = XR_TYPE_SPACE_LOCATION;
  l.locationFlags = flags;
  l.pose.position = {0.1f, 1.2f, -0.3f};
  l.pose.orientation = {0.0f, 0.0f, 0.0f, 2.0f};  // not unit: normalised on the way
  return l;
}

TEST(OpenXrInput, ALocatedSpaceIsValidOnlyWhenItsPositionIsTracked) {
  const XrSpaceLocationFlags all = XR_SPACE_LOCATION_POSITION_VALID_BIT |
                                   XR_SPACE_LOCATION_ORIENTATION_VALID_BIT |
                                   XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
  const DevicePose d = device_pose(location(all));
  EXPECT_TRUE(d.valid);
  EXPECT_NEAR((d.position - Eigen::Vector3d(0.1, 1.2, -0.3)).norm(), 0.0, 1e-6);
  EXPECT_NEAR(d.orientation.w(), 1.0, 1e-12);
  EXPECT_NEAR(d.orientation.norm(), 1.0, 1e-12);
  EXPECT_FALSE(device_pose(location(all & ~XR_SPACE_LOCATION_POSITION_TRACKED_BIT)).valid)
      << "an inferred position is not good enough to measure with";
  EXPECT_FALSE(device_pose(location(all & ~XR_SPACE_LOCATION_ORIENTATION_VALID_BIT)).valid);
  EXPECT_FALSE(device_pose(location(0)).valid);
}

}  // namespace
}  // namespace caliper::vr
