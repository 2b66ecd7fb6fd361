// The editor's model: commands in, state out. Sections: regressor choices, model entries,
// recomputation of the avatar, inputs and the hierarchy, undo/redo, files, comparison, the text
// command language of headless scripts.
#include "app/editor_core.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "caliper/errors.hpp"
#include "caliper/journal.hpp"
#include "caliper/json.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/io.hpp"
#include "smpl/text.hpp"

namespace caliper::app {

// ---------------------------------------------------------------------------------------------
// Regressor choices
namespace {

constexpr size_t kMaxUndo = 200;
constexpr size_t kMaxMessages = 50;

}  // namespace

std::string to_string(RegressorChoice choice) {
  switch (choice) {
    case RegressorChoice::R2:
      return "R2";
    case RegressorChoice::R4:
      return "R4";
    case RegressorChoice::R5:
      return "R5";
    case RegressorChoice::R6:
      return "R6";
    case RegressorChoice::NoiseAware:
      return "noise-aware";
  }
  return "R2";
}

std::optional<RegressorChoice> parse_regressor_choice(const std::string& text) {
  const std::string t = smpl::to_lower(text);
  if (t == "r2") return RegressorChoice::R2;
  if (t == "r4") return RegressorChoice::R4;
  if (t == "r5") return RegressorChoice::R5;
  if (t == "r6") return RegressorChoice::R6;
  if (t == "noise-aware" || t == "noise_aware" || t == "na") return RegressorChoice::NoiseAware;
  return std::nullopt;
}

const std::vector<std::string>& choice_inputs(RegressorChoice choice) {
  switch (choice) {
    case RegressorChoice::R2:
      return regressor_inputs(RegressorKind::R2);
    case RegressorChoice::R4:
      return regressor_inputs(RegressorKind::R4);
    case RegressorChoice::R5:
      return regressor_inputs(RegressorKind::R5);
    case RegressorChoice::R6:
    case RegressorChoice::NoiseAware:
      break;
  }
  return regressor_inputs(RegressorKind::R6);
}

namespace {
/// Inputs of hierarchy level 1..3 (paper: height+weight, + inseam+arm span, + arm length+hip).
const std::vector<std::string>& level_inputs(int level) {
  return choice_inputs(level <= 1   ? RegressorChoice::R2
                       : level == 2 ? RegressorChoice::R4
                                    : RegressorChoice::R6);
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Model entries
ModelEntry make_model_entry(std::shared_ptr<const smpl::BodyModel> model, const std::string& label,
                            const TrainOptions& options) {
  smpl::validate(*model, label);
  ModelEntry e;
  e.label = label;
  e.landmarks = landmarks_for(*model);
  e.regressors = std::make_shared<const RegressorSet>(train_regressors(*model, options));
  e.model = std::move(model);
  return e;
}

void EditorCore::add_model(ModelEntry entry) {
  models_.push_back(std::move(entry));
  if (current_ < 0) select_model(0);
}

const ModelEntry& EditorCore::model() const {
  return models_.at(static_cast<size_t>(current_));
}

bool EditorCore::select_model(int index) {
  if (index < 0 || index >= static_cast<int>(models_.size())) {
    post(Message::Level::Error, "no model number " + std::to_string(index));
    return false;
  }
  const int previous = current_;
  current_ = index;
  if (previous < 0 || doc_.values.empty()) {
    // First model: start from the mean shape's own measurements.
    doc_ = Document{};
    AvatarView mean;
    const smpl::BodyModel& m = *model().model;
    smpl::Vertices v = m.v_template;
    try {
      MeasureOptions mo;
      mo.circumferences = false;
      const MeasurementMap a = measure_all(m, v, mo);
      for (const std::string& id : choice_inputs(RegressorChoice::R6)) {
        auto it = a.find(id);
        if (it != a.end()) doc_.values[id] = it->second;
      }
    } catch (const std::exception& e) {
      post(Message::Level::Error, std::string("cannot measure the mean shape: ") + e.what());
    }
  }
  try {
    recompute(true);
  } catch (const std::exception& e) {
    post(Message::Level::Error, "model " + model().label + ": " + e.what());
    current_ = previous;
    if (previous >= 0) recompute(true);
    return false;
  }
  if (!baseline_set_) {
    saved_doc_ = doc_;
    baseline_set_ = true;
  }
  post(Message::Level::Info, "model: " + model().label);
  return true;
}

bool EditorCore::select_sex(const std::string& sex) {
  for (size_t i = 0; i < models_.size(); ++i) {
    if (smpl::to_lower(models_[i].model->meta.gender) == smpl::to_lower(sex))
      return select_model(static_cast<int>(i));
  }
  post(Message::Level::Error, "no " + sex + " model is loaded");
  return false;
}

bool EditorCore::load_model_file(const std::string& path) {
  try {
    auto m = std::make_shared<smpl::BodyModel>(smpl::load_model(path));
    if (m->meta.source.empty()) m->meta.source = path;
    std::string label = path.substr(path.find_last_of('/') + 1);
    ModelEntry e = make_model_entry(std::move(m), label);
    models_.push_back(std::move(e));
    return select_model(static_cast<int>(models_.size()) - 1);
  } catch (const std::exception& e) {
    post(Message::Level::Error,
         "could not open model " + path + ": " + e.what() + " (the current avatar is unchanged)");
    return false;
  }
}

// ---------------------------------------------------------------------------------------------
// Recomputation of the avatar
namespace {
RegressorChoice effective_choice(const Document& d) {
  if (!d.hierarchical || d.regressor == RegressorChoice::NoiseAware) return d.regressor;
  return d.level <= 1   ? RegressorChoice::R2
         : d.level == 2 ? RegressorChoice::R4
                        : RegressorChoice::R6;
}
}  // namespace

RegressorChoice EditorCore::active_regressor() const {
  return effective_choice(doc_);
}

std::string measurement_label(const std::string& id) {
  if (id == "weight") return "Weight";
  if (id == "volume") return "Volume";
  for (const MeasurementDef& d : paper_measurements()) {
    if (d.id == id) return d.label;
  }
  return id;
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

std::vector<std::string> EditorCore::editable_inputs() const {
  return doc_.hierarchical ? level_inputs(doc_.level) : choice_inputs(doc_.regressor);
}

void EditorCore::recompute(bool complete) {
  if (!has_model()) return;
  const ModelEntry& e = model();
  const smpl::BodyModel& m = *e.model;
  MeasurementMap in;
  for (const std::string& id : editable_inputs()) {
    auto it = doc_.values.find(id);
    if (it == doc_.values.end()) throw InvalidInputError("no value for " + id);
    in[id] = it->second;
  }
  AvatarView a;
  Eigen::VectorXd b;
  std::optional<Eigen::MatrixXd> covariance;
  const RegressorChoice choice = effective_choice(doc_);
  if (choice == RegressorChoice::NoiseAware) {
    if (!e.regressors->noise_aware)
      throw InvalidInputError("this model has no noise-aware regressor");
    Posterior p = e.regressors->noise_aware->predict(in);
    b = p.mean;
    a.beta_sd = p.sd();
    covariance = p.covariance;
  } else {
    const LinearRegressor* r = e.regressors->find(to_string(choice));
    if (r == nullptr) throw InvalidInputError("this model has no regressor " + to_string(choice));
    b = r->predict(in);
  }
  if (!b.allFinite()) throw InvalidInputError("the regressor returned non-finite betas");
  const int k = static_cast<int>(b.size());
  a.betas = Eigen::VectorXd::Zero(m.num_betas());
  a.betas.head(k) = b;
  // Rest-pose vertices: v_template + shapedirs * betas (allocation-free after the first call).
  const Eigen::Index n3 = m.v_template.size();
  shaped_.resize(n3);
  shaped_.noalias() = m.shapedirs.leftCols(k) * b;
  a.vertices.resize(m.num_vertices(), 3);
  Eigen::Map<Eigen::VectorXd>(a.vertices.data(), n3) =
      Eigen::Map<const Eigen::VectorXd>(m.v_template.data(), n3) + shaped_;
  const double floor = a.vertices.col(1).minCoeff();
  a.vertices.col(1).array() -= floor;
  a.plausibility = plausibility(b);
  if (complete) {
    MeasureOptions mo;
    mo.circumferences = true;
    a.achieved = measure_all(m, a.vertices, mo);
    a.achieved_complete = true;
  } else {
    a.achieved = measure(a.vertices, e.landmarks);
  }
  // Colour-map values.
  const Eigen::VectorXd excess = b - b.cwiseMax(-2.0).cwiseMin(2.0);
  a.implausible_displacement.assign(static_cast<size_t>(m.num_vertices()), 0.0f);
  if (excess.cwiseAbs().maxCoeff() > 0) {
    const Eigen::VectorXd d = m.shapedirs.leftCols(k) * excess;
    for (int v = 0; v < m.num_vertices(); ++v) {
      a.implausible_displacement[static_cast<size_t>(v)] =
          static_cast<float>(d.segment<3>(3 * v).norm());
    }
  }
  a.uncertainty.assign(static_cast<size_t>(m.num_vertices()), 0.0f);
  if (covariance && complete) {
    const Eigen::MatrixXd& s = *covariance;
    for (int v = 0; v < m.num_vertices(); ++v) {
      const auto block = m.shapedirs.block(3 * v, 0, 3, k);
      const double trace = (block * s * block.transpose()).trace();
      a.uncertainty[static_cast<size_t>(v)] = static_cast<float>(std::sqrt(std::max(0.0, trace)));
    }
  }
  if (comparison_ && comparison_->vertices.rows() == a.vertices.rows()) {
    comparison_->difference.resize(static_cast<size_t>(a.vertices.rows()));
    for (Eigen::Index v = 0; v < a.vertices.rows(); ++v) {
      comparison_->difference[static_cast<size_t>(v)] =
          static_cast<float>((a.vertices.row(v) - comparison_->vertices.row(v)).norm());
    }
  } else if (comparison_) {
    comparison_->difference.clear();
  }
  avatar_ = std::move(a);
  ++revision_;
}

void EditorCore::apply(const Document& doc, bool complete) {
  const Document old = doc_;
  doc_ = doc;
  try {
    recompute(complete);
  } catch (const std::exception& e) {
    doc_ = old;
    throw;
  }
}

// ---------------------------------------------------------------------------------------------
// Inputs and the hierarchy
bool EditorCore::check_value(const std::string& id, double v) {
  const std::vector<std::string> editable = editable_inputs();
  if (std::find(editable.begin(), editable.end(), id) == editable.end()) {
    post(Message::Level::Error, id + " is not an input of the current regressor / level");
    return false;
  }
  if (!std::isfinite(v)) {
    post(Message::Level::Error, id + ": not a number; the avatar is unchanged");
    return false;
  }
  MeasurementRange r;
  try {
    r = measurement_range(id);
  } catch (const std::exception& e) {
    post(Message::Level::Error, e.what());
    return false;
  }
  if (v < r.error_min || v > r.error_max) {
    post(Message::Level::Error, id + " = " + value_text(id, v, view_.units) + " is out of range (" +
                                    value_text(id, r.error_min, view_.units) + " to " +
                                    value_text(id, r.error_max, view_.units) +
                                    "); the avatar is unchanged");
    return false;
  }
  MeasurementMap trial;
  for (const std::string& e : editable) {
    auto it = doc_.values.find(e);
    if (it != doc_.values.end()) trial[e] = it->second;
  }
  trial[id] = v;
  for (const ValidationMessage& m : validate_measurements(trial)) {
    // Refuse only problems that involve the changed value (single values and ratios naming it).
    if (m.severity == Severity::Error && m.id.find(id) != std::string::npos) {
      post(Message::Level::Error, m.message + "; the avatar is unchanged");
      return false;
    }
  }
  if (v < r.warning_min || v > r.warning_max) {
    post(Message::Level::Warning,
         id + " = " + value_text(id, v, view_.units) + " is unusual for an adult");
  }
  return true;
}

bool EditorCore::set_value(const std::string& id, double value_si) {
  clear_stale_messages();
  if (!has_model()) {
    post(Message::Level::Error, "open a model first");
    return false;
  }
  if (!check_value(id, value_si)) return false;
  Document d = doc_;
  d.values[id] = value_si;
  try {
    if (dragging_) {
      apply(d, true);  // the drag's start is already one undo step (begin_drag)
    } else {
      commit(d);
    }
  } catch (const std::exception& e) {
    post(Message::Level::Error, id + ": " + e.what() + "; the avatar is unchanged");
    return false;
  }
  return true;
}

bool EditorCore::set_display_value(const std::string& id, double shown) {
  return set_value(id, from_display(id, shown, view_.units));
}

void EditorCore::begin_drag() {
  if (dragging_) return;
  clear_stale_messages();
  push_undo();
  dragging_ = true;
}

bool EditorCore::drag_value(const std::string& id, double value_si) {
  if (!has_model()) return false;
  if (!dragging_) begin_drag();
  const std::vector<std::string> editable = editable_inputs();
  if (std::find(editable.begin(), editable.end(), id) == editable.end() ||
      !std::isfinite(value_si)) {
    return false;
  }
  const MeasurementRange r = measurement_range(id);
  value_si = std::clamp(value_si, r.error_min, r.error_max);
  Document d = doc_;
  d.values[id] = value_si;
  try {
    apply(d, false);
  } catch (const std::exception& e) {
    post(Message::Level::Error, id + ": " + e.what());
    return false;
  }
  return true;
}

void EditorCore::end_drag() {
  if (!dragging_) return;
  dragging_ = false;
  try {
    recompute(true);
  } catch (const std::exception& e) {
    post(Message::Level::Error, e.what());
  }
}

std::optional<double> EditorCore::shown_value(const std::string& id) const {
  const std::vector<std::string> editable = editable_inputs();
  if (std::find(editable.begin(), editable.end(), id) != editable.end()) {
    auto it = doc_.values.find(id);
    if (it != doc_.values.end()) return it->second;
  }
  auto it = avatar_.achieved.find(id);
  if (it != avatar_.achieved.end()) return it->second;
  return std::nullopt;
}

void EditorCore::use_regressor(RegressorChoice choice) {
  clear_stale_messages();
  Document d = doc_;
  d.regressor = choice;
  d.hierarchical = false;
  const std::vector<std::string> before_inputs = editable_inputs();
  for (const std::string& id : choice_inputs(choice)) {
    if (std::find(before_inputs.begin(), before_inputs.end(), id) == before_inputs.end()) {
      auto it = avatar_.achieved.find(id);
      if (it != avatar_.achieved.end()) d.values[id] = it->second;
    }
  }
  try {
    commit(d);
    post(Message::Level::Info, "regressor " + describe_regressor(choice));
  } catch (const std::exception& e) {
    post(Message::Level::Error, std::string("regressor ") + to_string(choice) + ": " + e.what());
  }
}

void EditorCore::set_regressor(RegressorChoice choice) {
  clear_stale_messages();
  Document d = doc_;
  d.regressor = choice;
  // New inputs start from the avatar's own measurements.
  for (const std::string& id : choice_inputs(choice)) {
    const auto& editable = editable_inputs();
    if (std::find(editable.begin(), editable.end(), id) == editable.end()) {
      auto it = avatar_.achieved.find(id);
      if (it != avatar_.achieved.end()) d.values[id] = it->second;
    }
  }
  try {
    commit(d);
  } catch (const std::exception& e) {
    post(Message::Level::Error, std::string("regressor ") + to_string(choice) + ": " + e.what());
  }
}

void EditorCore::set_hierarchical(bool on) {
  clear_stale_messages();
  Document d = doc_;
  d.hierarchical = on;
  // Inputs the new mode edits start from the avatar's own values.
  const std::vector<std::string> before_inputs = editable_inputs();
  for (const std::string& id : on ? level_inputs(d.level) : choice_inputs(d.regressor)) {
    if (std::find(before_inputs.begin(), before_inputs.end(), id) == before_inputs.end()) {
      auto it = avatar_.achieved.find(id);
      if (it != avatar_.achieved.end()) d.values[id] = it->second;
    }
  }
  try {
    commit(d);
    post(Message::Level::Info,
         on ? "hierarchical adjustment on: level " + std::to_string(d.level) + " uses " +
                  to_string(active_regressor())
            : "hierarchical adjustment off: regressor " + describe_regressor(d.regressor));
  } catch (const std::exception& e) {
    post(Message::Level::Error, e.what());
  }
}

bool EditorCore::set_level(int level) {
  clear_stale_messages();
  if (level < 1 || level > 3) {
    post(Message::Level::Error, "level must be 1, 2 or 3, not " + std::to_string(level));
    return false;
  }
  Document d = doc_;
  d.hierarchical = true;
  const std::vector<std::string> before_inputs = editable_inputs();
  d.level = level;
  for (const std::string& id : level_inputs(level)) {
    if (std::find(before_inputs.begin(), before_inputs.end(), id) == before_inputs.end()) {
      auto it = avatar_.achieved.find(id);
      if (it != avatar_.achieved.end()) d.values[id] = it->second;
    }
  }
  try {
    commit(d);
    std::string names;
    for (const std::string& id : level_inputs(level))
      names += (names.empty() ? "" : ", ") + measurement_label(id);
    post(Message::Level::Info, "level " + std::to_string(level) + " (" +
                                   to_string(active_regressor()) + "): you can edit " + names);
  } catch (const std::exception& e) {
    post(Message::Level::Error, std::string("level ") + std::to_string(level) + ": " + e.what());
    return false;
  }
  return true;
}

void EditorCore::reset() {
  if (!has_model()) return;
  clear_stale_messages();
  push_undo();
  const Document keep = doc_;
  doc_.values.clear();
  const int c = current_;
  current_ = -1;
  if (!select_model(c)) doc_ = keep;
  doc_.regressor = keep.regressor;
  doc_.hierarchical = keep.hierarchical;
  doc_.level = keep.level;
  recompute(true);
}

// ---------------------------------------------------------------------------------------------
// Undo / redo
void EditorCore::push_undo() {
  remember(doc_);
}

void EditorCore::remember(const Document& before) {
  undo_.push_back(before);
  if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
  redo_.clear();
}

void EditorCore::commit(const Document& d) {
  const Document before = doc_;
  apply(d, true);  // throws before anything changes when `d` cannot be applied
  remember(before);
}

bool EditorCore::step_history(std::vector<Document>& from, std::vector<Document>& to,
                              const char* what) {
  clear_stale_messages();
  if (from.empty()) return false;
  const Document target = from.back();
  try {
    const Document now = doc_;
    apply(target, true);
    from.pop_back();
    to.push_back(now);
    post(Message::Level::Info, std::string(what == std::string("undo") ? "undone: " : "redone: ") +
                                   describe_change(now, target));
  } catch (const std::exception& e) {
    post(Message::Level::Error, std::string(what) + ": " + e.what());
    return false;
  }
  return true;
}

std::string EditorCore::describe_change(const Document& from, const Document& to) const {
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : "; ") + part; };
  if (from.regressor != to.regressor || from.hierarchical != to.hierarchical ||
      from.level != to.level) {
    if (to.hierarchical && to.regressor != RegressorChoice::NoiseAware)
      add("hierarchical level " + std::to_string(to.level));
    else
      add("regressor " + to_string(to.regressor));
  }
  for (const auto& [id, v] : to.values) {
    auto it = from.values.find(id);
    if (it != from.values.end() && it->second == v) continue;
    char buf[128];
    const double shown = to_display(id, v, view_.units);
    if (it != from.values.end()) {
      std::snprintf(buf, sizeof buf, "%.1f -> %.1f %s", to_display(id, it->second, view_.units),
                    shown, unit_label(id, view_.units).c_str());
    } else {
      std::snprintf(buf, sizeof buf, "%.1f %s", shown, unit_label(id, view_.units).c_str());
    }
    add(measurement_label(id) + " " + buf);
  }
  return s.empty() ? "no visible change" : s;
}

bool EditorCore::undo() {
  return step_history(undo_, redo_, "undo");
}

bool EditorCore::redo() {
  return step_history(redo_, undo_, "redo");
}

// ---------------------------------------------------------------------------------------------
// Files
bool EditorCore::save_profile(const std::string& path) {
  try {
    Json j = Json::object();
    j.set("format", "caliper-profile");
    j.set("version", 1);
    j.set("units", to_string(view_.units));
    if (has_model()) {
      j.set("model", model().label);
      j.set("sex", model().model->meta.gender);
    }
    j.set("regressor", to_string(doc_.regressor));
    j.set("hierarchical", doc_.hierarchical);
    j.set("level", doc_.level);
    Json values = Json::object();
    for (const std::string& id : editable_inputs()) {
      auto it = doc_.values.find(id);
      if (it != doc_.values.end()) values.set(id, it->second);
    }
    j.set("measurements", values);
    std::vector<double> betas(avatar_.betas.data(), avatar_.betas.data() + avatar_.betas.size());
    j.set("betas", Json(betas));
    write_json_file(path, j);
    saved_doc_ = doc_;
    post(Message::Level::Info, "saved profile " + path);
    return true;
  } catch (const std::exception& e) {
    post(Message::Level::Error, "could not save profile " + path + ": " + e.what());
    return false;
  }
}

bool EditorCore::open_profile(const std::string& path) {
  clear_stale_messages();
  const int previous_model = current_;
  try {
    const Json j = read_json_file(path);
    if (!j.is_object() || !j.contains("format") ||
        j.at("format").as_string() != "caliper-profile") {
      throw InvalidInputError("not a caliper profile (expected \"format\": \"caliper-profile\")");
    }
    const int version = j.at("version").as_int();
    if (version != 1)
      throw InvalidInputError("profile version " + std::to_string(version) +
                              " is not supported (expected 1)");
    Document d = doc_;
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
    const Json& values = j.at("measurements");
    MeasurementMap read;
    for (const auto& [id, v] : values.as_object()) {
      const double x = v.as_number();
      const MeasurementRange r = measurement_range(id);
      if (!std::isfinite(x) || x < r.error_min || x > r.error_max) {
        throw InvalidInputError(id + " = " + std::to_string(x) + " (SI units) is out of range");
      }
      read[id] = x;
    }
    for (const auto& [id, x] : read) d.values[id] = x;
    std::optional<UnitSystem> units;
    if (const Json* u = j.find("units")) units = parse_unit_system(u->as_string());
    if (const Json* s = j.find("sex");
        s != nullptr && has_model() && s->as_string() != model().model->meta.gender) {
      for (size_t i = 0; i < models_.size(); ++i) {
        if (models_[i].model->meta.gender == s->as_string()) {
          current_ = static_cast<int>(i);
          break;
        }
      }
    }
    commit(d);
    if (units) view_.units = *units;
    saved_doc_ = doc_;
    post(Message::Level::Info, "opened profile " + path);
    return true;
  } catch (const std::exception& e) {
    if (current_ != previous_model) {  // the profile's sex switched the model: switch back
      current_ = previous_model;
      try {
        recompute(true);
      } catch (const std::exception&) {
        // The previous state was valid a moment ago; nothing more to do.
      }
    }
    post(Message::Level::Error,
         "could not open profile " + path + ": " + e.what() + " (the current avatar is unchanged)");
    return false;
  }
}

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
}  // namespace

bool EditorCore::open_session(const std::string& path) {
  clear_stale_messages();
  try {
    const std::optional<std::string> contents = smpl::read_file(path);
    if (!contents) throw InvalidInputError("cannot open the file");
    const std::string& text = *contents;
    MeasurementMap found;
    bool parsed = false;
    try {
      const Json j = parse_json(text);
      parsed = true;
      if (j.is_object()) {
        if (const Json* m = j.find("measurements")) collect_measurements(*m, found);
        if (const Json* r = j.find("result"); r && r->is_object()) {
          if (const Json* m = r->find("measurements")) collect_measurements(*m, found);
        }
      }
    } catch (const JsonError&) {
      parsed = false;
    }
    if (!parsed) {  // a JSON Lines session journal: the mean of each step's takes after redos
      const JournalContents jc = parse_journal(text, path);
      std::map<std::string, std::vector<double>> takes;
      for (const JournalRecord& r : jc.records) {
        if (r.type == "redo") takes.erase(r.step);
        if ((r.type == "sample" || r.type == "typed") && r.text.empty())
          takes[r.step].push_back(r.value);
      }
      for (const auto& [step, v] : takes) {
        double s = 0;
        for (double x : v) s += x;
        found[step] = s / static_cast<double>(v.size());
      }
    }
    Document d = doc_;
    int used = 0;
    for (const auto& [id, x] : found) {
      MeasurementRange r;
      try {
        r = measurement_range(id);
      } catch (const std::exception&) {
        continue;  // not a measurement id (e.g. a protocol step of another kind)
      }
      if (std::isfinite(x) && x >= r.error_min && x <= r.error_max) {
        d.values[id] = x;
        ++used;
      }
    }
    if (used == 0) throw InvalidInputError("no usable measurement found");
    // Use the most detailed level the session provides.
    int level = 1;
    auto has = [&](const std::string& id) { return found.count(id) > 0; };
    if (has("inseam_height") && has("arm_span_fingertips")) level = 2;
    if (level == 2 && has("arm_length") && has("hip_width")) level = 3;
    if (d.hierarchical) d.level = std::max(d.level, level);
    for (const std::string& id :
         d.hierarchical ? level_inputs(d.level) : choice_inputs(d.regressor)) {
      if (!d.values.count(id)) {
        auto it = avatar_.achieved.find(id);
        if (it != avatar_.achieved.end()) d.values[id] = it->second;
      }
    }
    commit(d);
    post(Message::Level::Info, "read " + std::to_string(used) + " measurements from " + path);
    return true;
  } catch (const std::exception& e) {
    post(Message::Level::Error,
         "could not read session " + path + ": " + e.what() + " (the current avatar is unchanged)");
    return false;
  }
}

const std::vector<smpl::ExportFormat>& export_formats() {
  return smpl::export_formats();
}

std::vector<std::string> EditorCore::export_extensions() {
  std::vector<std::string> extensions;
  for (const auto& f : export_formats()) extensions.push_back(f.extension);
  return extensions;
}

std::map<std::string, std::string> EditorCore::export_metadata() const {
  std::map<std::string, std::string> extras;
  if (!has_model()) return extras;
  const smpl::BodyModel& m = *model().model;
  extras["generator"] = std::string("caliper-editor ") + CALIPER_APP_VERSION;
  extras["regressor"] = to_string(doc_.regressor);
  extras["betas"] =
      Json(std::vector<double>(avatar_.betas.data(), avatar_.betas.data() + avatar_.betas.size()))
          .dump();
  Json measurements = Json::object();
  for (const auto& [id, value] : avatar_.achieved) measurements.set(id, value);
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

bool EditorCore::export_avatar(const std::string& path, smpl::ExportOptions options) {
  if (!has_model()) {
    post(Message::Level::Error, "nothing to export: open a model first");
    return false;
  }
  try {
    options.extras = export_metadata();
    smpl::export_avatar(path, *model().model, avatar_.betas, options);
    post(Message::Level::Info, "exported " + path);
    return true;
  } catch (const std::exception& e) {
    post(Message::Level::Error, "could not export " + path + ": " + e.what());
    return false;
  }
}

// ---------------------------------------------------------------------------------------------
// Comparison
void EditorCore::pin_comparison(const std::string& label) {
  if (!has_model()) return;
  Comparison c;
  c.label = label;
  c.vertices = avatar_.vertices;
  c.values = avatar_.achieved;
  c.difference.assign(static_cast<size_t>(c.vertices.rows()), 0.0f);
  comparison_ = std::move(c);
  post(Message::Level::Info, "pinned the current avatar for comparison");
}

void EditorCore::clear_comparison() {
  comparison_.reset();
  view_.compare = CompareMode::Off;
}

void EditorCore::clear_stale_messages() {
  messages_.erase(std::remove_if(messages_.begin(), messages_.end(),
                                 [](const Message& m) { return m.level != Message::Level::Info; }),
                  messages_.end());
}

void EditorCore::post(Message::Level level, const std::string& text) {
  messages_.push_back({level, text});
  while (messages_.size() > kMaxMessages) messages_.pop_front();
}

// ---------------------------------------------------------------------------------------------
// The text command language (headless scripts, tests)
bool EditorCore::run_command(const std::string& line) {
  std::istringstream in(line);
  std::string cmd;
  if (!(in >> cmd) || cmd[0] == '#') return true;  // blank or comment
  std::string a, b;
  auto fail = [&](const std::string& why) {
    post(Message::Level::Error, "command '" + line + "': " + why);
    return false;
  };
  auto on_off = [&](const std::string& s, bool& out) {
    if (s == "on" || s == "1" || s == "true")
      out = true;
    else if (s == "off" || s == "0" || s == "false")
      out = false;
    else
      return false;
    return true;
  };
  if (cmd == "set" || cmd == "drag") {
    double v = 0;
    if (!(in >> a >> v)) return fail("expected: " + cmd + " <id> <value> [unit]");
    std::string unit;
    in >> unit;
    double si = from_display(a, v, view_.units);
    if (!unit.empty()) {
      auto s = to_si_with_suffix(a, v, unit);
      if (!s) return fail("unit '" + unit + "' does not fit " + a);
      si = *s;
    }
    if (cmd == "set") return set_value(a, si);
    begin_drag();
    const bool ok = drag_value(a, si);
    end_drag();
    return ok;
  }
  if (cmd == "units") {
    in >> a;
    auto u = parse_unit_system(a);
    if (!u) return fail("units are metric or imperial");
    view_.units = *u;
    return true;
  }
  if (cmd == "regressor") {
    in >> a;
    auto c = parse_regressor_choice(a);
    if (!c) return fail("regressor is R2, R4, R5, R6 or noise-aware");
    set_regressor(*c);
    return true;
  }
  if (cmd == "hierarchical") {
    bool on = true;
    in >> a;
    if (!on_off(a, on)) return fail("expected on or off");
    set_hierarchical(on);
    return true;
  }
  if (cmd == "level") {
    int l = 0;
    if (!(in >> l)) return fail("expected a level 1..3");
    return set_level(l);
  }
  if (cmd == "sex") {
    in >> a;
    return select_sex(a);
  }
  if (cmd == "model") {
    in >> a;
    if (a.empty()) return fail("expected a model index or file");
    if (std::all_of(a.begin(), a.end(), [](unsigned char c) { return std::isdigit(c); })) {
      return select_model(std::stoi(a));
    }
    return load_model_file(a);
  }
  if (cmd == "undo") return undo() || fail("nothing to undo");
  if (cmd == "redo") return redo() || fail("nothing to redo");
  if (cmd == "reset") {
    reset();
    return true;
  }
  if (cmd == "open-profile") return (in >> a) ? open_profile(a) : fail("expected a file");
  if (cmd == "save-profile") return (in >> a) ? save_profile(a) : fail("expected a file");
  if (cmd == "open-session") return (in >> a) ? open_session(a) : fail("expected a file");
  if (cmd == "export") return (in >> a) ? export_mesh(a) : fail("expected a file");
  if (cmd == "wireframe") {
    in >> a;
    return on_off(a, view_.wireframe) || fail("expected on or off");
  }
  if (cmd == "overlay") {
    in >> a;
    return on_off(a, view_.overlay) || fail("expected on or off");
  }
  if (cmd == "scale") {
    in >> a;
    if (a != "fixed" && a != "fit") return fail("scale is fixed or fit");
    view_.fixed_scale = a == "fixed";
    return true;
  }
  if (cmd == "colour" || cmd == "color") {
    in >> a;
    if (a == "skin")
      view_.colour = ColourMode::Skin;
    else if (a == "plausibility")
      view_.colour = ColourMode::Plausibility;
    else if (a == "uncertainty")
      view_.colour = ColourMode::Uncertainty;
    else
      return fail("colour is skin, plausibility or uncertainty");
    return true;
  }
  if (cmd == "compare") {
    in >> a;
    if (a == "pin") {
      in >> b;
      pin_comparison(b.empty() ? "pinned" : b);
    } else if (a == "off") {
      view_.compare = CompareMode::Off;
    } else if (a == "side") {
      if (!comparison_) return fail("pin an avatar first (compare pin)");
      view_.compare = CompareMode::SideBySide;
    } else if (a == "difference") {
      if (!comparison_) return fail("pin an avatar first (compare pin)");
      view_.compare = CompareMode::Difference;
    } else if (a == "clear") {
      clear_comparison();
    } else {
      return fail("compare pin|side|difference|off|clear");
    }
    return true;
  }
  return fail("unknown command");
}

}  // namespace caliper::app
