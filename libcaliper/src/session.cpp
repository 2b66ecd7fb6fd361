// Measuring session state machine (Pujades et al., The Virtual Caliper, TVCG 2019, sec. 3.1).
// ISAK arithmetic and the floor plane fit come from protocol.hpp (libcaliper core).
#include "caliper/session.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/protocol.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/text.hpp"

namespace caliper {
namespace {

const char* hand_name(Tip t) {
  return t == Tip::Left ? "left" : "right";
}

SessionEvent make_event(EventType type, std::string step, std::string message, double value = 0.0) {
  SessionEvent e;
  e.type = type;
  e.step = std::move(step);
  e.message = std::move(message);
  e.value = value;
  return e;
}

// An operator's action on a step ("skip", "redo"): the event and the journal record it carries.
SessionEvent action_event(EventType type, const std::string& step, std::string message,
                          const char* action, double time) {
  JournalRecord r;
  r.type = action;
  r.time = time;
  r.step = step;
  SessionEvent e = make_event(type, step, std::move(message));
  e.record = r;
  return e;
}

void append(std::vector<SessionEvent>& to, std::vector<SessionEvent> from) {
  for (SessionEvent& e : from) to.push_back(std::move(e));
}

// The mean of each tip's samples, and in `jitter` the larger RMS distance of a tip's samples
// from their mean.
std::vector<Eigen::Vector3d> sample_means(const std::vector<std::vector<Eigen::Vector3d>>& samples,
                                          size_t tips, double& jitter) {
  std::vector<Eigen::Vector3d> means(tips);
  jitter = 0.0;
  for (size_t i = 0; i < tips; ++i) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : samples[i]) m += p;
    m /= static_cast<double>(samples[i].size());
    double ss = 0.0;
    for (const Eigen::Vector3d& p : samples[i]) ss += (p - m).squaredNorm();
    jitter = std::max(jitter, std::sqrt(ss / static_cast<double>(samples[i].size())));
    means[i] = m;
  }
  return means;
}

}  // namespace

const char* event_type_name(EventType type) {
  // In the order of EventType.
  static constexpr std::array<const char*, 12> kNames = {
      "started",          "hold_started", "sample_accepted",      "sample_rejected",
      "floor_calibrated", "floor_retry",  "third_take_requested", "step_completed",
      "step_skipped",     "step_redo",    "step_started",         "session_complete"};
  static_assert(kNames.size() == static_cast<std::size_t>(EventType::SessionComplete) + 1);
  return smpl::enum_name(type, kNames);
}

Eigen::Vector3d tip_position(const DevicePose& grip, const Eigen::Vector3d& offset) {
  return grip.position + grip.orientation * offset;
}

SessionFrame session_frame(const PoseFrame& frame, const TipOffsets& offsets) {
  SessionFrame s;
  s.time = frame.time;
  const DevicePose& head = frame.device(Device::Head);
  s.head_valid = head.valid;
  s.head_position = head.position;
  s.head_orientation = head.orientation;
  const DevicePose& l = frame.device(Device::Left);
  const DevicePose& r = frame.device(Device::Right);
  s.left.valid = l.valid;
  s.left.tip = tip_position(l, offsets.left);
  s.left.trigger = l.trigger;
  s.right.valid = r.valid;
  s.right.tip = tip_position(r, offsets.right);
  s.right.trigger = r.trigger;
  s.commands = frame.commands;
  return s;
}

MeasuringSession::MeasuringSession(Protocol protocol, SessionOptions options)
    : protocol_(std::move(protocol)), options_(std::move(options)) {
  steps_.resize(protocol_.steps.size());
  if (options_.weight) typed_["weight"] = Json(*options_.weight);
  if (!options_.sex.empty()) typed_["sex"] = Json(options_.sex);
  if (options_.role != "operator") {
    view_.phase = Phase::Floor;
    view_.message = protocol_.floor.instruction;
  } else {
    view_.message = "Waiting for the operator to press Start.";
  }
}

const ProtocolStep* MeasuringSession::current_step() const {
  if (view_.phase != Phase::Steps || view_.step < 0) return nullptr;
  return &protocol_.steps[static_cast<size_t>(view_.step)];
}

std::vector<Tip> MeasuringSession::hold_tips(Tip hand) const {
  if (const ProtocolStep* s = current_step()) return s->tips;
  return {hand};
}

