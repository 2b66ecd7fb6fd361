// The VR app layer: feedback, video and GPU resources around the session (see vr_app.hpp).
#include "vr_app.hpp"

#include <algorithm>

namespace caliper::vr {

VrApp::VrApp(VrAppOptions options, Audio& audio, render::Renderer* renderer)
    : session_(static_cast<VrSessionOptions&&>(options)),
      builder_(session_.options().avatar, static_cast<const SceneOptions&>(options)),
      audio_(audio),
      renderer_(renderer) {}

VrApp::~VrApp() = default;

const std::vector<SessionEvent>& VrApp::advance(const PoseFrame& frame, PoseSource* haptics) {
  const std::vector<SessionEvent>& events = session_.advance(frame);
  for (const Feedback& f : session_.feedback()) {
    if (f.kind == Feedback::Kind::Tone)
      audio_.confirm();
    else if (haptics)
      haptics->haptic_pulse(f.hand, f.amplitude, f.seconds);
  }
  return events;
}

const render::Image* VrApp::video_frame() {
  const std::optional<InstructionVideo> want = session_.instruction_video();
  const std::string step = want ? want->step : "";
  if (step != video_step_) {
    video_.reset();
    video_step_ = step;
    if (want) {
      try {
        video_ = std::make_unique<VideoPlayer>(want->path);
      } catch (const VideoError&) {
        video_.reset();  // the panel text still explains the step
      }
    }
  }
  if (!video_ || !renderer_) return nullptr;
  if (video_->seek_to(std::max(0.0, session_.step_time())) || !video_texture_) {
    if (!video_texture_)
      video_texture_ = renderer_->upload_texture(video_->image());
    else
      renderer_->update_texture(video_texture_, video_->image());
  }
  return &video_->image();
}

void VrApp::build_scene(render::Scene& scene, bool own_head) {
  SceneInputs in;
  in.own_head = own_head;
  in.video = video_frame();
  builder_.build(session_, scene, in);
  resolve_handles(scene);
}

render::MeshHandle VrApp::mesh_handle(render::MeshHandle slot) {
  if (!renderer_ || slot == 0 || slot >= kMeshSlotEnd) return 0;
  const SceneAssets::Mesh& m = builder_.assets().meshes[slot];
  Uploaded& u = meshes_[slot];
  if (m.version == 0) return 0;
  if (!u.handle)
    u.handle = renderer_->upload_mesh(m.data);
  else if (u.version != m.version)
    renderer_->update_positions(u.handle, m.data.positions);
  u.version = m.version;
  return u.handle;
}

void VrApp::resolve_handles(render::Scene& scene) {
  for (render::MeshInstance& m : scene.meshes) m.mesh = mesh_handle(m.mesh);
  const SceneAssets& a = builder_.assets();
  if (renderer_ && a.panel_version != panel_.version) {
    if (!panel_.handle)
      panel_.handle = renderer_->upload_texture(a.panel);
    else
      renderer_->update_texture(panel_.handle, a.panel);
    panel_.version = a.panel_version;
  }
  for (render::TexturedQuad& q : scene.quads)
    q.texture = q.texture == kPanelTexture   ? panel_.handle
                : q.texture == kVideoTexture ? video_texture_
                                             : 0;
  // Without a renderer nothing was uploaded: nothing to draw by handle.
  scene.meshes.erase(std::remove_if(scene.meshes.begin(), scene.meshes.end(),
                                    [](const render::MeshInstance& m) { return m.mesh == 0; }),
                     scene.meshes.end());
  scene.quads.erase(std::remove_if(scene.quads.begin(), scene.quads.end(),
                                   [](const render::TexturedQuad& q) { return q.texture == 0; }),
                    scene.quads.end());
}

}  // namespace caliper::vr
