// The general population's body for a height and a weight (caliper/shape_curve.hpp): the fit
// recovers a quadratic, stops at the subjects' range, round-trips through the model metadata to
// the bit, names its weight input (the cube root or the weight itself), refuses hostile entries
// naming the key; and a plain regressor started from it
// (caliper::linear_betas) still reproduces its inputs while the rest follows the curve.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "caliper/avatar.hpp"
#include "caliper/errors.hpp"
#include "caliper/portable_math.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "core_test_meshes.hpp"

namespace {

// Only the number of betas matters for the metadata.
smpl::BodyModel curve_test_model(int b) {
  smpl::BodyModel m;
  m.shapedirs = Eigen::MatrixXd::Zero(3, b);
  return m;
}

// n subjects over heights 1.5-1.9 m and weights 45-160 kg; betas an exact quadratic of the
// standardised (height, cube root of weight) with coefficients `truth` (B x 6).
struct CurveSample {
  Eigen::VectorXd height, weight, wt;
  Eigen::MatrixXd betas;
};

CurveSample curve_sample(const Eigen::MatrixXd& truth, int n, bool kilograms = false) {
  CurveSample s;
  s.height.resize(n);
  s.weight.resize(n);
  s.wt = Eigen::VectorXd::Ones(n);
  for (int i = 0; i < n; ++i) {
    s.height[i] = 1.5 + 0.4 * ((i * 37) % n) / n;
    s.weight[i] = 45.0 + 115.0 * ((i * 61) % n) / n;
  }
  // The standardisation the fit will find (weighted mean and SD of the raw features).
  Eigen::MatrixXd x(n, 2);
  for (int i = 0; i < n; ++i) {
    x.row(i) << s.height[i], kilograms ? s.weight[i] : caliper::portable::cbrt(s.weight[i]);
  }
  const Eigen::RowVector2d mean = x.colwise().mean();
  const Eigen::RowVector2d sd =
      ((x.rowwise() - mean).array().square().colwise().sum() / n).sqrt().matrix();
  s.betas.resize(n, truth.rows());
  for (int i = 0; i < n; ++i) {
    const Eigen::RowVector2d z = (x.row(i) - mean).cwiseQuotient(sd);
    s.betas.row(i) = (truth * caliper::shape_curve_features(z[0], z[1])).transpose();
  }
  return s;
}

Eigen::MatrixXd curve_truth(int b) {
  Eigen::MatrixXd t(b, 6);
  for (int r = 0; r < b; ++r) {
    for (int q = 0; q < 6; ++q) t(r, q) = 0.1 * (r + 1) - 0.07 * q + 0.01 * r * q;
  }
  return t;
}

TEST(ShapeCurve, FitRecoversAQuadraticAndStopsAtTheSubjectsRange) {
  const Eigen::MatrixXd truth = curve_truth(3);
  const CurveSample s = curve_sample(truth, 200);
  const caliper::ShapeCurve c =
      caliper::fit_shape_curve(s.height, s.weight, s.betas, s.wt, "test population");
  EXPECT_EQ(c.subjects, 200);
  EXPECT_EQ(c.population, "test population");
  EXPECT_LT((c.coefficients - truth).cwiseAbs().maxCoeff(), 1e-9);
  for (int i = 0; i < 200; i += 17) {
    EXPECT_LT((c.betas(s.height[i], s.weight[i]) - s.betas.row(i).transpose()).norm(), 1e-9);
  }
  // Beyond the range: the edge's value, not the quadratic's turn.
  EXPECT_LT((c.betas(2.5, 400.0) - c.betas(c.hi[0], c.hi[1] * c.hi[1] * c.hi[1])).norm(), 1e-9);
  EXPECT_LT((c.betas(1.0, 20.0) - c.betas(c.lo[0], c.lo[1] * c.lo[1] * c.lo[1])).norm(), 1e-9);
  // Subjects with sample weight 0 take no part.
  CurveSample z = s;
  z.betas(0, 0) += 1e6;
  z.wt[0] = 0.0;
  const caliper::ShapeCurve d = caliper::fit_shape_curve(z.height, z.weight, z.betas, z.wt, "");
  EXPECT_EQ(d.subjects, 199);
  EXPECT_LT((d.betas(1.7, 80.0) - c.betas(1.7, 80.0)).norm(), 1e-3);
}

TEST(ShapeCurve, BadSubjectsAndInputsAreRefused) {
  const CurveSample s = curve_sample(curve_truth(2), 40);
  const auto fit = [](const CurveSample& x) {
    return caliper::fit_shape_curve(x.height, x.weight, x.betas, x.wt, "");
  };
  CurveSample bad = s;
  bad.height[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fit(bad), std::invalid_argument);
  bad = s;
  bad.weight[5] = -60.0;
  EXPECT_THROW(fit(bad), std::invalid_argument);
  bad = s;
  bad.wt.conservativeResize(39);
  EXPECT_THROW(fit(bad), std::invalid_argument);
  bad = s;
  bad.wt.tail(34).setZero();  // 6 subjects left: fewer than 7
  EXPECT_THROW(fit(bad), std::invalid_argument);
  bad = s;
  bad.height.setConstant(1.7);
  EXPECT_THROW(fit(bad), std::invalid_argument);
  const caliper::ShapeCurve c = fit(s);
  EXPECT_THROW(c.betas(std::nan(""), 70.0), caliper::InvalidInputError);
  EXPECT_THROW(c.betas(1.7, 0.0), caliper::InvalidInputError);
  EXPECT_THROW(c.betas(-1.7, 70.0), caliper::InvalidInputError);
}

TEST(ShapeCurve, RoundTripsThroughTheModelMetadataToTheBit) {
  smpl::BodyModel m = curve_test_model(3);
  EXPECT_FALSE(caliper::shape_curve(m).has_value());
  const CurveSample s = curve_sample(curve_truth(3), 60);
  const caliper::ShapeCurve c = caliper::fit_shape_curve(s.height, s.weight, s.betas, s.wt, "p");
  caliper::set_shape_curve(m, c);
  const std::optional<caliper::ShapeCurve> back = caliper::shape_curve(m);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->population, "p");
  EXPECT_EQ(back->subjects, 60);
  EXPECT_TRUE(back->center == c.center && back->scale == c.scale);
  EXPECT_TRUE(back->lo == c.lo && back->hi == c.hi);
  EXPECT_TRUE(back->coefficients == c.coefficients);
  EXPECT_THROW(caliper::set_shape_curve(*std::make_unique<smpl::BodyModel>(curve_test_model(4)), c),
               std::invalid_argument);
}

