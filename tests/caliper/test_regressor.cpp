// Regressors: the paper's R2/R4/R5/R6 (least squares) and the noise-aware posterior; an
// analytic model whose features are exactly affine in the betas, a body-shaped random model,
// JSON round trips and refusal of a mismatched model.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "caliper/avatar.hpp"
#include "caliper/errors.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "caliper_test/shape_curve_example.hpp"
#include "core_test_meshes.hpp"

namespace caliper {
namespace {

// Least squares on 1024 well-conditioned rows, O(1) values: recovery to ~1e-12.
constexpr double kMachineTol = 1e-10;

const std::vector<std::string> kSix = regressor_inputs(RegressorKind::R6);

/// A training set whose six features are exactly f = M beta + c (weight through the cube root of
/// the volume), so linear regression is exact.
struct AnalyticModel {
  Eigen::MatrixXd M;  // 6 x 10
  Eigen::VectorXd c;  // 6
  WeightFormula formula = female_weight_formula();

  AnalyticModel() : M(6, 10), c(6) {
    // Height, cube-root volume, arm span, inseam, hip width, arm length: means and per-SD slopes
    // of the right size, deterministic.
    c << 1.70, 0.40, 1.72, 0.78, 0.36, 0.56;
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 10; ++j) M(i, j) = 0.01 * std::sin(1.0 + 3.0 * i + 1.7 * j * (i + 1));
    }
  }
  Eigen::VectorXd features(const Eigen::VectorXd& b) const { return M * b + c; }
  MeasurementMap values(const Eigen::VectorXd& b) const {
    const Eigen::VectorXd f = features(b);
    MeasurementMap m;
    for (int i = 0; i < 6; ++i) m[kSix[i]] = f(i);
    m["weight"] = weight_from_feature(f(1), formula);
    return m;
  }
  TrainingSet training(const Eigen::MatrixXd& betas) const {
    TrainingSet t;
    t.betas = betas;
    t.ids = {"height", "arm_span_fingertips", "inseam_height", "hip_width", "arm_length"};
    const Eigen::MatrixXd F = (betas * M.transpose()).rowwise() + c.transpose();
    t.measurements.resize(betas.rows(), 5);
    t.measurements << F.col(0), F.col(2), F.col(3), F.col(4), F.col(5);
    t.volumes = F.col(1).array().cube();
    t.weight_formula = formula;
    t.weights = (formula.coefficient * t.volumes).array() + formula.intercept;
    return t;
  }
};

ModelSignature analytic_signature() {
  return {"analytic", "female", 100, 10};
}

TEST(LinearRegressor, AnalyticModelReproducesItsInputsToMachinePrecision) {
  const AnalyticModel am;
  const TrainingSet t = am.training(corner_betas(10, 2.0));
  const Eigen::MatrixXd truth = gaussian_betas(50, 10, 3);
  for (RegressorKind kind : all_regressor_kinds()) {
    const LinearRegressor r = LinearRegressor::fit(t, kind, analytic_signature());
    EXPECT_EQ(r.name(), to_string(kind));
    ASSERT_EQ(r.coefficients().rows(), 10);
    ASSERT_EQ(r.coefficients().cols(), static_cast<Eigen::Index>(r.inputs().size()) + 1);
    EXPECT_LT(r.training_rms().maxCoeff(), kMachineTol);
    for (int s = 0; s < truth.rows(); ++s) {
      const MeasurementMap in = am.values(truth.row(s).transpose());
      const Eigen::VectorXd got = am.features(r.predict(in));
      for (std::size_t i = 0; i < r.inputs().size(); ++i) {
        const auto idx = static_cast<Eigen::Index>(i);
        const double want = am.features(truth.row(s).transpose())(idx);
        EXPECT_NEAR(got(idx), want, kMachineTol) << to_string(kind) << " " << r.inputs()[i];
      }
    }
  }
}

