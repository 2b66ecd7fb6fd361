/// \file session.hpp
/// The measuring session state machine of The Virtual Caliper (Pujades et al., TVCG 2019, sec.
/// 3.1): floor calibration (tip on the floor at five targets, trigger held one second, floor
/// offset = median height, plane fit tilt and residual checked), then the protocol's steps with
/// ISAK takes (two takes, a third when they differ by more than 1.5 %, the value is their mean or
/// the median of three), self and operator roles, skip and redo, typed weight and sex.
///
/// Pure logic: no GL, no OpenXR, no files. The app feeds one SessionFrame per rendered frame
/// (from OpenXR or a pose log) and operator commands; the session returns events (a sample was
/// accepted: play a tone, pulse the haptics, flash the ring) and exposes a read-only view for
/// rendering. Every state change that must survive a crash comes out as a JournalRecord on the
/// event; apply() replays such records (`--resume`).
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "caliper/journal.hpp"
#include "caliper/pose_log.hpp"
#include "caliper/protocol_file.hpp"

namespace caliper {

/// Tip offsets in the grip frame of each controller, metres.
struct TipOffsets {
  Eigen::Vector3d left = Eigen::Vector3d(0.0, -0.03, 0.09);
  Eigen::Vector3d right = Eigen::Vector3d(0.0, -0.03, 0.09);
};

/// A controller as the session sees it: its tip (grip pose + offset), tracking and trigger.
struct ControllerInput {
  bool valid = false;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();  ///< tip position, tracking space, m
  double trigger = 0.0;                           ///< [0, 1]
};

/// One frame of input.
struct SessionFrame {
  double time = 0.0;  ///< s, increasing
  bool head_valid = false;
  Eigen::Vector3d head_position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond head_orientation = Eigen::Quaterniond::Identity();
  ControllerInput left, right;
  std::vector<OperatorCommand> commands;
};

/// Tip position of a tracked grip pose: position + orientation * offset.
Eigen::Vector3d tip_position(const DevicePose& grip, const Eigen::Vector3d& offset);

/// Converts a pose log frame (grip poses) to session input with the given tip offsets.
SessionFrame session_frame(const PoseFrame& frame, const TipOffsets& offsets);

/// Session settings that are not in the protocol.
struct SessionOptions {
  std::string role = "self";      ///< "self": starts at once; "operator": waits for "start"
  double trigger_press = 0.75;    ///< trigger value that starts a hold
  double trigger_release = 0.25;  ///< below this the trigger counts as released (hysteresis)
  double max_target_distance =
      0.25;  ///< floor tip further than this from its ring (x, z) is rejected, m
  std::optional<double> weight;  ///< typed in advance (kg), e.g. --weight
  std::string sex;               ///< typed in advance, e.g. --sex ("" = not given)
};

enum class Phase { WaitingForStart, Floor, Steps, Done };

enum class EventType {
  Started,             ///< the session started
  HoldStarted,         ///< a trigger hold began
  SampleAccepted,      ///< a floor or step sample was taken: tone + haptic + visual
  SampleRejected,      ///< a hold ended without a sample; `message` says why
  FloorCalibrated,     ///< floor offset known; `value` = offset (m), message has tilt/residual
  FloorRetry,          ///< plane fit off; floor samples discarded; `message` says why
  ThirdTakeRequested,  ///< the two takes differ by more than the ISAK threshold
  StepCompleted,       ///< `step` done; `value` = ISAK value (or typed number)
  StepSkipped,
  StepRedo,     ///< takes of `step` discarded
  StepStarted,  ///< now at `step`
  SessionComplete,
};
/// "sample_accepted", ... (snake_case of the enumerator).
const char* event_type_name(EventType type);

struct SessionEvent {
  EventType type = EventType::Started;
  std::string step;     ///< step id ("floor" during floor calibration)
  std::string message;  ///< plain words for the user
  double value = 0.0;
  Tip hand = Tip::Right;                ///< controller whose trigger made the hold (for haptics)
  std::optional<JournalRecord> record;  ///< set when the event must go into the journal
};

/// Floor calibration result.
struct FloorResult {
  bool valid = false;
  double offset = 0.0;    ///< floor height in tracking space = median of the sample heights, m
  double tilt_deg = 0.0;  ///< angle between the fitted plane's normal and +Y
  double residual = 0.0;  ///< RMS distance of the samples to the fitted plane, m
  std::vector<Eigen::Vector3d> samples;
};

/// State of one protocol step.
struct StepState {
  std::vector<double> takes;                            ///< accepted take values (m), in order
  std::vector<std::vector<Eigen::Vector3d>> take_tips;  ///< tip positions of each take
  bool done = false;
  bool skipped = false;
  std::optional<double> value;  ///< ISAK value (measured steps) or typed number
  std::string text;             ///< typed choice
};

/// What the app shows (read-only view of the session).
struct SessionView {
  Phase phase = Phase::WaitingForStart;
  int step = -1;         ///< current step index during Phase::Steps
  int floor_target = 0;  ///< current floor target index during Phase::Floor
  bool holding = false;
  double hold_progress = 0.0;  ///< [0, 1], fills the progress ring
  Tip hold_hand = Tip::Right;
  double jitter = 0.0;             ///< RMS tip motion of the current hold so far, m
  std::string message;             ///< last feedback in plain words
  double last_accept_time = -1e9;  ///< session time of the last accepted sample (for the flash)
};

/// Final result of a session.
struct SessionResult {
  std::map<std::string, double> measurements;        ///< measurement id -> value (m; weight kg)
  std::map<std::string, std::vector<double>> takes;  ///< measurement id -> takes (m)
  std::string sex;                                   ///< "" when not given
  double floor_offset = 0.0;
  std::vector<std::string> skipped;
};

class MeasuringSession {
 public:
  MeasuringSession(Protocol protocol, SessionOptions options = {});

