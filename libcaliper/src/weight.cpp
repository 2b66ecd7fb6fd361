// Weight from volume: Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.2; a model's own
// formula from its metadata (JSON through nlohmann-json).
#include "caliper/weight.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

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

namespace {

// What a body model's own formula may be: the density of a human body is 0.9-1.1 kg/L, and the
// paper's intercepts (what a scan's volume holds that is not body: -2.4, -5.3 kg) are a few kg.
constexpr double kMinCoefficient = 500.0, kMaxCoefficient = 2000.0, kMaxIntercept = 50.0;

std::string formula_problem(const WeightFormula& f) {
  if (!std::isfinite(f.coefficient) || f.coefficient < kMinCoefficient ||
      f.coefficient > kMaxCoefficient) {
    return "a coefficient of " + smpl::format_general(f.coefficient, 6) +
           " kg/m^3 (a body's density: 500-2000)";
  }
  if (!std::isfinite(f.intercept) || std::abs(f.intercept) > kMaxIntercept) {
    return "an intercept of " + smpl::format_general(f.intercept, 6) + " kg (within +/-50)";
  }
  return "";
}

}  // namespace

WeightFormula weight_formula_of(const smpl::BodyModel& model) {
  const auto it = model.meta.extra.find(kWeightFormulaMetaKey);
  if (it == model.meta.extra.end()) return weight_formula_for(model.meta.gender);
  const std::string where = std::string("the model's '") + kWeightFormulaMetaKey + "' metadata";
  WeightFormula f;
  try {
    const nlohmann::json j = nlohmann::json::parse(it->second);
    f.coefficient = j.at("coefficient").get<double>();
    f.intercept = j.at("intercept").get<double>();
    const auto name = j.find("name");
    f.name = name == j.end() ? model.meta.gender : name->get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw smpl::ModelError(where + " is not a weight formula (" + e.what() +
                           "); regenerate the model with caliper-modelgen");
  }
  if (const std::string problem = formula_problem(f); !problem.empty()) {
    throw smpl::ModelError(where + " has " + problem +
                           "; regenerate the model with caliper-modelgen");
  }
  return f;
}

void set_weight_formula(smpl::BodyModel& model, const WeightFormula& formula) {
  if (const std::string problem = formula_problem(formula); !problem.empty()) {
    throw std::invalid_argument("set_weight_formula: " + problem);
  }
  nlohmann::json j;
  j["name"] = formula.name;
  j["coefficient"] = formula.coefficient;
  j["intercept"] = formula.intercept;
  model.meta.extra[kWeightFormulaMetaKey] = j.dump();
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
