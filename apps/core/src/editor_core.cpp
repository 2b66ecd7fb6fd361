// The editor's model as a facade: the state the units share (models, document, avatar, view,
// comparison, history, messages) and the commands that combine them. Sections: models, the
// avatar, inputs and the hierarchy, undo/redo, files, comparison, messages.
#include "app/editor_core.hpp"

#include <algorithm>
#include <cmath>

#include "app/commands.hpp"
#include "caliper/json.hpp"
#include "smpl/io.hpp"
#include "smpl/text.hpp"

namespace caliper::app {

// ---------------------------------------------------------------------------------------------
// Models
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
  const ModelEntry& entry = models_[static_cast<size_t>(index)];
  Document d = doc_;
  if (current_ < 0 || doc_.values.empty()) {
    // First model: start from the mean shape's own measurements.
    d = Document{};
    log_.attempt([&] { d.values = mean_shape_inputs(entry); }, "cannot measure the mean shape: ");
  }
  if (!log_.attempt([&] { apply(d, true, index); }, "model " + entry.label + ": ")) return false;
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
  return log_.attempt(
      [&] {
        auto m = std::make_shared<smpl::BodyModel>(smpl::load_model(path));
        if (m->meta.source.empty()) m->meta.source = path;
        std::string label = path.substr(path.find_last_of('/') + 1);
        models_.push_back(make_model_entry(std::move(m), label));
        return select_model(static_cast<int>(models_.size()) - 1);
      },
      "could not open model " + path + ": ", " (the current avatar is unchanged)");
}

// ---------------------------------------------------------------------------------------------
// The avatar
RegressorChoice EditorCore::active_regressor() const {
  return app::active_regressor(doc_);
}

std::vector<std::string> EditorCore::editable_inputs() const {
  return app::editable_inputs(doc_);
}

void EditorCore::show(AvatarView avatar) {
  if (comparison_) update_difference(*comparison_, avatar.vertices);
  avatar_ = std::move(avatar);
  ++revision_;
}

void EditorCore::apply(const Document& d, bool complete, int model) {
  if (model < 0) {
    doc_ = d;
    return;
  }
  AvatarView a = recompute(d, models_.at(static_cast<size_t>(model)), complete);  // may throw
  current_ = model;
  doc_ = d;
  show(std::move(a));
}

void EditorCore::commit(const Document& d, int model) {
  const Document before = doc_;
  apply(d, true, model);  // throws before anything changes when `d` cannot be applied
  history_.record(before);
}

// ---------------------------------------------------------------------------------------------
// Inputs and the hierarchy
bool EditorCore::check_value(const std::string& id, double v) {
  const std::vector<std::string>& editable = app::editable_inputs(doc_);
  if (std::find(editable.begin(), editable.end(), id) == editable.end()) {
    post(Message::Level::Error, id + " is not an input of the current regressor / level");
    return false;
  }
  if (!std::isfinite(v)) {
    post(Message::Level::Error, id + ": not a number; the avatar is unchanged");
    return false;
  }
  MeasurementRange r;
  if (!log_.attempt([&] { r = measurement_range(id); })) return false;
  const UnitSystem u = view_.units;
  if (v < r.error_min || v > r.error_max) {
    post(Message::Level::Error, id + " = " + value_text(id, v, u) + " is out of range (" +
                                    value_text(id, r.error_min, u) + " to " +
                                    value_text(id, r.error_max, u) + "); the avatar is unchanged");
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
    post(Message::Level::Warning, id + " = " + value_text(id, v, u) + " is unusual for an adult");
  }
  return true;
}

Document EditorCore::start_new_inputs(Document d, const std::vector<std::string>& ids,
                                      const std::vector<std::string>& kept) const {
  if (!has_model()) {
    start_from_avatar(d, ids, kept, avatar_.achieved);
    return d;
  }
  const auto has = [](const std::vector<std::string>& v, const char* id) {
    return std::find(v.begin(), v.end(), id) != v.end();
  };
  // A new arm length the model cannot map from a hanging one starts out sideways.
  if (d.arm_taken_hanging && has(ids, "arm_length") && !has(kept, "arm_length") &&
      !hanging_arm_unavailable().empty()) {
    d.arm_taken_hanging = false;
  }
  start_from_avatar(d, ids, kept, as_typed(d, model(), avatar_.achieved));
  return d;
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
  return log_.attempt(
      [&] {
        if (dragging_) {
          apply(d, true);  // the drag's start is already one undo step (begin_drag)
        } else {
          commit(d);
        }
      },
      id + ": ", "; the avatar is unchanged");
}

bool EditorCore::set_display_value(const std::string& id, double shown) {
  return set_value(id, from_display(id, shown, view_.units));
}

