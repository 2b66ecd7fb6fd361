#include "app/units.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "caliper/measurements.hpp"
#include "smpl/text.hpp"

namespace caliper::app {

namespace {
constexpr double kCubicMetresPerCubicFoot = 0.028316846592;  // 0.3048^3
}  // namespace

std::string to_string(UnitSystem units) {
  return units == UnitSystem::Metric ? "metric" : "imperial";
}

std::optional<UnitSystem> parse_unit_system(const std::string& text) {
  const std::string t = smpl::to_lower(text);
  if (t == "metric" || t == "cm" || t == "si") return UnitSystem::Metric;
  if (t == "imperial" || t == "in" || t == "us") return UnitSystem::Imperial;
  return std::nullopt;
}

Quantity quantity_of(const std::string& id) {
  if (id == "weight") return Quantity::Mass;
  if (id == "volume") return Quantity::Volume;
  return Quantity::Length;
}

double to_display(const std::string& id, double value_si, UnitSystem units) {
  switch (quantity_of(id)) {
    case Quantity::Mass:
      return units == UnitSystem::Metric ? value_si : value_si / kKilogramsPerPound;
    case Quantity::Volume:
      return units == UnitSystem::Metric ? value_si * 1000.0 : value_si / kCubicMetresPerCubicFoot;
    case Quantity::Length:
      break;
  }
  return units == UnitSystem::Metric ? value_si * 100.0 : value_si / kMetresPerInch;
}

double from_display(const std::string& id, double shown, UnitSystem units) {
  switch (quantity_of(id)) {
    case Quantity::Mass:
      return units == UnitSystem::Metric ? shown : shown * kKilogramsPerPound;
    case Quantity::Volume:
      return units == UnitSystem::Metric ? shown / 1000.0 : shown * kCubicMetresPerCubicFoot;
    case Quantity::Length:
      break;
  }
  return units == UnitSystem::Metric ? shown / 100.0 : shown * kMetresPerInch;
}

std::string unit_label(const std::string& id, UnitSystem units) {
  switch (quantity_of(id)) {
    case Quantity::Mass:
      return units == UnitSystem::Metric ? "kg" : "lb";
    case Quantity::Volume:
      return units == UnitSystem::Metric ? "L" : "ft3";
    case Quantity::Length:
      break;
  }
  return units == UnitSystem::Metric ? "cm" : "in";
}

std::optional<double> to_si_with_suffix(const std::string& id, double value,
                                        const std::string& suffix) {
  const std::string s = smpl::to_lower(suffix);
  const Quantity q = quantity_of(id);
  if (q == Quantity::Length) {
    if (s == "cm") return value / 100.0;
    if (s == "mm") return value / 1000.0;
    if (s == "m") return value;
    if (s == "in" || s == "inch" || s == "inches") return value * kMetresPerInch;
  } else if (q == Quantity::Mass) {
    if (s == "kg") return value;
    if (s == "lb" || s == "lbs") return value * kKilogramsPerPound;
  }
  return std::nullopt;
}

std::string measurement_name(const std::string& id) {
  if (id == "weight") return "Weight";
  if (id == "volume") return "Volume";
  for (const MeasurementDef& d : paper_measurements()) {
    if (d.id == id) return d.label;
  }
  return id;
}

std::string value_text(const std::string& id, double value_si, UnitSystem units) {
  return smpl::format_fixed(to_display(id, value_si, units), 1) + " " + unit_label(id, units);
}

std::string measurement_text(const std::string& id, double value_si, UnitSystem units) {
  return measurement_name(id) + " " + value_text(id, value_si, units);
}

}  // namespace caliper::app
