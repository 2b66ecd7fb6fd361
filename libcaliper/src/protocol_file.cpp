// Measuring protocol file (Pujades et al., The Virtual Caliper, TVCG 2019, sec. 3.1).
#include "caliper/protocol_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "caliper/json.hpp"
#include "caliper/measurements.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/text.hpp"

namespace caliper {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& where, const std::string& what) {
  throw ProtocolError(name + ": " + where + ": " + what);
}

std::string str_or(const Json& j, const char* key, const std::string& fallback) {
  const Json* v = j.find(key);
  return v && v->is_string() ? v->as_string() : fallback;
}

double positive_number(const Json& j, const char* key, double fallback, const std::string& name,
                       const std::string& where) {
  const Json* v = j.find(key);
  if (!v) return fallback;
  if (!v->is_number() || !std::isfinite(v->as_number()) || v->as_number() <= 0.0)
    fail(name, where, std::string("\"") + key + "\" must be a positive number");
  return v->as_number();
}

constexpr std::array<const char*, 4> kStepKindNames = {"height", "distance", "typed_number",
                                                       "typed_choice"};
static_assert(kStepKindNames.size() == static_cast<std::size_t>(StepKind::TypedChoice) + 1);

StepKind parse_kind(const std::string& s, const std::string& name, const std::string& where) {
  if (const auto kind = smpl::enum_from_name<StepKind>(s, kStepKindNames)) return *kind;
  fail(name, where,
       "unknown kind \"" + s + "\" (known: height, distance, typed_number, typed_choice)");
}

}  // namespace

const char* step_kind_name(StepKind kind) {
  return smpl::enum_name(kind, kStepKindNames);
}

int Protocol::find_step(const std::string& id) const {
  for (size_t i = 0; i < steps.size(); ++i)
    if (steps[i].id == id) return static_cast<int>(i);
  return -1;
}

