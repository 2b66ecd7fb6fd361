/// \file body_ik.hpp
/// Embodiment: drives an SMPL-structured avatar from a headset and two controllers, so that the
/// user sees *their* body move in the virtual mirror and when looking down. Platform-free (no GL,
/// no OpenXR): poses in, joint rotations out; caliper-vr feeds it every frame after the avatar
/// is made, and the tests and the benchmark feed it pose logs.
///
/// The pieces, each usable and tested on its own:
/// - solve_two_bone(): analytic two-bone IK (law of cosines) with a pole direction; the middle
///   joint bends one way only (elbows and knees never bend backwards).
/// - follow_heading(), hands_yaw(): the body's heading follows the head's only beyond a neck
///   limit, and the line between the hands when they agree with the head, so turning the head
///   alone does not turn the body, while turning round does.
/// - BodyIk: the whole body. Head joint and orientation from the headset (rigid offset from the
///   eyes); spine and neck bend in equal parts towards the head's offset over the pelvis; the
///   pelvis is where that chain ends (so crouching lowers it); feet stay planted on the
///   calibrated floor and step, one at a time, when the upright body (pelvis under the head) has
///   moved more than a step away from them or turned, the other foot following; arms by two-bone IK
///   to the wrist derived from each controller's grip pose, the elbow pole down and out; wrist
///   orientation from the controller, within joint limits.
///
/// Frames: the avatar's rest pose stands on y = 0 facing +Z, its left is +X (the project's
/// convention); tracking space is OpenXR's (+Y up; the headset looks along its -Z). Joint
/// indices are SMPL's (pelvis 0, ..., head 15, shoulders 16/17, elbows 18/19, wrists 20/21).
#pragma once

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "smpl/body_model.hpp"

