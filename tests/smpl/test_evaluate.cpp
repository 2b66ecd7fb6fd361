// smpl::evaluate, smpl::shape, smpl::rodrigues: the independent numpy reference
// (tests/smpl/reference/smpl_reference.py, run by Debian's python3), invariants and analytic cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/constants.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/npz.hpp"

namespace {

namespace fs = std::filesystem;
using caliper::test::make_random_model;
using caliper::test::random_betas;
using caliper::test::random_pose;

using smpl::kPi;
// Double-precision agreement with the numpy reference (the requirement): both sides sum a few
// hundred products of O(1) numbers, so rounding differences are ~1e-14 m; 1e-9 m is the contract.
constexpr double kReferenceTol = 1e-9;
// The single-precision pose-blend-shape path: float rounding of posedirs (|entry| ~ 1e-2) and of
// the feature vector gives ~1e-9 m; the contract is 1e-6 m.
constexpr double kFloatPathTol = 1e-6;
// Identities that hold up to a few roundings of O(1) numbers.
constexpr double kRoundingTol = 1e-12;

struct Case {
  Eigen::VectorXd betas;
  Eigen::VectorXd pose;
  Eigen::Vector3d trans;
};

smpl::NpyArray reshaped(const Eigen::MatrixXd& m, std::vector<size_t> shape) {
  smpl::NpyArray a = smpl::make_npy(m);
  a.shape = std::move(shape);
  return a;
}

// Writes the model and the cases, runs the numpy reference, returns its output archive.
smpl::NpzArchive run_reference(const smpl::BodyModel& m, const std::vector<Case>& cases,
                               const std::string& name) {
  const fs::path dir = fs::path(CALIPER_TEST_DATA_DIR) / "reference";
  fs::create_directories(dir);
  const auto V = static_cast<size_t>(m.num_vertices());
  const auto K = static_cast<size_t>(m.num_joints());
  const auto B = static_cast<size_t>(m.num_betas());
  smpl::NpzArchive in;
  in["v_template"] = smpl::make_npy(m.v_template);
  in["shapedirs"] = reshaped(m.shapedirs, {V, 3, B});
  if (m.has_pose_blend_shapes()) {
    in["posedirs"] = reshaped(m.posedirs, {V, 3, static_cast<size_t>(m.num_pose_features())});
  }
  in["J_regressor"] = smpl::make_npy(Eigen::MatrixXd(m.j_regressor));
  in["weights"] = smpl::make_npy(Eigen::MatrixXd(m.weights));
  std::vector<std::int64_t> parents(m.parents.begin(), m.parents.end());
  in["parents"] = smpl::make_npy(parents, {K});
  Eigen::MatrixXd betas =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(cases.size()), m.num_betas());
  Eigen::MatrixXd poses(static_cast<Eigen::Index>(cases.size()), 3 * m.num_joints());
  Eigen::MatrixXd trans(static_cast<Eigen::Index>(cases.size()), 3);
  std::vector<std::int64_t> nbetas;
  for (size_t i = 0; i < cases.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    betas.row(r).head(cases[i].betas.size()) = cases[i].betas.transpose();
    nbetas.push_back(cases[i].betas.size());
    if (cases[i].pose.size()) {
      poses.row(r) = cases[i].pose.transpose();
    } else {
      poses.row(r).setZero();
    }
    trans.row(r) = cases[i].trans.transpose();
  }
  in["betas"] = smpl::make_npy(betas);
  in["nbetas"] = smpl::make_npy(nbetas, {cases.size()});
  in["poses"] = smpl::make_npy(poses);
  in["trans"] = smpl::make_npy(trans);
  const fs::path input = dir / (name + "_input.npz");
  const fs::path output = dir / (name + "_output.npz");
  smpl::write_npz(input.string(), in);
  fs::remove(output);
  const std::string cmd = std::string("\"") + CALIPER_SYSTEM_PYTHON + "\" \"" +
                          CALIPER_TESTS_SOURCE_DIR + "/reference/smpl_reference.py\" \"" +
                          input.string() + "\" \"" + output.string() + "\"";
  const int status = std::system(cmd.c_str());
  if (status != 0) throw std::runtime_error("the numpy reference failed: " + cmd);
  return smpl::read_npz(output.string());
}

