// Unit tests of caliper-vr's parts: pivot calibration step, tones, panel, controller config,
// pose sources.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "audio.hpp"
#include "caliper/body_ik.hpp"
#include "caliper/measurements.hpp"
#include "controller_config.hpp"
#include "panel.hpp"
#include "pivot.hpp"
#include "pose_source.hpp"
#include "render/text.hpp"
#include "smpl/constants.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"
#include "video.hpp"
#include "vr_app.hpp"

namespace caliper::vr {
namespace {

TEST(Pivot, RecoversTheTipOffsetFromARotatingController) {
  // The tip rests on a fixed point while the grip rotates about it: p_i = q - R_i t.
  const Eigen::Vector3d t(0.004, -0.031, 0.087), q(0.2, 0.01, 0.3);
  PivotCollector pivot(Tip::Right);
  std::optional<PivotCalibration> result;
  for (int i = 0; i <= 200 && !result; ++i) {
    PoseFrame f;
    f.time = i / 90.0;
    DevicePose& d = f.device(Device::Right);
    d.valid = true;
    const double a = 0.02 * i;
    d.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * std::sin(a), Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(0.6 * std::cos(1.3 * a), Eigen::Vector3d::UnitZ()));
    d.position = q - d.orientation * t;
    d.trigger = i < 200 ? 1.0 : 0.0;
    result = pivot.feed(f);
  }
  ASSERT_TRUE(result);
  EXPECT_LT((result->tip_offset - t).norm(), 1e-6);
  EXPECT_LT((result->pivot - q).norm(), 1e-6);
  EXPECT_LT(result->rms_residual, 1e-6);
}

TEST(Pivot, ShortHoldGivesNothing) {
  PivotCollector pivot(Tip::Left);
  PoseFrame f;
  f.device(Device::Left).valid = true;
  f.device(Device::Left).trigger = 1.0;
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(pivot.feed(f));
  f.device(Device::Left).trigger = 0.0;
  EXPECT_FALSE(pivot.feed(f));
}

TEST(Audio, ToneHasItsLengthPeakAndSilentGap) {
  ToneSpec s;
  const std::vector<short> x = tone_samples(s);
  EXPECT_EQ(x.size(), static_cast<size_t>(std::lround((s.duration + s.gap) * s.sample_rate)));
  int peak = 0;
  for (size_t i = 0; i < static_cast<size_t>(s.duration * s.sample_rate); ++i)
    peak = std::max(peak, std::abs(static_cast<int>(x[i])));
  EXPECT_NEAR(peak, s.amplitude * 32767, 0.01 * 32767);
  for (size_t i = static_cast<size_t>(std::ceil(s.duration * s.sample_rate)); i < x.size(); ++i)
    ASSERT_EQ(x[i], 0);
  EXPECT_EQ(x[0], 0) << "raised-cosine edge: no click";
}

TEST(Audio, SilentAudioCounts) {
  SilentAudio a;
  a.confirm();
  a.confirm();
  EXPECT_EQ(a.count(), 2);
}

TEST(Panel, WrapsAndDrawsText) {
  const std::vector<std::string> lines =
      wrap_text("one two three four five six seven eight nine ten", 2.0f, 120.0f);
  ASSERT_GT(lines.size(), 1u);
  for (const std::string& l : lines) EXPECT_LE(render::text_width(l, 2.0f), 120.0f) << l;
  PanelContent c;
  c.title = "Height";
  c.body = "Put the tip on your head.";
  const render::Image img = panel_image(c, 256, 160);
  ASSERT_EQ(img.width, 256);
  // Some pixels of the title area are dark (text), the background is light.
  int dark = 0;
  for (int y = 8; y < 40; ++y)
    for (int x = 8; x < 200; ++x) dark += img.pixel(x, y)[0] < 100;
  EXPECT_GT(dark, 20);
  EXPECT_GT(img.pixel(128, 150)[0], 200);
  PanelContent d = c;
  EXPECT_EQ(c, d);
  d.highlight = true;
  EXPECT_NE(c, d);
}

TEST(ControllerConfig, CommittedFileMatchesTheDefaults) {
  const ControllerConfig a =
      read_controller_config(std::string(CALIPER_SOURCE_DIR) + "/assets/protocol/controllers.json");
  const ControllerConfig b = default_controller_config();
  ASSERT_EQ(a.profiles.size(), b.profiles.size());
  for (const char* p : kProfiles) {
    ASSERT_TRUE(a.profiles.count(p)) << p;
    EXPECT_EQ(a.offsets(p).left, b.offsets(p).left) << p;
    EXPECT_EQ(a.offsets(p).right, b.offsets(p).right) << p;
  }
  EXPECT_EQ(a.offsets("/interaction_profiles/unknown").right, a.fallback.right);
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/controllers_roundtrip.json";
  ControllerConfig c = b;
  c.profiles[kProfiles[0]].right = Eigen::Vector3d(0.01, 0.02, 0.03);
  write_controller_config(path, c);
  EXPECT_EQ(read_controller_config(path).offsets(kProfiles[0]).right,
            Eigen::Vector3d(0.01, 0.02, 0.03));
  EXPECT_THROW(read_controller_config("/nonexistent/controllers.json"), std::exception);
}

TEST(Video, DecodesTheInstructionVideoToRgbaAndLoops) {
  const std::string path = std::string(CALIPER_SOURCE_DIR) + "/assets/media/arm-span.mp4";
  VideoPlayer v(path);
  EXPECT_NEAR(v.duration(), 3.0, 0.2);
  ASSERT_TRUE(v.seek_to(0.0));
  ASSERT_EQ(v.image().width, 192);
  ASSERT_EQ(v.image().height, 128);
  ASSERT_EQ(v.image().rgba.size(), 4u * 192 * 128);
  const std::vector<std::uint8_t> first = v.image().rgba;
  EXPECT_FALSE(v.seek_to(0.01)) << "same frame at 12 frames/s";
  ASSERT_TRUE(v.seek_to(1.5));
  EXPECT_NE(v.image().rgba, first) << "the arms have moved";
  // Past the end it loops: 3.0 s + 0 is the first frame again.
  ASSERT_TRUE(v.seek_to(v.duration() + 0.0));
  EXPECT_EQ(v.image().rgba, first);
  EXPECT_THROW(VideoPlayer("/nonexistent/video.mp4"), VideoError);
}

TEST(PoseSources, ReplayAndRecordingDecorator) {
  PoseLog log;
  log.header.role = "operator";
  for (int i = 0; i < 3; ++i) {
    PoseFrame f;
    f.time = i * 0.1;
    log.frames.push_back(f);
  }
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/recorded.jsonl";
  {
    RecordingPoseSource rec(std::make_unique<ReplayPoseSource>(log), path, log.header);
    EXPECT_EQ(rec.role(), "operator");
    rec.record_command({"skip", Json()});
    int n = 0;
    while (rec.next_frame()) ++n;
    EXPECT_EQ(n, 3);
  }
  const PoseLog back = read_pose_log(path);
  ASSERT_EQ(back.frames.size(), 3u);
  ASSERT_EQ(back.frames[0].commands.size(), 1u)
      << "a command from the window goes with the next frame";
  EXPECT_EQ(back.frames[0].commands[0].command, "skip");
  EXPECT_EQ(back.header.role, "operator");
}

/// A live-like source: the runtime reports the controllers only from frame 2, runs at 144 Hz,
/// and is lost after `lose_after` frames (never when negative).
class LiveLikeSource final : public PoseSource {
 public:
  explicit LiveLikeSource(int lose_after) : lose_after_(lose_after) {}
  std::optional<PoseFrame> next_frame() override {
    if (n_ == lose_after_) throw PoseSourceLost("the OpenXR runtime lost the session (test)");
    if (n_ >= 6) return std::nullopt;
    if (n_ == 2) profile_ = "/interaction_profiles/valve/index_controller";
    PoseFrame f;
    f.time = n_ / 144.0;
    ++n_;
    return f;
  }
  std::string interaction_profile() const override { return profile_; }
  double frame_rate() const override { return 144.0; }

