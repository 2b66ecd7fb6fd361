// Guards of the evaluation studies (docs/evaluation.md) on a small generated model: the paper's
// Table 1 property (a regressor's avatar reproduces its inputs) and the simulation study's
// requirements (noise-aware beats every plain regressor on self-measured input; no avatar beyond
// 3 SD where the true body was within 2 SD).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "caliper/assets.hpp"
#include "caliper/circumference.hpp"
#include "caliper/measurements.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "cli_fixture.hpp"
#include "inputs.hpp"
#include "model_source.hpp"
#include "smpl/io.hpp"
#include "studies.hpp"

namespace caliper::cli {
namespace {

// The issue's bounds: inputs a regressor uses come back to 1 mm, weight to 0.5 kg (R2/R4/R5).
constexpr double kInputTolCm = 0.1;
constexpr double kStudyWeightTolKg = 0.5;

// As load_bundle() makes it by default: the model's shape curve too, when it carries one.

ModelBundle bundle_for(const smpl::BodyModel& model) {
  ModelBundle b;
  b.model = model;
  b.regressors = train_regressors(b.model);
  b.curve = shape_curve(b.model);
  b.measure_info.emplace(b.model);
  return b;
}

// The committed open model of `sex` (assets/models).
ModelBundle committed_bundle(const char* sex) {
  return bundle_for(smpl::load_model(
      default_model_path(std::string(CALIPER_SOURCE_DIR) + "/assets/models", sex)));
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
      const double tol = id == "weight" ? kStudyWeightTolKg : kInputTolCm;
      if (id == "weight" && *kind == RegressorKind::R6) continue;  // paper: R6 may miss weight
      EXPECT_LE(r.max_abs(static_cast<Eigen::Index>(k), c), tol)
          << r.regressors[k] << " " << id << "\n"
          << table1_markdown(r, false);
    }
  }
  // Columns a regressor does not use are not reproduced exactly (the table is informative).
  EXPECT_GT(r.mean_abs(0, 2), kInputTolCm) << table1_markdown(r, false);  // R2, arm span
}

// The paper's Table 1 on the committed open models (docs/evaluation.md): every length a
// regressor takes comes back to 1 mm, on each model, the neutral one too (its floor is the same
// vertex for every body: mh::level_soles); the weight from volume of R2-R5 within 1 kg on
// average (the tables: 0.0-0.9 kg from the models' shape curve). R6's arm length on the neutral
// model, not linear in its betas, missed by up to 4.7 mm (1,000 bodies) with the shape curve's
// single step; linear_betas() now repeats the step on the lengths.
TEST(Table1Study, CommittedModelsGiveTheirLengthInputsBack) {
  for (const char* sex : {"female", "male", "neutral"}) {
    const ModelBundle b = committed_bundle(sex);
    const Table1Result r = table1_study(b, 40, 11);
    for (size_t k = 0; k < r.regressors.size(); ++k) {
      const auto kind = parse_regressor_kind(r.regressors[k]);
      if (!kind) continue;  // the noise-aware row
      for (const auto& id : regressor_inputs(*kind)) {
        const auto c = static_cast<Eigen::Index>(
            std::find(table1_columns().begin(), table1_columns().end(), id) -
            table1_columns().begin());
        const auto row = static_cast<Eigen::Index>(k);
        if (id != "weight") {
          EXPECT_LE(r.max_abs(row, c), kInputTolCm)
              << sex << " " << r.regressors[k] << " " << id << "\n"
              << table1_markdown(r, false);
        } else if (*kind != RegressorKind::R6) {
          EXPECT_LE(r.mean_abs(row, c), 1.0) << sex << " " << r.regressors[k] << " weight\n"
                                             << table1_markdown(r, false);
        }
      }
    }
  }
}

