// Embodiment IK: each piece on analytic cases, then the whole-body solver on the open female
// model (forward kinematics agree with smpl::evaluate, wrists reach, heading, crouch, steps,
// joint limits), and the posed mesh over the simulator's scripted motions (hands outside the
// torso's surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "caliper/body_ik.hpp"
#include "caliper/measurements.hpp"
#include "caliper/protocol_file.hpp"
#include "caliper/simulator.hpp"
#include "smpl/constants.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/io.hpp"

namespace caliper {
namespace {

using namespace ik_joint;
using smpl::kPi;
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

TEST(BodyIk, TurningRoundWithTheHandsAtTheSidesTurnsTheBodyFully) {
  // Head and hands turn together by 90 degrees over 2 s (the whole person turns): the hands'
  // line turns the body all the way, not only to within the neck's range of the head.
  Fixture f;
  BodyIk ik(f.rig);
  for (int i = 0; i <= 270; ++i) {
    const double t = i / 90.0;
    const double yaw = (kPi / 2) * std::min(1.0, t / 2.0);
    IkInput in = f.standing(Eigen::Vector3d::Zero(), yaw, 0.0, t);
    const Eigen::Quaterniond body(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
    for (int s = 0; s < 2; ++s) {
      const bool left = s == 0;
      const int sh = left ? kLeftShoulder : kRightShoulder;
      // Hanging at the side, fingers down, palms in.
      const Eigen::Vector3d wrist =
          body * (f.rig.rest[sh] + Eigen::Vector3d(left ? 0.06 : -0.06, -0.5, 0.03));
      const Eigen::Quaterniond hand =
          body * Eigen::AngleAxisd(left ? -kPi / 2 : kPi / 2, Eigen::Vector3d::UnitZ());
      RigidPose g;
      g.orientation = HandGrip::grip_from_hand(hand, left);
      g.position = wrist - g.orientation * ik.options().grip.wrist_in_grip;
      in.grips[static_cast<size_t>(s)] = g;
    }
    const IkPose& p = ik.solve(in);
    ASSERT_TRUE(check_limits(f.rig, p, ik.options().limits).empty()) << "frame " << i;
  }
  // Within the rate limit's lag of the turn's end (it ended 1 s ago).
  EXPECT_NEAR(ik.pose().body_yaw, kPi / 2, 1e-6);
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

TEST(Grip, TheWristSitsBehindThePalmCentreByHalfThePalm) {
  // Palm = 0.60 of the hand (ANSUR II), the grip point at its centre: 0.30 of the hand.
  EXPECT_NEAR(HandGrip::for_hand_length(0.19).wrist_in_grip.z(), 0.057, kExact);
  EXPECT_NEAR(HandGrip::for_hand_length(0.17).wrist_in_grip.z(), 0.051, kExact);
  EXPECT_EQ(HandGrip::for_hand_length(0.19).wrist_in_grip.head<2>(), Eigen::Vector2d::Zero());
  for (double bad : {0.0, 0.01, 0.5, -0.19, std::nan("")})
    EXPECT_THROW(HandGrip::for_hand_length(bad), std::invalid_argument) << bad;
}

TEST(BodyIk, TheGripIsScaledToTheAvatarsHand) {
  // The avatar's hands (wrist joint to fingertip in the T-pose) set where the wrist sits in the
  // controller's grip, so a large hand holds the controller with its wrist farther back.
  Fixture f;
  // The open female model's mean body: within ANSUR II's women (hand length 181 mm, SD 9 mm).
  EXPECT_GT(f.rig.hand_length, 0.16);
  EXPECT_LT(f.rig.hand_length, 0.20);
  const BodyIk ik(f.rig);
  EXPECT_NEAR(ik.options().grip.wrist_in_grip.z(), 0.30 * f.rig.hand_length, kExact);
  BodyIkOptions fixed;
  fixed.grip_from_hand = false;
  fixed.grip.wrist_in_grip.z() = 0.07;
  EXPECT_EQ(BodyIk(f.rig, fixed).options().grip.wrist_in_grip.z(), 0.07);
  // The taller of the bodies two units either way along the first shape coefficient (the
  // open models' size axis) has the longer hands.
  Eigen::VectorXd a = f.betas, b = f.betas;
  a[0] = 2.0;
  b[0] = -2.0;
  const auto height = [&](const Eigen::VectorXd& betas) {
    const smpl::Vertices v = shaped_vertices(f.model, betas);
    return v.col(1).maxCoeff() - v.col(1).minCoeff();
  };
  const Eigen::VectorXd& taller = height(a) > height(b) ? a : b;
  const Eigen::VectorXd& shorter = height(a) > height(b) ? b : a;
  EXPECT_GT(height(taller), height(shorter) + 0.1);
  EXPECT_GT(make_ik_rig(f.model, taller, f.eyes).hand_length,
            make_ik_rig(f.model, shorter, f.eyes).hand_length + 0.01);
  // The hand is the one a session measured: fingertip minus wrist along the arm.
  const smpl::Vertices v = shaped_vertices(f.model, f.betas);
  const Eigen::RowVector3d lo = v.colwise().minCoeff(), hi = v.colwise().maxCoeff();
  const double shift_x = -(lo.x() + hi.x()) / 2;
  EXPECT_NEAR(f.rig.hand_length,
              0.5 * ((hi.x() + shift_x - f.rig.rest[kLeftWrist].x()) +
                     (f.rig.rest[kRightWrist].x() - lo.x() - shift_x)),
              kExact);
  // Wrists still reach the controllers held with that grip.
  BodyIk solver(f.rig);
  IkInput in = f.standing();
  RigidPose g;
  g.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d wrist = f.rig.rest[kLeftShoulder] + Eigen::Vector3d(0.05, -0.2, 0.3);
  g.position = wrist - g.orientation * solver.options().grip.wrist_in_grip;
  in.grips[0] = g;
  EXPECT_LT((solver.solve(in).joints[kLeftWrist] - wrist).norm(), 1e-9);
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

/// Dominant skinning joint of every vertex.
std::vector<int> dominant_joint(const smpl::BodyModel& model) {
  std::vector<int> out(static_cast<size_t>(model.num_vertices()), -1);
  for (Eigen::Index v = 0; v < model.weights.outerSize(); ++v) {
    double best = -1.0;
    for (smpl::SparseMatrix::InnerIterator it(model.weights, v); it; ++it)
      if (it.value() > best) {
        best = it.value();
        out[static_cast<size_t>(v)] = static_cast<int>(it.col());
      }
  }
  return out;
}

/// How far the hands of a posed body are inside the rest of it: the largest depth of a hand
/// vertex (skinned mostly to a wrist or hand joint) behind the tangent plane of the nearest
/// vertex of the trunk, legs, neck or head (skinned mostly to a joint that is not an arm's), m;
/// negative when every hand vertex is in front. Hand vertices with no such vertex within
/// `kSearch` are outside (no part of the body is thicker than 2 x kSearch).
struct HandsInsideCheck {
  static constexpr double kSearch = 0.15;  // m
  std::vector<Eigen::Index> body, hands;
  double closest = 1e9;  ///< m, smallest hand-to-body vertex distance seen

  explicit HandsInsideCheck(const smpl::BodyModel& model) {
    const std::vector<int> owner = dominant_joint(model);
    for (size_t v = 0; v < owner.size(); ++v) {
      const int j = owner[v];
      if (j < kLeftShoulder) body.push_back(static_cast<Eigen::Index>(v));
      if (j == kLeftWrist || j == kRightWrist || j == kLeftHand || j == kRightHand)
        hands.push_back(static_cast<Eigen::Index>(v));
    }
  }

  double depth(const smpl::Vertices& v, const smpl::Faces& faces) {
    const smpl::Vertices normals = smpl::vertex_normals(v, faces);
    // Body vertices near the hands only (a box around them, grown by the search distance), in a
    // uniform grid of kCell cubes: the nearest body vertex to a hand vertex is searched shell by
    // shell of cells around it and the search stops once no farther shell can hold a nearer one
    // (the same answer as comparing with every body vertex, at a fraction of the work: the test
    // skins 1,650 frames and runs under the sanitizers too).
    constexpr double kCell = 0.075;  // m
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    for (Eigen::Index h : hands) {
      lo = lo.cwiseMin(v.row(h).transpose());
      hi = hi.cwiseMax(v.row(h).transpose());
    }
    lo.array() -= kSearch;
    hi.array() += kSearch;
    std::array<int, 3> n{};
    for (int a = 0; a < 3; ++a) n[a] = static_cast<int>((hi[a] - lo[a]) / kCell) + 1;
    const auto cell_of = [&](const double* q, int a) {
      return std::clamp(static_cast<int>((q[a] - lo[a]) / kCell), 0, n[a] - 1);
    };
    const auto index = [&](int x, int y, int z) {
      return (static_cast<size_t>(z) * static_cast<size_t>(n[1]) + static_cast<size_t>(y)) *
                 static_cast<size_t>(n[0]) +
             static_cast<size_t>(x);
    };
    // Counting sort of the near body vertices by cell: points[start[c] .. start[c + 1]).
    std::vector<std::array<double, 3>> near;
    std::vector<Eigen::Index> near_id;
    std::vector<size_t> cell;
    for (Eigen::Index t : body) {
      const std::array<double, 3> q{v(t, 0), v(t, 1), v(t, 2)};
      if (q[0] < lo[0] || q[1] < lo[1] || q[2] < lo[2] || q[0] > hi[0] || q[1] > hi[1] ||
          q[2] > hi[2])
        continue;
      near.push_back(q);
      near_id.push_back(t);
      cell.push_back(index(cell_of(q.data(), 0), cell_of(q.data(), 1), cell_of(q.data(), 2)));
    }
    std::vector<size_t> start(
        static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]) * static_cast<size_t>(n[2]) + 1, 0);
    for (size_t c : cell) ++start[c + 1];
    for (size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    std::vector<size_t> fill(start.begin(), start.end() - 1), order(near.size());
    for (size_t i = 0; i < near.size(); ++i) order[fill[cell[i]]++] = i;

    const int shells = static_cast<int>(std::ceil(kSearch / kCell));
    double deepest = -1e9;
    for (Eigen::Index h : hands) {
      const std::array<double, 3> x{v(h, 0), v(h, 1), v(h, 2)};
      const int cx = cell_of(x.data(), 0), cy = cell_of(x.data(), 1), cz = cell_of(x.data(), 2);
      double best = kSearch * kSearch;
      size_t nearest = near.size();
      for (int r = 0; r <= shells; ++r) {
        for (int z = std::max(cz - r, 0); z <= std::min(cz + r, n[2] - 1); ++z)
          for (int y = std::max(cy - r, 0); y <= std::min(cy + r, n[1] - 1); ++y)
            for (int xx = std::max(cx - r, 0); xx <= std::min(cx + r, n[0] - 1); ++xx) {
              if (std::max({std::abs(xx - cx), std::abs(y - cy), std::abs(z - cz)}) != r)
                continue;  // an inner shell, already searched
              const size_t c = index(xx, y, z);
              for (size_t k = start[c]; k < start[c + 1]; ++k) {
                const std::array<double, 3>& q = near[order[k]];
                const double d2 = (q[0] - x[0]) * (q[0] - x[0]) + (q[1] - x[1]) * (q[1] - x[1]) +
                                  (q[2] - x[2]) * (q[2] - x[2]);
                if (d2 < best || (d2 == best && nearest < near.size() && order[k] < nearest)) {
                  best = d2;
                  nearest = order[k];
                }
              }
            }
        // Every vertex in shell r + 1 or beyond is at least r cells from x.
        if (nearest < near.size() && std::sqrt(best) <= r * kCell) break;
      }
      if (nearest == near.size()) continue;
      const Eigen::Index t = near_id[nearest];
      closest = std::min(closest, std::sqrt(best));
      deepest =
          std::max(deepest, -(v.row(h) - v.row(t)).dot(normals.row(t)) / normals.row(t).norm());
    }
    return deepest;
  }
};

TEST(BodyIk, HandsStayOutsideTheBodyOverTheScriptedMotions) {
  // The "hands never inside the torso", on the mesh the user sees: the simulator's
  // motions (wave, reach up, cross arms, squat, turn) at 90 Hz on the open female model, as
  // `caliper-vr --simulate --motions` makes them; each frame's pose is skinned as the app does
  // (no pose correctives) and no hand vertex may be inside the trunk (or the legs, or the head).
  const std::string assets = std::string(CALIPER_SOURCE_DIR) + "/assets";
  smpl::BodyModel model = smpl::load_model(assets + "/models/caliper-female.npz");
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  betas.head(4) << 0.8, -0.6, 0.4, 0.2;
  const SimulatedPerson person = person_from_model(model, betas, 61.5, "female");
  SimulatorOptions so;
  so.motions = true;
  const SimulatedSession sim =
      simulate_session(read_protocol(assets + "/protocol/virtual-caliper.json"), person, so);
  ASSERT_GT(sim.motion_end, sim.motion_begin + 1500) << "about 20 s of motions at 90 Hz";
  BodyIk ik(make_ik_rig(model, betas, eyes_below_head_top(person.landmarks.at("head_top"))));
  model.posedirs.resize(model.posedirs.rows(), 0);
  HandsInsideCheck check(model);
  ASSERT_GT(check.body.size(), 3000u);
  ASSERT_GT(check.hands.size(), 100u);
  // A point on a curved surface is up to the sag of one edge behind a neighbouring vertex's
  // tangent plane (edges under 3 cm, radii over 8 cm: (1.5 cm)^2 / (2 x 8 cm) = 1.4 mm); a hand
  // resting on the body is not inside it.
  constexpr double kSurfaceSag = 0.002;  // m
  smpl::Workspace ws;
  smpl::Body body;
  double deepest = -1e9;
  size_t frames_inside = 0, frames = 0;
  IkInput in;
  for (size_t i = sim.motion_begin; i < sim.motion_end; ++i) {
    const PoseFrame& f = sim.log.frames[i];
    in.head = {f.device(Device::Head).position, f.device(Device::Head).orientation};
    for (int h = 0; h < 2; ++h) {
      const DevicePose& d = f.device(h == 0 ? Device::Left : Device::Right);
      in.grips[static_cast<size_t>(h)] = RigidPose{d.position, d.orientation};
    }
    in.floor = so.runtime_floor_offset;
    in.time = f.time;
    const IkPose& p = ik.solve(in);
    smpl::evaluate(model, betas, p.axis_angle(), p.translation, ws, body);
    const double d = check.depth(body.vertices, model.faces);
    deepest = std::max(deepest, d);
    frames_inside += d > kSurfaceSag ? 1 : 0;
    ++frames;
  }
  std::printf(
      "hands over %zu frames: nearest hand vertex to a body vertex %.1f mm; deepest behind the "
      "body's surface %.1f mm (negative: in front); %zu frames inside\n",
      frames, 1e3 * check.closest, 1e3 * deepest, frames_inside);
  EXPECT_EQ(frames_inside, 0u) << "deepest " << deepest << " m";

  // The check finds a hand that is inside: the left wrist sent to the middle of the chest.
  const IkPose& last = ik.pose();
  const Eigen::Vector3d chest = last.joints[kSpine3];
  in.grips[0]->position = chest - in.grips[0]->orientation * ik.options().grip.wrist_in_grip;
  in.time += 1.0;
  const IkPose& p = ik.solve(in);
  ASSERT_LT((p.joints[kLeftWrist] - chest).norm(), kWristBound);
  smpl::evaluate(model, betas, p.axis_angle(), p.translation, ws, body);
  EXPECT_GT(check.depth(body.vertices, model.faces), 0.02);
}

TEST(BodyIk, TheSimulatedPersonHangsTheHandsOutsideFullerHips) {
  // The scripted motions' rest hangs the wrists where every vertex of the hanging hand clears
  // the body at its height: a body made 25 % wider below the waist hangs them farther out, and
  // outside its hips, where "6 cm outside the shoulder joints" put them inside.
  const std::string assets = std::string(CALIPER_SOURCE_DIR) + "/assets";
  const smpl::BodyModel model = smpl::load_model(assets + "/models/caliper-female.npz");
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  const std::vector<int> owner = dominant_joint(model);
  const double waist = (model.j_regressor.row(kSpine1) * model.v_template.col(1)).value();
  smpl::BodyModel wide = model;
  for (Eigen::Index v = 0; v < wide.v_template.rows(); ++v) {
    if (owner[static_cast<size_t>(v)] < kLeftShoulder && wide.v_template(v, 1) < waist)
      wide.v_template(v, 0) *= 1.25;
  }
  const auto half_width = [&](const smpl::BodyModel& m) {  // hips and thighs, rest pose
    double w = 0.0;
    for (Eigen::Index v = 0; v < m.v_template.rows(); ++v) {
      if (owner[static_cast<size_t>(v)] < kLeftShoulder && m.v_template(v, 1) < waist &&
          m.v_template(v, 1) > waist - 0.45)
        w = std::max(w, std::abs(m.v_template(v, 0)));
    }
    return w;
  };
  const SimulatedPerson slim = person_from_model(model, betas, 60.0, "female");
  const SimulatedPerson full = person_from_model(wide, betas, 75.0, "female");
  const double slim_hips = half_width(model), full_hips = half_width(wide);
  std::printf("hips' half-width %.3f -> %.3f m; hanging wrist %.3f -> %.3f m (shoulder %.3f)\n",
              slim_hips, full_hips, slim.hang_wrist_x, full.hang_wrist_x,
              full.joints[kLeftShoulder].x());
  ASSERT_GT(full_hips, full.joints[kLeftShoulder].x() + 0.06) << "the test body is not full enough";
  EXPECT_GT(slim.hang_wrist_x, slim_hips);
  EXPECT_GT(full.hang_wrist_x, full_hips + 0.02);
  EXPECT_GT(full.hang_wrist_x - slim.hang_wrist_x, 0.5 * (full_hips - slim_hips));
}

}  // namespace
}  // namespace caliper
