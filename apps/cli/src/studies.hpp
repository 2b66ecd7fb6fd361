/// \file studies.hpp
/// The evaluation studies of docs/evaluation.md, as functions (run by `caliper evaluate` and
/// guarded by tests/cli on small models):
/// 1. table1_study: the paper's Table 1 (Pujades et al. 2019): input vs avatar measurement error
///    per regressor, columns H, W, AS, I, HW, AL (cm, kg), mean and max absolute error.
/// 2. simulation_study: bodies drawn from the model, their measurements perturbed by the paper's
///    Table 2 self/other errors (MAE * sqrt(pi/2) as Gaussian SD), avatars by R2/R4/R5/R6 and the
///    noise-aware regressor, mean vertex-to-vertex error against the true body.
/// 3. ansur_study: held-out ANSUR II subjects (every 5th of each file), avatars from their real
///    inputs, circumferences and biacromial breadth on the avatar vs the survey, next to the
///    direct linear-regression baseline fitted on the other subjects.
/// 4. nhanes_study: NHANES 2017-2020 adults (development half), R2 avatars from height and
///    weight per sex and BMI bin: hip and iliac-crest waist against the survey next to a
///    cross-validated height+weight linear fit, weight from the avatar's volume, and the share
///    of avatars beyond 3 SD (issue 11, "Must show" 4).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/regressor.hpp"
#include "inputs.hpp"
#include "model_source.hpp"

