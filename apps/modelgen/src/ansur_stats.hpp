/// \file ansur_stats.hpp
/// Population statistics of the body dimensions the open-model generator needs, computed from the
/// ANSUR II survey (2012 US Army Anthropometric Survey, public release; Gordon et al. 2014) per
/// sex: means, standard deviations and the correlation matrix. The generator reads only the small
/// committed table (assets/models/ansur_stats.csv), never the survey itself.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace modelgen {

/// The survey dimensions used, in table order. Values are metres (weight: kilograms).
enum Dim : int {
  kStature,
  kCrotchHeight,
  kSpan,
  kAcromionRadiale,
  kRadialeStylion,
  kBiacromial,
  kChestBreadth,
  kChestDepth,
  kWaistBreadth,
  kWaistDepth,
  kHipBreadth,
  kButtockDepth,
  kChestCirc,
  kWaistCirc,
  kButtockCirc,
  kThighCirc,
  kLowerThighCirc,
  kCalfCirc,
  kAnkleCirc,
  kBicepsCirc,
  kForearmCirc,
  kWristCirc,
  kNeckCirc,
  kHeadCirc,
  kHeadBreadth,
  kHeadLength,
  kTragionTop,
  kHandLength,
  kHandBreadth,
  kFootLength,
  kFootBreadth,
  kChestHeight,
  kWaistHeight,
  kAcromialHeight,
  kAxillaHeight,
  kCervicaleHeight,
  kButtockHeight,
  kKneeHeight,
  kMalleolusHeight,
  kWeight,
  kNumDims
};

/// ANSUR II column name of each Dim (lengths in mm in the survey, weightkg in 0.1 kg).
const std::array<const char*, kNumDims>& dim_columns();

/// Statistics of one sex: mean and SD per dimension and the correlation matrix.
struct SexStats {
  std::string sex;              ///< "female" or "male"
  int count = 0;                ///< number of subjects
  Eigen::VectorXd mean;         ///< kNumDims, metres / kg
  Eigen::VectorXd sd;           ///< kNumDims, sample standard deviations
  Eigen::MatrixXd correlation;  ///< kNumDims x kNumDims

  /// Covariance matrix sd_i sd_j corr_ij.
  Eigen::MatrixXd covariance() const;
};

/// Both sexes.
struct SurveyStats {
  SexStats female;
  SexStats male;
  const SexStats& of(const std::string& sex) const { return sex == "male" ? male : female; }
};

/// Reads the numeric `columns` of a survey CSV file (ANSUR II, NHANES): one row per data line,
/// values as written (no unit conversion), columns in the order asked. Read by caliper/csv.hpp:
/// lines starting with '#' are comments (NHANES); header names may be quoted and match case-
/// insensitively; empty lines are skipped. Throws std::runtime_error (caliper::CsvError for the
/// file's form) naming the file, and the line and column, for a missing file or column, a row
/// with another number of cells than the header, or a value that is not a finite number.
Eigen::MatrixXd read_survey_columns(const std::string& csv_path,
                                    const std::vector<std::string>& columns);

/// Reads one ANSUR II CSV file (Latin-1 or ASCII) and computes the statistics of the Dim columns.
/// Throws std::runtime_error naming the file and column when a column is missing or a value is
/// not a number.
SexStats stats_from_survey_file(const std::string& csv_path, const std::string& sex);

/// Reads both survey files from `dir` (ANSUR_II_FEMALE_Public.csv, ANSUR_II_MALE_Public.csv).
SurveyStats stats_from_survey(const std::string& dir);

/// Writes the table: one line per (sex, dim) with count, mean, sd and the correlation row, values
/// printed with 9 significant digits so that the file is the same on every machine; written
/// atomically (smpl::WriteError when it cannot be).
void write_stats_table(const SurveyStats& stats, const std::string& path);

/// Reads the table written by write_stats_table(). Throws std::runtime_error naming the file and
/// line when it is malformed.
SurveyStats read_stats_table(const std::string& path);

}  // namespace modelgen