void EditorCore::begin_drag() {
  if (dragging_) return;
  clear_stale_messages();
  history_.record(doc_);
  dragging_ = true;
}

bool EditorCore::drag_value(const std::string& id, double value_si) {
  if (!has_model()) return false;
  if (!dragging_) begin_drag();
  const std::vector<std::string>& editable = app::editable_inputs(doc_);
  if (std::find(editable.begin(), editable.end(), id) == editable.end() ||
      !std::isfinite(value_si)) {
    return false;
  }
  const MeasurementRange r = measurement_range(id);
  Document d = doc_;
  d.values[id] = std::clamp(value_si, r.error_min, r.error_max);
  return log_.attempt([&] { apply(d, false); }, id + ": ");
}

void EditorCore::end_drag() {
  if (!dragging_) return;
  dragging_ = false;
  log_.attempt([&] { apply(doc_, true); });
}

std::optional<double> EditorCore::shown_value(const std::string& id) const {
  const std::vector<std::string>& editable = app::editable_inputs(doc_);
  if (std::find(editable.begin(), editable.end(), id) != editable.end()) {
    auto it = doc_.values.find(id);
    if (it != doc_.values.end()) return it->second;
  }
  const MeasurementMap achieved = achieved_as_typed();
  auto it = achieved.find(id);
  if (it != achieved.end()) return it->second;
  return std::nullopt;
}

MeasurementMap EditorCore::achieved_as_typed() const {
  if (!has_model()) return avatar_.achieved;
  return as_typed(doc_, model(), avatar_.achieved);
}

std::string EditorCore::hanging_arm_unavailable() const {
  return has_model() ? app::hanging_arm_unavailable(model()) : std::string();
}

bool EditorCore::set_arm_taken_hanging(bool hanging) {
  clear_stale_messages();
  if (!has_model()) {
    post(Message::Level::Error, "open a model first");
    return false;
  }
  if (doc_.arm_taken_hanging == hanging) return true;
  return log_.attempt(
      [&] {
        const Document d = with_arm_taken_hanging(doc_, model(), hanging);
        std::string how = hanging ? "arm length taken hanging" : "arm length out sideways";
        const auto from = doc_.values.find("arm_length");
        const auto to = d.values.find("arm_length");
        if (from != doc_.values.end() && to != d.values.end()) {
          how += ": " + value_text("arm_length", from->second, view_.units) + " -> " +
                 value_text("arm_length", to->second, view_.units) +
                 " (the model's map; the avatar stays)";
        }
        commit(d);
        post(Message::Level::Info, how);
      },
      "arm length: ", "; the avatar is unchanged");
}

void EditorCore::use_regressor(RegressorChoice choice) {
  clear_stale_messages();
  Document d = doc_;
  d.regressor = choice;
  d.hierarchical = false;
  d = start_new_inputs(d, choice_inputs(choice), app::editable_inputs(doc_));
  log_.attempt(
      [&] {
        commit(d);
        post(Message::Level::Info, "regressor " + describe_regressor(choice));
      },
      "regressor " + to_string(choice) + ": ");
}

void EditorCore::set_regressor(RegressorChoice choice) {
  clear_stale_messages();
  Document d = doc_;
  d.regressor = choice;
  // New inputs start from the avatar's own measurements.
  d = start_new_inputs(d, choice_inputs(choice), app::editable_inputs(doc_));
  log_.attempt([&] { commit(d); }, "regressor " + to_string(choice) + ": ");
}

void EditorCore::set_hierarchical(bool on) {
  clear_stale_messages();
  Document d = doc_;
  d.hierarchical = on;
  // Inputs the new mode edits start from the avatar's own values.
  d = start_new_inputs(d, app::editable_inputs(d), app::editable_inputs(doc_));
  log_.attempt([&] {
    commit(d);
    post(Message::Level::Info,
         on ? "hierarchical adjustment on: level " + std::to_string(d.level) + " uses " +
                  to_string(active_regressor())
            : "hierarchical adjustment off: regressor " + describe_regressor(d.regressor));
  });
}

bool EditorCore::set_level(int level) {
  clear_stale_messages();
  if (level < 1 || level > 3) {
    post(Message::Level::Error, "level must be 1, 2 or 3, not " + std::to_string(level));
    return false;
  }
  Document d = doc_;
  d.hierarchical = true;
  d.level = level;
  d = start_new_inputs(d, level_inputs(level), app::editable_inputs(doc_));
  return log_.attempt(
      [&] {
        commit(d);
        std::string names;
        for (const std::string& id : level_inputs(level))
          names += (names.empty() ? "" : ", ") + measurement_label(id);
        post(Message::Level::Info, "level " + std::to_string(level) + " (" +
                                       to_string(active_regressor()) + "): you can edit " + names);
      },
      "level " + std::to_string(level) + ": ");
}

