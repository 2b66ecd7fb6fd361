/// \file test_makehuman.cpp
/// MakeHuman asset readers and the skin mesh, on the real CC0 files (../shared/data/makehuman)
/// and on small hand-written files for the error paths.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>

#include <Eigen/SVD>

#include "caliper/volume.hpp"
#include "makehuman.hpp"
#include "makehuman_test_data.hpp"
#include "mesh_checks.hpp"
#include "pose_correctives.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace {

using makehuman_test::have_assets;
using makehuman_test::kMh;

std::string write_file(const std::string& name, const std::string& text) {
  std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// Loaded once: parsing the 2 MB OBJ is the slow part of these tests.
const modelgen::mh::BaseMesh& base() {
  static const modelgen::mh::BaseMesh b = modelgen::mh::read_base_mesh(kMh + "/3dobjs/base.obj");
  return b;
}

}  // namespace

TEST(MakeHumanReader, ReadsTheBaseMeshWithUvsAndGroups) {
  REQUIRE_ASSETS();
  const auto& b = base();
  // Counts stated in the assets' README (hm08).
  EXPECT_EQ(b.vertices.rows(), 19158);
  EXPECT_EQ(b.uvs.rows(), 21334);
  int body_faces = 0;
  for (const auto& f : b.faces) {
    ASSERT_GE(f.group, 0);
    if (b.groups[static_cast<std::size_t>(f.group)] == "body") {
      ++body_faces;
      EXPECT_EQ(f.corners, 4);
    }
  }
  EXPECT_EQ(body_faces, 13378);
  for (const char* g : {"body", "helper-l-eye", "helper-upper-teeth", "joint-pelvis"}) {
    EXPECT_NE(std::find(b.groups.begin(), b.groups.end(), g), b.groups.end()) << g;
  }
}

TEST(MakeHumanReader, SkinMeshIsTheClosedBodyInMetresFacingPlusZ) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const mh::SkinMesh skin = mh::skin_mesh(base());
  const smpl::Vertices v = mh::skin_vertices(skin, base().vertices);
  EXPECT_EQ(v.rows(), 13380);               // README: the body group uses 13,380 vertices
  EXPECT_EQ(skin.faces.rows(), 2 * 13378);  // every quad split in two
  EXPECT_EQ(skin.uv_faces.rows(), skin.faces.rows());
  EXPECT_GT(skin.uvs.rows(), v.rows());  // seams: some vertices have several UVs
  EXPECT_LE(skin.uvs.rows(), base().uvs.rows());
  EXPECT_GE(skin.uvs.minCoeff(), 0.0);
  EXPECT_LE(skin.uvs.maxCoeff(), 1.0);

  const auto topo = modelgen::topology_report(static_cast<int>(v.rows()), skin.faces);
  EXPECT_TRUE(topo.closed);
  EXPECT_TRUE(topo.oriented);
  EXPECT_TRUE(topo.vertex_manifold);
  EXPECT_EQ(topo.unused_vertices, 0);

  // Helpers are excluded: no skin vertex comes from an eye, tooth or joint-cube group.
  std::set<int> helper;
  for (const auto& f : base().faces) {
    if (base().groups[static_cast<std::size_t>(f.group)] != "body") {
      for (int c = 0; c < f.corners; ++c) {
        helper.insert(f.v[static_cast<std::size_t>(c)]);
      }
    }
  }
  for (const int s : skin.source_vertex) {
    ASSERT_EQ(helper.count(s), 0u) << "skin vertex from a helper: " << s;
  }

  // Metres, Y up: the README's 1.69 m including helpers; the skin alone is a little shorter.
  const double height = v.col(1).maxCoeff() - v.col(1).minCoeff();
  EXPECT_GT(height, 1.60);
  EXPECT_LT(height, 1.70);
  // Outward winding gives a positive volume; an adult of 1.6-1.7 m has 45-90 litres.
  const double volume = caliper::mesh_volume(v, skin.faces);
  EXPECT_GT(volume, 0.045);
  EXPECT_LT(volume, 0.090);
  // Facing +Z: the nose (highest-z point of the head, above 1.4 m from the feet) is in front of
  // the back of the head.
  const double floor = v.col(1).minCoeff();
  double head_front = -1e9, head_back = 1e9;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    if (v(i, 1) - floor > 1.45) {
      head_front = std::max(head_front, v(i, 2));
      head_back = std::min(head_back, v(i, 2));
    }
  }
  // Symmetric about x = 0 (subject's left at +X): the extremes match within 5 mm.
  EXPECT_NEAR(v.col(0).maxCoeff(), -v.col(0).minCoeff(), 0.005);
  EXPECT_GT(head_front, 0.0);
  EXPECT_GT(head_front - 0.0, -head_back * 0.5);
}

