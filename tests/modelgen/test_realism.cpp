// Realism against the survey: bodies sampled with betas ~ N(0, I) from the committed models,
// measured with libcaliper, reproduce ANSUR II (committed statistics table) - means within 2 %,
// SDs within 20 %, stature-span and stature-weight correlations within 0.1.
//
// 2,000 bodies per model keep the test fast. Sampling error at n = 2000 is small next to the
// tolerances: the standard error of a mean is SD / sqrt(n) (under 0.3 % of the mean for every
// measurement here), of an SD about 1.6 %, of a correlation (1 - r^2) / sqrt(n) < 0.02.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ansur_stats.hpp"
#include "generator.hpp"
#include "smpl/io.hpp"

namespace {

constexpr int kSamples = 2000;
constexpr double kMeanTol = 0.02;  // issue 6: means within 2 %
constexpr double kSdTol = 0.20;    // issue 6: SDs within 20 %
constexpr double kCorrTol = 0.10;  // issue 6: correlations within 0.1

// Shoulder-to-wrist length cannot match the survey in a T-pose: ANSUR's biacromial/2 + arm
// length + hand length exceeds span/2 by 8.6 cm (women) and 9.7 cm (men), so a body that has
// the survey's span, biacromial breadth and hand length has a shorter acromion-to-wrist
// distance (docs/models.md). The test pins the documented bias so that it cannot drift.
constexpr double kArmLengthBias = -0.14;     // model / survey - 1, documented
constexpr double kArmLengthBiasTol = 0.025;  // allowed movement around it

class Realism : public ::testing::TestWithParam<const char*> {};

TEST_P(Realism, SampledBodiesMatchTheSurvey) {
  const std::string gender = GetParam();
  const modelgen::SurveyStats stats =
      modelgen::read_stats_table(std::string(CALIPER_MODELS_DIR) + "/ansur_stats.csv");
  const smpl::BodyModel model =
      smpl::load_model(std::string(CALIPER_MODELS_DIR) + "/caliper-" + gender + ".npz");
  const modelgen::ValidationFigures m = modelgen::model_figures(model, kSamples, 2024);
  const modelgen::ValidationFigures s = modelgen::survey_figures(stats, gender);
  for (const std::string& id : modelgen::validation_ids()) {
    const double rel = m.mean.at(id) / s.mean.at(id) - 1.0;
    if (id == "arm_length") {
      EXPECT_NEAR(rel, kArmLengthBias, kArmLengthBiasTol) << id;
    } else {
      EXPECT_LT(std::abs(rel), kMeanTol)
          << id << ": model mean " << m.mean.at(id) << " survey " << s.mean.at(id);
    }
    EXPECT_LT(std::abs(m.sd.at(id) / s.sd.at(id) - 1.0), kSdTol)
        << id << ": model SD " << m.sd.at(id) << " survey " << s.sd.at(id);
  }
  EXPECT_LT(std::abs(m.corr_stature_span - s.corr_stature_span), kCorrTol);
  EXPECT_LT(std::abs(m.corr_stature_weight - s.corr_stature_weight), kCorrTol);
}

INSTANTIATE_TEST_SUITE_P(Committed, Realism, ::testing::Values("female", "male", "neutral"));

}  // namespace
