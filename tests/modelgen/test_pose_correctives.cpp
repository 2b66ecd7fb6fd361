/// \file test_pose_correctives.cpp
/// Pose correctives (apps/modelgen/src/pose_correctives.hpp) on a model whose fault is known: a
/// closed tube along +x (an arm: shoulder at x = 0, elbow at 0.3 m, wrist at 0.5 m, 5 cm radius)
/// with sharp skinning weights at the elbow and the wrist. Linear blend skinning folds the inner
/// side of the elbow bent 90 degrees; the correctives must unfold it there, leave the skin far
/// from the joints alone, and come out the same whatever the number of threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "mesh_checks.hpp"
#include "pose_correctives.hpp"
#include "smpl/evaluate.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kRings = 61;   // one every centimetre, x = 0 .. 0.6 m
constexpr int kAround = 24;  // vertices per ring
constexpr double kElbow = 0.3;
constexpr double kWrist = 0.5;

double ramp(double x, double at, double half_width) {
  const double t = std::min(1.0, std::max(0.0, (x - (at - half_width)) / (2 * half_width)));
  return t * t * (3 - 2 * t);
}

/// The tube: rings of kAround vertices, two cap centres; joints shoulder (root), elbow, wrist.
smpl::BodyModel tube() {
  smpl::BodyModel m;
  const int nv = kRings * kAround + 2;
  m.v_template.resize(nv, 3);
  for (int r = 0; r < kRings; ++r) {
    for (int a = 0; a < kAround; ++a) {
      const double phi = 2 * kPi * a / kAround;
      m.v_template.row(r * kAround + a) << 0.01 * r, 0.05 * std::cos(phi), 0.05 * std::sin(phi);
    }
  }
  const int c0 = kRings * kAround, c1 = c0 + 1;
  m.v_template.row(c0) << 0.0, 0.0, 0.0;
  m.v_template.row(c1) << 0.01 * (kRings - 1), 0.0, 0.0;
  std::vector<Eigen::Vector3i> f;
  for (int r = 0; r + 1 < kRings; ++r) {
    for (int a = 0; a < kAround; ++a) {
      const int i = r * kAround + a, j = r * kAround + (a + 1) % kAround;
      f.emplace_back(i, j + kAround, j);  // outward: the tube runs along +x
      f.emplace_back(i, i + kAround, j + kAround);
    }
  }
  for (int a = 0; a < kAround; ++a) {
    f.emplace_back(c0, a, (a + 1) % kAround);
    const int last = (kRings - 1) * kAround;
    f.emplace_back(c1, last + (a + 1) % kAround, last + a);
  }
  m.faces.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t t = 0; t < f.size(); ++t) m.faces.row(static_cast<Eigen::Index>(t)) = f[t];
  m.parents = {-1, 0, 1};
  m.joint_names = {"shoulder", "elbow", "wrist"};
  std::vector<Eigen::Triplet<double>> w, jr;
  for (int i = 0; i < nv; ++i) {
    const double x = m.v_template(i, 0);
    const double elbow = ramp(x, kElbow, 0.02), wrist = ramp(x, kWrist, 0.02);
    const double part[3] = {1 - elbow, elbow - wrist, wrist};
    for (int k = 0; k < 3; ++k) {
      if (part[k] > 0) w.emplace_back(i, k, part[k]);
    }
  }
  m.weights.resize(nv, 3);
  m.weights.setFromTriplets(w.begin(), w.end());
  for (int a = 0; a < kAround; ++a) {
    jr.emplace_back(0, a, 1.0 / kAround);
    jr.emplace_back(1, 30 * kAround + a, 1.0 / kAround);
    jr.emplace_back(2, 50 * kAround + a, 1.0 / kAround);
  }
  m.j_regressor.resize(3, nv);
  m.j_regressor.setFromTriplets(jr.begin(), jr.end());
  m.shapedirs = Eigen::MatrixXd::Zero(3 * Eigen::Index{nv}, 1);
  m.posedirs.resize(3 * Eigen::Index{nv}, 0);
  smpl::validate(m, "tube");
  return m;
}

Eigen::VectorXd bend(int joint, const Eigen::Vector3d& axis_angle) {
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(9);
  theta.segment<3>(3 * Eigen::Index{joint}) = axis_angle;
  return theta;
}

std::size_t flipped(const smpl::BodyModel& m, const Eigen::VectorXd& theta) {
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(1);
  return modelgen::flipped_triangles(m, m.v_template, smpl::evaluate(m, betas, theta)).size();
}

