// Pose log format: round trip, and every kind of bad input gives its line number.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "caliper/pose_log.hpp"
#include "caliper/simulator.hpp"
#include "session_fixtures.hpp"

namespace caliper {
namespace {

// The writer prints 6 decimals: positions round-trip to half a micrometre.
constexpr double kWrittenPrecision = 0.5e-6 + 1e-12;

const char* kHeader =
    R"({"format":"caliper-pose-log","version":1,"units":"metres","reference_space":"stage","role":"self"})";

std::string frame_line(double t, double x) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                R"({"t":%.4f,"head":{"valid":true,"p":[0,1.6,0],"q":[0,0,0,1]},)"
                R"("left":{"valid":true,"p":[%.4f,1,0],"q":[0,0,0,1],"trigger":0},)"
                R"("right":{"valid":false,"trigger":0.5,"buttons":["menu"]}})",
                t, x);
  return buf;
}

std::string small_log(int frames) {
  std::string s = std::string(kHeader) + "\n";
  for (int i = 0; i < frames; ++i) s += frame_line(i / 90.0, 0.1 + 0.001 * i) + "\n";
  return s;
}

/// Expects parse_pose_log(text) to throw with `line` and a message containing `words`.
void expect_error(const std::string& text, int line, const std::string& words) {
  try {
    parse_pose_log(text, "test.jsonl");
    FAIL() << "no error for a log that should fail at line " << line << " (" << words << ")";
  } catch (const PoseLogError& e) {
    EXPECT_EQ(e.line, line) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("test.jsonl:" + std::to_string(line) + ":"),
              std::string::npos)
        << "the message names the file and the line: " << e.what();
  }
}

TEST(PoseLog, ParsesAHandWrittenLog) {
  const PoseLog log = parse_pose_log(small_log(3), "x");
  ASSERT_EQ(log.frames.size(), 3u);
  EXPECT_EQ(log.header.role, "self");
  EXPECT_EQ(log.frames[1].line, 3);
  EXPECT_TRUE(log.frames[0].device(Device::Left).valid);
  EXPECT_FALSE(log.frames[0].device(Device::Right).valid);
  EXPECT_TRUE(log.frames[0].device(Device::Right).menu);
  EXPECT_DOUBLE_EQ(log.frames[0].device(Device::Right).trigger, 0.5);
  EXPECT_DOUBLE_EQ(log.frames[2].device(Device::Left).position.x(), 0.102);
}

TEST(PoseLog, RoundTripsASimulatedSession) {
  SimulatorOptions o;
  o.tip_noise = 0.001;
  o.role = "operator";
  o.frame_rate = 45.0;
  const SimulatedSession sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/roundtrip.jsonl";
  write_pose_log(path, sim.log);
  const PoseLog back = read_pose_log(path);
  EXPECT_EQ(back.header.role, "operator");
  EXPECT_EQ(back.header.frame_rate, 45.0);
  ASSERT_EQ(back.frames.size(), sim.log.frames.size());
  int commands = 0;
  for (size_t i = 0; i < back.frames.size(); ++i) {
    const PoseFrame& a = sim.log.frames[i];
    const PoseFrame& b = back.frames[i];
    EXPECT_NEAR(a.time, b.time, kWrittenPrecision);
    for (int d = 0; d < kNumDevices; ++d) {
      ASSERT_EQ(a.devices[d].valid, b.devices[d].valid) << "frame " << i;
      if (!a.devices[d].valid) continue;
      EXPECT_LT((a.devices[d].position - b.devices[d].position).cwiseAbs().maxCoeff(),
                kWrittenPrecision);
      // q and -q are the same rotation.
      EXPECT_NEAR(std::abs(a.devices[d].orientation.dot(b.devices[d].orientation)), 1.0, 1e-5);
      EXPECT_EQ(a.devices[d].trigger, b.devices[d].trigger);
    }
    ASSERT_EQ(a.commands.size(), b.commands.size());
    for (size_t c = 0; c < a.commands.size(); ++c) {
      EXPECT_EQ(a.commands[c].command, b.commands[c].command);
      EXPECT_EQ(a.commands[c].value.dump(), b.commands[c].value.dump());
      ++commands;
    }
  }
  EXPECT_EQ(commands, 3) << "operator: start, weight, sex";
}

TEST(PoseLog, EmptyFileAndMissingHeader) {
  expect_error("", 1, "empty");
  expect_error(frame_line(0.0, 0.0) + "\n", 1, "not a pose log header");
  expect_error("\n\n", 1, "no header");
}

