// A survey's population in a model's metadata (apps/modelgen/src/population.hpp): written and
// read back to the bit, wrong or hostile entries refused with the key named, and the sampling
// factor of a semi-definite covariance.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "population.hpp"

namespace {

// Only the number of betas matters here.
smpl::BodyModel model_with_betas(int b) {
  smpl::BodyModel m;
  m.shapedirs = Eigen::MatrixXd::Zero(3, b);
  return m;
}

modelgen::SurveyPopulation example(int b) {
  modelgen::SurveyPopulation p;
  p.survey = "ANSUR II";
  p.subjects = 1986;
  p.mean = Eigen::VectorXd::LinSpaced(b, -0.3, 0.7) / 3.0;  // not exact in binary
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(b, b) / 7.0;
  p.cov = a * a.transpose();
  p.cov = 0.5 * (p.cov + p.cov.transpose()).eval();
  return p;
}

TEST(Population, RoundTripsThroughTheModelMetadataToTheBit) {
  smpl::BodyModel m = model_with_betas(4);
  EXPECT_FALSE(modelgen::survey_population(m, "ansur2").has_value());
  const modelgen::SurveyPopulation p = example(4);
  modelgen::set_survey_population(m, "ansur2", p);
  const std::optional<modelgen::SurveyPopulation> back = modelgen::survey_population(m, "ansur2");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->survey, "ANSUR II");
  EXPECT_EQ(back->subjects, 1986);
  EXPECT_TRUE(back->mean == p.mean);
  EXPECT_TRUE(back->cov == p.cov);
  EXPECT_FALSE(modelgen::survey_population(m, "nhanes").has_value());
  // Sizes other than the model's betas are refused on writing.
  EXPECT_THROW(modelgen::set_survey_population(m, "nhanes", example(3)), std::invalid_argument);
}

TEST(Population, BadEntriesAreRefusedNamingTheKey) {
  smpl::BodyModel m = model_with_betas(4);
  const std::string key = modelgen::population_meta_key("ansur2");
  auto refused = [&](const std::string& text) {
    m.meta.extra[key] = text;
    try {
      modelgen::survey_population(m, "ansur2");
    } catch (const std::runtime_error& e) {
      return std::string(e.what()).find(key) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(refused("not json"));
  EXPECT_TRUE(refused(R"({"survey":"x","subjects":2,"mean":[0,0,0],"cov":[]})"));  // 3 betas
  EXPECT_TRUE(refused(R"({"survey":"x","subjects":2,"mean":[0,0,0,0],"cov":[[1,0,0,0]]})"));
  EXPECT_TRUE(refused(R"({"survey":"x","subjects":2,"mean":[0,0,0,0],)"
                      R"("cov":[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,-1]]})"));  // negative
  EXPECT_TRUE(refused(R"({"survey":"x","subjects":2,"mean":[0,0,0,0],)"
                      R"("cov":[[1,0.5,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})"));  // asymmetric
  EXPECT_TRUE(refused(R"({"survey":"x","subjects":2,"mean":[0,0,0,1e999],)"
                      R"("cov":[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})"));  // infinity
}

TEST(Population, SamplingFactorReproducesASemiDefiniteCovariance) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(5, 3);
  const Eigen::MatrixXd cov = a * a.transpose();  // rank 3
  const Eigen::MatrixXd l = modelgen::sampling_factor(cov);
  constexpr double kRounding = 1e-12;
  EXPECT_LT((l * l.transpose() - cov).norm(), kRounding * (1.0 + cov.norm()));
}

}  // namespace
