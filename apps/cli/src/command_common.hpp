/// \file command_common.hpp
/// Pieces shared by `caliper create` and `caliper batch`: the measurement options, input
/// validation with clear messages, and one avatar from one set of inputs.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "caliper/avatar.hpp"
#include "caliper/mapping.hpp"
#include "cli_support.hpp"
#include "model_source.hpp"

namespace caliper::cli {

/// --height, --weight, --arm-span, --inseam, --hip-width, --arm-length (+ their ids).
const std::vector<OptionSpec>& measurement_options();

/// Reads the measurement options into id -> SI value (UsageError for a missing or unknown unit).
MeasurementMap read_measurement_options(const ParsedArgs& args);

/// Runs validate_measurements(): Error messages throw ImplausibleInput (unless `force`, then
/// they become warnings); returns the warnings as plain lines.
std::vector<std::string> check_inputs(const MeasurementMap& inputs, bool force);

/// Throws UsageError when `regressor` ("R2".."R6") needs an input that is not in `inputs`,
/// naming the missing options.
void require_inputs(const std::string& regressor, const MeasurementMap& inputs);

/// One avatar: the regressor `regressor` ("R2".."R6" or "noise-aware") of `bundle` on `inputs`.
/// `exact_inputs` (plain regressors): refine the betas so that every input, weight included, is
/// reproduced exactly (libcaliper's refine_to_inputs); off = the paper's linear prediction.
/// `check_model` false: the caller has already checked the regressor against bundle.model
/// (check_regressors_once), so the model fingerprint is not recomputed for this avatar.
/// `prior` (noise-aware only): the population the person comes from (population_prior()).
Avatar make_avatar(const ModelBundle& bundle, const std::string& regressor,
                   const MeasurementMap& inputs, const MeasurementMapping* mapping,
                   bool circumferences, bool exact_inputs = false, bool check_model = true,
                   const ShapePrior* prior = nullptr);

/// Loads a mapping: a .json written by MeasurementMapping::save, or a .csv of paired values
/// (fitted on the fly). Errors become RuntimeError naming the file.
MeasurementMapping load_mapping(const std::string& path);

/// Option name of a measurement id ("arm_span_fingertips" -> "--arm-span").
std::string option_of(const std::string& id);

}  // namespace caliper::cli
