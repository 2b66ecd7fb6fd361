/// \file inputs.hpp
/// Measurement inputs as people type them, shared by the `caliper` command and the Python module:
/// lengths and masses with their unit stated ("168cm", "1.68m", "66in", "5ft6in", "62kg",
/// "137lb"), regressor names, and which regressor a set of inputs gets by default (docs/cli.md).
/// 1 in = 2.54 cm, 1 ft = 12 in, 1 lb = 0.45359237 kg exactly (international yard and pound).
#pragma once

#include <optional>
#include <string>

#include "caliper/measurements.hpp"

namespace caliper {

/// A length with its unit stated: mm, cm, m, in, ft, and feet-inches ("5ft6in", "5'6\""); a
/// decimal comma between digits ("1,68m") is read as a decimal point.
/// Returns metres. Throws InvalidInputError naming `what` (e.g. "--height") when the unit is
/// missing or unknown, or the number is not finite.
double parse_length(const std::string& text, const std::string& what);
/// A mass with its unit stated: kg, g, lb/lbs. Returns kilograms. Throws InvalidInputError.
double parse_mass(const std::string& text, const std::string& what);
/// Metres (for a length) or kilograms per unit: "mm", "cm", "m", "in", "ft", "kg", "g", "lb"
/// (case-insensitive). Returns nullopt for an unknown unit.
std::optional<double> unit_scale(const std::string& unit);

/// Which regressor takes `inputs` by default: exactly the inputs of R2, R4 or R5 -> that
/// regressor ("R2", "R4", "R5"); all six or any other subset -> "noise-aware" (R6 reproduces
/// every input but amplifies measurement noise into implausible shapes, paper Fig. 9).
/// Keys that are not regressor inputs are ignored.
std::string default_regressor(const MeasurementMap& inputs);

/// Normalises a regressor name to "R2", "R4", "R5", "R6" or "noise-aware" (also accepted:
/// "r5", "noise_aware", "noiseaware", "na", "bayes"). Throws InvalidInputError naming `what`
/// (e.g. "--regressor") and the text.
std::string normalise_regressor_name(const std::string& text,
                                     const std::string& what = "regressor");

}  // namespace caliper
