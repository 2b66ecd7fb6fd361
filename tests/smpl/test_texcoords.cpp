// Texture coordinates in every export (issue 11): GLB/glTF/VRM TEXCOORD_0 with the mesh split at
// seams at export time, FBX UV channel 0 (through Assimp), OBJ `vt` with per-corner indices, read
// back by read_gltf() and by Assimp (smpl::read_with_assimp); models without texture coordinates
// export the same bytes as before the feature.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "caliper_test/files.hpp"
#include "caliper_test/random_model.hpp"
#include "node_tools.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"
#include "smpl/mesh_read.hpp"

namespace {

namespace fs = std::filesystem;

// Texture coordinates read back: the bound for every format. The test's coordinates are
// multiples of 1/128, which float32 and %.9g hold exactly, so any difference is a wrong corner.
constexpr double kUvTol = 1e-6;
// Positions stored as float32: a coordinate of magnitude <= 2 m rounds by at most 1.2e-7 m.
constexpr double kTexFloatTol = 2.5e-7;
// Morph targets are float32 displacements of at most a few centimetres.
constexpr double kTexMorphTol = 1e-8;
// Renormalised skin weights are float32 in [0, 1]; FBX keeps every weight as float32.
constexpr double kWeightTol = 2e-7;

using caliper::test::slurp;

fs::path texcoords_out_dir() {
  return caliper::test::output_dir(CALIPER_TEST_DATA_DIR, "texcoords");
}

// FNV-1a, 64 bits: a fingerprint of a file's bytes.
std::uint64_t fnv1a(const std::string& bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

// A small 24-joint model with pose blend shapes and no texture coordinates.
smpl::BodyModel plain_model() {
  caliper::test::RandomModelOptions o;
  o.num_betas = 4;
  o.rings = 12;
  o.segments = 10;
  o.seed = 31;
  smpl::BodyModel m = caliper::test::make_random_model(o);
  m.meta.extra["licence"] = "MIT";
  return m;
}

// Models without texture coordinates (SMPL's own files, the first open models) export exactly the
// bytes they did before texture coordinates were exported: the fingerprints below were taken
// from the exporters of main at c8545f7 (before this feature) with this model and these options.
// FBX is compared without its time of export, which Assimp writes into the file.
TEST(Texcoords, ModelWithoutThemExportsTheSameBytesAsBefore) {
  const smpl::BodyModel m = plain_model();
  ASSERT_FALSE(m.has_uvs());
  Eigen::VectorXd betas(4);
  betas << 0.5, -1.0, 0.25, 1.5;
  smpl::ExportOptions o;
  o.extras = {{"model", "plain"}};
  o.shape_keys = 2;
  o.pose_correctives = true;
  smpl::ExportOptions mesh_o;
  mesh_o.extras = o.extras;
  struct Case {
    const char* file;
    const smpl::ExportOptions* options;
    std::uint64_t expected;
  };
  // glTF/GLB/VRM: unsigned short indices since issue 14 (a mesh with fewer than 65,535
  // vertices); with unsigned int indices forced the bytes hash to the old 0xd8798cda8eeab3b1 /
  // 0xbdcbb202611f9317 / 0xe3d000d418bfaf85.
  const std::vector<Case> cases = {{"plain.glb", &o, 0x5c4a3af4e652f56eull},
                                   {"plain.gltf", &o, 0x739ad195965a65e1ull},
                                   {"plain.vrm", &mesh_o, 0x4fcb0e04cf9277e5ull},
                                   // OBJ/PLY: the metadata comment is nlohmann-json's compact
                                   // {"model":"plain"} since issue 15 (was {"model": "plain"};
                                   // with those two spaces put back the bytes hash to the old
                                   // 0xd6e68e6807d173a2 / 0x3a1e2f26fe249ba2).
                                   {"plain.obj", &mesh_o, 0xad1b99881de027f8ull},
                                   {"plain.ply", &mesh_o, 0x5b67a489a4286596ull}};
  for (const auto& c : cases) {
    const fs::path file = texcoords_out_dir() / c.file;
    smpl::export_avatar(file.string(), m, betas, *c.options);
    const std::uint64_t h = fnv1a(slurp(file));
    EXPECT_EQ(h, c.expected) << c.file << std::hex << ": 0x" << h;
  }
  // FBX: the same bytes apart from the time of export (the CreationTimeStamp node, up to the
  // Creator node that follows it), which is blanked before the fingerprint.
  const fs::path fbx = texcoords_out_dir() / "plain.fbx";
  smpl::export_avatar(fbx.string(), m, betas, mesh_o);
  std::string bytes = slurp(fbx);
  const size_t stamp = bytes.find("CreationTimeStamp");
  ASSERT_NE(stamp, std::string::npos);
  const size_t creator = bytes.find("Creator", stamp);
  ASSERT_NE(creator, std::string::npos);
  std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(stamp),
            bytes.begin() + static_cast<std::ptrdiff_t>(creator), '\0');
  const std::uint64_t h = fnv1a(bytes);
  EXPECT_EQ(h, 0xa8dc96fcd82cb31eull) << "plain.fbx" << std::hex << ": 0x" << h;
}

// plain_model() with texture coordinates and seams: corner c of face f normally uses coordinate
// faces(f, c) (one per vertex); the corners of every 7th face and of every face touching vertex 0
// get coordinates of their own (V + 3 f + c) instead, so those vertices lie on seams, and vertex
// 0 on several. Coordinates are multiples of 1/128 in [0, 1).
smpl::BodyModel textured_model() {
  smpl::BodyModel m = plain_model();
  const Eigen::Index V = m.num_vertices(), F = m.num_faces();
  m.uvs.resize(V + 3 * F, 2);
  for (Eigen::Index i = 0; i < m.uvs.rows(); ++i) {
    m.uvs.row(i) << static_cast<double>(i % 128) / 128.0,
        static_cast<double>((i / 128) % 128) / 128.0;
  }
  m.uv_faces = m.faces;
  for (Eigen::Index f = 0; f < F; ++f) {
    if (f % 7 == 0 || (m.faces.row(f).array() == 0).any()) {
      for (int c = 0; c < 3; ++c) m.uv_faces(f, c) = static_cast<int>(V + 3 * f + c);
    }
  }
  smpl::validate(m, "textured_model");
  return m;
}

// Distinct (vertex, texture coordinate) pairs of the model's corners: the vertex count of a file
// split at the seams.
size_t corner_pairs(const smpl::BodyModel& m) {
  std::set<std::pair<int, int>> pairs;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) pairs.emplace(m.faces(f, c), m.uv_faces(f, c));
  }
  return pairs.size();
}