// Row `i` of an (N, R, C) array as an R x C matrix.
Eigen::MatrixXd slice(const smpl::NpyArray& a, size_t i) {
  const std::vector<double> all = a.to_double();
  const size_t R = a.shape.at(1), C = a.size() / a.shape.at(0) / R;
  Eigen::MatrixXd m(static_cast<Eigen::Index>(R), static_cast<Eigen::Index>(C));
  for (size_t r = 0; r < R; ++r) {
    for (size_t c = 0; c < C; ++c) {
      m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = all[(i * R + r) * C + c];
    }
  }
  return m;
}

std::vector<Case> reference_cases(const smpl::BodyModel& m, std::uint64_t seed) {
  const int K = m.num_joints(), B = m.num_betas();
  std::vector<Case> cases;
  cases.reserve(7);  // 4 random, fewer betas, a sparse pose, the rest pose
  // Random betas and poses of growing amplitude, up to 3 pi (beyond the 2 pi wraparound).
  for (int i = 0; i < 4; ++i) {
    cases.push_back({random_betas(B, 2.0, seed + i),
                     random_pose(K, (i + 1) * 0.75 * kPi, seed + 10 + i),
                     Eigen::Vector3d(0.1 * i, -0.2, 0.3)});
  }
  // Fewer betas than the model has (the rest are zero).
  cases.push_back({random_betas(B / 2, 1.0, seed + 20), random_pose(K, 1.0, seed + 21),
                   Eigen::Vector3d::Zero()});
  // Some joints exactly at rest (their pose-blend-shape columns are skipped), tiny angles too.
  Eigen::VectorXd sparse_pose = random_pose(K, 2.0, seed + 22);
  for (int k = 0; k < K; k += 2) sparse_pose.segment<3>(3 * static_cast<Eigen::Index>(k)).setZero();
  sparse_pose.segment<3>(3) = Eigen::Vector3d(1e-9, -2e-9, 5e-10);
  cases.push_back({random_betas(B, 1.0, seed + 23), sparse_pose, Eigen::Vector3d(0, 1, 0)});
  // Rest pose (empty pose vector) with betas.
  cases.push_back({random_betas(B, 1.0, seed + 24), Eigen::VectorXd(), Eigen::Vector3d::Zero()});
  return cases;
}

void expect_matches_reference(const smpl::BodyModel& m, const std::string& name) {
  const auto cases = reference_cases(m, 100);
  const smpl::NpzArchive ref = run_reference(m, cases, name);
  smpl::Workspace ws, ws_float;
  ws_float.single_precision_pose_blend_shapes = true;
  smpl::Body body, body_float;
  double worst = 0.0, worst_float = 0.0;
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(name + " case " + std::to_string(i));
    smpl::evaluate(m, cases[i].betas, cases[i].pose, cases[i].trans, ws, body);
    const Eigen::MatrixXd rv = slice(ref.at("vertices"), i);
    const Eigen::MatrixXd rj = slice(ref.at("joints"), i);
    EXPECT_MATRIX_NEAR(body.vertices, rv, kReferenceTol);
    EXPECT_MATRIX_NEAR(body.joints, rj, kReferenceTol);
    const Eigen::MatrixXd rg = slice(ref.at("transforms"), i);  // K x 16, row-major 4x4 each
    for (int k = 0; k < m.num_joints(); ++k) {
      const Eigen::Matrix4d g =
          Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(rg.row(k).eval().data());
      ASSERT_MATRIX_NEAR(body.transforms[static_cast<size_t>(k)], g, kReferenceTol)
          << "joint " << k;
    }
    smpl::evaluate(m, cases[i].betas, cases[i].pose, cases[i].trans, ws_float, body_float);
    EXPECT_MATRIX_NEAR(body_float.vertices, rv, kFloatPathTol);
    worst = std::max({worst, (body.vertices - rv).cwiseAbs().maxCoeff(),
                      (body.joints - rj).cwiseAbs().maxCoeff()});
    worst_float = std::max(worst_float, (body_float.vertices - rv).cwiseAbs().maxCoeff());
    // The one-shot overload gives the same numbers as the workspace overload.
    const smpl::Body once = smpl::evaluate(m, cases[i].betas, cases[i].pose, cases[i].trans);
    EXPECT_MATRIX_NEAR(once.vertices, body.vertices, 0.0);
  }
  std::printf("%s: max |C++ - numpy| = %.3g m (double), %.3g m (float pose blend shapes)\n",
              name.c_str(), worst, worst_float);
}

