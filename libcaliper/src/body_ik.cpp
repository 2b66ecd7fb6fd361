// Embodiment IK (see body_ik.hpp).
//
// Sections: helpers | hand grip | two-bone IK and frames | heading | rig | limits | body solver.
#include "caliper/body_ik.hpp"

#include <algorithm>
#include <cmath>

#include "smoothstep.hpp"
#include "smpl/constants.hpp"
#include "smpl/evaluate.hpp"

namespace caliper {
namespace {

using namespace ik_joint;

using smpl::kPi;
/// Below this length a direction is taken as undefined (m, or unit-vector components).
constexpr double kTiny = 1e-9;
/// After one foot stepped, the other steps too when it is more than this share of the step
/// thresholds away from its place (people finish a stance with both feet).
constexpr double kFollowUp = 0.15;

double wrap_angle(double a) {
  while (a > kPi) a -= 2.0 * kPi;
  while (a < -kPi) a += 2.0 * kPi;
  return a;
}

Eigen::Quaterniond yaw_rotation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
}

double rotation_angle(const Eigen::Quaterniond& q) {
  return Eigen::AngleAxisd(q.normalized()).angle();
}

/// `q` with its angle limited to `max_angle` (same axis).
Eigen::Quaterniond clamp_rotation(const Eigen::Quaterniond& q, double max_angle) {
  const Eigen::AngleAxisd aa(q.normalized());
  if (aa.angle() <= max_angle) return q.normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(max_angle, aa.axis()));
}

/// The fraction `t` of rotation `q` (same axis).
Eigen::Quaterniond fraction(const Eigen::Quaterniond& q, double t) {
  return Eigen::Quaterniond::Identity().slerp(t, q);
}

using detail::smoothstep;

/// Grip frame axes of the avatar's rest hand frame (columns: images of world x, y, z).
Eigen::Matrix3d grip_axes(bool left) {
  Eigen::Matrix3d m;
  if (left)
    m << 0, -1, 0,  //
        0, 0, 1,    //
        -1, 0, 0;
  else
    m << 0, 1, 0,  //
        0, 0, 1,   //
        1, 0, 0;
  return m;
}

/// Rest hinge axes: elbows fold the forearm forwards (+Z) from the T-pose, knees fold the shin
/// backwards (-Z).
Eigen::Vector3d elbow_hinge(bool left) {
  return left ? Eigen::Vector3d(0, -1, 0) : Eigen::Vector3d(0, 1, 0);
}
const Eigen::Vector3d kKneeHinge(1, 0, 0);

/// The joints of one limb, from the body outwards: shoulder, elbow, wrist, hand or hip, knee,
/// ankle, foot.
struct Limb {
  int root, mid, end, tip;
};
/// Arms and legs by side (0 = left, 1 = right).
constexpr Limb kArms[2] = {{kLeftShoulder, kLeftElbow, kLeftWrist, kLeftHand},
                           {kRightShoulder, kRightElbow, kRightWrist, kRightHand}};
constexpr Limb kLegs[2] = {{kLeftHip, kLeftKnee, kLeftAnkle, kLeftFoot},
                           {kRightHip, kRightKnee, kRightAnkle, kRightFoot}};

