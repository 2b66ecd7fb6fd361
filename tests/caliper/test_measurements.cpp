// Measurements as data, landmark tables, circumferences by plane slicing, input validation.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "caliper/circumference.hpp"
#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "caliper_test/random_model.hpp"
#include "core_test_meshes.hpp"
#include "smpl/body_model.hpp"
#include "smpl/constants.hpp"

namespace caliper {
namespace {

using test::Mesh;

// Differences of coordinates of O(1) size: a few ulps.
constexpr double kExactTol = 1e-12;

TEST(MeasurementDefs, ThirteenInPaperOrderWithKnownLandmarks) {
  const std::vector<std::string> expected = {
      "height",          "nipple_height", "navel_height",  "inseam_height", "shoulder_width",
      "chest_width",     "waist_width",   "torso_depth",   "hip_width",     "arm_span_fingertips",
      "arm_span_wrists", "arm_length",    "forearm_length"};
  const auto& defs = paper_measurements();
  ASSERT_EQ(defs.size(), expected.size());
  const auto& names = landmark_names();
  const std::set<std::string> known(names.begin(), names.end());
  for (std::size_t i = 0; i < defs.size(); ++i) {
    EXPECT_EQ(defs[i].id, expected[i]);
    EXPECT_TRUE(known.count(defs[i].from)) << defs[i].from;
    if (defs[i].kind == MeasurementKind::Distance) {
      EXPECT_TRUE(known.count(defs[i].to));
    }
    EXPECT_EQ(&measurement_def(defs[i].id), &defs[i]);
  }
  EXPECT_EQ(measurement_def("arm_length").from, "left_shoulder");
  EXPECT_EQ(measurement_def("arm_length").to, "left_wrist");
  EXPECT_EQ(measurement_def("forearm_length").from, "left_elbow");
  EXPECT_THROW(measurement_def("wingspan"), InvalidInputError);
}

TEST(LandmarkTables, SmplTableMatchesTheReference) {
  // Vertex ids from /work/shared/reference/smpl-format.md (0-based).
  const auto& t = smpl_landmarks();
  EXPECT_EQ(t.at("head_top"), std::vector<int>{411});
  EXPECT_EQ(t.at("left_fingertip"), std::vector<int>{2445});
  EXPECT_EQ(t.at("right_fingertip"), std::vector<int>{5905});
  EXPECT_EQ(t.at("crotch"), std::vector<int>{1209});
  EXPECT_EQ(t.at("left_hip"), std::vector<int>{3129});  // widest, trochanter level
  EXPECT_EQ(t.at("right_hip"), std::vector<int>{6550});
  EXPECT_EQ(t.at("left_shoulder"), std::vector<int>{3011});
  EXPECT_EQ(t.at("left_wrist"), std::vector<int>{2241});
  EXPECT_EQ(t.at("left_elbow"), std::vector<int>{1657});
  // Issue 10: 3501 is the navel pit (3500 is 1.6 mm off it); the right nipple, elbow and heel
  // are the mirrors of the left ones (within 2.7-6.4 mm), 6488 / 5129 / 6787 were not.
  EXPECT_EQ(t.at("navel"), std::vector<int>{3501});
  EXPECT_EQ(t.at("left_nipple"), std::vector<int>{3042});
  EXPECT_EQ(t.at("right_nipple"), std::vector<int>{6489});
  EXPECT_EQ(t.at("right_elbow"), std::vector<int>{5126});
  EXPECT_EQ(t.at("left_heel"), std::vector<int>{3387});
  EXPECT_EQ(t.at("right_heel"), std::vector<int>{6786});
  for (const auto& [name, ids] : t) {
    for (int id : ids) EXPECT_TRUE(id >= 0 && id < kSmplVertexCount) << name;
  }
  // Sides and back are derived per model, not fixed ids.
  EXPECT_EQ(t.count("left_waist"), 0u);
  EXPECT_EQ(t.count("torso_back"), 0u);
}

// A vertical prism body: a 1.8 m column with landmarks at known vertices.
struct ColumnBody {
  Mesh mesh;
  LandmarkTable landmarks;
};

ColumnBody column_body(double floor_y) {
  ColumnBody b;
  b.mesh = test::make_prism(test::circle(16, 0.15), floor_y, floor_y + 1.8, 10);
  const auto at = [&](double x, double y, double z) {
    return test::nearest_vertex(b.mesh.v, Eigen::Vector3d(x, floor_y + y, z));
  };
  b.landmarks["head_top"] = {at(0, 1.8, 0)};
  b.landmarks["navel"] = {at(0, 1.0, 0.15)};
  b.landmarks["left_hip"] = {at(0.15, 0.8, 0)};
  b.landmarks["right_hip"] = {at(-0.15, 0.8, 0)};
  b.landmarks["left_wrist"] = {at(0.15, 1.6, 0), at(0.15, 1.4, 0)};  // mean of two
  return b;
}

TEST(Measure, HeightsAboveTheLowestPointAndDistances) {
  for (double floor_y : {0.0, -1.12}) {
    const ColumnBody b = column_body(floor_y);
    const MeasurementMap m = measure(b.mesh.v, b.landmarks);
    EXPECT_NEAR(m.at("height"), 1.8, kExactTol);
    EXPECT_NEAR(m.at("navel_height"), 1.0, kExactTol);
    EXPECT_NEAR(m.at("hip_width"), 0.3, kExactTol);
    EXPECT_EQ(m.count("arm_length"), 0u);  // shoulders missing: left out
    MeasurementDef wrist{"wrist_height", MeasurementKind::Height, "left_wrist", "", ""};
    EXPECT_NEAR(measure(b.mesh.v, b.landmarks, wrist), 1.5, kExactTol);
    EXPECT_NEAR(floor_height(b.mesh.v), floor_y, kExactTol);
  }
}

TEST(Measure, MissingLandmarkIsNamed) {
  const ColumnBody b = column_body(0.0);
  try {
    measure(b.mesh.v, b.landmarks, measurement_def("arm_length"));
    FAIL() << "expected LandmarkError";
  } catch (const LandmarkError& e) {
    EXPECT_NE(std::string(e.what()).find("left_shoulder"), std::string::npos) << e.what();
  }
  LandmarkTable bad = b.landmarks;
  bad["navel"] = {100000};
  EXPECT_THROW(measure(b.mesh.v, bad, measurement_def("navel_height")), LandmarkError);
  bad["navel"] = {};
  EXPECT_THROW(measure(b.mesh.v, bad, measurement_def("navel_height")), LandmarkError);
  EXPECT_THROW(floor_height(smpl::Vertices(0, 3)), InvalidInputError);
}

TEST(LandmarksFor, ModelTableOverridesTheSmplTable) {
  smpl::BodyModel model = test::make_random_model(10, 24, false, 3);
  ASSERT_EQ(model.num_vertices(), kSmplVertexCount);
  model.landmarks.erase("crotch");  // falls back to the built-in SMPL id
  const LandmarkTable t = landmarks_for(model);
  EXPECT_EQ(t.at("head_top"), model.landmarks.at("head_top"));
  EXPECT_EQ(t.at("crotch"), smpl_landmarks().at("crotch"));
  // Another topology gets only its own table.
  smpl::BodyModel other = model;
  other.v_template.conservativeResize(100, 3);
  other.landmarks = {{"head_top", {5}}};
  const LandmarkTable t2 = landmarks_for(other);
  EXPECT_EQ(t2.size(), 1u);
  other.landmarks["navel"] = {100};
  EXPECT_THROW(landmarks_for(other), LandmarkError);
}

TEST(LandmarksFor, DerivedTorsoLandmarksOnAnEllipsoid) {
  // Torso: ellipsoid with half-widths 0.16 (x) and 0.1 (z); the navel on the front at y = 0.
  const Mesh m = test::make_ellipsoid(0.16, 0.4, 0.1, 41, 64);
  LandmarkTable t;
  t["navel"] = {test::nearest_vertex(m.v, Eigen::Vector3d(0, 0, 0.1))};
  t["left_nipple"] = {test::nearest_vertex(m.v, Eigen::Vector3d(0.08, 0.2, 0.09))};
  t["right_nipple"] = {test::nearest_vertex(m.v, Eigen::Vector3d(-0.08, 0.2, 0.09))};
  t["left_waist"] = {7};  // existing entries are kept
  derive_torso_landmarks(m.v, t);
  EXPECT_EQ(t.at("left_waist"), std::vector<int>{7});
  ASSERT_TRUE(t.count("right_waist") && t.count("torso_back") && t.count("left_chest"));
  const Eigen::Vector3d rw = landmark_point(m.v, t.at("right_waist"));
  const Eigen::Vector3d back = landmark_point(m.v, t.at("torso_back"));
  const Eigen::Vector3d lc = landmark_point(m.v, t.at("left_chest"));
  EXPECT_NEAR(rw.x(), -0.16, 1e-3);  // the widest point on the equator ring
  EXPECT_NEAR(back.z(), -0.1, 1e-3);
  EXPECT_GT(lc.x(), 0.1);
  EXPECT_NEAR(lc.y(), landmark_point(m.v, t.at("left_nipple")).y(), 0.015);
}

TEST(MeasureAll, VolumeWeightAndCircumferences) {
  const smpl::BodyModel model = test::make_random_model(10, 24, false, 5);
  const Eigen::VectorXd betas = Eigen::VectorXd::LinSpaced(4, -1.0, 1.0);
  const smpl::Vertices v = shaped_vertices(model, betas);
  const MeasurementMap m = measure_all(model, v);
  const double volume = mesh_volume(v, model.faces);
  EXPECT_DOUBLE_EQ(m.at("volume"), volume);
  EXPECT_DOUBLE_EQ(m.at("weight"),
                   weight_from_volume(volume, weight_formula_for(model.meta.gender)));
  // A model that carries its own weight formula is weighed with it, not with its gender's.
  smpl::BodyModel own = model;
  set_weight_formula(own, {1010.0, 1.5, "own"});
  EXPECT_DOUBLE_EQ(measure_all(own, v).at("weight"), 1010.0 * volume + 1.5);
  for (const auto& d : paper_measurements()) EXPECT_TRUE(m.count(d.id)) << d.id;
  EXPECT_TRUE(m.count("waist_circumference"));
  EXPECT_THROW(measure_all(model, smpl::Vertices(10, 3)), InvalidInputError);
  // shaped_vertices: v_template + shapedirs * betas, with bad input refused.
  EXPECT_NEAR(v(100, 1), model.v_template(100, 1) + model.shapedirs.row(301).head(4).dot(betas),
              kExactTol);
  EXPECT_THROW(shaped_vertices(model, Eigen::VectorXd::Zero(11)), InvalidInputError);
  Eigen::VectorXd nan = Eigen::VectorXd::Zero(3);
  nan(1) = std::nan("");
  EXPECT_THROW(shaped_vertices(model, nan), InvalidInputError);
}

TEST(MeasureAll, ModelInfoMadeOnceGivesTheSameValues) {
  const smpl::BodyModel model = test::make_random_model(10, 24, false, 5);
  const ModelMeasureInfo info(model);
  EXPECT_TRUE(info.closed);
  EXPECT_EQ(info.landmarks, landmarks_for(model));
  for (double b : {-1.5, 0.0, 2.0}) {
    const smpl::Vertices v = shaped_vertices(model, Eigen::VectorXd::Constant(4, b));
    EXPECT_EQ(measure_all(model, v, info), measure_all(model, v));  // bit for bit
  }
  EXPECT_THROW(measure_all(model, smpl::Vertices(10, 3), info), InvalidInputError);
  // An open surface (one face removed): no volume or weight, with or without the info.
  smpl::BodyModel open = model;
  open.faces = model.faces.topRows(model.faces.rows() - 1);
  const ModelMeasureInfo open_info(open);
  EXPECT_FALSE(open_info.closed);
  const MeasurementMap m = measure_all(open, open.v_template, open_info);
  EXPECT_EQ(m.count("volume") + m.count("weight"), 0u);
  EXPECT_EQ(m, measure_all(open, open.v_template));
}

// ---------------------------------------------------------------------------------------------
// Circumferences

double polygon_perimeter(int n, double r) {
  return 2.0 * n * r * std::sin(M_PI / n);
}

TEST(Circumference, CylinderSliceIsTheRingPerimeter) {
  const Mesh m = test::make_prism(test::circle(64, 0.2), 0.0, 1.0, 5);
  const auto loops = slice_mesh(m.v, m.f, 0.37);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_TRUE(loops[0].closed);
  // Two crossings per side quad: its vertical edge and its diagonal (colinear with the ring).
  EXPECT_EQ(loops[0].points.size(), 128u);
  EXPECT_NEAR(loops[0].length, polygon_perimeter(64, 0.2), kExactTol);
  EXPECT_NEAR(convex_hull_perimeter(loops[0].points), polygon_perimeter(64, 0.2), kExactTol);
  EXPECT_TRUE(loop_contains(loops[0], Eigen::Vector2d(0.0, 0.0)));
  EXPECT_FALSE(loop_contains(loops[0], Eigen::Vector2d(0.3, 0.0)));
  // A slice through a ring of vertices (exactly on the plane) still gives one closed loop.
  const auto on_ring = slice_mesh(m.v, m.f, 0.25);
  ASSERT_EQ(on_ring.size(), 1u);
  EXPECT_NEAR(on_ring[0].length, polygon_perimeter(64, 0.2), 1e-9);
  EXPECT_TRUE(slice_mesh(m.v, m.f, 2.0).empty());
}

TEST(Circumference, FaceIndicesOutOfRangeAreRefused) {
  const Mesh m = test::make_prism(test::circle(8, 0.2), 0.0, 1.0, 2);
  for (const int bad : {-1, static_cast<int>(m.v.rows())}) {
    smpl::Faces f = m.f;
    f(f.rows() - 1, 2) = bad;
    EXPECT_THROW(slice_mesh(m.v, f, 0.37), InvalidInputError) << bad;
  }
}

TEST(Circumference, TapeSpansConcavities) {
  // A star prism: 8 outer points at 0.2 m and 8 inner at 0.1 m.
  std::vector<Eigen::Vector2d> star;
  for (int i = 0; i < 16; ++i) {
    const double r = i % 2 ? 0.1 : 0.2, t = 2.0 * M_PI * i / 16;
    star.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  const Mesh m = test::make_prism(star, 0.0, 1.0, 3);
  const auto loops = slice_mesh(m.v, m.f, 0.3);
  ASSERT_EQ(loops.size(), 1u);
  double star_length = 0.0;
  for (int i = 0; i < 16; ++i) star_length += (star[(i + 1) % 16] - star[i]).norm();
  EXPECT_NEAR(loops[0].length, star_length, kExactTol);
  EXPECT_NEAR(convex_hull_perimeter(loops[0].points), polygon_perimeter(8, 0.2), kExactTol);
}

TEST(Circumference, EllipsoidEquatorConvergesToTheEllipsePerimeter) {
  const double a = 0.17, c = 0.11;
  const double h = std::pow((a - c) / (a + c), 2);
  const double ramanujan = M_PI * (a + c) * (1 + 3 * h / (10 + std::sqrt(4 - 3 * h)));
  double previous = 1.0;
  for (int n : {16, 64, 256}) {
    const Mesh m = test::make_ellipsoid(a, 0.4, c, 2 * n + 1, n);  // a ring at the equator
    const auto loops = slice_mesh(m.v, m.f, 0.0);
    ASSERT_EQ(loops.size(), 1u);
    const double err = std::abs(convex_hull_perimeter(loops[0].points) - ramanujan);
    EXPECT_LT(err, previous);
    previous = err;
  }
  EXPECT_LT(previous / ramanujan, 1e-4);  // 256 segments: polygon error ~ (pi/n)^2 / 6
}

TEST(Circumference, TorsoLegsAndArmsAreSeparated) {
  // Two legs (x = +/-0.1, r = 0.07) from 0 to 0.8, a torso (r = 0.15) from 0.8 to 1.4 and two
  // T-pose "hands" (small prisms at x = +/-0.7) crossing the same heights.
  Mesh body = test::make_prism(test::circle(32, 0.07, 0.1), 0.0, 0.8, 4, 0.1);
  test::append(body, test::make_prism(test::circle(32, 0.07, -0.1), 0.0, 0.8, 4, -0.1));
  test::append(body, test::make_prism(test::circle(32, 0.15), 0.8, 1.4, 4));
  test::append(body, test::make_prism(test::circle(8, 0.04, 0.7), 0.5, 1.3, 3, 0.7));
  test::append(body, test::make_prism(test::circle(8, 0.04, -0.7), 0.5, 1.3, 3, -0.7));
  LandmarkTable t;
  const auto at = [&](double x, double y, double z) {
    return std::vector<int>{test::nearest_vertex(body.v, Eigen::Vector3d(x, y, z))};
  };
  t["crotch"] = at(0, 0.8, 0);
  t["navel"] = at(0, 1.0, 0.15);
  t["left_waist"] = at(0.15, 1.0, 0);
  t["right_waist"] = at(-0.15, 1.0, 0);
  t["left_hip"] = at(0.17, 0.6, 0);
  t["right_hip"] = at(-0.17, 0.6, 0);
  const auto c = circumferences(body.v, body.f, t);
  // Waist: the torso loop only, not the hands.
  EXPECT_NEAR(c.at("waist_circumference"), polygon_perimeter(32, 0.15), 1e-9);
  // Hip below the crotch: the hull around both legs = 2 half circles + 2 straight spans.
  const double legs_hull = 2 * 0.2 + polygon_perimeter(32, 0.07);
  EXPECT_NEAR(c.at("hip_circumference"), legs_hull, 1e-9);
  // Thigh: the left leg (+x) alone.
  EXPECT_NEAR(c.at("thigh_circumference"), polygon_perimeter(32, 0.07), 1e-9);
  EXPECT_EQ(c.count("chest_circumference"), 0u);  // no nipple landmark
  const auto lengths = circumferences(body.v, body.f, t, false);
  EXPECT_NEAR(lengths.at("hip_circumference"), 2 * polygon_perimeter(32, 0.07), 1e-9);
}

// The chest's landmarks on a prism torso of half-width 0.15 m from 1.0 to 1.4 m (rings at 1.0,
// 1.133, 1.267, 1.4): the nipple between the two middle rings (the plane at 1.2 m), the chest's
// sides at the torso's sides and, with `acromia`, the shoulders at x = +/-0.2.
LandmarkTable chest_landmarks(const Mesh& m, bool acromia) {
  const auto at = [&](double x, double y, double z) {
    return test::nearest_vertex(m.v, Eigen::Vector3d(x, y, z));
  };
  LandmarkTable t;
  t["left_nipple"] = {at(0.15, 1.13, 0.1), at(0.15, 1.27, 0.1)};
  t["left_chest"] = {at(0.15, 1.2, 0.1)};
  t["right_chest"] = {at(-0.15, 1.2, 0.1)};
  if (acromia) {
    t["left_shoulder"] = {at(0.2, 1.4, 0.04)};
    t["right_shoulder"] = {at(-0.2, 1.4, 0.04)};
  }
  return t;
}

TEST(Circumference, TheChestTakesNoneOfTheArmsBeyondTheAcromia) {
  // In the T-pose the plane at the nipples can run along the underside of the arms: one loop
  // round the torso and both arms. The torso's section here is the rectangle |x| <= 0.15,
  // |z| <= 0.1, each arm the band 0.15 <= |x| <= 0.6, |z| <= 0.04 (one outline, a prism). With
  // the acromia at x = +/-0.2 the tape goes round the torso and the arms' roots up to there: the
  // hull of (+/-0.15, +/-0.1) and (+/-0.2, +/-0.04). Without the shoulder landmarks, the girth
  // as before: the hull reaches the arms' ends.
  const std::vector<Eigen::Vector2d> outline = {
      // counter-clockwise in (x, z)
      {0.15, -0.1},  {0.15, -0.04}, {0.2, -0.04},   {0.6, -0.04},  {0.6, 0.04},  {0.2, 0.04},
      {0.15, 0.04},  {0.15, 0.1},   {-0.15, 0.1},   {-0.15, 0.04}, {-0.2, 0.04}, {-0.6, 0.04},
      {-0.6, -0.04}, {-0.2, -0.04}, {-0.15, -0.04}, {-0.15, -0.1}};
  const Mesh body = test::make_prism(outline, 1.0, 1.4, 4);
  LandmarkTable t = chest_landmarks(body, false);
  ASSERT_NEAR(landmark_point(body.v, t.at("left_nipple")).y(), 1.2, 1e-12);
  const double whole = 2 * 0.3 + 2 * 0.08 + 4 * std::hypot(0.45, 0.06);
  EXPECT_NEAR(circumferences(body.v, body.f, t).at("chest_circumference"), whole, 1e-9);
  t = chest_landmarks(body, true);
  const double clipped = 2 * 0.3 + 2 * 0.08 + 4 * std::hypot(0.05, 0.06);
  EXPECT_NEAR(circumferences(body.v, body.f, t).at("chest_circumference"), clipped, 1e-9);
  // Acromia that coincide (a broken landmark table) give no band: the girth as without them.
  LandmarkTable same = t;
  same["right_shoulder"] = same["left_shoulder"];
  EXPECT_NEAR(circumferences(body.v, body.f, same).at("chest_circumference"), whole, 1e-9);
  // The tape's length (convex_hull false): the outline closed straight along the cuts.
  const double along = 2 * 0.3 + 4 * 0.06 + 4 * 0.05 + 2 * 0.08;
  EXPECT_NEAR(circumferences(body.v, body.f, t, false).at("chest_circumference"), along, 1e-9);
  // Arms that have not met the torso yet (their own loops, 2 cm from its sides) count up to the
  // acromia too: the same girth, no jump as the plane passes the armpit.
  Mesh apart =
      test::make_prism({{0.15, -0.1}, {0.15, 0.1}, {-0.15, 0.1}, {-0.15, -0.1}}, 1.0, 1.4, 4);
  for (const double side : {1.0, -1.0}) {
    std::vector<Eigen::Vector2d> arm = {{0.17, -0.04}, {0.2, -0.04}, {0.6, -0.04},
                                        {0.6, 0.04},   {0.2, 0.04},  {0.17, 0.04}};
    for (auto& p : arm) p.x() *= side;
    if (side < 0) std::reverse(arm.begin(), arm.end());  // counter-clockwise once mirrored
    test::append(apart, test::make_prism(arm, 1.0, 1.4, 4, side * 0.4));
  }
  ASSERT_EQ(slice_mesh(apart.v, apart.f, 1.2).size(), 3u);
  EXPECT_NEAR(
      circumferences(apart.v, apart.f, chest_landmarks(apart, true)).at("chest_circumference"),
      clipped, 1e-9);
}

TEST(Circumference, ThighAtTheGlutealFoldKeepsToTheLeftOfTouchingThighs) {
  // Thighs that touch make one loop (a stadium: half circles of r = 0.07 about x = +/-0.1 joined
  // by straight sides) from 0 to 0.8 under a torso. With a left_gluteal_fold landmark the thigh
  // is taken at its height around the left leg only: the hull of the loop's part at x >= the
  // crotch's x (the half circle, the two straight halves and the cut across, where a tape passes
  // between the thighs). Without it, the slice 2 cm under the crotch finds no loop of its own for
  // the left leg, and there is no thigh girth.
  constexpr int kHalf = 16;
  constexpr double r = 0.07;
  std::vector<Eigen::Vector2d> stadium;
  for (int i = 0; i <= kHalf; ++i) {  // the left (+x) half circle, front to back
    const double t = -M_PI / 2 + M_PI * i / kHalf;
    stadium.emplace_back(0.1 + r * std::cos(t), r * std::sin(t));
  }
  for (int i = 0; i <= kHalf; ++i) {
    const double t = M_PI / 2 + M_PI * i / kHalf;
    stadium.emplace_back(-0.1 + r * std::cos(t), r * std::sin(t));
  }
  Mesh body = test::make_prism(stadium, 0.0, 0.8, 4);
  test::append(body, test::make_prism(test::circle(32, 0.2), 0.8, 1.4, 4));
  LandmarkTable t;
  t["crotch"] = {test::nearest_vertex(body.v, Eigen::Vector3d(0.0, 0.8, 0.07))};
  const auto without = circumferences(body.v, body.f, t);
  EXPECT_EQ(without.count("thigh_circumference"), 0u);
  t["left_gluteal_fold"] = {test::nearest_vertex(body.v, Eigen::Vector3d(0.1, 0.6, -0.07))};
  ASSERT_LT(landmark_point(body.v, t.at("left_gluteal_fold")).y(), 0.7);  // a ring of the legs
  double half_circle = 0.0;
  for (int i = 0; i < kHalf; ++i) half_circle += (stadium[i + 1] - stadium[i]).norm();
  const auto with = circumferences(body.v, body.f, t);
  ASSERT_EQ(with.count("thigh_circumference"), 1u);
  EXPECT_NEAR(with.at("thigh_circumference"), half_circle + 2 * 0.1 + 2 * r, 1e-9);
}

TEST(Circumference, TheThighLevelIsTheFoldButAtLeastThreeCentimetresUnderTheCrotch) {
  // A man's fold vertex can lie above his crotch (the open male model's mean ANSUR II man: 6.5 mm
  // above), where a slice goes round the pelvis: the level is then 3 cm under the crotch; a fold
  // further down (the average woman's, 4.3 cm) is taken as it is.
  smpl::Vertices v(3, 3);
  v << 0.0, 0.80, 0.0,  // crotch
      0.1, 0.81, -0.1,  // a fold above the crotch
      0.1, 0.75, -0.1;  // a fold 5 cm under it
  LandmarkTable t;
  EXPECT_FALSE(thigh_fold_level(v, t).has_value());
  t["crotch"] = {0};
  EXPECT_FALSE(thigh_fold_level(v, t).has_value());
  t["left_gluteal_fold"] = {1};
  ASSERT_TRUE(thigh_fold_level(v, t).has_value());
  EXPECT_DOUBLE_EQ(*thigh_fold_level(v, t), 0.80 - kThighBelowCrotch);
  EXPECT_DOUBLE_EQ(kThighBelowCrotch, 0.03);
  t["left_gluteal_fold"] = {2};
  EXPECT_DOUBLE_EQ(*thigh_fold_level(v, t), 0.75);
}

TEST(Circumference, IliacCrestWaistIsTheGirthAtTheCrestLandmarks) {
  // A torso of three stacked prisms: r = 0.16 from 0.8 to 1.05 (the pelvis, iliac crest level),
  // r = 0.13 from 1.05 to 1.4 (the waist at the navel) and r = 0.2 from 1.4 to 1.6 (the
  // shoulders), legs below, T-pose "hands" at x = +/-0.7 crossing both lower levels.
  Mesh body = test::make_prism(test::circle(32, 0.07, 0.1), 0.0, 0.8, 4, 0.1);
  test::append(body, test::make_prism(test::circle(32, 0.07, -0.1), 0.0, 0.8, 4, -0.1));
  test::append(body, test::make_prism(test::circle(32, 0.16), 0.8, 1.05, 4));
  test::append(body, test::make_prism(test::circle(32, 0.13), 1.05, 1.4, 4));
  test::append(body, test::make_prism(test::circle(32, 0.2), 1.4, 1.6, 4));
  test::append(body, test::make_prism(test::circle(8, 0.04, 0.7), 0.5, 1.3, 3, 0.7));
  test::append(body, test::make_prism(test::circle(8, 0.04, -0.7), 0.5, 1.3, 3, -0.7));
  LandmarkTable t;
  const auto at = [&](double x, double y, double z) {
    return std::vector<int>{test::nearest_vertex(body.v, Eigen::Vector3d(x, y, z))};
  };
  t["navel"] = at(0, 1.2, 0.13);
  t["left_waist"] = at(0.13, 1.2, 0);
  t["right_waist"] = at(-0.13, 1.2, 0);
  t["left_shoulder"] = at(0.2, 1.6, 0);
  t["right_shoulder"] = at(-0.2, 1.6, 0);
  EXPECT_EQ(circumferences(body.v, body.f, t).count("waist_iliac_circumference"), 0u)
      << "no iliac crest landmarks, no iliac-crest waist";
  const double crest_y = 0.8 + 0.25 * 2.0 / 3.0;  // the prism's third ring of vertices
  t["left_iliac_crest"] = at(0.16, crest_y, 0);
  t["right_iliac_crest"] = at(-0.16, crest_y, 0);
  const auto c = circumferences(body.v, body.f, t);
  EXPECT_NEAR(c.at("waist_iliac_circumference"), polygon_perimeter(32, 0.16), 1e-9);
  EXPECT_NEAR(c.at("waist_circumference"), polygon_perimeter(32, 0.13), 1e-9);

  // The opt-in rule finds the same two vertices when asked for that level (the hands lie
  // outside the shoulders and are skipped), and never replaces a landmark a table has.
  LandmarkTable derived = t;
  derived.erase("left_iliac_crest");
  derived.erase("right_iliac_crest");
  derive_iliac_crest_landmarks(body.v, derived, crest_y / 1.6, 0.01);
  ASSERT_EQ(derived.count("left_iliac_crest"), 1u);
  EXPECT_NEAR(body.v(derived.at("left_iliac_crest")[0], 0), 0.16, 1e-12);
  EXPECT_NEAR(body.v(derived.at("left_iliac_crest")[0], 1), crest_y, 1e-12);
  EXPECT_NEAR(body.v(derived.at("right_iliac_crest")[0], 0), -0.16, 1e-12);
  LandmarkTable kept = t;
  derive_iliac_crest_landmarks(body.v, kept, 0.2);
  EXPECT_EQ(kept.at("left_iliac_crest"), t.at("left_iliac_crest"));
  // Without shoulders, or with no vertex near the level, the rule says why.
  derived.erase("left_shoulder");
  derived.erase("left_iliac_crest");
  EXPECT_THROW(derive_iliac_crest_landmarks(body.v, derived), LandmarkError);
  LandmarkTable gap = t;
  gap.erase("left_iliac_crest");
  EXPECT_THROW(derive_iliac_crest_landmarks(body.v, gap, 0.75 / 1.6, 0.001), LandmarkError);
}

TEST(Circumference, HullCornerCases) {
  EXPECT_EQ(convex_hull_perimeter({}), 0.0);
  EXPECT_EQ(convex_hull_perimeter({Eigen::Vector2d(1, 1)}), 0.0);
  EXPECT_NEAR(convex_hull_perimeter({{0, 0}, {1, 0}, {2, 0}}), 4.0, kExactTol);  // colinear
  EXPECT_NEAR(convex_hull_perimeter({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}}), 4.0, kExactTol);
}

// ---------------------------------------------------------------------------------------------
// Validation

MeasurementMap typical_adult() {
  return {{"height", 1.75},        {"weight", 70.0},    {"arm_span_fingertips", 1.76},
          {"inseam_height", 0.80}, {"hip_width", 0.34}, {"arm_length", 0.58}};
}

const ValidationMessage* find_message(const std::vector<ValidationMessage>& m,
                                      const std::string& id) {
  for (const auto& x : m) {
    if (x.id == id) return &x;
  }
  return nullptr;
}

TEST(Validate, TypicalAdultIsClean) {
  EXPECT_TRUE(validate_measurements(typical_adult()).empty());
}

TEST(Validate, FourMetreTallPerson) {
  MeasurementMap m = typical_adult();
  m["height"] = 4.0;
  const auto msgs = validate_measurements(m);
  EXPECT_TRUE(has_errors(msgs));
  const ValidationMessage* h = find_message(msgs, "height");
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(h->severity, Severity::Error);
  EXPECT_DOUBLE_EQ(h->min, 0.5);
  EXPECT_DOUBLE_EQ(h->max, 2.5);
  EXPECT_NE(h->message.find("4 m"), std::string::npos) << h->message;
  EXPECT_NE(h->message.find("0.5 to 2.5 m"), std::string::npos) << h->message;
}

TEST(Validate, NegativeWeightNaNAndUnknown) {
  MeasurementMap m = typical_adult();
  m["weight"] = -70.0;
  m["hip_width"] = std::nan("");
  m["shoe_size"] = 42.0;
  const auto msgs = validate_measurements(m);
  ASSERT_NE(find_message(msgs, "weight"), nullptr);
  EXPECT_EQ(find_message(msgs, "weight")->severity, Severity::Error);
  EXPECT_NE(find_message(msgs, "weight")->message.find("-70 kg"), std::string::npos);
  ASSERT_NE(find_message(msgs, "hip_width"), nullptr);
  EXPECT_EQ(find_message(msgs, "hip_width")->severity, Severity::Error);
  ASSERT_NE(find_message(msgs, "shoe_size"), nullptr);
  EXPECT_EQ(find_message(msgs, "shoe_size")->severity, Severity::Warning);
}

TEST(Validate, ArmSpanHalfTheHeight) {
  MeasurementMap m = typical_adult();
  m["arm_span_fingertips"] = 0.875;  // within its own range, but half the height
  const auto msgs = validate_measurements(m);
  const ValidationMessage* r = find_message(msgs, "arm_span_fingertips/height");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->severity, Severity::Error);
  EXPECT_NEAR(r->value, 0.5, 1e-12);
  EXPECT_NE(r->message.find("0.5 times height"), std::string::npos) << r->message;
}

TEST(Validate, UnusualButPossibleIsAWarning) {
  MeasurementMap m = typical_adult();
  m["height"] = 2.2;
  m["arm_span_fingertips"] = 2.2;
  m["inseam_height"] = 1.0;
  m["weight"] = 100.0;
  m["arm_length"] = 0.72;
  m["hip_width"] = 0.4;
  const auto msgs = validate_measurements(m);
  EXPECT_FALSE(has_errors(msgs));
  ASSERT_NE(find_message(msgs, "height"), nullptr);
  EXPECT_EQ(find_message(msgs, "height")->severity, Severity::Warning);
  EXPECT_THROW(measurement_range("shoe_size"), InvalidInputError);
}

// ---------------------------------------------------------------------------------------------
// The hanging arm (ANSUR II's protocol; moved here from tests/modelgen with the code).

// A three-vertex-per-side stand-in for a model: acromion (on the collar), wrist (on the
// elbow, which follows the shoulder) and a vertex that is the shoulder joint.
smpl::BodyModel hanging_arm_fixture() {
  smpl::BodyModel m;
  m.parents = smpl::smpl_parents();
  m.v_template.resize(6, 3);
  m.v_template << 0.20, 1.50, 0.0,  // 0 left acromion
      0.70, 1.50, 0.0,              // 1 left wrist
      0.17, 1.45, 0.0,              // 2 left shoulder joint
      -0.20, 1.50, 0.0,             // 3 right acromion
      -0.70, 1.50, 0.0,             // 4 right wrist
      -0.17, 1.45, 0.0;             // 5 right shoulder joint
  std::vector<Eigen::Triplet<double>> jr, w;
  for (int j = 0; j < 24; ++j) {
    jr.emplace_back(j, j == 17 ? 5 : 2, 1.0);
  }
  m.j_regressor.resize(24, 6);
  m.j_regressor.setFromTriplets(jr.begin(), jr.end());
  w.emplace_back(0, 13, 1.0);  // left_collar
  w.emplace_back(1, 18, 1.0);  // left_elbow
  w.emplace_back(2, 16, 1.0);
  w.emplace_back(3, 14, 1.0);  // right_collar
  w.emplace_back(4, 19, 0.5);  // right_elbow and right_wrist
  w.emplace_back(4, 21, 0.5);
  w.emplace_back(5, 17, 1.0);
  m.weights.resize(6, 24);
  m.weights.setFromTriplets(w.begin(), w.end());
  m.landmarks = {
      {"left_shoulder", {0}}, {"left_wrist", {1}}, {"right_shoulder", {3}}, {"right_wrist", {4}}};
  return m;
}

// The hanging-arm length (ANSUR's protocol): the wrist swings down about the shoulder joint,
// the acromion stays. Joint (0.17, 1.45), wrist (0.70, 1.50): hanging wrist at (0.22, 0.92),
// 0.5803 m from the acromion (0.20, 1.50), against 0.50 m in the T-pose.
TEST(HangingArm, SwingsTheWristAboutTheShoulderJointAndKeepsTheAcromion) {
  const smpl::BodyModel m = hanging_arm_fixture();
  EXPECT_NEAR(hanging_arm_length(m, m.v_template), std::hypot(0.02, 0.58), 1e-12);
  // A wrist weighted half on a joint that does not follow the shoulder moves half way.
  smpl::BodyModel half = m;
  std::vector<Eigen::Triplet<double>> w;
  for (int v = 0; v < 6; ++v) {
    for (smpl::SparseMatrix::InnerIterator it(m.weights, v); it; ++it) {
      if (v != 1) {
        w.emplace_back(v, static_cast<int>(it.col()), it.value());
      }
    }
  }
  w.emplace_back(1, 18, 0.5);
  w.emplace_back(1, 9, 0.5);  // spine3
  half.weights.setFromTriplets(w.begin(), w.end());
  const Eigen::Vector2d left =
      0.5 * Eigen::Vector2d(0.70, 1.50) + 0.5 * Eigen::Vector2d(0.22, 0.92);
  const double expected =
      0.5 * ((left - Eigen::Vector2d(0.20, 1.50)).norm() + std::hypot(0.02, 0.58));
  EXPECT_NEAR(hanging_arm_length(half, half.v_template), expected, 1e-12);
  smpl::BodyModel missing = m;
  missing.landmarks.erase("right_wrist");
  EXPECT_THROW(hanging_arm_length(missing, missing.v_template), LandmarkError);
  smpl::BodyModel few_joints = m;
  few_joints.parents.resize(16);
  EXPECT_THROW(hanging_arm_length(few_joints, few_joints.v_template), ModelMismatchError);
}

// The acromion-radiale length swings the radiale as the arm length swings the wrist (the
// fixture's radiale placed on its wrist vertices gives the same length), and is NaN, not an
// error, for a model without radiale landmarks (SMPL files), which validation_measurements()
// then leaves out.
TEST(HangingArm, TheUpperArmSwingsTheRadialeAndIsMissingWithoutIt) {
  smpl::BodyModel m = hanging_arm_fixture();
  EXPECT_TRUE(std::isnan(hanging_upper_arm_length(m, m.v_template)));
  m.landmarks["left_radiale"] = {1};
  m.landmarks["right_radiale"] = {4};
  EXPECT_NEAR(hanging_upper_arm_length(m, m.v_template), hanging_arm_length(m, m.v_template),
              1e-15);
  const HangingArms h = hanging_arms(m, m.v_template);
  EXPECT_NEAR(h.radiale[0].x(), 0.22, 1e-12);
  EXPECT_NEAR(h.radiale[0].y(), 0.92, 1e-12);
}

}  // namespace
}  // namespace caliper