  /// Advances one frame (its commands first). Returns the events of this frame.
  std::vector<SessionEvent> update(const SessionFrame& frame);

  /// Applies one operator command ("start", "redo", "skip", "weight", "sex").
  std::vector<SessionEvent> command(const OperatorCommand& command, double time);

  /// Replays a journal record (resume after a crash); same effect as when it was made. Throws
  /// JournalError when the record does not fit the session state (e.g. a step id that is not in
  /// the protocol). A sample that update() would reject today (a height at or below the floor,
  /// journalled by an older build) is skipped, so that every journal can be resumed.
  void apply(const JournalRecord& record);

  const Protocol& protocol() const { return protocol_; }
  const SessionOptions& options() const { return options_; }
  const SessionView& view() const { return view_; }
  const FloorResult& floor() const { return floor_; }
  const std::vector<StepState>& steps() const { return steps_; }
  /// The current step, or nullptr outside Phase::Steps.
  const ProtocolStep* current_step() const;
  bool done() const { return view_.phase == Phase::Done; }
  /// Measurements so far (complete steps only), floor-corrected.
  SessionResult result() const;

 private:
  std::vector<SessionEvent> accept_floor(const Eigen::Vector3d& point, double time, Tip hand);
  std::vector<SessionEvent> accept_step(const std::vector<Eigen::Vector3d>& tips, double time,
                                        Tip hand);
  std::vector<SessionEvent> enter_step(int index, double time);
  std::vector<SessionEvent> complete_floor(double time);
  std::vector<SessionEvent> finish_step(double time);
  std::vector<SessionEvent> set_typed(const std::string& measurement, const Json& value,
                                      double time, bool journal);
  std::vector<SessionEvent> skip(double time);
  std::vector<SessionEvent> redo(double time);
  std::vector<Tip> hold_tips(Tip hand) const;
  double step_value(const ProtocolStep& step, const std::vector<Eigen::Vector3d>& tips) const;
  /// Why `tips` cannot be a take of `step` (a height at or below the floor, two tips at one
  /// point, NaN), in plain words for the person measuring; "" for a good take.
  std::string bad_take(const ProtocolStep& step, const std::vector<Eigen::Vector3d>& tips) const;
  /// Why a full hold with these tip means and jitter is rejected (too much jitter, the tip off the
  /// floor target, a take that is no length), or "" to accept it.
  std::string rejected_hold(const std::vector<Eigen::Vector3d>& means, double jitter) const;
  /// The trigger state machine before a hold: armed once both triggers are released, a hold
  /// started (HoldStarted) when one is pressed.
  void arm_hold(const SessionFrame& frame, bool any_pressed, bool all_released,
                std::vector<SessionEvent>& events);

  Protocol protocol_;
  SessionOptions options_;
  SessionView view_;
  FloorResult floor_;
  std::vector<StepState> steps_;
  std::map<std::string, Json> typed_;  ///< typed values by measurement id ("weight", "sex")
  // Hold tracking.
  enum class HoldState { Armed, Holding, WaitRelease };
  HoldState hold_state_ = HoldState::Armed;
  double hold_start_ = 0.0;
  std::vector<std::vector<Eigen::Vector3d>> hold_samples_;  ///< per tip, per frame
};

}  // namespace caliper