double MeasuringSession::step_value(const ProtocolStep& step,
                                    const std::vector<Eigen::Vector3d>& tips) const {
  if (step.kind == StepKind::Height) return tips.at(0).y() - floor_.offset;
  return (tips.at(0) - tips.at(1)).norm();
}

std::string MeasuringSession::rejected_hold(const std::vector<Eigen::Vector3d>& means,
                                            double jitter) const {
  if (jitter > protocol_.max_jitter_m) {
    return "The tip moved " + smpl::format_fixed_or_short(jitter * 1000.0, 1) +
           " mm during the hold (limit " +
           smpl::format_fixed_or_short(protocol_.max_jitter_m * 1000.0, 1) +
           " mm); rest your hand and hold still.";
  }
  if (view_.phase == Phase::Floor) {
    const Eigen::Vector2d target = protocol_.floor.targets[static_cast<size_t>(view_.floor_target)];
    const double d = (Eigen::Vector2d(means[0].x(), means[0].z()) - target).norm();
    if (d > options_.max_target_distance) {
      return "The tip was " + smpl::format_fixed_or_short(d, 2) +
             " m away from the glowing ring; put it inside the ring.";
    }
  }
  if (view_.phase == Phase::Steps) {
    // A take must be a length: a tip below the calibrated floor (the floor moved, or was
    // calibrated on a raised surface) is a rejected sample to retake, never the end of the session.
    return bad_take(*current_step(), means);
  }
  return "";
}

void MeasuringSession::arm_hold(const SessionFrame& frame, bool any_pressed, bool all_released,
                                std::vector<SessionEvent>& events) {
  switch (hold_state_) {
    case HoldState::WaitRelease:
      if (all_released) hold_state_ = HoldState::Armed;
      break;
    case HoldState::Armed:
      if (any_pressed) {
        view_.hold_hand = frame.right.trigger >= options_.trigger_press ? Tip::Right : Tip::Left;
        hold_state_ = HoldState::Holding;
        hold_start_ = frame.time;
        hold_samples_.assign(hold_tips(view_.hold_hand).size(), {});
        view_.holding = true;
        view_.hold_progress = 0.0;
        view_.jitter = 0.0;
        SessionEvent e =
            make_event(EventType::HoldStarted, current_step() ? current_step()->id : "floor", "");
        e.hand = view_.hold_hand;
        events.push_back(e);
      }
      break;
    case HoldState::Holding:
      break;
  }
}

std::vector<SessionEvent> MeasuringSession::update(const SessionFrame& frame) {
  std::vector<SessionEvent> events;
  for (const OperatorCommand& c : frame.commands) append(events, command(c, frame.time));
  const bool measuring =
      view_.phase == Phase::Floor ||
      (view_.phase == Phase::Steps && current_step() &&
       (current_step()->kind == StepKind::Height || current_step()->kind == StepKind::Distance));
  const ControllerInput* ctl[2] = {&frame.left, &frame.right};
  const auto input = [&](Tip t) -> const ControllerInput& { return *ctl[t == Tip::Left ? 0 : 1]; };
  const bool any_pressed =
      frame.left.trigger >= options_.trigger_press || frame.right.trigger >= options_.trigger_press;
  const bool all_released = frame.left.trigger < options_.trigger_release &&
                            frame.right.trigger < options_.trigger_release;

  if (!measuring) {
    hold_state_ = all_released ? HoldState::Armed : HoldState::WaitRelease;
    view_.holding = false;
    view_.hold_progress = 0.0;
    return events;
  }
  arm_hold(frame, any_pressed, all_released, events);
  if (hold_state_ != HoldState::Holding) return events;

  const std::string step_id = current_step() ? current_step()->id : "floor";
  const auto reject = [&](const std::string& why, bool released) {
    SessionEvent e = make_event(EventType::SampleRejected, step_id, why);
    e.hand = view_.hold_hand;
    events.push_back(e);
    view_.message = why;
    view_.holding = false;
    view_.hold_progress = 0.0;
    hold_state_ = released ? HoldState::Armed : HoldState::WaitRelease;
  };
  const double elapsed = frame.time - hold_start_;
  if (input(view_.hold_hand).trigger < options_.trigger_release) {
    reject("Trigger released after " + smpl::format_fixed_or_short(elapsed, 2) +
               " s; hold it for " + smpl::format_fixed_or_short(protocol_.hold_seconds, 1) +
               " s until the ring is full.",
           all_released);
    return events;
  }
  const std::vector<Tip> tips = hold_tips(view_.hold_hand);
  for (Tip t : tips) {
    if (!input(t).valid) {
      reject(std::string("Tracking of the ") + hand_name(t) +
                 " controller was lost during the hold; keep it in view of the base stations and "
                 "try again.",
             false);
      return events;
    }
  }
  for (size_t i = 0; i < tips.size(); ++i) hold_samples_[i].push_back(input(tips[i]).tip);
  double jitter = 0.0;
  const std::vector<Eigen::Vector3d> means = sample_means(hold_samples_, tips.size(), jitter);
  view_.jitter = jitter;
  view_.hold_progress = std::min(1.0, elapsed / protocol_.hold_seconds);
  // Tolerate floating-point time stamps that land a hair before the full second.
  constexpr double kTimeSlack = 1e-6;
  if (elapsed + kTimeSlack < protocol_.hold_seconds) return events;

  const std::string why = rejected_hold(means, jitter);
  if (!why.empty()) {
    reject(why, false);
    return events;
  }
  hold_state_ = HoldState::WaitRelease;
  view_.holding = false;
  view_.hold_progress = 0.0;
  if (view_.phase == Phase::Floor)
    append(events, accept_floor(means[0], frame.time, view_.hold_hand));
  else
    append(events, accept_step(means, frame.time, view_.hold_hand));
  return events;
}