// Distinct positions among `v`'s rows: a mesh split at seams is still welded in positions when
// this equals the model's vertex count (the test model has no two vertices at one place).
size_t unique_positions(const smpl::Vertices& v) {
  std::set<std::tuple<double, double, double>> s;
  for (Eigen::Index i = 0; i < v.rows(); ++i) s.emplace(v(i, 0), v(i, 1), v(i, 2));
  return s.size();
}

// The length of the first array property of the binary FBX node `name` (e.g. the doubles of
// "Vertices", 3 per control point), or -1. Array properties start with their type ('d', 'i',
// ...) and a uint32 element count, whether or not they are compressed.
long fbx_array_length(const std::string& bytes, const std::string& name) {
  const size_t at = bytes.find(std::string(1, static_cast<char>(name.size())) + name);
  if (at == std::string::npos || at + 1 + name.size() + 5 > bytes.size()) return -1;
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + at + 1 + name.size() + 1, 4);
  return static_cast<long>(n);
}

Eigen::VectorXd test_betas() {
  Eigen::VectorXd b(4);
  b << 0.5, -1.0, 0.25, 1.5;
  return b;
}

// Checks, corner by corner, that a file's mesh (`faces` into `vertices` and `uvs`) is the model's
// avatar `body` with the model's texture coordinates.
void expect_corners(const smpl::BodyModel& m, const smpl::Vertices& body, const smpl::Faces& faces,
                    const smpl::Vertices& vertices, const smpl::TexCoords& uvs,
                    const std::string& what) {
  ASSERT_EQ(faces.rows(), m.num_faces()) << what;
  ASSERT_EQ(uvs.rows(), vertices.rows()) << what;
  double worst_uv = 0.0, worst_pos = 0.0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int out = faces(f, c);
      worst_uv =
          std::max(worst_uv, (uvs.row(out) - m.uvs.row(m.uv_faces(f, c))).cwiseAbs().maxCoeff());
      worst_pos =
          std::max(worst_pos, (vertices.row(out) - body.row(m.faces(f, c))).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst_uv, kUvTol) << what;
  EXPECT_LE(worst_pos, kTexFloatTol) << what;
}

