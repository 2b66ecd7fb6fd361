// Geometry of the committed open models (assets/models/caliper-*.npz): closed 2-manifold with
// outward winding, positive volume, no self-intersection at the mean and at +/- 2 SD along the
// first 10 components, no flipped triangles in the test poses, SMPL layout through libsmpl, a
// floor (lowest vertex) that is the same vertex at every training corner.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "caliper/measurements.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "makehuman_measures.hpp"
#include "mesh_checks.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"

namespace {

const char* const kGenders[] = {"female", "male", "neutral"};

std::string model_path(const std::string& gender) {
  return std::string(CALIPER_MODELS_DIR) + "/caliper-" + gender + ".npz";
}

smpl::Vertices shaped(const smpl::BodyModel& m, const Eigen::VectorXd& betas) {
  return smpl::shape(m, betas).vertices;
}

class OpenModel : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override { model_ = smpl::load_model(model_path(GetParam())); }
  smpl::BodyModel model_;
};

TEST_P(OpenModel, HasTheSmplStructure) {
  EXPECT_GE(model_.num_vertices(), 6000);
  EXPECT_LE(model_.num_vertices(), 15000);
  EXPECT_EQ(model_.num_joints(), 24);
  EXPECT_EQ(model_.parents, smpl::smpl_parents());
  EXPECT_EQ(model_.joint_names, smpl::smpl_joint_names());
  EXPECT_GE(model_.num_betas(), 10);
  EXPECT_EQ(model_.meta.gender, GetParam());
  // regressor and weight rows sum to 1, at most 4 weights per vertex, none negative
  constexpr double kSumTol = 1e-9;  // renormalised in double precision
  for (int j = 0; j < model_.j_regressor.rows(); ++j) {
    EXPECT_NEAR(model_.j_regressor.row(j).sum(), 1.0, kSumTol) << "joint " << j;
  }
  for (int v = 0; v < model_.weights.rows(); ++v) {
    int nnz = 0;
    double sum = 0;
    for (smpl::SparseMatrix::InnerIterator it(model_.weights, v); it; ++it) {
      if (it.value() != 0.0) {
        ++nnz;
      }
      EXPECT_GE(it.value(), 0.0);
      sum += it.value();
    }
    ASSERT_LE(nnz, 4) << "vertex " << v;
    ASSERT_NEAR(sum, 1.0, kSumTol) << "vertex " << v;
  }
  // mirror is an involution
  ASSERT_EQ(static_cast<int>(model_.mirror.size()), model_.num_vertices());
  for (int v = 0; v < model_.num_vertices(); ++v) {
    ASSERT_EQ(model_.mirror[static_cast<std::size_t>(model_.mirror[static_cast<std::size_t>(v)])],
              v);
  }
}

// The product weighs an avatar as the generator fitted it: the model carries the generator's
// formula (the paper's on the skin's volume plus 4 L), and its shape curve names the weight in
// kg as its input.
TEST_P(OpenModel, CarriesTheWeightFormulaAndCurveInputItWasFittedWith) {
  const caliper::WeightFormula own = caliper::weight_formula_of(model_);
  const caliper::WeightFormula fitted = modelgen::mh::open_model_weight_formula(GetParam());
  EXPECT_EQ(own.coefficient, fitted.coefficient);
  EXPECT_EQ(own.intercept, fitted.intercept);
  EXPECT_EQ(own.name, fitted.name);
  EXPECT_NE(own.intercept, caliper::weight_formula_for(GetParam()).intercept);
  const std::optional<caliper::ShapeCurve> curve = caliper::shape_curve(model_);
  ASSERT_TRUE(curve);
  EXPECT_EQ(curve->weight_input, caliper::ShapeCurve::WeightInput::kKilograms);
}

