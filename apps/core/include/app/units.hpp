/// \file units.hpp
/// Display units of the editor: metric (cm, kg) or imperial (inches, pounds). Values inside the
/// app core are SI (metres, kilograms, cubic metres); conversion happens only at the UI edge.
/// 1 in = 2.54 cm and 1 lb = 0.45359237 kg exactly (international yard and pound, 1959).
#pragma once

#include <optional>
#include <string>

namespace caliper::app {

enum class UnitSystem { Metric, Imperial };

constexpr double kMetresPerInch = 0.0254;
constexpr double kKilogramsPerPound = 0.45359237;

/// "metric" / "imperial".
std::string to_string(UnitSystem units);
/// Parses "metric", "cm", "imperial", "in" (case-insensitive); std::nullopt otherwise.
std::optional<UnitSystem> parse_unit_system(const std::string& text);

/// What kind of quantity a measurement id is: "weight" is a mass, "volume" a volume, every
/// other id (heights, widths, lengths, circumferences) a length.
enum class Quantity { Length, Mass, Volume };
Quantity quantity_of(const std::string& id);

/// SI value -> displayed value (length: cm or in; mass: kg or lb; volume: litres or cubic feet).
double to_display(const std::string& id, double value_si, UnitSystem units);
/// Displayed value -> SI value (inverse of to_display).
double from_display(const std::string& id, double shown, UnitSystem units);
/// "cm", "in", "kg", "lb", "L", "ft3".
std::string unit_label(const std::string& id, UnitSystem units);
/// The value as the editor shows it: `value_si` in `units` with one decimal, then the unit
/// ("191.8 cm", "90.3 kg", "70.9 in").
std::string value_text(const std::string& id, double value_si, UnitSystem units);
/// The name people read for a measurement id: the paper measurement's label ("Arm span
/// (fingertips)", "Overall height"), "Weight", "Volume"; any other id is returned as it is.
std::string measurement_name(const std::string& id);
/// The measurement as the editor shows it: name, value in `units` with one decimal, unit
/// ("Arm span (fingertips) 191.8 cm", "Weight 90.3 kg").
std::string measurement_text(const std::string& id, double value_si, UnitSystem units);
/// Unit of a typed suffix: "cm", "mm", "m", "in", "kg", "lb"; converts `value` in that unit to
/// SI. Returns std::nullopt for an unknown suffix or one that does not fit the id's quantity.
std::optional<double> to_si_with_suffix(const std::string& id, double value,
                                        const std::string& suffix);

}  // namespace caliper::app
