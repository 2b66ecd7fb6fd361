// Shared fixtures of the session tests: a hand-made person and a runner that feeds a pose log
// into a MeasuringSession.
#pragma once

#include <string>
#include <vector>

#include "caliper/session.hpp"
#include "caliper/simulator.hpp"

namespace caliper::test {

/// Noise-free logs are written with 6 decimals (see test_session.cpp): a measurement read back
/// from one is within this of the truth.
constexpr double kNoiseFreeTolerance = 5e-6;  // m

/// A file in the tests' data folder.
inline std::string data_path(const std::string& name) {
  return std::string(CALIPER_TEST_DATA_DIR) + "/" + name;
}

/// A person given by landmark points only (metres, floor at y = 0, facing +Z): no model needed.
inline SimulatedPerson hand_made_person() {
  SimulatedPerson p;
  p.landmarks["head_top"] = {0.0, 1.72, 0.02};
  p.landmarks["left_fingertip"] = {0.86, 1.42, 0.0};
  p.landmarks["right_fingertip"] = {-0.85, 1.41, 0.01};
  p.landmarks["crotch"] = {0.0, 0.80, 0.02};
  p.landmarks["left_hip"] = {0.17, 0.90, 0.0};
  p.landmarks["right_hip"] = {-0.18, 0.90, 0.01};
  p.landmarks["left_shoulder"] = {0.19, 1.43, 0.0};
  p.landmarks["left_wrist"] = {0.71, 1.42, 0.01};
  p.weight = 64.5;
  p.sex = "female";
  return p;
}

/// Everything a replay produced.
struct ReplayOutcome {
  std::vector<SessionEvent> events;
  std::vector<JournalRecord> records;  ///< journal records in order
  int count(EventType type) const {
    int n = 0;
    for (const SessionEvent& e : events) n += e.type == type;
    return n;
  }
};

/// Feeds frames [begin, end) of `log` into `session`.
inline ReplayOutcome run_frames(MeasuringSession& session, const PoseLog& log,
                                const TipOffsets& offsets, size_t begin = 0,
                                size_t end = static_cast<size_t>(-1)) {
  ReplayOutcome out;
  end = std::min(end, log.frames.size());
  for (size_t i = begin; i < end; ++i) {
    for (SessionEvent& e : session.update(session_frame(log.frames[i], offsets))) {
      if (e.record) out.records.push_back(*e.record);
      out.events.push_back(std::move(e));
    }
  }
  return out;
}

}  // namespace caliper::test