namespace caliper::cli {

/// The six regressor inputs in the paper's column order (H, W, AS, I, HW, AL).
const std::vector<std::string>& table1_columns();

/// Result of table1_study().
struct Table1Result {
  std::vector<std::string> regressors;  ///< row names: R2, R4, R5, R6, noise-aware
  Eigen::MatrixXd mean_abs;             ///< regressors x 6: cm (weight kg)
  Eigen::MatrixXd max_abs;              ///< regressors x 6
  int bodies = 0;
  std::string condition;  ///< how the inputs were made
};

/// Inputs: `n` bodies with betas ~ N(0, I) over the regressors' components (seeded), their six
/// measurements perturbed by the self (even bodies) or other (odd bodies) measurement noise, as
/// the paper's Table 1 mixes self and other inputs (when `noisy`). Avatars from each regressor are
/// measured and compared with the inputs.
/// `exact_inputs`: plain regressors refine their betas to reproduce every input (libcaliper).
Table1Result table1_study(const ModelBundle& bundle, int n, std::uint64_t seed, bool noisy = true,
                          bool exact_inputs = false);
/// The result in the paper's layout (markdown table, "R2 Mean", "R2 Max", ...), with the
/// paper's own figures when `with_paper`.
std::string table1_markdown(const Table1Result& r, bool with_paper);

/// One row of the simulation study.
struct SimulationRow {
  std::string regressor;               ///< R2, R4, R5, R6, noise-aware
  std::string condition;               ///< self | other | exact
  double mean_v2v_mm = 0.0;            ///< mean over bodies of the mean vertex-to-vertex error
  double p90_v2v_mm = 0.0;             ///< 90th percentile over bodies
  int beyond_3sd = 0;                  ///< avatars with a component beyond 3 SD
  int beyond_3sd_true_within_2sd = 0;  ///< ... among bodies whose true betas are all within 2 SD
  int true_within_2sd = 0;             ///< bodies whose true betas are all within 2 SD
  int bodies = 0;
};

/// Runs every regressor on `n` bodies for each condition ("exact", "self", "other"). Bodies and
/// avatars are set on a common floor and centred by their bounding boxes (the paper's alignment).
std::vector<SimulationRow> simulation_study(const ModelBundle& bundle, int n, std::uint64_t seed);
std::string simulation_markdown(const std::vector<SimulationRow>& rows);

/// One row of the ANSUR study: MAE (mm) per target for one sex and one method.
struct AnsurRow {
  std::string sex;
  /// R2, R4, R5, noise-aware, "ANSUR II prior (H+W)", "ANSUR II prior (6 inputs)" (models that
  /// carry the ANSUR II population), "linear (H+W)", "linear (6 inputs)"
  std::string method;
  std::vector<double> mae_mm;   ///< per ansur_targets()
  std::vector<double> bias_mm;  ///< mean signed error (avatar - survey)
  int subjects = 0;
  int failed = 0;  ///< subjects whose avatar could not be made
};

/// Survey columns compared: chestcircumference, waistcircumference, buttockcircumference,
/// thighcircumference, biacromialbreadth.
const std::vector<std::string>& ansur_targets();
/// The avatar measurement compared with each target (chest_circumference, ...,
/// shoulder_width).
const std::vector<std::string>& ansur_avatar_measurements();

/// For each person list (e.g. the male and the female file) and its bundle: subjects with index
/// % `every` == `every` - 1 are held out; the baseline is fitted on the others.
std::vector<AnsurRow> ansur_study(
    const std::vector<std::pair<std::vector<Person>, const ModelBundle*>>& groups, int every = 5);
std::string ansur_markdown(const std::vector<AnsurRow>& rows);

/// One NHANES adult: survey values in SI units.
struct NhanesPerson {
  double height = 0.0;  ///< BMXHT, m
  double weight = 0.0;  ///< BMXWT, kg
  double hip = 0.0;     ///< BMXHIP, m (maximum extension of the buttocks)
  double waist = 0.0;  ///< BMXWAIST, m (just above the uppermost lateral border of the iliac crest)
  int line = 0;        ///< source line
  double bmi() const { return weight / (height * height); }
};

/// Reads one file of the NHANES body measures (`#` comment lines, a header with the columns
/// BMXWT, BMXHT, BMXHIP, BMXWAIST among others, quoted or not; cm and kg). Throws RuntimeError
/// naming the file when it cannot be opened, a column is missing, or a value is not a positive
/// number (with its line).
std::vector<NhanesPerson> read_nhanes_csv(const std::string& path);

/// The BMI bins of the study: "<20", "20-25", "25-30", "30-35", "35-40", "40-50", ">50"
/// (lower bound included).
const std::vector<std::string>& nhanes_bmi_bins();
/// Index into nhanes_bmi_bins() of a BMI in kg/m^2.
int nhanes_bmi_bin(double bmi);

/// One row of the NHANES study: one sex and one BMI bin ("all" for the whole sex).
struct NhanesRow {
  std::string sex;
  std::string bin;
  int count = 0;   ///< people in the bin
  int failed = 0;  ///< people whose avatar could not be made (left out of every figure)
  double hip_bias_mm = 0.0, hip_mae_mm = 0.0, hip_baseline_mae_mm = 0.0;
  double waist_bias_mm = 0.0, waist_mae_mm = 0.0, waist_baseline_mae_mm = 0.0;
  double weight_mean_abs_kg = 0.0, weight_max_abs_kg = 0.0;
  int beyond_3sd = 0;  ///< avatars with a component beyond 3 SD
  int measured() const { return count - failed; }
};

/// One sex of the NHANES study: the people, the model bundle (with its R2 regressor) and the
/// model file (named in errors).
struct NhanesGroup {
  std::string sex;
  std::vector<NhanesPerson> people;
  const ModelBundle* bundle = nullptr;
};

/// Landmarks the iliac-crest waist needs (caliper::circumferences()).
const std::vector<std::string>& nhanes_waist_landmarks();

/// For each group: R2 avatars from height and weight (the model's in-process or loaded R2),
/// their hip_circumference and waist_iliac_circumference against BMXHIP and BMXWAIST (bias =
/// mean of avatar - survey), the baseline (circumference ~ height + weight + 1, least squares,
/// `folds`-fold cross-validated: person i is predicted by the fit on the people with
/// i % folds != its fold), the avatar's weight from its volume (the paper's formula for the
/// model's gender) against BMXWT, and the avatars beyond 3 SD (caliper::plausibility). Rows per
/// BMI bin, then "all", per group. Throws RuntimeError naming the model file and the landmark
/// when a bundle's model lacks an nhanes_waist_landmarks() landmark.
std::vector<NhanesRow> nhanes_study(const std::vector<NhanesGroup>& groups, int folds = 10);

/// The issue-11 targets `r` misses ("hip bias", "hip MAE", "waist bias", "waist MAE", "weight
/// mean", "weight max", "3 SD", "N failed"; empty: none): |bias| <= 20 mm (30 mm over BMI 50),
/// avatar MAE <= 1.15 x baseline MAE, weight from volume within 0.5 kg mean and 2 kg max, under
/// 5 % beyond 3 SD (bins under BMI 50).
std::vector<std::string> nhanes_misses(const NhanesRow& r);

/// Markdown table of the rows with a last column naming nhanes_misses() of each row.
std::string nhanes_markdown(const std::vector<NhanesRow>& rows);

}  // namespace caliper::cli