std::string MeasuringSession::bad_take(const ProtocolStep& step,
                                       const std::vector<Eigen::Vector3d>& tips) const {
  const double value = step_value(step, tips);
  if (std::isfinite(value) && value > 0.0) return "";
  if (step.kind == StepKind::Height)
    return "The tip was " + smpl::format_fixed_or_short(-value * 1000.0, 1) +
           " mm below the calibrated floor; put it on the top of the head and take it again (if "
           "this repeats, redo the floor calibration).";
  return "The two tips were at the same point; put them on the two landmarks and take it again.";
}

std::vector<SessionEvent> MeasuringSession::accept_floor(const Eigen::Vector3d& point, double time,
                                                         Tip hand) {
  std::vector<SessionEvent> events;
  JournalRecord r;
  r.type = "floor_sample";
  r.index = view_.floor_target;
  r.points = {point};
  r.time = time;
  floor_.samples.push_back(point);
  SessionEvent e = make_event(EventType::SampleAccepted, "floor",
                              "Floor point " + std::to_string(view_.floor_target + 1) + " of " +
                                  std::to_string(protocol_.floor.targets.size()) + " taken.",
                              point.y());
  e.hand = hand;
  e.record = r;
  events.push_back(e);
  view_.last_accept_time = time;
  view_.message = e.message;
  ++view_.floor_target;
  if (static_cast<size_t>(view_.floor_target) >= protocol_.floor.targets.size())
    append(events, complete_floor(time));
  return events;
}

std::vector<SessionEvent> MeasuringSession::complete_floor(double time) {
  std::vector<SessionEvent> events;
  std::string problem;
  FloorCalibration fit;
  try {
    fit = calibrate_floor(floor_.samples);
    if (fit.tilt_degrees > protocol_.floor.max_tilt_deg)
      problem = "the floor points tilt by " + smpl::format_fixed_or_short(fit.tilt_degrees, 1) +
                " degrees (limit " + smpl::format_fixed_or_short(protocol_.floor.max_tilt_deg, 1) +
                ")";
    else if (fit.rms_residual > protocol_.floor.max_residual_m)
      problem = "the floor points are " +
                smpl::format_fixed_or_short(fit.rms_residual * 1000.0, 1) +
                " mm off a plane (limit " +
                smpl::format_fixed_or_short(protocol_.floor.max_residual_m * 1000.0, 1) + " mm)";
  } catch (const CalibrationError& e) {
    problem = std::string("the floor points do not span a plane (") + e.what() + ")";
  }
  if (!problem.empty()) {
    JournalRecord r;
    r.type = "floor_retry";
    r.time = time;
    SessionEvent e =
        make_event(EventType::FloorRetry, "floor",
                   "Floor calibration again: " + problem + ". Put the tip flat on the floor.");
    e.record = r;
    events.push_back(e);
    floor_ = FloorResult{};
    view_.floor_target = 0;
    view_.message = e.message;
    return events;
  }
  floor_.valid = true;
  floor_.offset = fit.floor_height;
  floor_.tilt_deg = fit.tilt_degrees;
  floor_.residual = fit.rms_residual;
  events.push_back(make_event(
      EventType::FloorCalibrated, "floor",
      "Floor calibrated: offset " + smpl::format_fixed_or_short(fit.floor_height * 1000.0, 1) +
          " mm, tilt " + smpl::format_fixed_or_short(fit.tilt_degrees, 2) + " degrees, residual " +
          smpl::format_fixed_or_short(fit.rms_residual * 1000.0, 1) + " mm.",
      fit.floor_height));
  append(events, enter_step(0, time));
  return events;
}

