// Realism against the survey: bodies sampled with betas ~ N(0, I) from the committed models
// (or from the ANSUR II population a model file carries, population.hpp),
// measured with libcaliper, reproduce ANSUR II (committed statistics table) - means within 2 %,
// SDs within 20 %, stature-span and stature-weight correlations within 0.1 (issue 6); and issue
// 11's tighter targets: means within 1 %, SDs within 10 %, correlations within 0.05, met by every
// measurement of every model. The men's chest SD, 1.10-1.11 until the models fitted the arm's
// girth (their nipple level lies where the T-posed torso flares into the armpit), was held to
// issue 6's bound only; since commit afb9e87 it is 1.03 over 4,000 bodies and held to issue 11's
// like the rest (docs/models.md, "Validation against the survey").
//
// 2,000 bodies per model keep the test fast. Sampling error at n = 2000 is small next to the
// tolerances: the standard error of a mean is SD / sqrt(n) (under 0.3 % of the mean for every
// measurement here), of an SD about 1.6 %, of a correlation (1 - r^2) / sqrt(n) < 0.02.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "ansur_stats.hpp"
#include "caliper/population.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"
#include "validation.hpp"

namespace {

constexpr int kSamples = 2000;
constexpr double kMeanTol = 0.02;     // issue 6: means within 2 %
constexpr double kSdTol = 0.20;       // issue 6: SDs within 20 %
constexpr double kCorrTol = 0.10;     // issue 6: correlations within 0.1
constexpr double kMeanTarget = 0.01;  // issue 11: means within 1 %
constexpr double kSdTarget = 0.10;    // issue 11: SDs within 10 %
constexpr double kCorrTarget = 0.05;  // issue 11: correlations within 0.05

class Realism : public ::testing::TestWithParam<const char*> {};

TEST_P(Realism, SampledBodiesMatchTheSurvey) {
  const std::string gender = GetParam();
  const modelgen::SurveyStats stats =
      modelgen::read_stats_table(std::string(CALIPER_MODELS_DIR) + "/ansur_stats.csv");
  const smpl::BodyModel model =
      smpl::load_model(std::string(CALIPER_MODELS_DIR) + "/caliper-" + gender + ".npz");
  // A model whose betas ~ N(0, I) stand for another population (the v2 models: the general
  // adult population) carries the survey's own population in its betas; sampled from that.
  const std::optional<caliper::SurveyPopulation> ansur =
      caliper::survey_population(model, "ansur2");
  const modelgen::ValidationFigures m =
      modelgen::model_figures(model, kSamples, 2024, ansur ? &*ansur : nullptr);
  const modelgen::ValidationFigures s = modelgen::survey_figures(stats, gender);
  for (const std::string& id : modelgen::validation_ids()) {
    const double rel = m.mean.at(id) / s.mean.at(id) - 1.0;
    EXPECT_LT(std::abs(rel), kMeanTol)
        << id << ": model mean " << m.mean.at(id) << " survey " << s.mean.at(id);
    EXPECT_LT(std::abs(m.sd.at(id) / s.sd.at(id) - 1.0), kSdTol)
        << id << ": model SD " << m.sd.at(id) << " survey " << s.sd.at(id);
  }
  EXPECT_LT(std::abs(m.corr_stature_span - s.corr_stature_span), kCorrTol);
  EXPECT_LT(std::abs(m.corr_stature_weight - s.corr_stature_weight), kCorrTol);
  for (const std::string& id : modelgen::validation_ids()) {
    EXPECT_LT(std::abs(m.mean.at(id) / s.mean.at(id) - 1.0), kMeanTarget)
        << id << ": model mean " << m.mean.at(id) << " survey " << s.mean.at(id);
    EXPECT_LT(std::abs(m.sd.at(id) / s.sd.at(id) - 1.0), kSdTarget)
        << id << ": model SD " << m.sd.at(id) << " survey " << s.sd.at(id);
  }
  EXPECT_LT(std::abs(m.corr_stature_span - s.corr_stature_span), kCorrTarget);
  EXPECT_LT(std::abs(m.corr_stature_weight - s.corr_stature_weight), kCorrTarget);
}

INSTANTIATE_TEST_SUITE_P(Committed, Realism, ::testing::Values("female", "male", "neutral"));

// An independent check of the shoulder joint's placement, on a survey dimension the generator
// never sees: the wrist height of a standing person with the arms hanging. ANSUR II means
// (wristheight, from ../shared/data/ansur2 by tests/modelgen/hanging_arm_check.py --ansur):
// women 794.2 mm (1,986 people), men 847.5 mm (4,082). The mean body of each model, arms
// hanging by its own skinning, must come within 2 % (a joint at the acromion, as before this
// check existed, puts the wrist 4.5 % too high). For a model whose mean body is another
// population's (v2: the general adult population, whose women are 18 mm shorter than ANSUR II's),
// the body at the mean betas of its ANSUR II population.
TEST(Realism, HangingWristHeightOfTheMeanBodyMatchesTheSurvey) {
  for (const auto& [gender, survey_mm] : {std::pair<std::string, double>{"female", 794.2},
                                          std::pair<std::string, double>{"male", 847.5}}) {
    const smpl::BodyModel model =
        smpl::load_model(std::string(CALIPER_MODELS_DIR) + "/caliper-" + gender + ".npz");
    const std::optional<caliper::SurveyPopulation> ansur =
        caliper::survey_population(model, "ansur2");
    const smpl::Vertices v =
        ansur ? smpl::shape(model, ansur->mean).vertices : smpl::Vertices(model.v_template);
    const modelgen::HangingArms h = modelgen::hanging_arms(model, v);
    const double floor = v.col(1).minCoeff();
    for (int s = 0; s < 2; ++s) {
      const double wrist_mm = 1000.0 * (h.wrist[s].y() - floor);
      EXPECT_LT(std::abs(wrist_mm / survey_mm - 1.0), kMeanTol)
          << gender << " side " << s << ": hanging wrist height " << wrist_mm << " mm, survey "
          << survey_mm << " mm";
      // The arm hangs at the side: the wrist lies below and to the side of the acromion.
      EXPECT_GT(h.acromion[s].y() - h.wrist[s].y(), 0.45) << gender;
      EXPECT_LT(std::abs(h.wrist[s].x() - h.acromion[s].x()), 0.06) << gender;
    }
  }
}

}  // namespace