Protocol parse_protocol(const std::string& text, const std::string& name) {
  Json j;
  try {
    j = parse_json(text);
  } catch (const JsonError& e) {
    throw ProtocolError(name + ": not valid JSON (line " + std::to_string(e.line) + ", column " +
                        std::to_string(e.column) + "): " + e.what());
  }
  if (!j.is_object() || str_or(j, "format", "") != "caliper-protocol")
    fail(name, "top level",
         "not a protocol file (expected {\"format\": \"caliper-protocol\", ...})");
  const Json* version = j.find("version");
  if (!version || !version->is_number() || version->as_number() != 1.0)
    fail(name, "\"version\"", "must be 1 (this build reads version 1)");
  Protocol p;
  p.name = str_or(j, "name", "");
  p.path = name;
  p.hold_seconds = positive_number(j, "hold_seconds", p.hold_seconds, name, "top level");
  p.max_jitter_m = positive_number(j, "max_jitter_m", p.max_jitter_m, name, "top level");
  p.isak_threshold = positive_number(j, "isak_threshold", p.isak_threshold, name, "top level");

  const Json* floor = j.find("floor");
  if (!floor || !floor->is_object())
    fail(name, "\"floor\"", "the floor calibration section is missing");
  p.floor.instruction = str_or(*floor, "instruction", "");
  p.floor.max_tilt_deg =
      positive_number(*floor, "max_tilt_deg", p.floor.max_tilt_deg, name, "floor");
  p.floor.max_residual_m =
      positive_number(*floor, "max_residual_m", p.floor.max_residual_m, name, "floor");
  const Json* targets = floor->find("targets");
  if (!targets || !targets->is_array() || targets->size() < 3)
    fail(name, "floor.targets", "needs at least 3 [x, z] targets (the paper uses 5)");
  for (size_t i = 0; i < targets->size(); ++i) {
    const Json& t = (*targets)[i];
    if (!t.is_array() || t.size() != 2 || !t[0].is_number() || !t[1].is_number())
      fail(name, "floor.targets[" + std::to_string(i) + "]", "must be [x, z] in metres");
    p.floor.targets.emplace_back(t[0].as_number(), t[1].as_number());
  }

  const Json* steps = j.find("steps");
  if (!steps || !steps->is_array() || steps->size() == 0)
    fail(name, "\"steps\"", "needs at least one step");
  const std::vector<std::string>& known = landmark_names();
  std::set<std::string> ids;
  for (size_t i = 0; i < steps->size(); ++i) {
    const Json& sj = (*steps)[i];
    std::string where = "steps[" + std::to_string(i) + "]";
    if (!sj.is_object()) fail(name, where, "must be an object");
    ProtocolStep s;
    s.id = str_or(sj, "id", "");
    if (s.id.empty()) fail(name, where, "has no \"id\"");
    where += " (\"" + s.id + "\")";
    if (!ids.insert(s.id).second) fail(name, where, "duplicate step id");
    s.measurement = str_or(sj, "measurement", s.id);
    s.kind = parse_kind(str_or(sj, "kind", ""), name, where);
    s.title = str_or(sj, "title", s.id);
    s.instruction = str_or(sj, "instruction", "");
    s.demo_pose = str_or(sj, "demo_pose", "arms_down");
    s.video = str_or(sj, "video", "");
    s.unit =
        str_or(sj, "unit", (s.kind == StepKind::Height || s.kind == StepKind::Distance) ? "m" : "");
    if (const Json* o = sj.find("optional"); o && o->is_bool()) s.optional = o->as_bool();
    if (const Json* tips = sj.find("tips")) {
      if (!tips->is_array()) fail(name, where, "\"tips\" must be an array of \"left\"/\"right\"");
      for (const Json& t : tips->as_array()) {
        if (!t.is_string() || (t.as_string() != "left" && t.as_string() != "right"))
          fail(name, where, "\"tips\" entries must be \"left\" or \"right\"");
        s.tips.push_back(t.as_string() == "left" ? Tip::Left : Tip::Right);
      }
    }
    if (const Json* lms = sj.find("landmarks")) {
      if (!lms->is_array()) fail(name, where, "\"landmarks\" must be an array of names");
      for (const Json& l : lms->as_array()) {
        if (!l.is_string()) fail(name, where, "\"landmarks\" entries must be strings");
        if (std::find(known.begin(), known.end(), l.as_string()) == known.end())
          fail(name, where,
               "unknown landmark \"" + l.as_string() + "\" (see docs/measurements.md)");
        s.landmarks.push_back(l.as_string());
      }
    }
    if (const Json* ch = sj.find("choices")) {
      if (!ch->is_array()) fail(name, where, "\"choices\" must be an array of strings");
      for (const Json& c : ch->as_array()) {
        if (!c.is_string()) fail(name, where, "\"choices\" entries must be strings");
        s.choices.push_back(c.as_string());
      }
    }
    const size_t need = s.kind == StepKind::Height ? 1 : s.kind == StepKind::Distance ? 2 : 0;
    if (s.tips.size() != need || s.landmarks.size() != need)
      fail(name, where,
           std::string("a \"") + step_kind_name(s.kind) + "\" step needs " + std::to_string(need) +
               " tips and " + std::to_string(need) + " landmarks, found " +
               std::to_string(s.tips.size()) + " and " + std::to_string(s.landmarks.size()));
    if (s.kind == StepKind::TypedChoice && s.choices.empty())
      fail(name, where, "a typed_choice step needs \"choices\"");
    p.steps.push_back(std::move(s));
  }
  return p;
}

Protocol read_protocol(const std::string& path) {
  const std::optional<std::string> text = smpl::read_file(path);
  if (!text) throw ProtocolError(path + ": cannot open the protocol file (does it exist?)");
  return parse_protocol(*text, path);
}

namespace embedded {
extern const char* const kDefaultProtocolJson;  // generated by caliper_embed_files (CMakeLists)
}

const char* default_protocol_json() {
  return embedded::kDefaultProtocolJson;
}

Protocol default_protocol() {
  Protocol p = parse_protocol(default_protocol_json(),
                              "the built-in protocol (assets/protocol/virtual-caliper.json)");
  p.path.clear();
  return p;
}

}  // namespace caliper