TEST(LinearRegressor, IsTheMinimumNormSolutionOnTheCorners) {
  // On the balanced corner design, LS of beta on f gives beta = M'(M M')^-1 (f - c).
  const AnalyticModel am;
  const TrainingSet t = am.training(corner_betas(10, 2.0));
  const LinearRegressor r = LinearRegressor::fit(t, RegressorKind::R6, analytic_signature());
  const Eigen::VectorXd b = gaussian_betas(1, 10, 5).row(0).transpose();
  const Eigen::VectorXd f = am.features(b);
  const Eigen::VectorXd expected =
      am.M.transpose() * (am.M * am.M.transpose()).ldlt().solve(f - am.c);
  EXPECT_MATRIX_NEAR(r.predict(am.values(b)), expected, kMachineTol);
}

TEST(LinearRegressor, BadInput) {
  const AnalyticModel am;
  const TrainingSet t = am.training(corner_betas(10, 2.0));
  const LinearRegressor r = LinearRegressor::fit(t, RegressorKind::R4, analytic_signature());
  MeasurementMap in = am.values(Eigen::VectorXd::Zero(10));
  in.erase("inseam_height");
  try {
    r.predict(in);
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("inseam_height"), std::string::npos) << e.what();
  }
  in = am.values(Eigen::VectorXd::Zero(10));
  in["weight"] = -5.0;
  EXPECT_THROW(r.predict(in), InvalidInputError);
  in["weight"] = std::nan("");
  EXPECT_THROW(r.predict(in), InvalidInputError);
  EXPECT_THROW(r.predict(Eigen::VectorXd::Ones(3)), InvalidInputError);
  EXPECT_THROW(LinearRegressor::fit(t, {"height", "shoe_size"}, analytic_signature()),
               InvalidInputError);
  EXPECT_THROW(LinearRegressor::fit(t, {"height", "height"}, analytic_signature()),
               InvalidInputError);  // rank deficient
  EXPECT_EQ(parse_regressor_kind("r5"), RegressorKind::R5);
  EXPECT_FALSE(parse_regressor_kind("R3").has_value());
}

TEST(NoiseAware, ClosedFormPosterior) {
  const AnalyticModel am;
  const TrainingSet t = am.training(gaussian_betas(2000, 10, 8));
  const NoiseLevels noise = self_measurement_noise();
  const NoiseAwareRegressor r = NoiseAwareRegressor::fit(t, analytic_signature(), noise);
  EXPECT_MATRIX_NEAR(r.forward_matrix(), am.M, kMachineTol);
  EXPECT_MATRIX_NEAR(r.forward_offset(), am.c, kMachineTol);
  EXPECT_LT(r.linearisation_rms().maxCoeff(), kMachineTol);
  const Eigen::VectorXd b = gaussian_betas(1, 10, 6).row(0).transpose();
  MeasurementMap in = am.values(b);
  in.erase("arm_length");  // any subset
  const Posterior p = r.predict(in);
  ASSERT_EQ(p.used_inputs.size(), 5u);
  // Closed form with the five inputs.
  const std::vector<int> rows = {0, 1, 2, 3, 4};
  Eigen::MatrixXd Mu(5, 10);
  Eigen::VectorXd fu(5), var(5);
  const Eigen::VectorXd f = am.features(b);
  for (int i = 0; i < 5; ++i) {
    Mu.row(i) = am.M.row(rows[i]);
    fu(i) = f(rows[i]);
    double sd = noise.at(kSix[rows[i]]);
    if (kSix[rows[i]] == "weight") sd /= 3.0 * am.formula.coefficient * f(1) * f(1);
    var(i) = sd * sd;
  }
  const Eigen::MatrixXd Ninv = var.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd cov =
      (Eigen::MatrixXd::Identity(10, 10) + Mu.transpose() * Ninv * Mu).inverse();
  const Eigen::VectorXd mean = cov * Mu.transpose() * Ninv * (fu - am.c.head(5));
  EXPECT_MATRIX_NEAR(p.mean, mean, 1e-9);
  EXPECT_MATRIX_NEAR(p.covariance, cov, 1e-9);
  // Posterior variance never exceeds the prior's and shrinks with more inputs.
  EXPECT_TRUE((p.sd().array() <= 1.0 + 1e-12).all());
  const Posterior p2 = r.predict({{"height", in.at("height")}, {"weight", in.at("weight")}});
  EXPECT_GT(p2.covariance.trace(), p.covariance.trace());
  // No inputs: the prior.
  const Posterior p0 = r.predict({});
  EXPECT_MATRIX_NEAR(p0.mean, Eigen::VectorXd::Zero(10), 0.0);
  EXPECT_MATRIX_NEAR(p0.covariance, Eigen::MatrixXd::Identity(10, 10), 0.0);
}

