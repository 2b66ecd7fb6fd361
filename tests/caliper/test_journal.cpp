// Session journal: round trip, a cut at every byte, resume after a crash.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "caliper/journal.hpp"
#include "caliper/line_file.hpp"
#include "caliper/session.hpp"
#include "caliper/simulator.hpp"
#include "session_fixtures.hpp"

namespace caliper {
namespace {

using test::data_path;
using test::kNoiseFreeTolerance;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A full session (with a third take and an operator redo) journaled to `path`.
test::ReplayOutcome journaled_session(const std::string& path, SimulatedSession& sim) {
  SimulatorOptions o;
  o.role = "operator";
  o.third_take_step = "height";
  o.redo_step = "hip_width";
  sim = simulate_session(default_protocol(), test::hand_made_person(), o);
  SessionOptions so;
  so.role = "operator";
  MeasuringSession session(default_protocol(), so);
  Json header = Json::object();
  header.set("role", "operator");
  JournalWriter w = JournalWriter::create(path, header);
  test::ReplayOutcome out = test::run_frames(session, sim.log, o.tip_offsets);
  for (const JournalRecord& r : out.records) w.append(r);
  EXPECT_TRUE(session.done());
  return out;
}

TEST(Journal, RoundTripRestoresTheSession) {
  SimulatedSession sim;
  const std::string path = data_path("journal_roundtrip.jsonl");
  const test::ReplayOutcome out = journaled_session(path, sim);
  const JournalContents c = read_journal(path);
  ASSERT_TRUE(c.has_header);
  EXPECT_FALSE(c.torn_tail);
  EXPECT_EQ(c.header.at("role").as_string(), "operator");
  ASSERT_EQ(c.records.size(), out.records.size());
  SessionOptions so;
  so.role = "operator";
  MeasuringSession restored(default_protocol(), so);
  for (const JournalRecord& r : c.records) restored.apply(r);
  ASSERT_TRUE(restored.done());
  for (const auto& kv : sim.truth)
    EXPECT_NEAR(restored.result().measurements.at(kv.first), kv.second, kNoiseFreeTolerance)
        << kv.first;
  EXPECT_EQ(restored.result().takes.at("height").size(), 3u);
}

TEST(Journal, SurvivesACutAtEveryByte) {
  SimulatedSession sim;
  const std::string path = data_path("journal_full.jsonl");
  journaled_session(path, sim);
  const std::string text = read_all(path);
  const JournalContents full = parse_journal(text, "full");
  // Byte offsets at which each line ends (just after its newline).
  std::vector<size_t> line_ends;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') line_ends.push_back(i + 1);
  ASSERT_EQ(line_ends.size(), full.records.size() + 1);
  SessionOptions so;
  so.role = "operator";
  for (size_t cut = 0; cut <= text.size(); ++cut) {
    JournalContents c;
    ASSERT_NO_THROW(c = parse_journal(text.substr(0, cut), "cut")) << "cut at byte " << cut;
    size_t complete = 0;
    while (complete < line_ends.size() && line_ends[complete] <= cut) ++complete;
    ASSERT_EQ(c.has_header, complete >= 1) << "cut at byte " << cut;
    ASSERT_EQ(c.records.size(), complete == 0 ? 0 : complete - 1) << "cut at byte " << cut;
    ASSERT_EQ(c.valid_bytes, complete == 0 ? 0 : line_ends[complete - 1]) << "cut at byte " << cut;
    ASSERT_EQ(c.torn_tail, cut != c.valid_bytes) << "cut at byte " << cut;
    // The recovered prefix replays into a session without error.
    MeasuringSession s(default_protocol(), so);
    ASSERT_NO_THROW(for (const JournalRecord& r : c.records) s.apply(r)) << "cut at byte " << cut;
  }
}

TEST(Journal, ResumeCutsTheTornTailAndAppends) {
  SimulatedSession sim;
  const std::string path = data_path("journal_resume.jsonl");
  journaled_session(path, sim);
  std::string text = read_all(path);
  text.resize(text.size() - 17);  // a torn last record
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << text;
  }
  JournalContents c = read_journal(path);
  ASSERT_TRUE(c.torn_tail);
  const size_t n = c.records.size();
  {
    JournalWriter w = JournalWriter::resume(path, c, Json::object());
    JournalRecord r;
    r.type = "skip";
    r.step = "sex";
    w.append(r);
  }
  const JournalContents after = read_journal(path);
  EXPECT_FALSE(after.torn_tail);
  ASSERT_EQ(after.records.size(), n + 1);
  EXPECT_EQ(after.records.back().type, "skip");
}

TEST(Journal, CorruptLineInTheMiddleNamesItsLine) {
  const std::string text =
      "{\"format\":\"caliper-session-journal\",\"version\":1}\n"
      "{\"type\":\"start\",\"time\":0}\n"
      "{\"type\":\"sample\",\"step\n"
      "{\"type\":\"skip\",\"step\":\"floor\",\"time\":1}\n";
  try {
    parse_journal(text, "j.jsonl");
    FAIL();
  } catch (const JournalError& e) {
    EXPECT_NE(std::string(e.what()).find("j.jsonl:3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_journal("{\"format\":\"something-else\"}\n", "x"), JournalError);
  EXPECT_THROW(read_journal("/nonexistent/journal.jsonl"), JournalError);
}

TEST(Journal, RecordOfAnotherProtocolIsRefused) {
  MeasuringSession s(default_protocol());
  JournalRecord r;
  r.type = "sample";
  r.step = "height";
  r.points = {Eigen::Vector3d(0, 1.7, 0)};
  EXPECT_THROW(s.apply(r), JournalError) << "the session is still calibrating the floor";
}

TEST(Journal, CrashAndResumeContinuesAtTheStep) {
  // A crash in the middle of the session: the first part of the log is replayed with a
  // journal, then a fresh session restored from the journal replays the rest.
  SimulatorOptions o;
  o.tip_noise = 0.0;
  const Protocol p = default_protocol();
  const SimulatedSession sim = simulate_session(p, test::hand_made_person(), o);
  const size_t cut = sim.quiet_frames[sim.quiet_frames.size() / 2];
  const std::string path = data_path("journal_crash.jsonl");
  std::string step_at_crash;
  {
    MeasuringSession first(p);
    JournalWriter w = JournalWriter::create(path, Json::object());
    const test::ReplayOutcome out = test::run_frames(first, sim.log, o.tip_offsets, 0, cut);
    for (const JournalRecord& r : out.records) w.append(r);
    ASSERT_FALSE(first.done());
    ASSERT_NE(first.current_step(), nullptr);
    step_at_crash = first.current_step()->id;
  }
  MeasuringSession second(p);
  for (const JournalRecord& r : read_journal(path).records) second.apply(r);
  ASSERT_NE(second.current_step(), nullptr);
  EXPECT_EQ(second.current_step()->id, step_at_crash);
  test::run_frames(second, sim.log, o.tip_offsets, cut);
  ASSERT_TRUE(second.done());
  for (const auto& kv : sim.truth)
    EXPECT_NEAR(second.result().measurements.at(kv.first), kv.second, kNoiseFreeTolerance)
        << kv.first;
}

TEST(LineFile, AppendsFlushedLinesAndMovesOwnership) {
  const std::string path = data_path("line-file.txt");
  LineFile closed;
  EXPECT_FALSE(closed.is_open());
  EXPECT_FALSE(closed.append_line("lost"));
  LineFile f(path, "wb");
  ASSERT_TRUE(f.is_open());
  EXPECT_TRUE(f.append_line("one"));
  LineFile moved = std::move(f);
  EXPECT_TRUE(moved.append_line("two", /*sync=*/true));
  {
    std::ifstream in(path);  // flushed: readable while the file is still open
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_EQ(ss.str(), "one\ntwo\n");
  }
  EXPECT_FALSE(LineFile("/nonexistent-dir/x.txt", "wb").is_open());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace caliper
