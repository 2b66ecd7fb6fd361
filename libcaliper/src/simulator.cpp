// Session simulator: pose logs of a virtual person doing the measuring protocol.
#include "caliper/simulator.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <random>

#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"

namespace caliper {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Gaussian numbers from mt19937_64 with our own Box-Muller, identical on every standard library.
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double uniform() {
    return (static_cast<double>(rng_() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
  }
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = uniform(), u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * kPi * u2);
  }

 private:
  std::mt19937_64 rng_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

/// One scripted thing the person does: move the tips to targets, then (maybe) hold a trigger.
struct Action {
  std::array<std::optional<Eigen::Vector3d>, 2> target;  ///< left, right; nullopt = rest
  bool press = false;
  Tip hand = Tip::Right;
  double hold = 0.0;         ///< trigger held this long, s
  double dropout_at = -1.0;  ///< seconds into the hold when tracking drops (< 0: none)
  Tip dropout_hand = Tip::Left;
  std::vector<OperatorCommand> commands;  ///< issued at the first frame of the action
  double pause = 0.0;                     ///< command-only actions: duration
  std::optional<Eigen::Vector3d> look;    ///< where the head looks (default: ahead, slightly down)
};

constexpr double kMove = 0.45;        ///< s, tips travel to the targets
constexpr double kSettle = 0.15;      ///< s, tips at the targets before the trigger
constexpr double kRelease = 0.30;     ///< s, after the trigger is released
constexpr double kHoldMargin = 0.15;  ///< s, people hold a bit longer than required
constexpr double kDropout = 0.15;     ///< s, tracking lost for this long

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

const Eigen::Vector3d& landmark(const SimulatedPerson& person, const std::string& name) {
  auto it = person.landmarks.find(name);
  if (it == person.landmarks.end())
    throw InvalidInputError("simulator: the person has no landmark \"" + name +
                            "\" that the protocol needs");
  return it->second;
}

}  // namespace

SimulatedPerson person_from_model(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
                                  double weight, const std::string& sex) {
  const smpl::Vertices v = shaped_vertices(model, betas);
  const LandmarkTable table = landmarks_for(model);
  const double floor = floor_height(v);
  const Eigen::Vector3d lo = v.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = v.colwise().maxCoeff().transpose();
  const Eigen::Vector3d shift(-(lo.x() + hi.x()) / 2.0, -floor, -(lo.z() + hi.z()) / 2.0);
  SimulatedPerson p;
  p.weight = weight;
  p.sex = sex;
  for (const auto& kv : table) p.landmarks[kv.first] = landmark_point(v, kv.second) + shift;
  return p;
}

std::map<std::string, double> true_measurements(const SimulatedPerson& person,
                                                const Protocol& protocol) {
  std::map<std::string, double> truth;
  for (const ProtocolStep& s : protocol.steps) {
    if (s.kind == StepKind::Height)
      truth[s.measurement] = landmark(person, s.landmarks[0]).y();
    else if (s.kind == StepKind::Distance)
      truth[s.measurement] =
          (landmark(person, s.landmarks[0]) - landmark(person, s.landmarks[1])).norm();
    else if (s.kind == StepKind::TypedNumber && s.measurement == "weight")
      truth[s.measurement] = person.weight;
  }
  return truth;
}