namespace caliper {

/// The model is not SMPL-structured enough for the IK (a joint it needs is missing).
class IkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// SMPL joint indices the IK drives.
namespace ik_joint {
constexpr int kPelvis = 0, kLeftHip = 1, kRightHip = 2, kSpine1 = 3, kLeftKnee = 4, kRightKnee = 5,
              kSpine2 = 6, kLeftAnkle = 7, kRightAnkle = 8, kSpine3 = 9, kLeftFoot = 10,
              kRightFoot = 11, kNeck = 12, kLeftCollar = 13, kRightCollar = 14, kHead = 15,
              kLeftShoulder = 16, kRightShoulder = 17, kLeftElbow = 18, kRightElbow = 19,
              kLeftWrist = 20, kRightWrist = 21, kLeftHand = 22, kRightHand = 23;
constexpr int kCount = 24;
}  // namespace ik_joint

/// A rigid pose.
struct RigidPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// How a hand holds a controller: the wrist joint in the controller's grip frame, and the grip
/// frame's axes (OpenXR: -Z along the fingers' tube, +X to the user's right for both hands, so
/// the left palm faces +X and the right palm -X). A closed fist around any of the supported
/// controllers; the measured tip offsets are separate (session.hpp). The grip point is the
/// palm's centre, so the wrist's distance behind it scales with the hand: for_hand_length().
struct HandGrip {
  /// Wrist to grip point (the palm's centre) per hand length (wrist crease to the tip of the
  /// middle finger): half the palm length, the palm being 0.60 of the hand (ANSUR II: palm
  /// length / hand length 0.603 for the men, 0.601 for the women, standard deviation 0.02).
  static constexpr double kWristToGripPerHandLength = 0.30;
  /// Wrist joint in the grip frame, m: behind the palm centre, along the handle. The default is
  /// for a hand 18.7 cm long (ANSUR II, men and women pooled); BodyIk sets it from the avatar's
  /// hand (IkRig::hand_length).
  Eigen::Vector3d wrist_in_grip = Eigen::Vector3d(0.0, 0.0, kWristToGripPerHandLength * 0.187);
  /// Hand lengths for_hand_length() takes, m (wider than any adult's: 14.5-23.9 cm in ANSUR II).
  static constexpr double kMinHandLength = 0.05, kMaxHandLength = 0.4;
  static bool is_hand_length(double m) { return m >= kMinHandLength && m <= kMaxHandLength; }
  /// The grip of a hand `hand_length` m long (wrist to middle fingertip). Throws
  /// std::invalid_argument unless is_hand_length(hand_length).
  static HandGrip for_hand_length(double hand_length);
  /// World rotation of the avatar's hand (rest-pose frame) for a grip orientation `grip`.
  static Eigen::Quaterniond hand_from_grip(const Eigen::Quaterniond& grip, bool left);
  /// The grip orientation that holds the hand at world rotation `hand` (inverse of the above).
  static Eigen::Quaterniond grip_from_hand(const Eigen::Quaterniond& hand, bool left);
};

/// Where a headset sits relative to the top of the head (rest frame, facing +Z): 11 cm below,
/// 8 cm in front. The simulator puts its headset there; the app uses it to attach the avatar.
inline Eigen::Vector3d eyes_below_head_top(const Eigen::Vector3d& head_top) {
  return head_top + Eigen::Vector3d(0.0, -0.11, 0.08);
}

/// Result of solve_two_bone().
struct TwoBoneSolution {
  Eigen::Vector3d middle = Eigen::Vector3d::Zero();  ///< elbow / knee position
  Eigen::Vector3d end = Eigen::Vector3d::Zero();     ///< wrist / ankle position reached
  bool reachable = false;  ///< the target was within [|a - b|, a + b] of the root
  double bend = 0.0;       ///< angle between the two bones' directions, rad, in [0, pi)
  Eigen::Vector3d hinge = Eigen::Vector3d::UnitX();  ///< unit axis turning bone 1 into bone 2
};

/// Analytic two-bone IK: bones of lengths `upper` and `lower` from `root` towards `target`; the
/// middle joint is displaced towards `pole` (any vector with a component perpendicular to the
/// root-target line; otherwise a perpendicular is chosen). An unreachable target gets the
/// straight (or fully folded) chain pointing at it. Throws std::invalid_argument for bone lengths
/// that are not positive.
TwoBoneSolution solve_two_bone(const Eigen::Vector3d& root, double upper, double lower,
                               const Eigen::Vector3d& target, const Eigen::Vector3d& pole);

/// Rotation R with R * a_rest = a (directions) and R * b_rest in the plane of a and b on b's side:
/// the frame of two rest directions aligned to two current ones (a wins when they disagree).
Eigen::Quaterniond align_two_directions(const Eigen::Vector3d& a_rest,
                                        const Eigen::Vector3d& b_rest, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b);

/// Yaw (about +Y, 0 = facing +Z) of the headset's view direction; stable when looking down
/// (the head's up vector then gives the direction).
double headset_yaw(const Eigen::Quaterniond& headset);

/// Heading of the chest from the two wrists (the left one on the body's +X side): the
/// horizontal direction perpendicular to the right-to-left line; nullopt when they are less than
/// `min_apart` apart horizontally. Radians, 0 = facing +Z.
std::optional<double> hands_yaw(const Eigen::Vector3d& left_wrist,
                                const Eigen::Vector3d& right_wrist, double min_apart);

/// The body's new heading: unchanged while the head is turned at most `max_neck_yaw` from it,
/// otherwise turned just enough to bring the head back to that limit. Radians.
double follow_heading(double body_yaw, double head_yaw, double max_neck_yaw);

/// Joint limits (radians) the solver keeps and check_limits() checks.
struct JointLimits {
  double max_elbow_bend = 2.7;   ///< elbow flexion (155 degrees); never negative
  double max_knee_bend = 2.6;    ///< knee flexion (150 degrees); never negative
  double max_wrist = 1.45;       ///< wrist rotation from the forearm (83 degrees)
  double max_head = 1.3;         ///< head rotation from the neck (75 degrees)
  double max_spine_joint = 0.5;  ///< each of pelvis tilt, spine 1-3 and neck (29 degrees)
  double max_ankle = 0.9;        ///< ankle rotation from the shin (52 degrees)
};

/// Settings of the body solver.
struct BodyIkOptions {
  HandGrip grip;
  /// Replace `grip` by HandGrip::for_hand_length(rig.hand_length) when the rig knows its hand.
  bool grip_from_hand = true;
  JointLimits limits;
  double max_neck_yaw = 0.79;  ///< rad (45 degrees): head turns beyond this turn the body
  /// m: with both hands tracked at least this far apart sideways, the line between them gives
  /// the chest's heading when it is within the neck's range of the head's; the body turns towards
  /// it, but only in the direction of the head's turn and not past the head (a whole-body turn
  /// turns the body fully; a head turn alone leaves the hands, and so the body, where they were;
  /// a hand moving while the head looks ahead does not twist it).
  double min_hands_apart = 0.2;
  double max_body_turn_speed = 3.0;  ///< rad/s towards the hands' heading
  double step_distance = 0.22;       ///< m: a foot steps when its target is this far from it
  double step_turn = 0.52;           ///< rad (30 degrees): ... or the body turned this much from it
  double step_seconds = 0.35;        ///< duration of one step
  double step_height = 0.06;         ///< m, foot lift at mid-step
  /// Share of the head's horizontal offset (from the standing posture over the feet) that the
  /// pelvis follows; the rest is spine bending (leaning forward bends, it does not slide).
  double pelvis_follow = 0.35;
  double max_spine_bend = 1.4;  ///< rad, whole-chain bend from pelvis to head joint
  /// rad/s: how fast the elbow may swing about the shoulder-wrist line, and the hand turn
  /// relative to the forearm (faster demands are followed over a few frames, never flipped).
  double max_elbow_swing = 8.0;
  double max_wrist_speed = 10.0;
};

/// The skeleton the solver works on: rest joints of one body (model + betas), standing.
struct IkRig {
  std::vector<Eigen::Vector3d> rest;  ///< K rest joint positions, standing frame (soles y = 0)
  std::vector<int> parents;           ///< K
  Eigen::Vector3d standing_shift = Eigen::Vector3d::Zero();  ///< standing = model frame + shift
  Eigen::Vector3d eyes = Eigen::Vector3d::Zero();  ///< the headset's point in the rest frame
  /// m: wrist joint to fingertip (the vertex farthest out along the arm in the T-pose), mean of
  /// the two hands. On an avatar made from a session it follows the measured arm span (to the
  /// fingertips) and arm length (to the wrist); 0 = unknown (the default grip is used).
  double hand_length = 0.0;
};

/// The rig of `model` with `betas` (rest vertices shifted to stand on y = 0, centred in x and z,
/// as the app shows the avatar); `eyes` is where the headset sits on that body. Throws IkError
/// when the model does not have SMPL's 24 joints in SMPL's order, or its rest skeleton is not a
/// standing T-pose (spine up, knees between hips and ankles, arms out, left at +X).
IkRig make_ik_rig(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
                  const Eigen::Vector3d& eyes);

/// What the solver gets each frame (tracking space; `floor` = calibrated floor height).
struct IkInput {
  RigidPose head;                                 ///< headset pose (must be valid)
  std::array<std::optional<RigidPose>, 2> grips;  ///< left, right grip poses; nullopt = untracked
  double floor = 0.0;
  double time = 0.0;  ///< s, increasing
};

/// The solved pose.
struct IkPose {
  std::vector<Eigen::Quaterniond> local;   ///< K rotations relative to the parent (rest = I)
  std::vector<Eigen::Quaterniond> global;  ///< K world rotations
  std::vector<Eigen::Vector3d> joints;     ///< K world joint positions
  /// smpl::evaluate(model, betas, axis_angle(), translation) puts the joints at `joints`.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector3d, 2> wrist_target;  ///< controller-derived wrists (left, right)
  std::array<bool, 2> hand_tracked{false, false};
  std::array<bool, 2> reachable{false, false};  ///< wrist target within the arm's reach
  double body_yaw = 0.0;
  /// SMPL pose vector: 3K axis-angle values.
  Eigen::VectorXd axis_angle() const;
};

/// One joint-limit violation found by check_limits(): joint index and what was wrong.
struct LimitViolation {
  int joint = -1;
  std::string what;
};

/// Checks a pose against the limits: elbows and knees bend only forwards (about their rest hinge
/// axis, by no more than the maximum), wrists, head, ankles and spine joints within their
/// angles. Tolerance 1e-6 rad.
std::vector<LimitViolation> check_limits(const IkRig& rig, const IkPose& pose,
                                         const JointLimits& limits);

/// The whole-body solver (keeps the feet, the heading and the step state between frames).
class BodyIk {
 public:
  explicit BodyIk(IkRig rig, BodyIkOptions options = {});
  /// Solves one frame. The first frame puts the feet under the body.
  const IkPose& solve(const IkInput& input);
  const IkPose& pose() const { return pose_; }
  const IkRig& rig() const { return rig_; }
  const BodyIkOptions& options() const { return options_; }
  /// Arm reach (upper arm + forearm), m, of the left (0) or right (1) arm.
  double arm_length(int side) const;