TEST(NoiseAware, APopulationPriorIsTheClosedFormPosteriorUnderIt) {
  // betas ~ N(mu, S) instead of N(0, I): precision S^-1 + M' N^-1 M, mean from S^-1 mu + M' N^-1
  // (f - c). Without inputs the posterior is the prior; N(0, I) given is the default.
  const AnalyticModel am;
  const TrainingSet t = am.training(gaussian_betas(2000, 10, 8));
  const NoiseLevels noise = self_measurement_noise();
  const NoiseAwareRegressor r = NoiseAwareRegressor::fit(t, analytic_signature(), noise);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(10, 10) / 4.0;
  ShapePrior prior;
  prior.mean = Eigen::VectorXd::LinSpaced(10, -0.8, 0.6);
  prior.covariance = a * a.transpose() + 0.2 * Eigen::MatrixXd::Identity(10, 10);
  const Eigen::VectorXd b = gaussian_betas(1, 10, 7).row(0).transpose();
  MeasurementMap in = am.values(b);
  const MeasurementMap hw = {{"height", in.at("height")}, {"weight", in.at("weight")}};
  const Posterior p = r.predict(hw, {}, &prior);
  const Eigen::VectorXd f = am.features(b);
  Eigen::MatrixXd Mu(2, 10);
  Mu.row(0) = am.M.row(0);
  Mu.row(1) = am.M.row(1);
  Eigen::Vector2d var(noise.at("height"),
                      noise.at("weight") / (3.0 * am.formula.coefficient * f(1) * f(1)));
  var = var.cwiseProduct(var);
  const Eigen::MatrixXd Ninv = var.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd Sinv = prior.covariance.inverse();
  const Eigen::MatrixXd cov = (Sinv + Mu.transpose() * Ninv * Mu).inverse();
  const Eigen::VectorXd mean =
      cov * (Sinv * prior.mean + Mu.transpose() * Ninv * (f.head(2) - am.c.head(2)));
  EXPECT_MATRIX_NEAR(p.mean, mean, 1e-9);
  EXPECT_MATRIX_NEAR(p.covariance, cov, 1e-9);
  const Posterior p0 = r.predict({}, {}, &prior);
  EXPECT_MATRIX_NEAR(p0.mean, prior.mean, 1e-12);
  EXPECT_MATRIX_NEAR(p0.covariance, prior.covariance, 1e-12);
  ShapePrior standard{Eigen::VectorXd::Zero(10), Eigen::MatrixXd::Identity(10, 10)};
  EXPECT_MATRIX_NEAR(r.predict(hw, {}, &standard).mean, r.predict(hw).mean, 1e-12);
  // A prior over more betas: its leading block is the regressor's prior.
  ShapePrior wide{Eigen::VectorXd::Zero(12), Eigen::MatrixXd::Identity(12, 12)};
  wide.mean.head(10) = prior.mean;
  wide.covariance.topLeftCorner(10, 10) = prior.covariance;
  EXPECT_MATRIX_NEAR(r.predict(hw, {}, &wide).mean, p.mean, 0.0);
  // A prior over fewer betas, or not positive definite, is refused.
  ShapePrior small{Eigen::VectorXd::Zero(3), Eigen::MatrixXd::Identity(3, 3)};
  EXPECT_THROW(r.predict(hw, {}, &small), InvalidInputError);
  ShapePrior singular{Eigen::VectorXd::Zero(10), Eigen::MatrixXd::Zero(10, 10)};
  EXPECT_THROW(r.predict(hw, {}, &singular), InvalidInputError);
}

