/// \file openxr_program.hpp
/// The program unit of the live path, following the OpenXR 1.0 frame loop: instance and system,
/// session and reference spaces, swapchains, then per frame poll events -> xrWaitFrame ->
/// xrBeginFrame -> sync actions / locate the head, controllers and views (next_frame()) ->
/// render each eye into its swapchain image -> xrEndFrame with one projection layer
/// (submit()). The graphics API is a plugin (openxr_graphics.hpp), the controllers are the
/// input unit (openxr_input.hpp); the program is a PoseSource for the app.
#pragma once

#include <openxr/openxr.h>

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "openxr_graphics.hpp"
#include "openxr_input.hpp"
#include "pose_source.hpp"
#include "render/scene.hpp"

namespace caliper::vr {

class OpenXrProgram final : public PoseSource {
 public:
  /// Creates the instance (with the plugin's extensions), finds the headset, initialises the
  /// plugin's device, creates the session, the stage space (else the local one), the input and
  /// the swapchains. Throws NoRuntimeError when no runtime is available, std::runtime_error in
  /// plain words for a missing headset or graphics extension and for other failures.
  explicit OpenXrProgram(std::unique_ptr<XrGraphicsPlugin> graphics);
  ~OpenXrProgram() override;

  /// Polls events and, while the session runs, waits for and begins the next frame. Returns
  /// std::nullopt when the runtime ends the session or the window is closed.
  std::optional<PoseFrame> next_frame() override;
  std::string interaction_profile() const override { return profile_; }
  /// The runtime's display rate (1 / predictedDisplayPeriod of the last frame).
  double frame_rate() const override;
  void haptic_pulse(Tip hand, double amplitude, double seconds) override {
    input_->haptic_pulse(hand, amplitude, seconds);
  }

  /// Renders the frame begun by next_frame() (both eyes, when the runtime asks for rendering)
  /// and ends it; no-op when no frame is begun.
  void submit(const render::Scene& scene);
  XrGraphicsPlugin& graphics() { return *graphics_; }

 private:
  void create_instance();
  void create_session();
  void create_swapchains();
  bool poll_events();  ///< false when the app must quit
  bool on_state_change(XrSessionState state);
  void update_profile();
  void render_eye(int eye, const render::Scene& scene, XrCompositionLayerProjectionView& layer);

  std::unique_ptr<XrGraphicsPlugin> graphics_;
  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrSession session_ = XR_NULL_HANDLE;
  XrSpace stage_ = XR_NULL_HANDLE;
  XrSpace view_space_ = XR_NULL_HANDLE;
  std::unique_ptr<XrInput> input_;
  struct Eye {
    XrSwapchain swapchain = XR_NULL_HANDLE;
    int width = 0, height = 0;
  };
  std::array<Eye, 2> eyes_;
  std::array<XrView, 2> views_{};
  XrFrameState frame_state_{};
  bool running_ = false;
  bool frame_begun_ = false;
  double start_time_ = -1.0;
  std::string profile_;  ///< "" until the runtime reports the bound controllers
};

}  // namespace caliper::vr