TEST(EvaluateReference, MatchesNumpyFor24JointsFullSize) {
  expect_matches_reference(make_random_model(10, 24, true, 31), "smpl24");
}

TEST(EvaluateReference, MatchesNumpyFor300Betas) {
  caliper::test::RandomModelOptions o;
  o.num_betas = 300;
  o.rings = 40;  // 1602 vertices keep the 300-beta fixture small
  o.segments = 40;
  o.seed = 32;
  expect_matches_reference(make_random_model(o), "smpl24_300betas");
}

TEST(EvaluateReference, MatchesNumpyFor55Joints) {
  caliper::test::RandomModelOptions o;
  o.num_joints = 55;
  o.rings = 60;  // 3602 vertices, 486 pose features
  o.segments = 60;
  o.seed = 33;
  expect_matches_reference(make_random_model(o), "smplx55");
}

TEST(EvaluateReference, MatchesNumpyFor16JointsWithoutPoseBlendShapes) {
  caliper::test::RandomModelOptions o;
  o.num_joints = 16;
  o.pose_blend_shapes = false;
  o.rings = 20;
  o.segments = 20;
  o.seed = 34;
  expect_matches_reference(make_random_model(o), "mano16");
}

// ---- invariants --------------------------------------------------------------------------

const smpl::BodyModel& model() {
  static const smpl::BodyModel m = make_random_model(10, 24, true, 41);
  return m;
}

TEST(Evaluate, ZeroPoseAndZeroBetasGiveTheTemplate) {
  const auto& m = model();
  const auto a = smpl::evaluate(m, Eigen::VectorXd::Zero(10), Eigen::VectorXd::Zero(72));
  EXPECT_MATRIX_NEAR(a.vertices, m.v_template, kRoundingTol);
  const smpl::Joints j = m.j_regressor * m.v_template;
  EXPECT_MATRIX_NEAR(a.joints, j, kRoundingTol);
  const auto b = smpl::evaluate(m, Eigen::VectorXd(), Eigen::VectorXd());  // empty = rest
  EXPECT_MATRIX_NEAR(b.vertices, a.vertices, 0.0);
  const auto s = smpl::shape(m, Eigen::VectorXd());
  EXPECT_MATRIX_NEAR(s.vertices, m.v_template, 0.0);
}

TEST(Evaluate, ShapeEqualsRestPoseEvaluation) {
  const auto& m = model();
  const Eigen::VectorXd betas = random_betas(10, 2.0, 42);
  const auto s = smpl::shape(m, betas);
  const auto e = smpl::evaluate(m, betas, Eigen::VectorXd::Zero(72));
  EXPECT_MATRIX_NEAR(s.vertices, e.vertices, kRoundingTol);
  EXPECT_MATRIX_NEAR(s.joints, e.joints, kRoundingTol);
  for (int k = 0; k < 24; ++k) {
    EXPECT_MATRIX_NEAR(s.transforms[static_cast<size_t>(k)], e.transforms[static_cast<size_t>(k)],
                       kRoundingTol);
  }
}

TEST(Evaluate, MissingBetasAreZero) {
  const auto& m = model();
  const Eigen::VectorXd betas = random_betas(4, 1.0, 43);
  Eigen::VectorXd padded = Eigen::VectorXd::Zero(10);
  padded.head(4) = betas;
  const Eigen::VectorXd pose = random_pose(24, 1.0, 44);
  EXPECT_MATRIX_NEAR(smpl::evaluate(m, betas, pose).vertices,
                     smpl::evaluate(m, padded, pose).vertices, kRoundingTol);
  EXPECT_MATRIX_NEAR(smpl::shape(m, betas).joints, smpl::shape(m, padded).joints, kRoundingTol);
}