TEST(MakeHumanReader, TargetsSkeletonAndWeights) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const int n = static_cast<int>(base().vertices.rows());
  const mh::Target t = mh::read_target(kMh + "/targets/measure/measure-waist-circ-incr.target", n);
  ASSERT_FALSE(t.index.empty());
  EXPECT_EQ(t.index.size(), t.delta.size());
  // Applying a target with weight w and then -w gives back the base exactly (same order).
  mh::Positions p = base().vertices;
  mh::add_target(t, 0.7, p);
  EXPECT_GT((p - base().vertices).cwiseAbs().maxCoeff(), 1e-3);
  mh::add_target(t, -0.7, p);
  EXPECT_LT((p - base().vertices).cwiseAbs().maxCoeff(), 1e-12);

  const mh::Skeleton sk = mh::read_skeleton(kMh + "/rigs/default.mhskel", n);
  EXPECT_EQ(sk.bones.size(), 163u);
  EXPECT_TRUE(sk.bones.front().parent.empty());
  std::set<std::string> seen;
  for (const auto& b : sk.bones) {
    if (!b.parent.empty()) {
      EXPECT_EQ(seen.count(b.parent), 1u) << b.name << " before its parent " << b.parent;
    }
    seen.insert(b.name);
  }
  // Joint centroids: the left elbow is at +X, above the hip and below the shoulder.
  const auto& P = base().vertices;
  const Eigen::Vector3d elbow = mh::joint_position(sk, sk.bones[sk.bone("lowerarm01.L")].head, P);
  const Eigen::Vector3d shoulder =
      mh::joint_position(sk, sk.bones[sk.bone("upperarm01.L")].head, P);
  const Eigen::Vector3d hip = mh::joint_position(sk, sk.bones[sk.bone("upperleg01.L")].head, P);
  EXPECT_GT(elbow.x(), shoulder.x());
  EXPECT_LT(elbow.y(), shoulder.y());
  EXPECT_GT(elbow.y(), hip.y());
  EXPECT_GT(hip.x(), 0.0);

  const mh::BoneWeights w = mh::read_weights(kMh + "/rigs/default_weights.mhw", n);
  EXPECT_EQ(w.size(), 139u);
  // Every skin vertex is weighted, and the weights of a vertex sum to about 1: the file prints
  // them with 3 decimals and leaves out the smallest, so sums reach 0.937 to 1.063 here (the
  // merge into SMPL's joints renormalises them).
  const mh::SkinMesh skin = mh::skin_mesh(base());
  std::vector<double> sum(static_cast<std::size_t>(n), 0.0);
  for (const auto& [bone, list] : w) {
    EXPECT_NO_THROW(sk.bone(bone));
    for (const auto& [i, x] : list) {
      sum[static_cast<std::size_t>(i)] += x;
    }
  }
  constexpr double kPrintedWeightTolerance = 0.07;
  for (const int s : skin.source_vertex) {
    ASSERT_NEAR(sum[static_cast<std::size_t>(s)], 1.0, kPrintedWeightTolerance) << "vertex " << s;
  }
}

TEST(MakeHumanReader, BadFilesGiveClearErrors) {
  namespace mh = modelgen::mh;
  auto message = [](auto&& fn) {
    try {
      fn();
    } catch (const mh::AssetError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { mh::read_base_mesh("/nonexistent/base.obj"); }).find("--makehuman"),
            std::string::npos);
  const std::string five = write_file("mh_five.obj",
                                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                      "v 2 2 0\ng body\nf 1 2 3 4 5\n");
  EXPECT_NE(message([&] { mh::read_base_mesh(five); }).find("line 7"), std::string::npos);
  const std::string range = write_file("mh_range.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n");
  EXPECT_NE(message([&] { mh::read_base_mesh(range); }).find("vertex index 9"), std::string::npos);
  const std::string nan = write_file("mh_nan.obj", "v 0 x 0\n");
  EXPECT_NE(message([&] { mh::read_base_mesh(nan); }).find("expected a number"), std::string::npos);
  const std::string nobody = write_file("mh_nobody.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(message([&] { mh::skin_mesh(mh::read_base_mesh(nobody)); }).find("'body'"),
            std::string::npos);
  const std::string tgt = write_file("mh_bad.target", "# c\n0 0 0 0\n5 0.1 0 0\n");
  EXPECT_NE(message([&] { mh::read_target(tgt, 3); }).find("line 3"), std::string::npos);
  const std::string js = write_file("mh_bad.mhskel", "{\"joints\": {}, ");
  EXPECT_NE(message([&] { mh::read_skeleton(js, 3); }).find("not valid JSON"), std::string::npos);
  const std::string cyc =
      write_file("mh_cycle.mhskel",
                 R"({"joints": {"j": [0]}, "bones": {"a": {"head": "j", "tail": "j", "parent": "b"},
                     "b": {"head": "j", "tail": "j", "parent": "a"}}})");
  EXPECT_NE(message([&] { mh::read_skeleton(cyc, 3); }).find("cycle"), std::string::npos);
  const std::string neg = write_file("mh_neg.mhw", R"({"weights": {"a": [[0, -0.5]]}})");
  EXPECT_NE(message([&] { mh::read_weights(neg, 3); }).find("weight"), std::string::npos);
}