// Issue 11, "Must show" 3 on the committed models: held-out ANSUR II soldiers' girths from height
// and weight, with the model's ANSUR II population as the prior, within 1.1x of the direct linear
// baseline (chest, waist, buttock, thigh) and the thigh's bias within +/-10 mm. Every 5th subject
// held out, as in docs/evaluation.md (fewer are too noisy for a 1.1x bound: every 25th puts the
// women's thigh at 1.10x, every 10th the men's waist at 1.11x). The men's thigh was 24.6 vs
// 17.8 mm (bias +20.3 mm) until its level was kept 3 cm under the crotch (caliper::
// thigh_fold_level()).
TEST(AnsurStudy, TheAnsurPriorMatchesTheLinearBaselineOnTheCommittedModels) {
  const std::string dir = CALIPER_ANSUR_DIR;
  if (!std::filesystem::exists(dir + "/ANSUR_II_MALE_Public.csv")) {
    GTEST_SKIP() << "no ANSUR II files in " << dir << " (../shared/data/ansur2)";
  }
  const ModelBundle male = committed_bundle("male");
  const ModelBundle female = committed_bundle("female");
  std::vector<std::pair<std::vector<Person>, const ModelBundle*>> groups;
  groups.emplace_back(read_ansur_csv(dir + "/ANSUR_II_MALE_Public.csv"), &male);
  groups.emplace_back(read_ansur_csv(dir + "/ANSUR_II_FEMALE_Public.csv"), &female);
  const std::vector<AnsurRow> rows = ansur_study(groups, 5);
  for (const char* sex : {"male", "female"}) {
    const auto row = [&](const std::string& method) {
      const auto it = std::find_if(rows.begin(), rows.end(), [&](const AnsurRow& r) {
        return r.sex == sex && r.method == method;
      });
      EXPECT_NE(it, rows.end()) << sex << " " << method;
      return it == rows.end() ? AnsurRow{} : *it;
    };
    const AnsurRow avatar = row("ANSUR II prior (H+W)");
    const AnsurRow baseline = row("linear (H+W)");
    ASSERT_EQ(avatar.mae_mm.size(), 5u);
    ASSERT_EQ(baseline.mae_mm.size(), 5u);
    EXPECT_EQ(avatar.failed, 0) << sex;
    for (size_t t = 0; t < 4; ++t) {  // chest, waist, buttock, thigh (not biacromial)
      EXPECT_LE(avatar.mae_mm[t], 1.1 * baseline.mae_mm[t])
          << sex << " " << ansur_targets()[t] << "\n"
          << ansur_markdown(rows);
    }
    EXPECT_LE(std::abs(avatar.bias_mm[3]), 10.0) << sex << "\n" << ansur_markdown(rows);
    // With all six inputs the survey's hanging arm is mapped onto the model's virtual arm
    // (caliper::hanging_arm_map()): taken as it is, 7 cm too long, it pulled the women's waist
    // out by +50 mm (docs/evaluation.md, section 3). The waist then stays within 20 mm on average.
    const AnsurRow six = row("ANSUR II prior (6 inputs)");
    ASSERT_EQ(six.bias_mm.size(), 5u);
    EXPECT_EQ(six.failed, 0) << sex;
    EXPECT_LE(std::abs(six.bias_mm[1]), 20.0) << sex << "\n" << ansur_markdown(rows);
  }
}