std::vector<SessionEvent> MeasuringSession::enter_step(int index, double time) {
  std::vector<SessionEvent> events;
  // Skip over steps that are already done (typed in advance, or restored).
  while (index < static_cast<int>(protocol_.steps.size())) {
    const ProtocolStep& s = protocol_.steps[static_cast<size_t>(index)];
    view_.phase = Phase::Steps;
    view_.step = index;
    if (steps_[static_cast<size_t>(index)].done) {
      ++index;
      continue;
    }
    if ((s.kind == StepKind::TypedNumber || s.kind == StepKind::TypedChoice) &&
        typed_.count(s.measurement)) {
      append(events, set_typed(s.measurement, typed_.at(s.measurement), time, false));
      if (steps_[static_cast<size_t>(index)].done) {
        ++index;
        continue;
      }
    }
    view_.message = s.instruction;
    events.push_back(make_event(EventType::StepStarted, s.id, s.instruction));
    return events;
  }
  view_.phase = Phase::Done;
  view_.step = -1;
  view_.message = "All measurements taken.";
  events.push_back(make_event(EventType::SessionComplete, "", view_.message));
  return events;
}

std::vector<SessionEvent> MeasuringSession::accept_step(const std::vector<Eigen::Vector3d>& tips,
                                                        double time, Tip hand) {
  std::vector<SessionEvent> events;
  const ProtocolStep& s = *current_step();
  StepState& st = steps_[static_cast<size_t>(view_.step)];
  const double value = step_value(s, tips);
  st.takes.push_back(value);
  st.take_tips.push_back(tips);
  JournalRecord r;
  r.type = "sample";
  r.step = s.id;
  r.points = tips;
  r.value = value;
  r.time = time;
  SessionEvent e = make_event(EventType::SampleAccepted, s.id,
                              s.title + ": take " + std::to_string(st.takes.size()) + " = " +
                                  smpl::format_fixed_or_short(value * 100.0, 1) + " cm.",
                              value);
  e.hand = hand;
  e.record = r;
  events.push_back(e);
  view_.last_accept_time = time;
  view_.message = e.message;
  append(events, finish_step(time));
  return events;
}

std::vector<SessionEvent> MeasuringSession::finish_step(double time) {
  std::vector<SessionEvent> events;
  const ProtocolStep& s = *current_step();
  StepState& st = steps_[static_cast<size_t>(view_.step)];
  if (st.takes.size() < 2) return events;
  if (st.takes.size() == 2 &&
      isak_needs_third(st.takes[0], st.takes[1], protocol_.isak_threshold)) {
    const double rel = isak_relative_difference(st.takes[0], st.takes[1]);
    SessionEvent e = make_event(
        EventType::ThirdTakeRequested, s.id,
        "The two takes differ by " + smpl::format_fixed_or_short(rel * 100.0, 1) +
            " % (more than " + smpl::format_fixed_or_short(protocol_.isak_threshold * 100.0, 1) +
            " %): take it a third time.",
        rel);
    view_.message = e.message;
    events.push_back(e);
    return events;
  }
  const IsakResult isak = isak_combine(st.takes, protocol_.isak_threshold);
  st.done = true;
  st.value = isak.value;
  events.push_back(make_event(EventType::StepCompleted, s.id,
                              s.title + ": " + smpl::format_fixed_or_short(isak.value * 100.0, 1) +
                                  " cm (" + std::to_string(isak.takes_used) + " takes).",
                              isak.value));
  append(events, enter_step(view_.step + 1, time));
  return events;
}