TEST(Evaluate, RootRotationRotatesEveryVertexRigidly) {
  const auto& m = model();
  const Eigen::VectorXd betas = random_betas(10, 1.0, 45);
  const Eigen::Vector3d root(0.3, -1.1, 0.7);
  Eigen::VectorXd pose = Eigen::VectorXd::Zero(72);
  pose.head<3>() = root;
  const auto rest = smpl::shape(m, betas);
  const auto posed = smpl::evaluate(m, betas, pose);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(root.norm(), root.normalized()).toRotationMatrix();
  const Eigen::RowVector3d j0 = rest.joints.row(0);
  const smpl::Vertices expected = ((rest.vertices.rowwise() - j0) * R.transpose()).rowwise() + j0;
  EXPECT_MATRIX_NEAR(posed.vertices, expected, kRoundingTol);
  const smpl::Joints expected_joints =
      ((rest.joints.rowwise() - j0) * R.transpose()).rowwise() + j0;
  EXPECT_MATRIX_NEAR(posed.joints, expected_joints, kRoundingTol);
}

TEST(Evaluate, TranslationIsAddedLast) {
  const auto& m = model();
  const Eigen::VectorXd betas = random_betas(10, 1.0, 46);
  const Eigen::VectorXd pose = random_pose(24, 1.5, 47);
  const Eigen::Vector3d t(0.5, -2.0, 3.25);
  const auto a = smpl::evaluate(m, betas, pose);
  const auto b = smpl::evaluate(m, betas, pose, t);
  EXPECT_MATRIX_NEAR(b.vertices, a.vertices.rowwise() + t.transpose(), kRoundingTol);
  EXPECT_MATRIX_NEAR(b.joints, a.joints.rowwise() + t.transpose(), kRoundingTol);
}

TEST(Evaluate, PoseChangesTheMeshAndPoseBlendShapesMatter) {
  const auto& m = model();
  const Eigen::VectorXd pose = random_pose(24, 1.0, 48);
  const auto a = smpl::evaluate(m, Eigen::VectorXd::Zero(10), pose);
  smpl::BodyModel no_correctives = m;
  no_correctives.posedirs.resize(0, 0);
  const auto b = smpl::evaluate(no_correctives, Eigen::VectorXd::Zero(10), pose);
  EXPECT_FALSE(caliper::test::matrices_near(a.vertices, b.vertices, 1e-4));
  EXPECT_FALSE(caliper::test::matrices_near(a.vertices, m.v_template, 1e-2));
}

TEST(Evaluate, WorkspaceGivesTheSameResultWhenReused) {
  const auto& m = model();
  smpl::Workspace ws;
  smpl::Body body;
  const Eigen::VectorXd betas = random_betas(10, 1.0, 49);
  const Eigen::VectorXd pose1 = random_pose(24, 1.0, 50), pose2 = random_pose(24, 2.0, 51);
  smpl::evaluate(m, betas, pose1, Eigen::Vector3d::Zero(), ws, body);
  smpl::evaluate(m, betas, pose2, Eigen::Vector3d::Zero(), ws, body);
  EXPECT_MATRIX_NEAR(body.vertices, smpl::evaluate(m, betas, pose2).vertices, 0.0);
}

TEST(Evaluate, WorkspaceBuffersStayPutAfterFirstUse) {
  const auto& m = model();
  for (bool single : {false, true}) {
    smpl::Workspace ws;
    ws.single_precision_pose_blend_shapes = single;
    smpl::Body body;
    smpl::evaluate(m, random_betas(10, 1.0, 52), random_pose(24, 1.0, 53), Eigen::Vector3d::Zero(),
                   ws, body);
    const void* ptrs[] = {ws.v_shaped.data(),   ws.pose_feature.data(), ws.rotations.data(),
                          ws.skinning.data(),   ws.rest_joints.data(),  ws.posedirs_f.data(),
                          body.vertices.data(), body.joints.data(),     body.transforms.data()};
    for (int i = 0; i < 5; ++i) {
      smpl::evaluate(m, random_betas(10, 1.0, 60 + i), random_pose(24, 2.0, 70 + i),
                     Eigen::Vector3d(i, 0, 0), ws, body);
    }
    const void* after[] = {ws.v_shaped.data(),   ws.pose_feature.data(), ws.rotations.data(),
                           ws.skinning.data(),   ws.rest_joints.data(),  ws.posedirs_f.data(),
                           body.vertices.data(), body.joints.data(),     body.transforms.data()};
    for (size_t i = 0; i < std::size(ptrs); ++i) EXPECT_EQ(ptrs[i], after[i]) << "buffer " << i;
  }
}

