// VRM 1.0 export: loaded by the reference loader @pixiv/three-vrm under Node (humanoid bones,
// meta, spec version, first-person split), checked by the Khronos glTF-Validator, read back;
// the licence rule; bad input. Also the glTF features every format shares: shape keys (morph
// targets against libsmpl's evaluation), SMPL bone names and a pose on the joints.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "node_tools.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace {

namespace fs = std::filesystem;
using caliper::test::node_tool_installed;
using caliper::test::run_node_tool;

// The bound for morphed vertices against libsmpl's evaluation. Float32 storage of base
// and targets (|x| <= 2 m, |shapedirs| ~ 0.05 m) and float morphing stay below 1e-6 m.
constexpr double kMorphTol = 1e-5;
constexpr double kVrmFloatTol = 2.5e-7;
// VRM's T-pose has the arms along X; the open models' rest pose is within 3 degrees of it
// (docs/file-formats.md says so), which this bound holds the exporter and the models to.
constexpr double kTPoseArmToleranceDeg = 3.0;

fs::path vrm_out_dir() {
  fs::path d = fs::path(CALIPER_TEST_DATA_DIR) / "vrm";
  fs::create_directories(d);
  return d;
}

// The model's vertices of a read-back avatar's per-vertex rows: a textured model is split at
// its texture seams on export (the model's vertices first, copies after them); joined again here.
smpl::Vertices model_rows(const smpl::GltfAvatar& a, const smpl::Vertices& per_vertex,
                          const smpl::BodyModel& m) {
  const smpl::SeamJoin j = smpl::join_seams(a.vertices, a.faces);
  EXPECT_EQ(j.faces, m.faces);
  smpl::Vertices out(static_cast<Eigen::Index>(j.kept.size()), 3);
  for (size_t k = 0; k < j.kept.size(); ++k) {
    out.row(static_cast<Eigen::Index>(k)) = per_vertex.row(j.kept[k]);
  }
  return out;
}

const smpl::BodyModel& open_male() {
  static const smpl::BodyModel m =
      smpl::load_model(std::string(CALIPER_ASSETS_DIR) + "/models/caliper-male.npz");
  return m;
}

Eigen::VectorXd some_betas(int n) {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  const double first[5] = {0.8, -1.1, 0.4, 0.9, -0.3};
  for (int i = 0; i < 5 && i < n; ++i) b[i] = first[i];
  return b;
}

// ---- VRM -------------------------------------------------------------------------------------

TEST(Vrm, ThreeVrmLoadsItWithEveryRequiredBoneMetaAndSpecVersion) {
  std::string why;
  if (!node_tool_installed(CALIPER_VRM_TOOLS_DIR, "@pixiv/three-vrm", why))
    GTEST_SKIP() << "three-vrm not installed: " << why;
  const auto& m = open_male();
  const fs::path file = vrm_out_dir() / "open_male.vrm";
  smpl::ExportOptions o;
  o.name = "test avatar";
  o.author = "ctest";
  smpl::write_vrm(file.string(), m, some_betas(m.num_betas()), o);
  std::string output;
  const int status = run_node_tool(CALIPER_VRM_TOOLS_DIR, "load_vrm.mjs", {file}, output);
  std::printf("%s", output.c_str());
  RecordProperty("three_vrm_report", output);
  ASSERT_EQ(status, 0) << output;
  auto has = [&](const std::string& s) { return output.find(s) != std::string::npos; };
  EXPECT_TRUE(has("\"specVersion\":\"1.0\"")) << output;
  EXPECT_TRUE(has("\"metaVersion\":\"1\"")) << output;
  EXPECT_TRUE(has("\"missingRequired\":[]")) << output;
  EXPECT_TRUE(has("\"name\":\"test avatar\"")) << output;
  EXPECT_TRUE(has("\"authors\":[\"ctest\"]")) << output;
  EXPECT_TRUE(has("\"licenseUrl\":\"https://vrm.dev/licenses/1.0/\"")) << output;
  EXPECT_TRUE(has("\"otherLicenseUrl\":\"https://opensource.org/license/mit/\"")) << output;
  EXPECT_TRUE(has("The Virtual Caliper")) << output;  // generator
  for (const char* bone :
       {"hips", "spine", "chest", "upperChest", "neck", "head", "leftShoulder", "rightShoulder",
        "leftUpperArm", "rightLowerArm", "leftHand", "rightUpperLeg", "leftFoot", "rightToes"}) {
    EXPECT_TRUE(has(std::string("\"") + bone + "\"")) << bone << "\n" << output;
  }
  // First person hides the head: fewer triangles in the first-person copy than in the body.
  const size_t fp = output.find("\"trianglesFirstPerson\":");
  const size_t tp = output.find("\"trianglesThirdPerson\":");
  ASSERT_NE(fp, std::string::npos);
  ASSERT_NE(tp, std::string::npos);
  const long first = std::stol(output.substr(fp + 23));
  const long third = std::stol(output.substr(tp + 23));
  EXPECT_GT(first, 0);
  EXPECT_LT(first, third) << output;
}