 private:
  int lose_after_;
  int n_ = 0;
  std::string profile_;
};

TEST(PoseSources, RecordingWritesTheHeaderWithTheFirstFrameAndProfileChanges) {
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/recorded-live.jsonl";
  std::filesystem::remove(path);
  PoseLogHeader h;
  h.role = "self";
  h.weight = 65.0;
  h.sex = "male";
  {
    RecordingPoseSource rec(std::make_unique<LiveLikeSource>(-1), path, h);
    EXPECT_FALSE(std::filesystem::exists(path)) << "nothing is written before the first frame";
    while (rec.next_frame()) {
    }
  }
  const PoseLog log = read_pose_log(path);
  EXPECT_EQ(log.header.interaction_profile, "") << "not reported yet at the first frame";
  EXPECT_EQ(log.header.frame_rate, 144.0);
  ASSERT_TRUE(log.header.weight.has_value());
  EXPECT_EQ(*log.header.weight, 65.0);
  EXPECT_EQ(log.header.sex, "male");
  ASSERT_EQ(log.frames.size(), 6u);
  EXPECT_EQ(log.frames[1].interaction_profile, "");
  EXPECT_EQ(log.frames[2].interaction_profile, "/interaction_profiles/valve/index_controller");
  EXPECT_EQ(log.frames[3].interaction_profile, "") << "recorded once, when it changes";
  // Replayed, the profile changes on the same frame.
  ReplayPoseSource replay(log);
  std::vector<std::string> seen;
  while (replay.next_frame()) seen.push_back(replay.interaction_profile());
  EXPECT_EQ(seen[1], "");
  EXPECT_EQ(seen[2], "/interaction_profiles/valve/index_controller");
  EXPECT_EQ(seen[5], "/interaction_profiles/valve/index_controller");
}

TEST(PoseSources, ALostSourceIsRecordedAndReplayedAsLost) {
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/recorded-lost.jsonl";
  {
    RecordingPoseSource rec(std::make_unique<LiveLikeSource>(4), path, PoseLogHeader{});
    int n = 0;
    try {
      while (rec.next_frame()) ++n;
      ADD_FAILURE() << "the loss must come through";
    } catch (const PoseSourceLost& e) {
      EXPECT_STREQ(e.what(), "the OpenXR runtime lost the session (test)");
    }
    EXPECT_EQ(n, 4);
  }
  const PoseLog log = read_pose_log(path);
  EXPECT_EQ(log.frames.size(), 4u);
  EXPECT_EQ(log.lost, "the OpenXR runtime lost the session (test)");
  ReplayPoseSource replay(log);
  int n = 0;
  EXPECT_THROW(
      {
        while (replay.next_frame()) ++n;
      },
      PoseSourceLost);
  EXPECT_EQ(n, 4);
}

TEST(OperatorWindowFields, ShowTheSessionsTypedValues) {
  const Protocol p =
      read_protocol(std::string(CALIPER_SOURCE_DIR) + "/assets/protocol/virtual-caliper.json");
  SessionOptions o;
  EXPECT_EQ(typed_fields(MeasuringSession(p, o)).weight, 70.0) << "the field's start value";
  EXPECT_EQ(typed_fields(MeasuringSession(p, o)).sex, -1);
  o.weight = 65.0;
  o.sex = "male";
  const TypedFields t = typed_fields(MeasuringSession(p, o));
  EXPECT_EQ(t.weight, 65.0) << "--weight 65";
  EXPECT_EQ(t.sex, 1);
}

/// Signed volume of a closed mesh (positive when its triangles face out).
double signed_volume(const std::vector<float>& p, const std::vector<std::uint32_t>& tri) {
  double v = 0.0;
  for (size_t t = 0; t + 2 < tri.size(); t += 3) {
    Eigen::Vector3d c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = Eigen::Vector3d(p[3 * static_cast<size_t>(tri[t + static_cast<size_t>(k)])],
                             p[3 * tri[t + static_cast<size_t>(k)] + 1],
                             p[3 * tri[t + static_cast<size_t>(k)] + 2]);
    v += c[0].dot(c[1].cross(c[2])) / 6.0;
  }
  return v;
}

TEST(Mirror, TheUsersLeftHandIsTheReflectionsRight) {
  // The open female avatar driven by the embodiment IK with the left hand raised over the head,
  // the mirror 1 m in front of the user as the app puts it. In a real mirror the raised hand
  // appears on the user's own left, and it is the reflection's right hand; an avatar merely
  // turned round to face the user would raise its left hand on the user's right.
  using namespace ik_joint;
  using smpl::kPi;
  const smpl::BodyModel model =
      smpl::load_model(std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-female.npz");
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  const smpl::Vertices rest = shaped_vertices(model, betas);
  const Eigen::RowVector3d lo = rest.colwise().minCoeff(), hi = rest.colwise().maxCoeff();
  const Eigen::Vector3d shift(-(lo.x() + hi.x()) / 2, -lo.y(), -(lo.z() + hi.z()) / 2);
  const Eigen::Vector3d eyes =
      eyes_below_head_top(landmark_point(rest, landmarks_for(model).at("head_top")) + shift);
  BodyIk ik(make_ik_rig(model, betas, eyes));
  // The user stands at the origin facing +Z (their left is +X); the headset looks along its -Z.
  IkInput in;
  in.head.position = eyes;
  in.head.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()));
  RigidPose grip;
  grip.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d wrist = ik.rig().rest[kLeftShoulder] + Eigen::Vector3d(0.05, 0.38, 0.1);
  grip.position = wrist - grip.orientation * ik.options().grip.wrist_in_grip;
  in.grips[0] = grip;
  const IkPose& pose = ik.solve(in);
  ASSERT_LT((pose.joints[kLeftWrist] - wrist).norm(), 0.01);
  const smpl::Body body = smpl::evaluate(model, betas, pose.axis_angle(), pose.translation);

