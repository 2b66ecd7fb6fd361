// Embodiment IK: each piece on analytic cases, then the whole-body solver on the open female
// model (forward kinematics agree with smpl::evaluate, wrists reach, heading, crouch, steps,
// joint limits).
#include <gtest/gtest.h>

#include <cmath>

#include "caliper/body_ik.hpp"
#include "caliper/measurements.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"

namespace caliper {
namespace {

using namespace ik_joint;
constexpr double kPi = 3.14159265358979323846;
// Closed-form results in double precision: equal to rounding.
constexpr double kExact = 1e-9;
// The forward pass of smpl::evaluate composes 24 rotations in another order: rounding only.
constexpr double kFkAgreement = 1e-9;
// The bound: avatar wrist within 1 cm of the controller-derived wrist when reachable.
constexpr double kWristBound = 0.01;

TEST(TwoBone, ReachableTargetIsReachedWithBoneLengthsKept) {
  const Eigen::Vector3d root(0.1, 1.4, 0.0), target(0.5, 1.2, 0.3);
  const TwoBoneSolution s = solve_two_bone(root, 0.3, 0.25, target, Eigen::Vector3d(0, -1, 0));
  EXPECT_TRUE(s.reachable);
  EXPECT_LT((s.end - target).norm(), kExact);
  EXPECT_NEAR((s.middle - root).norm(), 0.3, kExact);
  EXPECT_NEAR((s.end - s.middle).norm(), 0.25, kExact);
  // The middle joint is on the pole's side of the root-target line.
  const Eigen::Vector3d w = (target - root).normalized();
  const Eigen::Vector3d off = (s.middle - root) - (s.middle - root).dot(w) * w;
  EXPECT_GT(off.dot(Eigen::Vector3d(0, -1, 0)), 0.0);
}

TEST(TwoBone, RightAngleCase) {
  // Bones of 1 and 1, target at sqrt(2) along +X: the middle is at (sqrt(2)/2, +-sqrt(2)/2) and
  // the chain bends by 90 degrees; pole +Y picks the upper solution.
  const TwoBoneSolution s =
      solve_two_bone(Eigen::Vector3d::Zero(), 1.0, 1.0, Eigen::Vector3d(std::sqrt(2.0), 0, 0),
                     Eigen::Vector3d(0.3, 1.0, 0.0));
  EXPECT_LT((s.middle - Eigen::Vector3d(std::sqrt(0.5), std::sqrt(0.5), 0)).norm(), kExact);
  EXPECT_NEAR(s.bend, kPi / 2, kExact);
  // Hinge: turns bone 1 (+X+Y) into bone 2 (+X-Y): about -Z.
  EXPECT_LT((s.hinge - Eigen::Vector3d(0, 0, -1)).norm(), kExact);
}

TEST(TwoBone, UnreachableTargetGetsTheStraightChain) {
  const TwoBoneSolution s = solve_two_bone(Eigen::Vector3d::Zero(), 0.3, 0.25,
                                           Eigen::Vector3d(0, 0, 2.0), Eigen::Vector3d(0, -1, 0));
  EXPECT_FALSE(s.reachable);
  EXPECT_LT((s.end - Eigen::Vector3d(0, 0, 0.55)).norm(), kExact);
  EXPECT_LT((s.middle - Eigen::Vector3d(0, 0, 0.3)).norm(), kExact);
  EXPECT_NEAR(s.bend, 0.0, 1e-6);
  // A pole along the line: still a valid chain (a perpendicular is chosen).
  const TwoBoneSolution t = solve_two_bone(Eigen::Vector3d::Zero(), 0.3, 0.25,
                                           Eigen::Vector3d(0, -0.4, 0), Eigen::Vector3d(0, -1, 0));
  EXPECT_TRUE(t.reachable);
  EXPECT_LT((t.end - Eigen::Vector3d(0, -0.4, 0)).norm(), kExact);
  EXPECT_THROW(solve_two_bone(Eigen::Vector3d::Zero(), 0.0, 1.0, Eigen::Vector3d::UnitX(),
                              Eigen::Vector3d::UnitY()),
               std::invalid_argument);
}

TEST(Frames, AlignTwoDirectionsRecoversARotation) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  const Eigen::Vector3d a(0.2, -1.0, 0.1), b(1.0, 0.3, 0.0);
  const Eigen::Quaterniond r = align_two_directions(a, b, q * a, q * b);
  EXPECT_LT((r.toRotationMatrix() - q.toRotationMatrix()).norm(), kExact);
}

TEST(Heading, HeadTurnsWithinTheNeckLimitDoNotTurnTheBody) {
  EXPECT_DOUBLE_EQ(follow_heading(0.2, 0.2 + 0.7, 0.79), 0.2);
  EXPECT_DOUBLE_EQ(follow_heading(0.2, 0.2 - 0.7, 0.79), 0.2);
  EXPECT_NEAR(follow_heading(0.0, 1.5, 0.79), 1.5 - 0.79, kExact);
  EXPECT_NEAR(follow_heading(0.0, -1.5, 0.79), -1.5 + 0.79, kExact);
  // Across +-pi: the short way round.
  EXPECT_NEAR(follow_heading(3.0, -3.0, 0.79), 3.0, kExact);
}

TEST(Heading, HeadsetYawIsStableLookingDown) {
  // OpenXR's identity looks along -Z: yaw pi (the avatar's 0 faces +Z).
  EXPECT_NEAR(std::abs(headset_yaw(Eigen::Quaterniond::Identity())), kPi, kExact);
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(kPi + 0.4, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(headset_yaw(turned), 0.4, kExact);
  // Looking straight down (pitch -90 degrees): the head's up vector gives the heading.
  const Eigen::Quaterniond down = turned * Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(headset_yaw(down), 0.4, 1e-6);
}

TEST(Grip, HandFromGripRoundTripsAndPointsTheFingersForward) {
  const Eigen::Quaterniond g(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  for (bool left : {true, false}) {
    const Eigen::Quaterniond h = HandGrip::hand_from_grip(g, left);
    EXPECT_LT((HandGrip::grip_from_hand(h, left).toRotationMatrix() - g.toRotationMatrix()).norm(),
              kExact);
    // The rest hand's fingers point out (+X left, -X right); held, they point where the
    // controller points (its -Z).
    const Eigen::Vector3d fingers = h * Eigen::Vector3d(left ? 1.0 : -1.0, 0.0, 0.0);
    EXPECT_LT((fingers - g * Eigen::Vector3d(0, 0, -1)).norm(), kExact);
  }
}

/// The open female model's rig, standing.
struct Fixture {
  smpl::BodyModel model =
      smpl::load_model(std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-female.npz");
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  IkRig rig;
  Eigen::Vector3d eyes;
  Fixture() {
    const smpl::Vertices v = shaped_vertices(model, betas);
    const Eigen::RowVector3d lo = v.colwise().minCoeff(), hi = v.colwise().maxCoeff();
    const Eigen::Vector3d shift(-(lo.x() + hi.x()) / 2, -lo.y(), -(lo.z() + hi.z()) / 2);
    const Eigen::Vector3d top = landmark_point(v, landmarks_for(model).at("head_top")) + shift;
    eyes = eyes_below_head_top(top);
    rig = make_ik_rig(model, betas, eyes);
  }
  /// Standing upright at `at` (floor 0) facing yaw `yaw`, hands hanging, headset level.
  IkInput standing(const Eigen::Vector3d& at = Eigen::Vector3d::Zero(), double yaw = 0.0,
                   double head_yaw = 0.0, double t = 0.0) const {
    IkInput in;
    const Eigen::Quaterniond body(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
    // A head turn pivots about the head joint.
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(head_yaw, Eigen::Vector3d::UnitY()));
    in.head.position = at + body * (rig.rest[kHead] + turn * (eyes - rig.rest[kHead]));
    in.head.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(yaw + head_yaw + kPi, Eigen::Vector3d::UnitY()));
    in.time = t;
    return in;
  }
};

TEST(BodyIk, ForwardKinematicsAgreeWithTheModel) {
  Fixture f;
  BodyIk ik(f.rig);
  IkInput in = f.standing();
  RigidPose grip;
  grip.position = f.rig.rest[kLeftShoulder] + Eigen::Vector3d(0.2, 0.1, 0.35);
  grip.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()));
  in.grips[0] = grip;
  in.head.orientation = in.head.orientation * Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX());
  const IkPose& p = ik.solve(in);
  const smpl::Body b = smpl::evaluate(f.model, f.betas, p.axis_angle(), p.translation);
  for (int k = 0; k < kCount; ++k)
    EXPECT_LT((b.joints.row(k).transpose() - p.joints[static_cast<size_t>(k)]).norm(), kFkAgreement)
        << "joint " << k;
}

