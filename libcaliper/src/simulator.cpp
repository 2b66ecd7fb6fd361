// Session simulator: pose logs of a virtual person doing the measuring protocol.
#include "caliper/simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>

#include "caliper/body_ik.hpp"
#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "smoothstep.hpp"
#include "smpl/constants.hpp"
#include "smpl/evaluate.hpp"

namespace caliper {
namespace {

using smpl::kPi;

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
  /// Three draws in a fixed order: z, then y, then x. The order of a call's arguments is
  /// unspecified in C++ (GCC 12 evaluated Vector3d(n(), n(), n()) last argument first, clang
  /// first argument first, so the simulated logs differed between the two compilers); this is
  /// GCC's order, which the committed logs and expected results were made with.
  Eigen::Vector3d vector() {
    const double z = (*this)();
    const double y = (*this)();
    const double x = (*this)();
    return {x, y, z};
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

constexpr double kMove = 0.45;           ///< s, tips travel to the targets
constexpr double kSettle = 0.15;         ///< s, tips at the targets before the trigger
constexpr double kRelease = 0.30;        ///< s, after the trigger is released
constexpr double kHoldMargin = 0.15;     ///< s, people hold a bit longer than required
constexpr double kDropout = 0.15;        ///< s, tracking lost for this long
constexpr double kHang = 0.93;           ///< hanging wrist under the shoulder joint, in arm lengths
constexpr double kHandClearance = 0.02;  ///< m, hanging hand to the side of the body

using detail::smoothstep;

const Eigen::Vector3d& landmark(const SimulatedPerson& person, const std::string& name) {
  auto it = person.landmarks.find(name);
  if (it == person.landmarks.end())
    throw InvalidInputError("simulator: the person has no landmark \"" + name +
                            "\" that the protocol needs");
  return it->second;
}

/// One posture of the embodiment motions, in the body frame (standing at the origin facing +Z
/// before `yaw`): wrists relative to the own shoulder, hand rotations, crouch.
struct Posture {
  double move = 0.8;                     ///< s to get here from the previous posture
  double hold = 1.0;                     ///< s held (waving, if `wave`)
  std::array<Eigen::Vector3d, 2> wrist;  ///< left, right: offset from the shoulder joint
  std::array<Eigen::Quaterniond, 2> hand;
  double yaw = 0.0, drop = 0.0, forward = 0.0;
  bool wave = false;
};

Eigen::Quaterniond rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

/// The left hand hanging at rest, fingers down, palm in (the right one mirrored).
Eigen::Quaterniond hanging_left_hand() {
  return rot(-kPi / 2, Eigen::Vector3d::UnitZ());
}

/// The x (from the midline) at which the left wrist hangs at rest so that every vertex of the
/// hanging hand clears the trunk and thigh at its height by kHandClearance; 0 without a wrist.
/// `v` is the rest pose (arms out at shoulder height, so every vertex at the hanging hand's
/// height is the trunk's or a leg's), shifted as the person is.
double hang_wrist_x(const smpl::BodyModel& model, const smpl::Vertices& v,
                    const std::vector<Eigen::Vector3d>& j) {
  using namespace ik_joint;
  if (j.size() <= static_cast<size_t>(kLeftHand) || model.weights.rows() != v.rows()) return 0.0;
  const double reach =
      (j[kLeftElbow] - j[kLeftShoulder]).norm() + (j[kLeftWrist] - j[kLeftElbow]).norm();
  const double wrist_y = 0.5 * (j[kLeftShoulder].y() + j[kRightShoulder].y()) - kHang * reach;
  // the body's half-width in 1 cm slices from 40 cm under to 10 cm over the hanging wrist
  constexpr double kSlice = 0.01;
  constexpr long kSlices = 50;
  const double bottom = wrist_y - 0.40;
  std::vector<double> half(kSlices, 0.0);
  std::vector<bool> hand(static_cast<size_t>(v.rows()), false);
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    double best = -1.0;
    int owner = -1;
    for (smpl::SparseMatrix::InnerIterator it(model.weights, i); it; ++it) {
      if (it.value() > best) {
        best = it.value();
        owner = static_cast<int>(it.col());
      }
    }
    hand[static_cast<size_t>(i)] = owner == kLeftWrist || owner == kLeftHand;
    const auto s = static_cast<long>(std::floor((v(i, 1) - bottom) / kSlice));
    if (!hand[static_cast<size_t>(i)] && s >= 0 && s < kSlices)
      half[static_cast<size_t>(s)] = std::max(half[static_cast<size_t>(s)], std::abs(v(i, 0)));
  }
  const Eigen::Quaterniond q = hanging_left_hand();
  double x = 0.0;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    if (!hand[static_cast<size_t>(i)]) continue;
    const Eigen::Vector3d o = q * (v.row(i).transpose() - j[kLeftWrist]);
    const auto s = static_cast<long>(std::floor((wrist_y + o.y() - bottom) / kSlice));
    for (long n = std::max(0L, s - 1); n <= std::min(s + 1, kSlices - 1); ++n)
      x = std::max(x, half[static_cast<size_t>(n)] + kHandClearance - o.x());
  }
  return x;
}

/// wave, reach up, cross arms, squat, turn (docs/vr.md).
std::vector<Posture> motion_script(const SimulatedPerson& person) {
  using namespace ik_joint;
  const std::vector<Eigen::Vector3d>& j = person.joints;
  const double reach =
      (j[kLeftElbow] - j[kLeftShoulder]).norm() + (j[kLeftWrist] - j[kLeftElbow]).norm();
  const double span = j[kLeftShoulder].x() - j[kRightShoulder].x();
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  // Hanging at rest: the wrists 6 cm outside the shoulder joints, or farther where the body is
  // wider there (a fuller body's hands hang beside its hips and thighs).
  const double out = std::max(0.06, person.hang_wrist_x - j[kLeftShoulder].x());
  Posture rest;
  rest.wrist = {Eigen::Vector3d(out, -kHang * reach, 0.03),
                Eigen::Vector3d(-out, -kHang * reach, 0.03)};
  rest.hand = {hanging_left_hand(), rot(kPi / 2, Z)};  // fingers down, palms in
  std::vector<Posture> s;
  s.push_back(rest);
  Posture wave = rest;
  wave.wrist[1] = Eigen::Vector3d(-0.2, 0.28, 0.12);
  wave.hand[1] = rot(kPi / 2, Y) * rot(-kPi / 2, Z);  // fingers up, palm forward
  wave.hold = 2.5;  // three waves at 1.2 Hz: the hand is back in the middle at the end
  wave.wave = true;
  s.push_back(wave);
  s.push_back(rest);
  Posture up = rest;
  up.wrist = {Eigen::Vector3d(0.04, 0.9 * reach, 0.06), Eigen::Vector3d(-0.04, 0.9 * reach, 0.06)};
  up.hand = {rot(kPi, Y) * rot(kPi / 2, Z), rot(kPi, Y) * rot(-kPi / 2, Z)};  // palms in
  up.move = 1.0;
  s.push_back(up);
  Posture cross = rest;
  cross.wrist = {Eigen::Vector3d(-span + 0.05, -0.18, 0.24),
                 Eigen::Vector3d(span - 0.05, -0.24, 0.27)};
  cross.hand = {rot(kPi / 2, X) * rot(kPi, Y), rot(kPi / 2, X) * rot(kPi, Y)};  // palms to body
  cross.move = 1.0;
  s.push_back(cross);
  s.push_back(rest);
  Posture squat = rest;
  squat.drop = 0.35;
  squat.forward = 0.12;
  squat.wrist = {Eigen::Vector3d(0.02, -0.1, 0.3), Eigen::Vector3d(-0.02, -0.1, 0.3)};
  squat.hand = {rot(-kPi / 2, Y), rot(kPi / 2, Y)};  // fingers forward, palms down
  squat.move = 1.2;
  s.push_back(squat);
  Posture stand = rest;
  stand.move = 1.2;
  s.push_back(stand);
  Posture turn = rest;
  turn.yaw = kPi / 2;
  turn.move = 2.0;
  s.push_back(turn);
  return s;
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
  const smpl::Body b = smpl::shape(model, betas);
  for (Eigen::Index k = 0; k < b.joints.rows(); ++k)
    p.joints.push_back(b.joints.row(k).transpose() + shift);
  smpl::Vertices shifted = v;
  shifted.rowwise() += shift.transpose();
  p.hang_wrist_x = hang_wrist_x(model, shifted, p.joints);
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

namespace {

/// The commands that type the person's weight and sex, for the protocol's typed steps.
std::vector<OperatorCommand> typed_commands(const Protocol& protocol,
                                            const SimulatedPerson& person) {
  std::vector<OperatorCommand> c;
  for (const ProtocolStep& s : protocol.steps) {
    if (s.kind == StepKind::TypedNumber && s.measurement == "weight")
      c.push_back({"weight", Json(person.weight)});
    if (s.kind == StepKind::TypedChoice && s.measurement == "sex")
      c.push_back({"sex", Json(person.sex)});
  }
  return c;
}

/// Appends the takes of one measured step: the scripted dropout, early release and redo, then
/// two takes (three if the second is scripted 3 % too long); counts the samples in `out`.
void script_step(const ProtocolStep& s, const SimulatedPerson& person, const SimulatorOptions& o,
                 double hold, std::vector<Action>& actions, SimulatedSession& out) {
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
    Action redo;
    redo.commands = {{"redo", Json()}};
    redo.pause = 0.4;
    actions.push_back(std::move(redo));
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

/// What the person (and operator) do, in order: start, the floor calibration (one tip on each
/// target, alternating hands), every step's takes and typed values, a pause at the end; counts
/// the samples the app should accept and reject in `out`.
std::vector<Action> script_actions(const Protocol& protocol, const SimulatedPerson& person,
                                   const SimulatorOptions& o, SimulatedSession& out) {
  const double hold = protocol.hold_seconds + kHoldMargin;
  std::vector<Action> actions;
  const auto pause = [&](std::vector<OperatorCommand> commands, double seconds) {
    Action a;
    a.commands = std::move(commands);
    a.pause = seconds;
    actions.push_back(std::move(a));
  };
  if (o.role == "operator") {
    pause({{"start", Json()}}, 0.5);
  } else {
    pause({}, 0.5);
  }
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
    if (i == 1 && o.role == "operator" && o.typed_in_log)
      pause(typed_commands(protocol, person), 0.3);
  }
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
    script_step(s, person, o, hold, actions, out);
  }
  pause({}, 0.5);
  return actions;
}

/// Where the recording stands between its parts (actions, motions, end button).
struct Playback {
  double dt = 0.0;            ///< s per frame
  Eigen::Vector3d up;         ///< the runtime floor offset, added to every device position
  Eigen::Vector3d head_top;   ///< the person's head_top landmark
  Eigen::Vector3d eye;        ///< the headset's position (without `up`) while measuring
  double t0 = 0.0;            ///< s, start of the next part
  size_t frame_index = 0;     ///< the next frame
  Eigen::Quaterniond head_q;  ///< the headset's orientation at the end of the last part
};

/// The headset's orientation at `eye` looking at `p`. OpenXR views look along -Z: yaw by 180
/// degrees (plus the target's azimuth), then pitch.
Eigen::Quaterniond look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& p) {
  const Eigen::Vector3d f = (p - eye).normalized();
  return Eigen::Quaterniond(
             Eigen::AngleAxisd(std::atan2(f.x(), f.z()) + kPi, Eigen::Vector3d::UnitY())) *
         Eigen::Quaterniond(
             Eigen::AngleAxisd(std::asin(std::clamp(f.y(), -1.0, 1.0)), Eigen::Vector3d::UnitX()));
}

/// Renders the actions into frames: tips move (smoothstep) to their targets with a new grip
/// each, settle, hold the trigger, release; the head looks at the target.
void play_actions(const std::vector<Action>& actions, const SimulatorOptions& o, Playback& pb,
                  SimulatedSession& out) {
  Normal normal(o.seed);
  const Eigen::Vector3d rest[2] = {Eigen::Vector3d(0.3, 0.95, 0.25),
                                   Eigen::Vector3d(-0.3, 0.95, 0.25)};
  const Eigen::Vector3d ahead(0.0, 1.2, 1.5);
  pb.head_q = look_at(pb.eye, ahead);
  std::array<Eigen::Vector3d, 2> tip = {rest[0], rest[1]};
  std::array<Eigen::Quaterniond, 2> orient = {
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX())),
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX()))};
  for (const Action& a : actions) {
    const double duration = a.press ? kMove + kSettle + a.hold + kRelease : a.pause;
    std::array<Eigen::Vector3d, 2> from = tip, to = tip;
    std::array<Eigen::Quaterniond, 2> q_from = orient, q_to = orient;
    const Eigen::Quaterniond head_from = pb.head_q;
    const Eigen::Quaterniond head_to =
        a.press ? look_at(pb.eye, a.look ? *a.look : ahead) : pb.head_q;
    if (a.press) {
      for (int h = 0; h < 2; ++h) {
        to[h] = a.target[h] ? *a.target[h] : rest[h];
        // A new, slightly different grip for every action (so the tip offset matters).
        const Eigen::Vector3d axis = normal.vector().normalized();
        q_to[h] = Eigen::Quaterniond(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX())) *
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * normal(), axis));
      }
    }
    bool first = true;
    // Frames whose time falls in [t0, t0 + duration).
    while (static_cast<double>(pb.frame_index) * pb.dt < pb.t0 + duration - 1e-9) {
      const double t = static_cast<double>(pb.frame_index) * pb.dt;
      const double local = t - pb.t0;
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
        if (o.tip_noise > 0.0) noisy += o.tip_noise * normal.vector();
        DevicePose& d = f.device(h == 0 ? Device::Left : Device::Right);
        const Eigen::Vector3d& offset = h == 0 ? o.tip_offsets.left : o.tip_offsets.right;
        d.valid = true;
        d.orientation = orient[h];
        d.position = noisy + pb.up - orient[h] * offset;
        const Tip hand = h == 0 ? Tip::Left : Tip::Right;
        d.trigger = pressed && hand == a.hand ? 1.0 : 0.0;
        if (a.dropout_at >= 0.0 && hand == a.dropout_hand && hold_t >= a.dropout_at &&
            hold_t < a.dropout_at + kDropout)
          d.valid = false;
      }
      DevicePose& head = f.device(Device::Head);
      head.valid = true;
      head.position = pb.eye + pb.up;
      head.orientation = head_from.slerp(s, head_to);
      if (a.press && local < kMove * 0.5) out.quiet_frames.push_back(pb.frame_index);
      out.log.frames.push_back(std::move(f));
      ++pb.frame_index;
    }
    for (int h = 0; h < 2; ++h) {
      tip[h] = to[h];
      orient[h] = q_to[h];
    }
    pb.head_q = head_to;
    pb.t0 += duration;
  }
}