// Issue 11, "Must show" 4 on the committed models: the NHANES development half, R2 avatars from
// height and weight in every BMI bin of each sex within the issue's targets (hip and iliac-crest
// waist bias within +/-20 mm, +/-30 mm over BMI 50; MAE within 1.15x of the cross-validated
// height+weight fit; weight from volume within 0.5 kg mean and 2 kg max; under 5 % beyond 3 SD
// under BMI 50). Met since the models carry their shape curve (caliper/shape_curve.hpp); the
// paper's R2 (`--no-shape-curve`) misses at both ends of the BMI range (docs/evaluation.md).
// About 4 s.
TEST(NhanesStudy, CommittedModelsMeetTheIssueTargetsInEveryBmiBin) {
  const std::string dir = CALIPER_NHANES_DIR;
  if (!std::filesystem::exists(dir + "/NHANES_2017_2020_FEMALE_dev.csv")) {
    GTEST_SKIP() << "no NHANES files in " << dir << " (../shared/data/nhanes)";
  }
  const ModelBundle female = committed_bundle("female");
  const ModelBundle male = committed_bundle("male");
  ASSERT_TRUE(female.curve && male.curve) << "the committed models carry no shape curve";
  std::vector<NhanesGroup> groups(2);
  groups[0] = {"female", read_nhanes_csv(dir + "/NHANES_2017_2020_FEMALE_dev.csv"), &female};
  groups[1] = {"male", read_nhanes_csv(dir + "/NHANES_2017_2020_MALE_dev.csv"), &male};
  const std::vector<NhanesRow> rows = nhanes_study(groups, 10);
  ASSERT_EQ(rows.size(), 2 * (nhanes_bmi_bins().size() + 1));
  for (const NhanesRow& r : rows) {
    EXPECT_GT(r.measured(), 0) << r.sex << " " << r.bin;
    std::string m;
    for (const auto& x : nhanes_misses(r)) m += x + "; ";
    EXPECT_TRUE(m.empty()) << r.sex << " BMI " << r.bin << " misses " << m << "\n"
                           << nhanes_markdown(rows);
  }
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
                id == "weight" ? kStudyWeightTolKg : kInputTolCm)
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

// ---------------------------------------------------------------------------------------------
// NHANES study