TEST(ShapeCurve, TheWeightItselfAsInputIsFittedNamedInTheFileAndReadBack) {
  using Input = caliper::ShapeCurve::WeightInput;
  const Eigen::MatrixXd truth = curve_truth(3);
  const CurveSample kg = curve_sample(truth, 200, true);
  const caliper::ShapeCurve c =
      caliper::fit_shape_curve(kg.height, kg.weight, kg.betas, kg.wt, "p", Input::kKilograms);
  EXPECT_EQ(c.weight_input, Input::kKilograms);
  EXPECT_LT((c.coefficients - truth).cwiseAbs().maxCoeff(), 1e-9);
  // The same subjects on the cube root's features do not give the quadratic back.
  const caliper::ShapeCurve wrong =
      caliper::fit_shape_curve(kg.height, kg.weight, kg.betas, kg.wt, "p");
  EXPECT_EQ(wrong.weight_input, Input::kCubeRoot);
  EXPECT_GT((wrong.coefficients - truth).cwiseAbs().maxCoeff(), 1e-3);
  // The file names the input, and the curve read back gives the same bodies.
  smpl::BodyModel m = curve_test_model(3);
  caliper::set_shape_curve(m, c);
  const std::string text = m.meta.extra.at(caliper::shape_curve_meta_key());
  EXPECT_NE(text.find(R"x("inputs":["height (m)","weight (kg)"])x"), std::string::npos) << text;
  const std::optional<caliper::ShapeCurve> back = caliper::shape_curve(m);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->weight_input, Input::kKilograms);
  for (const double w : {52.0, 81.5, 140.0}) {
    EXPECT_TRUE(back->betas(1.71, w) == c.betas(1.71, w)) << w;
  }
  // A cube-root curve keeps the text every model made so far has, and a file without the
  // names is read as the cube root's.
  const CurveSample cube = curve_sample(truth, 200);
  caliper::set_shape_curve(
      m, caliper::fit_shape_curve(cube.height, cube.weight, cube.betas, cube.wt, "p"));
  std::string old = m.meta.extra.at(caliper::shape_curve_meta_key());
  const std::string names = R"x("inputs":["height (m)","cube root of weight (kg)"],)x";
  const size_t at = old.find(names);
  ASSERT_NE(at, std::string::npos) << old;
  EXPECT_EQ(caliper::shape_curve(m)->weight_input, Input::kCubeRoot);
  m.meta.extra[caliper::shape_curve_meta_key()] = old.erase(at, names.size());
  const std::optional<caliper::ShapeCurve> unnamed = caliper::shape_curve(m);
  ASSERT_TRUE(unnamed.has_value());
  EXPECT_EQ(unnamed->weight_input, Input::kCubeRoot);
}

