// Guards of the evaluation studies (docs/evaluation.md) on a small generated model: the paper's
// Table 1 property (a regressor's avatar reproduces its inputs) and the simulation study's
// requirements (noise-aware beats every plain regressor on self-measured input; no avatar beyond
// 3 SD where the true body was within 2 SD).
#include <gtest/gtest.h>

#include "caliper/regressor.hpp"
#include "cli_fixture.hpp"
#include "model_source.hpp"
#include "studies.hpp"

namespace caliper::cli {
namespace {

// The bounds: inputs a regressor uses come back to 1 mm, weight to 0.5 kg (R2/R4/R5).
constexpr double kInputTolCm = 0.1;
constexpr double kWeightTolKg = 0.5;

ModelBundle bundle_for(const smpl::BodyModel& model) {
  ModelBundle b;
  b.model = model;
  b.regressors = train_regressors(b.model);
  return b;
}

TEST(Table1Study, RegressorsReproduceTheirInputs) {
  const ModelBundle b = bundle_for(test::cli_test_model("female"));
  const Table1Result r =
      table1_study(b, 60, 5, false);  // exact inputs: the toy model is not human-sized
  ASSERT_EQ(r.regressors.size(), 5u);
  for (size_t k = 0; k < 4; ++k) {
    const auto kind = parse_regressor_kind(r.regressors[k]);
    ASSERT_TRUE(kind);
    for (const auto& id : regressor_inputs(*kind)) {
      const auto c = std::find(table1_columns().begin(), table1_columns().end(), id) -
                     table1_columns().begin();
      const double tol = id == "weight" ? kWeightTolKg : kInputTolCm;
      if (id == "weight" && *kind == RegressorKind::R6) continue;  // paper: R6 may miss weight
      EXPECT_LE(r.max_abs(static_cast<Eigen::Index>(k), c), tol)
          << r.regressors[k] << " " << id << "\n"
          << table1_markdown(r, false);
    }
  }
  // Columns a regressor does not use are not reproduced exactly (the table is informative).
  EXPECT_GT(r.mean_abs(0, 2), kInputTolCm) << table1_markdown(r, false);  // R2, arm span
}

TEST(Table1Study, ExactInputsReproduceEveryInputOnNoisyInput) {
  const ModelBundle b = bundle_for(test::cli_test_model("female"));
  const Table1Result r = table1_study(b, 30, 9, true, true);
  // R2, R4, R5. (R6 is left out here: the toy model's 11 cm arm barely varies, so human-sized
  // arm-length noise asks for betas far outside the model; docs/evaluation.md has R6 on the open
  // model.)
  for (size_t k = 0; k < 3; ++k) {
    for (const auto& id : regressor_inputs(*parse_regressor_kind(r.regressors[k]))) {
      const auto c = std::find(table1_columns().begin(), table1_columns().end(), id) -
                     table1_columns().begin();
      EXPECT_LE(r.max_abs(static_cast<Eigen::Index>(k), c),
                id == "weight" ? kWeightTolKg : kInputTolCm)
          << r.regressors[k] << " " << id << "\n"
          << table1_markdown(r, false);
    }
  }
}

TEST(SimulationStudy, NoiseAwareBeatsPlainRegressorsAndStaysPlausible) {
  const ModelBundle b = bundle_for(test::cli_test_model("male", 11));
  const auto rows = simulation_study(b, 120, 3);
  const SimulationRow* na = nullptr;
  for (const auto& r : rows)
    if (r.condition == "self" && r.regressor == "noise-aware") na = &r;
  ASSERT_NE(na, nullptr);
  for (const auto& r : rows) {
    if (r.condition != "self" || r.regressor == "noise-aware") continue;
    EXPECT_LT(na->mean_v2v_mm, r.mean_v2v_mm) << r.regressor << "\n" << simulation_markdown(rows);
  }
  for (const auto& r : rows) {
    if (r.regressor == "noise-aware") {
      EXPECT_EQ(r.beyond_3sd_true_within_2sd, 0) << r.condition << "\n"
                                                 << simulation_markdown(rows);
    }
    EXPECT_GT(r.true_within_2sd, 0);
  }
}

}  // namespace
}  // namespace caliper::cli