/// A frame at time t with the devices where the last frame of `log` has them, triggers and menu
/// buttons released.
PoseFrame still_frame(const PoseLog& log, double t) {
  PoseFrame f;
  f.time = t;
  f.device(Device::Head) = log.frames.back().device(Device::Head);
  f.device(Device::Left) = log.frames.back().device(Device::Left);
  f.device(Device::Right) = log.frames.back().device(Device::Right);
  for (Device d : {Device::Left, Device::Right}) {
    f.device(d).trigger = 0.0;
    f.device(d).menu = false;
  }
  return f;
}

/// What the embodiment motions start from: the grip of the person's hands on the controllers,
/// the wrists and hands where the controllers are at the end of the measuring, the shoulders.
struct MotionStart {
  HandGrip grip;
  std::array<Eigen::Vector3d, 2> wrist0;
  std::array<Eigen::Quaterniond, 2> hand0;
  std::array<Eigen::Vector3d, 2> shoulder;
};

MotionStart motion_start(const SimulatedPerson& person, const PoseFrame& last,
                         const Eigen::Vector3d& up) {
  using namespace ik_joint;
  MotionStart m;
  // The person's hands hold the controllers as their size dictates (HandGrip), the truth the
  // app's IK estimates from the avatar's hands.
  if (person.landmarks.count("left_fingertip") && person.landmarks.count("right_fingertip")) {
    const double hand =
        0.5 * ((person.landmarks.at("left_fingertip") - person.joints[kLeftWrist]).norm() +
               (person.landmarks.at("right_fingertip") - person.joints[kRightWrist]).norm());
    if (HandGrip::is_hand_length(hand)) m.grip = HandGrip::for_hand_length(hand);
  }
  for (int h = 0; h < 2; ++h) {
    const DevicePose& d = last.device(h == 0 ? Device::Left : Device::Right);
    m.wrist0[h] = d.position + d.orientation * m.grip.wrist_in_grip - up;
    m.hand0[h] = HandGrip::hand_from_grip(d.orientation, h == 0);
  }
  m.shoulder = {person.joints[kLeftShoulder], person.joints[kRightShoulder]};
  return m;
}

