// FBX export through Assimp, read back with Assimp: skeleton, vertex count, skinning weights,
// height, bind pose, unit scale, SMPL bone names; the repair of Assimp 5.2's nested null
// records; bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "caliper_test/files.hpp"
#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/fbx.hpp"
#include "smpl/io.hpp"

namespace {

namespace fs = std::filesystem;

// FBX stores vertices as double but Assimp's aiVector3D is float: 1 m rounds by 6e-8 m.
constexpr double kFloatTol = 2.5e-7;
// Each weight is stored as double, summed in float by Assimp: 24 terms of rounding 6e-8.
constexpr double kWeightSumTol = 1e-6;
// The bound on the height of the avatar read back.
constexpr double kHeightTol = 1e-3;

fs::path fbx_out_dir() {
  return caliper::test::output_dir(CALIPER_TEST_DATA_DIR, "fbx");
}

const smpl::BodyModel& open_female() {
  static const smpl::BodyModel m =
      smpl::load_model(std::string(CALIPER_ASSETS_DIR) + "/models/caliper-female.npz");
  return m;
}

using caliper::test::slurp;

// The bind joints of `read` in the order of `names` (Assimp lists bones by name).
smpl::Joints by_name(const smpl::FbxAvatar& read, const std::vector<std::string>& names) {
  smpl::Joints j = smpl::Joints::Constant(static_cast<Eigen::Index>(names.size()), 3, std::nan(""));
  for (size_t k = 0; k < names.size(); ++k) {
    const auto it = std::find(read.bone_names.begin(), read.bone_names.end(), names[k]);
    EXPECT_NE(it, read.bone_names.end()) << "no bone " << names[k];
    if (it != read.bone_names.end()) {
      j.row(static_cast<Eigen::Index>(k)) = read.bind_joints.row(it - read.bone_names.begin());
    }
  }
  return j;
}

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Vertices of `read` put back in the model's order through the faces (Assimp joins identical
// vertices in its own order but keeps the polygon order). Fails the test on a mismatch.
smpl::Vertices in_model_order(const smpl::FbxAvatar& read, const smpl::Faces& faces,
                              const smpl::Vertices& per_vertex) {
  // One row per model vertex (a textured model's file has more: it is split at its seams).
  smpl::Vertices v = smpl::Vertices::Constant(faces.maxCoeff() + 1, 3, std::nan(""));
  EXPECT_EQ(read.faces.rows(), faces.rows());
  for (Eigen::Index f = 0; f < std::min(read.faces.rows(), faces.rows()); ++f) {
    for (int i = 0; i < 3; ++i) v.row(faces(f, i)) = per_vertex.row(read.faces(f, i));
  }
  return v;
}
smpl::Vertices in_model_order(const smpl::FbxAvatar& read, const smpl::Faces& faces) {
  return in_model_order(read, faces, read.vertices);
}

TEST(Fbx, OpenModelReadsBackWith24BonesWeightsAndHeight) {
  const auto& m = open_female();
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(m.num_betas());
  betas[0] = 1.2;
  betas[1] = -0.8;
  betas[2] = 0.5;
  betas[3] = 0.3;
  const fs::path file = fbx_out_dir() / "open_female.fbx";
  smpl::ExportOptions o;
  o.extras = {{"model", m.meta.name}, {"open_model_sex", "female"}};
  smpl::write_fbx(file.string(), m, betas, o);

  const smpl::FbxAvatar a = smpl::read_fbx(file.string());
  ASSERT_EQ(a.bone_names.size(), 24u);
  EXPECT_EQ(sorted(a.bone_names), sorted(m.joint_names));
  // Identical vertices joined by Assimp: one per model vertex, plus the copies of a textured
  // model's texture seams, which join_seams joins.
  ASSERT_EQ(smpl::join_seams(a.vertices, a.faces).kept.size(),
            static_cast<size_t>(m.num_vertices()));
  ASSERT_EQ(a.faces.rows(), m.num_faces());
  for (Eigen::Index v = 0; v < a.weight_sums.size(); ++v) {
    ASSERT_NEAR(a.weight_sums[v], 1.0, kWeightSumTol) << "vertex " << v;
  }
  EXPECT_DOUBLE_EQ(a.unit_scale_factor, 100.0);       // metres, recorded
  ASSERT_EQ(a.metadata.count("open_model_sex"), 1u);  // the extras, as the mesh's properties
  EXPECT_EQ(a.metadata.at("open_model_sex"), "female");
  EXPECT_EQ(a.metadata.at("model"), m.meta.name);

  smpl::Body body = smpl::shape(m, betas);
  const double lift = -body.vertices.col(1).minCoeff();
  body.vertices.col(1).array() += lift;
  body.joints.col(1).array() += lift;
  const double height = body.vertices.col(1).maxCoeff() - body.vertices.col(1).minCoeff();
  const double read_height = a.vertices.col(1).maxCoeff() - a.vertices.col(1).minCoeff();
  EXPECT_NEAR(read_height, height, kHeightTol);
  EXPECT_NEAR(a.vertices.col(1).minCoeff(), 0.0, kFloatTol);  // stands on the floor
  // Every vertex where it was, and the bind pose at the rest joints.
  EXPECT_MATRIX_NEAR(in_model_order(a, m.faces), body.vertices, kFloatTol);
  EXPECT_MATRIX_NEAR(by_name(a, m.joint_names), body.joints, 1e-5);
  // Per-vertex normals, as libsmpl computes them (unit vectors stored as double, read as float).
  ASSERT_EQ(a.normals.rows(), a.vertices.rows());
  EXPECT_MATRIX_NEAR(in_model_order(a, m.faces, a.normals),
                     smpl::vertex_normals(body.vertices, m.faces), kFloatTol);
  std::printf("FBX: %zu bones, %lld vertices, height %.4f m (avatar %.4f m), unit scale %g\n",
              a.bone_names.size(), static_cast<long long>(a.vertices.rows()), read_height, height,
              a.unit_scale_factor);
}

TEST(Fbx, SmplBoneNamesAndAPose) {
  const auto m = caliper::test::make_random_model(10, 24, false, 31);
  const fs::path file = fbx_out_dir() / "smpl_names_posed.fbx";
  smpl::ExportOptions o;
  o.bone_names = smpl::BoneNames::Smpl;
  o.pose = Eigen::VectorXd::Zero(72);
  o.pose[3 * 16 + 2] = -0.9;  // left shoulder down about -Z: an A-pose
  o.pose[3 * 17 + 2] = 0.9;
  smpl::write_fbx(file.string(), m, Eigen::VectorXd::Zero(10), o);
  const smpl::FbxAvatar a = smpl::read_fbx(file.string());
  ASSERT_EQ(a.bone_names.size(), 24u);
  EXPECT_EQ(sorted(a.bone_names), sorted(smpl::smpl_fbx_bone_names()));
  // The pose is baked into mesh and skeleton alike: the bind joints are the posed joints and
  // the vertices the posed mesh (lifted by the rest pose's floor offset).
  const double lift = -smpl::shape(m, Eigen::VectorXd::Zero(10)).vertices.col(1).minCoeff();
  smpl::Body posed = smpl::evaluate(m, Eigen::VectorXd::Zero(10), o.pose);
  posed.joints.col(1).array() += lift;
  posed.vertices.col(1).array() += lift;
  EXPECT_MATRIX_NEAR(by_name(a, smpl::smpl_fbx_bone_names()), posed.joints, 1e-5);
  EXPECT_MATRIX_NEAR(in_model_order(a, m.faces), posed.vertices, kFloatTol);
}

// Runs tests/smpl/fbx_check.py (Blender's reading rules) on `file`; returns its exit status.
int blender_structure_check(const fs::path& file, std::string& output) {
  const std::string cmd = std::string("\"") + CALIPER_SYSTEM_PYTHON + "\" \"" +
                          CALIPER_TESTS_SOURCE_DIR + "/fbx_check.py\" \"" + file.string() +
                          "\" 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Fbx, EveryNestedListIsClosedAsBlenderRequires) {
  const auto m = caliper::test::make_random_model(10, 24, false, 34);
  const fs::path file = fbx_out_dir() / "structure.fbx";
  smpl::write_fbx(file.string(), m, Eigen::VectorXd::Zero(10));
  std::string output;
  EXPECT_EQ(blender_structure_check(file, output), 0) << output;
  EXPECT_NE(output.find("every nested list closed by a null record"), std::string::npos) << output;
  // The check can fail: a file cut short.
  const std::string bytes = slurp(file);
  const fs::path cut = fbx_out_dir() / "structure_cut.fbx";
  std::ofstream(cut, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  output.clear();
  EXPECT_EQ(blender_structure_check(cut, output), 1) << output;
}

// Sizes in binary FBX 7.5: the 27-byte file header, and a node record's header (end offset,
// property count, property bytes: 8 bytes each, then the 1-byte name length), which is also
// the size of a null record.
constexpr std::uint64_t kFileHeader = 27;
constexpr std::uint64_t kRecordHeader = 25;

// A binary FBX 7.5 file as Assimp 5.2 writes it: node "Objects" with one child "Model" and no
// null record closing the child list; then the top-level null record and a footer.
std::string fbx_without_nested_null_record() {
  auto u64 = [](std::uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); };
  std::string b = std::string("Kaydara FBX Binary  ") + '\0' + '\x1a' + '\0';
  const std::uint32_t version = 7500;
  b.append(reinterpret_cast<const char*>(&version), 4);
  const std::uint64_t child_at = kFileHeader + kRecordHeader + 7;
  const std::uint64_t child_end = child_at + kRecordHeader + 5;
  b += u64(child_end) + u64(0) + u64(0) + '\x07' + "Objects";  // ends with its child
  b += u64(child_end) + u64(0) + u64(0) + '\x05' + "Model";
  b.append(kRecordHeader, '\0');  // top-level null record
  b += std::string(16, '\xfa') + std::string(4, '\0');
  b.append(16 - b.size() % 16, '\0');  // padding to a multiple of 16
  b.append(reinterpret_cast<const char*>(&version), 4);
  b.append(120, '\0');
  b += std::string(16, '\xf8');
  return b;
}

TEST(Fbx, RepairAddsTheNullRecordsBlenderNeeds) {
  const std::string broken = fbx_without_nested_null_record();
  const fs::path before = fbx_out_dir() / "assimp52_like.fbx";
  std::ofstream(before, std::ios::binary)
      .write(broken.data(), static_cast<std::streamsize>(broken.size()));
  std::string output;
  EXPECT_EQ(blender_structure_check(before, output), 1) << output;
  EXPECT_NE(output.find("/Objects: the nested list does not end with a null record"),
            std::string::npos)
      << output;

  const std::string fixed = smpl::fix_fbx_null_records(broken);
  const fs::path after = fbx_out_dir() / "assimp52_like_fixed.fbx";
  std::ofstream(after, std::ios::binary)
      .write(fixed.data(), static_cast<std::streamsize>(fixed.size()));
  output.clear();
  EXPECT_EQ(blender_structure_check(after, output), 0) << output;
  EXPECT_NE(output.find("2 nodes, every nested list closed"), std::string::npos) << output;
  // The footer follows Objects, Model, the null record now closing Objects' list and the
  // top-level null record; it is padded to 16 bytes after its id, as the FBX SDK writes it.
  const size_t footer = kFileHeader + (kRecordHeader + 7) + (kRecordHeader + 5) + 2 * kRecordHeader;
  EXPECT_EQ(fixed.substr(footer, 16), std::string(16, '\xfa'));
  const size_t version_at = fixed.size() - 16 - 120 - 4;
  EXPECT_EQ(version_at % 16, 0u);
  EXPECT_GT(version_at, footer + 16 + 4);

  // Our own files already have them: the repair changes nothing.
  const auto m = caliper::test::make_random_model(2, 4, false, 32);
  const auto bytes = smpl::fbx_bytes(m, Eigen::VectorXd::Zero(2));
  const std::string s(bytes.begin(), bytes.end());
  EXPECT_EQ(smpl::fix_fbx_null_records(s), s);
  EXPECT_THROW(smpl::fix_fbx_null_records("not an fbx file at all, just some text......"),
               smpl::ModelError);
}

TEST(Fbx, ErrorsNameTheFile) {
  const auto m = caliper::test::make_random_model(2, 4, false, 33);
  try {
    smpl::write_fbx("/nonexistent-dir/a.fbx", m, Eigen::VectorXd::Zero(2));
    FAIL() << "writing into a missing folder succeeded";
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/a.fbx"), std::string::npos);
  }
  EXPECT_THROW(smpl::write_fbx((fbx_out_dir() / "a.glb").string(), m, Eigen::VectorXd::Zero(2)),
               smpl::ModelError);
  smpl::ExportOptions smpl_names;
  smpl_names.bone_names = smpl::BoneNames::Smpl;  // a 4-joint model has no SMPL names
  EXPECT_THROW(
      smpl::write_fbx((fbx_out_dir() / "x.fbx").string(), m, Eigen::VectorXd::Zero(2), smpl_names),
      smpl::ModelError);
  smpl::ExportOptions bad_pose;
  bad_pose.pose = Eigen::VectorXd::Zero(5);
  EXPECT_THROW(
      smpl::write_fbx((fbx_out_dir() / "x.fbx").string(), m, Eigen::VectorXd::Zero(2), bad_pose),
      smpl::ModelError);
  // A failed write leaves an existing file as it was.
  const fs::path keep = fbx_out_dir() / "keep.fbx";
  smpl::write_fbx(keep.string(), m, Eigen::VectorXd::Zero(2));
  const std::string before = slurp(keep);
  EXPECT_THROW(smpl::write_fbx(keep.string(), m, Eigen::VectorXd::Zero(2), bad_pose),
               smpl::ModelError);
  EXPECT_EQ(slurp(keep), before);
  const fs::path text = fbx_out_dir() / "text.fbx";
  std::ofstream(text) << "; FBX 7.5.0 project file\nnot really\n";
  EXPECT_THROW(smpl::read_fbx(text.string()), smpl::ModelError);
}

}  // namespace