  MirrorPlane mirror;
  mirror.normal = Eigen::Vector3d::UnitZ();
  mirror.centre = Eigen::Vector3d(eyes.x(), 0.0, eyes.z()) + 1.0 * mirror.normal;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitY(), user_left = Eigen::Vector3d::UnitX();
  const auto joint = [&](int k) { return Eigen::Vector3d(body.joints.row(k).transpose()); };
  const Eigen::Vector3d left = mirror.reflect(joint(kLeftWrist)),
                        right = mirror.reflect(joint(kRightWrist)),
                        pelvis = mirror.reflect(joint(kPelvis)),
                        head = mirror.reflect(joint(kHead));
  // Seen from the eyes, the raised hand's image is on the user's left, above the head's image,
  // and the hanging right hand's image on the user's right.
  EXPECT_GT((left - eyes).dot(user_left), 0.1);
  EXPECT_LT((right - eyes).dot(user_left), -0.1);
  EXPECT_GT(left.y(), head.y());
  EXPECT_LT(right.y(), pelvis.y() + 0.1);
  // The reflection faces the user; its own left (up x facing) is the user's right, so the
  // raised hand is the reflection's right hand.
  const Eigen::Vector3d forward(std::sin(pose.body_yaw), 0.0, std::cos(pose.body_yaw));
  const Eigen::Vector3d facing = mirror.reflect(Eigen::Vector3d(joint(kPelvis) + forward)) - pelvis;
  EXPECT_GT(facing.normalized().dot((eyes - pelvis).normalized()), 0.9);
  const Eigen::Vector3d reflection_left = up.cross(facing).normalized();
  EXPECT_LT((left - pelvis).dot(reflection_left), -0.1);
  EXPECT_GT((right - pelvis).dot(reflection_left), 0.1);
  // The reflected mesh's vertices are the reflected body, and its turned triangles still face
  // out: the same volume, positive (the triangles as they were would give it negative).
  const std::vector<float> image = mirror.reflect(body.vertices);
  ASSERT_EQ(image.size(), static_cast<size_t>(body.vertices.size()));
  for (Eigen::Index i = 0; i < body.vertices.rows(); i += 97)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(image[static_cast<size_t>(3 * i + c)],
                  mirror.reflect(Eigen::Vector3d(body.vertices.row(i).transpose()))[c], 1e-6);
  std::vector<float> own(static_cast<size_t>(body.vertices.size()));
  std::vector<std::uint32_t> tri;
  for (Eigen::Index i = 0; i < body.vertices.rows(); ++i)
    for (int c = 0; c < 3; ++c)
      own[static_cast<size_t>(3 * i + c)] = static_cast<float>(body.vertices(i, c));
  for (Eigen::Index i = 0; i < model.faces.rows(); ++i)
    for (int c = 0; c < 3; ++c) tri.push_back(static_cast<std::uint32_t>(model.faces(i, c)));
  const double volume = signed_volume(own, tri);
  const double reflected = signed_volume(image, MirrorPlane::reflected_triangles(model.faces));
  EXPECT_GT(volume, 0.03);
  EXPECT_NEAR(reflected, volume, 1e-4 * volume);
  EXPECT_LT(signed_volume(image, tri), 0.0);
}

}  // namespace
}  // namespace caliper::vr
