/// \file report.hpp
/// Human-readable and JSON reports of the `caliper` command: measurement tables (input vs
/// achieved, in cm / kg / litres for people, SI units in JSON), betas and plausibility.
#pragma once

#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/json.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"

namespace caliper::cli {

/// Every id a report lists, in order: height, weight, the paper's 13 (without height), the four
/// circumferences, volume.
const std::vector<std::string>& report_ids();

/// Human-readable label of an id ("Arm span (fingertips)", "Chest circumference", "Volume").
std::string label_of(const std::string& id);

/// `v` with `decimals` decimals ("%.*f") while |v| < 1e9; larger values in exponent notation
/// with 4 significant digits ("5.000e+31"), so that an absurd value never prints as hundreds
/// of digits or is cut short; "nan", "inf", "-inf" for the others.
std::string format_number(double v, int decimals);

/// A value for people: "168.0 cm", "62.0 kg", "60.2 L" (volume). `decimals` for the number.
std::string format_value(const std::string& id, double value_si, int decimals = 1);
/// A signed difference in the same display unit: "+0.0 cm".
std::string format_difference(const std::string& id, double difference_si, int decimals = 1);

/// The table "measurement | input | achieved | difference" for `ids` (inputs may be empty).
/// `imperial`: lengths in inches and weight in pounds, each with the metric value beside it
/// (for inputs given in imperial units).
std::string measurement_table(const MeasurementMap& input, const MeasurementMap& achieved,
                              bool imperial = false);
/// True when a typed value uses imperial units ("66in", "5ft6in", "5'6\"", "137lb").
bool is_imperial_text(const std::string& text);

/// "0.12 -1.05 ..." with 3 decimals.
std::string format_betas(const Eigen::VectorXd& betas);

/// Plausibility in one or two lines of plain words.
std::string format_plausibility(const Plausibility& p);

/// JSON of a measurement map (SI units: metres, kg, m^3), in report_ids() order, then others.
Json measurements_json(const MeasurementMap& values);
/// JSON of a plausibility result.
Json plausibility_json(const Plausibility& p);
/// JSON array of betas.
Json betas_json(const Eigen::VectorXd& betas);

/// Display unit and factor from SI for an id: ("cm", 100), ("kg", 1), ("L", 1000).
std::pair<std::string, double> display_unit(const std::string& id);

}  // namespace caliper::cli