TEST(Vrm, ValidatorReportsNoErrorsAndItReadsBackAsTheAvatar) {
  const auto& m = open_male();
  const Eigen::VectorXd betas = some_betas(m.num_betas());
  const fs::path file = vrm_out_dir() / "validate.vrm";
  smpl::ExportOptions o;
  o.shape_keys = 4;
  smpl::write_vrm(file.string(), m, betas, o);
  const smpl::GltfAvatar a = smpl::read_gltf(file.string());
  smpl::Body body = smpl::shape(m, betas);
  body.vertices.col(1).array() -= body.vertices.col(1).minCoeff();
  Eigen::VectorXd w = betas.head(4);
  smpl::Vertices morphed = a.vertices;
  for (int b = 0; b < 4; ++b) morphed += w[b] * a.morph_targets[static_cast<size_t>(b)];
  EXPECT_MATRIX_NEAR(model_rows(a, morphed, m), body.vertices, kMorphTol);
  // VRM T-pose: the arms (shoulder to wrist) run along X within a few degrees of horizontal.
  auto joint = [&](const char* name) {
    const auto it = std::find(a.joint_names.begin(), a.joint_names.end(), name);
    EXPECT_NE(it, a.joint_names.end()) << name;
    return Eigen::RowVector3d(a.joints.row(it - a.joint_names.begin()));
  };
  for (const auto& [shoulder, wrist] :
       {std::pair{"left_shoulder", "left_wrist"}, std::pair{"right_shoulder", "right_wrist"}}) {
    const Eigen::RowVector3d d = joint(wrist) - joint(shoulder);
    const double degrees = std::atan2(std::hypot(d.y(), d.z()), std::abs(d.x())) * 180.0 / M_PI;
    EXPECT_LT(degrees, kTPoseArmToleranceDeg) << shoulder;
    std::printf("%s to %s: %.2f degrees off the X axis\n", shoulder, wrist, degrees);
  }
  EXPECT_NEAR(morphed.col(1).minCoeff(), 0.0, kMorphTol);  // feet on y = 0 (as shown)

  std::string why;
  if (!node_tool_installed(CALIPER_GLTF_TOOLS_DIR, "gltf-validator", why))
    GTEST_SKIP() << "Khronos glTF-Validator not installed: " << why;
  std::string output;
  EXPECT_EQ(run_node_tool(CALIPER_GLTF_TOOLS_DIR, "validate.mjs", {file}, output), 0) << output;
  EXPECT_NE(output.find(file.string() + ": errors=0 "), std::string::npos) << output;
  std::printf("%s", output.c_str());
}