std::vector<SessionEvent> MeasuringSession::set_typed(const std::string& measurement,
                                                      const Json& value, double time,
                                                      bool journal) {
  std::vector<SessionEvent> events;
  const int index = [&] {
    for (size_t i = 0; i < protocol_.steps.size(); ++i)
      if (protocol_.steps[i].measurement == measurement) return static_cast<int>(i);
    return -1;
  }();
  if (index < 0) return events;
  const ProtocolStep& s = protocol_.steps[static_cast<size_t>(index)];
  StepState& st = steps_[static_cast<size_t>(index)];
  std::string shown;
  if (s.kind == StepKind::TypedNumber) {
    if (!value.is_number() || !std::isfinite(value.as_number()) || value.as_number() <= 0.0) {
      view_.message = s.title + ": type a positive number.";
      return events;
    }
    // A typed value outside the human range (a weight of 1e308 kg) is refused like a bad take.
    std::optional<MeasurementRange> range;
    try {
      range = measurement_range(measurement);
    } catch (const InvalidInputError&) {
    }
    if (range && (value.as_number() < range->error_min || value.as_number() > range->error_max)) {
      view_.message = s.title + ": " + smpl::format_fixed_or_short(value.as_number(), 1) + " " +
                      s.unit + " is not a plausible value (expected " +
                      smpl::format_fixed_or_short(range->error_min, 1) + " to " +
                      smpl::format_fixed_or_short(range->error_max, 1) + " " + s.unit +
                      "); type it again.";
      return events;
    }
    st.value = value.as_number();
    shown = smpl::format_fixed_or_short(value.as_number(), 1) + " " + s.unit;
  } else if (s.kind == StepKind::TypedChoice) {
    if (!value.is_string() ||
        std::find(s.choices.begin(), s.choices.end(), value.as_string()) == s.choices.end()) {
      view_.message = s.title + ": choose one of the listed values.";
      return events;
    }
    st.text = value.as_string();
    shown = st.text;
  } else {
    return events;
  }
  typed_[measurement] = value;
  st.done = true;
  st.skipped = false;
  SessionEvent e = make_event(EventType::StepCompleted, s.id, s.title + ": " + shown + ".",
                              st.value.value_or(0.0));
  if (journal) {
    JournalRecord r;
    r.type = "typed";
    r.step = s.id;
    if (value.is_number())
      r.value = value.as_number();
    else
      r.text = value.as_string();
    r.time = time;
    e.record = r;
  }
  events.push_back(e);
  // Typing the current step's value moves on.
  if (view_.phase == Phase::Steps && view_.step == index)
    append(events, enter_step(index + 1, time));
  return events;
}

std::vector<SessionEvent> MeasuringSession::skip(double time) {
  std::vector<SessionEvent> events;
  if (view_.phase == Phase::Floor) {
    events.push_back(action_event(EventType::StepSkipped, "floor",
                                  "Floor calibration skipped: heights use the runtime's floor.",
                                  "skip", time));
    floor_ = FloorResult{};
    append(events, enter_step(0, time));
    return events;
  }
  if (const ProtocolStep* s = current_step()) {
    StepState& st = steps_[static_cast<size_t>(view_.step)];
    st = StepState{};
    st.done = true;
    st.skipped = true;
    events.push_back(
        action_event(EventType::StepSkipped, s->id, s->title + " skipped.", "skip", time));
    append(events, enter_step(view_.step + 1, time));
  }
  return events;
}

std::vector<SessionEvent> MeasuringSession::redo(double time) {
  std::vector<SessionEvent> events;
  hold_state_ = HoldState::WaitRelease;
  view_.holding = false;
  if (view_.phase == Phase::Floor ||
      (view_.phase == Phase::Steps && view_.step == 0 && steps_[0].takes.empty())) {
    floor_ = FloorResult{};
    view_.phase = Phase::Floor;
    view_.floor_target = 0;
    view_.step = -1;
    view_.message = "Floor calibration again. " + protocol_.floor.instruction;
    events.push_back(action_event(EventType::StepRedo, "floor", view_.message, "redo", time));
    return events;
  }
  int index =
      view_.phase == Phase::Done ? static_cast<int>(protocol_.steps.size()) - 1 : view_.step;
  // Nothing taken at this step yet: redo the previous one.
  if (view_.phase == Phase::Steps && steps_[static_cast<size_t>(index)].takes.empty() && index > 0)
    --index;
  const ProtocolStep& s = protocol_.steps[static_cast<size_t>(index)];
  steps_[static_cast<size_t>(index)] = StepState{};
  if (s.kind == StepKind::TypedNumber || s.kind == StepKind::TypedChoice)
    typed_.erase(s.measurement);
  events.push_back(action_event(EventType::StepRedo, s.id, s.title + ": again.", "redo", time));
  view_.phase = Phase::Steps;
  view_.step = index;
  view_.message = s.instruction;
  events.push_back(make_event(EventType::StepStarted, s.id, s.instruction));
  return events;
}