// ------------------------------------------------------------------------------------------------
// Rig: SMPL joints, merged weights, T-pose, regressor (stage 2 of issue 11)
// ------------------------------------------------------------------------------------------------

#include "makehuman_rig.hpp"

namespace {

using makehuman_test::assets;

}  // namespace

TEST(MakeHumanRig, MergedWeightsAreFourPerVertexSummingToOne) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const auto& a = assets();
  for (const auto& [bone, list] : a.weights) {
    (void)list;
    const int seg = mh::smpl_segment(a.skeleton, bone);
    EXPECT_GE(seg, 0);
    EXPECT_LT(seg, 24);
  }
  EXPECT_EQ(mh::smpl_segment(a.skeleton, "finger1-3.L"), 22);  // thumb tip: left hand
  EXPECT_EQ(mh::smpl_segment(a.skeleton, "toe5-2.R"), 11);     // little toe: right foot
  EXPECT_EQ(mh::smpl_segment(a.skeleton, "jaw"), 15);          // face bones: head
  EXPECT_EQ(mh::smpl_segment(a.skeleton, "pelvis.L"), 0);
  EXPECT_EQ(mh::smpl_segment(a.skeleton, "upperarm02.R"), 17);
  const smpl::SparseMatrix w = mh::merged_weights(a);
  ASSERT_EQ(w.rows(), static_cast<Eigen::Index>(a.skin.source_vertex.size()));
  ASSERT_EQ(w.cols(), 24);
  std::array<int, 24> dominant{};
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    int nnz = 0;
    double sum = 0.0, best = -1.0;
    int arg = -1;
    for (smpl::SparseMatrix::InnerIterator it(w, i); it; ++it) {
      ++nnz;
      sum += it.value();
      EXPECT_GT(it.value(), 0.0);
      if (it.value() > best) {
        best = it.value();
        arg = static_cast<int>(it.col());
      }
    }
    ASSERT_GE(nnz, 1);
    ASSERT_LE(nnz, 4);
    constexpr double kRoundoff = 1e-12;  // a division by the row sum
    ASSERT_NEAR(sum, 1.0, kRoundoff) << "vertex " << i;
    ++dominant[static_cast<std::size_t>(arg)];
  }
  // No vertex off the midline carries a weight of the other side's limbs (hm08 has four such
  // strays, dropped by the merge: merged_weights()).
  int cross = 0;
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    const double x = a.base.vertices(a.skin.source_vertex[static_cast<std::size_t>(i)], 0);
    for (smpl::SparseMatrix::InnerIterator it(w, i); it; ++it) {
      const int k = static_cast<int>(it.col());
      const bool left = k == 1 || k == 4 || k == 7 || k == 10 || k == 13 || (k >= 16 && k % 2 == 0);
      const bool right = k != 0 && k != 3 && k != 6 && k != 9 && k != 12 && k != 15 && !left;
      cross += (left && x < -mh::kMidlineBand) || (right && x > mh::kMidlineBand);
    }
  }
  EXPECT_EQ(cross, 0);
  // Every joint drives some skin; left and right sides drive the same number of vertices
  // (MakeHuman's weights are symmetric, the mesh too) to within 1 %.
  const auto& names = smpl::smpl_joint_names();
  for (int k = 0; k < 24; ++k) {
    EXPECT_GT(dominant[static_cast<std::size_t>(k)], 0) << names[static_cast<std::size_t>(k)];
  }
  for (const auto& [l, r] : std::vector<std::pair<int, int>>{
           {1, 2}, {4, 5}, {7, 8}, {10, 11}, {13, 14}, {16, 17}, {18, 19}, {20, 21}, {22, 23}}) {
    EXPECT_NEAR(dominant[static_cast<std::size_t>(l)], dominant[static_cast<std::size_t>(r)],
                0.01 * dominant[static_cast<std::size_t>(l)] + 1)
        << names[static_cast<std::size_t>(l)];
  }
}