TEST(Texcoords, SplitAtSeamsCopiesVerticesOnlyWhereCornersDiffer) {
  const smpl::BodyModel m = textured_model();
  const Eigen::Index V = m.num_vertices();
  const smpl::SeamSplit s = smpl::split_at_seams(m, "test");
  ASSERT_GT(corner_pairs(m), static_cast<size_t>(V));  // the model has seams
  ASSERT_EQ(s.source.size(), corner_pairs(m));
  ASSERT_EQ(s.uvs.rows(), static_cast<Eigen::Index>(s.source.size()));
  for (Eigen::Index v = 0; v < V; ++v) ASSERT_EQ(s.source[static_cast<size_t>(v)], v);
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int out = s.faces(f, c);
      ASSERT_EQ(s.source[static_cast<size_t>(out)], m.faces(f, c));
      ASSERT_EQ(s.uvs.row(out), m.uvs.row(m.uv_faces(f, c)));
      ASSERT_TRUE(out == m.faces(f, c) || out >= V);  // a vertex keeps its index where it can
    }
  }
  // Without texture coordinates: the model's own mesh.
  const smpl::SeamSplit plain = smpl::split_at_seams(plain_model(), "test");
  EXPECT_EQ(plain.source.size(), static_cast<size_t>(V));
  EXPECT_EQ(plain.faces, plain_model().faces);
  EXPECT_EQ(plain.uvs.rows(), 0);
  // Texture-coordinate faces that do not fit are refused, naming the context.
  smpl::BodyModel bad = textured_model();
  bad.uv_faces(3, 2) = static_cast<int>(bad.uvs.rows());
  EXPECT_THROW(smpl::split_at_seams(bad, "bad"), smpl::ModelError);
  bad = textured_model();
  bad.uv_faces.conservativeResize(bad.num_faces() - 1, 3);
  EXPECT_THROW(smpl::split_at_seams(bad, "bad"), smpl::ModelError);
  bad = textured_model();
  bad.uvs(5, 1) = std::nan("");
  try {
    smpl::split_at_seams(bad, "bad.glb");
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.glb"), std::string::npos) << e.what();
  }
}