TEST(Evaluate, RejectsWrongSizes) {
  const auto& m = model();
  EXPECT_THROW(smpl::evaluate(m, Eigen::VectorXd::Zero(11), Eigen::VectorXd()),
               std::invalid_argument);
  EXPECT_THROW(smpl::shape(m, Eigen::VectorXd::Zero(11)), std::invalid_argument);
  EXPECT_THROW(smpl::evaluate(m, Eigen::VectorXd::Zero(10), Eigen::VectorXd::Zero(71)),
               std::invalid_argument);
}

// ---- Rodrigues ---------------------------------------------------------------------------

TEST(Rodrigues, ExactIdentityAndFiniteAtZero) {
  EXPECT_EQ(smpl::rodrigues(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
  const double tiny = std::numeric_limits<double>::denorm_min();
  const Eigen::Matrix3d R = smpl::rodrigues(Eigen::Vector3d(tiny, -tiny, tiny));
  EXPECT_TRUE(R.allFinite());
  EXPECT_MATRIX_NEAR(R, Eigen::Matrix3d::Identity(), 1e-300);
}

TEST(Rodrigues, SmallAnglesAreFirstOrderExact) {
  // R = I + [r]x + O(t^2): at t = 1e-10 the second-order term is 5e-21.
  const Eigen::Vector3d r(3e-11, -4e-11, 1.2e-10);
  Eigen::Matrix3d K;
  K << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  EXPECT_MATRIX_NEAR(smpl::rodrigues(r), Eigen::Matrix3d::Identity() + K, 1e-20);
}

TEST(Rodrigues, AgreesWithAngleAxisAcrossTheSeriesThreshold) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -2).normalized();
  for (double t : {1e-8, 1e-5, 9.99e-4, 1e-3, 1.001e-3, 0.1, 1.0, 3.0, kPi, 5.0, 7.0, 20.0}) {
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(t, axis).toRotationMatrix();
    const Eigen::Matrix3d R = smpl::rodrigues(t * axis);
    EXPECT_MATRIX_NEAR(R, expected, 4e-16 * std::max(1.0, t)) << "angle " << t;
    EXPECT_MATRIX_NEAR(R * R.transpose(), Eigen::Matrix3d::Identity(), 1e-15) << "angle " << t;
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
  }
}

TEST(Rodrigues, MinusQIsTheInverseAndTwoPiWrapsAround) {
  const Eigen::Vector3d q(0.4, -0.9, 1.3);
  const Eigen::Matrix3d R = smpl::rodrigues(q);
  EXPECT_MATRIX_NEAR(smpl::rodrigues(-q), R.transpose(), 1e-15);
  const Eigen::Vector3d wrapped = q + 2.0 * kPi * q.normalized();
  EXPECT_MATRIX_NEAR(smpl::rodrigues(wrapped), R, 1e-14);
  // The same rotation reached the other way round: angle t about k equals 2 pi - t about -k.
  const Eigen::Vector3d other = -(2.0 * kPi - q.norm()) * q.normalized();
  EXPECT_MATRIX_NEAR(smpl::rodrigues(other), R, 1e-14);
  // A half turn is symmetric: +pi and -pi about the same axis agree.
  const Eigen::Vector3d k = q.normalized();
  EXPECT_MATRIX_NEAR(smpl::rodrigues(kPi * k), smpl::rodrigues(-kPi * k), 1e-15);
}

}  // namespace