TEST(MakeHumanRig, TPoseHasHorizontalStraightArmsPalmsDownAndKeepsTheVolume) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const auto& a = assets();
  const mh::TPoseBody t = mh::t_pose(a, a.base.vertices);
  const auto& j = t.joints;
  // Millimetres here are 0.01 file units (decimetres).
  constexpr double kLine = 0.05;  // 5 mm: joints placed on the line by construction
  for (const auto& [sh, el, wr, ha, sign] : std::vector<std::tuple<int, int, int, int, double>>{
           {16, 18, 20, 22, 1.0}, {17, 19, 21, 23, -1.0}}) {
    for (const int k : {el, wr, ha}) {
      EXPECT_NEAR(j(k, 1), j(sh, 1), kLine) << "joint " << k << " off the shoulder's height";
      EXPECT_NEAR(j(k, 2), j(sh, 2), kLine) << "joint " << k << " off the shoulder's depth";
    }
    EXPECT_GT(sign * (j(el, 0) - j(sh, 0)), 2.0);  // the upper arm is over 20 cm long
    EXPECT_GT(sign * (j(wr, 0) - j(el, 0)), 2.0);
    EXPECT_GT(sign * (j(ha, 0) - j(wr, 0)), 0.5);
    // Bone lengths are kept by the rigid arm chain.
    const auto ra = mh::smpl_joints(a, a.base.vertices);
    EXPECT_NEAR((j.row(wr) - j.row(el)).norm(), (ra.row(wr) - ra.row(el)).norm(), 1e-9);
  }
  // Palms down: the index knuckle is in front of the little-finger knuckle. The skin vertex
  // nearest to each MakeHuman knuckle joint shows it.
  const auto knuckle = [&](const std::string& bone) {
    const auto& b = a.skeleton.bones[static_cast<std::size_t>(a.skeleton.bone(bone))];
    // Posed: average of the joint's group is not posed (joint cubes have no weights), so use the
    // skin vertices with the largest weight of that finger bone.
    double best = -1.0;
    int arg = -1;
    for (const auto& [i, w] : a.weights.at(bone)) {
      if (a.skin.skin_vertex[static_cast<std::size_t>(i)] >= 0 && w > best) {
        best = w;
        arg = i;
      }
    }
    (void)b;
    return Eigen::Vector3d(t.positions.row(arg).transpose());
  };
  EXPECT_GT(knuckle("finger2-1.L").z(), knuckle("finger5-1.L").z());
  EXPECT_GT(knuckle("finger2-1.R").z(), knuckle("finger5-1.R").z());
  // Trunk and legs do not move; the volume changes by less than 3 % (skin folds at the
  // shoulders under linear blend skinning).
  const smpl::Vertices rest = mh::skin_vertices(a.skin, a.base.vertices);
  const smpl::Vertices posed = mh::skin_vertices(a.skin, t.positions);
  const double v0 = caliper::mesh_volume(rest, a.skin.faces);
  const double v1 = caliper::mesh_volume(posed, a.skin.faces);
  std::printf("volume A-pose %.5f m^3, T-pose %.5f m^3\n", v0, v1);
  EXPECT_NEAR(v1 / v0, 1.0, 0.03);
  const auto x0 = modelgen::self_intersections(rest, a.skin.faces, 0.01);
  const auto x1 = modelgen::self_intersections(posed, a.skin.faces, 0.01);
  std::printf("self-intersecting triangle pairs: A-pose %zu, T-pose %zu\n", x0.size(), x1.size());
  EXPECT_LE(x1.size(), x0.size());
}

TEST(MakeHumanRig, RegressorReproducesTheJointsOfHeldOutBodies) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const auto& a = assets();
  std::vector<mh::TPoseBody> bodies{mh::t_pose(a, a.base.vertices)};
  for (const std::string& rel : mh::default_regressor_targets()) {
    mh::Positions p = a.base.vertices;
    mh::add_target(mh::read_asset_target(a, rel), 1.0, p);
    bodies.push_back(mh::t_pose(a, p));
  }
  const smpl::SparseMatrix r = mh::fit_joint_regressor(a, bodies);
  ASSERT_EQ(r.rows(), 24);
  double lo = 0.0, hi = 0.0;
  for (Eigen::Index k = 0; k < 24; ++k) {
    EXPECT_NEAR(r.row(k).sum(), 1.0, 1e-12);
    for (smpl::SparseMatrix::InnerIterator it(r, k); it; ++it) {
      lo = std::min(lo, it.value());
      hi = std::max(hi, it.value());
    }
  }
  std::printf("regressor entries in [%.3f, %.3f]\n", lo, hi);
  // No wild cancellation: a joint is a blend of nearby skin, not a difference of far points.
  EXPECT_GT(lo, -0.6);
  EXPECT_LT(hi, 1.0);
  // Worst and sum of squared joint errors (metres) of the regressor on one body.
  auto errors = [&](const mh::TPoseBody& b, double& worst, double& sq, int& count) {
    const smpl::Vertices v = mh::skin_vertices(a.skin, b.positions);
    const smpl::Joints jr = r * v;
    for (int k = 0; k < 24; ++k) {
      const double e = (jr.row(k) - mh::kMetresPerUnit * b.joints.row(k)).norm();
      worst = std::max(worst, e);
      sq += e * e;
      ++count;
    }
  };
  double train = 0.0, train_sq = 0.0;
  int train_n = 0;
  for (const auto& b : bodies) {
    errors(b, train, train_sq, train_n);
  }
  // Held out: bodies the fit never saw (proportions, old age, a mix of two targets).
  double held = 0.0, held_sq = 0.0;
  int held_n = 0;
  for (const std::vector<std::string>& mix : std::vector<std::vector<std::string>>{
           {"macrodetails/proportions/"
            "female-young-averagemuscle-averageweight-idealproportions.target"},
           {"macrodetails/universal-male-old-maxmuscle-maxweight.target"},
           {"macrodetails/universal-female-young-minmuscle-maxweight.target",
            "measure/measure-hips-circ-incr.target"}}) {
    mh::Positions p = a.base.vertices;
    for (const auto& rel : mix) {
      mh::add_target(mh::read_asset_target(a, rel), 1.0, p);
    }
    errors(mh::t_pose(a, p), held, held_sq, held_n);
  }
  const double train_rms = std::sqrt(train_sq / train_n);
  const double held_rms = std::sqrt(held_sq / held_n);
  std::printf(
      "regressor joint error: training RMS %.2f mm, worst %.2f mm; held out RMS %.2f mm, "
      "worst %.2f mm\n",
      1e3 * train_rms, 1e3 * train, 1e3 * held_rms, 1e3 * held);
  // MakeHuman's weight and muscle targets leave the spine joint cubes where they are while the
  // back's skin moves by centimetres, and no skin ring reproduces that exactly: the worst errors
  // are spine joints of the extreme (max-weight) corners. 1 cm RMS and 4 cm worst still catch a
  // wrong vertex choice or a broken solve (which give errors of decimetres).
  constexpr double kRms = 0.010;
  constexpr double kWorst = 0.040;
  EXPECT_LT(train_rms, kRms);
  EXPECT_LT(held_rms, kRms);
  EXPECT_LT(train, kWorst);
  EXPECT_LT(held, kWorst);
}

