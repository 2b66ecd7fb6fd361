// Measuring session state machine, driven by simulated pose logs whose true answer is known.
#include <gtest/gtest.h>

#include <cmath>

#include "caliper/protocol.hpp"
#include "caliper/session.hpp"
#include "caliper/simulator.hpp"
#include "session_fixtures.hpp"

namespace caliper {
namespace {

// Noise-free logs are written with 6 decimals (half a micrometre per coordinate); a distance
// of two such points is off by at most ~2 micrometres.
constexpr double kSessionNoiseFreeTol = 5e-6;  // m
// The acceptance bound for replayed sessions.
constexpr double kAcceptance = 0.005;  // m

struct SessionRun {
  SimulatedSession sim;
  test::ReplayOutcome outcome;
  SessionResult result;
  bool done = false;
};

SessionRun run(const SimulatorOptions& o, const Protocol& protocol = default_protocol(),
               SessionOptions so = {}) {
  SessionRun r;
  r.sim = simulate_session(protocol, test::hand_made_person(), o);
  so.role = o.role;
  MeasuringSession session(protocol, so);
  r.outcome = test::run_frames(session, r.sim.log, o.tip_offsets);
  r.result = session.result();
  r.done = session.done();
  return r;
}

void expect_truth(const SessionRun& r, double tolerance) {
  ASSERT_TRUE(r.done);
  for (const auto& kv : r.sim.truth) {
    ASSERT_TRUE(r.result.measurements.count(kv.first)) << kv.first;
    EXPECT_NEAR(r.result.measurements.at(kv.first), kv.second, tolerance) << kv.first;
  }
  EXPECT_EQ(r.result.sex, "female");
}

TEST(Session, SelfRoleNoiseFreeGivesTheTruth) {
  SimulatorOptions o;
  const SessionRun r = run(o);
  expect_truth(r, kSessionNoiseFreeTol);
  EXPECT_EQ(r.outcome.count(EventType::SampleAccepted), r.sim.accepted_samples);
  EXPECT_EQ(r.sim.accepted_samples, 5 + 5 * 2);
  EXPECT_EQ(r.outcome.count(EventType::SampleRejected), 0);
  EXPECT_EQ(r.outcome.count(EventType::SessionComplete), 1);
  EXPECT_NEAR(r.result.floor_offset, o.runtime_floor_offset, kSessionNoiseFreeTol);
  for (const auto& kv : r.result.takes) EXPECT_EQ(kv.second.size(), 2u) << kv.first;
}

TEST(Session, TipOffsetIsApplied) {
  // The same log read with a wrong tip offset: the controllers are held at a different angle
  // for every sample, so the wrong tip points scatter and the takes are off the truth (an app
  // that ignored the offset would get the truth exactly).
  SimulatorOptions o;
  SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  MeasuringSession session(default_protocol());
  TipOffsets wrong;
  wrong.right += Eigen::Vector3d(0.0, 0.0, 0.05);
  wrong.left += Eigen::Vector3d(0.0, 0.0, 0.05);
  test::run_frames(session, sim.log, wrong);
  double worst = 0.0;
  const Protocol p = default_protocol();
  for (size_t i = 0; i < p.steps.size(); ++i)
    for (double take : session.steps()[i].takes)
      worst = std::max(worst, std::abs(take - sim.truth.at(p.steps[i].measurement)));
  EXPECT_GT(worst, 0.002);
}

TEST(Session, NoisyLogIsWithinFiveMillimetres) {
  SimulatorOptions o;
  o.tip_noise = 0.0008;
  o.seed = 7;
  const SessionRun r = run(o);
  expect_truth(r, kAcceptance);
}

TEST(Session, TrackingDropoutDuringAHoldIsRejectedAndRetaken) {
  SimulatorOptions o;
  o.dropout_step = "arm_span_fingertips";
  const SessionRun r = run(o);
  expect_truth(r, kSessionNoiseFreeTol);
  ASSERT_EQ(r.outcome.count(EventType::SampleRejected), 1);
  for (const SessionEvent& e : r.outcome.events)  // NOLINT
    if (e.type == EventType::SampleRejected) {
      EXPECT_EQ(e.step, "arm_span_fingertips");
      EXPECT_NE(e.message.find("Tracking of the right controller was lost"), std::string::npos)
          << e.message;
    }
  EXPECT_EQ(r.outcome.count(EventType::SampleAccepted), r.sim.accepted_samples);
}

TEST(Session, EarlyReleaseIsRejected) {
  SimulatorOptions o;
  o.early_release_step = "height";
  const SessionRun r = run(o);
  expect_truth(r, kSessionNoiseFreeTol);
  ASSERT_EQ(r.outcome.count(EventType::SampleRejected), 1);
  for (const SessionEvent& e : r.outcome.events) {
    if (e.type == EventType::SampleRejected) {
      EXPECT_NE(e.message.find("released"), std::string::npos);
    }
  }
}

TEST(Session, IsakAsksForAThirdTakeAndTakesTheMedian) {
  SimulatorOptions o;
  o.third_take_step = "hip_width";
  const SessionRun r = run(o);
  expect_truth(r, kSessionNoiseFreeTol);
  EXPECT_EQ(r.outcome.count(EventType::ThirdTakeRequested), 1);
  ASSERT_EQ(r.result.takes.at("hip_width").size(), 3u);
  const std::vector<double>& t = r.result.takes.at("hip_width");
  EXPECT_TRUE(isak_needs_third(t[0], t[1]));
  EXPECT_NEAR(t[1] / t[0], 1.03, 1e-4);
  EXPECT_EQ(r.outcome.count(EventType::SampleAccepted), 5 + 5 * 2 + 1);
}

TEST(Session, JitterAboveTheThresholdIsRejected) {
  SimulatorOptions o;
  o.tip_noise = 0.004;  // RMS ~7 mm, above the protocol's 4 mm
  const SessionRun r = run(o);
  EXPECT_FALSE(r.done);
  EXPECT_EQ(r.outcome.count(EventType::SampleAccepted), 0);
  ASSERT_GT(r.outcome.count(EventType::SampleRejected), 0);
  for (const SessionEvent& e : r.outcome.events) {
    if (e.type == EventType::SampleRejected) {
      EXPECT_NE(e.message.find("hold still"), std::string::npos);
    }
  }
}

TEST(Session, OperatorRoleWaitsForStartThenRedoes) {
  SimulatorOptions o;
  o.role = "operator";
  o.redo_step = "inseam_height";
  const SessionRun r = run(o);
  expect_truth(r, kSessionNoiseFreeTol);
  EXPECT_EQ(r.outcome.count(EventType::Started), 1);
  EXPECT_EQ(r.outcome.count(EventType::StepRedo), 1);
  EXPECT_EQ(r.outcome.count(EventType::SampleAccepted), 5 + 5 * 2 + 1);
  EXPECT_DOUBLE_EQ(r.result.measurements.at("weight"), 64.5);

  // Without the start command nothing happens in the operator role.
  SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  for (PoseFrame& f : sim.log.frames) f.commands.clear();
  SessionOptions so;
  so.role = "operator";
  MeasuringSession session(default_protocol(), so);
  const test::ReplayOutcome out = test::run_frames(session, sim.log, o.tip_offsets);
  EXPECT_EQ(session.view().phase, Phase::WaitingForStart);
  EXPECT_TRUE(out.events.empty());
}

TEST(Session, TypedValuesGivenInAdvance) {
  SimulatorOptions o;
  o.typed_in_log = false;
  SessionOptions so;
  so.weight = 80.0;
  so.sex = "male";
  SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  MeasuringSession session(default_protocol(), so);
  test::run_frames(session, sim.log, o.tip_offsets);
  ASSERT_TRUE(session.done());
  EXPECT_EQ(session.result().measurements.at("weight"), 80.0);
  EXPECT_EQ(session.result().sex, "male");
}

TEST(Session, MissingTypedValueKeepsTheSessionWaiting) {
  SimulatorOptions o;
  o.typed_in_log = false;
  SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  MeasuringSession session(default_protocol());
  test::run_frames(session, sim.log, o.tip_offsets);
  EXPECT_FALSE(session.done());
  ASSERT_NE(session.current_step(), nullptr);
  EXPECT_EQ(session.current_step()->id, "weight");
  // An invalid typed value is refused with a message; a valid one completes the step.
  session.command({"weight", Json(-3.0)}, 100.0);
  EXPECT_EQ(session.current_step()->id, "weight");
  session.command({"weight", Json(70.0)}, 100.0);
  session.command({"sex", Json("other")}, 100.0);
  EXPECT_EQ(session.current_step()->id, "sex");
  session.command({"sex", Json("male")}, 100.0);
  EXPECT_TRUE(session.done());
}

TEST(Session, SkipAStep) {
  Protocol p = default_protocol();
  SimulatorOptions o;
  SimulatedSession sim = simulate_session(p, test::hand_made_person(), o);
  MeasuringSession session(p);
  // SessionRun until the height step starts, skip it: the log's height holds then count for arm
  // span.
  size_t i = 0;
  for (; i < sim.log.frames.size() && !session.current_step(); ++i)
    session.update(session_frame(sim.log.frames[i], o.tip_offsets));
  ASSERT_NE(session.current_step(), nullptr);
  EXPECT_EQ(session.current_step()->id, "height");
  const auto events = session.command({"skip", Json()}, 50.0);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events[0].type, EventType::StepSkipped);
  ASSERT_TRUE(events[0].record);
  EXPECT_EQ(session.current_step()->id, "arm_span_fingertips");
  EXPECT_EQ(session.result().skipped, std::vector<std::string>{"height"});
}

TEST(Session, TiltedFloorAsksForARetry) {
  SimulatorOptions o;
  SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  // Tilt the whole tracking space by 6 degrees: the floor plane is off by more than 3 degrees.
  const Eigen::Quaterniond tilt(
      Eigen::AngleAxisd(6.0 * 3.14159265358979 / 180.0, Eigen::Vector3d::UnitX()));
  for (PoseFrame& f : sim.log.frames)
    for (DevicePose& d : f.devices) {
      d.position = tilt * d.position;
      d.orientation = tilt * d.orientation;
    }
  MeasuringSession session(default_protocol());
  const test::ReplayOutcome out = test::run_frames(session, sim.log, o.tip_offsets);
  ASSERT_GE(out.count(EventType::FloorRetry), 1);
  for (const SessionEvent& e : out.events) {
    if (e.type == EventType::FloorRetry) {
      EXPECT_NE(e.message.find("tilt"), std::string::npos) << e.message;
    }
  }
  EXPECT_EQ(out.count(EventType::FloorCalibrated), 0);
}

TEST(Session, TipOutsideTheFloorRingIsRejected) {
  Protocol p = default_protocol();
  SimulatorOptions o;
  SimulatedSession sim = simulate_session(p, test::hand_made_person(), o);
  Protocol moved = p;
  moved.floor.targets[0] =
      Eigen::Vector2d(1.0, 1.0);  // the session expects the first ring elsewhere
  MeasuringSession session(moved);
  const test::ReplayOutcome out = test::run_frames(session, sim.log, o.tip_offsets);
  ASSERT_GE(out.count(EventType::SampleRejected), 1);
  EXPECT_NE(out.events[1].message.find("away from the glowing ring"), std::string::npos)
      << out.events[1].message;
}

TEST(Session, HoldProgressFillsTheRing) {
  SimulatorOptions o;
  SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  MeasuringSession session(default_protocol());
  double max_progress = 0.0;
  bool saw_half = false;
  for (const PoseFrame& f : sim.log.frames) {
    session.update(session_frame(f, o.tip_offsets));
    max_progress = std::max(max_progress, session.view().hold_progress);
    saw_half =
        saw_half || (session.view().holding && std::abs(session.view().hold_progress - 0.5) < 0.02);
    if (session.view().floor_target >= 1) break;
  }
  EXPECT_TRUE(saw_half);
  EXPECT_LE(max_progress, 1.0);
}

}  // namespace
}  // namespace caliper
