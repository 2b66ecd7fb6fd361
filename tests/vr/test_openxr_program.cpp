// The live path's program unit (apps/vr/src/openxr_program.hpp): the check of OpenXR results
// and the start without a runtime, with a graphics plugin that records what it is asked.
#include <gtest/gtest.h>

#include <cstdlib>

#include "openxr_check.hpp"
#include "openxr_errors.hpp"
#include "openxr_program.hpp"

namespace caliper::vr {
namespace {

TEST(OpenXrProgram, CheckedCallsSayWhatFailedAndALostSessionIsALostSource) {
  EXPECT_NO_THROW(CALIPER_XR(XR_NULL_HANDLE, XR_SUCCESS));
  EXPECT_NO_THROW(CALIPER_XR(XR_NULL_HANDLE, XR_SESSION_NOT_FOCUSED)) << "a success code";
  try {
    CALIPER_XR(XR_NULL_HANDLE, XR_ERROR_VALIDATION_FAILURE);
    FAIL() << "no throw";
  } catch (const PoseSourceLost&) {
    FAIL() << "not a lost source";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("XR_ERROR_VALIDATION_FAILURE"), std::string::npos) << m;
    EXPECT_NE(m.find("XrResult -1"), std::string::npos) << m;
    EXPECT_NE(m.find("test_openxr_program.cpp:"), std::string::npos) << m;
  }
  for (XrResult lost : {XR_ERROR_SESSION_LOST, XR_ERROR_INSTANCE_LOST}) {
    try {
      CALIPER_XR(XR_NULL_HANDLE, lost);
      FAIL() << "no throw";
    } catch (const PoseSourceLost& e) {
      EXPECT_NE(std::string(e.what()).find(lost == XR_ERROR_SESSION_LOST ? "session" : "instance"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_TRUE(is_no_runtime(XR_ERROR_RUNTIME_UNAVAILABLE));
  EXPECT_TRUE(is_no_runtime(XR_ERROR_FILE_ACCESS_ERROR));
  EXPECT_FALSE(is_no_runtime(XR_ERROR_FORM_FACTOR_UNAVAILABLE)) << "runtime there, no headset";
}

/// A graphics plugin that records the calls the program makes.
class RecordingGraphics final : public XrGraphicsPlugin {
 public:
  explicit RecordingGraphics(std::vector<std::string>& calls) : calls_(calls) {}
  std::vector<std::string> instance_extensions() const override {
    calls_.push_back("instance_extensions");
    return {"XR_KHR_opengl_enable"};
  }
  void initialize_device(XrInstance, XrSystemId) override { calls_.push_back("initialize"); }
  const void* graphics_binding() const override { return nullptr; }
  int64_t select_color_format(const std::vector<int64_t>& f) const override { return f.at(0); }
  void attach_swapchain(XrInstance, int, XrSwapchain, int, int) override {
    calls_.push_back("attach");
  }
  void render_view(int, std::uint32_t, const XrView&, const render::Scene&) override {}
  void release_targets() override { calls_.push_back("release"); }
  render::Renderer& renderer() override { throw std::logic_error("no renderer"); }
  bool poll_window() override { return true; }

 private:
  std::vector<std::string>& calls_;
};

TEST(OpenXrProgram, WithoutARuntimeItSaysSoBeforeTouchingTheGraphics) {
  // The loader reads XR_RUNTIME_JSON when the program asks it for the runtime's extensions.
  const char* old = std::getenv("XR_RUNTIME_JSON");
  const std::string saved = old ? old : "";
  setenv("XR_RUNTIME_JSON", "/nonexistent/caliper-test-runtime.json", 1);
  std::vector<std::string> calls;
  try {
    OpenXrProgram program(std::make_unique<RecordingGraphics>(calls));
    FAIL() << "a program without a runtime";
  } catch (const NoRuntimeError& e) {
    EXPECT_EQ(std::string(e.what()), kNoRuntimeMessage);
  }
  if (old)
    setenv("XR_RUNTIME_JSON", saved.c_str(), 1);
  else
    unsetenv("XR_RUNTIME_JSON");
  EXPECT_TRUE(std::find(calls.begin(), calls.end(), "initialize") == calls.end())
      << "no context or window without a runtime";
  EXPECT_TRUE(std::find(calls.begin(), calls.end(), "attach") == calls.end());
}

}  // namespace
}  // namespace caliper::vr
