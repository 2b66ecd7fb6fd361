// What the headset shows (see scene_builder.hpp).
//
// Sections: helpers | construction | build (floor targets, controllers, panel and video,
// demonstration, mirror) | views.
#include "scene_builder.hpp"

#include <algorithm>
#include <cmath>

#include "caliper/measurements.hpp"
#include "panel.hpp"
#include "render/camera.hpp"
#include "smpl/constants.hpp"
#include "smpl/io.hpp"

namespace caliper::vr {
namespace {

using smpl::kPiF;

constexpr double kIpd = 0.064;          ///< m, interpupillary distance of the stereo views
constexpr float kFovYDegrees = 100.0f;  ///< vertical field of view of the stereo views
const Eigen::Vector3d kPanelCentre(-0.15, 1.35, 0.95);  ///< in front of the user (who faces +Z)
constexpr double kPanelHalfWidth = 0.36;
const Eigen::Vector3d kDemoPosition(0.8, 0.0, 1.7);   ///< reference avatar beside the panel
constexpr double kMirrorDistance = 1.6;               ///< m in front of the head (rest avatar)
const render::Rgba kSkin{0.80f, 0.66f, 0.56f, 1.0f};  ///< the user's own body
const render::Rgba kHoldColour{0.95f, 0.6f, 0.05f, 1};

render::Vec3 f3(const Eigen::Vector3d& v) {
  return v.cast<float>();
}

render::Mat4 pose_matrix(const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  render::Mat4 m = render::Mat4::Identity();
  m.block<3, 3>(0, 0) = q.toRotationMatrix().cast<float>();
  m.block<3, 1>(0, 3) = p.cast<float>();
  return m;
}

/// The mirror's frame: a rectangle 2.1 m high and 2 x `half_width` wide standing on the floor
/// point `centre`, in the vertical plane whose horizontal normal is `normal`.
void add_mirror_frame(render::Scene& scene, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& normal, double half_width) {
  const Eigen::Vector3d side = Eigen::Vector3d(normal.z(), 0.0, -normal.x()) * half_width;
  const Eigen::Vector3d up(0.0, 2.1, 0.0);
  const Eigen::Vector3d corners[4] = {centre - side, centre + side, centre + side + up,
                                      centre - side + up};
  for (int i = 0; i < 4; ++i) {
    render::Line l;
    l.a = f3(corners[i]);
    l.b = f3(corners[(i + 1) % 4]);
    l.colour = {0.35f, 0.3f, 0.25f, 1};
    l.on_top = false;
    scene.lines.push_back(l);
  }
}

void add_circle(render::Scene& scene, const Eigen::Vector3d& centre, double radius,
                const render::Rgba& colour, double fraction = 1.0, int segments = 40) {
  const int n = std::max(1, static_cast<int>(std::ceil(segments * fraction)));
  for (int i = 0; i < n; ++i) {
    const double a0 = 2.0 * kPiF * fraction * i / n, a1 = 2.0 * kPiF * fraction * (i + 1) / n;
    render::Line l;
    l.a = f3(centre + radius * Eigen::Vector3d(std::sin(a0), 0.0, std::cos(a0)));
    l.b = f3(centre + radius * Eigen::Vector3d(std::sin(a1), 0.0, std::cos(a1)));
    l.colour = colour;
    l.on_top = false;
    scene.lines.push_back(l);
  }
}

void positions(const smpl::Vertices& v, std::vector<float>& out) {
  out.resize(static_cast<size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.rows(); ++i)
    for (int c = 0; c < 3; ++c) out[static_cast<size_t>(3 * i + c)] = static_cast<float>(v(i, c));
}

std::vector<std::uint32_t> triangles(const smpl::Faces& f) {
  std::vector<std::uint32_t> out(static_cast<size_t>(f.size()));
  for (Eigen::Index i = 0; i < f.rows(); ++i)
    for (int c = 0; c < 3; ++c)
      out[static_cast<size_t>(3 * i + c)] = static_cast<std::uint32_t>(f(i, c));
  return out;
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

void add_floor_targets(const VrSession& session, render::Scene& scene) {
  const SessionView& v = session.measuring().view();
  const std::vector<Eigen::Vector2d>& targets = session.options().protocol.floor.targets;
  const double y = 0.003;  // runtime floor until calibrated
  for (size_t i = 0; i < targets.size(); ++i) {
    const Eigen::Vector3d c(targets[i].x(), y, targets[i].y());
    const bool done = static_cast<int>(i) < v.floor_target;
    const bool current = static_cast<int>(i) == v.floor_target;
    const render::Rgba colour = done      ? render::Rgba{0.1f, 0.7f, 0.2f, 1}
                                : current ? render::Rgba{0.1f, 0.35f, 0.95f, 1}
                                          : render::Rgba{0.5f, 0.5f, 0.55f, 1};
    add_circle(scene, c, 0.08, colour);
    add_circle(scene, c, 0.075, colour);
    if (current) {
      const double pulse = 0.10 + 0.01 * std::sin(6.0 * session.time());
      add_circle(scene, c, pulse, colour);
      if (v.holding)
        add_circle(scene, c + Eigen::Vector3d(0, 0.002, 0), 0.13, kHoldColour, v.hold_progress);
    }
    render::Label label;
    label.text = std::to_string(i + 1);
    label.anchor = f3(c + Eigen::Vector3d(0.0, 0.02, -0.16));
    label.scale = 2.0f;
    scene.labels.push_back(label);
  }
}

void add_controllers(const VrSession& session, render::Scene& scene) {
  const SessionView& v = session.measuring().view();
  const bool flash = session.time() - v.last_accept_time < kFlashSeconds;
  const bool rejected = session.time() - session.last_reject_time() < kFlashSeconds;
  for (Device d : {Device::Left, Device::Right}) {
    const DevicePose& p = session.last_frame().device(d);
    if (!p.valid) continue;
    render::Box box;
    box.transform = pose_matrix(p.orientation, p.position);
    box.half_extents = {0.02f, 0.025f, 0.07f};
    scene.boxes.push_back(box);
    const TipOffsets& tips = session.options().tips;
    const Eigen::Vector3d& offset = d == Device::Left ? tips.left : tips.right;
    render::Point tip;
    tip.position = f3(tip_position(p, offset));
    tip.colour = flash      ? render::Rgba{0.1f, 0.8f, 0.2f, 1}
                 : rejected ? render::Rgba{0.9f, 0.15f, 0.1f, 1}
                            : render::Rgba{1.0f, 0.55f, 0.0f, 1};
    tip.size_px = flash ? 16.0f : 10.0f;
    scene.points.push_back(tip);
    const Tip hand = d == Device::Left ? Tip::Left : Tip::Right;
    if (v.holding && v.phase == Phase::Steps && hand == v.hold_hand)
      add_circle(scene, tip_position(p, offset), 0.05, kHoldColour, v.hold_progress, 24);
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Construction

SceneBuilder::SceneBuilder(const AvatarSettings& models, SceneOptions options) : options_(options) {
  if (!options_.demo_avatar) return;
  try {
    demo_model_ =
        models.model_path.empty()
            ? load_default_model(models.models_dir, "")
            : std::make_shared<const smpl::BodyModel>(smpl::load_model(models.model_path));
    const smpl::Vertices v = standing(demo_model_->v_template);
    for (const auto& kv : landmarks_for(*demo_model_))
      demo_landmarks_[kv.first] = landmark_point(v, kv.second);
    set_mesh(kDemoMesh, v, demo_model_->faces);
  } catch (const std::exception&) {
    demo_model_.reset();  // no model: the demonstration shows the controllers and targets only
  }
}

void SceneBuilder::set_mesh(MeshSlot slot, const smpl::Vertices& v, const smpl::Faces& f) {
  SceneAssets::Mesh& m = assets_.meshes[slot];
  positions(v, m.data.positions);
  m.data.indices = triangles(f);
  ++m.version;
}

// ---------------------------------------------------------------------------------------------
// Build

void SceneBuilder::build(const VrSession& session, render::Scene& scene,
                         const SceneInputs& inputs) {
  const MeasuringSession& ms = session.measuring();
  scene = render::Scene{};
  scene.background = {0.80f, 0.86f, 0.92f, 1.0f};
  scene.grid.visible = true;
  scene.grid.height = static_cast<float>(ms.floor().valid ? ms.floor().offset : 0.0);
  scene.grid.extent = 2.5f;
  scene.light_direction = {0.3f, 0.7f, -0.65f};  // from behind the user, who faces +Z
  if (ms.view().phase == Phase::Floor) add_floor_targets(session, scene);
  add_controllers(session, scene);
  add_panel(session, scene, inputs);
  if (ms.view().phase == Phase::Steps) add_demo(session, scene);
  if (ms.view().phase == Phase::Done) add_mirror(session, scene, inputs.own_head);
}

void SceneBuilder::add_panel(const VrSession& session, render::Scene& scene,
                             const SceneInputs& inputs) {
  // The panel's image is redrawn only when its text changes.
  const PanelContent content = session.panel();
  if (assets_.panel_version == 0 || content != panel_) {
    assets_.panel = panel_image(content, options_.panel_pixels, options_.panel_pixels * 5 / 8);
    ++assets_.panel_version;
  }
  panel_ = content;
  const double floor = session.measuring().floor().offset;
  const bool done = session.measuring().view().phase == Phase::Done;
  render::TexturedQuad quad;
  quad.texture = kPanelTexture;
  // Beside the mirror once done; in front of the user (who faces +Z: their right is -X) before.
  quad.centre = f3(kPanelCentre + Eigen::Vector3d(done ? -0.7 : 0.0, floor, done ? 0.3 : 0.0));
  quad.right = render::Vec3(static_cast<float>(-kPanelHalfWidth), 0, 0);
  quad.up = render::Vec3(0, static_cast<float>(kPanelHalfWidth * 5.0 / 8.0), 0);
  scene.quads.push_back(quad);
  if (!inputs.video) return;
  // The instruction video of the current step, under the panel, a little tilted towards the
  // user's eyes.
  render::TexturedQuad vq;
  vq.texture = kVideoTexture;
  const float aspect = static_cast<float>(inputs.video->height) /
                       static_cast<float>(std::max(1, inputs.video->width));
  const float half = 0.15f;
  vq.centre =
      f3(kPanelCentre +
         Eigen::Vector3d(0.0, floor - kPanelHalfWidth * 5.0 / 8.0 - half * aspect - 0.02, 0.0));
  vq.right = render::Vec3(-half, 0, 0);
  vq.up = render::Vec3(0, half * aspect, 0);
  scene.quads.push_back(vq);
}

void SceneBuilder::add_demo(const VrSession& session, render::Scene& scene) {
  const ProtocolStep* s = session.measuring().current_step();
  if (!demo_model_ || !s) return;
  // The reference avatar faces the user (turned by 180 degrees), half size beside the panel.
  const double scale = 0.45;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(kPiF, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d base =
      kDemoPosition + Eigen::Vector3d(0.0, session.measuring().floor().offset + 0.9, 0.0);
  const auto place = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(base + scale * (R * p));
  };
  render::MeshInstance inst;
  inst.mesh = kDemoMesh;
  inst.model.block<3, 3>(0, 0) = (scale * R).cast<float>();
  inst.model.block<3, 1>(0, 3) = base.cast<float>();
  inst.colour = {0.72f, 0.74f, 0.80f, 1.0f};
  scene.meshes.push_back(inst);
  // Controllers move from the avatar's sides to the landmarks, hold, and start again.
  const double cycle = 3.0;
  const double phase = std::fmod(std::max(0.0, session.step_time()), cycle) / cycle;
  const double a = smoothstep(phase / 0.6);
  for (size_t k = 0; k < s->landmarks.size(); ++k) {
    auto it = demo_landmarks_.find(s->landmarks[k]);
    if (it == demo_landmarks_.end()) continue;
    const Eigen::Vector3d target = place(it->second);
    const Eigen::Vector3d start =
        place(Eigen::Vector3d(s->tips[k] == Tip::Left ? 0.35 : -0.35, 0.9, 0.35));
    const Eigen::Vector3d tip = start + a * (target - start);
    render::Point lmk;
    lmk.position = f3(target);
    lmk.colour = {0.9f, 0.1f, 0.5f, 1};
    lmk.size_px = 9.0f;
    scene.points.push_back(lmk);
    render::Box ctl;
    ctl.transform =
        pose_matrix(Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX())),
                    tip + Eigen::Vector3d(0.0, 0.0, -0.04));
    ctl.half_extents = {0.01f, 0.0125f, 0.035f};
    ctl.colour = {0.25f, 0.25f, 0.3f, 1};
    scene.boxes.push_back(ctl);
    render::Line l;
    l.a = f3(tip);
    l.b = f3(target);
    l.colour = {0.9f, 0.1f, 0.5f, 1};
    l.on_top = true;
    if (a < 1.0) scene.lines.push_back(l);
  }
}

void SceneBuilder::add_driven_body(const VrSession& session, render::Scene& scene, bool own_head) {
  // The driven body: the user's own (first person, without the head) and its reflection in a
  // mirror fixed in the room (reflected vertices, triangles turned round so they still face
  // out).
  const AvatarOutcome& avatar = *session.avatar();
  const smpl::Vertices& v = session.posed_vertices();
  SceneAssets::Mesh& own = assets_.meshes[kOwnBodyMesh];
  SceneAssets::Mesh& mirrored = assets_.meshes[kMirrorBodyMesh];
  SceneAssets::Mesh& full = assets_.meshes[kFullBodyMesh];
  if (own.version == 0) {
    own.data.indices = avatar.headless_faces;
    mirrored.data.indices = MirrorPlane::reflected_triangles(avatar.model->faces);
    full.data.indices = triangles(avatar.model->faces);
  }
  positions(v, own.data.positions);
  ++own.version;
  mirrored.data.positions = session.mirror().reflect(v);
  ++mirrored.version;
  if (own_head || full.version == 0) {
    full.data.positions = own.data.positions;
    ++full.version;
  }
  render::MeshInstance reflection;
  reflection.mesh = kMirrorBodyMesh;
  scene.meshes.push_back(reflection);
  render::MeshInstance self;
  self.mesh = own_head ? kFullBodyMesh : kOwnBodyMesh;
  self.colour = kSkin;
  scene.meshes.push_back(self);
  add_mirror_frame(scene, session.mirror().centre, session.mirror().normal, 0.7);
}

void SceneBuilder::add_mirror(const VrSession& session, render::Scene& scene, bool own_head) {
  if (!session.avatar()) return;
  if (session.body_ik() && session.embodiment().frames > 0) {
    add_driven_body(session, scene, own_head);
    return;
  }
  // Not driven: the rest-pose avatar facing the user in a mirror kMirrorDistance in front of the
  // head, and aligned to the headset as the own body.
  if (assets_.meshes[kAvatarMesh].version == 0)
    set_mesh(kAvatarMesh, session.avatar()->avatar.vertices, session.avatar()->model->faces);
  const DevicePose& head = session.last_frame().device(Device::Head);
  const double yaw = head_yaw(head.orientation);
  const Eigen::Vector3d forward(std::sin(yaw), 0.0, std::cos(yaw));
  const Eigen::Vector3d head_floor(head.position.x(), session.measuring().floor().offset,
                                   head.position.z());
  render::MeshInstance mirrored;
  mirrored.mesh = kAvatarMesh;
  mirrored.model.block<3, 3>(0, 0) =
      Eigen::AngleAxisd(yaw + kPiF, Eigen::Vector3d::UnitY()).toRotationMatrix().cast<float>();
  mirrored.model.block<3, 1>(0, 3) = f3(head_floor + kMirrorDistance * forward);
  scene.meshes.push_back(mirrored);
  add_mirror_frame(scene, head_floor + (kMirrorDistance + 0.25) * forward, forward, 0.55);
  // First person: eyes at the head (in front of the head's centre line), facing where it looks.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d eye_offset(0.0, 0.0, 0.16);
  render::MeshInstance self;
  self.mesh = kAvatarMesh;
  self.model.block<3, 3>(0, 0) = R.cast<float>();
  self.model.block<3, 1>(0, 3) = f3(head_floor - R * eye_offset);
  self.colour = kSkin;
  scene.meshes.push_back(self);
}

// ---------------------------------------------------------------------------------------------
// Views

std::vector<render::View> stereo_views(const VrSession& session, int eye_width, int eye_height) {
  const DevicePose& head = session.last_frame().device(Device::Head);
  std::vector<render::View> views;
  for (int eye = 0; eye < 2; ++eye) {
    const Eigen::Vector3d offset((eye == 0 ? -0.5 : 0.5) * kIpd, 0.0, 0.0);
    const Eigen::Vector3d pos = head.position + head.orientation * offset;
    render::View v;
    v.viewport = {eye * eye_width, 0, eye_width, eye_height};
    v.camera.use_matrices = true;
    v.camera.view = pose_matrix(head.orientation, pos).inverse();
    v.camera.projection = render::perspective(
        kFovYDegrees * kPiF / 180.0f,
        static_cast<float>(eye_width) / static_cast<float>(eye_height), 0.05f, 50.0f);
    views.push_back(v);
  }
  return views;
}

render::View first_person_view(const VrSession& session, int width, int height,
                               float pitch_degrees) {
  const DevicePose& head = session.last_frame().device(Device::Head);
  const double yaw = head_yaw(head.orientation);
  // OpenXR looks along -Z: turn by yaw + 180 degrees about Y, then pitch down.
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(yaw + kPiF, Eigen::Vector3d::UnitY())) *
      Eigen::Quaterniond(
          Eigen::AngleAxisd(-pitch_degrees * kPiF / 180.0, Eigen::Vector3d::UnitX()));
  render::View v;
  v.viewport = {0, 0, width, height};
  v.camera.use_matrices = true;
  v.camera.view = pose_matrix(q, head.position).inverse();
  v.camera.projection =
      render::perspective(kFovYDegrees * kPiF / 180.0f,
                          static_cast<float>(width) / static_cast<float>(height), 0.05f, 50.0f);
  return v;
}

render::View operator_view(const VrSession& session, int width, int height) {
  const BodyIk* ik = session.body_ik();
  if (!ik || session.embodiment().frames == 0) {
    render::View v = stereo_views(session, width, height)[0];
    v.viewport = {0, 0, width, height};
    return v;
  }
  const IkPose& p = ik->pose();
  const Eigen::Vector3d chest = p.joints[ik_joint::kSpine3];
  const Eigen::Vector3d eye =
      chest + Eigen::AngleAxisd(p.body_yaw, Eigen::Vector3d::UnitY()) *
                  Eigen::Vector3d(1.2, 0.25, 1.9);  // the user's front left, a little higher
  render::View v;
  v.viewport = {0, 0, width, height};
  v.camera.eye = f3(eye);
  v.camera.target = f3(chest - Eigen::Vector3d(0.0, 0.25, 0.0));
  v.camera.fov_y_degrees = 55.0f;
  return v;
}

render::View overview(int width, int height) {
  render::View v;
  v.viewport = {0, 0, width, height};
  v.camera.eye = {0.9f, 2.3f, -2.0f};
  v.camera.target = {0.0f, 0.9f, 0.9f};
  v.camera.fov_y_degrees = 50.0f;
  return v;
}

}  // namespace caliper::vr