TEST(NoiseAware, TinyNoiseGivesThePlainRegressor) {
  const AnalyticModel am;
  const TrainingSet t = am.training(corner_betas(10, 2.0));
  NoiseLevels tiny;
  for (const auto& id : kSix) tiny[id] = 1e-7;
  const NoiseAwareRegressor na = NoiseAwareRegressor::fit(t, analytic_signature(), tiny);
  const LinearRegressor r6 = LinearRegressor::fit(t, RegressorKind::R6, analytic_signature());
  const MeasurementMap in = am.values(gaussian_betas(1, 10, 12).row(0).transpose());
  // The posterior mean tends to the minimum-norm solution as noise -> 0: relative 1e-6.
  EXPECT_MATRIX_NEAR(na.predict(in).mean, r6.predict(in), 1e-6);
  NoiseLevels bad = {{"height", -1.0}};
  EXPECT_THROW(na.predict(in, bad), InvalidInputError);
  EXPECT_THROW(NoiseAwareRegressor::fit(t, analytic_signature(), bad), InvalidInputError);
}

TEST(NoiseAware, DefaultNoiseIsPaperTable2) {
  const NoiseLevels s = self_measurement_noise();
  EXPECT_NEAR(s.at("height"), 0.0153 * std::sqrt(M_PI / 2), 1e-15);
  EXPECT_NEAR(s.at("arm_span_fingertips"), 0.0201 * std::sqrt(M_PI / 2), 1e-15);
  EXPECT_NEAR(s.at("arm_length"), 0.0129 * std::sqrt(M_PI / 2), 1e-15);
  EXPECT_NEAR(s.at("inseam_height"), 0.0206 * std::sqrt(M_PI / 2), 1e-15);
  EXPECT_NEAR(s.at("hip_width"), 0.0077 * std::sqrt(M_PI / 2), 1e-15);
  EXPECT_DOUBLE_EQ(s.at("weight"), 1.0);
  EXPECT_NEAR(other_measurement_noise().at("hip_width"), 0.0065 * kMaeToSd, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// A body-shaped model (tests/support): real measurements, volume and training.

// Avatars without circumferences (faster) and without refusing unusual inputs.
AvatarOptions quiet_options() {
  AvatarOptions o;
  o.circumferences = false;
  o.refuse_invalid = false;
  return o;
}

class BodyModelRegressors : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = new smpl::BodyModel(test::make_random_model(10, 24, false, 21));
    test::make_shape_space_smooth(*model_, 21, 0.01);  // 1 % per SD and axis: SMPL-like height SD
    set_ = new RegressorSet(train_regressors(*model_));
  }
  static void TearDownTestSuite() {
    delete set_;
    delete model_;
  }
  static smpl::BodyModel* model_;
  static RegressorSet* set_;
};
smpl::BodyModel* BodyModelRegressors::model_ = nullptr;
RegressorSet* BodyModelRegressors::set_ = nullptr;

TEST_F(BodyModelRegressors, AvatarsReproduceTheirInputs) {
  // Table 1 of the paper on a synthetic body: the inputs of each regressor come back from its
  // avatar. Tolerances: the 1 mm for lengths, 0.5 kg for weight.
  ASSERT_EQ(set_->linear.size(), 4u);
  const Eigen::MatrixXd truth = gaussian_betas(20, 10, 77);
  for (const auto& r : set_->linear) {
    for (int s = 0; s < truth.rows(); ++s) {
      const smpl::Vertices v = shaped_vertices(*model_, truth.row(s).transpose());
      const MeasurementMap m = measure_all(*model_, v, {false, true});
      AvatarOptions opt;
      opt.circumferences = false;
      opt.refuse_invalid = false;  // a random ellipsoid body is not a typical adult
      const Avatar a = create_avatar(*model_, r, m, opt);
      for (const auto& id : r.inputs()) {
        const double tol = id == "weight" ? 0.5 : 0.001;
        EXPECT_NEAR(a.achieved.at(id), m.at(id), tol) << r.name() << " " << id << " body " << s;
      }
    }
  }
}