TEST(BodyIk, StandingStillIsNearTheRestPoseWithinLimits) {
  Fixture f;
  BodyIk ik(f.rig);
  const IkPose& p = ik.solve(f.standing());
  // Upright: head joint and pelvis at their rest places (the head is attached to the headset).
  EXPECT_LT((p.joints[kHead] - f.rig.rest[kHead]).norm(), 1e-9);
  EXPECT_LT((p.joints[kPelvis] - f.rig.rest[kPelvis]).norm(), 1e-6);
  EXPECT_LT((p.joints[kLeftAnkle] - f.rig.rest[kLeftAnkle]).norm(), 1e-6);
  EXPECT_TRUE(check_limits(f.rig, p, ik.options().limits).empty());
}

TEST(BodyIk, WristsReachTheControllersAndElbowsPointDown) {
  Fixture f;
  BodyIk ik(f.rig);
  IkInput in = f.standing();
  // Both hands forward at chest height, controllers level.
  for (int s = 0; s < 2; ++s) {
    RigidPose g;
    const int sh = s == 0 ? kLeftShoulder : kRightShoulder;
    const Eigen::Vector3d wrist = f.rig.rest[sh] + Eigen::Vector3d(0.0, -0.15, 0.35);
    g.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()));
    g.position = wrist - g.orientation * ik.options().grip.wrist_in_grip;
    in.grips[static_cast<size_t>(s)] = g;
  }
  const IkPose& p = ik.solve(in);
  for (int s = 0; s < 2; ++s) {
    const int wr = s == 0 ? kLeftWrist : kRightWrist;
    const int el = s == 0 ? kLeftElbow : kRightElbow;
    const int sh = s == 0 ? kLeftShoulder : kRightShoulder;
    EXPECT_TRUE(p.reachable[static_cast<size_t>(s)]);
    EXPECT_LT((p.joints[static_cast<size_t>(wr)] - p.wrist_target[static_cast<size_t>(s)]).norm(),
              1e-9);
    // Elbow below the shoulder-wrist line and outside it.
    const Eigen::Vector3d mid =
        0.5 * (p.joints[static_cast<size_t>(sh)] + p.joints[static_cast<size_t>(wr)]);
    EXPECT_LT(p.joints[static_cast<size_t>(el)].y(), mid.y());
    EXPECT_GT((s == 0 ? 1.0 : -1.0) * (p.joints[static_cast<size_t>(el)].x() - mid.x()), 0.0);
  }
  EXPECT_TRUE(check_limits(f.rig, p, ik.options().limits).empty());
}