SimulatedSession simulate_session(const Protocol& protocol, const SimulatedPerson& person,
                                  const SimulatorOptions& o) {
  for (const std::string* id :
       {&o.dropout_step, &o.third_take_step, &o.early_release_step, &o.redo_step})
    if (!id->empty() && protocol.find_step(*id) < 0)
      throw InvalidInputError("simulator: scripted step \"" + *id + "\" is not in the protocol");
  if (!(o.frame_rate >= 10.0))
    throw InvalidInputError("simulator: frame_rate must be at least 10 frames/s");

  SimulatedSession out;
  out.truth = true_measurements(person, protocol);
  const double hold = protocol.hold_seconds + kHoldMargin;
  const Eigen::Vector3d up(0.0, o.runtime_floor_offset, 0.0);
  std::vector<Action> actions;

  const auto pause = [&](std::vector<OperatorCommand> commands, double seconds) {
    Action a;
    a.commands = std::move(commands);
    a.pause = seconds;
    actions.push_back(std::move(a));
  };
  const auto typed_commands = [&] {
    std::vector<OperatorCommand> c;
    for (const ProtocolStep& s : protocol.steps) {
      if (s.kind == StepKind::TypedNumber && s.measurement == "weight")
        c.push_back({"weight", Json(person.weight)});
      if (s.kind == StepKind::TypedChoice && s.measurement == "sex")
        c.push_back({"sex", Json(person.sex)});
    }
    return c;
  };
  if (o.role == "operator") {
    pause({{"start", Json()}}, 0.5);
  } else {
    pause({}, 0.5);
  }
  // Floor calibration: one tip on each target, alternating hands.
  for (size_t i = 0; i < protocol.floor.targets.size(); ++i) {
    Action a;
    a.press = true;
    a.hand = i % 2 == 0 ? Tip::Right : Tip::Left;
    a.hold = hold;
    const Eigen::Vector2d& t = protocol.floor.targets[i];
    a.target[a.hand == Tip::Left ? 0 : 1] = Eigen::Vector3d(t.x(), 0.0, t.y());
    a.look = Eigen::Vector3d(t.x(), 0.0, t.y());
    actions.push_back(a);
    ++out.accepted_samples;
    if (i == 1 && o.role == "operator" && o.typed_in_log) pause(typed_commands(), 0.3);
  }
  // Steps.
  for (const ProtocolStep& s : protocol.steps) {
    if (s.kind == StepKind::TypedNumber || s.kind == StepKind::TypedChoice) {
      if (o.role != "operator" && o.typed_in_log) {
        std::vector<OperatorCommand> c;
        if (s.measurement == "weight")
          c.push_back({"weight", Json(person.weight)});
        else if (s.measurement == "sex")
          c.push_back({"sex", Json(person.sex)});
        pause(c, 0.4);
      }
      continue;
    }
    Action base;
    base.press = true;
    base.hand = s.tips[0];
    base.hold = hold;
    for (size_t k = 0; k < s.tips.size(); ++k)
      base.target[s.tips[k] == Tip::Left ? 0 : 1] = landmark(person, s.landmarks[k]);
    if (s.id == o.dropout_step) {
      Action a = base;
      a.dropout_at = 0.4;
      a.dropout_hand = s.tips.back();
      actions.push_back(a);
      ++out.rejected_samples;
    }
    if (s.id == o.early_release_step) {
      Action a = base;
      a.hold = 0.4;
      actions.push_back(a);
      ++out.rejected_samples;
    }
    int takes = 2;
    if (s.id == o.redo_step && o.role == "operator") {
      actions.push_back(base);
      ++out.accepted_samples;
      pause({{"redo", Json()}}, 0.4);
    }
    for (int k = 0; k < takes; ++k) {
      Action a = base;
      if (k == 1 && s.id == o.third_take_step) {
        // 3 % too long: raise the tip (height) or move the second tip outwards (distance).
        const int moved = s.tips.back() == Tip::Left ? 0 : 1;
        if (s.kind == StepKind::Height) {
          *a.target[moved] += Eigen::Vector3d(0.0, 0.03 * a.target[moved]->y(), 0.0);
        } else {
          const Eigen::Vector3d& anchor = landmark(person, s.landmarks[0]);
          const Eigen::Vector3d d = *a.target[moved] - anchor;
          *a.target[moved] = anchor + 1.03 * d;
        }
        takes = 3;
      }
      actions.push_back(a);
      ++out.accepted_samples;
    }
  }
  pause({}, 0.5);

  // Render the actions into frames.
  Normal normal(o.seed);
  const double dt = 1.0 / o.frame_rate;
  const Eigen::Vector3d rest[2] = {Eigen::Vector3d(0.3, 0.95, 0.25),
                                   Eigen::Vector3d(-0.3, 0.95, 0.25)};
  const Eigen::Vector3d head_top = landmark(person, "head_top");
  const Eigen::Vector3d eye = head_top + Eigen::Vector3d(0.0, -0.11, 0.08);
  // OpenXR views look along -Z: yaw by 180 degrees (plus the target's azimuth), then pitch.
  const auto look_at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d f = (p - eye).normalized();
    return Eigen::Quaterniond(
               Eigen::AngleAxisd(std::atan2(f.x(), f.z()) + kPi, Eigen::Vector3d::UnitY())) *
           Eigen::Quaterniond(Eigen::AngleAxisd(std::asin(std::clamp(f.y(), -1.0, 1.0)),
                                                Eigen::Vector3d::UnitX()));
  };
  const Eigen::Vector3d ahead(0.0, 1.2, 1.5);
  Eigen::Quaterniond head_q = look_at(ahead);
  std::array<Eigen::Vector3d, 2> tip = {rest[0], rest[1]};
  std::array<Eigen::Quaterniond, 2> orient = {
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX())),
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX()))};
  out.log.header.role = o.role;
  out.log.header.frame_rate = o.frame_rate;
  out.log.header.interaction_profile = o.interaction_profile;
  out.log.header.source = "caliper simulator seed=" + std::to_string(o.seed);
  double t0 = 0.0;
  size_t frame_index = 0;
  for (const Action& a : actions) {
    const double duration = a.press ? kMove + kSettle + a.hold + kRelease : a.pause;
    std::array<Eigen::Vector3d, 2> from = tip, to = tip;
    std::array<Eigen::Quaterniond, 2> q_from = orient, q_to = orient;
    const Eigen::Quaterniond head_from = head_q;
    const Eigen::Quaterniond head_to = a.press ? look_at(a.look ? *a.look : ahead) : head_q;
    if (a.press) {
      for (int h = 0; h < 2; ++h) {
        to[h] = a.target[h] ? *a.target[h] : rest[h];
        // A new, slightly different grip for every action (so the tip offset matters).
        const Eigen::Vector3d axis = Eigen::Vector3d(normal(), normal(), normal()).normalized();
        q_to[h] = Eigen::Quaterniond(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX())) *
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * normal(), axis));
      }
    }
    bool first = true;
    // Frames whose time falls in [t0, t0 + duration).
    while (static_cast<double>(frame_index) * dt < t0 + duration - 1e-9) {
      const double t = static_cast<double>(frame_index) * dt;
      const double local = t - t0;
      PoseFrame f;
      f.time = t;
      if (first) {
        f.commands = a.commands;
        first = false;
      }
      const double s = a.press ? smoothstep(local / kMove) : 1.0;
      const double hold_t = local - kMove - kSettle;
      const bool pressed = a.press && hold_t >= 0.0 && hold_t < a.hold;
      for (int h = 0; h < 2; ++h) {
        tip[h] = from[h] + s * (to[h] - from[h]);
        orient[h] = q_from[h].slerp(s, q_to[h]);
        Eigen::Vector3d noisy = tip[h];
        if (o.tip_noise > 0.0) noisy += o.tip_noise * Eigen::Vector3d(normal(), normal(), normal());
        DevicePose& d = f.device(h == 0 ? Device::Left : Device::Right);
        const Eigen::Vector3d& offset = h == 0 ? o.tip_offsets.left : o.tip_offsets.right;
        d.valid = true;
        d.orientation = orient[h];
        d.position = noisy + up - orient[h] * offset;
        const Tip hand = h == 0 ? Tip::Left : Tip::Right;
        d.trigger = pressed && hand == a.hand ? 1.0 : 0.0;
        if (a.dropout_at >= 0.0 && hand == a.dropout_hand && hold_t >= a.dropout_at &&
            hold_t < a.dropout_at + kDropout)
          d.valid = false;
      }
      DevicePose& head = f.device(Device::Head);
      head.valid = true;
      head.position = eye + up;
      head.orientation = head_from.slerp(s, head_to);
      if (a.press && local < kMove * 0.5) out.quiet_frames.push_back(frame_index);
      out.log.frames.push_back(std::move(f));
      ++frame_index;
    }
    for (int h = 0; h < 2; ++h) {
      tip[h] = to[h];
      orient[h] = q_to[h];
    }
    head_q = head_to;
    t0 += duration;
  }
  return out;
}

}  // namespace caliper