TEST(ShapeCurve, BadEntriesAreRefusedNamingTheKeyAndWhatToDo) {
  smpl::BodyModel m = curve_test_model(2);
  const CurveSample s = curve_sample(curve_truth(2), 40);
  caliper::set_shape_curve(m, caliper::fit_shape_curve(s.height, s.weight, s.betas, s.wt, "p"));
  const std::string good = m.meta.extra.at(caliper::shape_curve_meta_key());
  const auto refused = [&](const std::string& text) {
    m.meta.extra[caliper::shape_curve_meta_key()] = text;
    try {
      caliper::shape_curve(m);
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      return what.find("shape_curve") != std::string::npos &&
             what.find("regenerate the model") != std::string::npos;
    }
    return false;
  };
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? t : t.replace(at, from.size(), to);
  };
  EXPECT_TRUE(refused("not json"));
  EXPECT_TRUE(refused("{}"));
  EXPECT_TRUE(refused("[1, 2, 3]"));
  EXPECT_TRUE(refused(replaced("\"scale\":[", "\"scale\":[-1,")));                   // 3 values
  EXPECT_TRUE(refused(replaced("\"coefficients\":[[", "\"coefficients\":[[1],[")));  // 3 rows
  EXPECT_TRUE(refused(replaced("\"coefficients\":[[", "\"coefficients\":[[1,")));    // 7 wide
  EXPECT_TRUE(refused(replaced("\"center\":[", "\"center\":[1e999,")));  // 3 values, inf
  // Inputs this program does not know: a curve read on the wrong feature would be wrong.
  EXPECT_TRUE(refused(replaced("cube root of weight (kg)", "weight (lb)")));
  EXPECT_TRUE(refused(replaced("\"height (m)\",", "")));
  EXPECT_TRUE(refused(replaced("[\"height (m)\",", "[\"stature (m)\",")));
  EXPECT_TRUE(refused(replaced("\"inputs\":[", "\"inputs\":[\"height (m)\",")));
  EXPECT_TRUE(refused(replaced("\"inputs\":[\"height (m)\"", "\"inputs\":[7")));
  // Values that parse but cannot be used.
  smpl::BodyModel n = curve_test_model(2);
  caliper::ShapeCurve c = caliper::fit_shape_curve(s.height, s.weight, s.betas, s.wt, "p");
  c.scale[1] = 0.0;
  caliper::set_shape_curve(n, c);
  m.meta.extra[caliper::shape_curve_meta_key()] = n.meta.extra.at(caliper::shape_curve_meta_key());
  EXPECT_TRUE(refused(m.meta.extra.at(caliper::shape_curve_meta_key())));
  c = caliper::fit_shape_curve(s.height, s.weight, s.betas, s.wt, "p");
  std::swap(c.lo, c.hi);
  caliper::set_shape_curve(n, c);
  EXPECT_TRUE(refused(n.meta.extra.at(caliper::shape_curve_meta_key())));
  c = caliper::fit_shape_curve(s.height, s.weight, s.betas, s.wt, "p");
  c.coefficients(1, 2) = std::numeric_limits<double>::quiet_NaN();
  caliper::set_shape_curve(n, c);
  EXPECT_TRUE(refused(n.meta.extra.at(caliper::shape_curve_meta_key())));
}

}  // namespace
