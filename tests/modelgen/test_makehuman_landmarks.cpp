/// \file test_makehuman_landmarks.cpp
/// The paper's landmarks on the MakeHuman topology (issue 11): every measurement definition works
/// on the open model v2's template and gives an adult's values; the rules pick the anatomical
/// places they name; left and right are mirror vertices.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "caliper/measurements.hpp"
#include "makehuman_landmarks.hpp"
#include "makehuman_rig.hpp"
#include "makehuman_test_data.hpp"

namespace {

using makehuman_test::kMh;

const smpl::BodyModel& model() {
  static const smpl::BodyModel m = [] {
    namespace mh = modelgen::mh;
    return mh::template_model(mh::read_assets(kMh), mh::default_regressor_targets());
  }();
  return m;
}

using makehuman_test::assets;

/// A T-posed body of the base mesh plus `target` (relative to targets/) at weight 1, in the
/// template's frame (metres); the base itself for an empty name.
smpl::Vertices body(const std::string& target) {
  namespace mh = modelgen::mh;
  mh::Positions p = assets().base.vertices;
  if (!target.empty()) mh::add_target(mh::read_asset_target(assets(), target), 1.0, p);
  return mh::skin_vertices(assets().skin, mh::t_pose(assets(), p).positions);
}

// Proportions of adults, as fractions of stature, wide enough for every body of the MakeHuman
// shape space the tests use (slim to heavy, both sexes) and narrow enough that a rule picking a
// vertex on the wrong part of the body fails: navel about 0.60 H, nipples about 0.72 H, crotch
// about 0.47 H (Drillis and Contini's segment proportions; ANSUR II's means: crotch height /
// stature 0.47 (women) and 0.48 (men), acromion breadth 0.22 to 0.24).
constexpr double kNavelMin = 0.56, kNavelMax = 0.64;
constexpr double kNippleMin = 0.68, kNippleMax = 0.76;
constexpr double kCrotchMin = 0.43, kCrotchMax = 0.50;
constexpr double kShoulderMin = 0.19, kShoulderMax = 0.27;

// Every measurement definition works on the MakeHuman topology, on the template and on bodies
// far from it (the young macro corners of both sexes at min and max weight): all landmarks of
// the paper present, no value the input validation calls impossible, the heights where an
// adult's are, and height from head top to sole.
TEST(MakeHumanLandmarks, EveryMeasurementWorksAndGivesAnAdultsProportions) {
  REQUIRE_ASSETS();
  const smpl::BodyModel& m = model();
  const caliper::LandmarkTable table = caliper::landmarks_for(m);
  for (const std::string& name : caliper::landmark_names()) {
    EXPECT_TRUE(table.count(name)) << name;
  }
  for (const caliper::MeasurementDef& def : caliper::paper_measurements()) {
    EXPECT_TRUE(caliper::is_available(def, table)) << def.id;
  }
  for (const std::string target :
       {"", "macrodetails/universal-female-young-averagemuscle-minweight.target",
        "macrodetails/universal-female-young-averagemuscle-maxweight.target",
        "macrodetails/universal-male-young-averagemuscle-minweight.target",
        "macrodetails/universal-male-young-maxmuscle-maxweight.target"}) {
    SCOPED_TRACE(target.empty() ? "base" : target);
    smpl::BodyModel b = m;
    b.v_template = body(target);
    const caliper::MeasurementMap v = caliper::measure_all(b, b.v_template);
    for (const caliper::ValidationMessage& msg : caliper::validate_measurements(v)) {
      EXPECT_NE(msg.severity, caliper::Severity::Error) << msg.message;
    }
    const double h = v.at("height");
    EXPECT_NEAR(h, b.v_template.col(1).maxCoeff() - b.v_template.col(1).minCoeff(), 1e-12);
    EXPECT_GT(v.at("navel_height") / h, kNavelMin);
    EXPECT_LT(v.at("navel_height") / h, kNavelMax);
    EXPECT_GT(v.at("nipple_height") / h, kNippleMin);
    EXPECT_LT(v.at("nipple_height") / h, kNippleMax);
    EXPECT_GT(v.at("inseam_height") / h, kCrotchMin);
    EXPECT_LT(v.at("inseam_height") / h, kCrotchMax);
    EXPECT_GT(v.at("shoulder_width") / h, kShoulderMin);
    EXPECT_LT(v.at("shoulder_width") / h, kShoulderMax);
    // Nipples above the navel above the crotch; the elbow between shoulder and wrist.
    EXPECT_GT(v.at("nipple_height"), v.at("navel_height"));
    EXPECT_GT(v.at("navel_height"), v.at("inseam_height"));
    EXPECT_LT(v.at("forearm_length"), v.at("arm_length"));
    for (const char* c : {"chest_circumference", "waist_circumference", "hip_circumference",
                          "thigh_circumference"}) {
      EXPECT_TRUE(v.count(c)) << c;
    }
    EXPECT_GT(v.at("weight"), 30.0);
  }
}

// Left and right landmarks are mirror vertices of each other (the base mesh is symmetric), so a
// symmetric body measures the same on both sides; the midline ones are on the midline.
TEST(MakeHumanLandmarks, LeftAndRightAreMirrorVertices) {
  REQUIRE_ASSETS();
  const smpl::BodyModel& m = model();
  const smpl::Vertices& v = m.v_template;
  constexpr double kMirror = 1e-4;  // metres; MakeHuman's mesh is symmetric to well under this
  for (const auto& [name, ids] : m.landmarks) {
    ASSERT_EQ(ids.size(), 1u) << name;
    if (name.rfind("left_", 0) == 0) {
      const std::string right = "right_" + name.substr(5);
      ASSERT_TRUE(m.landmarks.count(right)) << right;
      const int r = m.landmarks.at(right).front();
      EXPECT_NEAR(v(ids[0], 0), -v(r, 0), kMirror) << name;
      EXPECT_NEAR(v(ids[0], 1), v(r, 1), kMirror) << name;
      EXPECT_NEAR(v(ids[0], 2), v(r, 2), kMirror) << name;
      EXPECT_GT(v(ids[0], 0), 0.0) << name << " is not on the subject's left (+X)";
    } else if (name.rfind("right_", 0) != 0) {
      EXPECT_NEAR(v(ids[0], 0), 0.0, kMirror) << name << " is not on the midline";
    }
  }
}

// The marker rules find the places MakeHuman's own targets name: the navel is a pit (behind the
// front midline 3 cm above and below it), and the nipple is the breast point of a full bust
// (the most forward skin point within 4 cm on the female body at max weight).
TEST(MakeHumanLandmarks, NavelIsThePitAndNippleTheTipOfTheBreast) {
  REQUIRE_ASSETS();
  const smpl::BodyModel& m = model();
  const smpl::Vertices& v = m.v_template;
  const int navel = m.landmarks.at("navel").front();
  for (double dy : {-0.03, 0.03}) {
    double front = -1.0;  // z of the front midline at navel height + dy
    for (Eigen::Index i = 0; i < v.rows(); ++i) {
      if (std::abs(v(i, 0)) < 0.002 && std::abs(v(i, 1) - v(navel, 1) - dy) < 0.015) {
        front = std::max(front, v(i, 2));
      }
    }
    EXPECT_GT(front, v(navel, 2)) << "the navel is not behind the belly " << dy << " m away";
  }
  const smpl::Vertices f =
      body("macrodetails/universal-female-young-averagemuscle-maxweight.target");
  for (const char* side : {"left_nipple", "right_nipple"}) {
    const int n = m.landmarks.at(side).front();
    int around = 0;
    for (Eigen::Index i = 0; i < f.rows(); ++i) {
      if ((f.row(i) - f.row(n)).norm() < 0.04) {
        ++around;
        EXPECT_LE(f(i, 2), f(n, 2) + 0.002) << side << ": vertex " << i << " is further forward";
      }
    }
    EXPECT_GT(around, 20) << side;
  }
}

}  // namespace
