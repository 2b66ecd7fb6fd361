/// \file weight.hpp
/// Weight from body volume (Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.2: linear
/// fits on SMPL registrations of CAESAR subjects): weight_kg = coefficient * volume_m3 + intercept.
/// Female: 1001.44 V - 2.36; male: 1056.44 V - 5.28. The neutral model uses the mean of both
/// formulas, 1028.94 V - 3.82 (documented in docs/measurements.md).
#pragma once

#include <string>

namespace caliper {

/// weight = coefficient * volume + intercept (kg from m^3).
struct WeightFormula {
  double coefficient = 0.0;  ///< kg per m^3
  double intercept = 0.0;    ///< kg
  std::string name;          ///< "female", "male" or "neutral"
};

WeightFormula female_weight_formula();   ///< 1001.44 V - 2.36
WeightFormula male_weight_formula();     ///< 1056.44 V - 5.28
WeightFormula neutral_weight_formula();  ///< mean of the two: 1028.94 V - 3.82

/// Formula for a model gender: "female" / "male" (case-insensitive, also "f", "m"); anything
/// else ("neutral", "", unknown) gives the neutral formula.
WeightFormula weight_formula_for(const std::string& gender);

/// Weight in kg of a body of volume `volume_m3`. Throws InvalidInputError for NaN/inf.
double weight_from_volume(double volume_m3, const WeightFormula& formula);

/// Volume in m^3 implied by `weight_kg` (inverse of weight_from_volume). Throws
/// InvalidInputError for NaN/inf or a weight whose implied volume is not positive
/// (weight <= intercept).
double volume_from_weight(double weight_kg, const WeightFormula& formula);

/// The regressors' weight feature: the cube root of the volume implied by `weight_kg`, metres.
/// Same errors as volume_from_weight().
double weight_feature(double weight_kg, const WeightFormula& formula);

/// Inverse of weight_feature(): weight in kg of a body whose cube-root volume is `feature_m`.
double weight_from_feature(double feature_m, const WeightFormula& formula);

}  // namespace caliper