TEST(MakeHumanRig, TemplateModelIsValidAndDeterministic) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const auto& a = assets();
  const smpl::BodyModel m1 = mh::template_model(a, mh::default_regressor_targets());
  EXPECT_EQ(m1.num_joints(), 24);
  EXPECT_EQ(m1.num_betas(), 0);
  EXPECT_TRUE(m1.has_uvs());
  EXPECT_EQ(m1.uv_faces.rows(), m1.faces.rows());
  // Round trip through the .npz format keeps the texture coordinates.
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/mh_template.npz";
  smpl::save_model(m1, path);
  const smpl::BodyModel back = smpl::load_model(path);
  EXPECT_TRUE(back.uvs == m1.uvs);
  EXPECT_TRUE(back.uv_faces == m1.uv_faces);
  const smpl::Joints j = m1.j_regressor * m1.v_template;
  EXPECT_LT(j.row(0).norm(), 1e-12);  // origin at the pelvis joint
  // The mirror map (vert_sym_idxs): an involution whose pairs are exact mirror images, the 188
  // midline vertices of MakeHuman's skin their own.
  ASSERT_EQ(static_cast<Eigen::Index>(m1.mirror.size()), m1.num_vertices());
  int midline = 0;
  for (Eigen::Index i = 0; i < m1.num_vertices(); ++i) {
    const int k = m1.mirror[static_cast<size_t>(i)];
    ASSERT_EQ(m1.mirror[static_cast<size_t>(k)], i);
    midline += k == i ? 1 : 0;
    EXPECT_EQ(m1.v_template(i, 0), -m1.v_template(k, 0)) << i;
    EXPECT_EQ(m1.v_template(i, 1), m1.v_template(k, 1)) << i;
    EXPECT_EQ(m1.v_template(i, 2), m1.v_template(k, 2)) << i;
  }
  EXPECT_EQ(midline, 188);
  EXPECT_TRUE(back.mirror == m1.mirror);
  const smpl::BodyModel m2 = mh::template_model(a, mh::default_regressor_targets());
  EXPECT_TRUE(m1.v_template == m2.v_template);
  EXPECT_TRUE(smpl::SparseMatrix(m1.j_regressor - m2.j_regressor).norm() == 0.0);
  EXPECT_TRUE(smpl::SparseMatrix(m1.weights - m2.weights).norm() == 0.0);  // smoothed twice
}

// The weight diffusion of merged_weights() (issue 11): 0 passes leaves MakeHuman's merge as it was;
// the smoothed weights give a vertex only joints that influenced it or a 1-ring neighbour before
// smoothing (no weight on a joint far from it), still 4 at most summing to 1 (checked above with
// the default passes); a negative pass count is refused.
TEST(MakeHumanRig, SmoothedWeightsStayOnTheJointsOfTheOneRing) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const auto& a = assets();
  const smpl::SparseMatrix w0 = mh::merged_weights(a, 0);
  const smpl::SparseMatrix w = mh::merged_weights(a);
  ASSERT_EQ(w.rows(), w0.rows());
  EXPECT_GT(smpl::SparseMatrix(w - w0).norm(), 1.0);  // the default smooths
  std::vector<std::set<int>> near(static_cast<std::size_t>(w0.rows()));
  auto add_row = [&](Eigen::Index to, Eigen::Index from) {
    for (smpl::SparseMatrix::InnerIterator it(w0, from); it; ++it) {
      near[static_cast<std::size_t>(to)].insert(static_cast<int>(it.col()));
    }
  };
  for (Eigen::Index i = 0; i < w0.rows(); ++i) add_row(i, i);
  const smpl::Faces& f = a.skin.faces;
  for (Eigen::Index t = 0; t < f.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      add_row(f(t, c), f(t, (c + 1) % 3));
      add_row(f(t, (c + 1) % 3), f(t, c));
    }
  }
  int far = 0;
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    for (smpl::SparseMatrix::InnerIterator it(w, i); it; ++it) {
      far += near[static_cast<std::size_t>(i)].count(static_cast<int>(it.col())) == 0 ? 1 : 0;
    }
  }
  EXPECT_EQ(far, 0);
  EXPECT_THROW(mh::merged_weights(a, -1), std::invalid_argument);
}

