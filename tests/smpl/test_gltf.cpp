// glTF 2.0 export: round trips through read_gltf() and the Khronos glTF-Validator (npm
// gltf-validator, installed in tests/gltf by `npm ci`; CI installs it, so there it always runs).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper_test/files.hpp"
#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/gltf.hpp"

namespace {

namespace fs = std::filesystem;
using caliper::test::make_random_model;

// glTF stores float32: a coordinate of magnitude <= 2 m rounds by at most 2 * 2^-24 = 1.2e-7 m.
constexpr double kFloatTol = 2.5e-7;
// Renormalised weights are float32 in [0, 1]: rounding 6e-8, the sum fix-up adds one more ulp.
constexpr double kWeightTol = 2e-7;

using caliper::test::slurp;

fs::path gltf_out_dir() {
  return caliper::test::output_dir(CALIPER_TEST_DATA_DIR, "gltf");
}

const smpl::BodyModel& model24() {
  static const smpl::BodyModel m = make_random_model(10, 24, true, 11);
  return m;
}

// The 4 largest weights of each vertex, renormalised: what the exporter promises.
void expected_influences(const smpl::BodyModel& m, Eigen::Index v, std::vector<int>& ids,
                         std::vector<double>& w) {
  std::vector<std::pair<double, int>> row;
  for (smpl::SparseMatrix::InnerIterator it(m.weights, v); it; ++it) {
    if (it.value() > 0) row.emplace_back(it.value(), static_cast<int>(it.col()));
  }
  std::sort(row.begin(), row.end(), [](auto a, auto b) { return a.first > b.first; });
  row.resize(std::min<size_t>(4, row.size()));
  double sum = 0;
  for (auto& r : row) sum += r.first;
  ids.clear();
  w.clear();
  for (auto& r : row) {
    ids.push_back(r.second);
    w.push_back(r.first / sum);
  }
}

TEST(Gltf, GlbRoundTripGivesVerticesJointsAndWeights) {
  const auto& m = model24();
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.5, 5);
  const fs::path file = gltf_out_dir() / "rest.glb";
  smpl::GltfOptions opt;
  opt.extras = {{"height_m", "1.72"}, {"note", "test"}};
  smpl::write_gltf(file.string(), m, betas, opt);
  const smpl::GltfAvatar a = smpl::read_gltf(file.string());
  EXPECT_TRUE(a.warnings.empty());

  smpl::Body body = smpl::shape(m, betas);
  const double lift = -body.vertices.col(1).minCoeff();
  body.vertices.col(1).array() += lift;
  body.joints.col(1).array() += lift;
  EXPECT_MATRIX_NEAR(a.vertices, body.vertices, kFloatTol);
  EXPECT_MATRIX_NEAR(a.joints, body.joints, kFloatTol);
  EXPECT_NEAR(a.vertices.col(1).minCoeff(), 0.0, kFloatTol);  // stands on the floor
  EXPECT_EQ(a.faces, m.faces);
  EXPECT_EQ(a.joint_names, m.joint_names);
  EXPECT_EQ(a.parents, m.parents);
  EXPECT_TRUE(a.morph_targets.empty());
  EXPECT_NE(a.generator.find("Virtual Caliper"), std::string::npos);
  EXPECT_EQ(a.extras.at("height_m"), "1.72");
  EXPECT_EQ(a.extras.at("note"), "test");

  std::vector<int> ids;
  std::vector<double> w;
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v) {
    expected_influences(m, v, ids, w);
    double sum = 0;
    for (int i = 0; i < 4; ++i) sum += a.joint_weights(v, i);
    ASSERT_NEAR(sum, 1.0, kWeightTol) << "vertex " << v;
    for (size_t i = 0; i < ids.size(); ++i) {
      ASSERT_EQ(a.joint_ids(v, static_cast<Eigen::Index>(i)), ids[i]) << "vertex " << v;
      ASSERT_NEAR(a.joint_weights(v, static_cast<Eigen::Index>(i)), w[i], kWeightTol) << v;
    }
  }
}

TEST(Gltf, GlbBytesEqualTheGlbFile) {
  const auto& m = model24();
  const Eigen::VectorXd betas = caliper::test::random_betas(4, 1.0, 6);  // fewer than the model's
  const fs::path file = gltf_out_dir() / "bytes.glb";
  smpl::write_gltf(file.string(), m, betas);
  const std::string disk_s = slurp(file);
  const std::vector<std::uint8_t> disk(disk_s.begin(), disk_s.end());
  const auto mem = smpl::glb_bytes(m, betas);
  ASSERT_GT(mem.size(), 12u);
  EXPECT_EQ(mem, disk);
  EXPECT_EQ(std::string(mem.begin(), mem.begin() + 4), "glTF");
}

