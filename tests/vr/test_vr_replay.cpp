// caliper-vr end to end, headless: simulated sessions are replayed through the real executable
// (OSMesa rendering, OpenAL's wave backend writing the tones to a WAV file), and the results are
// compared with the simulated person's true measurements and the avatar the regressor gives for
// them. Also: the no-runtime message, bad logs, crash and --resume, golden images.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "caliper/avatar.hpp"
#include "caliper/journal.hpp"
#include "caliper/json.hpp"
#include "caliper/pose_log.hpp"
#include "caliper/regressor.hpp"
#include "caliper_test/random_model.hpp"
#include "render/image.hpp"
#include "smpl/io.hpp"

namespace {

namespace fs = std::filesystem;
using caliper::Json;

// The issue's acceptance bound: replayed measurements within 5 mm of the truth.
constexpr double kAcceptance = 0.005;  // m
// Golden images: llvmpipe is deterministic on one machine; allow small driver differences.
constexpr int kGoldenMaxMeanAbs = 2;             // mean channel difference, 0..255
constexpr double kGoldenMaxFractionOver = 0.01;  // pixels differing by more than 16

const std::string kExe = CALIPER_VR_EXE;
const std::string kSource = CALIPER_SOURCE_DIR;
const std::string kModel = kSource + "/assets/models/caliper-female.npz";

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh folder for one test.
std::string work_dir(const std::string& name) {
  const fs::path d = fs::path(CALIPER_TEST_DATA_DIR) / "vr" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

/// Runs caliper-vr with `args` in `dir`; audio goes to dir/<wav> through OpenAL's wave backend.
RunResult run_vr(const std::string& dir, const std::string& args,
                 const std::string& wav = "tones.wav", const std::string& env = "") {
  const std::string conf = dir + "/alsoft.conf";
  std::ofstream(conf)
      << "[general]\ndrivers = wave\nchannels = mono\nsample-type = int16\nfrequency = 44100\n"
      << "[wave]\nfile = " << dir << "/" << wav << "\n";
  const std::string cmd = "cd '" + dir + "' && ALSOFT_CONF='" + conf + "' ALSOFT_DRIVERS=wave " +
                          env + " '" + kExe + "' " + args + " > '" + dir + "/stdout.txt' 2> '" +
                          dir + "/stderr.txt'";
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(dir + "/stdout.txt");
  r.err = read_file(dir + "/stderr.txt");
  return r;
}

/// Tone bursts in a 16-bit PCM WAV (plain or WAVE_FORMAT_EXTENSIBLE): RMS over 5 ms windows,
/// a burst starts where the RMS rises above a tenth of full scale.
int count_tone_bursts(const std::string& path) {
  const std::string b = read_file(path);
  if (b.size() < 12 || b.compare(0, 4, "RIFF") != 0 || b.compare(8, 4, "WAVE") != 0) return -1;
  const auto u32 = [&](size_t i) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(b[i])) |
           static_cast<std::uint32_t>(static_cast<unsigned char>(b[i + 1])) << 8 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(b[i + 2])) << 16 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(b[i + 3])) << 24;
  };
  const auto u16 = [&](size_t i) {
    return static_cast<unsigned>(static_cast<unsigned char>(b[i])) |
           static_cast<unsigned>(static_cast<unsigned char>(b[i + 1])) << 8;
  };
  unsigned channels = 0, bits = 0, rate = 0;
  size_t data = 0, data_size = 0;
  for (size_t i = 12; i + 8 <= b.size();) {
    const std::uint32_t size = u32(i + 4);
    if (b.compare(i, 4, "fmt ") == 0) {
      channels = u16(i + 10);
      rate = u32(i + 12);
      bits = u16(i + 22);
    } else if (b.compare(i, 4, "data") == 0) {
      data = i + 8;
      data_size = std::min<size_t>(size, b.size() - data);
    }
    i += 8 + size + (size & 1u);
  }
  if (bits != 16 || channels == 0 || rate == 0 || data == 0) return -1;
  const size_t frames = data_size / (2 * static_cast<size_t>(channels));
  const size_t window = rate / 200;
  int bursts = 0;
  bool on = false;
  for (size_t w = 0; w + window <= frames; w += window) {
    double ss = 0.0;
    for (size_t k = w; k < w + window; ++k) {
      const auto v = static_cast<std::int16_t>(u16(data + 2 * static_cast<size_t>(channels) * k));
      ss += static_cast<double>(v) * v;
    }
    const bool now = std::sqrt(ss / static_cast<double>(window)) > 3276.7;
    if (now && !on) ++bursts;
    on = now;
  }
  return bursts;
}