// Geometry of the template (issue 11, "Must show" 2; the shape models are checked by
// caliper-modelgen-check, docs/models.md): a closed genus-0 manifold of one piece, positive
// volume, no self-intersection in the T-pose; in the 10 test poses, the flipped triangles are the
// folds linear blend skinning makes with MakeHuman's weights at 90-degree bends (inner elbow,
// back of the knee, groin, armpit). Their counts are guarded at today's figures, per pose; the
// pose correctives must leave none.
TEST(MakeHumanRig, TemplateIsAClosedManifoldWithoutSelfIntersectionAndFewFoldsInTestPoses) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const smpl::BodyModel m = mh::template_model(assets(), mh::default_regressor_targets());
  const modelgen::TopologyReport r = modelgen::topology_report(m.num_vertices(), m.faces);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.oriented);
  EXPECT_TRUE(r.vertex_manifold);
  EXPECT_EQ(r.components, 1);
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.unused_vertices, 0);
  EXPECT_GT(caliper::mesh_volume(m.v_template, m.faces), 0.045);
  EXPECT_TRUE(modelgen::self_intersections(m.v_template, m.faces).empty());
  // Flipped triangles per test pose (test_poses() order) measured on 2026-11-25 with the weights
  // diffused kWeightSmoothingPasses = 50 times (168 in all before: 17 17 14 14 25 25 14 21 21 0;
  // DISABLED_WeightSmoothingTable, docs/models.md): the issue asks for none; these ceilings keep
  // the folds left (arms lowered, hips flexed) from growing. Lower them, never raise them.
  // The left-right pairs are equal: mesh and weights are symmetric.
  const std::size_t kFlippedToday[10] = {0, 0, 0, 0, 2, 2, 0, 3, 3, 0};
  const Eigen::VectorXd betas(0);
  ASSERT_EQ(modelgen::test_poses().size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) {
    const modelgen::TestPose& p = modelgen::test_poses()[i];
    const smpl::Body body = smpl::evaluate(m, betas, p.theta);
    const std::vector<int> flipped = modelgen::flipped_triangles(m, m.v_template, body);
    const auto hits = modelgen::self_intersections(body.vertices, m.faces);
    std::printf("%-22s %3zu flipped triangles, %4zu self-intersecting pairs\n", p.name.c_str(),
                flipped.size(), hits.size());
    EXPECT_LE(flipped.size(), kFlippedToday[i]) << p.name;
  }
  // With the pose correctives the generator gives every shape model (pose_correctives.hpp),
  // fitted here on the template: no flipped triangle in any test pose.
  smpl::BodyModel corrected = m;
  modelgen::PoseCorrectiveOptions o;
  o.threads = 2;
  corrected.posedirs = modelgen::pose_correctives(m, o);
  for (const modelgen::TestPose& p : modelgen::test_poses()) {
    const smpl::Body body = smpl::evaluate(corrected, betas, p.theta);
    EXPECT_TRUE(modelgen::flipped_triangles(corrected, m.v_template, body).empty()) << p.name;
  }
}

