// The editor's document and the rules that follow from it alone (regressor choices, the
// hierarchy's inputs, descriptions for messages).
#include "app/document.hpp"

#include <algorithm>
#include <cstdio>
#include <map>

#include "caliper/regressor.hpp"
#include "smpl/text.hpp"

namespace caliper::app {

namespace {
constexpr RegressorChoice kLinearChoices[] = {RegressorChoice::R2, RegressorChoice::R4,
                                              RegressorChoice::R5, RegressorChoice::R6};

/// The linear regressor a choice names (caliper::RegressorKind); nullopt for the noise-aware one.
std::optional<RegressorKind> linear_kind(RegressorChoice choice) {
  switch (choice) {
    case RegressorChoice::R2:
      return RegressorKind::R2;
    case RegressorChoice::R4:
      return RegressorKind::R4;
    case RegressorChoice::R5:
      return RegressorKind::R5;
    case RegressorChoice::R6:
      return RegressorKind::R6;
    case RegressorChoice::NoiseAware:
      break;
  }
  return std::nullopt;
}
}  // namespace

std::string to_string(RegressorChoice choice) {
  const std::optional<RegressorKind> kind = linear_kind(choice);
  return kind ? caliper::to_string(*kind) : "noise-aware";
}

std::optional<RegressorChoice> parse_regressor_choice(const std::string& text) {
  const std::string t = smpl::to_lower(text);
  if (t == "noise-aware" || t == "noise_aware" || t == "na") return RegressorChoice::NoiseAware;
  const std::optional<RegressorKind> kind = parse_regressor_kind(text);  // R2..R6, any case
  for (RegressorChoice choice : kLinearChoices) {
    if (kind && linear_kind(choice) == kind) return choice;
  }
  return std::nullopt;
}

const std::vector<std::string>& choice_inputs(RegressorChoice choice) {
  // The noise-aware regressor takes R6's inputs.
  return regressor_inputs(linear_kind(choice).value_or(RegressorKind::R6));
}

namespace {
/// The regressor of hierarchy level 1..3 (paper: height+weight, + inseam+arm span, + arm
/// length+hip width).
RegressorChoice level_choice(int level) {
  return level <= 1 ? RegressorChoice::R2 : level == 2 ? RegressorChoice::R4 : RegressorChoice::R6;
}
}  // namespace

const std::vector<std::string>& level_inputs(int level) {
  return choice_inputs(level_choice(level));
}

RegressorChoice active_regressor(const Document& doc) {
  if (!doc.hierarchical || doc.regressor == RegressorChoice::NoiseAware) return doc.regressor;
  return level_choice(doc.level);
}

const std::vector<std::string>& editable_inputs(const Document& doc) {
  return doc.hierarchical ? level_inputs(doc.level) : choice_inputs(doc.regressor);
}

void start_from_avatar(Document& doc, const std::vector<std::string>& ids,
                       const std::vector<std::string>& kept, const MeasurementMap& achieved) {
  for (const std::string& id : ids) {
    if (std::find(kept.begin(), kept.end(), id) != kept.end()) continue;
    auto it = achieved.find(id);
    if (it != achieved.end()) doc.values[id] = it->second;
  }
}

std::string measurement_label(const std::string& id) {
  return measurement_name(id);
}

std::string input_label(const Document& doc, const std::string& id) {
  if (id == "arm_length" && doc.arm_taken_hanging) return "Arm length (hanging)";
  return measurement_label(id);
}

std::string measurement_hint(const std::string& id) {
  static const std::map<std::string, std::string> kHints = {
      {"height", "Standing straight, barefoot: floor to the top of the head."},
      {"weight", "Body weight, lightly dressed."},
      {"arm_span_fingertips",
       "Arms stretched out sideways at shoulder height: fingertip to fingertip."},
      {"inseam_height", "Standing: floor to the crotch."},
      {"hip_width", "The hips' widest breadth, at the greater trochanters, seen from the front."},
      {"arm_length",
       "Shoulder tip (acromion) to the wrist with the arm stretched out sideways, as the\n"
       "VR protocol takes it. A tape on the relaxed hanging arm reads about 7 cm more:\n"
       "tick 'taken hanging' to type such a value (the model's own map turns it into this\n"
       "one, as `caliper create --arm-length-hanging` does)."},
  };
  const auto it = kHints.find(id);
  return it == kHints.end() ? std::string() : it->second;
}

std::string describe_regressor(RegressorChoice choice) {
  std::string s = to_string(choice) + ": ";
  if (choice == RegressorChoice::NoiseAware) s = "noise-aware: ";
  bool first = true;
  for (const std::string& id : choice_inputs(choice)) {
    s += (first ? "" : ", ") + measurement_label(id);
    first = false;
  }
  if (choice == RegressorChoice::NoiseAware)
    s += " (weighs each input by its measuring noise; shows the shape's uncertainty)";
  return s;
}

std::string describe_change(const Document& from, const Document& to, UnitSystem units) {
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : "; ") + part; };
  if (from.regressor != to.regressor || from.hierarchical != to.hierarchical ||
      from.level != to.level) {
    if (to.hierarchical && to.regressor != RegressorChoice::NoiseAware)
      add("hierarchical level " + std::to_string(to.level));
    else
      add("regressor " + to_string(to.regressor));
  }
  if (from.arm_taken_hanging != to.arm_taken_hanging)
    add(to.arm_taken_hanging ? "arm length taken hanging" : "arm length out sideways");
  for (const auto& [id, v] : to.values) {
    auto it = from.values.find(id);
    if (it != from.values.end() && it->second == v) continue;
    char buf[128];
    const double shown = to_display(id, v, units);
    if (it != from.values.end()) {
      std::snprintf(buf, sizeof buf, "%.1f -> %.1f %s", to_display(id, it->second, units), shown,
                    unit_label(id, units).c_str());
    } else {
      std::snprintf(buf, sizeof buf, "%.1f %s", shown, unit_label(id, units).c_str());
    }
    add(input_label(to, id) + " " + buf);
  }
  return s.empty() ? "no visible change" : s;
}

}  // namespace caliper::app
