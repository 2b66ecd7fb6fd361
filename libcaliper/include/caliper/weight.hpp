/// \file weight.hpp
/// Weight from body volume (Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.2: linear
/// fits on SMPL registrations of CAESAR subjects): weight_kg = coefficient * volume_m3 + intercept.
/// Female: 1001.44 V - 2.36; male: 1056.44 V - 5.28. The neutral model uses the mean of both
/// formulas, 1028.94 V - 3.82 (documented in docs/measurements.md).
#pragma once

#include <string>

#include "smpl/body_model.hpp"

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

/// The metadata key of a model's own weight formula: "weight_formula" (JSON: coefficient in kg
/// per m^3, intercept in kg, name).
inline constexpr const char* kWeightFormulaMetaKey = "weight_formula";

/// The formula that weighs the bodies of `model`: its own (meta.extra["weight_formula"]) when
/// the file carries one, which a generated model whose volume is not the one of the paper's
/// CAESAR registrations must (its skin without what a scan includes), else the paper's formula
/// for its gender (weight_formula_for(model.meta.gender); every SMPL-family file). Throws
/// smpl::ModelError naming the key when the entry is not JSON of a finite coefficient of
/// 500-2000 kg/m^3 and a finite intercept within +/-50 kg.
WeightFormula weight_formula_of(const smpl::BodyModel& model);

/// Stores `formula` in `model`'s metadata (weight_formula_of() then returns it). Throws
/// std::invalid_argument for a formula weight_formula_of() would refuse.
void set_weight_formula(smpl::BodyModel& model, const WeightFormula& formula);

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