 private:
  struct Foot {
    Eigen::Vector3d planted = Eigen::Vector3d::Zero();  ///< ankle on the ground
    double yaw = 0.0;
    bool stepping = false;
    Eigen::Vector3d from = Eigen::Vector3d::Zero();
    double from_yaw = 0.0;
    double step_start = 0.0;
  };
  void solve_arm(int side, const IkInput& input);
  void solve_leg(int side, const Eigen::Vector3d& ankle, double foot_yaw);
  /// body_yaw_ after this frame: head turns beyond the neck's range turn the body; so does the
  /// line between the hands, when both are tracked and it agrees with the head (rate-limited,
  /// towards the head only).
  void update_heading(const IkInput& input, double head_yaw);
  /// Feet planted; one starts a step when its place under the upright body (`goal`, left and
  /// right) moved or turned away from it, a stepping foot moves on; then the legs are solved.
  void move_feet(const IkInput& input, const std::array<Eigen::Vector3d, 2>& goal);
  void place(int joint);  ///< joints[joint] from its parent and the parent's global rotation
  /// Turns the bones root -> mid -> end (shoulder, elbow, wrist or hip, knee, ankle) onto `sol`,
  /// solved from joints[root]: bone 1 towards sol.middle with its rest hinge axis `hinge` onto
  /// sol.hinge, bone 2 towards sol.end about the same hinge; then places mid and end.
  void pose_two_bones(int root, int mid, int end, const Eigen::Vector3d& hinge,
                      const TwoBoneSolution& sol);

  IkRig rig_;
  BodyIkOptions options_;
  IkPose pose_;
  bool started_ = false;
  double body_yaw_ = 0.0;
  std::array<Foot, 2> feet_;
  int follow_foot_ = -1;
  double dt_ = 0.0, last_time_ = 0.0;  ///< this frame's interval (0 on the first frame)
  std::array<Eigen::Vector3d, 2> elbow_dir_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Quaterniond, 2> wrist_local_{
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond::Identity()};  ///< foot that may finish the stance after the other stepped
};

}  // namespace caliper