TEST(Gltf, PrecomputedSkinWeightsGiveTheSameBytes) {
  const auto& m = model24();
  const Eigen::VectorXd betas = caliper::test::random_betas(4, 1.0, 6);
  const smpl::GltfSkinWeights skin = smpl::gltf_skin_weights(m);
  ASSERT_EQ(skin.joints.size(), 4u * static_cast<size_t>(m.num_vertices()));
  smpl::GltfOptions o;
  o.skin_weights = &skin;
  EXPECT_EQ(smpl::glb_bytes(m, betas, o), smpl::glb_bytes(m, betas));
  smpl::GltfSkinWeights wrong = skin;
  wrong.weights.pop_back();
  o.skin_weights = &wrong;
  EXPECT_THROW(smpl::glb_bytes(m, betas, o), std::invalid_argument);
}

TEST(Gltf, GivenRestVerticesGiveTheSameBytesAndAreUsed) {
  const auto& m = model24();
  const Eigen::VectorXd betas = caliper::test::random_betas(4, 1.0, 6);
  const smpl::Vertices rest = smpl::shape(m, betas).vertices;
  smpl::GltfOptions o;
  o.rest_vertices = &rest;
  EXPECT_EQ(smpl::glb_bytes(m, betas, o), smpl::glb_bytes(m, betas));
  // They are what is written: moved vertices come back moved (and the joints with them).
  smpl::Vertices moved = rest;
  moved.col(0).array() += 0.25;
  o.rest_vertices = &moved;
  const auto bytes = smpl::glb_bytes(m, betas, o);
  const smpl::GltfAvatar a = smpl::read_gltf_from_memory(bytes.data(), bytes.size(), "moved.glb");
  smpl::Body body = smpl::shape(m, betas);
  body.vertices.col(0).array() += 0.25;
  body.joints.col(0).array() += 0.25;
  const double lift = -body.vertices.col(1).minCoeff();
  body.vertices.col(1).array() += lift;
  body.joints.col(1).array() += lift;
  EXPECT_MATRIX_NEAR(a.vertices, body.vertices, kFloatTol);
  EXPECT_MATRIX_NEAR(a.joints, body.joints, kFloatTol);
  const smpl::Vertices few = rest.topRows(rest.rows() - 1);
  o.rest_vertices = &few;
  EXPECT_THROW(smpl::glb_bytes(m, betas, o), std::invalid_argument);
}

TEST(Gltf, MorphTargetsArePoseCorrectives) {
  auto m = make_random_model(2, 4, true, 12);  // 4 joints: 27 targets keep the file small
  const fs::path file = gltf_out_dir() / "morph.glb";
  smpl::GltfOptions opt;
  opt.pose_correctives = true;
  opt.stand_on_floor = false;
  smpl::write_gltf(file.string(), m, Eigen::VectorXd::Zero(2), opt);
  const auto a = smpl::read_gltf(file.string());
  ASSERT_EQ(a.morph_targets.size(), 27u);
  EXPECT_MATRIX_NEAR(a.vertices, m.v_template, kFloatTol);  // no lift, no betas: the template
  for (size_t p = 0; p < 27; ++p) {
    const Eigen::VectorXd col = m.posedirs.col(static_cast<Eigen::Index>(p));
    const smpl::Vertices expected =
        Eigen::Map<const smpl::Vertices>(col.data(), m.num_vertices(), 3);
    ASSERT_MATRIX_NEAR(a.morph_targets[p], expected, 1e-9);  // |posedirs| ~ 1e-2: float ulp 1e-9
  }
}

TEST(Gltf, EmbeddedGltfRoundTrips) {
  const auto m = make_random_model(3, 55, false, 13);
  const Eigen::VectorXd betas = caliper::test::random_betas(3, 1.0, 7);
  const fs::path file = gltf_out_dir() / "smplx_like.gltf";
  smpl::write_gltf(file.string(), m, betas);
  const auto a = smpl::read_gltf(file.string());
  EXPECT_EQ(a.joints.rows(), 55);
  EXPECT_EQ(a.parents, m.parents);
  smpl::Body body = smpl::shape(m, betas);
  body.vertices.col(1).array() -= body.vertices.col(1).minCoeff();
  EXPECT_MATRIX_NEAR(a.vertices, body.vertices, kFloatTol);
  const std::string text = slurp(file);
  EXPECT_NE(text.find("data:application/octet-stream;base64,"), std::string::npos);
}