void EditorCore::reset() {
  if (!has_model()) return;
  clear_stale_messages();
  history_.record(doc_);
  Document d = doc_;  // keeps the regressor, mode, level and the arm's convention
  d.values.clear();
  if (d.arm_taken_hanging && !hanging_arm_unavailable().empty()) d.arm_taken_hanging = false;
  log_.attempt([&] { d.values = as_typed(d, model(), mean_shape_inputs(model())); },
               "cannot measure the mean shape: ");
  if (log_.attempt([&] { apply(d, true); }, "model " + model().label + ": "))
    post(Message::Level::Info, "model: " + model().label);
}

// ---------------------------------------------------------------------------------------------
// Undo / redo
bool EditorCore::step_history(bool undo) {
  clear_stale_messages();
  if (undo ? !history_.can_undo() : !history_.can_redo()) return false;
  const Document before = doc_;
  return log_.attempt(
      [&] {
        const auto to = [&](const Document& target) { apply(target, true); };
        if (undo) {
          history_.undo(doc_, to);
        } else {
          history_.redo(doc_, to);
        }
        post(Message::Level::Info, std::string(undo ? "undone: " : "redone: ") +
                                       describe_change(before, doc_, view_.units));
      },
      undo ? "undo: " : "redo: ");
}

bool EditorCore::undo() {
  return step_history(true);
}

bool EditorCore::redo() {
  return step_history(false);
}

// ---------------------------------------------------------------------------------------------
// Files
bool EditorCore::save_profile(const std::string& path) {
  return log_.attempt(
      [&] {
        const ModelEntry* m = has_model() ? &model() : nullptr;
        write_json_file(path, profile_json(doc_, view_.units, m, avatar_.betas));
        saved_doc_ = doc_;
        post(Message::Level::Info, "saved profile " + path);
      },
      "could not save profile " + path + ": ");
}

bool EditorCore::open_profile(const std::string& path) {
  clear_stale_messages();
  return log_.attempt(
      [&] {
        const Profile p = read_profile(path, doc_);
        int m = current_;  // the profile's sex may pick another model
        if (p.sex && has_model() && *p.sex != model().model->meta.gender) {
          for (size_t i = 0; i < models_.size(); ++i) {
            if (models_[i].model->meta.gender == *p.sex) {
              m = static_cast<int>(i);
              break;
            }
          }
        }
        commit(p.document, m);
        if (p.units) view_.units = *p.units;
        saved_doc_ = doc_;
        post(Message::Level::Info, "opened profile " + path);
      },
      "could not open profile " + path + ": ", " (the current avatar is unchanged)");
}

bool EditorCore::open_session(const std::string& path) {
  clear_stale_messages();
  return log_.attempt(
      [&] {
        const SessionInputs s =
            session_inputs(doc_, read_session_measurements(path), achieved_as_typed());
        commit(s.document);
        post(Message::Level::Info, "read " + std::to_string(s.used) + " measurements from " + path);
      },
      "could not read session " + path + ": ", " (the current avatar is unchanged)");
}

std::vector<std::string> EditorCore::export_extensions() {
  return app::export_extensions();
}

std::map<std::string, std::string> EditorCore::export_metadata() const {
  if (!has_model()) return {};
  return app::export_metadata(model(), doc_, avatar_);
}

bool EditorCore::export_avatar(const std::string& path, smpl::ExportOptions options) {
  if (!has_model()) {
    post(Message::Level::Error, "nothing to export: open a model first");
    return false;
  }
  return log_.attempt(
      [&] {
        options.extras = export_metadata();
        smpl::export_avatar(path, *model().model, avatar_.betas, options);
        post(Message::Level::Info, "exported " + path);
      },
      "could not export " + path + ": ");
}

// ---------------------------------------------------------------------------------------------
// Comparison
void EditorCore::pin_comparison(const std::string& label) {
  if (!has_model()) return;
  comparison_ = pin(label, avatar_);
  post(Message::Level::Info, "pinned the current avatar for comparison");
}

void EditorCore::clear_comparison() {
  comparison_.reset();
  view_.compare = CompareMode::Off;
}

// ---------------------------------------------------------------------------------------------
// Messages and commands
void EditorCore::clear_stale_messages() {
  log_.clear_stale();
}

void EditorCore::post(Message::Level level, const std::string& text) {
  log_.post(level, text);
}

bool EditorCore::run_command(const std::string& line) {
  return app::run_command(*this, line);
}

}  // namespace caliper::app
