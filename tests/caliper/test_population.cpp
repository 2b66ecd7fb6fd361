// A survey's population in a model's metadata (caliper/population.hpp): written and read back to
// the bit, wrong or hostile entries refused with the key named, a regressor's prior from it, and
// the sampling factor of a semi-definite covariance.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/errors.hpp"
#include "caliper/population.hpp"

namespace {

// Only the number of betas matters here.
smpl::BodyModel model_with_betas(int b) {
  smpl::BodyModel m;
  m.shapedirs = Eigen::MatrixXd::Zero(3, b);
  return m;
}

caliper::SurveyPopulation example(int b) {
  caliper::SurveyPopulation p;
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
  EXPECT_FALSE(caliper::survey_population(m, "ansur2").has_value());
  const caliper::SurveyPopulation p = example(4);
  caliper::set_survey_population(m, "ansur2", p);
  const std::optional<caliper::SurveyPopulation> back = caliper::survey_population(m, "ansur2");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->survey, "ANSUR II");
  EXPECT_EQ(back->subjects, 1986);
  EXPECT_TRUE(back->mean == p.mean);
  EXPECT_TRUE(back->cov == p.cov);
  EXPECT_FALSE(caliper::survey_population(m, "nhanes").has_value());
  // Sizes other than the model's betas are refused on writing.
  EXPECT_THROW(caliper::set_survey_population(m, "nhanes", example(3)), std::invalid_argument);
}

TEST(Population, BadEntriesAreRefusedNamingTheKey) {
  smpl::BodyModel m = model_with_betas(4);
  const std::string key = caliper::population_meta_key("ansur2");
  auto refused = [&](const std::string& text) {
    m.meta.extra[key] = text;
    try {
      caliper::survey_population(m, "ansur2");
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

TEST(Population, PriorOfARegressorsBetasAndWhatAModelWithoutOneSays) {
  smpl::BodyModel m = model_with_betas(4);
  m.meta.name = "test-model";
  try {
    caliper::population_prior(m, "ansur2");
    ADD_FAILURE() << "no population, no prior";
  } catch (const caliper::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("carries no population 'ansur2' (it carries none"),
              std::string::npos)
        << e.what();
  }
  const caliper::SurveyPopulation p = example(4);
  caliper::set_survey_population(m, "ansur2", p);
  EXPECT_EQ(caliper::population_keys(m), std::vector<std::string>{"ansur2"});
  const caliper::ShapePrior prior = caliper::population_prior(m, "ansur2");
  EXPECT_TRUE(prior.mean == p.mean);
  EXPECT_TRUE(prior.covariance == p.cov);
  try {
    caliper::population_prior(m, "soldiers");
    ADD_FAILURE() << "unknown population";
  } catch (const caliper::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("it carries: ansur2"), std::string::npos) << e.what();
  }
}

TEST(Population, SamplingFactorReproducesASemiDefiniteCovariance) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(5, 3);
  const Eigen::MatrixXd cov = a * a.transpose();  // rank 3
  const Eigen::MatrixXd l = caliper::sampling_factor(cov);
  constexpr double kRounding = 1e-12;
  EXPECT_LT((l * l.transpose() - cov).norm(), kRounding * (1.0 + cov.norm()));
}

}  // namespace