TEST(BodyIk, TurningTheHeadAloneDoesNotTurnTheBody) {
  Fixture f;
  BodyIk ik(f.rig);
  ik.solve(f.standing());
  const IkPose& p = ik.solve(f.standing(Eigen::Vector3d::Zero(), 0.0, 0.6, 0.1));
  EXPECT_NEAR(p.body_yaw, 0.0, kExact);
  EXPECT_LT((p.joints[kPelvis] - f.rig.rest[kPelvis]).norm(), 0.01);
  // Turning the whole body by 90 degrees: the body follows (to within the neck's range).
  const IkPose& q = ik.solve(f.standing(Eigen::Vector3d::Zero(), kPi / 2, 0.0, 0.2));
  EXPECT_NEAR(q.body_yaw, kPi / 2 - ik.options().max_neck_yaw, kExact);
  EXPECT_TRUE(check_limits(f.rig, q, ik.options().limits).empty());
}

TEST(BodyIk, CrouchingLowersThePelvisAndBendsTheKnees) {
  Fixture f;
  BodyIk ik(f.rig);
  ik.solve(f.standing());
  IkInput in = f.standing(Eigen::Vector3d::Zero(), 0.0, 0.0, 0.1);
  in.head.position.y() -= 0.3;
  const IkPose& p = ik.solve(in);
  EXPECT_NEAR(p.joints[kPelvis].y(), f.rig.rest[kPelvis].y() - 0.3, 0.02);
  // Feet stay where they were.
  EXPECT_LT((p.joints[kLeftAnkle] - f.rig.rest[kLeftAnkle]).norm(), 0.01);
  // Knees forward of the hip-ankle line.
  const Eigen::Vector3d mid = 0.5 * (p.joints[kLeftHip] + p.joints[kLeftAnkle]);
  EXPECT_GT(p.joints[kLeftKnee].z(), mid.z() + 0.05);
  EXPECT_TRUE(check_limits(f.rig, p, ik.options().limits).empty());
}

