/// \file population.hpp
/// A survey's population in a model's shape space: the mean and covariance of the betas of the
/// survey's registered subjects (issue 11). A model's betas ~ N(0, I) stand for one population
/// (the v2 models: the general adult population); the subjects of a survey (ANSUR II's soldiers)
/// are another, and sampling them needs their own moments. The generator writes them into the
/// model file's metadata (BodyModel::meta.extra["population.<key>"], JSON: survey, subjects, mean,
/// cov), the validation samples from them (caliper-modelgen --validate, tests/modelgen
/// Realism), and the noise-aware regressor takes one as its prior to make the avatar of a person
/// of that population (population_prior(); `caliper create --population`, `caliper evaluate
/// ansur`). The open models' "nhanes" is the general adult population their betas stand for
/// (N(0, I)), not the NHANES subjects' own moments, which are singular (registered from four
/// measurements).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/regressor.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// The betas of one survey's subjects in a model's shape space.
struct SurveyPopulation {
  std::string survey;    ///< e.g. "ANSUR II"
  int subjects = 0;      ///< how many registered subjects the moments are of
  Eigen::VectorXd mean;  ///< B
  Eigen::MatrixXd cov;   ///< B x B, symmetric positive semi-definite
};

/// The metadata key of population `key` ("ansur2", "nhanes"): "population.<key>".
std::string population_meta_key(const std::string& key);

/// Stores `p` in `model`'s metadata under `key` (JSON; doubles written to round-trip exactly).
/// Throws std::invalid_argument when the sizes are not the model's betas.
void set_survey_population(smpl::BodyModel& model, const std::string& key,
                           const SurveyPopulation& p);

/// The population `key` of `model`, nullopt when the model has none. Throws std::runtime_error
/// naming the key when the entry is not valid JSON of the model's betas (sizes, finite numbers,
/// a symmetric covariance with no negative variance).
std::optional<SurveyPopulation> survey_population(const smpl::BodyModel& model,
                                                  const std::string& key);

/// The populations `model` carries (the keys of its "population.<key>" metadata, sorted).
std::vector<std::string> population_keys(const smpl::BodyModel& model);

/// Population `key` of `model` as a shape prior over all the model's betas (a regressor uses its
/// leading block; ShapePrior). Throws InvalidInputError naming the populations the model carries
/// when it has no population `key`; std::runtime_error for a malformed entry
/// (survey_population()).
ShapePrior population_prior(const smpl::BodyModel& model, const std::string& key);

/// A matrix L with L L' = cov (symmetric square root of the positive part: works for a
/// semi-definite covariance), for drawing betas = mean + L n, n ~ N(0, I).
Eigen::MatrixXd sampling_factor(const Eigen::MatrixXd& cov);

}  // namespace caliper