TEST(PoseCorrectives, UnfoldTheBentElbowAndLeaveTheFarSkinAlone) {
  smpl::BodyModel m = tube();
  const double right = kPi / 2;
  // skinning alone folds the inner elbow, whichever way it bends
  ASSERT_GT(flipped(m, bend(1, {0, 0, right})), 0u);
  ASSERT_GT(flipped(m, bend(1, {0, -right, 0})), 0u);

  modelgen::PoseCorrectiveOptions o;
  o.rings = 8;
  modelgen::PoseCorrectiveReport r;
  m.posedirs = modelgen::pose_correctives(m, o, &r);
  ASSERT_EQ(m.posedirs.rows(), 3 * m.v_template.rows());
  ASSERT_EQ(m.posedirs.cols(), 18);
  ASSERT_EQ(r.joints.size(), 2u);
  EXPECT_EQ(r.joints[0].joint, 1);
  EXPECT_EQ(r.joints[0].samples, 18);  // 3 axes x 2 ways x the 3 default angles (45, 90, 110)
  EXPECT_GT(r.joints[0].folds_skinned, 0);
  EXPECT_LT(r.joints[0].folds_target, r.joints[0].folds_skinned);
  EXPECT_TRUE(r.joints[0].kept);
  EXPECT_GT(r.joints[0].largest_offset, 0.005);

  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1),
                                      Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)}) {
    for (const double deg : {45.0, 70.0, 90.0}) {
      EXPECT_EQ(flipped(m, bend(1, axis * deg * kPi / 180)), 0u) << axis.transpose() << " " << deg;
    }
  }
  // the shoulder's ring and the skin between the joints beyond the band: no offset
  for (const int v : {0, 5, 10 * kAround, 10 * kAround + 7}) {
    EXPECT_EQ(m.posedirs.row(3 * Eigen::Index{v}).norm(), 0.0) << v;
  }
  // the elbow's columns act on the elbow's band only; the wrist's on the wrist's
  const Eigen::Index at_elbow = Eigen::Index{30} * kAround, at_wrist = Eigen::Index{50} * kAround;
  EXPECT_GT(m.posedirs.block(3 * at_elbow, 0, 3, 9).norm(), 0.0);
  EXPECT_EQ(m.posedirs.block(3 * at_elbow, 9, 3, 9).norm(), 0.0);
  EXPECT_GT(m.posedirs.block(3 * at_wrist, 9, 3, 9).norm(), 0.0);
  // rounded to 2^-20 m
  int off_grid = 0;
  for (Eigen::Index i = 0; i < m.posedirs.size(); ++i) {
    const double scaled = std::ldexp(m.posedirs.data()[i], 20);
    off_grid += scaled != std::round(scaled) ? 1 : 0;
  }
  EXPECT_EQ(off_grid, 0);
}

TEST(PoseCorrectives, TheWristsBandReachesTheEndOfTheTubeAndTheHandStillFollowsIt) {
  smpl::BodyModel m = tube();
  modelgen::PoseCorrectiveOptions o;
  o.rings = 20;  // the wrist's band runs to the end cap: no skin beyond it is held
  m.posedirs = modelgen::pose_correctives(m, o);
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(1);
  const Eigen::VectorXd theta = bend(2, {0, 0, kPi / 2});
  const smpl::Body posed = smpl::evaluate(m, betas, theta);
  smpl::BodyModel plain = m;
  plain.posedirs.resize(plain.posedirs.rows(), 0);
  const smpl::Body skinned = smpl::evaluate(plain, betas, theta);
  // the end cap's centre is wholly on the wrist: it stays within 1 cm of where skinning puts it
  const int end = kRings * kAround + 1;
  EXPECT_LT((posed.vertices.row(end) - skinned.vertices.row(end)).norm(), 0.01);
  EXPECT_EQ(flipped(m, theta), 0u);
}

TEST(PoseCorrectives, SameBytesWithOneOrTwoThreads) {
  const smpl::BodyModel m = tube();
  modelgen::PoseCorrectiveOptions o;
  o.rings = 8;
  const Eigen::MatrixXd one = modelgen::pose_correctives(m, o);
  o.threads = 2;
  const Eigen::MatrixXd two = modelgen::pose_correctives(m, o);
  ASSERT_EQ(one.rows(), two.rows());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), sizeof(double) * one.size()), 0);
}

TEST(PoseCorrectives, FoldedTrianglesFollowTheBlendedRotation) {
  const smpl::BodyModel m = tube();
  const Eigen::VectorXd s = Eigen::VectorXd::Ones(m.num_vertices());
  const Eigen::Vector4d identity(1, 0, 0, 0);
  EXPECT_TRUE(modelgen::folded_triangles(m.v_template, m.v_template, m.faces, s, identity).empty());
  // the whole tube turned 180 degrees about its axis (x) with the rotation given: nothing folded
  const Eigen::Vector4d half_turn(0, 1, 0, 0);
  smpl::Vertices turned = m.v_template;
  turned.col(1) = -m.v_template.col(1);
  turned.col(2) = -m.v_template.col(2);
  EXPECT_TRUE(modelgen::folded_triangles(m.v_template, turned, m.faces, s, half_turn).empty());
  // the same turn with no rotation given (s = 0): every triangle of the side is folded (their
  // normals turned over), none of the caps (normals along the axis)
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(m.num_vertices());
  EXPECT_EQ(modelgen::folded_triangles(m.v_template, turned, m.faces, none, half_turn).size(),
            static_cast<std::size_t>(2 * (kRings - 1) * kAround));
  // a triangle collapsed to a point is folded
  smpl::Vertices collapsed = m.v_template;
  collapsed.row(m.faces(0, 1)) = collapsed.row(m.faces(0, 0));
  collapsed.row(m.faces(0, 2)) = collapsed.row(m.faces(0, 0));
  const std::vector<int> f =
      modelgen::folded_triangles(m.v_template, collapsed, m.faces, s, identity);
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(f.front(), 0);
}

}  // namespace