TEST(Vrm, AModelWithoutALicenceIsRefusedUntilTheUserStatesOne) {
  auto m = caliper::test::make_random_model(10, 24, false, 41);  // like a user's SMPL file
  m.meta.name = "SMPL_FEMALE";
  m.meta.extra.erase("licence");
  const fs::path file = vrm_out_dir() / "smpl_user.vrm";
  fs::remove(file);
  try {
    smpl::write_vrm(file.string(), m, Eigen::VectorXd::Zero(10));
    FAIL() << "a model without a licence was exported to VRM";
  } catch (const smpl::ModelError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("licence"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--licence"), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(file));
  smpl::ExportOptions o;
  o.licence = "https://smpl.is.tue.mpg.de/modellicense.html";
  smpl::write_vrm(file.string(), m, Eigen::VectorXd::Zero(10), o);
  EXPECT_TRUE(fs::exists(file));
}

TEST(Vrm, RefusesAPoseAndAModelWithoutHumanoidJoints) {
  const auto& m = open_male();
  smpl::ExportOptions posed;
  posed.pose = Eigen::VectorXd::Zero(72);
  EXPECT_THROW(smpl::write_vrm((vrm_out_dir() / "posed.vrm").string(), m, Eigen::VectorXd(), posed),
               smpl::ModelError);
  auto hand = caliper::test::make_random_model(2, 16, false, 42);  // MANO-like: no humanoid
  smpl::ExportOptions o;
  o.licence = "MIT";
  EXPECT_THROW(smpl::write_vrm((vrm_out_dir() / "hand.vrm").string(), hand, Eigen::VectorXd(), o),
               smpl::ModelError);
}

// ---- Shape keys, bone names, pose (glTF) -----------------------------------------------------

TEST(GltfShapeKeys, MorphWeightsSetToOtherBetasGiveLibsmplsBody) {
  const auto& m = open_male();
  const Eigen::VectorXd betas = some_betas(m.num_betas());
  const int N = 8;
  const fs::path file = vrm_out_dir() / "shape_keys.glb";
  smpl::ExportOptions o;
  o.shape_keys = N;
  smpl::write_gltf(file.string(), m, betas, o);
  const smpl::GltfAvatar a = smpl::read_gltf(file.string());
  ASSERT_EQ(a.morph_targets.size(), static_cast<size_t>(N));
  const double lift = -smpl::shape(m, betas).vertices.col(1).minCoeff();
  // Other betas for the first N components (the rest stay the avatar's, baked in).
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd other = betas;
    other.head(N) = caliper::test::random_betas(N, 2.0, 100 + static_cast<std::uint64_t>(trial));
    smpl::Vertices morphed = a.vertices;
    for (int b = 0; b < N; ++b) morphed += other[b] * a.morph_targets[static_cast<size_t>(b)];
    smpl::Vertices expected = smpl::shape(m, other).vertices;
    expected.col(1).array() += lift;
    EXPECT_MATRIX_NEAR(model_rows(a, morphed, m), expected, kMorphTol);
  }
  // Default weights: the avatar as made.
  smpl::Vertices as_made = a.vertices;
  for (int b = 0; b < N; ++b) as_made += betas[b] * a.morph_targets[static_cast<size_t>(b)];
  smpl::Vertices body = smpl::shape(m, betas).vertices;
  body.col(1).array() += lift;
  EXPECT_MATRIX_NEAR(model_rows(a, as_made, m), body, kMorphTol);

  smpl::ExportOptions too_many;
  too_many.shape_keys = m.num_betas() + 1;
  EXPECT_THROW(smpl::write_gltf((vrm_out_dir() / "x.glb").string(), m, betas, too_many),
               smpl::ModelError);

  std::string why;
  if (!node_tool_installed(CALIPER_GLTF_TOOLS_DIR, "gltf-validator", why))
    GTEST_SKIP() << "Khronos glTF-Validator not installed: " << why;
  std::string output;
  EXPECT_EQ(run_node_tool(CALIPER_GLTF_TOOLS_DIR, "validate.mjs", {file}, output), 0) << output;
  EXPECT_NE(output.find(file.string() + ": errors=0 warnings=0 "), std::string::npos) << output;
  EXPECT_NE(fs::file_size(file), 0u);
}

TEST(GltfShapeKeys, TargetNamesAndDefaultWeightsAreInTheFile) {
  const auto& m = open_male();
  const Eigen::VectorXd betas = some_betas(m.num_betas());
  smpl::ExportOptions o;
  o.shape_keys = 3;
  const auto bytes = smpl::glb_bytes(m, betas, o);
  const std::string s(bytes.begin(), bytes.end());
  EXPECT_NE(s.find("\"targetNames\":[\"beta_00\",\"beta_01\",\"beta_02\"]"), std::string::npos);
  EXPECT_NE(s.find("\"weights\":[0.8"), std::string::npos);
}

TEST(GltfBoneNames, SmplNamesAndAPoseOnTheJoints) {
  const auto& m = open_male();
  smpl::ExportOptions o;
  o.bone_names = smpl::BoneNames::Smpl;
  o.pose = Eigen::VectorXd::Zero(72);
  o.pose[3 * 16 + 2] = -0.8;  // A-pose: shoulders rotated down
  o.pose[3 * 17 + 2] = 0.8;
  const fs::path file = vrm_out_dir() / "smpl_names_apose.glb";
  smpl::write_gltf(file.string(), m, Eigen::VectorXd(), o);
  const smpl::GltfAvatar a = smpl::read_gltf(file.string());
  EXPECT_EQ(a.joint_names, smpl::smpl_fbx_bone_names());
  // POSITION is the bind (rest) pose; the posed joints are where libsmpl puts them.
  smpl::Body rest = smpl::shape(m, Eigen::VectorXd());
  const double lift = -rest.vertices.col(1).minCoeff();
  rest.vertices.col(1).array() += lift;
  EXPECT_MATRIX_NEAR(model_rows(a, a.vertices, m), rest.vertices, kVrmFloatTol);
  smpl::Body posed = smpl::evaluate(m, Eigen::VectorXd(), o.pose);
  posed.joints.col(1).array() += lift;
  EXPECT_MATRIX_NEAR(a.joints, posed.joints, 1e-6);

  std::string why;
  if (!node_tool_installed(CALIPER_GLTF_TOOLS_DIR, "gltf-validator", why))
    GTEST_SKIP() << "Khronos glTF-Validator not installed: " << why;
  std::string output;
  EXPECT_EQ(run_node_tool(CALIPER_GLTF_TOOLS_DIR, "validate.mjs", {file}, output), 0) << output;
  EXPECT_NE(output.find(file.string() + ": errors=0 warnings=0 "), std::string::npos) << output;
}

}  // namespace