/// Simulates a session with caliper-vr --simulate; returns the truth file's content.
Json simulate(const std::string& dir, const std::string& log, const std::string& extra) {
  const RunResult r =
      run_vr(dir, "--simulate " + log + " --model '" + kModel +
                      "' --sex female --weight 61.5 --betas '0.8 -0.6 0.4 0.2' " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return caliper::read_json_file(dir + "/" + log + ".truth.json");
}

/// Checks a finished replay: measurements within 5 mm, one tone per accepted sample, the
/// expected avatar.
void expect_session_matches(const std::string& dir, const Json& truth,
                            const std::string& wav = "tones.wav") {
  const Json session = caliper::read_json_file(dir + "/out/session.json");
  ASSERT_TRUE(session.at("complete").as_bool());
  caliper::MeasurementMap measured;
  for (const auto& kv : truth.at("truth").as_object()) {
    const Json& m = session.at("measurements").at(kv.first);
    measured[kv.first] = m.at("value").as_number();
    EXPECT_NEAR(m.at("value").as_number(), kv.second.as_number(), kAcceptance) << kv.first;
  }
  EXPECT_EQ(session.at("sex").as_string(), "female");
  const int accepted = session.at("accepted_samples_this_run").as_int();
  EXPECT_GT(accepted, 0);
  EXPECT_EQ(count_tone_bursts(dir + "/" + wav), accepted) << "one tone per accepted sample";

  // The avatar: the one R5 makes (caliper::create_avatar(), from the model's shape curve, as the
  // session does) from the true measurements, within what a 5 mm error in each input can change
  // it: |d beta_i| <= sum_j |A_ij| * 5 mm (weight is exact). Not the paper's linear prediction
  // (r5.predict()): the simulated woman's 61.5 kg is not her body's (89.6 kg), and so far from the
  // population the two part by more than that bound (beta 3: 0.114 against 0.110 on the models
  // of 2026-12-07; measurements within 0.5 mm).
  ASSERT_TRUE(session.contains("avatar")) << session.dump(2);
  EXPECT_EQ(session.at("avatar").at("regressor").as_string(), "R5");
  const smpl::BodyModel model = smpl::load_model(kModel);
  const caliper::RegressorSet set = caliper::train_regressors(model);
  const caliper::LinearRegressor& r5 = *set.find("R5");
  caliper::MeasurementMap true_inputs;
  for (const std::string& id : r5.inputs()) true_inputs[id] = truth.at("truth").at(id).as_number();
  caliper::AvatarOptions options;
  options.circumferences = false;
  const Eigen::VectorXd expected =
      caliper::create_avatar(model, r5, true_inputs, options).betas.head(r5.coefficients().rows());
  const std::vector<double> betas = session.at("avatar").at("betas").as_numbers();
  ASSERT_GE(betas.size(), static_cast<size_t>(expected.size()));
  const Eigen::MatrixXd& A = r5.coefficients();
  for (Eigen::Index i = 0; i < expected.size(); ++i) {
    double bound = 1e-9;
    for (size_t j = 0; j < r5.inputs().size(); ++j)
      if (r5.inputs()[j] != "weight")
        bound += std::abs(A(i, static_cast<Eigen::Index>(j))) * kAcceptance;
    EXPECT_NEAR(betas[static_cast<size_t>(i)], expected[i], bound) << "beta " << i;
  }
  EXPECT_TRUE(fs::exists(dir + "/out/avatar.glb"));
}

const std::string kReplayArgs = " --out out --eye-size 96x107 --draw-every 25 ";

TEST(VrApp, NoRuntimeSaysSoInPlainWords) {
  const std::string dir = work_dir("no_runtime");
  const RunResult r =
      run_vr(dir, "", "tones.wav", "XR_RUNTIME_JSON=/nonexistent/openxr_runtime.json");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(
      r.err.find(
          "No OpenXR runtime is running. Start SteamVR or Monado, or set XR_RUNTIME_JSON; to test "
          "without a headset use --replay FILE"),
      std::string::npos)
      << r.err;
}

TEST(VrApp, SelfRoleReplay) {
  const std::string dir = work_dir("self");
  const Json truth = simulate(dir, "log.jsonl", "--role self");
  const RunResult r = run_vr(dir, "--replay log.jsonl" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
  EXPECT_EQ(truth.at("accepted_samples").as_int(), 15);
}

TEST(VrApp, OperatorRoleReplayWithRedo) {
  const std::string dir = work_dir("operator");
  const Json truth = simulate(dir, "log.jsonl", "--role operator --redo hip_width");
  const RunResult r = run_vr(dir, "--replay log.jsonl" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
  const Json session = caliper::read_json_file(dir + "/out/session.json");
  EXPECT_EQ(session.at("role").as_string(), "operator");
  EXPECT_EQ(session.at("accepted_samples_this_run").as_int(), 16)
      << "5 floor + 5 x 2 takes + 1 redone";
}

TEST(VrApp, TrackingDropoutDuringAHold) {
  const std::string dir = work_dir("dropout");
  const Json truth = simulate(dir, "log.jsonl", "--dropout arm_length");
  const RunResult r = run_vr(dir, "--replay log.jsonl" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
  const Json session = caliper::read_json_file(dir + "/out/session.json");
  EXPECT_EQ(session.at("rejected_samples_this_run").as_int(), 1);
}

TEST(VrApp, IsakThirdTake) {
  const std::string dir = work_dir("third_take");
  const Json truth = simulate(dir, "log.jsonl", "--third-take height --noise 0.0");
  const RunResult r = run_vr(dir, "--replay log.jsonl" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
  const Json session = caliper::read_json_file(dir + "/out/session.json");
  EXPECT_EQ(session.at("measurements").at("height").at("takes").size(), 3u);
  EXPECT_EQ(session.at("accepted_samples_this_run").as_int(), 16);
}

TEST(VrApp, CrashAndResume) {
  const std::string dir = work_dir("resume");
  const Json truth = simulate(dir, "log.jsonl", "--role self --noise 0.0");
  // Cut the log at a quiet frame near the middle: part 1 ends there (the "crash"), part 2 is the
  // rest (with the header again).
  const caliper::PoseLog log = caliper::read_pose_log(dir + "/log.jsonl");
  const std::vector<double> quiet = truth.at("quiet_frames").as_numbers();
  const size_t cut = static_cast<size_t>(quiet[quiet.size() / 2]);
  caliper::PoseLog first, second;
  first.header = second.header = log.header;
  first.frames.assign(log.frames.begin(), log.frames.begin() + static_cast<long>(cut));
  second.frames.assign(log.frames.begin() + static_cast<long>(cut), log.frames.end());
  caliper::write_pose_log(dir + "/part1.jsonl", first);
  caliper::write_pose_log(dir + "/part2.jsonl", second);

  const RunResult r1 = run_vr(dir, "--replay part1.jsonl" + kReplayArgs, "tones1.wav");
  EXPECT_EQ(r1.exit_code, 3) << r1.err;
  EXPECT_NE(r1.err.find("--resume"), std::string::npos) << r1.err;
  const Json s1 = caliper::read_json_file(dir + "/out/session.json");
  EXPECT_FALSE(s1.at("complete").as_bool());
  const int accepted1 = s1.at("accepted_samples_this_run").as_int();
  EXPECT_EQ(count_tone_bursts(dir + "/tones1.wav"), accepted1);

  const RunResult r2 =
      run_vr(dir, "--replay part2.jsonl --resume out/journal.jsonl" + kReplayArgs, "tones2.wav");
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  expect_session_matches(dir, truth, "tones2.wav");
  const Json s2 = caliper::read_json_file(dir + "/out/session.json");
  EXPECT_EQ(accepted1 + s2.at("accepted_samples_this_run").as_int(),
            truth.at("accepted_samples").as_int());
  EXPECT_GT(accepted1, 5) << "the crash happened after the floor calibration";
}

/// Occurrences of `needle` in `hay`.
size_t count_of(const std::string& hay, const std::string& needle) {
  size_t n = 0;
  for (size_t p = hay.find(needle); p != std::string::npos; p = hay.find(needle, p + 1)) ++n;
  return n;
}

TEST(VrApp, LiveRecordingWhoseProfileIsReportedLateReplaysToTheSameResult) {
  // A live recording: the header is written with the first frame, before the runtime reported
  // the bound controllers (Valve Index); the frame where it did names the profile. Weight and
  // sex came from the command line.
  const std::string dir = work_dir("late_profile");
  const std::string index = "/interaction_profiles/valve/index_controller";
  const Json truth = simulate(dir, "index.jsonl", "--typed-in-log no --profile " + index);
  caliper::PoseLog live = caliper::read_pose_log(dir + "/index.jsonl");
  ASSERT_EQ(live.header.interaction_profile, index);
  live.header.interaction_profile = "";
  live.frames[3].interaction_profile = index;
  caliper::write_pose_log(dir + "/live.jsonl", live);
  // Replayed with the live command line's typed values, re-recorded.
  const RunResult r = run_vr(dir,
                             "--replay live.jsonl --weight 61.5 --sex female --record "
                             "rec.jsonl" +
                                 kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
  const caliper::PoseLog rec = caliper::read_pose_log(dir + "/rec.jsonl");
  EXPECT_EQ(rec.header.frame_rate, 90.0) << "the source's frame rate";
  ASSERT_TRUE(rec.header.weight.has_value());
  EXPECT_EQ(*rec.header.weight, 61.5);
  EXPECT_EQ(rec.header.sex, "female");
  EXPECT_EQ(rec.frames.at(3).interaction_profile, index);
  // The recording alone (no --weight, no --sex) replays to the same result.
  const std::string dir2 = work_dir("late_profile_rec");
  fs::copy_file(dir + "/rec.jsonl", dir2 + "/rec.jsonl");
  const RunResult r2 = run_vr(dir2, "--replay rec.jsonl" + kReplayArgs);
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  expect_session_matches(dir2, truth);
  // Without the profile change the Vive-like fallback offsets measure wrongly: the change matters.
  caliper::PoseLog stale = live;
  stale.frames[3].interaction_profile.clear();
  caliper::write_pose_log(dir + "/stale.jsonl", stale);
  const std::string dir3 = work_dir("late_profile_stale");
  fs::copy_file(dir + "/stale.jsonl", dir3 + "/stale.jsonl");
  const RunResult r3 =
      run_vr(dir3, "--replay stale.jsonl --weight 61.5 --sex female" + kReplayArgs);
  ASSERT_EQ(r3.exit_code, 0) << r3.err;
  const Json s3 = caliper::read_json_file(dir3 + "/out/session.json");
  double worst = 0.0;
  for (const auto& kv : truth.at("truth").as_object())
    worst = std::max(worst, std::abs(s3.at("measurements").at(kv.first).at("value").as_number() -
                                     kv.second.as_number()));
  EXPECT_GT(worst, kAcceptance);
}

TEST(VrApp, LostRuntimeEndsWithSummaryExit3AndTheResumeCommand) {
  const std::string dir = work_dir("lost");
  const Json truth = simulate(dir, "log.jsonl", "--role self --noise 0.0");
  const caliper::PoseLog log = caliper::read_pose_log(dir + "/log.jsonl");
  const std::vector<double> quiet = truth.at("quiet_frames").as_numbers();
  const size_t cut = static_cast<size_t>(quiet[quiet.size() / 2]);
  caliper::PoseLog first, second;
  first.header = second.header = log.header;
  first.frames.assign(log.frames.begin(), log.frames.begin() + static_cast<long>(cut));
  first.lost = "the OpenXR runtime lost the session (XR_ERROR_SESSION_LOST from xrWaitFrame)";
  second.frames.assign(log.frames.begin() + static_cast<long>(cut), log.frames.end());
  caliper::write_pose_log(dir + "/part1.jsonl", first);
  caliper::write_pose_log(dir + "/part2.jsonl", second);
  const RunResult r = run_vr(dir, "--replay part1.jsonl" + kReplayArgs);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("caliper-vr: " + first.lost), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("accepted samples:"), std::string::npos) << "the summary: " << r.out;
  const std::string expected =
      "caliper-vr --replay part1.jsonl --out out --eye-size 96x107 --draw-every 25 --resume "
      "out/journal.jsonl";
  ASSERT_NE(r.err.find("continue with:\n  " + expected + "\n"), std::string::npos) << r.err;
  // That command (given the rest of the log) finishes the session.
  std::string cmd = expected.substr(std::string("caliper-vr ").size());
  cmd.replace(cmd.find("part1"), 5, "part2");
  const RunResult r2 = run_vr(dir, cmd, "tones2.wav");
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  expect_session_matches(dir, truth, "tones2.wav");
}

TEST(VrApp, TheMenuButtonEndsACompletedSessionAndOutputsAreReportedOnce) {
  const std::string dir = work_dir("end_button");
  const Json truth = simulate(dir, "log.jsonl", "--role self --frame-rate 30");
  const RunResult r = run_vr(dir, "--replay log.jsonl" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
  EXPECT_NE(r.out.find("To finish, press the menu button of a controller"), std::string::npos)
      << r.out;
  EXPECT_EQ(count_of(r.out, "wrote "), 2u) << r.out;
  EXPECT_EQ(count_of(r.out, "wrote out/session.json"), 1u);
  // It ended on the press: the frames after it (0.8 s at 30 Hz from the press) were not read.
  const long frames = truth.at("frames").as_int();
  long replayed = -1;
  std::sscanf(r.out.substr(r.out.find("replayed ")).c_str(), "replayed %ld", &replayed);
  EXPECT_EQ(replayed, frames - 24 + 1) << r.out;
}

TEST(VrApp, AnOperatorSessionStoppedBeforeStartSaysSo) {
  const std::string dir = work_dir("before_start");
  simulate(dir, "log.jsonl", "--role operator");
  // The operator presses Start a second in (not on the first frame as the simulator does).
  caliper::PoseLog log = caliper::read_pose_log(dir + "/log.jsonl");
  ASSERT_EQ(log.frames[0].commands.at(0).command, "start");
  log.frames[0].commands.clear();
  log.frames[30].commands.push_back({"start", Json()});
  caliper::write_pose_log(dir + "/late-start.jsonl", log);
  const RunResult r = run_vr(dir, "--replay late-start.jsonl --max-frames 10" + kReplayArgs);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("(before the operator pressed Start)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("floor calibration"), std::string::npos) << r.err;
}

/// The issue's bounds over the scripted motions of a replay's embodiment report (frame rate
/// `rate`): wrist within 1 cm when reachable, no hand in the torso, no joint-limit violation, no
/// joint move over 5 cm per frame; and the mirror pictures with raised, crossed and bent arms.
void expect_embodiment_bounds(const std::string& dir, const Json& truth, double rate) {
  const Json report = caliper::read_json_file(dir + "/report.json");
  const Json& per = report.at("per_frame");
  const std::vector<double> time = per.at("time").as_numbers();
  const std::vector<double> wrist = per.at("wrist_error_m").as_numbers();
  const std::vector<double> step = per.at("joint_step_m").as_numbers();
  const std::vector<double> limits = per.at("limit_violations").as_numbers();
  const std::vector<double> window = truth.at("motion_frames").as_numbers();
  const double t0 = window[0] / rate, t1 = window[1] / rate;
  // Bounds from the issue: wrist within 1 cm when reachable, no joint move over 5 cm per frame
  // (at 90 Hz; at a lower rate the same speed moves a joint further: the bound scales).
  const double kWristBound = 0.01, kStepBound = 0.05 * 90.0 / rate;
  size_t in_window = 0, reachable = 0;
  for (size_t i = 0; i < time.size(); ++i) {
    if (time[i] < t0 - 1e-9 || time[i] >= t1 - 1e-9) continue;
    ++in_window;
    if (wrist[i] >= 0.0) {
      ++reachable;
      EXPECT_LT(wrist[i], kWristBound) << "t = " << time[i];
    }
    EXPECT_FALSE(per.at("hand_in_torso")[i].as_bool()) << "t = " << time[i];
    EXPECT_EQ(limits[i], 0.0) << "t = " << time[i];
    EXPECT_LT(step[i], kStepBound) << "t = " << time[i];
  }
  EXPECT_GT(static_cast<double>(in_window), 17.0 * rate) << "about 20 s of motions";
  EXPECT_GT(reachable, in_window * 9 / 10);
  std::vector<std::string> shots;
  for (const Json& j : report.at("snapshots").as_array()) shots.push_back(j.as_string());
  for (const char* s : {"vr-mirror-raised", "vr-mirror-crossed", "vr-mirror-bent"})
    EXPECT_NE(std::find(shots.begin(), shots.end(), s), shots.end()) << s;
}

TEST(VrApp, EmbodimentFollowsTheScriptedMotions) {
  // The avatar driven at 90 Hz through wave, reach up, cross arms, squat and turn; the issue's
  // bounds over the scripted motions.
  const std::string dir = work_dir("embodiment");
  const Json truth = simulate(dir, "log.jsonl", "--role self --frame-rate 90 --motions");
  const RunResult r = run_vr(dir,
                             "--replay log.jsonl --no-audio --draw-every 0 --out out "
                             "--embodiment-report report.json --frames-dir frames "
                             "--eye-size 64x72");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_embodiment_bounds(dir, truth, 90.0);
}

TEST(VrApp, EmbodimentInTheOperatorRole) {
  // Operator role: after the measurements the participant wears the headset and the controllers
  // and the avatar follows them; same bounds, at 30 Hz.
  const std::string dir = work_dir("embodiment_operator");
  const Json truth = simulate(dir, "log.jsonl", "--role operator --frame-rate 30 --motions");
  const RunResult r = run_vr(dir,
                             "--replay log.jsonl --no-audio --draw-every 0 --out out "
                             "--embodiment-report report.json --frames-dir frames "
                             "--eye-size 64x72");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(caliper::read_json_file(dir + "/out/session.json").at("complete").as_bool());
  expect_embodiment_bounds(dir, truth, 30.0);
}

TEST(VrApp, CommittedSampleLogsReplay) {
  for (const char* name : {"self-female", "operator-male"}) {
    const std::string dir = work_dir(std::string("sample-") + name);
    const std::string log = kSource + "/assets/logs/" + name + ".jsonl";
    const Json truth = caliper::read_json_file(log + ".truth.json");
    const RunResult r = run_vr(dir, "--replay '" + log + "'" + kReplayArgs + " --models-dir '" +
                                        kSource + "/assets/models'");
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
    const Json session = caliper::read_json_file(dir + "/out/session.json");
    for (const auto& kv : truth.at("truth").as_object())
      EXPECT_NEAR(session.at("measurements").at(kv.first).at("value").as_number(),
                  kv.second.as_number(), kAcceptance)
          << name << " " << kv.first;
    EXPECT_EQ(count_tone_bursts(dir + "/tones.wav"),
              session.at("accepted_samples_this_run").as_int())
        << name;
  }
}

TEST(VrApp, HipWidthMappingIsApplied) {
  // A learned real->virtual mapping of the hip width changes the regressor's input: the avatar
  // is the R5 prediction for the mapped hip width (from the model's shape curve, as every plain
  // regressor's avatar: caliper::linear_betas).
  const std::string dir = work_dir("mapping");
  const Json truth = simulate(dir, "log.jsonl", "");
  std::ofstream(dir + "/mapping.json")
      << R"({"format":"caliper-mapping","version":1,"maps":{"hip_width":{"a":1.0,"b":0.03,"count":20}}})";
  const RunResult r = run_vr(dir, "--replay log.jsonl --mapping mapping.json" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json session = caliper::read_json_file(dir + "/out/session.json");
  EXPECT_EQ(session.at("avatar").at("mapping").as_string(), "mapping.json");
  const smpl::BodyModel model = smpl::load_model(kModel);
  const caliper::RegressorSet set = caliper::train_regressors(model);
  const caliper::LinearRegressor& r5 = *set.find("R5");
  const std::optional<caliper::ShapeCurve> curve = caliper::shape_curve(model);
  ASSERT_TRUE(curve) << "the open model carries its shape curve";
  const auto predict = [&](const caliper::MeasurementMap& in) {
    return caliper::linear_betas(model, r5, in, &*curve, caliper::landmarks_for(model));
  };
  caliper::MeasurementMap in;
  for (const std::string& id : r5.inputs())
    in[id] = session.at("measurements").at(id).at("value").as_number();
  const Eigen::VectorXd unmapped = predict(in);
  in["hip_width"] += 0.03;
  const Eigen::VectorXd mapped = predict(in);
  const std::vector<double> betas = session.at("avatar").at("betas").as_numbers();
  // Same inputs, same arithmetic: equal to rounding.
  constexpr double kSameArithmetic = 1e-9;
  double to_mapped = 0.0, to_unmapped = 0.0;
  for (Eigen::Index i = 0; i < mapped.size(); ++i) {
    to_mapped = std::max(to_mapped, std::abs(betas[static_cast<size_t>(i)] - mapped[i]));
    to_unmapped = std::max(to_unmapped, std::abs(betas[static_cast<size_t>(i)] - unmapped[i]));
  }
  EXPECT_LT(to_mapped, kSameArithmetic);
  EXPECT_GT(to_unmapped, 100 * kSameArithmetic);
}

TEST(VrApp, PivotCalibrationStepWritesTheTipOffset) {
  // A log of the pivot step: the right tip rests on a fixed point while the grip rotates.
  const std::string dir = work_dir("pivot");
  caliper::PoseLog log;
  const Eigen::Vector3d t(0.003, -0.028, 0.094), q(0.1, 0.02, 0.4);
  for (int i = 0; i < 400; ++i) {
    caliper::PoseFrame f;
    f.time = i / 90.0;
    caliper::DevicePose& d = f.device(caliper::Device::Right);
    d.valid = true;
    const double a = 0.015 * i;
    d.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * std::sin(a), Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(0.6 * std::cos(1.3 * a), Eigen::Vector3d::UnitZ()));
    d.position = q - d.orientation * t;
    d.trigger = i >= 20 && i < 380 ? 1.0 : 0.0;
    log.frames.push_back(f);
  }
  caliper::write_pose_log(dir + "/pivot.jsonl", log);
  fs::copy_file(kSource + "/assets/protocol/controllers.json", dir + "/controllers.json");
  const RunResult r =
      run_vr(dir, "--replay pivot.jsonl --calibrate-tip right --controllers controllers.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("RMS residual"), std::string::npos) << r.out;
  const Json c = caliper::read_json_file(dir + "/controllers.json");
  const std::vector<double> got =
      c.at("profiles").at("/interaction_profiles/htc/vive_controller").at("right").as_numbers();
  // The log keeps 6 decimals (half a micrometre) of every pose.
  constexpr double kLogPrecision = 2e-5;
  ASSERT_EQ(got.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[static_cast<size_t>(k)], t[k], kLogPrecision);
  // The left offset is untouched.
  EXPECT_EQ(
      c.at("profiles").at("/interaction_profiles/htc/vive_controller").at("left").as_numbers(),
      (std::vector<double>{0.0, -0.03, 0.09}));
  // No hold in the log: a clear message.
  caliper::PoseLog idle = log;
  for (caliper::PoseFrame& f : idle.frames) f.device(caliper::Device::Right).trigger = 0.0;
  caliper::write_pose_log(dir + "/idle.jsonl", idle);
  const RunResult r2 =
      run_vr(dir, "--replay idle.jsonl --calibrate-tip right --controllers controllers.json");
  EXPECT_EQ(r2.exit_code, 1);
  EXPECT_NE(r2.err.find("no trigger hold"), std::string::npos) << r2.err;
}

TEST(VrApp, BadLogsGiveTheLineNumber) {
  const std::string dir = work_dir("bad_log");
  const std::string header =
      R"({"format":"caliper-pose-log","version":1,"units":"metres","role":"self"})"
      "\n";
  const std::string good =
      R"({"t":0.0,"head":{"valid":true,"p":[0,1.6,0],"q":[0,0,0,1]},"left":{"valid":false},"right":{"valid":false}})"
      "\n";
  std::ofstream(dir + "/nan.jsonl")
      << header << good
      << R"({"t":0.1,"head":{"valid":true,"p":[0,NaN,0],"q":[0,0,0,1]},"left":{"valid":false},"right":{"valid":false}})"
      << "\n";
  std::ofstream(dir + "/cut.jsonl") << header << good << R"({"t":0.1,"head":{"valid":tr)";
  const RunResult a = run_vr(dir, "--replay nan.jsonl --no-audio");
  EXPECT_EQ(a.exit_code, 1);
  EXPECT_NE(a.err.find("nan.jsonl:3: contains NaN"), std::string::npos) << a.err;
  const RunResult b = run_vr(dir, "--replay cut.jsonl --no-audio");
  EXPECT_EQ(b.exit_code, 1);
  EXPECT_NE(b.err.find("cut.jsonl:3: the file is truncated"), std::string::npos) << b.err;
  const RunResult c = run_vr(dir, "--replay missing.jsonl --no-audio");
  EXPECT_EQ(c.exit_code, 1);
  EXPECT_NE(c.err.find("missing.jsonl: cannot open"), std::string::npos) << c.err;
  const RunResult d = run_vr(dir, "--replay");
  EXPECT_EQ(d.exit_code, 2) << "usage error";
}

TEST(VrApp, OperatorWindowUnderXvfb) {
#ifndef CALIPER_XVFB_RUN
  GTEST_SKIP() << "xvfb-run is not installed (Debian package xvfb)";
#else
  // The operator's desktop window (GLFW + ImGui) mirrors the headset view; replayed under Xvfb.
  const std::string dir = work_dir("operator_window");
  const std::string log = kSource + "/assets/logs/operator-male.jsonl";
  const RunResult r =
      run_vr(dir,
             "--replay '" + log +
                 "' --operator-window --no-audio --draw-every 0 --eye-size 240x270 --frames-dir "
                 "frames --out out",
             // Leak checking off for the window run only (as for the editor's Xvfb test): the
             // GLX driver is unloaded at exit, so its process-lifetime allocations are reported
             // from an unnamed module that no suppression can match. Headless runs keep it on.
             "tones.wav",
             "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 '" CALIPER_XVFB_RUN
             "' -a -s '-screen 0 800x600x24'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const caliper::render::Image img =
      caliper::render::read_png(dir + "/frames/vr-operator-instruction-panel.png");
  EXPECT_EQ(img.width, 480);
  EXPECT_EQ(img.height, 270);
  // The ImGui window's title bar (dark blue) is in the top-left corner.
  const std::uint8_t* p = img.pixel(150, 19);
  EXPECT_LT(p[0], 100);
  EXPECT_GT(p[2], p[0]);
  EXPECT_TRUE(caliper::read_json_file(dir + "/out/session.json").at("complete").as_bool());
#endif
}

TEST(VrApp, GoldenImages) {
  // A fixed body model built by the test (not the open models of assets/models, which are
  // regenerated as their generator improves), so that the pictures change only when the app's
  // drawing does.
  const std::string dir = work_dir("golden");
  fs::create_directories(dir + "/models");
  caliper::test::RandomModelOptions mo;
  mo.rings = 40;
  mo.segments = 36;
  mo.pose_blend_shapes = false;
  smpl::BodyModel fixed = caliper::test::make_random_model(mo);
  // Smooth shape directions (the random ones are per-vertex noise, which a regressor turns into
  // spikes): stretches and widenings of body regions, 3 cm per unit beta.
  for (Eigen::Index v = 0; v < fixed.v_template.rows(); ++v) {
    const Eigen::Vector3d p = fixed.v_template.row(v).transpose();
    const double up = std::max(0.0, p.y()), down = std::min(0.0, p.y());
    const double arm = std::abs(p.x()) > 0.2 ? p.x() - std::copysign(0.2, p.x()) : 0.0;
    const Eigen::Vector3d dirs[10] = {p,
                                      {0, p.y(), 0},
                                      {p.x(), 0, p.z()},
                                      {p.x() * up, 0, 0},
                                      {p.x() * -down, 0, 0},
                                      {arm, 0, 0},
                                      {0, std::min(0.0, p.y() + 0.2), 0},
                                      {0, 0, p.z()},
                                      {0, up, 0},
                                      {p.x() * (p.y() < 0.0 && p.y() > -0.3 ? 1.0 : 0.0), 0, 0}};
    for (int b = 0; b < 10; ++b) fixed.shapedirs.block<3, 1>(3 * v, b) = 0.03 * dirs[b];
  }
  for (const char* sex : {"female", "male", "neutral"})
    smpl::save_model(fixed, dir + "/models/caliper-" + sex + ".npz");
  const std::string log = kSource + "/assets/logs/self-female.jsonl";
  const RunResult r = run_vr(
      dir, "--replay '" + log +
               "' --no-audio --draw-every 0 --eye-size 160x178 --frames-dir frames --out out "
               "--models-dir models");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const bool update = std::getenv("CALIPER_UPDATE_GOLDEN") != nullptr;
  for (const char* name : {"vr-floor-targets", "vr-instruction-panel", "vr-mirror"}) {
    const std::string got = dir + "/frames/" + name + ".png";
    const std::string golden = std::string(CALIPER_VR_GOLDEN_DIR) + "/" + name + ".png";
    ASSERT_TRUE(fs::exists(got)) << got;
    if (update) fs::copy_file(got, golden, fs::copy_options::overwrite_existing);
    const caliper::render::ImageDifference d = caliper::render::compare_images(
        caliper::render::read_png(got), caliper::render::read_png(golden));
    ASSERT_TRUE(d.same_size) << name;
    EXPECT_LE(d.mean_abs, kGoldenMaxMeanAbs) << name;
    EXPECT_LE(d.fraction_over, kGoldenMaxFractionOver) << name;
  }
}

TEST(VrApp, EmbodimentGoldenImages) {
  // The driven avatar in the mirror with raised, crossed and bent arms (the simulator's reach up,
  // cross arms and squat). Drawn with the open female model: the IK needs a humanoid skeleton,
  // which the test's fixed model (GoldenImages) does not have; so these pictures move when the
  // open models are regenerated (CALIPER_UPDATE_GOLDEN=1, then review them).
  const std::string dir = work_dir("embodiment_golden");
  simulate(dir, "log.jsonl", "--role self --frame-rate 30 --motions");
  const RunResult r =
      run_vr(dir,
             "--replay log.jsonl --no-audio --draw-every 0 --eye-size 160x178 --frames-dir frames "
             "--out out --models-dir '" +
                 kSource + "/assets/models'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const bool update = std::getenv("CALIPER_UPDATE_GOLDEN") != nullptr;
  for (const char* name : {"vr-mirror-raised", "vr-mirror-crossed", "vr-mirror-bent"}) {
    const std::string got = dir + "/frames/" + name + ".png";
    const std::string golden = std::string(CALIPER_VR_GOLDEN_DIR) + "/" + name + ".png";
    ASSERT_TRUE(fs::exists(got)) << got;
    if (update) fs::copy_file(got, golden, fs::copy_options::overwrite_existing);
    const caliper::render::ImageDifference d = caliper::render::compare_images(
        caliper::render::read_png(got), caliper::render::read_png(golden));
    ASSERT_TRUE(d.same_size) << name;
    EXPECT_LE(d.mean_abs, kGoldenMaxMeanAbs) << name;
    EXPECT_LE(d.fraction_over, kGoldenMaxFractionOver) << name;
  }
}

// Issue 10: a new session never wipes an earlier journal; --resume refuses a journal of another
// protocol; --force starts over.
TEST(VrApp, ExistingJournalIsNeverWiped) {
  const std::string dir = work_dir("existing_journal");
  simulate(dir, "log.jsonl", "--role self");
  ASSERT_EQ(run_vr(dir, "--replay log.jsonl --no-audio --out out --draw-every 0 --max-frames 900")
                .exit_code,
            3);
  const std::string journal = read_file(dir + "/out/journal.jsonl");
  ASSERT_FALSE(journal.empty());
  const RunResult again = run_vr(dir, "--replay log.jsonl --no-audio --out out --draw-every 0");
  EXPECT_EQ(again.exit_code, 1) << again.err;
  EXPECT_NE(again.err.find("out/journal.jsonl already holds a session journal"), std::string::npos)
      << again.err;
  EXPECT_NE(again.err.find("caliper-vr --replay log.jsonl --resume out/journal.jsonl --out out"),
            std::string::npos)
      << again.err;
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
  EXPECT_EQ(read_file(dir + "/out/journal.jsonl"), journal) << "the journal must be untouched";

  // A journal of another protocol is refused by --resume, naming both protocols.
  std::string other = journal;
  const size_t p = other.find("\"protocol\":\"");
  ASSERT_NE(p, std::string::npos) << journal.substr(0, 200);
  other.insert(p + 12, "another ");
  std::ofstream(dir + "/other.jsonl") << other;
  const RunResult resumed =
      run_vr(dir, "--replay log.jsonl --no-audio --draw-every 0 --resume other.jsonl");
  EXPECT_EQ(resumed.exit_code, 1) << resumed.err;
  EXPECT_NE(resumed.err.find("the journal was written with the protocol \"another "),
            std::string::npos)
      << resumed.err;

  const RunResult forced =
      run_vr(dir, "--replay log.jsonl --no-audio --out out --draw-every 0 --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

// Issue 10: older builds journalled a height take below the calibrated floor and then stopped
// with exit 1, on every --resume again. That journal now resumes at the height step (the bad take
// is skipped) and the rest of the session completes with the true measurements.
TEST(VrApp, TheOldFailingJournalResumes) {
  const std::string dir = work_dir("old_failing_journal");
  const Json truth = simulate(dir, "log.jsonl", "--role self --noise 0.0");
  ASSERT_EQ(run_vr(dir, "--replay log.jsonl --no-audio --out full --draw-every 0").exit_code, 0);
  const caliper::JournalContents full = caliper::read_journal(dir + "/full/journal.jsonl");
  // The old journal: the floor calibration, then the first height take, 5 cm below the floor.
  std::vector<caliper::JournalRecord> old;
  double floor_done = -1.0, bad_take = -1.0;
  for (const caliper::JournalRecord& r : full.records) {
    if (r.type == "floor_sample") floor_done = r.time;
    if (r.type == "sample" && r.step == "height") {
      caliper::JournalRecord bad = r;
      bad.points.at(0).y() = -0.05;
      bad.value = -0.05;
      old.push_back(bad);
      bad_take = r.time;
      break;
    }
    old.push_back(r);
  }
  ASSERT_GT(floor_done, 0.0);
  ASSERT_GT(bad_take, floor_done);
  fs::create_directories(dir + "/out");
  {
    caliper::JournalWriter w =
        caliper::JournalWriter::create(dir + "/out/journal.jsonl", full.header);
    for (const caliper::JournalRecord& r : old) w.append(r);
  }
  // The pose source after the crash: from the first quiet frame after the floor calibration,
  // so that both height takes are in it.
  caliper::PoseLog log = caliper::read_pose_log(dir + "/log.jsonl");
  size_t from = 0;
  for (const double q : truth.at("quiet_frames").as_numbers()) {
    from = static_cast<size_t>(q);
    if (log.frames.at(from).time > floor_done) break;
  }
  ASSERT_LT(log.frames.at(from).time, bad_take) << "no quiet frame before the height take";
  log.frames.erase(log.frames.begin(), log.frames.begin() + static_cast<long>(from));
  caliper::write_pose_log(dir + "/rest.jsonl", log);

  const RunResult r = run_vr(dir, "--replay rest.jsonl --resume out/journal.jsonl" + kReplayArgs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_session_matches(dir, truth);
}

// Issue 10: a second run with the same --record file does not replace the first recording.
TEST(VrApp, ExistingRecordingIsNeverReplaced) {
  const std::string dir = work_dir("existing_recording");
  simulate(dir, "log.jsonl", "--role self");
  const std::string args = "--replay log.jsonl --no-audio --draw-every 0 --max-frames 200 ";
  ASSERT_EQ(run_vr(dir, args + "--out a --record rec.jsonl").exit_code, 3);
  const std::string recording = read_file(dir + "/rec.jsonl");
  ASSERT_FALSE(recording.empty());
  const RunResult again = run_vr(dir, args + "--out b --record rec.jsonl");
  EXPECT_EQ(again.exit_code, 1) << again.err;
  EXPECT_NE(again.err.find("rec.jsonl already exists"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
  EXPECT_EQ(read_file(dir + "/rec.jsonl"), recording) << "the recording must be untouched";
  EXPECT_FALSE(fs::exists(dir + "/b")) << "refused before any work";
  EXPECT_EQ(run_vr(dir, args + "--out c --record rec.jsonl --force").exit_code, 3);
}

TEST(VrApp, OddOptionsAreUsageErrors) {
  const std::string dir = work_dir("odd_options");
  simulate(dir, "log.jsonl", "--role self");
  for (const char* eye : {"1500000000x2", "2x1500000000", "0x10", "10x", "-5x10", "10x10junk"}) {
    const RunResult r = run_vr(dir, std::string("--replay log.jsonl --no-audio --eye-size ") + eye);
    EXPECT_EQ(r.exit_code, 2) << eye << ": " << r.err;
    EXPECT_NE(r.err.find("--eye-size"), std::string::npos) << r.err;
  }
  const RunResult frames = run_vr(dir, "--replay log.jsonl --no-audio --max-frames 1e300");
  EXPECT_EQ(frames.exit_code, 2) << frames.err;
  EXPECT_NE(frames.err.find("--max-frames needs a whole number"), std::string::npos) << frames.err;
  for (const char* weight : {"1e308", "-5", "0.5", "nan"}) {
    const RunResult r =
        run_vr(dir, std::string("--replay log.jsonl --no-audio --weight ") + weight);
    EXPECT_EQ(r.exit_code, 2) << weight << ": " << r.err;
    EXPECT_NE(r.err.find("--weight"), std::string::npos) << r.err;
  }
  const RunResult sim = run_vr(dir, "--simulate s.jsonl --weight 1e308");
  EXPECT_EQ(sim.exit_code, 2) << sim.err;
  EXPECT_FALSE(fs::exists(dir + "/s.jsonl"));
  EXPECT_FALSE(fs::exists(dir + "/caliper-journal.jsonl")) << "refused before any work";
}

}  // namespace