TEST_P(OpenModel, HasEveryLandmarkOfTheSharedVocabulary) {
  for (const std::string& name : caliper::landmark_names()) {
    ASSERT_TRUE(model_.landmarks.count(name)) << name;
  }
  const smpl::Vertices& v = model_.v_template;
  auto pt = [&](const std::string& n) {
    return caliper::landmark_point(v, model_.landmarks.at(n));
  };
  const double floor = v.col(1).minCoeff();
  constexpr double kTopTol = 0.005;  // head_top is the mesh's highest point within 5 mm
  EXPECT_NEAR(pt("head_top").y(), v.col(1).maxCoeff(), kTopTol);
  constexpr double kSoleTol = 0.01;  // the sole landmark lies on the floor within 1 cm
  EXPECT_NEAR(pt("left_sole").y(), floor, kSoleTol);
  EXPECT_GT(pt("left_fingertip").x(), 0.7);  // the middle fingertip ends the arm span
  EXPECT_NEAR(pt("left_fingertip").x(), v.col(0).maxCoeff(), 0.005);
  EXPECT_GT(pt("left_nipple").z(), pt("left_chest").z());
  EXPECT_GT(pt("navel").z(), pt("torso_back").z());
  // left/right pairs mirror each other
  for (const char* base : {"fingertip", "wrist", "shoulder", "elbow", "hip", "nipple", "waist",
                           "chest", "heel", "sole"}) {
    const Eigen::Vector3d l = pt(std::string("left_") + base), r = pt(std::string("right_") + base);
    constexpr double kMirrorTol = 1e-6;
    EXPECT_NEAR(l.x(), -r.x(), kMirrorTol) << base;
    EXPECT_NEAR(l.y(), r.y(), kMirrorTol) << base;
    EXPECT_GT(l.x(), 0.0) << base;
  }
  // origin near the pelvis, like SMPL
  Eigen::Vector3d pelvis = Eigen::Vector3d::Zero();
  for (smpl::SparseMatrix::InnerIterator it(model_.j_regressor, 0); it; ++it) {
    pelvis += it.value() * caliper::landmark_point(v, {static_cast<int>(it.col())});
  }
  constexpr double kPelvisTol = 0.01;  // the generator puts the pelvis joint at the origin
  EXPECT_LT(pelvis.norm(), kPelvisTol);
}

// The ends of the upper leg the fit measured (docs/measurements.md): the trochanterion, a point
// on one mesh edge written as kTrochanterShares ids, on the side of the hip between the crotch
// and the iliac crest; the knee's lateral vertex; each right landmark the left one's mirror.
TEST_P(OpenModel, CarriesTheUpperLegsLandmarksWhereItWasFitted) {
  const smpl::Vertices& v = model_.v_template;
  for (const char* name :
       {"left_trochanterion", "right_trochanterion", "left_knee_lateral", "right_knee_lateral"}) {
    ASSERT_TRUE(model_.landmarks.count(name)) << name;
  }
  const std::vector<int>& ids = model_.landmarks.at("left_trochanterion");
  ASSERT_EQ(ids.size(), static_cast<size_t>(modelgen::mh::kTrochanterShares));
  std::vector<int> ends = ids;
  std::sort(ends.begin(), ends.end());
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  ASSERT_LE(ends.size(), 2u);
  if (ends.size() == 2) {  // the two ends of one edge of the mesh
    bool edge = false;
    for (Eigen::Index f = 0; f < model_.faces.rows() && !edge; ++f) {
      int hits = 0;
      for (int c = 0; c < 3; ++c) {
        if (model_.faces(f, c) == ends[0] || model_.faces(f, c) == ends[1]) ++hits;
      }
      edge = hits == 2;
    }
    EXPECT_TRUE(edge) << ends[0] << "-" << ends[1] << " is not an edge";
  }
  auto pt = [&](const std::string& n) {
    return caliper::landmark_point(v, model_.landmarks.at(n));
  };
  const Eigen::Vector3d trochanter = pt("left_trochanterion");
  EXPECT_GT(trochanter.y(), pt("crotch").y());
  EXPECT_LT(trochanter.y(), pt("left_iliac_crest").y());
  // On the side of the hip, well outside the hip joint (SMPL's joint 1, the left hip).
  Eigen::Vector3d hip_joint = Eigen::Vector3d::Zero();
  for (smpl::SparseMatrix::InnerIterator it(model_.j_regressor, 1); it; ++it) {
    hip_joint += it.value() * caliper::landmark_point(v, {static_cast<int>(it.col())});
  }
  EXPECT_GT(trochanter.x() - hip_joint.x(), 0.04);
  const Eigen::Vector3d knee = pt("left_knee_lateral");
  EXPECT_LT(knee.y(), pt("crotch").y());
  for (const char* base : {"trochanterion", "knee_lateral"}) {
    const Eigen::Vector3d l = pt(std::string("left_") + base), r = pt(std::string("right_") + base);
    EXPECT_NEAR(l.x(), -r.x(), 1e-6) << base;
    EXPECT_NEAR(l.y(), r.y(), 1e-6) << base;
    EXPECT_NEAR(l.z(), r.z(), 1e-6) << base;
  }
  // The upper leg of the mean body: a quarter of the stature or so (ANSUR II: 0.233).
  const double stature = v.col(1).maxCoeff() - v.col(1).minCoeff();
  EXPECT_NEAR((trochanter.y() - knee.y()) / stature, 0.233, 0.02);
}