/// Hand h's wrist position and rotation in the world at posture p (waving: wave_t s into it).
std::pair<Eigen::Vector3d, Eigen::Quaterniond> posture_hand(const Posture& p, const MotionStart& m,
                                                            int h, double wave_t) {
  const Eigen::Quaterniond body = rot(p.yaw, Eigen::Vector3d::UnitY());
  const Eigen::Vector3d lowered(0.0, -p.drop, p.forward);
  Eigen::Vector3d w = m.shoulder[h] + lowered + p.wrist[h];
  if (p.wave && h == 1) w.x() += 0.1 * std::sin(2.0 * kPi * 1.2 * wave_t);
  return std::make_pair(Eigen::Vector3d(body * w), Eigen::Quaterniond(body * p.hand[h]));
}

/// One frame of the embodiment motions, `local` s into the move from `prev` (or, for the first
/// posture, from where the measuring left the controllers) to `p`.
PoseFrame motion_frame(const PoseLog& log, double t, double local, const Posture& p,
                       const Posture& prev, bool first, const MotionStart& m, const Playback& pb) {
  const double e = smoothstep(local / p.move);
  const double wave_t = std::max(0.0, local - p.move);
  PoseFrame f = still_frame(log, t);
  const double yaw = first ? p.yaw : prev.yaw + e * (p.yaw - prev.yaw);
  const double drop = first ? e * p.drop : prev.drop + e * (p.drop - prev.drop);
  const double fwd = first ? e * p.forward : prev.forward + e * (p.forward - prev.forward);
  const Eigen::Quaterniond body = rot(yaw, Eigen::Vector3d::UnitY());
  DevicePose& head = f.device(Device::Head);
  head.position =
      body * (eyes_below_head_top(pb.head_top) + Eigen::Vector3d(0.0, -drop, fwd)) + pb.up;
  head.orientation = pb.head_q.slerp(first ? e : 1.0, rot(yaw + kPi, Eigen::Vector3d::UnitY()));
  for (int h = 0; h < 2; ++h) {
    const auto to = posture_hand(p, m, h, wave_t);
    Eigen::Vector3d w;
    Eigen::Quaterniond q;
    if (first) {
      // From the last measuring posture (a hand may be on the other shoulder) round the
      // front of the body, not through it.
      w = m.wrist0[h] + e * (to.first - m.wrist0[h]) +
          0.3 * std::sin(kPi * e) * Eigen::Vector3d(0.0, 0.0, 1.0);
      q = m.hand0[h].slerp(e, to.second);
    } else {
      // Intermediate postures turn and crouch with the body.
      Posture mid = p;
      mid.yaw = yaw;
      mid.drop = drop;
      mid.forward = fwd;
      // Hands travel in an arc in front of the body (raising the arms from the sides to
      // above the head does not pass through the shoulder).
      for (int k = 0; k < 2; ++k)
        mid.wrist[k] = prev.wrist[k] + e * (p.wrist[k] - prev.wrist[k]) +
                       0.5 * (p.wrist[k] - prev.wrist[k]).norm() * std::sin(kPi * e) *
                           Eigen::Vector3d(0.0, 0.0, 1.0);
      w = posture_hand(mid, m, h, wave_t).first;
      q = Eigen::Quaterniond(rot(yaw, Eigen::Vector3d::UnitY()) * prev.hand[h].slerp(e, p.hand[h]));
    }
    DevicePose& d = f.device(h == 0 ? Device::Left : Device::Right);
    d.valid = true;
    d.orientation = HandGrip::grip_from_hand(q, h == 0);
    d.position = w - d.orientation * m.grip.wrist_in_grip + pb.up;
  }
  return f;
}

