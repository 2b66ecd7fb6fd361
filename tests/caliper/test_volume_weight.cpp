// Mesh volume and weight-from-volume: analytic cases and invariants.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "caliper/errors.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "core_test_meshes.hpp"

namespace caliper {
namespace {

using test::Mesh;

// Sums of a dozen products of O(1) numbers: a few ulps.
constexpr double kVolumeExactTol = 1e-14;

TEST(MeshVolume, UnitCubeIsOne) {
  const Mesh m = test::make_cube();
  EXPECT_NEAR(mesh_volume(m.v, m.f), 1.0, kVolumeExactTol);
}

TEST(MeshVolume, TetrahedronIsOneSixth) {
  const Mesh m = test::make_tetrahedron();
  EXPECT_NEAR(mesh_volume(m.v, m.f), 1.0 / 6.0, kVolumeExactTol);
}

TEST(MeshVolume, InwardWindingNegates) {
  Mesh m = test::make_cube();
  m.f.col(1).swap(m.f.col(2));
  EXPECT_NEAR(mesh_volume(m.v, m.f), -1.0, kVolumeExactTol);
}

TEST(MeshVolume, SphereConvergesFromBelow) {
  // An inscribed polyhedron has less volume than the sphere; the error falls roughly 4x when the
  // resolution doubles (second order).
  const double exact = 4.0 / 3.0 * M_PI;
  double previous_error = 1.0;
  for (int n : {8, 16, 32, 64, 128}) {
    const Mesh m = test::make_ellipsoid(1, 1, 1, n, 2 * n);
    const double v = mesh_volume(m.v, m.f);
    const double error = exact - v;
    EXPECT_GT(error, 0.0) << n;
    EXPECT_LT(error, previous_error / 3.0) << n;  // second-order convergence (ratio ~4)
    previous_error = error;
  }
  EXPECT_LT(previous_error / exact, 1e-3);
}

TEST(MeshVolume, EllipsoidVolume) {
  const Mesh m = test::make_ellipsoid(0.2, 0.9, 0.1, 200, 400);
  // The inscribed UV mesh loses about (pi / 200)^2 / 2.4 = 1.0e-4 of the volume (the sphere
  // test's convergence rate); 2e-4 relative bounds it.
  const double exact = 4.0 / 3.0 * M_PI * 0.2 * 0.9 * 0.1;
  const double v = mesh_volume(m.v, m.f);
  EXPECT_LT(v, exact);
  EXPECT_NEAR(v, exact, 2e-4 * exact);
}

TEST(MeshVolume, RigidMotionInvariance) {
  const Mesh m = test::make_ellipsoid(0.3, 0.8, 0.2, 20, 40);
  const double v0 = mesh_volume(m.v, m.f);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(5.0, -3.0, 12.0);
  smpl::Vertices moved = (m.v * R.transpose()).rowwise() + t;
  // Translation by ~13 m makes the per-face terms ~13^2 times larger: relative 1e-12.
  EXPECT_NEAR(mesh_volume(moved, m.f), v0, 1e-12);
}

TEST(MeshVolume, ScalesAsCube) {
  const Mesh m = test::make_ellipsoid(0.3, 0.8, 0.2, 20, 40);
  const double v0 = mesh_volume(m.v, m.f);
  for (double s : {0.5, 2.0, 3.7}) {
    const smpl::Vertices scaled = m.v * s;
    EXPECT_NEAR(mesh_volume(scaled, m.f), s * s * s * v0, 1e-13 * s * s * s);
  }
}

TEST(MeshVolume, DisjointComponentsAdd) {
  Mesh a = test::make_cube();
  Mesh b = test::make_tetrahedron();
  b.v.col(0).array() += 3.0;
  test::append(a, b);
  EXPECT_NEAR(mesh_volume(a.v, a.f), 1.0 + 1.0 / 6.0, kVolumeExactTol);
}

TEST(MeshVolume, BadInput) {
  const Mesh m = test::make_cube();
  EXPECT_THROW(mesh_volume(m.v, smpl::Faces(0, 3)), InvalidInputError);
  smpl::Faces bad = m.f;
  bad(3, 1) = 8;
  EXPECT_THROW(mesh_volume(m.v, bad), InvalidInputError);
  bad(3, 1) = -1;
  EXPECT_THROW(mesh_volume(m.v, bad), InvalidInputError);
  smpl::Vertices nan = m.v;
  nan(2, 1) = std::nan("");
  EXPECT_THROW(mesh_volume(nan, m.f), InvalidInputError);
}

TEST(Weight, PaperFormulas) {
  // The SMPL template's 0.0688 m^3 gives 66.5 kg (female) and 67.4 kg (male):
  // smpl-format.md, rounded to 0.1 kg.
  EXPECT_NEAR(weight_from_volume(0.0688, female_weight_formula()), 66.5, 0.05);
  EXPECT_NEAR(weight_from_volume(0.0688, male_weight_formula()), 67.4, 0.05);
  EXPECT_DOUBLE_EQ(female_weight_formula().coefficient, 1001.44);
  EXPECT_DOUBLE_EQ(female_weight_formula().intercept, -2.36);
  EXPECT_DOUBLE_EQ(male_weight_formula().coefficient, 1056.44);
  EXPECT_DOUBLE_EQ(male_weight_formula().intercept, -5.28);
}

TEST(Weight, NeutralIsTheMeanOfBoth) {
  for (double v : {0.04, 0.07, 0.12}) {
    const double mean = 0.5 * (weight_from_volume(v, female_weight_formula()) +
                               weight_from_volume(v, male_weight_formula()));
    EXPECT_NEAR(weight_from_volume(v, neutral_weight_formula()), mean, 1e-12);
  }
  EXPECT_EQ(weight_formula_for("female").name, "female");
  EXPECT_EQ(weight_formula_for("Male").name, "male");
  EXPECT_EQ(weight_formula_for("neutral").name, "neutral");
  EXPECT_EQ(weight_formula_for("").name, "neutral");
}

TEST(Weight, AModelsOwnFormulaIsReadFromItsMetadataElseThePapersForItsGender) {
  smpl::BodyModel model;
  model.meta.gender = "female";
  EXPECT_EQ(weight_formula_of(model).coefficient, female_weight_formula().coefficient);
  model.meta.gender = "male";
  EXPECT_EQ(weight_formula_of(model).intercept, male_weight_formula().intercept);
  // Doubles that are not exact in binary come back to the bit.
  const WeightFormula own{1001.44 + 0.1, -2.36 + 1.0 / 3.0, "open-male"};
  set_weight_formula(model, own);
  const WeightFormula back = weight_formula_of(model);
  EXPECT_EQ(back.coefficient, own.coefficient);
  EXPECT_EQ(back.intercept, own.intercept);
  EXPECT_EQ(back.name, "open-male");
  EXPECT_DOUBLE_EQ(weight_from_volume(0.07, back), own.coefficient * 0.07 + own.intercept);
  // Formulas no body has are refused on writing, and the model is left as it was.
  for (const WeightFormula& bad :
       {WeightFormula{0.0, 0.0, ""}, WeightFormula{3000.0, 0.0, ""},
        WeightFormula{std::nan(""), 0.0, ""}, WeightFormula{1000.0, 80.0, ""},
        WeightFormula{1000.0, std::numeric_limits<double>::infinity(), ""}}) {
    EXPECT_THROW(set_weight_formula(model, bad), std::invalid_argument);
  }
  EXPECT_EQ(weight_formula_of(model).coefficient, own.coefficient);
}

TEST(Weight, ABadFormulaInAModelIsRefusedNamingTheKey) {
  smpl::BodyModel model;
  model.meta.gender = "female";
  for (const char* text :
       {"", "not json", "[]", "{\"coefficient\": 1000}", "{\"intercept\": -2}",
        "{\"coefficient\": \"1000\", \"intercept\": -2}",
        "{\"coefficient\": 1e308, \"intercept\": 0}", "{\"coefficient\": 100, \"intercept\": 0}",
        "{\"coefficient\": 1000, \"intercept\": -60}",
        "{\"coefficient\": 1000, \"intercept\": 0, \"name\": 7}"}) {
    model.meta.extra[kWeightFormulaMetaKey] = text;
    try {
      (void)weight_formula_of(model);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const smpl::ModelError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("'weight_formula'"), std::string::npos) << what;
      EXPECT_NE(what.find("caliper-modelgen"), std::string::npos) << what;
    }
  }
}

TEST(Weight, InverseAndCubeRoot) {
  for (const auto& f : {female_weight_formula(), male_weight_formula(), neutral_weight_formula()}) {
    for (double w : {45.0, 70.0, 120.0}) {
      const double v = volume_from_weight(w, f);
      EXPECT_NEAR(weight_from_volume(v, f), w, 1e-12);
      EXPECT_NEAR(weight_feature(w, f), std::cbrt(v), 1e-15);
      EXPECT_NEAR(weight_from_feature(weight_feature(w, f), f), w, 1e-11);
    }
  }
}

TEST(Weight, BadInput) {
  const auto f = female_weight_formula();
  EXPECT_THROW(volume_from_weight(-70.0, f), InvalidInputError);
  EXPECT_THROW(volume_from_weight(-2.36, f), InvalidInputError);  // zero volume
  EXPECT_THROW(volume_from_weight(std::nan(""), f), InvalidInputError);
  EXPECT_THROW(weight_feature(INFINITY, f), InvalidInputError);
  EXPECT_THROW(weight_from_volume(std::nan(""), f), InvalidInputError);
  try {
    volume_from_weight(-70.0, f);
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("-70"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace caliper