// GLB, glTF and VRM: TEXCOORD_0 on the split vertices, read back by read_gltf and by Assimp;
// every copy carries its vertex's position, influences and morph-target displacements; the
// mesh stays welded in positions; the Khronos validator reports no errors.
TEST(Texcoords, GltfAndVrmCarryTexcoord0SplitAtSeams) {
  const smpl::BodyModel m = textured_model();
  const Eigen::Index V = m.num_vertices();
  const Eigen::VectorXd betas = test_betas();
  smpl::Vertices body = smpl::shape(m, betas).vertices;
  body.col(1).array() -= body.col(1).minCoeff();
  const smpl::GltfSkinWeights skin = smpl::gltf_skin_weights(m);
  std::vector<fs::path> files;
  for (const char* name : {"textured.glb", "textured.gltf", "textured.vrm"}) {
    const fs::path file = texcoords_out_dir() / name;
    files.push_back(file);
    smpl::ExportOptions o;
    o.shape_keys = 2;
    o.pose_correctives = fs::path(name).extension() != ".vrm";
    smpl::export_avatar(file.string(), m, betas, o);
    const smpl::GltfAvatar a = smpl::read_gltf(file.string());
    EXPECT_TRUE(a.warnings.empty()) << name;
    ASSERT_EQ(a.vertices.rows(), static_cast<Eigen::Index>(corner_pairs(m))) << name;
    // POSITION holds the body without its shape keys; their default weights add them back.
    smpl::Vertices shown = a.vertices;
    for (int b = 0; b < 2; ++b)
      shown += a.morph_weights[static_cast<size_t>(b)] * a.morph_targets[static_cast<size_t>(b)];
    expect_corners(m, body, a.faces, shown, a.texcoords, name);
    EXPECT_EQ(unique_positions(a.vertices), static_cast<size_t>(V)) << name;
    // Joined again at the seams: the model's own vertices (the first V, in order) and faces.
    const smpl::SeamJoin joined = smpl::join_seams(a.vertices, a.faces);
    ASSERT_EQ(joined.kept.size(), static_cast<size_t>(V)) << name;
    for (Eigen::Index v = 0; v < V; ++v) ASSERT_EQ(joined.kept[static_cast<size_t>(v)], v) << name;
    EXPECT_EQ(joined.faces, m.faces) << name;
    smpl::Faces outside = a.faces;
    outside(0, 0) = static_cast<int>(a.vertices.rows());
    EXPECT_THROW(smpl::join_seams(a.vertices, outside), smpl::ModelError) << name;
    for (Eigen::Index v = 0; v < a.vertices.rows(); ++v) {
      ASSERT_EQ(a.vertices.row(v), a.vertices.row(joined.to_kept[static_cast<size_t>(v)])) << name;
    }
    ASSERT_EQ(a.morph_targets.size(), o.pose_correctives ? 2u + 9u * 23u : 2u) << name;
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      for (int c = 0; c < 3; ++c) {
        const int out = a.faces(f, c), src = m.faces(f, c);
        for (int k = 0; k < 4; ++k) {
          ASSERT_EQ(a.joint_ids(out, k), skin.joints[static_cast<size_t>(4 * src + k)]) << name;
          ASSERT_NEAR(a.joint_weights(out, k), skin.weights[static_cast<size_t>(4 * src + k)],
                      kWeightTol)
              << name;
        }
        for (size_t t = 0; t < a.morph_targets.size(); ++t) {
          const Eigen::Index col =
              t < 2 ? static_cast<Eigen::Index>(t) : static_cast<Eigen::Index>(t - 2);
          const Eigen::MatrixXd& dirs = t < 2 ? m.shapedirs : m.posedirs;
          for (int d = 0; d < 3; ++d) {
            ASSERT_NEAR(a.morph_targets[t](out, d), dirs(3 * src + d, col), kTexMorphTol)
                << name << " target " << t;
          }
        }
      }
    }
    // Assimp's glTF reader (v turned back up, as OBJ) gives the same texture coordinates.
    // Assimp knows VRM only as GLB: it reads a copy named .glb.
    fs::path assimp_file = file;
    if (file.extension() == ".vrm") {
      assimp_file.replace_extension(".vrm.glb");
      fs::copy_file(file, assimp_file, fs::copy_options::overwrite_existing);
    }
    const smpl::FbxAvatar b = smpl::read_with_assimp(assimp_file.string());
    ASSERT_EQ(b.faces.rows(), m.num_faces()) << name;
    // Assimp joins identical vertices: with positions, normals and texture coordinates equal
    // only within a seam copy's own pair, the file's split survives (no vertex welded across a
    // seam, none split further).
    EXPECT_EQ(b.vertices.rows(), a.vertices.rows()) << name;
    double worst = 0.0;
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      for (int c = 0; c < 3; ++c) {
        worst = std::max(
            worst, (b.uvs.row(b.faces(f, c)) - m.uvs.row(m.uv_faces(f, c))).cwiseAbs().maxCoeff());
      }
    }
    EXPECT_LE(worst, kUvTol) << name << " through Assimp";
  }
  std::string why;
  if (!caliper::test::node_tool_installed(CALIPER_GLTF_TOOLS_DIR, "gltf-validator", why)) {
    GTEST_SKIP() << "Khronos glTF-Validator not installed: " << why;
  }
  std::string output;
  EXPECT_EQ(caliper::test::run_node_tool(CALIPER_GLTF_TOOLS_DIR, "validate.mjs", files, output), 0)
      << output;
  for (const auto& f : files) {
    EXPECT_NE(output.find(f.string() + ": errors=0 warnings=0 "), std::string::npos) << output;
  }
  std::printf("%s", output.c_str());
}

