#include "caliper/inputs.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>
#include <vector>

#include "caliper/errors.hpp"
#include "caliper/regressor.hpp"
#include "smpl/text.hpp"

namespace caliper {

std::optional<double> unit_scale(const std::string& unit_in) {
  const std::string u = smpl::to_lower(unit_in);
  if (u == "mm") return 0.001;
  if (u == "cm") return 0.01;
  if (u == "m") return 1.0;
  if (u == "in" || u == "inch" || u == "inches" || u == "\"") return 0.0254;
  if (u == "ft" || u == "feet" || u == "foot" || u == "'") return 0.3048;
  if (u == "kg") return 1.0;
  if (u == "g") return 0.001;
  if (u == "lb" || u == "lbs") return 0.45359237;
  return std::nullopt;
}

namespace {

/// Splits "168.5cm" into 168.5 and "cm"; returns false when there is no leading number.
bool split_number_unit(const std::string& text, size_t& pos, double& value, std::string& unit) {
  while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
  const char* begin = text.c_str() + pos;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(begin, &end);
  if (end == begin) return false;
  // strtod accepts "nan", "inf" and hex; the caller checks finiteness.
  pos += static_cast<size_t>(end - begin);
  while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
  const size_t start = pos;
  while (pos < text.size() && (std::isalpha(static_cast<unsigned char>(text[pos])) ||
                               text[pos] == '\'' || text[pos] == '"')) {
    ++pos;
    if (text[pos - 1] == '\'' || text[pos - 1] == '"') break;  // one-character units
  }
  unit = text.substr(start, pos - start);
  return true;
}

double parse_with_units(const std::string& typed, const std::string& what, bool is_length) {
  const std::string examples =
      is_length ? "e.g. 168cm, 1.68m, 1680mm, 66in or 5ft6in" : "e.g. 62kg or 137lb";
  // A decimal comma between digits ("1,68m", "62,5 kg") is a decimal point.
  std::string text = typed;
  for (size_t i = 1; i + 1 < text.size(); ++i) {
    if (text[i] == ',' && std::isdigit(static_cast<unsigned char>(text[i - 1])) &&
        std::isdigit(static_cast<unsigned char>(text[i + 1])))
      text[i] = '.';
  }
  double total = 0.0;
  size_t pos = 0;
  int parts = 0;
  std::string last_unit;
  while (true) {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    if (pos >= text.size()) break;
    double v = 0.0;
    std::string unit;
    if (!split_number_unit(text, pos, v, unit)) {
      throw InvalidInputError(what + " '" + text + "': not a number with a unit (" + examples +
                              ")");
    }
    if (!std::isfinite(v)) throw InvalidInputError(what + " '" + text + "': not a finite number");
    if (unit.empty()) {
      throw InvalidInputError(what + " '" + text + "': no unit given; state it, " + examples);
    }
    const std::string u = smpl::to_lower(unit);  // units are case-insensitive: "5FT6IN" is "5ft6in"
    const auto scale = unit_scale(u);
    const bool unit_is_length = scale && u != "kg" && u != "g" && u != "lb" && u != "lbs";
    if (!scale || unit_is_length != is_length) {
      throw InvalidInputError(what + " '" + text + "': unknown unit '" + unit + "' (" + examples +
                              ")");
    }
    const auto is_feet = [](const std::string& x) {
      return x == "ft" || x == "'" || x == "feet" || x == "foot";
    };
    const bool is_inches = u == "in" || u == "inch" || u == "inches" || u == "\"";
    if (parts >= 2) {
      throw InvalidInputError(what + " '" + text + "': too many parts (" + examples + ")");
    }
    // Only feet followed by inches may be combined ("5ft6in", "5'6\""), both not negative and
    // the inches under 12: "5ft60cm" and "6ft-6in" are refused, not guessed.
    if (parts == 1) {
      if (!is_feet(last_unit) || !is_inches) {
        throw InvalidInputError(what + " '" + text +
                                "': only feet followed by inches may be combined (" + examples +
                                ")");
      }
      if (total < 0.0 || v < 0.0 || v >= 12.0) {
        throw InvalidInputError(what + " '" + text +
                                "': in feet and inches, both are positive and the inches under "
                                "12 (" +
                                examples + ")");
      }
    }
    total += v * *scale;
    last_unit = u;
    ++parts;
  }
  if (parts == 0) throw InvalidInputError(what + ": empty value (" + examples + ")");
  return total;
}

}  // namespace

double parse_length(const std::string& text, const std::string& what) {
  return parse_with_units(text, what, true);
}

double parse_mass(const std::string& text, const std::string& what) {
  return parse_with_units(text, what, false);
}

std::string default_regressor(const MeasurementMap& inputs) {
  std::set<std::string> given;
  for (const auto& [id, v] : inputs) {
    (void)v;
    for (const auto& r6 : regressor_inputs(RegressorKind::R6))
      if (r6 == id) given.insert(id);
  }
  for (RegressorKind k : {RegressorKind::R2, RegressorKind::R4, RegressorKind::R5}) {
    const auto& need = regressor_inputs(k);
    if (given == std::set<std::string>(need.begin(), need.end())) return to_string(k);
  }
  return "noise-aware";
}

std::string normalise_regressor_name(const std::string& text, const std::string& what) {
  if (auto k = parse_regressor_kind(text)) return to_string(*k);
  const std::string t = smpl::to_lower(text);
  if (t == "noise-aware" || t == "noise_aware" || t == "noiseaware" || t == "na" || t == "bayes")
    return "noise-aware";
  throw InvalidInputError(what + " " + text + ": expected R2, R4, R5, R6 or noise-aware");
}

}  // namespace caliper
