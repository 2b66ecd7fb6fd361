// The VR scene builder (apps/vr/src/scene_builder.hpp), headless: what it draws in each phase,
// the slots that stand in for GPU handles and the versions that tell the app layer what to
// upload. Links the VR core only.
#include <gtest/gtest.h>

#include <algorithm>

#include "caliper/protocol.hpp"
#include "caliper/simulator.hpp"
#include "controller_config.hpp"
#include "scene_builder.hpp"
#include "smpl/io.hpp"

namespace caliper::vr {
namespace {

const std::string kRepoDir = CALIPER_SOURCE_DIR;

const SimulatedSession& male_session() {
  static const SimulatedSession sim = [] {
    const Protocol protocol = read_protocol(kRepoDir + "/assets/protocol/virtual-caliper.json");
    const smpl::BodyModel model = smpl::load_model(kRepoDir + "/assets/models/caliper-male.npz");
    Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
    betas.head(2) << -0.3, 0.4;
    SimulatorOptions o;
    o.tip_offsets = default_controller_config().offsets(o.interaction_profile);
    return simulate_session(protocol, person_from_model(model, betas, 80.0, "male"), o);
  }();
  return sim;
}

VrSessionOptions scene_session_options() {
  VrSessionOptions o;
  o.protocol = read_protocol(kRepoDir + "/assets/protocol/virtual-caliper.json");
  o.protocol_dir = kRepoDir + "/assets/protocol";
  o.tips = default_controller_config().offsets(male_session().log.header.interaction_profile);
  o.avatar.models_dir = kRepoDir + "/assets/models";
  return o;
}

AvatarSettings models() {
  AvatarSettings a;
  a.models_dir = kRepoDir + "/assets/models";
  return a;
}

size_t count_mesh(const render::Scene& s, render::MeshHandle slot) {
  return static_cast<size_t>(std::count_if(s.meshes.begin(), s.meshes.end(),
                                           [&](const auto& m) { return m.mesh == slot; }));
}

size_t count_quad(const render::Scene& s, render::TextureHandle slot) {
  return static_cast<size_t>(std::count_if(s.quads.begin(), s.quads.end(),
                                           [&](const auto& q) { return q.texture == slot; }));
}

/// Advances `session` until `until` holds (or the log ends); returns whether it held.
template <typename Pred>
bool advance_until(VrSession& session, size_t& next, Pred until) {
  const PoseLog& log = male_session().log;
  while (next < log.frames.size()) {
    session.advance(log.frames[next++]);
    if (until()) return true;
  }
  return false;
}

TEST(SceneBuilder, TheFloorPhaseShowsNumberedTargetsControllersAndThePanel) {
  VrSession session(scene_session_options());
  SceneBuilder builder(models(), {});
  size_t next = 0;
  ASSERT_TRUE(advance_until(session, next, [&] {
    return session.measuring().view().phase == Phase::Floor &&
           session.last_frame().device(Device::Left).valid &&
           session.last_frame().device(Device::Right).valid;
  }));
  render::Scene scene;
  builder.build(session, scene);
  const size_t targets = session.options().protocol.floor.targets.size();
  ASSERT_EQ(scene.labels.size(), targets);
  for (size_t i = 0; i < targets; ++i) EXPECT_EQ(scene.labels[i].text, std::to_string(i + 1));
  EXPECT_EQ(scene.boxes.size(), 2u) << "one box per tracked controller";
  EXPECT_EQ(scene.points.size(), 2u) << "one tip per tracked controller";
  EXPECT_EQ(count_quad(scene, kPanelTexture), 1u);
  EXPECT_EQ(count_quad(scene, kVideoTexture), 0u) << "no video given";
  EXPECT_TRUE(scene.meshes.empty()) << "no demonstration during the floor calibration";
  // The panel's image is drawn at the configured size.
  EXPECT_EQ(builder.assets().panel.width, 512);
  EXPECT_EQ(builder.assets().panel.height, 320);
}

TEST(SceneBuilder, ThePanelIsRedrawnOnlyWhenItsTextChanges) {
  VrSession session(scene_session_options());
  SceneOptions so;
  so.panel_pixels = 256;
  SceneBuilder builder(models(), so);
  render::Scene scene;
  size_t next = 0;
  const PoseLog& log = male_session().log;
  std::uint64_t redraws = 0, changes = 0;
  PanelContent last;
  for (; next < std::min<size_t>(log.frames.size(), 600); ++next) {
    session.advance(log.frames[next]);
    const std::uint64_t before = builder.assets().panel_version;
    builder.build(session, scene);
    const PanelContent now = session.panel();
    const bool changed = next == 0 || now != last;
    changes += changed;
    redraws += builder.assets().panel_version - before;
    EXPECT_EQ(builder.assets().panel_version - before, changed ? 1u : 0u) << "frame " << next;
    last = now;
  }
  EXPECT_EQ(redraws, changes);
  EXPECT_GT(changes, 3u);
  EXPECT_LT(changes, 600u) << "most frames keep the text";
  EXPECT_EQ(builder.assets().panel.width, 256);
}

TEST(SceneBuilder, TheStepsShowTheDemonstrationAndTheVideoUnderThePanel) {
  VrSession session(scene_session_options());
  SceneBuilder builder(models(), {});
  ASSERT_GT(builder.assets().meshes[kDemoMesh].version, 0u) << "loaded with the builder";
  ASSERT_FALSE(builder.demo_landmarks().empty());
  size_t next = 0;
  ASSERT_TRUE(advance_until(session, next, [&] {
    const ProtocolStep* s = session.measuring().current_step();
    return s && s->id == "arm_span_fingertips" && session.step_time() > 0.5;
  }));
  render::Image frame;
  frame.width = 320;
  frame.height = 180;
  frame.rgba.assign(std::size_t{320} * 180 * 4, 0);
  SceneInputs in;
  in.video = &frame;
  render::Scene scene;
  builder.build(session, scene, in);
  EXPECT_EQ(count_mesh(scene, kDemoMesh), 1u);
  ASSERT_EQ(count_quad(scene, kVideoTexture), 1u);
  const auto video = std::find_if(scene.quads.begin(), scene.quads.end(),
                                  [](const auto& q) { return q.texture == kVideoTexture; });
  const auto panel = std::find_if(scene.quads.begin(), scene.quads.end(),
                                  [](const auto& q) { return q.texture == kPanelTexture; });
  EXPECT_NEAR(video->up.y() / -video->right.x(), 180.0 / 320.0, 1e-6) << "the frame's aspect";
  EXPECT_LT(video->centre.y() + video->up.y(), panel->centre.y() - panel->up.y())
      << "under the panel";
  // The demonstration's controllers: one box and one landmark per landmark of the step.
  const size_t landmarks = session.measuring().current_step()->landmarks.size();
  size_t controllers = 0;
  for (Device d : {Device::Left, Device::Right})
    controllers += session.last_frame().device(d).valid ? 1 : 0;
  EXPECT_EQ(scene.boxes.size(), landmarks + controllers);
}

TEST(SceneBuilder, TheDoneSceneDrawsTheDrivenBodyAndItsReflection) {
  VrSession session(scene_session_options());
  SceneBuilder builder(models(), {});
  size_t next = 0;
  ASSERT_TRUE(advance_until(session, next, [&] { return session.embodiment().frames > 2; }));
  ASSERT_TRUE(session.avatar()) << session.avatar_error();
  render::Scene scene;
  builder.build(session, scene);
  EXPECT_EQ(count_mesh(scene, kMirrorBodyMesh), 1u);
  EXPECT_EQ(count_mesh(scene, kOwnBodyMesh), 1u);
  EXPECT_EQ(count_mesh(scene, kFullBodyMesh), 0u) << "the user's own view: no head";
  EXPECT_EQ(count_mesh(scene, kDemoMesh), 0u);
  const SceneAssets& a = builder.assets();
  const smpl::Vertices& v = session.posed_vertices();
  EXPECT_EQ(a.meshes[kMirrorBodyMesh].data.positions, session.mirror().reflect(v));
  EXPECT_EQ(a.meshes[kMirrorBodyMesh].data.indices,
            MirrorPlane::reflected_triangles(session.avatar()->model->faces));
  EXPECT_EQ(a.meshes[kOwnBodyMesh].data.indices, session.avatar()->headless_faces);
  ASSERT_EQ(a.meshes[kOwnBodyMesh].data.positions.size(), static_cast<size_t>(v.size()));
  EXPECT_FLOAT_EQ(a.meshes[kOwnBodyMesh].data.positions[3], static_cast<float>(v(1, 0)));
  // Each build moves the driven meshes on; the full body only when it is drawn.
  const std::uint64_t own = a.meshes[kOwnBodyMesh].version, full = a.meshes[kFullBodyMesh].version;
  session.advance(male_session().log.frames[next++]);
  builder.build(session, scene);
  EXPECT_EQ(a.meshes[kOwnBodyMesh].version, own + 1);
  EXPECT_EQ(a.meshes[kFullBodyMesh].version, full);
  SceneInputs outside;
  outside.own_head = true;
  builder.build(session, scene, outside);
  EXPECT_EQ(count_mesh(scene, kFullBodyMesh), 1u);
  EXPECT_EQ(count_mesh(scene, kOwnBodyMesh), 0u);
  EXPECT_EQ(a.meshes[kFullBodyMesh].version, full + 1);
  EXPECT_EQ(a.meshes[kFullBodyMesh].data.positions, a.meshes[kOwnBodyMesh].data.positions);
  EXPECT_EQ(scene.lines.size(), 4u) << "the mirror's frame";
}

TEST(SceneBuilder, TheStereoViewsAreTheEyesOfTheHead) {
  VrSession session(scene_session_options());
  PoseFrame f;
  f.device(Device::Head).valid = true;
  f.device(Device::Head).position = Eigen::Vector3d(0.1, 1.6, 0.2);
  f.device(Device::Head).orientation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()));
  session.advance(f);
  const std::vector<render::View> v = stereo_views(session, 300, 200);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[1].viewport.x, 300);
  const Eigen::Vector3f l = v[0].camera.view.inverse().block<3, 1>(0, 3);
  const Eigen::Vector3f r = v[1].camera.view.inverse().block<3, 1>(0, 3);
  EXPECT_NEAR((r - l).norm(), 0.064, 1e-6) << "interpupillary distance";
  EXPECT_NEAR(((l + r) / 2 - f.device(Device::Head).position.cast<float>()).norm(), 0.0, 1e-6);
  // Without a driven body the operator sees the left eye's view.
  const render::View op = operator_view(session, 300, 200);
  EXPECT_TRUE(op.camera.view.isApprox(v[0].camera.view));
}

TEST(SceneBuilder, WithoutAModelTheDemonstrationIsLeftOut) {
  AvatarSettings none;
  none.models_dir = "/nonexistent";
  SceneBuilder builder(none, {});
  EXPECT_EQ(builder.assets().meshes[kDemoMesh].version, 0u);
  EXPECT_TRUE(builder.demo_landmarks().empty());
  SceneOptions off;
  off.demo_avatar = false;
  EXPECT_EQ(SceneBuilder(models(), off).assets().meshes[kDemoMesh].version, 0u);
}

}  // namespace
}  // namespace caliper::vr