TEST_F(BodyModelRegressors, TheWeightEntersTheInterceptAtTheMeanBody) {
  // Default: the slopes of the paper's least squares; the intercept moved by the weight slope
  // times (the mean body's cube-root volume - its average over the corners). The paper's
  // intercept (TrainOptions::intercept_at_mean = false) is the least-squares one.
  const TrainingSet t = paper_training_set(*model_);
  ASSERT_GT(t.mean_volume, 0.0);
  const double shift = std::cbrt(t.mean_volume) - t.column("weight_feature").mean();
  EXPECT_GT(std::abs(shift), 1e-7);  // the cube root of the volume curves
  TrainOptions paper;
  paper.intercept_at_mean = false;
  paper.noise_aware = false;
  const RegressorSet least_squares = train_regressors(*model_, paper);
  for (std::size_t k = 0; k < set_->linear.size(); ++k) {
    const Eigen::MatrixXd& a = set_->linear[k].coefficients();
    const Eigen::MatrixXd& b = least_squares.linear[k].coefficients();
    const Eigen::Index m = a.cols() - 1;
    const auto w = static_cast<Eigen::Index>(
        std::find(set_->linear[k].inputs().begin(), set_->linear[k].inputs().end(), "weight") -
        set_->linear[k].inputs().begin());
    ASSERT_LT(w, m) << set_->linear[k].name();
    EXPECT_TRUE(a.leftCols(m) == b.leftCols(m)) << set_->linear[k].name();
    EXPECT_TRUE(a.col(m).isApprox(b.col(m) - b.col(w) * shift, 1e-12)) << set_->linear[k].name();
  }
}

TEST_F(BodyModelRegressors, APopulationPriorSetsTheBetasBeyondTheRegressorsToTheirMeanGivenThem) {
  // A regressor of 6 betas on a 10-beta model, a population over all 10: betas 7-10 of the avatar
  // are mu_r + S_rk S_kk^-1 (beta_k - mu_k); the plausibility counts the regressor's 6.
  TrainOptions six;
  six.num_betas = 6;
  const RegressorSet s = train_regressors(*model_, six);
  ASSERT_TRUE(s.noise_aware.has_value());
  ShapePrior p;
  p.mean = Eigen::VectorXd::LinSpaced(10, -0.5, 0.4);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(10, 10) / 3.0;
  p.covariance = a * a.transpose() + 0.3 * Eigen::MatrixXd::Identity(10, 10);
  const Eigen::VectorXd truth = gaussian_betas(1, 10, 79).row(0).transpose();
  const MeasurementMap m = measure_all(*model_, shaped_vertices(*model_, truth), {false, true});
  AvatarOptions o;
  o.prior = &p;
  o.refuse_invalid = false;
  o.circumferences = false;
  const Avatar av = create_avatar(*model_, *s.noise_aware, m, o);
  ASSERT_EQ(av.betas.size(), 10);
  const Eigen::VectorXd k = av.betas.head(6);
  const Eigen::VectorXd rest = p.mean.tail(4) + p.covariance.block(6, 0, 4, 6) *
                                                    p.covariance.topLeftCorner(6, 6).inverse() *
                                                    (k - p.mean.head(6));
  EXPECT_MATRIX_NEAR(av.betas.tail(4), rest, 1e-10);
  EXPECT_EQ(av.plausibility.dof, 6);
  // With exact inputs every input comes back (from the population's posterior mean).
  AvatarOptions exact = o;
  exact.exact_inputs = true;
  const Avatar ex = create_avatar(*model_, *s.noise_aware, m, exact);
  for (const auto& [id, value] : m) {
    if (std::find(kSix.begin(), kSix.end(), id) == kSix.end()) continue;
    EXPECT_NEAR(ex.achieved.at(id), value, id == "weight" ? 1e-6 : 1e-8) << id;
  }
  // A plain regressor refuses a prior.
  EXPECT_THROW(create_avatar(*model_, set_->linear.front(), m, o), InvalidInputError);
}

