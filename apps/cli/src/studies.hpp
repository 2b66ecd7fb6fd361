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
  std::string method;           ///< R2, R4, R5, noise-aware, "linear (H+W)", "linear (6)"
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

}  // namespace caliper::cli