// read_gltf refuses a TEXCOORD_0 that is not one VEC2 per vertex, naming the file.
TEST(Texcoords, ReadGltfRefusesAMisshapenTexcoord0) {
  const fs::path file = texcoords_out_dir() / "texcoord_check.gltf";
  smpl::export_avatar(file.string(), textured_model(), test_betas());
  std::string json = slurp(file);
  const std::string attribute = "\"TEXCOORD_0\": ";
  const size_t at = json.find(attribute);
  ASSERT_NE(at, std::string::npos);
  const size_t end = json.find_first_not_of("0123456789", at + attribute.size());
  json.replace(at + attribute.size(), end - at - attribute.size(), "0");  // POSITION: VEC3
  const fs::path bad = texcoords_out_dir() / "texcoord_vec3.gltf";
  smpl::write_file_atomic(bad.string(), json);
  try {
    smpl::read_gltf(bad.string());
    FAIL() << "a VEC3 TEXCOORD_0 was accepted";
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("TEXCOORD_0 must be VEC2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
  }
}

// FBX through Assimp: one control point per model vertex, UV channel 0 per polygon corner, read
// back by Assimp with the model's coordinates at every corner; the skin still sums to 1.
TEST(Texcoords, FbxCarriesUvChannel0) {
  const smpl::BodyModel m = textured_model();
  const Eigen::VectorXd betas = test_betas();
  smpl::Vertices body = smpl::shape(m, betas).vertices;
  body.col(1).array() -= body.col(1).minCoeff();
  const fs::path file = texcoords_out_dir() / "textured.fbx";
  smpl::export_avatar(file.string(), m, betas);
  // In the file: one control point per model vertex (Assimp's writer welded the seam copies),
  // texture coordinates per polygon corner.
  const std::string bytes = slurp(file);
  ASSERT_EQ(fbx_array_length(bytes, "Vertices"), 3L * m.num_vertices());
  EXPECT_EQ(fbx_array_length(bytes, "UVIndex"), 3L * m.num_faces());
  // ... in the model's vertex order. The array's header: type 'd', count, encoding (0: plain,
  // as Assimp 5.2 writes it), byte length; then the doubles.
  const size_t at = bytes.find("\x08Vertices") + 9;
  std::uint32_t encoding = 1;
  std::memcpy(&encoding, bytes.data() + at + 5, 4);
  ASSERT_EQ(encoding, 0u);
  ASSERT_LE(at + 13 + 24 * static_cast<size_t>(m.num_vertices()), bytes.size());
  smpl::Vertices points(m.num_vertices(), 3);
  std::memcpy(points.data(), bytes.data() + at + 13, 24 * static_cast<size_t>(m.num_vertices()));
  EXPECT_LE((points - body).cwiseAbs().maxCoeff(), kTexFloatTol);
  const smpl::FbxAvatar a = smpl::read_fbx(file.string());
  expect_corners(m, body, a.faces, a.vertices, a.uvs, "textured.fbx");
  EXPECT_EQ(unique_positions(a.vertices), static_cast<size_t>(m.num_vertices()));
  EXPECT_EQ(a.vertices.rows(), static_cast<Eigen::Index>(corner_pairs(m)));
  for (Eigen::Index v = 0; v < a.weight_sums.size(); ++v) {
    ASSERT_NEAR(a.weight_sums[v], 1.0, 1e-5) << "vertex " << v;
  }
  // Without texture coordinates: no texture coordinates, one vertex per model vertex.
  const fs::path plain = texcoords_out_dir() / "plain_uv_check.fbx";
  smpl::export_avatar(plain.string(), plain_model(), betas);
  EXPECT_EQ(fbx_array_length(slurp(plain), "Vertices"), 3L * m.num_vertices());
  EXPECT_EQ(fbx_array_length(slurp(plain), "UVIndex"), -1);
  const smpl::FbxAvatar p = smpl::read_fbx(plain.string());
  EXPECT_EQ(p.uvs.rows(), 0);
  EXPECT_EQ(p.vertices.rows(), m.num_vertices());
}

// OBJ: `vt` lines and `f v/t/n` corners, no vertex split; the project's reader still reads the
// welded mesh, Assimp reads the texture coordinates. PLY carries none (docs/file-formats.md).
TEST(Texcoords, ObjHasVtPerCornerAndPlyStaysWelded) {
  const smpl::BodyModel m = textured_model();
  const Eigen::VectorXd betas = test_betas();
  smpl::Vertices body = smpl::shape(m, betas).vertices;
  body.col(1).array() -= body.col(1).minCoeff();
  const fs::path file = texcoords_out_dir() / "textured.obj";
  smpl::export_avatar(file.string(), m, betas);
  const smpl::MeshData own = smpl::read_obj(file.string());
  EXPECT_EQ(own.vertices.rows(), m.num_vertices());
  EXPECT_EQ(own.faces, m.faces);
  EXPECT_LE((own.vertices - body).cwiseAbs().maxCoeff(), 1e-8);  // %.9g of metres
  const std::string text = slurp(file);
  EXPECT_NE(text.find("\nvt "), std::string::npos);
  const int a = m.faces(0, 0) + 1, t = m.uv_faces(0, 0) + 1;
  EXPECT_NE(text.find("\nf " + std::to_string(a) + "/" + std::to_string(t) + "/" +
                      std::to_string(a) + " "),
            std::string::npos);
  const smpl::FbxAvatar b = smpl::read_with_assimp(file.string());
  expect_corners(m, body, b.faces, b.vertices, b.uvs, "textured.obj through Assimp");
  EXPECT_EQ(unique_positions(b.vertices), static_cast<size_t>(m.num_vertices()));
  // --up z turns the positions only.
  smpl::ExportOptions z;
  z.up = smpl::UpAxis::Z;
  const fs::path zfile = texcoords_out_dir() / "textured_z.obj";
  smpl::export_avatar(zfile.string(), m, betas, z);
  const smpl::FbxAvatar bz = smpl::read_with_assimp(zfile.string());
  expect_corners(m, smpl::to_up_axis(body, smpl::UpAxis::Z), bz.faces, bz.vertices, bz.uvs,
                 "textured_z.obj through Assimp");
  // write_obj refuses texture-coordinate faces that do not fit.
  smpl::Faces short_ft = m.uv_faces.topRows(m.num_faces() - 1);
  EXPECT_THROW(smpl::write_obj((texcoords_out_dir() / "bad.obj").string(), body, m.faces,
                               smpl::UpAxis::Y, {}, m.uvs, short_ft),
               smpl::ModelError);
  EXPECT_FALSE(fs::exists(texcoords_out_dir() / "bad.obj"));

  const fs::path ply = texcoords_out_dir() / "textured.ply";
  smpl::export_avatar(ply.string(), m, betas);
  const smpl::MeshData pm = smpl::read_ply(ply.string());
  EXPECT_EQ(pm.vertices.rows(), m.num_vertices());
  EXPECT_EQ(pm.faces, m.faces);
}

}  // namespace
