/// \file inputs.hpp
/// The `caliper` command's batch inputs: people read from a CSV whose header states units
/// (`height_cm,weight_kg,...`), and the ANSUR II public CSV files read directly. (Range checks
/// of the values are libcaliper's validate_measurements().)
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "caliper/mapping.hpp"
#include "cli_support.hpp"

namespace caliper::cli {

/// Measurement id -> value in metres (lengths) or kilograms (weight).
using MeasurementValues = std::map<std::string, double>;

/// One person of a batch.
struct Person {
  std::string id;   ///< from the id column, or the 1-based row number
  std::string sex;  ///< "female", "male", "neutral" or "" (use the command's --sex)
  MeasurementValues inputs;
  /// Extra numeric columns kept for studies (ANSUR: survey girths in metres), by column name.
  std::map<std::string, double> extra;
  /// inputs' arm_length was taken on the hanging arm, as a survey takes it (ANSUR II), not as
  /// the paper's virtual arm length: map it onto the model's (model_inputs()).
  bool hanging_arm = false;
  int line = 0;       ///< source line, for messages
  std::string error;  ///< a problem reading this row ("" when fine)
};

/// Maps a CSV header cell such as "height_cm", "weight_kg", "arm_span_fingertips_in" or
/// "arm_span_cm" to a measurement id and the factor to SI units. Returns nullopt when the cell
/// is not a known measurement with a known unit.
std::optional<std::pair<std::string, double>> measurement_column(const std::string& header);

/// Normalises a sex value ("F", "female", "Woman", "M", "male", "neutral") to "female", "male",
/// "neutral"; returns "" for an empty cell and throws UsageError naming the value otherwise.
std::string normalise_sex(const std::string& value);

/// Reads people from a CSV with units in the header (see measurement_column), plus optional
/// `id` and `sex`/`gender` columns. An `arm_length_hanging_<unit>` column (a tape on the hanging
/// arm) becomes the person's arm_length with `hanging_arm` set; a header with both it and an
/// arm_length column is refused (RuntimeError). Throws RuntimeError naming the file when the header
/// has no measurement column; bad cells and rows with a wrong number of cells give that person an
/// `error` instead of stopping the batch.
std::vector<Person> read_people_csv(const std::string& path);

/// Reads an ANSUR II public CSV (male file Latin-1, female ASCII; ids `subjectid`/`SubjectId`):
/// height = stature, weight = weightkg / 10, arm_span_fingertips = span, inseam_height =
/// crotchheight, hip_width = hipbreadth, arm_length = acromionradialelength +
/// radialestylionlength (millimetres to metres; the hanging arm: `hanging_arm` is set). `extra`
/// holds chestcircumference, waistcircumference, buttockcircumference, thighcircumference,
/// biacromialbreadth, in metres. The sex comes from the Gender column. Throws RuntimeError naming
/// the file and missing column.
std::vector<Person> read_ansur_csv(const std::string& path);

/// The inputs of `p` for a model: an arm length taken on the hanging arm (Person::hanging_arm)
/// mapped onto the model's virtual arm length by `arm_map` (caliper::hanging_arm_map() of that
/// model); everything else as it is. Throws std::logic_error when the person's arm needs a map
/// and `arm_map` is null.
MeasurementValues model_inputs(const Person& p, const LinearMap* arm_map);

}  // namespace caliper::cli