TEST(PoseLog, UnknownVersion) {
  expect_error(R"({"format":"caliper-pose-log","version":7})"
               "\n",
               1, "version 7");
}

TEST(PoseLog, MalformedLineGivesItsNumber) {
  std::string s = small_log(5);
  const std::string bad = frame_line(5 / 90.0, 0.105);
  s += bad.substr(0, 40) + "}\n" + frame_line(6 / 90.0, 0.106) + "\n";
  expect_error(s, 7, "malformed JSON");
}

TEST(PoseLog, TruncatedLastLine) {
  const std::string s = small_log(4);
  const std::string cut = s.substr(0, s.size() - 25);  // no newline at the end
  expect_error(cut, 5, "truncated");
}

TEST(PoseLog, NaNIsNamed) {
  std::string s = small_log(2);
  std::string l = frame_line(2 / 90.0, 0.2);
  l.replace(l.find("0.2000"), 6, "NaN");
  s += l + "\n";
  expect_error(s, 4, "NaN");
  std::string s2 = small_log(1);
  std::string l2 = frame_line(1 / 90.0, 0.2);
  l2.replace(l2.find("1.6"), 3, "-inf");
  expect_error(s2 + l2 + "\n", 3, "NaN or infinity");
  // A number too large for a double is caught by the JSON reader.
  std::string l3 = frame_line(1 / 90.0, 0.2);
  l3.replace(l3.find("1.6"), 3, "1e999");
  expect_error(s2 + l3 + "\n", 3, "out of range");
}

TEST(PoseLog, ImpossibleJump) {
  std::string s = small_log(3);
  s += frame_line(3 / 90.0, 2.5) + "\n";  // 2.4 m in 11 ms
  expect_error(s, 5, "impossible jump of the left device");
}

TEST(PoseLog, JumpAcrossATrackingGapIsNotChecked) {
  std::string s = small_log(3);
  std::string gap = frame_line(3 / 90.0, 0.0);
  gap.replace(gap.find(R"("left":{"valid":true,"p":[0.0000,1,0],"q":[0,0,0,1])"),
              std::string(R"("left":{"valid":true,"p":[0.0000,1,0],"q":[0,0,0,1])").size(),
              R"("left":{"valid":false)");
  s += gap + "\n" + frame_line(2.0, 1.5) + "\n";
  EXPECT_EQ(parse_pose_log(s, "x").frames.size(), 5u);
}

TEST(PoseLog, TimeMustIncrease) {
  std::string s = small_log(3);
  s += frame_line(1 / 90.0, 0.103) + "\n";
  expect_error(s, 5, "does not increase");
}

TEST(PoseLog, NonUnitQuaternion) {
  std::string s = small_log(1);
  std::string l = frame_line(1 / 90.0, 0.101);
  l.replace(l.find("[0,0,0,1]"), 9, "[0,0,0,2]");
  expect_error(s + l + "\n", 3, "not a unit quaternion");
}

TEST(PoseLog, MissingAndMistypedKeys) {
  std::string l = frame_line(0.5, 0.1);
  l.replace(l.find(R"("t":)"), 4, R"("x":)");
  expect_error(std::string(kHeader) + "\n" + l + "\n", 2, "no time");
  std::string l2 = frame_line(0.5, 0.1);
  l2.replace(l2.find(R"("trigger":0})"), 12, R"("trigger":"on"})");
  expect_error(std::string(kHeader) + "\n" + l2 + "\n", 2, "must be a number");
  std::string l3 = frame_line(0.5, 0.1);
  l3.replace(l3.find(R"("valid":true,"p":[0,1.6,0])"), 26, R"("valid":true)");
  expect_error(std::string(kHeader) + "\n" + l3 + "\n", 2, "has no \"p\"");
}

TEST(PoseLog, UnknownCommand) {
  std::string l = frame_line(0.5, 0.1);
  l.pop_back();
  l += R"(,"commands":[{"command":"explode"}]})";
  expect_error(std::string(kHeader) + "\n" + l + "\n", 2, "unknown command");
}

TEST(PoseLog, MissingFile) {
  try {
    read_pose_log("/nonexistent/log.jsonl");
    FAIL();
  } catch (const PoseLogError& e) {
    EXPECT_EQ(e.line, 0);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/log.jsonl"), std::string::npos);
  }
}

TEST(PoseLog, WriterRefusesNaN) {
  PoseFrame f;
  f.device(Device::Head).valid = true;
  f.device(Device::Head).position.x() = std::nan("");
  EXPECT_THROW(pose_log_frame_line(f), PoseLogError);
}

}  // namespace
}  // namespace caliper
