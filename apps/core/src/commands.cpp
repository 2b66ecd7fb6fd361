// The editor's text command language: one handler per command, found by name.
#include "app/commands.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>

#include "app/editor_core.hpp"

namespace caliper::app {

namespace {

/// One command line being run: the core, the words after the command name, and how to fail.
struct Line {
  EditorCore& core;
  const std::string& text;
  const std::string& name;
  std::istringstream& in;

  /// The next word ("" when there is none).
  std::string word() {
    std::string w;
    in >> w;
    return w;
  }
  bool fail(const std::string& why) const {
    core.post(Message::Level::Error, "command '" + text + "': " + why);
    return false;
  }
};

/// "on"/"1"/"true" or "off"/"0"/"false" into `out`; false (leaving `out`) for anything else.
bool parse_on_off(const std::string& s, bool& out) {
  if (s == "on" || s == "1" || s == "true") {
    out = true;
  } else if (s == "off" || s == "0" || s == "false") {
    out = false;
  } else {
    return false;
  }
  return true;
}

bool set_or_drag(Line& l) {
  std::string id;
  double v = 0;
  if (!(l.in >> id >> v)) return l.fail("expected: " + l.name + " <id> <value> [unit]");
  const std::string unit = l.word();
  double si = from_display(id, v, l.core.view().units);
  if (!unit.empty()) {
    auto s = to_si_with_suffix(id, v, unit);
    if (!s) return l.fail("unit '" + unit + "' does not fit " + id);
    si = *s;
  }
  if (l.name == "set") return l.core.set_value(id, si);
  l.core.begin_drag();
  const bool ok = l.core.drag_value(id, si);
  l.core.end_drag();
  return ok;
}

bool units(Line& l) {
  auto u = parse_unit_system(l.word());
  if (!u) return l.fail("units are metric or imperial");
  l.core.view().units = *u;
  return true;
}

bool regressor(Line& l) {
  auto c = parse_regressor_choice(l.word());
  if (!c) return l.fail("regressor is R2, R4, R5, R6 or noise-aware");
  l.core.set_regressor(*c);
  return true;
}

bool hierarchical(Line& l) {
  bool on = true;
  if (!parse_on_off(l.word(), on)) return l.fail("expected on or off");
  l.core.set_hierarchical(on);
  return true;
}

/// "arm-hanging on|off": the arm length is taken on the hanging arm or out sideways.
bool arm_hanging(Line& l) {
  bool on = true;
  if (!parse_on_off(l.word(), on)) return l.fail("expected on or off");
  return l.core.set_arm_taken_hanging(on);
}

bool level(Line& l) {
  int n = 0;
  if (!(l.in >> n)) return l.fail("expected a level 1..3");
  return l.core.set_level(n);
}

bool model(Line& l) {
  const std::string a = l.word();
  if (a.empty()) return l.fail("expected a model index or file");
  if (std::all_of(a.begin(), a.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return l.core.select_model(std::stoi(a));
  }
  return l.core.load_model_file(a);
}

/// A command taking one file name: `action` on it.
template <bool (EditorCore::*action)(const std::string&)>
bool with_file(Line& l) {
  const std::string file = l.word();
  return file.empty() ? l.fail("expected a file") : (l.core.*action)(file);
}

bool export_file(Line& l) {
  const std::string file = l.word();
  return file.empty() ? l.fail("expected a file") : l.core.export_mesh(file);
}

bool wireframe(Line& l) {
  return parse_on_off(l.word(), l.core.view().wireframe) || l.fail("expected on or off");
}

bool overlay(Line& l) {
  return parse_on_off(l.word(), l.core.view().overlay) || l.fail("expected on or off");
}

bool scale(Line& l) {
  const std::string a = l.word();
  if (a != "fixed" && a != "fit") return l.fail("scale is fixed or fit");
  l.core.view().fixed_scale = a == "fixed";
  return true;
}

bool colour(Line& l) {
  static const std::map<std::string, ColourMode> modes = {
      {"skin", ColourMode::Skin},
      {"plausibility", ColourMode::Plausibility},
      {"uncertainty", ColourMode::Uncertainty}};
  auto it = modes.find(l.word());
  if (it == modes.end()) return l.fail("colour is skin, plausibility or uncertainty");
  l.core.view().colour = it->second;
  return true;
}

bool compare(Line& l) {
  const std::string a = l.word();
  if (a == "pin") {
    const std::string label = l.word();
    l.core.pin_comparison(label.empty() ? "pinned" : label);
  } else if (a == "off") {
    l.core.view().compare = CompareMode::Off;
  } else if (a == "side" || a == "difference") {
    if (!l.core.comparison()) return l.fail("pin an avatar first (compare pin)");
    l.core.view().compare = a == "side" ? CompareMode::SideBySide : CompareMode::Difference;
  } else if (a == "clear") {
    l.core.clear_comparison();
  } else {
    return l.fail("compare pin|side|difference|off|clear");
  }
  return true;
}

using Handler = bool (*)(Line&);

const std::map<std::string, Handler>& handlers() {
  static const std::map<std::string, Handler> table = {
      {"set", set_or_drag},
      {"drag", set_or_drag},
      {"units", units},
      {"regressor", regressor},
      {"hierarchical", hierarchical},
      {"level", level},
      {"arm-hanging", arm_hanging},
      {"sex", [](Line& l) { return l.core.select_sex(l.word()); }},
      {"model", model},
      {"undo", [](Line& l) { return l.core.undo() || l.fail("nothing to undo"); }},
      {"redo", [](Line& l) { return l.core.redo() || l.fail("nothing to redo"); }},
      {"reset",
       [](Line& l) {
         l.core.reset();
         return true;
       }},
      {"open-profile", with_file<&EditorCore::open_profile>},
      {"save-profile", with_file<&EditorCore::save_profile>},
      {"open-session", with_file<&EditorCore::open_session>},
      {"export", export_file},
      {"wireframe", wireframe},
      {"overlay", overlay},
      {"scale", scale},
      {"colour", colour},
      {"color", colour},
      {"compare", compare},
  };
  return table;
}

}  // namespace

bool run_command(EditorCore& core, const std::string& line) {
  std::istringstream in(line);
  std::string name;
  if (!(in >> name) || name[0] == '#') return true;  // blank or comment
  Line l{core, line, name, in};
  auto it = handlers().find(name);
  if (it == handlers().end()) return l.fail("unknown command");
  return it->second(l);
}

std::vector<std::string> command_names() {
  std::vector<std::string> names;
  for (const auto& [name, handler] : handlers()) names.push_back(name);
  return names;
}

}  // namespace caliper::app