TEST_F(BodyModelRegressors, ExactInputsAreReproducedExactly) {
  // Gauss-Newton refinement after the paper's prediction: every input, weight included, comes
  // back to ~1e-9 m (residual test) / a few micrograms, with a small change of the betas.
  const Eigen::MatrixXd truth = gaussian_betas(5, 10, 78);
  const AvatarOptions plain = quiet_options();
  AvatarOptions exact = quiet_options();
  exact.exact_inputs = true;
  for (const auto& r : set_->linear) {
    for (int s = 0; s < truth.rows(); ++s) {
      const smpl::Vertices v = shaped_vertices(*model_, truth.row(s).transpose());
      const MeasurementMap m = measure_all(*model_, v, {false, true});
      const Avatar a = create_avatar(*model_, r, m, plain);
      const Avatar b = create_avatar(*model_, r, m, exact);
      for (const auto& id : r.inputs()) {
        EXPECT_NEAR(b.achieved.at(id), m.at(id), id == "weight" ? 1e-6 : 1e-8) << r.name() << id;
      }
      EXPECT_LT((b.betas - a.betas).norm(), 0.5) << r.name();
    }
  }
  EXPECT_THROW(refine_to_inputs(*model_, Eigen::VectorXd::Zero(1),
                                {{"height", 1.7}, {"weight", 60}}, female_weight_formula()),
               InvalidInputError);  // more targets than betas
}

TEST_F(BodyModelRegressors, AShapeCurveDecidesOnlyWhatTheInputsDoNotMeasure) {
  // A plain regressor started from a shape curve (linear_betas, create_avatar's default when
  // the model carries one): along the directions its inputs measure (the span of its slopes)
  // the betas are the inputs' correction, across them the curve's own; the inputs come back as
  // well as from the paper's prediction; the measurer's shortcut gives the mesh's betas.
  smpl::BodyModel curved = *model_;
  const ShapeCurve curve = test::example_shape_curve(Eigen::MatrixXd::Random(10, 6) * 0.3);
  set_shape_curve(curved, curve);
  const ShapeMeasurer measurer(curved, landmarks_for(curved), paper_measurements(), 10);
  const Eigen::MatrixXd truth = gaussian_betas(8, 10, 79);
  const AvatarOptions o = quiet_options();
  AvatarOptions paper = quiet_options();
  paper.shape_curve = false;
  for (const auto& r : set_->linear) {
    const Eigen::MatrixXd A = r.coefficients().leftCols(r.inputs().size());
    const Eigen::MatrixXd across =  // projector onto what the inputs do not measure
        Eigen::MatrixXd::Identity(10, 10) - A * (A.transpose() * A).inverse() * A.transpose();
    for (int s = 0; s < truth.rows(); ++s) {
      const MeasurementMap m =
          measure_all(curved, shaped_vertices(curved, truth.row(s).transpose()), {false, true});
      const Avatar a = create_avatar(curved, r, m, o);
      const Avatar b = create_avatar(curved, r, m, paper);
      EXPECT_MATRIX_NEAR(b.betas, r.predict(m), 1e-12);
      const Eigen::VectorXd c = curve.betas(m.at("height"), m.at("weight"));
      // (1e-8: the projector's rounding; the slopes are hundreds of betas per metre)
      EXPECT_MATRIX_NEAR(across * a.betas, across * c, 1e-8);
      EXPECT_GT((across * (a.betas - b.betas)).norm(), 1e-3) << "the curve changed nothing";
      for (const auto& id : r.inputs()) {
        const double tol = id == "weight" ? 0.5 : 1e-3;
        EXPECT_NEAR(a.achieved.at(id), m.at(id), tol) << r.name() << " " << id;
      }
      const LandmarkTable lm = landmarks_for(curved);
      EXPECT_MATRIX_NEAR(linear_betas(curved, r, m, &curve, lm, &measurer), a.betas, 1e-9);
      EXPECT_MATRIX_NEAR(linear_betas(curved, r, m, nullptr, lm), b.betas, 1e-12);
    }
  }
  // A regressor that does not take both height and weight keeps its own prediction.
  const TrainingSet t = paper_training_set(*model_);
  const LinearRegressor spans =
      LinearRegressor::fit(t, {"height", "arm_span_fingertips"}, ModelSignature::of(curved, 10));
  const MeasurementMap in{{"height", 1.7}, {"arm_span_fingertips", 1.72}};
  EXPECT_MATRIX_NEAR(linear_betas(curved, spans, in, &curve, landmarks_for(curved)),
                     spans.predict(in), 0.0);
}