TEST(Gltf, ErrorsNameTheFile) {
  const auto& m = model24();
  EXPECT_THROW(
      smpl::write_gltf((gltf_out_dir() / "avatar.fbx").string(), m, Eigen::VectorXd::Zero(1)),
      smpl::ModelError);
  EXPECT_THROW(smpl::write_gltf("/nonexistent-dir/a.glb", m, Eigen::VectorXd::Zero(1)),
               smpl::ModelError);
  const fs::path bad = gltf_out_dir() / "truncated.glb";
  {
    const auto bytes = smpl::glb_bytes(m, Eigen::VectorXd::Zero(1));
    std::ofstream(bad, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), 1000);
  }
  try {
    smpl::read_gltf(bad.string());
    FAIL() << "a truncated GLB was accepted";
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated.glb"), std::string::npos) << e.what();
  }
  EXPECT_THROW(smpl::read_gltf((gltf_out_dir() / "missing.glb").string()), smpl::ModelError);
}

// Runs `node validate.mjs files...`; returns its exit status and output.
int run_validator(const std::vector<fs::path>& files, std::string& output) {
  std::string cmd =
      std::string("\"") + CALIPER_NODE + "\" \"" + CALIPER_GLTF_TOOLS_DIR + "/validate.mjs\"";
  for (const auto& f : files) cmd += " \"" + f.string() + "\"";
  cmd += " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) output.append(buf.data(), n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool validator_installed(std::string& why) {
  if (std::string(CALIPER_NODE).empty() ||
      std::string(CALIPER_NODE).find("NOTFOUND") != std::string::npos) {
    why = "node was not found at configure time (install nodejs: .ci/install-deps.sh)";
    return false;
  }
  if (!fs::exists(fs::path(CALIPER_GLTF_TOOLS_DIR) / "node_modules" / "gltf-validator")) {
    why = "tests/gltf/node_modules is missing: run `npm ci` in tests/gltf (.ci/install-deps.sh)";
    return false;
  }
  return true;
}

TEST(GltfValidator, ExportedAvatarsHaveNoErrors) {
  std::string why;
  if (!validator_installed(why)) GTEST_SKIP() << "Khronos glTF-Validator not installed: " << why;
  const auto& m = model24();
  const fs::path dir = gltf_out_dir() / "validator";
  fs::create_directories(dir);
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 2.0, 8);
  smpl::GltfOptions floor;
  floor.extras = {{"source", "test"}};
  smpl::GltfOptions morph;
  morph.pose_correctives = true;
  smpl::GltfOptions raw;
  raw.stand_on_floor = false;
  const std::vector<fs::path> files = {dir / "rest_floor.glb", dir / "rest_morph.glb",
                                       dir / "rest_raw.gltf", dir / "smplx_like.glb",
                                       dir / "mano_like.glb"};
  smpl::write_gltf(files[0].string(), m, betas, floor);
  smpl::write_gltf(files[1].string(), m, betas, morph);
  smpl::write_gltf(files[2].string(), m, betas, raw);
  // SMPL-X- and MANO-like skeletons with all their morph targets on smaller meshes (a full-size
  // 55-joint file with 486 targets would be 40 MB for no extra coverage).
  caliper::test::RandomModelOptions o;
  o.rings = o.segments = 30;
  o.num_joints = 55;
  o.seed = 21;
  smpl::write_gltf(files[3].string(), make_random_model(o), betas, morph);
  o.num_joints = 16;
  o.seed = 22;
  smpl::write_gltf(files[4].string(), make_random_model(o), betas, morph);
  std::string output;
  const int status = run_validator(files, output);
  EXPECT_EQ(status, 0) << output;
  for (const auto& f : files) {
    // Zero errors is the requirement; zero warnings holds today and keeps the files clean.
    EXPECT_NE(output.find(f.string() + ": errors=0 warnings=0 "), std::string::npos) << output;
  }
  RecordProperty("validator_report", output);
  std::printf("%s", output.c_str());
}

TEST(GltfValidator, CatchesABrokenFile) {
  std::string why;
  if (!validator_installed(why)) GTEST_SKIP() << "Khronos glTF-Validator not installed: " << why;
  // The validator must be able to fail: a GLB whose JSON chunk is cut short.
  const auto bytes = smpl::glb_bytes(model24(), Eigen::VectorXd::Zero(1));
  const fs::path bad = gltf_out_dir() / "validator_broken.glb";
  std::ofstream(bad, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), 200);
  std::string output;
  EXPECT_NE(run_validator({bad}, output), 0) << output;
}

}  // namespace