TEST(BodyIk, LeaningBendsTheSpineAndFeetStepWhenThePelvisMovesAway) {
  Fixture f;
  BodyIk ik(f.rig);
  ik.solve(f.standing());
  // Leaning forward by 0.25 rad about the pelvis: the spine bends, the feet stay.
  IkInput lean = f.standing(Eigen::Vector3d::Zero(), 0.0, 0.0, 0.1);
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitX()));
  lean.head.position = f.rig.rest[kPelvis] + tilt * (lean.head.position - f.rig.rest[kPelvis]);
  lean.head.orientation = tilt * lean.head.orientation;
  const IkPose& p = ik.solve(lean);
  EXPECT_GT(Eigen::AngleAxisd(p.local[kSpine2]).angle(), 0.02);
  EXPECT_GT(p.joints[kHead].z(), f.rig.rest[kHead].z() + 0.1);
  EXPECT_LT((p.joints[kLeftAnkle] - f.rig.rest[kLeftAnkle]).norm(), 1e-6);
  EXPECT_TRUE(check_limits(f.rig, p, ik.options().limits).empty());
  // Walking 0.6 m to the side: the feet step, one at a time, and end under the body.
  double t = 0.2;
  for (int i = 0; i <= 180; ++i, t += 1.0 / 90.0) {
    const double x = 0.6 * std::min(1.0, i / 60.0);
    const IkPose& q = ik.solve(f.standing(Eigen::Vector3d(x, 0, 0), 0.0, 0.0, t));
    ASSERT_TRUE(check_limits(f.rig, q, ik.options().limits).empty()) << "frame " << i;
  }
  const IkPose& q = ik.pose();
  // Within the follow-up threshold (15 % of a 22 cm step).
  EXPECT_NEAR(q.joints[kLeftAnkle].x(), f.rig.rest[kLeftAnkle].x() + 0.6, 0.035);
  EXPECT_NEAR(q.joints[kRightAnkle].x(), f.rig.rest[kRightAnkle].x() + 0.6, 0.035);
  EXPECT_NEAR(q.joints[kLeftAnkle].y(), f.rig.rest[kLeftAnkle].y(), 1e-9) << "on the floor";
}

TEST(BodyIk, ElbowsNeverBendBackwardsForTargetsAllAround) {
  Fixture f;
  BodyIk ik(f.rig);
  IkInput in = f.standing();
  for (int i = 0; i < 400; ++i) {
    const double a = 0.37 * i, b = 0.23 * i;
    RigidPose g;
    g.position =
        f.rig.rest[kRightShoulder] +
        0.45 * std::abs(std::sin(0.11 * i)) *
            Eigen::Vector3d(std::cos(a) * std::cos(b), std::sin(b), std::sin(a) * std::cos(b));
    g.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d(1, 1, 0).normalized()));
    in.grips[1] = g;
    in.time = i / 90.0;
    const IkPose& p = ik.solve(in);
    const std::vector<LimitViolation> v = check_limits(f.rig, p, ik.options().limits);
    ASSERT_TRUE(v.empty()) << "case " << i << ": " << v[0].what;
    if (p.reachable[1]) {
      EXPECT_LT((p.joints[kRightWrist] - p.wrist_target[1]).norm(), kWristBound) << i;
    }
  }
}

}  // namespace
}  // namespace caliper