TEST_P(OpenModel, IsAClosedOrientedManifoldWithPositiveVolume) {
  const modelgen::TopologyReport r = modelgen::topology_report(model_.num_vertices(), model_.faces);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.oriented);
  EXPECT_TRUE(r.vertex_manifold);
  EXPECT_EQ(r.components, 1);
  EXPECT_EQ(r.euler, 2);  // a sphere: genus 0
  EXPECT_EQ(r.unused_vertices, 0);
  EXPECT_GT(caliper::mesh_volume(model_.v_template, model_.faces), 0.04);
}

TEST_P(OpenModel, HasNoSelfIntersectionAtMeanAndTwoSdAlongTenComponents) {
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model_.num_betas());
  auto hits = modelgen::self_intersections(shaped(model_, betas), model_.faces);
  EXPECT_TRUE(hits.empty()) << hits.size() << " intersecting pairs at the mean";
  for (int k = 0; k < 10; ++k) {
    for (double s : {-2.0, 2.0}) {
      betas.setZero();
      betas[k] = s;
      const smpl::Vertices v = shaped(model_, betas);
      hits = modelgen::self_intersections(v, model_.faces);
      EXPECT_TRUE(hits.empty()) << hits.size() << " intersecting pairs at beta[" << k
                                << "] = " << s;
      EXPECT_GT(caliper::mesh_volume(v, model_.faces), 0.0);
    }
  }
}

// Height and inseam are measured from the floor, the body's lowest vertex: it must be the same
// vertex at every training corner (beta in {-2, +2}^10), else those measurements are not
// linear in the betas and the regressors cannot give them back (mh::level_soles()).
TEST_P(OpenModel, FloorIsTheSameVertexAtEveryTrainingCorner) {
  Eigen::Index lowest = 0;
  model_.v_template.col(1).minCoeff(&lowest);
  const Eigen::Index nv = model_.num_vertices();
  Eigen::MatrixXd dy(nv, 10);  // each component's height offsets
  for (Eigen::Index v = 0; v < nv; ++v) dy.row(v) = model_.shapedirs.row(3 * v + 1).head(10);
  int moved = 0;
  double deepest = 0.0;
  for (int corner = 0; corner < 1024; ++corner) {
    Eigen::VectorXd betas(10);
    for (int k = 0; k < 10; ++k) betas[k] = (corner >> k & 1) != 0 ? 2.0 : -2.0;
    const Eigen::VectorXd y = model_.v_template.col(1) + dy * betas;
    const double below = y[lowest] - y.minCoeff();
    if (below > 0.0) ++moved;
    deepest = std::max(deepest, below);
  }
  EXPECT_EQ(moved, 0) << "corners whose lowest vertex is another one, up to " << 1000.0 * deepest
                      << " mm below the mean body's";
}

// The 10 test poses (modelgen::test_poses(): each bends one joint by 45 or 90 degrees).
TEST_P(OpenModel, HasNoFlippedTrianglesInTestPoses) {
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(model_.num_betas());
  const smpl::Vertices rest = shaped(model_, betas);
  ASSERT_EQ(modelgen::test_poses().size(), 10u);
  for (const modelgen::TestPose& p : modelgen::test_poses()) {
    const smpl::Body body = smpl::evaluate(model_, betas, p.theta);
    const std::vector<int> flipped = modelgen::flipped_triangles(model_, rest, body);
    EXPECT_TRUE(flipped.empty()) << p.name << ": " << flipped.size() << " flipped triangles";
  }
}

INSTANTIATE_TEST_SUITE_P(Committed, OpenModel, ::testing::ValuesIn(kGenders));

}  // namespace
