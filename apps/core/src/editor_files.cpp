// The editor's files: measurement profiles, VR session measurements, export metadata.
#include "app/editor_files.hpp"

#include <algorithm>
#include <cmath>

#include "caliper/errors.hpp"
#include "caliper/journal.hpp"
#include "smpl/text.hpp"

namespace caliper::app {

// ---------------------------------------------------------------------------------------------
// Measurement profiles
Json profile_json(const Document& doc, UnitSystem units, const ModelEntry* model,
                  const Eigen::VectorXd& betas) {
  Json j = format_header("caliper-profile");
  j.set("units", to_string(units));
  if (model != nullptr) {
    j.set("model", model->label);
    j.set("sex", model->model->meta.gender);
  }
  j.set("regressor", to_string(doc.regressor));
  j.set("hierarchical", doc.hierarchical);
  j.set("level", doc.level);
  // Only when true: absent means out sideways, as in the profiles written before the field.
  // Such a profile is version 2, so that an editor older than the field refuses it instead of
  // taking the hanging arm length for one out sideways (an arm some 7 cm too long).
  if (doc.arm_taken_hanging) {
    j.set("version", 2);
    j.set("arm_taken_hanging", true);
  }
  Json values = Json::object();
  for (const std::string& id : editable_inputs(doc)) {
    auto it = doc.values.find(id);
    if (it != doc.values.end()) values.set(id, it->second);
  }
  j.set("measurements", values);
  j.set("betas", Json(std::vector<double>(betas.data(), betas.data() + betas.size())));
  return j;
}

namespace {
/// The profile's measurements, each within its plausible range.
MeasurementMap profile_measurements(const Json& values) {
  MeasurementMap read;
  for (const auto& [id, v] : values.as_object()) {
    const double x = v.as_number();
    const MeasurementRange r = measurement_range(id);
    if (!std::isfinite(x) || x < r.error_min || x > r.error_max) {
      throw InvalidInputError(id + " = " + std::to_string(x) + " (SI units) is out of range");
    }
    read[id] = x;
  }
  return read;
}
}  // namespace

Profile read_profile(const std::string& path, const Document& base) {
  const Json j = read_json_file(path);
  if (!j.is_object() || !j.contains("format") || j.at("format").as_string() != "caliper-profile") {
    throw InvalidInputError("not a caliper profile (expected \"format\": \"caliper-profile\")");
  }
  const int version = j.at("version").as_int();
  if (version != 1 && version != 2)
    throw InvalidInputError("profile version " + std::to_string(version) +
                            " is not supported (expected 1, or 2 with the arm taken hanging)");
  Profile p;
  Document& d = p.document;
  d = base;
  if (const Json* r = j.find("regressor")) {
    auto c = parse_regressor_choice(r->as_string());
    if (!c) throw InvalidInputError("unknown regressor '" + r->as_string() + "'");
    d.regressor = *c;
  }
  if (const Json* h = j.find("hierarchical")) d.hierarchical = h->as_bool();
  if (const Json* l = j.find("level")) {
    d.level = l->as_int();
    if (d.level < 1 || d.level > 3) throw InvalidInputError("level must be 1, 2 or 3");
  }
  // Absent: the arm length was taken out sideways (profiles before the field), whatever the
  // base document's convention.
  d.arm_taken_hanging = false;
  if (const Json* h = j.find("arm_taken_hanging")) {
    if (!h->is_bool()) {
      throw InvalidInputError("\"arm_taken_hanging\" must be true or false, not " + h->dump() +
                              " (true: the arm length was taken on the hanging arm)");
    }
    d.arm_taken_hanging = h->as_bool();
  }
  for (const auto& [id, x] : profile_measurements(j.at("measurements"))) d.values[id] = x;
  if (const Json* u = j.find("units")) p.units = parse_unit_system(u->as_string());
  if (const Json* s = j.find("sex")) p.sex = s->as_string();
  return p;
}

// ---------------------------------------------------------------------------------------------
// VR measuring sessions
namespace {
void collect_measurements(const Json& m, MeasurementMap& out) {
  if (m.is_object()) {
    for (const auto& [id, v] : m.as_object()) {
      if (v.is_number()) {
        out[id] = v.as_number();
      } else if (v.is_object() && v.contains("value") && v.at("value").is_number()) {
        out[id] = v.at("value").as_number();
      }
    }
  } else if (m.is_array()) {
    for (const Json& e : m.as_array()) {
      if (e.is_object() && e.contains("id") && e.contains("value") && e.at("value").is_number()) {
        out[e.at("id").as_string()] = e.at("value").as_number();
      }
    }
  }
}

/// A JSON Lines session journal: the mean of each step's takes after its last redo.
MeasurementMap journal_measurements(const std::string& text, const std::string& path) {
  const JournalContents jc = parse_journal(text, path);
  std::map<std::string, std::vector<double>> takes;
  for (const JournalRecord& r : jc.records) {
    if (r.type == "redo") takes.erase(r.step);
    if ((r.type == "sample" || r.type == "typed") && r.text.empty())
      takes[r.step].push_back(r.value);
  }
  MeasurementMap found;
  for (const auto& [step, v] : takes) {
    double s = 0;
    for (double x : v) s += x;
    found[step] = s / static_cast<double>(v.size());
  }
  return found;
}
}  // namespace

MeasurementMap read_session_measurements(const std::string& path) {
  const std::optional<std::string> contents = smpl::read_file(path);
  if (!contents) throw InvalidInputError("cannot open the file");
  try {
    const Json j = parse_json(*contents);
    MeasurementMap found;
    if (j.is_object()) {
      if (const Json* m = j.find("measurements")) collect_measurements(*m, found);
      if (const Json* r = j.find("result"); r && r->is_object()) {
        if (const Json* m = r->find("measurements")) collect_measurements(*m, found);
      }
    }
    return found;
  } catch (const JsonError&) {
    // Not one JSON value (or one whose measurements are malformed): a JSON Lines journal.
    return journal_measurements(*contents, path);
  }
}

namespace {
/// True when `x` is a plausible value of measurement `id`; false for any other id (e.g. a
/// protocol step of another kind).
bool usable(const std::string& id, double x) {
  MeasurementRange r;
  try {
    r = measurement_range(id);
  } catch (const std::exception&) {
    return false;
  }
  return std::isfinite(x) && x >= r.error_min && x <= r.error_max;
}
}  // namespace

SessionInputs session_inputs(const Document& base, const MeasurementMap& found,
                             const MeasurementMap& achieved) {
  SessionInputs s;
  Document& d = s.document;
  d = base;
  for (const auto& [id, x] : found) {
    if (!usable(id, x)) continue;
    d.values[id] = x;
    ++s.used;
    // The VR protocol takes the arm length out sideways.
    if (id == "arm_length") d.arm_taken_hanging = false;
  }
  if (s.used == 0) throw InvalidInputError("no usable measurement found");
  // Use the most detailed level the session provides.
  int level = 1;
  auto has = [&](const std::string& id) { return found.count(id) > 0; };
  if (has("inseam_height") && has("arm_span_fingertips")) level = 2;
  if (level == 2 && has("arm_length") && has("hip_width")) level = 3;
  if (d.hierarchical) d.level = std::max(d.level, level);
  for (const std::string& id : editable_inputs(d)) {
    if (d.values.count(id)) continue;
    auto it = achieved.find(id);
    if (it != achieved.end()) d.values[id] = it->second;
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Exported avatars
const std::vector<smpl::ExportFormat>& export_formats() {
  return smpl::export_formats();
}

std::vector<std::string> export_extensions() {
  std::vector<std::string> extensions;
  for (const auto& f : export_formats()) extensions.push_back(f.extension);
  return extensions;
}

std::map<std::string, std::string> export_metadata(const ModelEntry& entry, const Document& doc,
                                                   const AvatarView& avatar) {
  std::map<std::string, std::string> extras;
  const smpl::BodyModel& m = *entry.model;
  extras["generator"] = std::string("caliper-editor ") + CALIPER_APP_VERSION;
  extras["regressor"] = to_string(doc.regressor);
  extras["betas"] =
      Json(std::vector<double>(avatar.betas.data(), avatar.betas.data() + avatar.betas.size()))
          .dump();
  Json measurements = Json::object();
  for (const auto& [id, value] : avatar.achieved) measurements.set(id, value);
  extras["measurements"] = measurements.dump();
  extras["model"] = m.meta.name;
  // An open default model (made by caliper-modelgen) is named by its sex, as `caliper create`
  // does, so that `caliper measure` picks it (and its weight formula) without being told.
  const std::string& g = m.meta.gender;
  if (m.meta.source.rfind("caliper-modelgen", 0) == 0 &&
      (g == "female" || g == "male" || g == "neutral")) {
    extras["open_model_sex"] = g;
  }
  return extras;
}

}  // namespace caliper::app
