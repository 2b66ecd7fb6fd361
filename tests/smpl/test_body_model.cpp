// BodyModel validation: every malformed model is refused with a message naming the problem.
#include <gtest/gtest.h>

#include <limits>

#include "smpl/body_model.hpp"

namespace {

// A two-triangle, two-joint model: the smallest valid BodyModel.
smpl::BodyModel tiny_model() {
  smpl::BodyModel m;
  m.v_template.resize(4, 3);
  m.v_template << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.faces.resize(4, 3);
  m.faces << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  m.shapedirs = Eigen::MatrixXd::Zero(12, 2);
  m.parents = {-1, 0};
  m.joint_names = {"root", "child"};
  m.j_regressor.resize(2, 4);
  m.j_regressor.insert(0, 0) = 1.0;
  m.j_regressor.insert(1, 3) = 1.0;
  m.weights.resize(4, 2);
  for (int v = 0; v < 4; ++v) m.weights.insert(v, v == 3 ? 1 : 0) = 1.0;
  return m;
}

void expect_invalid(const smpl::BodyModel& m, const std::string& fragment) {
  try {
    smpl::validate(m, "tiny.npz");
    FAIL() << "expected a ModelError mentioning '" << fragment << "'";
  } catch (const smpl::ModelError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("tiny.npz"), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

TEST(BodyModel, TinyModelIsValid) {
  const auto m = tiny_model();
  EXPECT_NO_THROW(smpl::validate(m, "tiny.npz"));
  EXPECT_EQ(m.num_vertices(), 4);
  EXPECT_EQ(m.num_joints(), 2);
  EXPECT_EQ(m.num_betas(), 2);
  EXPECT_FALSE(m.has_pose_blend_shapes());
}

TEST(BodyModel, RefusesNaNInTemplate) {
  auto m = tiny_model();
  m.v_template(2, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_invalid(m, "NaN");
}

TEST(BodyModel, RefusesFaceIndexOutOfRange) {
  auto m = tiny_model();
  m.faces(1, 2) = 7;
  expect_invalid(m, "vertex 7");
}

TEST(BodyModel, RefusesWrongShapedirsRows) {
  auto m = tiny_model();
  m.shapedirs = Eigen::MatrixXd::Zero(11, 2);
  expect_invalid(m, "shapedirs");
}

TEST(BodyModel, RefusesWrongPosedirsShape) {
  auto m = tiny_model();
  m.posedirs = Eigen::MatrixXd::Zero(12, 8);
  expect_invalid(m, "(12, 9)");
}

TEST(BodyModel, RefusesChildBeforeParent) {
  auto m = tiny_model();
  m.parents = {-1, 1};
  expect_invalid(m, "parents must precede");
}

TEST(BodyModel, RefusesLandmarkOutOfRange) {
  auto m = tiny_model();
  m.landmarks["head_top"] = {42};
  expect_invalid(m, "head_top");
}

TEST(BodyModel, SmplSkeletonConstants) {
  ASSERT_EQ(smpl::smpl_joint_names().size(), 24u);
  ASSERT_EQ(smpl::smpl_parents().size(), 24u);
  EXPECT_EQ(smpl::smpl_joint_names()[15], "head");
  for (size_t k = 1; k < 24; ++k) EXPECT_LT(smpl::smpl_parents()[k], static_cast<int>(k));
}

}  // namespace
