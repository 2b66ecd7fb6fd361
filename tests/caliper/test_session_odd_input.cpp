// Issue 10 for the measuring session: a bad take is a rejected sample (never the end of the
// session), every journal resumes, a journal of another version or protocol is refused, typed
// values and pose-log versions outside any sense are refused without undefined behaviour.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "caliper/journal.hpp"
#include "caliper/pose_log.hpp"
#include "caliper/protocol.hpp"
#include "caliper/session.hpp"
#include "caliper/simulator.hpp"
#include "session_fixtures.hpp"

namespace caliper {
namespace {

using test::data_path;
using test::kNoiseFreeTolerance;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(SessionOddInput, TipBelowTheFloorIsARetakeNotAnAbort) {
  SimulatedPerson person = test::hand_made_person();
  person.landmarks["head_top"].y() = -0.05;  // the floor was calibrated 5 cm too high
  SimulatorOptions o;
  const SimulatedSession sim = simulate_session(default_protocol(), person, o);
  MeasuringSession session(default_protocol());
  // Up to the second height take (the simulated person does not take it again: the holds that
  // follow are meant for the next steps).
  int below = 0;
  for (size_t i = 0; i < sim.log.frames.size() && below < 2; ++i) {
    std::vector<SessionEvent> events;
    ASSERT_NO_THROW(events = session.update(session_frame(sim.log.frames[i], o.tip_offsets)));
    for (const SessionEvent& e : events) {
      EXPECT_FALSE(e.record && e.record->step == "height") << "nothing journalled";
      EXPECT_FALSE(e.type == EventType::SampleAccepted && e.step == "height") << e.message;
      if (e.type == EventType::SampleRejected && e.step == "height") {
        EXPECT_TRUE(contains(e.message, "50.0 mm below the calibrated floor")) << e.message;
        ++below;
      }
    }
  }
  EXPECT_EQ(below, 2) << "both height takes are rejected, to be taken again";
  ASSERT_NE(session.current_step(), nullptr);
  EXPECT_EQ(session.current_step()->id, "height");
  EXPECT_FALSE(session.result().takes.count("height"));
}

/// The journal an older build wrote before it stopped: floor samples, then a height take below
/// the floor (the take that ended that session with exit 1, and every --resume after it).
std::vector<JournalRecord> old_failing_journal(std::vector<JournalRecord>& full,
                                               SimulatedSession& sim) {
  SimulatorOptions o;
  sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  MeasuringSession session(default_protocol());
  full = test::run_frames(session, sim.log, o.tip_offsets).records;
  std::vector<JournalRecord> old;
  for (const JournalRecord& r : full) {
    if (r.type == "sample" && r.step == "height") {
      JournalRecord bad = r;
      bad.points[0].y() = -0.05;
      bad.value = -0.05;
      old.push_back(bad);
      break;
    }
    old.push_back(r);
  }
  return old;
}

TEST(SessionOddInput, TheOldFailingJournalResumes) {
  std::vector<JournalRecord> full;
  SimulatedSession sim;
  const std::vector<JournalRecord> old = old_failing_journal(full, sim);
  const std::string path = data_path("journal_old_failing.jsonl");
  {
    Json header = Json::object();
    header.set("protocol", default_protocol().name);
    JournalWriter w = JournalWriter::create(path, header);
    for (const JournalRecord& r : old) w.append(r);
  }
  const JournalContents c = read_journal(path);
  ASSERT_EQ(c.records.size(), old.size());
  ASSERT_NO_THROW(check_journal_protocol(c, default_protocol().name, path));
  MeasuringSession resumed(default_protocol());
  for (const JournalRecord& r : c.records) ASSERT_NO_THROW(resumed.apply(r)) << r.type;
  ASSERT_NE(resumed.current_step(), nullptr);
  EXPECT_EQ(resumed.current_step()->id, "height") << "resumes at the step of the bad take";
  EXPECT_FALSE(resumed.result().takes.count("height"));

  // The same bad take in the middle of a complete journal: skipped, the session completes.
  MeasuringSession complete(default_protocol());
  for (const JournalRecord& r : old) complete.apply(r);
  for (size_t i = old.size() - 1; i < full.size(); ++i) complete.apply(full[i]);
  ASSERT_TRUE(complete.done());
  for (const auto& kv : sim.truth)
    EXPECT_NEAR(complete.result().measurements.at(kv.first), kv.second, kNoiseFreeTolerance)
        << kv.first;
}

TEST(SessionOddInput, AJournalOfAnotherVersionOrProtocolIsRefused) {
  for (const char* version : {"2", "1e300", "\"1\"", "-1"}) {
    const std::string text = std::string("{\"format\":\"caliper-session-journal\",\"version\":") +
                             version + "}\n{\"type\":\"start\",\"time\":0}\n";
    try {
      parse_journal(text, "j.jsonl");
      ADD_FAILURE() << "version " << version << " accepted";
    } catch (const JournalError& e) {
      EXPECT_TRUE(contains(e.what(), "j.jsonl:1: session journal version")) << e.what();
      EXPECT_TRUE(contains(e.what(), "this build reads version 1")) << e.what();
    }
  }
  EXPECT_THROW(parse_journal("{\"format\":\"caliper-session-journal\"}\n", "j"), JournalError);
  const JournalContents c = parse_journal(
      "{\"format\":\"caliper-session-journal\",\"version\":1,\"protocol\":\"isak-short\"}\n", "j");
  try {
    check_journal_protocol(c, "virtual-caliper", "j.jsonl");
    ADD_FAILURE() << "a journal of another protocol was accepted";
  } catch (const JournalError& e) {
    EXPECT_TRUE(contains(e.what(), "\"isak-short\"")) << e.what();
    EXPECT_TRUE(contains(e.what(), "\"virtual-caliper\"")) << e.what();
  }
  EXPECT_NO_THROW(check_journal_protocol(c, "isak-short", "j.jsonl"));
}

TEST(SessionOddInput, AnAbsurdTypedWeightIsRefused) {
  MeasuringSession session(default_protocol());
  SessionFrame f;
  f.commands.push_back({"weight", Json(1e308)});
  const auto completed = [](const std::vector<SessionEvent>& events) {
    for (const SessionEvent& e : events)
      if (e.type == EventType::StepCompleted && e.step == "weight") return true;
    return false;
  };
  EXPECT_FALSE(completed(session.update(f)));
  EXPECT_TRUE(contains(session.view().message, "not a plausible value")) << session.view().message;
  EXPECT_LT(session.view().message.size(), 200u) << "1e308 printed short";
  EXPECT_FALSE(session.result().measurements.count("weight"));
  f.time = 0.1;
  f.commands = {{"weight", Json(64.5)}};
  EXPECT_TRUE(completed(session.update(f)));
  EXPECT_EQ(session.result().measurements.at("weight"), 64.5);
}

TEST(SessionOddInput, PoseLogVersionOutOfIntRangeIsRefused) {
  for (const char* version : {"1e300", "-1e300", "2", "1.5"}) {
    const std::string text = std::string("{\"format\":\"caliper-pose-log\",\"version\":") +
                             version + ",\"units\":\"metres\"}\n";
    try {
      parse_pose_log(text, "log.jsonl");
      ADD_FAILURE() << "version " << version << " accepted";
    } catch (const PoseLogError& e) {
      EXPECT_TRUE(contains(e.what(), "is not supported")) << e.what();
    }
  }
}

}  // namespace
}  // namespace caliper