/// Smallest distance between the ends of a two-bone chain bent by at most `max_bend`.
double min_reach(double a, double b, double max_bend) {
  return std::sqrt(std::max(0.0, a * a + b * b + 2.0 * a * b * std::cos(max_bend)));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Hand grip

HandGrip HandGrip::for_hand_length(double hand_length) {
  if (!is_hand_length(hand_length))
    throw std::invalid_argument("hand length " + std::to_string(hand_length) +
                                " m: expected 0.05 to 0.4 m (wrist to middle fingertip)");
  HandGrip g;
  g.wrist_in_grip = Eigen::Vector3d(0.0, 0.0, kWristToGripPerHandLength * hand_length);
  return g;
}

Eigen::Quaterniond HandGrip::hand_from_grip(const Eigen::Quaterniond& grip, bool left) {
  return (grip * Eigen::Quaterniond(grip_axes(left))).normalized();
}

Eigen::Quaterniond HandGrip::grip_from_hand(const Eigen::Quaterniond& hand, bool left) {
  return (hand * Eigen::Quaterniond(grip_axes(left)).conjugate()).normalized();
}

// ---------------------------------------------------------------------------------------------
// Two-bone IK and frames

TwoBoneSolution solve_two_bone(const Eigen::Vector3d& root, double upper, double lower,
                               const Eigen::Vector3d& target, const Eigen::Vector3d& pole) {
  if (!(upper > 0.0) || !(lower > 0.0))
    throw std::invalid_argument("solve_two_bone: bone lengths must be positive");
  TwoBoneSolution s;
  const Eigen::Vector3d to = target - root;
  const double d = to.norm();
  Eigen::Vector3d w = d > kTiny ? Eigen::Vector3d(to / d) : Eigen::Vector3d(-pole.normalized());
  if (!w.allFinite() || w.norm() < 0.5) w = -Eigen::Vector3d::UnitY();
  const double lo = std::abs(upper - lower), hi = upper + lower;
  s.reachable = d <= hi + kTiny && d >= lo - kTiny;
  const double dc = std::clamp(d, lo, hi);
  Eigen::Vector3d p = pole - pole.dot(w) * w;
  if (p.norm() < kTiny) p = w.unitOrthogonal();
  p.normalize();
  const double x = dc > kTiny ? (upper * upper - lower * lower + dc * dc) / (2.0 * dc) : upper;
  const double h = std::sqrt(std::max(0.0, upper * upper - x * x));
  s.middle = root + x * w + h * p;
  s.end = root + dc * w;
  const Eigen::Vector3d u = (s.middle - root).normalized();
  const Eigen::Vector3d f = (s.end - s.middle).normalized();
  s.bend = std::acos(std::clamp(u.dot(f), -1.0, 1.0));
  s.hinge = p.cross(w).normalized();
  return s;
}

Eigen::Quaterniond align_two_directions(const Eigen::Vector3d& a_rest,
                                        const Eigen::Vector3d& b_rest, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b) {
  const auto frame = [](const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
    Eigen::Matrix3d m;
    const Eigen::Vector3d e1 = x.normalized();
    Eigen::Vector3d e2 = y - y.dot(e1) * e1;
    e2 =
        e2.norm() > kTiny ? Eigen::Vector3d(e2.normalized()) : Eigen::Vector3d(e1.unitOrthogonal());
    m.col(0) = e1;
    m.col(1) = e2;
    m.col(2) = e1.cross(e2);
    return m;
  };
  const Eigen::Matrix3d r = frame(a, b) * frame(a_rest, b_rest).transpose();
  return Eigen::Quaterniond(r).normalized();
}

// ---------------------------------------------------------------------------------------------
// Heading

double headset_yaw(const Eigen::Quaterniond& headset) {
  const Eigen::Vector3d f = headset * Eigen::Vector3d(0.0, 0.0, -1.0);
  const Eigen::Vector3d up = headset * Eigen::Vector3d(0.0, 1.0, 0.0);
  const double down = std::max(0.0, -f.y());
  const double x = f.x() + down * up.x(), z = f.z() + down * up.z();
  if (std::abs(x) + std::abs(z) < kTiny) return 0.0;
  return std::atan2(x, z);
}

std::optional<double> hands_yaw(const Eigen::Vector3d& left_wrist,
                                const Eigen::Vector3d& right_wrist, double min_apart) {
  const Eigen::Vector3d v = left_wrist - right_wrist;
  if (std::hypot(v.x(), v.z()) < min_apart) return std::nullopt;
  // Left = body * +X = (cos y, 0, -sin y); forward = (sin y, 0, cos y) = (-v.z, v.x).
  return std::atan2(-v.z(), v.x());
}

double follow_heading(double body_yaw, double head_yaw, double max_neck_yaw) {
  const double delta = wrap_angle(head_yaw - body_yaw);
  if (std::abs(delta) <= max_neck_yaw) return body_yaw;
  return wrap_angle(body_yaw + delta - std::copysign(max_neck_yaw, delta));
}

// ---------------------------------------------------------------------------------------------
// Rig

IkRig make_ik_rig(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
                  const Eigen::Vector3d& eyes) {
  if (model.num_joints() != kCount || model.parents != smpl::smpl_parents())
    throw IkError("the body model has " + std::to_string(model.num_joints()) +
                  " joints; the embodiment IK needs SMPL's 24 joints in SMPL's order");
  const smpl::Body b = smpl::shape(model, betas);
  const Eigen::RowVector3d lo = b.vertices.colwise().minCoeff(),
                           hi = b.vertices.colwise().maxCoeff();
  IkRig rig;
  rig.standing_shift = Eigen::Vector3d(-(lo.x() + hi.x()) / 2.0, -lo.y(), -(lo.z() + hi.z()) / 2.0);
  rig.parents = model.parents;
  for (int k = 0; k < kCount; ++k)
    rig.rest.push_back(b.joints.row(k).transpose() + rig.standing_shift);
  rig.eyes = eyes;
  // A standing T-pose skeleton (the solver's hinge axes and poles assume it): spine upwards,
  // knees between hips and ankles, arms outwards, the subject's left at +X.
  const std::vector<Eigen::Vector3d>& r = rig.rest;
  const bool upright = r[kPelvis].y() < r[kSpine3].y() && r[kSpine3].y() < r[kNeck].y() &&
                       r[kNeck].y() < r[kHead].y();
  const bool legs = r[kLeftAnkle].y() < r[kLeftKnee].y() && r[kLeftKnee].y() < r[kLeftHip].y() &&
                    r[kRightAnkle].y() < r[kRightKnee].y() && r[kRightKnee].y() < r[kRightHip].y();
  const bool arms =
      r[kLeftShoulder].x() < r[kLeftElbow].x() && r[kLeftElbow].x() < r[kLeftWrist].x() &&
      r[kRightShoulder].x() > r[kRightElbow].x() && r[kRightElbow].x() > r[kRightWrist].x();
  if (!upright || !legs || !arms)
    throw IkError(
        "the body model's rest skeleton is not a standing T-pose (spine up, knees between hips and "
        "ankles, arms out to the sides with the left at +X); the embodiment IK needs one");
  // The hands: from each wrist out to the farthest vertex along the arm (the middle fingertip of
  // a T-pose), the measure the grip is scaled by.
  const double left_tip = hi.x() + rig.standing_shift.x(),
               right_tip = lo.x() + rig.standing_shift.x();
  const double hand = 0.5 * ((left_tip - r[kLeftWrist].x()) + (r[kRightWrist].x() - right_tip));
  if (HandGrip::is_hand_length(hand)) rig.hand_length = hand;
  return rig;
}

// ---------------------------------------------------------------------------------------------
// Pose and limits

Eigen::VectorXd IkPose::axis_angle() const {
  Eigen::VectorXd v(3 * static_cast<Eigen::Index>(local.size()));
  for (size_t k = 0; k < local.size(); ++k) {
    const Eigen::AngleAxisd aa(local[k].normalized());
    v.segment<3>(3 * static_cast<Eigen::Index>(k)) = aa.angle() * aa.axis();
  }
  return v;
}

std::vector<LimitViolation> check_limits(const IkRig& rig, const IkPose& pose,
                                         const JointLimits& limits) {
  constexpr double kTol = 1e-6;
  std::vector<LimitViolation> out;
  const auto hinge = [&](int root, int middle, int end, const Eigen::Vector3d& rest_axis,
                         double max_bend, const char* name) {
    const Eigen::Vector3d u = pose.joints[middle] - pose.joints[root];
    const Eigen::Vector3d f = pose.joints[end] - pose.joints[middle];
    const double bend = std::acos(std::clamp(u.normalized().dot(f.normalized()), -1.0, 1.0));
    if (bend > max_bend + kTol)
      out.push_back({middle, std::string(name) + " bent " + std::to_string(bend) + " rad"});
    // Forwards only: the fold turns about the joint's own hinge (its rest axis carried along).
    const double sense = u.cross(f).dot(pose.global[root] * rest_axis);
    if (bend > 1e-3 && sense < -kTol * u.norm() * f.norm())
      out.push_back({middle, std::string(name) + " bends backwards"});
  };
  hinge(kLeftShoulder, kLeftElbow, kLeftWrist, elbow_hinge(true), limits.max_elbow_bend,
        "left elbow");
  hinge(kRightShoulder, kRightElbow, kRightWrist, elbow_hinge(false), limits.max_elbow_bend,
        "right elbow");
  hinge(kLeftHip, kLeftKnee, kLeftAnkle, kKneeHinge, limits.max_knee_bend, "left knee");
  hinge(kRightHip, kRightKnee, kRightAnkle, kKneeHinge, limits.max_knee_bend, "right knee");
  const auto angle = [&](int joint, double max_angle, const char* name) {
    const double a = rotation_angle(pose.local[joint]);
    if (a > max_angle + kTol)
      out.push_back({joint, std::string(name) + " turned " + std::to_string(a) + " rad"});
  };
  angle(kLeftWrist, limits.max_wrist, "left wrist");
  angle(kRightWrist, limits.max_wrist, "right wrist");
  angle(kHead, limits.max_head, "head");
  angle(kLeftAnkle, limits.max_ankle, "left ankle");
  angle(kRightAnkle, limits.max_ankle, "right ankle");
  for (int j : {kSpine1, kSpine2, kSpine3, kNeck}) angle(j, limits.max_spine_joint, "spine");
  (void)rig;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Body solver

BodyIk::BodyIk(IkRig rig, BodyIkOptions options)
    : rig_(std::move(rig)), options_(std::move(options)) {
  if (static_cast<int>(rig_.rest.size()) != kCount ||
      static_cast<int>(rig_.parents.size()) != kCount)
    throw IkError("the IK rig needs SMPL's 24 joints");
  if (options_.grip_from_hand && rig_.hand_length > 0.0)
    options_.grip = HandGrip::for_hand_length(rig_.hand_length);
  pose_.local.assign(kCount, Eigen::Quaterniond::Identity());
  pose_.global.assign(kCount, Eigen::Quaterniond::Identity());
  pose_.joints = rig_.rest;
}

double BodyIk::arm_length(int side) const {
  const Limb& arm = kArms[side == 0 ? 0 : 1];
  return (rig_.rest[arm.mid] - rig_.rest[arm.root]).norm() +
         (rig_.rest[arm.end] - rig_.rest[arm.mid]).norm();
}

void BodyIk::place(int j) {
  const int p = rig_.parents[j];
  pose_.joints[j] = pose_.joints[p] + pose_.global[p] * (rig_.rest[j] - rig_.rest[p]);
}

void BodyIk::solve_arm(int side, const IkInput& in) {
  const bool left = side == 0;
  const auto [sh, el, wr, hand] = kArms[left ? 0 : 1];
  const std::vector<Eigen::Vector3d>& r = rig_.rest;
  const Eigen::Quaterniond body = yaw_rotation(body_yaw_);
  const Eigen::Vector3d out = body * Eigen::Vector3d(left ? 1.0 : -1.0, 0.0, 0.0);
  const Eigen::Vector3d back = body * Eigen::Vector3d(0.0, 0.0, -1.0);
  const Eigen::Vector3d& S = pose_.joints[sh];
  const double a = (r[el] - r[sh]).norm(), b = (r[wr] - r[el]).norm();
  Eigen::Vector3d target;
  Eigen::Quaterniond hand_rotation;
  const std::optional<RigidPose>& grip = in.grips[static_cast<size_t>(side)];
  pose_.hand_tracked[static_cast<size_t>(side)] = grip.has_value();
  if (grip) {
    target = grip->position + grip->orientation * options_.grip.wrist_in_grip;
    hand_rotation = HandGrip::hand_from_grip(grip->orientation, left);
  } else {
    // Untracked: the arm hangs at the side, the hand along the forearm.
    target = S + 0.97 * (a + b) * Eigen::Vector3d(0.0, -1.0, 0.0) + 0.08 * out;
    hand_rotation = Eigen::Quaterniond::FromTwoVectors(r[wr] - r[el], target - S);
  }
  pose_.wrist_target[static_cast<size_t>(side)] = target;
  // Elbow down and out (and a little back), pulled towards where the controller's handle points
  // (the forearm continues behind the grip, along its +Z).
  Eigen::Vector3d pole = (Eigen::Vector3d(0.0, -1.0, 0.0) + 0.6 * out + 0.3 * back).normalized();
  if (grip) {
    const Eigen::Vector3d hint = target + grip->orientation * Eigen::Vector3d(0.0, 0.0, b) - S;
    if (hint.norm() > kTiny) pole += 0.8 * hint.normalized();
  }
  // Keep the fold within the elbow's range: a target closer than that is pushed out.
  const double dmin = min_reach(a, b, options_.limits.max_elbow_bend);
  Eigen::Vector3d goal = target;
  if ((goal - S).norm() < dmin) {
    const Eigen::Vector3d d = goal - S;
    goal = S + dmin * (d.norm() > kTiny ? Eigen::Vector3d(d.normalized()) : -back);
  }
  // The elbow's swing about the shoulder-wrist line is rate-limited, so that a pole passing
  // close to that line does not flip the elbow from one frame to the next.
  const Eigen::Vector3d line =
      (goal - S).norm() > kTiny ? Eigen::Vector3d((goal - S).normalized()) : Eigen::Vector3d(-back);
  Eigen::Vector3d swing = pole - pole.dot(line) * line;
  swing = swing.norm() > kTiny ? Eigen::Vector3d(swing.normalized()) : line.unitOrthogonal();
  Eigen::Vector3d& previous = elbow_dir_[static_cast<size_t>(side)];
  if (dt_ > 0.0) {
    Eigen::Vector3d q = previous - previous.dot(line) * line;
    if (q.norm() > 1e-6) {
      q.normalize();
      const double angle = std::acos(std::clamp(q.dot(swing), -1.0, 1.0));
      const double max_angle = options_.max_elbow_swing * dt_;
      if (angle > max_angle) {
        const Eigen::Vector3d axis =
            q.cross(swing).norm() > kTiny ? Eigen::Vector3d(q.cross(swing).normalized()) : line;
        swing = Eigen::AngleAxisd(max_angle, axis) * q;
      }
    }
  }
  previous = swing;
  const TwoBoneSolution sol = solve_two_bone(S, a, b, goal, swing);
  pose_.reachable[static_cast<size_t>(side)] = sol.reachable && (target - S).norm() >= dmin - kTiny;
  pose_two_bones(sh, el, wr, elbow_hinge(left), sol);
  Eigen::Quaterniond wrist_local =
      clamp_rotation(pose_.global[el].conjugate() * hand_rotation, options_.limits.max_wrist);
  // Rate-limited too: a hand turned past the wrist's range must not flip the hand over.
  Eigen::Quaterniond& last = wrist_local_[static_cast<size_t>(side)];
  if (dt_ > 0.0) {
    const double angle = last.angularDistance(wrist_local);
    const double max_angle = options_.max_wrist_speed * dt_;
    if (angle > max_angle) wrist_local = last.slerp(max_angle / angle, wrist_local).normalized();
  }
  last = wrist_local;
  pose_.global[wr] = (pose_.global[el] * wrist_local).normalized();
  pose_.global[hand] = pose_.global[wr];
  place(hand);
}

void BodyIk::pose_two_bones(int root, int mid, int end, const Eigen::Vector3d& hinge,
                            const TwoBoneSolution& sol) {
  const std::vector<Eigen::Vector3d>& r = rig_.rest;
  const Eigen::Quaterniond g_root =
      align_two_directions(r[mid] - r[root], hinge, sol.middle - pose_.joints[root], sol.hinge);
  const Eigen::Quaterniond l_mid = align_two_directions(
      r[end] - r[mid], hinge, g_root.conjugate() * (sol.end - sol.middle), hinge);
  pose_.global[root] = g_root;
  pose_.global[mid] = (g_root * l_mid).normalized();
  place(mid);
  place(end);
}

void BodyIk::solve_leg(int side, const Eigen::Vector3d& ankle, double foot_yaw) {
  const auto [hip, knee, ank, foot] = kLegs[side == 0 ? 0 : 1];
  const std::vector<Eigen::Vector3d>& r = rig_.rest;
  const Eigen::Vector3d& H = pose_.joints[hip];
  const double a = (r[knee] - r[hip]).norm(), b = (r[ank] - r[knee]).norm();
  const double dmin = min_reach(a, b, options_.limits.max_knee_bend);
  Eigen::Vector3d goal = ankle;
  if ((goal - H).norm() < dmin) goal = H + dmin * (goal - H).normalized();
  const Eigen::Quaterniond foot_rotation = yaw_rotation(foot_yaw);
  const Eigen::Vector3d pole = foot_rotation * Eigen::Vector3d(0.0, 0.0, 1.0);
  const TwoBoneSolution sol = solve_two_bone(H, a, b, goal, pole);
  pose_two_bones(hip, knee, ank, kKneeHinge, sol);
  // The foot flat on the floor, turned with the step, as far as the ankle allows.
  const Eigen::Quaterniond ankle_local =
      clamp_rotation(pose_.global[knee].conjugate() * foot_rotation, options_.limits.max_ankle);
  pose_.global[ank] = (pose_.global[knee] * ankle_local).normalized();
  pose_.global[foot] = pose_.global[ank];
  place(foot);
}

void BodyIk::update_heading(const IkInput& in, double head_yaw) {
  if (started_) {
    if (in.grips[0] && in.grips[1]) {
      const auto wrist = [&](int s) {
        const RigidPose& g = *in.grips[static_cast<size_t>(s)];
        return Eigen::Vector3d(g.position + g.orientation * options_.grip.wrist_in_grip);
      };
      const std::optional<double> hands = hands_yaw(wrist(0), wrist(1), options_.min_hands_apart);
      // Only towards the head and not past it: hands moving while the head looks ahead (a
      // wave, one hand reaching forwards) do not twist the body.
      const double to_head = wrap_angle(head_yaw - body_yaw_);
      if (hands && std::abs(wrap_angle(*hands - head_yaw)) <= options_.max_neck_yaw) {
        const double to_hands = wrap_angle(*hands - body_yaw_);
        const double turn =
            to_head > 0.0 ? std::clamp(to_hands, 0.0, to_head) : std::clamp(to_hands, to_head, 0.0);
        const double max_turn = options_.max_body_turn_speed * dt_;
        body_yaw_ = wrap_angle(body_yaw_ + std::clamp(turn, -max_turn, max_turn));
      }
    }
    body_yaw_ = follow_heading(body_yaw_, head_yaw, options_.max_neck_yaw);
  } else {
    body_yaw_ = head_yaw;
  }
}

void BodyIk::move_feet(const IkInput& in, const std::array<Eigen::Vector3d, 2>& goal) {
  if (!feet_[0].stepping && !feet_[1].stepping) {
    int worst = -1;
    double worst_error = 0.0;
    for (int s = 0; s < 2; ++s) {
      const Foot& f = feet_[static_cast<size_t>(s)];
      Eigen::Vector3d d = goal[static_cast<size_t>(s)] - f.planted;
      d.y() = 0.0;
      const double turn = std::abs(wrap_angle(body_yaw_ - f.yaw));
      // Right after the other foot stepped, this one follows to finish the stance.
      const double scale = s == follow_foot_ ? kFollowUp : 1.0;
      const double error = std::max(d.norm() / (scale * options_.step_distance),
                                    turn / (scale * options_.step_turn));
      if (error > 1.0 && error > worst_error) {
        worst = s;
        worst_error = error;
      }
    }
    follow_foot_ = -1;
    if (worst >= 0) {
      Foot& f = feet_[static_cast<size_t>(worst)];
      f.stepping = true;
      f.from = f.planted;
      f.from_yaw = f.yaw;
      f.step_start = in.time;
    }
  }
  for (int s = 0; s < 2; ++s) {
    Foot& f = feet_[static_cast<size_t>(s)];
    Eigen::Vector3d ankle = f.planted;
    double yaw = f.yaw;
    if (f.stepping) {
      const double t = std::clamp((in.time - f.step_start) / options_.step_seconds, 0.0, 1.0);
      const double e = smoothstep(t);
      ankle = f.from + e * (goal[static_cast<size_t>(s)] - f.from) +
              Eigen::Vector3d(0.0, options_.step_height * std::sin(kPi * t), 0.0);
      yaw = f.from_yaw + e * wrap_angle(body_yaw_ - f.from_yaw);
      if (t >= 1.0) {
        f.stepping = false;
        follow_foot_ = 1 - s;
        f.planted = goal[static_cast<size_t>(s)];
        f.yaw = body_yaw_;
        ankle = f.planted;
        yaw = f.yaw;
      }
    }
    solve_leg(s, ankle, yaw);
  }
}

const IkPose& BodyIk::solve(const IkInput& in) {
  const std::vector<Eigen::Vector3d>& r = rig_.rest;
  dt_ = started_ ? std::max(0.0, in.time - last_time_) : 0.0;
  last_time_ = in.time;
  // Head: rigidly attached to the headset (which looks along its -Z; the avatar faces +Z).
  const Eigen::Quaterniond g_head = (in.head.orientation * yaw_rotation(kPi)).normalized();
  const Eigen::Vector3d head_joint = in.head.position + g_head * (r[kHead] - rig_.eyes);

  // Heading: head turns beyond the neck's range turn the body; so does the line between the
  // hands, when both are tracked and it agrees with the head (rate-limited, towards the head
  // only): the chest follows a whole-body turn, not a head turn.
  const double head_yaw = headset_yaw(in.head.orientation);
  update_heading(in, head_yaw);
  pose_.body_yaw = body_yaw_;
  const Eigen::Quaterniond body = yaw_rotation(body_yaw_);
  const Eigen::Vector3d spine_rest = r[kHead] - r[kPelvis];
  const auto ankle_rest = [&](int side) {
    return Eigen::Vector3d(r[kLegs[side == 0 ? 0 : 1].end] - r[kPelvis]);
  };
  const auto on_floor = [&](Eigen::Vector3d p, int side) {
    p.y() = in.floor + r[kLegs[side == 0 ? 0 : 1].end].y();
    return p;
  };
  if (!started_) {
    const Eigen::Vector3d pelvis = head_joint - body * spine_rest;
    for (int s = 0; s < 2; ++s) {
      feet_[static_cast<size_t>(s)] = Foot{};
      feet_[static_cast<size_t>(s)].planted = on_floor(pelvis + body * ankle_rest(s), s);
      feet_[static_cast<size_t>(s)].yaw = body_yaw_;
    }
    started_ = true;
  }

  // Pelvis estimate: over the feet, following part of the head's horizontal offset; its height
  // standing. The spine then bends towards the head joint, and the pelvis goes where the chain
  // ends (lower when crouching).
  const Eigen::Vector3d feet_mid = 0.5 * (feet_[0].planted + feet_[1].planted);
  const Eigen::Vector3d feet_rest_mid = 0.5 * (ankle_rest(0) + ankle_rest(1));
  Eigen::Vector3d over_feet = feet_mid - body * feet_rest_mid;
  Eigen::Vector3d upright = head_joint - body * spine_rest;
  Eigen::Vector3d pelvis = over_feet + options_.pelvis_follow * (upright - over_feet);
  pelvis.y() = in.floor + r[kPelvis].y();
  const Eigen::Quaterniond bend =
      clamp_rotation(Eigen::Quaterniond::FromTwoVectors(body * spine_rest, head_joint - pelvis),
                     options_.max_spine_bend);
  const int chain[5] = {kPelvis, kSpine1, kSpine2, kSpine3, kNeck};
  for (int i = 0; i < 5; ++i)
    pose_.global[chain[i]] = (fraction(bend, (i + 1) / 5.0) * body).normalized();
  pose_.joints[kPelvis] = pelvis;
  for (int j : {kSpine1, kSpine2, kSpine3, kNeck, kHead}) place(j);
  const Eigen::Vector3d shift = head_joint - pose_.joints[kHead];
  for (int j : {kPelvis, kSpine1, kSpine2, kSpine3, kNeck, kHead}) pose_.joints[j] += shift;
  pose_.global[kHead] =
      (pose_.global[kNeck] *
       clamp_rotation(pose_.global[kNeck].conjugate() * g_head, options_.limits.max_head))
          .normalized();

  // Arms.
  for (int c : {kLeftCollar, kRightCollar}) {
    pose_.global[c] = pose_.global[kSpine3];
    place(c);
  }
  for (int s : {kLeftShoulder, kRightShoulder}) place(s);
  solve_arm(0, in);
  solve_arm(1, in);

  // Legs: feet planted; one steps when the pelvis moved or turned away from it.
  pose_.global[kLeftHip] = pose_.global[kRightHip] = pose_.global[kPelvis];
  place(kLeftHip);
  place(kRightHip);
  // Each foot's place under the upright body (leaning does not move it; walking does).
  std::array<Eigen::Vector3d, 2> goal;
  for (int s = 0; s < 2; ++s)
    goal[static_cast<size_t>(s)] = on_floor(upright + body * ankle_rest(s), s);
  move_feet(in, goal);
  // Local rotations and the model translation.
  for (int j = 0; j < kCount; ++j) {
    const int p = rig_.parents[j];
    pose_.local[j] =
        p < 0 ? pose_.global[j] : (pose_.global[p].conjugate() * pose_.global[j]).normalized();
  }
  pose_.translation = pose_.joints[kPelvis] - (r[kPelvis] - rig_.standing_shift);
  return pose_;
}

}  // namespace caliper
