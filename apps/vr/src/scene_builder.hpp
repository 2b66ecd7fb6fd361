/// \file scene_builder.hpp
/// What the headset shows, decided from a const VrSession: floor targets, controllers and their
/// tips, the instruction panel (drawn on the CPU), the demonstration avatar, the avatar in the
/// mirror and the user's own body, and the views (stereo eyes, first person, operator,
/// overview). The builder does not touch the GPU: the render::Scene it fills refers to meshes
/// and textures by slot (MeshSlot, TextureSlot) in place of GPU handles, and SceneAssets holds
/// what each slot must contain, with a version that changes when the content does. The app layer
/// (vr_app.hpp) uploads changed slots and swaps its handles in before drawing.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "render/image.hpp"
#include "render/scene.hpp"
#include "vr_session.hpp"

namespace caliper::vr {

/// The meshes a VR scene draws; the values stand in render::MeshInstance::mesh.
enum MeshSlot : render::MeshHandle {
  kDemoMesh = 1,    ///< the demonstration (reference) avatar, rest pose
  kAvatarMesh,      ///< the made avatar, rest pose (when it cannot be driven)
  kOwnBodyMesh,     ///< the driven avatar without head and neck (first person)
  kFullBodyMesh,    ///< the driven avatar with its head (seen from outside)
  kMirrorBodyMesh,  ///< the driven avatar's reflection
  kMeshSlotEnd
};
/// The textures a VR scene draws; the values stand in render::TexturedQuad::texture.
enum TextureSlot : render::TextureHandle {
  kPanelTexture = 1,  ///< the instruction panel (SceneAssets::panel)
  kVideoTexture,      ///< the current instruction video frame (decoded by the app layer)
  kTextureSlotEnd
};

/// The CPU content behind the slots. A version of 0 means "not set yet"; a mesh whose version
/// changed after its first upload changed its positions only (indices stay).
struct SceneAssets {
  struct Mesh {
    render::MeshData data;
    std::uint64_t version = 0;
  };
  std::array<Mesh, kMeshSlotEnd> meshes;  ///< indexed by MeshSlot (index 0 unused)
  render::Image panel;                    ///< the instruction panel's image
  std::uint64_t panel_version = 0;
};

struct SceneOptions {
  bool demo_avatar = true;  ///< show the animated reference avatar on the instruction panel
  int panel_pixels = 512;   ///< instruction panel texture width (height = 5/8 of it)
};

/// What the app layer adds to a frame's scene.
struct SceneInputs {
  /// The driven body keeps its head (seen from outside: the operator's window); otherwise the
  /// head is left out (it would block the user's own view).
  bool own_head = false;
  /// The current instruction video frame (decoded by the app layer), or null: no video quad.
  const render::Image* video = nullptr;
};

class SceneBuilder {
 public:
  /// Loads the demonstration avatar (options.demo_avatar) from `models`: the explicit model, else
  /// the neutral open model; without a readable model the demonstration shows the controllers
  /// and targets only.
  SceneBuilder(const AvatarSettings& models, SceneOptions options);

  /// Fills `scene` (cleared first) for the session's current state and updates assets().
  void build(const VrSession& session, render::Scene& scene, const SceneInputs& inputs = {});
  const SceneAssets& assets() const { return assets_; }
  /// The demonstration avatar's landmarks, standing on y = 0 (empty without a model).
  const std::map<std::string, Eigen::Vector3d>& demo_landmarks() const { return demo_landmarks_; }

 private:
  void set_mesh(MeshSlot slot, const smpl::Vertices& v, const smpl::Faces& f);
  void add_panel(const VrSession& session, render::Scene& scene, const SceneInputs& inputs);
  void add_demo(const VrSession& session, render::Scene& scene);
  void add_mirror(const VrSession& session, render::Scene& scene, bool own_head);
  void add_driven_body(const VrSession& session, render::Scene& scene, bool own_head);

  SceneOptions options_;
  SceneAssets assets_;
  std::shared_ptr<const smpl::BodyModel> demo_model_;
  std::map<std::string, Eigen::Vector3d> demo_landmarks_;
  PanelContent panel_;
};

/// Two eye views side by side in a framebuffer of 2 eye_width x eye_height pixels, from the
/// last head pose (interpupillary distance 64 mm, symmetric 100 degree vertical field).
std::vector<render::View> stereo_views(const VrSession& session, int eye_width, int eye_height);
/// One view from the head looking down by `pitch_degrees` (the first-person check).
render::View first_person_view(const VrSession& session, int width, int height,
                               float pitch_degrees = 60.0f);
/// One view from behind and above the user (documentation pictures of the whole scene).
render::View overview(int width, int height);
/// The operator's view of the driven avatar: from in front and to the side of the user, 2.3 m
/// away, following the body's heading (the left eye's view before the avatar is driven).
render::View operator_view(const VrSession& session, int width, int height);

}  // namespace caliper::vr