/// A folder of its own for the NHANES test files.
std::string nhanes_test_dir() {
  const auto dir = std::filesystem::temp_directory_path() / "caliper-cli-nhanes-test";
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string write_file(const std::string& name, const std::string& text) {
  std::string path = nhanes_test_dir() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// The toy model with left/right_iliac_crest placed by the library's rule (at the toy's own
/// waist level: the toy is not human-shaped, so ANSUR's 0.608 of stature is not used).
smpl::BodyModel toy_with_iliac_crest(const std::string& sex, std::uint64_t seed) {
  smpl::BodyModel m = test::cli_test_model(sex, seed);
  LandmarkTable t = landmarks_for(m);
  const double floor = m.v_template.col(1).minCoeff();
  const double navel = landmark_point(m.v_template, t.at("navel")).y();
  derive_iliac_crest_landmarks(m.v_template, t,
                               (navel - floor) / (m.v_template.col(1).maxCoeff() - floor), 0.02);
  for (const char* n : {"left_iliac_crest", "right_iliac_crest"}) m.landmarks[n] = t.at(n);
  return m;
}

/// An NHANES-format file (comment lines, quoted header, cm and kg) of `n` bodies drawn from the
/// model: their own height, weight from volume, hip and iliac-crest waist.
std::string nhanes_file_from(const smpl::BodyModel& m, int n, std::uint64_t seed,
                             const std::string& name) {
  std::ostringstream s;
  s << "# test bodies drawn from " << m.meta.name << "\n#\n"
    << "\"BMXWT\",\"BMXHT\",\"BMXARML\",\"BMXLEG\",\"BMXARMC\",\"BMXHIP\",\"BMXWAIST\"\n";
  const Eigen::MatrixXd betas = gaussian_betas(n, 10, seed);
  for (int i = 0; i < n; ++i) {
    const MeasurementMap a = measure_all(m, shaped_vertices(m, betas.row(i).transpose()));
    s << a.at("weight") << "," << a.at("height") * 100 << ",30,40,30,"
      << a.at("hip_circumference") * 100 << "," << a.at("waist_iliac_circumference") * 100 << "\n";
  }
  return write_file(name, s.str());
}

TEST(NhanesStudy, SmallSampleGivesOneRowPerBinAndSex) {
  constexpr int kPeople = 40;
  ModelBundle female = bundle_for(toy_with_iliac_crest("female", 7));
  ModelBundle male = bundle_for(toy_with_iliac_crest("male", 11));
  female.path = "toy-female.npz";
  male.path = "toy-male.npz";
  std::vector<NhanesGroup> groups = {
      {"female", read_nhanes_csv(nhanes_file_from(female.model, kPeople, 3, "f.csv")), &female},
      {"male", read_nhanes_csv(nhanes_file_from(male.model, kPeople, 4, "m.csv")), &male}};
  ASSERT_EQ(groups[0].people.size(), static_cast<size_t>(kPeople));
  EXPECT_EQ(groups[0].people[0].line, 4);  // after two comment lines and the header
  const auto rows = nhanes_study(groups, 5);
  const std::string table = nhanes_markdown(rows);
  ASSERT_EQ(rows.size(), 2 * (nhanes_bmi_bins().size() + 1)) << table;
  for (size_t g = 0; g < 2; ++g) {
    int in_bins = 0;
    for (size_t b = 0; b < nhanes_bmi_bins().size(); ++b) in_bins += rows[g * 8 + b].count;
    const NhanesRow& all = rows[g * 8 + 7];
    EXPECT_EQ(all.bin, "all");
    EXPECT_EQ(in_bins, kPeople) << table;
    EXPECT_EQ(all.count, kPeople) << table;
    EXPECT_EQ(all.failed, 0) << table;
    // R2 reproduces the weight of the model's own bodies (the Table 1 bound).
    EXPECT_LE(all.weight_mean_abs_kg, kStudyWeightTolKg) << table;
    for (double v :
         {all.hip_mae_mm, all.hip_baseline_mae_mm, all.waist_mae_mm, all.waist_baseline_mae_mm}) {
      EXPECT_TRUE(std::isfinite(v) && v > 0.0) << table;
    }
    EXPECT_LE(std::abs(all.hip_bias_mm), all.hip_mae_mm) << table;
    EXPECT_LE(all.beyond_3sd, all.count);
  }
  EXPECT_NE(table.find("| female | all | 40 |"), std::string::npos) << table;
  EXPECT_EQ(table.find("nan"), std::string::npos) << table;  // empty bins print dashes
  EXPECT_NE(table.find("| male | all | 40 |"), std::string::npos) << table;
}

TEST(NhanesStudy, MissingLandmarkNamesItAndTheModelFile) {
  ModelBundle plain = bundle_for(test::cli_test_model("female", 7));
  plain.path = "plain-toy.npz";
  const smpl::BodyModel with = toy_with_iliac_crest("female", 7);
  std::vector<NhanesGroup> groups = {
      {"female", read_nhanes_csv(nhanes_file_from(with, 20, 3, "few.csv")), &plain}};
  try {
    nhanes_study(groups, 5);
    FAIL() << "a model without iliac crest landmarks was accepted";
  } catch (const RuntimeError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'left_iliac_crest'"), std::string::npos) << what;
    EXPECT_NE(what.find("plain-toy.npz"), std::string::npos) << what;
    EXPECT_NE(what.find("--derive-iliac-crest"), std::string::npos) << what;
  }
}

TEST(NhanesStudy, BadFilesAreNamed) {
  const auto message = [](const std::string& path) {
    try {
      read_nhanes_csv(path);
    } catch (const RuntimeError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(nhanes_test_dir() + "/absent.csv").find("cannot open"), std::string::npos);
  const std::string no_waist = write_file("no_waist.csv", "BMXWT,BMXHT,BMXHIP\n70,170,100\n");
  EXPECT_NE(message(no_waist).find("no column BMXWAIST"), std::string::npos) << message(no_waist);
  const std::string bad =
      write_file("bad.csv", "# c\nBMXWT,BMXHT,BMXHIP,BMXWAIST\n70,170,100,90\n70,,100,90\n");
  EXPECT_NE(message(bad).find("bad.csv:4: BMXHT '' is not a positive number"), std::string::npos)
      << message(bad);
}

}  // namespace
}  // namespace caliper::cli