// The table behind kWeightSmoothingPasses (docs/models.md, "Geometry checks"); minutes, so not
// in CI: modelgen_tests --gtest_also_run_disabled_tests --gtest_filter='*WeightSmoothingTable*'.
// Per pass count: flipped triangles per test pose, and the side effects: the body's volume
// change (ml) with both wrists twisted 90 degrees about the forearm (the candy wrapper) and with
// both elbows flexed 90 degrees, and how far (mm, largest and median) the vertices that MakeHuman
// gives wholly to the left wrist+hand or left ankle+foot move from where the unsmoothed weights
// put them with that wrist and ankle flexed 90 degrees (the hands and feet still follow their
// joints when this stays small).
TEST(MakeHumanRig, DISABLED_WeightSmoothingTable) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const auto& a = assets();
  smpl::BodyModel m = mh::template_model(a, mh::default_regressor_targets());
  const Eigen::VectorXd betas(0);
  constexpr double kRight = 1.5707963267948966;
  Eigen::VectorXd twist = Eigen::VectorXd::Zero(72), elbows = twist, distal = twist;
  twist.segment<3>(3 * Eigen::Index{20}) = Eigen::Vector3d(kRight, 0, 0);
  twist.segment<3>(3 * Eigen::Index{21}) = Eigen::Vector3d(kRight, 0, 0);
  elbows.segment<3>(3 * Eigen::Index{18}) = Eigen::Vector3d(0, -kRight, 0);
  elbows.segment<3>(3 * Eigen::Index{19}) = Eigen::Vector3d(0, kRight, 0);
  distal.segment<3>(3 * Eigen::Index{20}) = Eigen::Vector3d(0, 0, -kRight);
  distal.segment<3>(3 * Eigen::Index{7}) = Eigen::Vector3d(kRight, 0, 0);
  const double rest_volume = caliper::mesh_volume(m.v_template, m.faces);
  const smpl::SparseMatrix w0 = mh::merged_weights(a, 0);
  m.weights = w0;
  const smpl::Vertices distal0 = smpl::evaluate(m, betas, distal).vertices;
  std::vector<Eigen::Index> tips;  // wholly on the left wrist+hand or the left ankle+foot
  for (Eigen::Index i = 0; i < w0.rows(); ++i) {
    double hand = 0.0, foot = 0.0;
    for (smpl::SparseMatrix::InnerIterator it(w0, i); it; ++it) {
      hand += (it.col() == 20 || it.col() == 22) ? it.value() : 0.0;
      foot += (it.col() == 7 || it.col() == 10) ? it.value() : 0.0;
    }
    if (hand > 0.999 || foot > 0.999) tips.push_back(i);
  }
  std::printf(
      "passes | flipped per test pose (test_poses() order) | total | self-intersecting pairs | "
      "wrist twist dV ml | "
      "elbows dV ml | hand+foot drift max/p95/median mm (%zu vertices); rest volume %.1f l\n",
      tips.size(), rest_volume * 1e3);
  for (const int passes : {0, 5, 10, 20, 30, 40, 50, 60, 70, 100}) {
    m.weights = mh::merged_weights(a, passes);
    std::size_t total = 0, pairs = 0;
    std::string row;
    for (const modelgen::TestPose& p : modelgen::test_poses()) {
      const smpl::Body body = smpl::evaluate(m, betas, p.theta);
      const std::size_t f = modelgen::flipped_triangles(m, m.v_template, body).size();
      total += f;
      pairs += modelgen::self_intersections(body.vertices, m.faces).size();
      row += std::to_string(f) + " ";
    }
    const double dv_twist =
        caliper::mesh_volume(smpl::evaluate(m, betas, twist).vertices, m.faces) - rest_volume;
    const double dv_elbows =
        caliper::mesh_volume(smpl::evaluate(m, betas, elbows).vertices, m.faces) - rest_volume;
    const smpl::Vertices d = smpl::evaluate(m, betas, distal).vertices;
    std::vector<double> drift;
    drift.reserve(tips.size());
    for (const Eigen::Index i : tips) drift.push_back((d.row(i) - distal0.row(i)).norm() * 1e3);
    std::sort(drift.begin(), drift.end());
    std::printf("%3d | %s| %3zu | %4zu | %7.1f | %7.1f | %6.2f / %6.2f / %6.2f\n", passes,
                row.c_str(), total, pairs, dv_twist * 1e6, dv_elbows * 1e6, drift.back(),
                drift[drift.size() * 95 / 100], drift[drift.size() / 2]);
  }
}

// The template's texture coordinates kept through the exports (issue 11): GLB split at the seams
// (one vertex per distinct corner pair, still welded in positions: as many distinct positions as
// the model has vertices), FBX and OBJ read back by Assimp, every corner's coordinate to 1e-6.
TEST(MakeHumanRig, TemplateExportsKeepTheTextureCoordinatesWeldedInPositions) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const smpl::BodyModel m = mh::template_model(assets(), mh::default_regressor_targets());
  ASSERT_TRUE(m.has_uvs());
  constexpr double kUvTol = 1e-6;  // the issue's bound; float32 of values in [0, 1]: 6e-8
  auto distinct = [](const smpl::Vertices& v) {
    std::set<std::tuple<double, double, double>> s;
    for (Eigen::Index i = 0; i < v.rows(); ++i) s.emplace(v(i, 0), v(i, 1), v(i, 2));
    return s.size();
  };
  std::set<std::pair<int, int>> pairs;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) pairs.emplace(m.faces(f, c), m.uv_faces(f, c));
  }
  const auto V = static_cast<size_t>(m.num_vertices());
  ASSERT_EQ(distinct(m.v_template), V);  // no two skin vertices share a place
  auto worst_uv = [&](const smpl::Faces& faces, const smpl::TexCoords& uvs) {
    EXPECT_EQ(faces.rows(), m.num_faces());
    double worst = 0.0;
    for (Eigen::Index f = 0; f < m.num_faces() && f < faces.rows(); ++f) {
      for (int c = 0; c < 3; ++c) {
        worst = std::max(
            worst, (uvs.row(faces(f, c)) - m.uvs.row(m.uv_faces(f, c))).cwiseAbs().maxCoeff());
      }
    }
    return worst;
  };
  const std::string dir = std::string(CALIPER_TEST_DATA_DIR) + "/";
  const Eigen::VectorXd no_betas(0);
  smpl::export_avatar(dir + "mh_template.glb", m, no_betas);
  const smpl::GltfAvatar g = smpl::read_gltf(dir + "mh_template.glb");
  EXPECT_EQ(static_cast<size_t>(g.vertices.rows()), pairs.size());
  EXPECT_EQ(distinct(g.vertices), V);
  EXPECT_LE(worst_uv(g.faces, g.texcoords), kUvTol);
  std::printf("GLB: %zu model vertices, %zu after the seam split\n", V, pairs.size());
  for (const char* ext : {".fbx", ".obj"}) {
    const std::string file = dir + "mh_template" + ext;
    smpl::export_avatar(file, m, no_betas);
    const smpl::FbxAvatar a = smpl::read_with_assimp(file);
    EXPECT_EQ(distinct(a.vertices), V) << ext;
    if (std::string(ext) == ".fbx") {
      // One control point per model vertex in the file (the "Vertices" array: its element count
      // follows the node name and the type byte 'd').
      std::ifstream in(file, std::ios::binary | std::ios::ate);
      std::string bytes(static_cast<size_t>(in.tellg()), '\0');
      in.seekg(0);
      in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      const size_t at = bytes.find("\x08Vertices");
      ASSERT_NE(at, std::string::npos);
      std::uint32_t n = 0;
      std::memcpy(&n, bytes.data() + at + 10, 4);
      EXPECT_EQ(n, 3 * V);
    }
    EXPECT_LE(worst_uv(a.faces, a.uvs), kUvTol) << ext;
  }
}