TEST_F(BodyModelRegressors, JsonRoundTripAndMismatch) {
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/c1_regressors.json";
  set_->save(path);
  const RegressorSet back = RegressorSet::load(path);
  ASSERT_EQ(back.linear.size(), 4u);
  ASSERT_TRUE(back.noise_aware.has_value());
  const MeasurementMap in = {
      {"height", 1.7},         {"weight", 65.0},    {"arm_span_fingertips", 1.7},
      {"inseam_height", 0.78}, {"hip_width", 0.35}, {"arm_length", 0.55}};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(back.linear[i].name(), set_->linear[i].name());
    EXPECT_MATRIX_NEAR(back.linear[i].predict(in), set_->linear[i].predict(in), 0.0);
  }
  EXPECT_MATRIX_NEAR(back.noise_aware->predict(in).mean, set_->noise_aware->predict(in).mean, 0.0);
  EXPECT_NE(back.find("r5"), nullptr);
  EXPECT_EQ(back.find("R3"), nullptr);
  back.check(*model_);
  // A renamed copy of the same model is accepted (the fingerprint identifies the content).
  smpl::BodyModel other = *model_;
  other.meta.name = "renamed file";
  back.check(other);
  // A different template is refused, naming both models.
  other.v_template(10, 1) += 1e-4;
  other.meta.name = "someone else";
  try {
    back.check(other);
    FAIL();
  } catch (const ModelMismatchError& e) {
    EXPECT_NE(std::string(e.what()).find("someone else"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(model_->meta.name), std::string::npos) << e.what();
  }
  EXPECT_THROW(create_avatar(other, back.linear[0], in), ModelMismatchError);
  other = *model_;
  other.shapedirs(30, 2) += 1e-4;  // a different shape space
  EXPECT_THROW(back.check(other), ModelMismatchError);
  other = *model_;
  other.v_template.conservativeResize(100, 3);
  EXPECT_THROW(back.check(other), ModelMismatchError);
  // Without a fingerprint (older files) the name and gender decide.
  ModelSignature sig = back.linear[0].signature();
  sig.fingerprint = 0.0;
  sig.check(*model_);
  other = *model_;
  other.meta.gender = "male";
  EXPECT_THROW(sig.check(other), ModelMismatchError);
  std::remove(path.c_str());
}

TEST_F(BodyModelRegressors, MalformedJsonIsRefused) {
  Json j = set_->to_json();
  j.set("format", "something-else");
  EXPECT_THROW(RegressorSet::from_json(j), ModelMismatchError);
  Json lin = set_->linear[0].to_json();
  lin.set("inputs", Json(Json::Array{Json("height")}));  // coefficients have 3 columns
  EXPECT_THROW(LinearRegressor::from_json(lin), ModelMismatchError);
  Json na = set_->noise_aware->to_json();
  na.set("kind", "linear");
  EXPECT_THROW(NoiseAwareRegressor::from_json(na), ModelMismatchError);
}

TEST_F(BodyModelRegressors, NoiseAwareOnTheBodyModel) {
  const Eigen::VectorXd truth = gaussian_betas(1, 10, 99).row(0).transpose();
  const smpl::Vertices v = shaped_vertices(*model_, truth);
  const MeasurementMap m = measure_all(*model_, v, {false, true});
  AvatarOptions opt;
  opt.circumferences = false;
  opt.refuse_invalid = false;
  const Avatar a = create_avatar(*model_, *set_->noise_aware, m, opt);
  ASSERT_TRUE(a.covariance.has_value());
  EXPECT_EQ(a.betas.size(), model_->num_betas());
  // With self-measurement noise the avatar matches the inputs within a few noise SDs.
  for (const auto& id : set_->noise_aware->inputs()) {
    const double sd = id == "weight" ? 1.0 : set_->noise_aware->noise().at(id);
    EXPECT_NEAR(a.achieved.at(id), m.at(id), 3.0 * sd) << id;
  }
  EXPECT_GE(a.plausibility.mahalanobis, 0.0);
}

}  // namespace
}  // namespace caliper