std::vector<SessionEvent> MeasuringSession::command(const OperatorCommand& c, double time) {
  std::vector<SessionEvent> events;
  if (c.command == "start") {
    if (view_.phase != Phase::WaitingForStart) return events;
    JournalRecord r;
    r.type = "start";
    r.time = time;
    view_.phase = Phase::Floor;
    view_.message = protocol_.floor.instruction;
    SessionEvent e = make_event(EventType::Started, "floor", view_.message);
    e.record = r;
    events.push_back(e);
    return events;
  }
  if (c.command == "weight") return set_typed("weight", c.value, time, true);
  if (c.command == "sex") return set_typed("sex", c.value, time, true);
  if (view_.phase == Phase::WaitingForStart) return events;
  if (c.command == "skip") return skip(time);
  if (c.command == "redo") return redo(time);
  return events;
}

void MeasuringSession::apply(const JournalRecord& r) {
  const auto mismatch = [&](const std::string& why) {
    throw JournalError("journal record \"" + r.type + "\"" +
                       (r.step.empty() ? "" : " for step \"" + r.step + "\"") +
                       " does not fit the session: " + why +
                       " (was the journal written with another protocol?)");
  };
  if (r.type == "start") {
    if (view_.phase == Phase::WaitingForStart) command(OperatorCommand{"start", Json()}, r.time);
    return;
  }
  if (view_.phase == Phase::WaitingForStart) {
    view_.phase = Phase::Floor;  // a journal from the self role has no start record
  }
  if (r.type == "floor_sample") {
    if (view_.phase != Phase::Floor) mismatch("the floor is already calibrated");
    if (r.points.size() != 1) mismatch("a floor sample has one point");
    accept_floor(r.points[0], r.time, Tip::Right);
  } else if (r.type == "floor_retry") {
    floor_ = FloorResult{};
    view_.phase = Phase::Floor;
    view_.floor_target = 0;
  } else if (r.type == "sample") {
    const ProtocolStep* s = current_step();
    if (!s || s->id != r.step) mismatch("the session is not at that step");
    if (r.points.size() != s->tips.size()) mismatch("wrong number of tip positions");
    // A take that is rejected today (journalled by an older build: a tip below the floor) is
    // skipped, so that such a journal still resumes, at that step.
    if (bad_take(*s, r.points).empty()) accept_step(r.points, r.time, Tip::Right);
  } else if (r.type == "typed") {
    const int i = protocol_.find_step(r.step);
    if (i < 0) mismatch("no such step");
    const Json v = r.text.empty() ? Json(r.value) : Json(r.text);
    set_typed(protocol_.steps[static_cast<size_t>(i)].measurement, v, r.time, false);
  } else if (r.type == "skip") {
    if (r.step == "floor" ? view_.phase != Phase::Floor
                          : (!current_step() || current_step()->id != r.step))
      mismatch("the session is not at that step");
    skip(r.time);
  } else if (r.type == "redo") {
    redo(r.time);
  } else {
    mismatch("unknown record type");
  }
  hold_state_ = HoldState::WaitRelease;
}

SessionResult MeasuringSession::result() const {
  SessionResult out;
  out.floor_offset = floor_.offset;
  for (size_t i = 0; i < protocol_.steps.size(); ++i) {
    const ProtocolStep& s = protocol_.steps[i];
    const StepState& st = steps_[i];
    if (st.skipped) out.skipped.push_back(s.id);
    if (!st.done || st.skipped) continue;
    if (s.kind == StepKind::TypedChoice) {
      if (s.measurement == "sex") out.sex = st.text;
      continue;
    }
    if (st.value) out.measurements[s.measurement] = *st.value;
    if (!st.takes.empty()) out.takes[s.measurement] = st.takes;
  }
  return out;
}

}  // namespace caliper
