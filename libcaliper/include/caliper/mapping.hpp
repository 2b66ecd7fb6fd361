/// \file mapping.hpp
/// Learned real-to-virtual mappings (Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.3,
/// the "L" regressor variants): per measurement, virtual = a * real + b, fitted by least squares
/// from paired values; identity for every measurement that was not fitted.
///
/// CSV format (docs/regressors.md): a header line naming at least the columns `measurement`,
/// `real` and `virtual` (any order, other columns ignored), then one pair per row, each row with
/// as many cells as the header (RFC 4180 quoting, caliper/csv.hpp); values in metres (weight in
/// kg); blank lines and lines starting with '#' are skipped.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "caliper/json.hpp"
#include "caliper/measurements.hpp"

namespace caliper {

/// One paired observation.
struct PairedValue {
  std::string measurement;     ///< measurement id
  double real = 0.0;           ///< measured on the person (e.g. with the controllers)
  double virtual_value = 0.0;  ///< the same measurement on the reference virtual body
};

/// Reads pairs from a CSV file. Throws InvalidInputError naming the file and line for a missing
/// column, an unparsable or non-finite number, a malformed row (CsvError's message), or an empty
/// file.
std::vector<PairedValue> read_paired_csv(const std::string& path);

/// virtual = a * real + b for one measurement, with its fit report.
struct LinearMap {
  double a = 1.0;
  double b = 0.0;
  int count = 0;              ///< pairs used (0: identity, not fitted)
  double fit_rms = 0.0;       ///< RMS residual of the fit, same unit as the values
  double loo_mae = 0.0;       ///< leave-one-out mean absolute error of the mapped value
  double loo_max = 0.0;       ///< leave-one-out max absolute error
  double identity_mae = 0.0;  ///< mean |real - virtual| (the error without mapping)

  double apply(double real) const { return a * real + b; }
};

class MeasurementMapping {
 public:
  /// The identity mapping.
  MeasurementMapping() = default;

  /// Fits one LinearMap per measurement present in `pairs`. Each needs at least 3 pairs (for
  /// leave-one-out) and two distinct real values, else InvalidInputError naming the
  /// measurement.
  static MeasurementMapping fit(const std::vector<PairedValue>& pairs);

  /// Mapped value (identity if `id` was not fitted).
  double apply(const std::string& id, double real) const;
  /// Maps every value of `real` (unfitted ids pass through unchanged).
  MeasurementMap apply(const MeasurementMap& real) const;

  bool is_identity() const { return maps_.empty(); }
  /// The fitted maps by measurement id.
  const std::map<std::string, LinearMap>& maps() const { return maps_; }

  /// {"format": "caliper-mapping", "version": 1, "maps": {"hip_width": {"a":..,"b":..,...}}}
  Json to_json() const;
  /// Throws InvalidInputError (or JsonError) for a malformed document.
  static MeasurementMapping from_json(const Json& json);
  void save(const std::string& path) const;
  static MeasurementMapping load(const std::string& path);

 private:
  std::map<std::string, LinearMap> maps_;
};

/// The map from the arm length a survey or a tape takes on the hanging arm (acromion to wrist,
/// hanging_arm_length(); ANSUR II's acromion-radiale plus radiale-stylion length) to the model's
/// virtual `arm_length` (the paper's: shoulder to wrist landmark in the T-pose, some 7 cm
/// shorter on the open models): virtual = a * hanging + b, least squares over `bodies` bodies of
/// the model with betas ~ N(0, I) (gaussian_betas() with a fixed seed: the same map on every
/// run; the landmarks of landmarks_for(model), so SMPL files work too), with its fit report
/// (fit_rms, leave-one-out errors, identity_mae: the error of taking one for the other). Throws
/// InvalidInputError for `bodies` < 3 and what hanging_arms() and measure() throw for a model
/// without the joints or landmarks.
LinearMap hanging_arm_map(const smpl::BodyModel& model, int bodies = 200);

}  // namespace caliper
