// OBJ and PLY export and vertex normals.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "caliper_test/files.hpp"
#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/export.hpp"

namespace {

namespace fs = std::filesystem;

using caliper::test::slurp;

fs::path export_out_dir() {
  return caliper::test::output_dir(CALIPER_TEST_DATA_DIR, "export");
}

// A unit cube, 8 vertices, 12 outward triangles.
void cube(smpl::Vertices& v, smpl::Faces& f) {
  v.resize(8, 3);
  for (int i = 0; i < 8; ++i) v.row(i) = Eigen::RowVector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  f.resize(12, 3);
  f << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1,
      3, 5, 3, 7, 5;
}

TEST(Export, NormalsOfACubePointOutwardAlongTheDiagonals) {
  smpl::Vertices v;
  smpl::Faces f;
  cube(v, f);
  const smpl::Vertices n = smpl::vertex_normals(v, f);
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(n.row(i).norm(), 1.0, 1e-12);
    const Eigen::RowVector3d out = (v.row(i).array() - 0.5).matrix().normalized();
    EXPECT_GT(n.row(i).dot(out), 0.5) << "vertex " << i;  // outward, near the diagonal
  }
}

TEST(Export, NormalsOfTheRandomModelPointAwayFromItsAxis) {
  const auto m = caliper::test::make_random_model(1, 24, false);
  const smpl::Vertices n = smpl::vertex_normals(m.v_template, m.faces);
  int outward = 0;
  for (Eigen::Index i = 0; i < n.rows(); ++i) {
    Eigen::RowVector3d radial = m.v_template.row(i);
    radial.y() += 0.26;  // the ellipsoid's centre
    outward += n.row(i).dot(radial) > 0;
  }
  EXPECT_EQ(outward, n.rows());
}

TEST(Export, ObjHasVerticesNormalsAndOneBasedFaces) {
  smpl::Vertices v;
  smpl::Faces f;
  cube(v, f);
  const fs::path p = export_out_dir() / "cube.obj";
  smpl::write_obj(p.string(), v, f);
  std::ifstream in(p);
  std::string line;
  int nv = 0, nn = 0, nf = 0;
  smpl::Vertices back(8, 3);
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      s >> back(nv, 0) >> back(nv, 1) >> back(nv, 2);
      ++nv;
    }
    nn += tag == "vn";
    if (tag == "f") {
      std::string a;
      s >> a;
      EXPECT_EQ(a, std::to_string(f(nf, 0) + 1) + "//" + std::to_string(f(nf, 0) + 1));
      ++nf;
    }
  }
  EXPECT_EQ(nv, 8);
  EXPECT_EQ(nn, 8);
  EXPECT_EQ(nf, 12);
  EXPECT_MATRIX_NEAR(back, v, 0.0);
}

TEST(Export, PlyIsBinaryLittleEndianWithNormals) {
  const auto m = caliper::test::make_random_model(1, 24, false);
  const fs::path p = export_out_dir() / "model.ply";
  smpl::write_ply(p.string(), m.v_template, m.faces);
  const std::string bytes = slurp(p);
  const std::string end = "end_header\n";
  const size_t body = bytes.find(end) + end.size();
  constexpr size_t kVertexBytes = 24, kFaceBytes = 13;  // 6 floats; a count byte and 3 int32
  ASSERT_NE(bytes.find("format binary_little_endian 1.0"), std::string::npos);
  ASSERT_NE(bytes.find("element vertex 6890"), std::string::npos);
  ASSERT_NE(bytes.find("element face 13776"), std::string::npos);
  ASSERT_NE(bytes.find("property float nx"), std::string::npos);
  ASSERT_EQ(bytes.size(), body + 6890 * kVertexBytes + 13776 * kFaceBytes);
  // Vertex 100 and face 7 read back.
  float xyz[3];
  std::memcpy(xyz, bytes.data() + body + 100 * kVertexBytes, 12);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(xyz[c], static_cast<float>(m.v_template(100, c)));
  const size_t f7 = body + 6890 * kVertexBytes + 7 * kFaceBytes;
  EXPECT_EQ(bytes[f7], 3);
  std::int32_t ids[3];
  std::memcpy(ids, bytes.data() + f7 + 1, 12);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(ids[c], m.faces(7, c));
}

TEST(Export, ErrorsNameTheFile) {
  smpl::Vertices v;
  smpl::Faces f;
  cube(v, f);
  try {
    smpl::write_obj("/nonexistent-dir/x.obj", v, f);
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.obj"), std::string::npos);
  }
  f(3, 1) = 8;  // out of range
  EXPECT_THROW(smpl::write_ply((export_out_dir() / "bad.ply").string(), v, f), smpl::ModelError);
}

}  // namespace

namespace {

TEST(Export, CheckPoseWithAContextPrefixesTheMessage) {
  const auto m = caliper::test::make_random_model(1, 24, false);
  smpl::ExportOptions o;
  o.pose = Eigen::VectorXd::Zero(5);
  try {
    smpl::check_pose(m, o, "out.glb");
    ADD_FAILURE() << "a 5-number pose was accepted";
  } catch (const smpl::ModelError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("out.glb: the pose has 5 numbers", 0), 0u) << e.what();
  }
  o.pose = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(m.num_joints()));
  EXPECT_NO_THROW(smpl::check_pose(m, o, "out.glb"));
}

}  // namespace
