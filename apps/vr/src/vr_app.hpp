/// \file vr_app.hpp
/// The app layer of the VR measuring app: it joins the platform-free session (vr_session.hpp)
/// and scene builder (scene_builder.hpp) to what they leave out. Per frame it feeds the session,
/// plays its feedback (OpenAL tones, haptics through the pose source), decodes the current
/// step's instruction video (FFmpeg), uploads the scene's changed meshes and textures to the
/// renderer (GL) and swaps the GPU handles into the scene. The OpenXR loop (openxr_system.cpp),
/// the headless replay (main.cpp) and the benchmark drive this same class.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "audio.hpp"
#include "pose_source.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "scene_builder.hpp"
#include "video.hpp"
#include "vr_session.hpp"

namespace caliper::vr {

/// Everything the app needs: the session's options and the scene's.
struct VrAppOptions : VrSessionOptions, SceneOptions {};

class VrApp {
 public:
  /// `renderer` may be null (no drawing: the scene then holds no meshes or textured quads).
  /// Throws on unreadable files.
  VrApp(VrAppOptions options, Audio& audio, render::Renderer* renderer);
  ~VrApp();
  VrApp(const VrApp&) = delete;
  VrApp& operator=(const VrApp&) = delete;

  /// Feeds one frame to the session, then plays its feedback: tones on `audio`, haptic pulses
  /// through `haptics` if given. Returns this frame's events.
  const std::vector<SessionEvent>& advance(const PoseFrame& frame, PoseSource* haptics = nullptr);
  /// New tip offsets (the runtime reported another interaction profile).
  void set_tips(const TipOffsets& tips) { session_.set_tips(tips); }
  /// An operator command from the desktop window (recorded by the caller if recording).
  void command(const OperatorCommand& command) { session_.command(command); }

  /// Fills `scene` for the current state, uploading changed meshes and textures when a
  /// renderer was given.
  void build_scene(render::Scene& scene) { build_scene(scene, false); }
  /// As build_scene(); with `own_head` the driven body keeps its head (seen from outside: the
  /// operator's window), otherwise the head is left out (it would block the user's own view).
  void build_scene(render::Scene& scene, bool own_head);
  /// The views of scene_builder.hpp for the current state.
  std::vector<render::View> stereo_views(int eye_width, int eye_height) const {
    return vr::stereo_views(session_, eye_width, eye_height);
  }
  render::View first_person_view(int width, int height, float pitch_degrees = 60.0f) const {
    return vr::first_person_view(session_, width, height, pitch_degrees);
  }
  render::View overview(int width, int height) const { return vr::overview(width, height); }
  render::View operator_view(int width, int height) const {
    return vr::operator_view(session_, width, height);
  }

  /// The platform-free session behind the app.
  const VrSession& vr_session() const { return session_; }
  const MeasuringSession& session() const { return session_.measuring(); }
  const std::optional<AvatarOutcome>& avatar() const { return session_.avatar(); }
  bool finished() const { return session_.finished(); }
  const std::string& avatar_error() const { return session_.avatar_error(); }
  int accepted_this_run() const { return session_.accepted_this_run(); }
  int rejected_this_run() const { return session_.rejected_this_run(); }
  double time() const { return session_.time(); }
  const PoseFrame& last_frame() const { return session_.last_frame(); }
  double step_time() const { return session_.step_time(); }
  bool end_requested() const { return session_.end_requested(); }
  const BodyIk* body_ik() const { return session_.body_ik(); }
  const EmbodimentStats& embodiment() const { return session_.embodiment(); }
  const smpl::Vertices& posed_vertices() const { return session_.posed_vertices(); }
  PanelContent panel() const { return session_.panel(); }
  std::vector<std::string> write_outputs() { return session_.write_outputs(); }
  bool outputs_written() const { return session_.outputs_written(); }
  Json session_json() const { return session_.session_json(); }

 private:
  const render::Image* video_frame();
  void resolve_handles(render::Scene& scene);
  render::MeshHandle mesh_handle(render::MeshHandle slot);

  VrSession session_;
  SceneBuilder builder_;
  Audio& audio_;
  render::Renderer* renderer_;
  /// GPU copies of the builder's mesh slots and the panel, with the version uploaded.
  struct Uploaded {
    std::uint32_t handle = 0;
    std::uint64_t version = 0;
  };
  std::array<Uploaded, kMeshSlotEnd> meshes_{};
  Uploaded panel_{};
  // Instruction video of the current step.
  std::unique_ptr<VideoPlayer> video_;
  std::string video_step_;
  render::TextureHandle video_texture_ = 0;
};

}  // namespace caliper::vr