// The texture coordinates of the skin as a checker texture would show them: every triangle keeps
// its orientation in the unwrap (no mirrored islands) and none is squeezed to nothing.
TEST(MakeHumanRig, TextureCoordinatesAreOrientedAndNotDegenerate) {
  REQUIRE_ASSETS();
  namespace mh = modelgen::mh;
  const smpl::BodyModel m = mh::template_model(assets(), mh::default_regressor_targets());
  ASSERT_TRUE(m.has_uvs());
  // A checker square drawn out to more than 2.5 : 1 would show on a textured render; 99 % of
  // the triangles must stay below that (measured 2.04 on the T-pose template). The worst few
  // (15.7 : 1, reported, not guarded) are for the checker render of issue 11 to judge.
  constexpr double kStretch99 = 2.5;
  double uv_total = 0.0, area_total = 0.0;
  std::vector<double> ratio(static_cast<size_t>(m.num_faces()));
  int flipped = 0, outside = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::RowVector2d a = m.uvs.row(m.uv_faces(f, 0)), b = m.uvs.row(m.uv_faces(f, 1)),
                             c = m.uvs.row(m.uv_faces(f, 2));
    const double uv_area = 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    const Eigen::RowVector3d p = m.v_template.row(m.faces(f, 0)),
                             q = m.v_template.row(m.faces(f, 1)),
                             r = m.v_template.row(m.faces(f, 2));
    const double area = 0.5 * (q - p).cross(r - p).norm();
    flipped += uv_area <= 0.0;
    for (int k = 0; k < 3; ++k) {
      const double u = m.uvs(m.uv_faces(f, k), 0), v = m.uvs(m.uv_faces(f, k), 1);
      outside += u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0;
    }
    uv_total += std::abs(uv_area);
    area_total += area;
    ratio[static_cast<size_t>(f)] = std::abs(uv_area) / area;
  }
  // Stretch: the singular values s1 >= s2 of the map from a triangle's texture coordinates to
  // the skin; s1 / s2 is how much a checker square is drawn out into a rectangle on it.
  std::vector<double> aniso;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::RowVector2d a = m.uvs.row(m.uv_faces(f, 0));
    Eigen::Matrix2d duv;
    duv.col(0) = (m.uvs.row(m.uv_faces(f, 1)) - a).transpose();
    duv.col(1) = (m.uvs.row(m.uv_faces(f, 2)) - a).transpose();
    Eigen::Matrix<double, 3, 2> dp;
    dp.col(0) = (m.v_template.row(m.faces(f, 1)) - m.v_template.row(m.faces(f, 0))).transpose();
    dp.col(1) = (m.v_template.row(m.faces(f, 2)) - m.v_template.row(m.faces(f, 0))).transpose();
    const Eigen::Matrix<double, 3, 2> jac = dp * duv.inverse();
    const Eigen::Vector2d sv = Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(jac).singularValues();
    aniso.push_back(sv(0) / sv(1));
  }
  std::sort(aniso.begin(), aniso.end());
  const double median = aniso[aniso.size() / 2], p99 = aniso[aniso.size() * 99 / 100];
  const double worst = aniso.back();
  const double mean_ratio = uv_total / area_total;
  int dense = 0;
  for (double x : ratio) dense += x > 10.0 * mean_ratio || x < 0.1 * mean_ratio;
  std::printf(
      "UV: %lld triangles, %d flipped or degenerate, %d corners outside [0,1]^2; stretch "
      "s1/s2 median %.3f, 99th percentile %.3f, worst %.3f; %d triangles with texture "
      "density beyond 10x of the mean either way; UV area covered %.3f\n",
      static_cast<long long>(m.num_faces()), flipped, outside, median, p99, worst, dense, uv_total);
  EXPECT_EQ(flipped, 0);
  EXPECT_EQ(outside, 0);
  EXPECT_LT(p99, kStretch99);
}
