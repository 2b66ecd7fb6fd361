// Weight from volume: Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.2.
#include "caliper/weight.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include "caliper/errors.hpp"
#include "smpl/text.hpp"

namespace caliper {

WeightFormula female_weight_formula() {
  return {1001.44, -2.36, "female"};
}
WeightFormula male_weight_formula() {
  return {1056.44, -5.28, "male"};
}
WeightFormula neutral_weight_formula() {
  const WeightFormula f = female_weight_formula(), m = male_weight_formula();
  return {0.5 * (f.coefficient + m.coefficient), 0.5 * (f.intercept + m.intercept), "neutral"};
}

WeightFormula weight_formula_for(const std::string& gender) {
  const std::string g = smpl::to_lower(gender);
  if (g == "female" || g == "f") return female_weight_formula();
  if (g == "male" || g == "m") return male_weight_formula();
  return neutral_weight_formula();
}

double weight_from_volume(double volume_m3, const WeightFormula& formula) {
  if (!std::isfinite(volume_m3)) {
    throw InvalidInputError("weight_from_volume: the volume is " +
                            smpl::format_general(volume_m3, 6) +
                            "; a finite volume in m^3 is needed");
  }
  return formula.coefficient * volume_m3 + formula.intercept;
}

double volume_from_weight(double weight_kg, const WeightFormula& formula) {
  if (!std::isfinite(weight_kg)) {
    throw InvalidInputError("weight " + smpl::format_general(weight_kg, 6) +
                            " kg is not a number; give a weight in kg");
  }
  const double v = (weight_kg - formula.intercept) / formula.coefficient;
  if (!(v > 0.0)) {
    throw InvalidInputError("weight " + smpl::format_general(weight_kg, 6) +
                            " kg implies a non-positive body volume; give a positive weight in kg");
  }
  return v;
}

double weight_feature(double weight_kg, const WeightFormula& formula) {
  return std::cbrt(volume_from_weight(weight_kg, formula));
}

double weight_from_feature(double feature_m, const WeightFormula& formula) {
  return weight_from_volume(feature_m * feature_m * feature_m, formula);
}

}  // namespace caliper