/// Embodiment motions: headset and controllers move as the body would (motion_script).
void play_motions(const SimulatedPerson& person, Playback& pb, SimulatedSession& out) {
  if (person.joints.size() != static_cast<size_t>(ik_joint::kCount))
    throw InvalidInputError("simulator: the motions need a body model with SMPL's 24 joints");
  const MotionStart m = motion_start(person, out.log.frames.back(), pb.up);
  const std::vector<Posture> script = motion_script(person);
  out.motion_begin = pb.frame_index;
  double local0 = pb.t0;
  Posture prev;
  bool first = true;
  for (const Posture& p : script) {
    const double duration = p.move + p.hold;
    while (static_cast<double>(pb.frame_index) * pb.dt < local0 + duration - 1e-9) {
      const double t = static_cast<double>(pb.frame_index) * pb.dt;
      out.log.frames.push_back(motion_frame(out.log, t, t - local0, p, prev, first, m, pb));
      ++pb.frame_index;
    }
    pb.head_q = rot(p.yaw + kPi, Eigen::Vector3d::UnitY());
    if (first) out.motion_begin = static_cast<size_t>(std::ceil((local0 + p.move) / pb.dt - 1e-9));
    prev = p;
    first = false;
    local0 += duration;
  }
  out.motion_end = pb.frame_index;
  pb.t0 = local0;
}

}  // namespace

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
  const std::vector<Action> actions = script_actions(protocol, person, o, out);

  Playback pb;
  pb.dt = 1.0 / o.frame_rate;
  pb.up = Eigen::Vector3d(0.0, o.runtime_floor_offset, 0.0);
  pb.head_top = landmark(person, "head_top");
  pb.eye = pb.head_top + Eigen::Vector3d(0.0, -0.11, 0.08);
  out.log.header.role = o.role;
  out.log.header.frame_rate = o.frame_rate;
  out.log.header.interaction_profile = o.interaction_profile;
  out.log.header.source = "caliper simulator seed=" + std::to_string(o.seed);
  play_actions(actions, o, pb, out);
  if (o.motions) play_motions(person, pb, out);
  if (o.end_button) {
    // The right menu button, pressed for 0.3 s, then 0.5 s more.
    const double end = pb.t0 + 0.8;
    while (static_cast<double>(pb.frame_index) * pb.dt < end - 1e-9) {
      const double t = static_cast<double>(pb.frame_index) * pb.dt;
      PoseFrame f = still_frame(out.log, t);
      f.device(Device::Right).menu = t - pb.t0 < 0.3;
      out.log.frames.push_back(std::move(f));
      ++pb.frame_index;
    }
  }
  return out;
}

}  // namespace caliper
