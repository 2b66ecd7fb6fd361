// The platform-free VR session (apps/vr/src/vr_session.hpp), driven headless by a simulated
// person: feedback as data, the journal, the avatar and mirror at the end, the end button, the
// panel and the instruction video. This file links the VR core only (no OpenAL, FFmpeg, GL or
// OpenXR), and checks that the core's headers include none of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include "caliper/protocol.hpp"
#include "caliper/simulator.hpp"
#include "controller_config.hpp"
#include "smpl/io.hpp"
#include "vr_session.hpp"

namespace caliper::vr {
namespace {

const std::string kSource = CALIPER_SOURCE_DIR;

/// One simulated self-role session (female open model, an early release on the height step so
/// that one hold is rejected), shared by the tests.
const SimulatedSession& female_session() {
  static const SimulatedSession sim = [] {
    const Protocol protocol = read_protocol(kSource + "/assets/protocol/virtual-caliper.json");
    const smpl::BodyModel model = smpl::load_model(kSource + "/assets/models/caliper-female.npz");
    Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
    betas.head(3) << 0.5, -0.4, 0.3;
    SimulatorOptions o;
    o.early_release_step = "height";
    o.tip_offsets = default_controller_config().offsets(o.interaction_profile);
    return simulate_session(protocol, person_from_model(model, betas, 61.5, "female"), o);
  }();
  return sim;
}

VrSessionOptions session_options(const std::string& journal) {
  VrSessionOptions o;
  o.protocol = read_protocol(kSource + "/assets/protocol/virtual-caliper.json");
  o.protocol_dir = kSource + "/assets/protocol";
  o.tips = default_controller_config().offsets(female_session().log.header.interaction_profile);
  o.journal_path = journal;
  o.avatar.models_dir = kSource + "/assets/models";
  return o;
}

std::string session_temp_path(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(CALIPER_TEST_DATA_DIR) / "vr_session";
  std::filesystem::create_directories(dir);
  std::filesystem::remove_all(dir / name);
  return (dir / name).string();
}

/// What one whole run of the simulated log through a VrSession produced.
struct SessionRun {
  std::vector<std::vector<Feedback>> feedback;  ///< per frame
  std::vector<std::vector<SessionEvent>> events;
  std::vector<PanelContent> panels;  ///< per frame
  std::vector<std::optional<InstructionVideo>> videos;
  long finished_at = -1;  ///< first frame with finished()
  Eigen::Vector3d head_when_finished = Eigen::Vector3d::Zero();
  long end_requested_at = -1;
};

SessionRun run_all(VrSession& s) {
  SessionRun r;
  const PoseLog& log = female_session().log;
  for (size_t i = 0; i < log.frames.size(); ++i) {
    r.events.push_back(s.advance(log.frames[i]));
    r.feedback.push_back(s.feedback());
    r.panels.push_back(s.panel());
    r.videos.push_back(s.instruction_video());
    if (s.finished() && r.finished_at < 0) {
      r.finished_at = static_cast<long>(i);
      r.head_when_finished = log.frames[i].device(Device::Head).position;
    }
    if (s.end_requested() && r.end_requested_at < 0) r.end_requested_at = static_cast<long>(i);
  }
  return r;
}

TEST(VrSession, FeedbackIsOneToneAndOnePulsePerAcceptedSampleAndAWeakPulsePerRejection) {
  VrSession s(session_options(session_temp_path("feedback.jsonl")));
  const SessionRun r = run_all(s);
  ASSERT_TRUE(s.finished());
  EXPECT_EQ(s.accepted_this_run(), female_session().accepted_samples);
  EXPECT_EQ(s.rejected_this_run(), female_session().rejected_samples);
  ASSERT_GT(female_session().rejected_samples, 0) << "the early release must be rejected";
  int tones = 0, strong = 0, weak = 0;
  for (size_t i = 0; i < r.feedback.size(); ++i) {
    int accepted = 0, rejected = 0;
    for (const SessionEvent& e : r.events[i]) {
      accepted += e.type == EventType::SampleAccepted;
      rejected += e.type == EventType::SampleRejected;
    }
    int frame_tones = 0, frame_strong = 0, frame_weak = 0;
    for (size_t k = 0; k < r.feedback[i].size(); ++k) {
      const Feedback& f = r.feedback[i][k];
      if (f.kind == Feedback::Kind::Tone) {
        ++frame_tones;
        // The tone comes first, then the strong short pulse on the same hand.
        ASSERT_LT(k + 1, r.feedback[i].size());
        EXPECT_EQ(r.feedback[i][k + 1], (Feedback{Feedback::Kind::Haptic, f.hand, 0.8, 0.08}));
      } else if (f.amplitude == 0.8 && f.seconds == 0.08) {
        ++frame_strong;
      } else {
        EXPECT_EQ(f, (Feedback{Feedback::Kind::Haptic, f.hand, 0.3, 0.25}));
        ++frame_weak;
      }
    }
    EXPECT_EQ(frame_tones, accepted) << "frame " << i;
    EXPECT_EQ(frame_strong, accepted) << "frame " << i;
    EXPECT_EQ(frame_weak, rejected) << "frame " << i;
    tones += frame_tones;
    strong += frame_strong;
    weak += frame_weak;
  }
  EXPECT_EQ(tones, female_session().accepted_samples);
  EXPECT_EQ(strong, female_session().accepted_samples);
  EXPECT_EQ(weak, female_session().rejected_samples);
}

TEST(VrSession, TheJournalRestoresTheSameResult) {
  const std::string journal = session_temp_path("journal.jsonl");
  SessionResult first;
  {
    VrSession s(session_options(journal));
    run_all(s);
    ASSERT_TRUE(s.measuring().done());
    first = s.measuring().result();
  }
  VrSessionOptions o = session_options(journal);
  o.resume = read_journal(journal);
  ASSERT_FALSE(o.resume->records.empty());
  VrSession resumed(std::move(o));
  EXPECT_TRUE(resumed.measuring().done());
  EXPECT_FALSE(resumed.finished()) << "the avatar is made on the next frame";
  const SessionResult again = resumed.measuring().result();
  ASSERT_EQ(again.measurements.size(), first.measurements.size());
  for (const auto& kv : first.measurements)
    EXPECT_EQ(again.measurements.at(kv.first), kv.second) << kv.first;
  resumed.advance(female_session().log.frames.back());
  EXPECT_TRUE(resumed.finished());
  EXPECT_TRUE(resumed.avatar().has_value()) << resumed.avatar_error();
}

TEST(VrSession, TheAvatarIsMadeAtTheEndWithTheMirrorOneMetreInFront) {
  VrSession s(session_options(""));
  const SessionRun r = run_all(s);
  ASSERT_GE(r.finished_at, 0);
  ASSERT_TRUE(s.avatar()) << s.avatar_error();
  EXPECT_EQ(s.avatar()->regressor, "R5");
  EXPECT_GT(s.avatar()->eye_height, 1.2);
  EXPECT_LT(s.avatar()->eye_height, 2.0);
  const MirrorPlane& m = s.mirror();
  EXPECT_NEAR(m.normal.norm(), 1.0, 1e-12);
  EXPECT_EQ(m.normal.y(), 0.0) << "a vertical mirror";
  const Eigen::Vector3d h = r.head_when_finished;
  EXPECT_NEAR(
      (Eigen::Vector3d(m.centre.x(), 0.0, m.centre.z()) - Eigen::Vector3d(h.x(), 0.0, h.z()))
          .norm(),
      1.0, 1e-9);
  EXPECT_NEAR(m.centre.y(), s.measuring().floor().offset, 1e-12) << "standing on the floor";
  // The driven body: as many vertices as the model, and not its rest pose.
  ASSERT_NE(s.body_ik(), nullptr);
  EXPECT_GT(s.embodiment().frames, 0);
  const smpl::Vertices& v = s.posed_vertices();
  ASSERT_EQ(v.rows(), s.avatar()->avatar.vertices.rows());
  EXPECT_GT((v - s.avatar()->avatar.vertices).cwiseAbs().maxCoeff(), 0.01);
  EXPECT_FALSE(s.avatar()->headless_faces.empty());
  EXPECT_LT(s.avatar()->headless_faces.size(),
            static_cast<size_t>(s.avatar()->model->faces.size()));
}

TEST(VrSession, OnlyAMenuPressAfterCompletionEndsTheSession) {
  VrSession s(session_options(""));
  const SessionRun r = run_all(s);
  ASSERT_GE(r.end_requested_at, 0) << "the simulated person presses menu at the end";
  EXPECT_GT(r.end_requested_at, r.finished_at);
  // Before the session is complete the menu button does nothing.
  VrSession fresh(session_options(""));
  PoseFrame f = female_session().log.frames.front();
  f.device(Device::Right).valid = true;
  f.device(Device::Right).menu = true;
  for (int i = 0; i < 10; ++i) {
    f.time += 0.1;
    fresh.advance(f);
  }
  EXPECT_FALSE(fresh.end_requested());
}

TEST(VrSession, ThePanelSaysWhatThePhaseAsks) {
  VrSession s(session_options(""));
  const SessionRun r = run_all(s);
  std::set<std::string> titles;
  for (const PanelContent& p : r.panels) titles.insert(p.title);
  const size_t targets = s.options().protocol.floor.targets.size();
  for (size_t k = 1; k <= targets; ++k)
    EXPECT_TRUE(
        titles.count("Floor calibration " + std::to_string(k) + " / " + std::to_string(targets)))
        << k;
  EXPECT_TRUE(std::any_of(titles.begin(), titles.end(),
                          [](const std::string& t) { return t.find("(1/") != std::string::npos; }));
  const PanelContent& done = r.panels.back();
  EXPECT_EQ(done.title, "Done");
  ASSERT_FALSE(done.lines.empty());
  EXPECT_EQ(done.lines.back(), kEndHint);
  EXPECT_NE(done.body.find("R5"), std::string::npos) << done.body;
  EXPECT_TRUE(done.footer.empty());
  // Right after an accepted sample the panel is highlighted, kFlashSeconds later no more.
  for (size_t i = 0; i + 1 < r.events.size(); ++i)
    for (const SessionEvent& e : r.events[i])
      if (e.type == EventType::SampleAccepted) {
        EXPECT_TRUE(r.panels[i].highlight) << i;
      }
}

TEST(VrSession, TheArmSpanStepShowsItsInstructionVideo) {
  VrSession s(session_options(""));
  const SessionRun r = run_all(s);
  std::set<std::string> steps;
  for (const std::optional<InstructionVideo>& v : r.videos)
    if (v) {
      steps.insert(v->step);
      EXPECT_TRUE(std::filesystem::exists(v->path)) << v->path;
    }
  EXPECT_EQ(steps, std::set<std::string>{"arm_span_fingertips"});
  EXPECT_FALSE(r.videos.back().has_value()) << "no step, no video";
}

TEST(VrSession, TheSessionFileNamesTheAvatar) {
  VrSessionOptions o = session_options("");
  o.output_dir = session_temp_path("out");
  VrSession s(std::move(o));
  run_all(s);
  const std::vector<std::string> files = s.write_outputs();
  ASSERT_EQ(files.size(), 2u);
  EXPECT_TRUE(s.outputs_written());
  for (const std::string& f : files) EXPECT_GT(std::filesystem::file_size(f), 100u) << f;
  const Json j = read_json_file(files[0]);
  EXPECT_EQ(j.at("avatar").at("regressor").as_string(), "R5");
  EXPECT_EQ(j.at("accepted_samples_this_run").as_number(), female_session().accepted_samples);
}

/// Every header reached from `header` through quoted includes found in `dirs`, and the angle
/// includes they make.
void collect_includes(const std::filesystem::path& header,
                      const std::vector<std::filesystem::path>& dirs, std::set<std::string>& quoted,
                      std::set<std::string>& angled) {
  std::ifstream in(header);
  ASSERT_TRUE(in) << header;
  std::string line;
  while (std::getline(in, line)) {
    // `#include <name>` or `#include "name"` (no std::regex: GCC 12 warns inside it at -O1).
    const size_t hash = line.find_first_not_of(" \t");
    if (hash == std::string::npos || line[hash] != '#') continue;
    const size_t inc = line.find("include", hash);
    if (inc == std::string::npos) continue;
    const size_t open = line.find_first_of("<\"", inc);
    if (open == std::string::npos) continue;
    const size_t close = line.find(line[open] == '<' ? '>' : '"', open + 1);
    if (close == std::string::npos) continue;
    const std::string name = line.substr(open + 1, close - open - 1);
    if (line[open] == '<') {
      angled.insert(name);
      continue;
    }
    if (!quoted.insert(name).second) continue;
    for (const std::filesystem::path& d : dirs)
      if (std::filesystem::exists(d / name)) {
        collect_includes(d / name, dirs, quoted, angled);
        break;
      }
  }
}

TEST(VrCore, PublicHeadersAreFreeOfOpenAlFfmpegGlAndOpenXr) {
  const std::filesystem::path src(kSource);
  const std::vector<std::filesystem::path> dirs = {src / "apps/vr/src", src / "apps/render/include",
                                                   src / "libcaliper/include",
                                                   src / "libsmpl/include"};
  std::set<std::string> quoted, angled;
  for (const char* h : {"vr_session.hpp", "scene_builder.hpp", "panel.hpp", "pose_source.hpp"})
    collect_includes(src / "apps/vr/src" / h, dirs, quoted, angled);
  EXPECT_TRUE(quoted.count("render/scene.hpp")) << "the walk follows the includes";
  for (const std::string& q : quoted)
    for (const char* platform : {"audio.hpp", "video.hpp", "renderer.hpp", "gl_functions.hpp",
                                 "context.hpp", "glfw_context.hpp", "openxr"})
      EXPECT_EQ(q.find(platform), std::string::npos) << q;
  for (const std::string& a : angled)
    for (const char* platform : {"AL/", "libav", "libsw", "GL/", "GLFW/", "openxr/", "imgui"})
      EXPECT_NE(a.rfind(platform, 0), 0u) << a;
}

}  // namespace
}  // namespace caliper::vr
