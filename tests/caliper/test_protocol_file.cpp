// Protocol file: the built-in protocol is the committed asset (embedded byte for byte at build
// time); bad files name the problem.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "caliper/protocol_file.hpp"
#include "caliper/simulator.hpp"
#include "session_fixtures.hpp"
#include "smpl/text.hpp"

namespace caliper {
namespace {

const std::string kAsset =
    std::string(CALIPER_SOURCE_DIR) + "/assets/protocol/virtual-caliper.json";

TEST(ProtocolFile, TheBuiltInProtocolIsTheAssetByteForByte) {
  const std::optional<std::string> asset = smpl::read_file(kAsset);
  ASSERT_TRUE(asset) << kAsset;
  EXPECT_EQ(std::string(default_protocol_json()), *asset)
      << "the embedded copy is stale: rebuild libcaliper";
  EXPECT_EQ(default_protocol().path, "");
}

TEST(ProtocolFile, AssetEqualsTheBuiltInProtocol) {
  const Protocol a = read_protocol(kAsset);
  const Protocol b = default_protocol();
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.hold_seconds, b.hold_seconds);
  EXPECT_EQ(a.max_jitter_m, b.max_jitter_m);
  EXPECT_EQ(a.isak_threshold, b.isak_threshold);
  EXPECT_EQ(a.floor.instruction, b.floor.instruction);
  ASSERT_EQ(a.floor.targets.size(), 5u);
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(a.floor.targets[i], b.floor.targets[i]);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t i = 0; i < a.steps.size(); ++i) {
    EXPECT_EQ(a.steps[i].id, b.steps[i].id);
    EXPECT_EQ(a.steps[i].measurement, b.steps[i].measurement);
    EXPECT_EQ(a.steps[i].kind, b.steps[i].kind);
    EXPECT_EQ(a.steps[i].title, b.steps[i].title);
    EXPECT_EQ(a.steps[i].instruction, b.steps[i].instruction) << a.steps[i].id;
    EXPECT_EQ(a.steps[i].tips, b.steps[i].tips);
    EXPECT_EQ(a.steps[i].landmarks, b.steps[i].landmarks);
    EXPECT_EQ(a.steps[i].demo_pose, b.steps[i].demo_pose);
    EXPECT_EQ(a.steps[i].video, b.steps[i].video);
    EXPECT_EQ(a.steps[i].choices, b.steps[i].choices);
  }
}

TEST(ProtocolFile, HasThePapersMeasurements) {
  const Protocol p = default_protocol();
  for (const char* id : {"height", "arm_span_fingertips", "inseam_height", "hip_width",
                         "arm_length", "weight", "sex"})
    EXPECT_GE(p.find_step(id), 0) << id;
  EXPECT_EQ(p.hold_seconds, 1.0);
  EXPECT_EQ(p.isak_threshold, 0.015);
}

void expect_protocol_error(const std::string& text, const std::string& words) {
  try {
    parse_protocol(text, "p.json");
    FAIL() << "no error, expected: " << words;
  } catch (const ProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("p.json"), std::string::npos) << e.what();
  }
}

std::string with_step(const std::string& step) {
  return R"({"format":"caliper-protocol","version":1,"floor":{"targets":[[0,0],[1,0],[0,1]]},"steps":[)" +
         step + "]}";
}

TEST(ProtocolFile, BadFilesNameTheProblem) {
  expect_protocol_error("{", "not valid JSON");
  expect_protocol_error(R"({"format":"x"})", "not a protocol file");
  expect_protocol_error(R"({"format":"caliper-protocol","version":2})", "version");
  expect_protocol_error(
      R"({"format":"caliper-protocol","version":1,"floor":{"targets":[[0,0]]},"steps":[]})",
      "at least 3");
  expect_protocol_error(with_step(R"({"id":"a","kind":"weird"})"), "unknown kind \"weird\"");
  expect_protocol_error(
      with_step(R"({"id":"a","kind":"distance","tips":["left"],"landmarks":["crotch"]})"),
      "needs 2 tips and 2 landmarks");
  expect_protocol_error(
      with_step(R"({"id":"a","kind":"height","tips":["left"],"landmarks":["elbow_tip"]})"),
      "unknown landmark \"elbow_tip\"");
  expect_protocol_error(
      with_step(R"({"id":"a","kind":"height","tips":["middle"],"landmarks":["crotch"]})"),
      "\"left\" or \"right\"");
  expect_protocol_error(
      with_step(R"({"id":"a","kind":"height","tips":["left"],"landmarks":["crotch"]},)"
                R"({"id":"a","kind":"height","tips":["left"],"landmarks":["crotch"]})"),
      "duplicate step id");
  expect_protocol_error(with_step(R"({"id":"s","kind":"typed_choice"})"), "needs \"choices\"");
  EXPECT_THROW(read_protocol("/nonexistent/p.json"), ProtocolError);
}

TEST(ProtocolFile, ExtraStepsWork) {
  // An optional extra step (shoulder width) from a protocol file is measured like the others.
  const Protocol p = parse_protocol(
      with_step(R"({"id":"shoulder_width","kind":"distance","tips":["left","right"],)"
                R"("landmarks":["left_shoulder","left_hip"],"optional":true})"),
      "p.json");
  ASSERT_EQ(p.steps.size(), 1u);
  EXPECT_TRUE(p.steps[0].optional);
  SimulatorOptions o;
  const SimulatedSession sim = simulate_session(p, test::hand_made_person(), o);
  MeasuringSession s(p);
  test::run_frames(s, sim.log, o.tip_offsets);
  ASSERT_TRUE(s.done());
  EXPECT_NEAR(s.result().measurements.at("shoulder_width"), sim.truth.at("shoulder_width"), 5e-6);
}

}  // namespace
}  // namespace caliper
