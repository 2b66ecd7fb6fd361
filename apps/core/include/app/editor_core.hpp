/// \file editor_core.hpp
/// The editor's model without any GL or UI (Pujades et al., The Virtual Caliper, TVCG 2019,
/// Sec. 4: "a desktop tool to type or drag measurements and see the avatar"). Commands in,
/// state out: panels read `state()` / `avatar()` and call the command methods; every command
/// either succeeds or leaves the state unchanged and posts a message.
///
/// Values are SI (metres, kilograms). The hierarchical adjustment follows the paper: level 1
/// edits height and weight (R2), level 2 adds inseam height and arm span (R4), level 3 adds
/// arm length and hip width (R6). Measurements not yet editable show the avatar's own values;
/// moving up a level starts the new inputs from those values so that the avatar does not jump.
///
/// EditorCore is a thin facade over the units that do the work: the undoable Document and its
/// rules (document.hpp), the pure recompute() of the avatar (recompute.hpp), a History of
/// documents (history.hpp), profiles, sessions and export metadata (editor_files.hpp), the
/// comparison avatar (comparison.hpp), the message log (messages.hpp) and the text command
/// language (commands.hpp). It holds the state they share and turns every failure into one
/// message (MessageLog::attempt).
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "app/comparison.hpp"
#include "app/document.hpp"
#include "app/editor_files.hpp"
#include "app/history.hpp"
#include "app/messages.hpp"
#include "app/recompute.hpp"
#include "app/units.hpp"
#include "smpl/avatar_export.hpp"

namespace caliper::app {

/// How the avatar is coloured.
enum class ColourMode { Skin, Plausibility, Uncertainty };
/// How the comparison avatar is shown.
enum class CompareMode { Off, SideBySide, Difference };

/// View settings (not undoable).
struct ViewSettings {
  UnitSystem units = UnitSystem::Metric;
  bool wireframe = false;
  bool overlay = true;  ///< measurement lines and values on the avatar
  ColourMode colour = ColourMode::Skin;
  CompareMode compare = CompareMode::Off;
  /// true: the 3D view keeps one scale (a 2.2 m tall box) so bodies of different heights look
  /// different, with a height ruler on the floor grid; false: it fits the avatar.
  bool fixed_scale = false;
};

class EditorCore {
 public:
  EditorCore() = default;

  // ---- Models --------------------------------------------------------------------------
  /// Adds a model to the list (e.g. the open models); the first one added becomes current.
  void add_model(ModelEntry entry);
  /// Loads an SMPL-family or project .npz/.pkl file, fits its regressors and makes it current.
  /// On failure posts an error and keeps the current model and avatar. Returns success.
  bool load_model_file(const std::string& path);
  /// Makes model `index` current (values are kept). Returns false (with a message) if out of
  /// range.
  bool select_model(int index);
  /// Selects the first model whose gender is `sex` ("female", "male", "neutral").
  bool select_sex(const std::string& sex);
  const std::vector<ModelEntry>& models() const { return models_; }
  int current_model() const { return current_; }
  bool has_model() const { return current_ >= 0; }
  const ModelEntry& model() const;  ///< precondition: has_model()

  // ---- Measurement inputs --------------------------------------------------------------
  /// Ids the user can edit now (the regressor's inputs; the hierarchy level's inputs).
  std::vector<std::string> editable_inputs() const;
  /// Sets an input (SI). Out of the plausible range (measurement_range's error range), NaN or
  /// not editable: error message, state unchanged, returns false. A warning-range value is
  /// accepted with a warning message.
  bool set_value(const std::string& id, double value_si);
  /// Sets an input given in display units (state().units) .
  bool set_display_value(const std::string& id, double shown);
  /// Slider drags: begin_drag() records one undo step; drag_value() updates the avatar cheaply
  /// (no circumferences, volume or weight); end_drag() completes the measurements.
  void begin_drag();
  bool drag_value(const std::string& id, double value_si);
  void end_drag();
  /// Between begin_drag() and end_drag(): the views may draw the body's simplified levels.
  bool dragging() const { return dragging_; }
  /// The value shown for `id`: the input when it is editable, else the avatar's measurement
  /// (as_typed(): an arm length taken hanging is shown as a hanging one).
  std::optional<double> shown_value(const std::string& id) const;
  /// The avatar's measurements in the convention of the inputs (app::as_typed()): with the arm
  /// length taken hanging, the avatar's arm as the hanging value that the model's map turns
  /// into it, so that it compares with what was typed.
  MeasurementMap achieved_as_typed() const;
  /// The arm length is taken with a tape on the hanging arm (`hanging`) or out sideways
  /// (Document::arm_taken_hanging). The value is converted by the model's map so that the
  /// avatar does not change; one undo step. Refused (message, state unchanged) without a model
  /// or for a model that cannot map a hanging arm (hanging_arm_unavailable()). Returns success.
  bool set_arm_taken_hanging(bool hanging);
  /// Why the current model cannot map an arm length taken hanging ("" when it can, or without
  /// a model); works the map out on the first call for a model (20-45 ms), then it is kept.
  std::string hanging_arm_unavailable() const;

  void set_regressor(RegressorChoice choice);
  /// Uses `choice` as the regressor from now on: hierarchical mode off (one undo step), so
  /// the choice takes effect at once (the UI's regressor list).
  void use_regressor(RegressorChoice choice);
  /// The regressor that turns the inputs into betas now: the chosen one, or the hierarchy
  /// level's (R2, R4, R6) when hierarchical mode is on with R2-R6.
  RegressorChoice active_regressor() const;
  void set_hierarchical(bool on);
  /// Level 1..3 (hierarchical mode). New inputs start from the avatar's own values.
  bool set_level(int level);
  /// Reset to the model's mean shape inputs (undoable).
  void reset();

  // ---- Undo / redo ---------------------------------------------------------------------
  /// Undo and redo post what they changed ("undone: height 170.0 cm -> 165.2 cm").
  bool can_undo() const { return history_.can_undo(); }
  bool can_redo() const { return history_.can_redo(); }
  bool undo();
  bool redo();

  // ---- Files ---------------------------------------------------------------------------
  /// Measurement profile JSON (docs/editor.md): {"format": "caliper-profile", "version": 1 (2 with
  /// the arm taken hanging), "units", "sex", "model", "regressor", "hierarchical", "level",
  /// "arm_taken_hanging" (only when true), "measurements": {id: SI}}.
  bool save_profile(const std::string& path);
  bool open_profile(const std::string& path);
  /// Reads the measurements of a VR measuring session file (JSON with a "measurements" object
  /// or array, or a JSON Lines journal whose records carry "id"/"value" pairs). Values become
  /// the inputs (undoable).
  bool open_session(const std::string& path);
  /// Exports the current avatar (rest pose, floor at 0) in the format of the file's extension,
  /// one of export_formats() (.glb, .gltf, .vrm, .fbx, .obj, .ply), with the same metadata as
  /// `caliper create` (generator, regressor, model, open_model_sex for an open model, betas,
  /// measurements; see export_metadata()), so that `caliper measure` on it picks the right
  /// model. `options` adds shape keys, bone names, a pose, an axis or a licence
  /// (smpl::ExportOptions); its extras are replaced by the metadata. Posts "exported PATH" or an
  /// error naming the problem (unknown extension listing the formats, a model without a licence
  /// for VRM, a write failure: an existing file is left as it was). Returns success.
  bool export_avatar(const std::string& path, smpl::ExportOptions options = {});
  /// export_avatar(path) with default options.
  bool export_mesh(const std::string& path) { return export_avatar(path); }
  /// The metadata export_avatar() writes for the current avatar (string values; betas and
  /// measurements as JSON text). Empty without a model.
  std::map<std::string, std::string> export_metadata() const;
  /// File extensions export_avatar() writes (lower case with the dot, the first is the default):
  /// those of export_formats().
  static std::vector<std::string> export_extensions();

  /// True when the inputs differ from the last saved or opened profile (or from the start).
  bool has_unsaved_changes() const { return doc_ != saved_doc_; }

  // ---- Comparison ----------------------------------------------------------------------
  /// Pins the current avatar as the comparison avatar.
  void pin_comparison(const std::string& label = "pinned");
  void clear_comparison();
  const std::optional<Comparison>& comparison() const { return comparison_; }

  // ---- State out -----------------------------------------------------------------------
  const Document& state() const { return doc_; }
  ViewSettings& view() { return view_; }
  const ViewSettings& view() const { return view_; }
  const AvatarView& avatar() const { return avatar_; }
  /// Increments whenever avatar().vertices change (renderers re-upload when it differs).
  std::uint64_t revision() const { return revision_; }
  const std::deque<Message>& messages() const { return log_.messages(); }
  void post(Message::Level level, const std::string& text);
  /// Drops the errors and warnings of earlier commands (each edit starts with a clean status).
  void clear_stale_messages();

  /// Runs one text command (app::run_command in commands.hpp: the headless script language,
  /// docs/editor.md), e.g. "set height 180 cm", "units imperial", "level 2", "undo". Returns
  /// false (with a message) for an unknown or malformed command. View-only commands that need
  /// a renderer (screenshot) are not handled here: the caller handles them first.
  bool run_command(const std::string& line);

 private:
  /// Makes `avatar` current: updates the comparison's difference and the revision.
  void show(AvatarView avatar);
  /// Makes `d` the document on model `model` (recomputing the avatar; `complete`: every
  /// measurement). Without a model only the document changes. Throws, changing nothing, when
  /// the avatar of `d` cannot be computed.
  void apply(const Document& d, bool complete, int model);
  void apply(const Document& d, bool complete) { apply(d, complete, current_); }
  /// apply() as one undo step (the current document is recorded only when apply succeeds).
  void commit(const Document& d, int model);
  void commit(const Document& d) { commit(d, current_); }
  /// Undo (`undo`) or redo one step, posting what changed. False when there is none or the
  /// document cannot be applied (a message names the problem).
  bool step_history(bool undo);
  bool check_value(const std::string& id, double value_si);
  /// `d` with its inputs `ids` that are not in `kept` started from the avatar's own values in
  /// d's convention (start_from_avatar, achieved_as_typed); when the current model cannot map
  /// an arm length taken hanging and the arm length is new, it is taken out sideways instead.
  Document start_new_inputs(Document d, const std::vector<std::string>& ids,
                            const std::vector<std::string>& kept) const;

  std::vector<ModelEntry> models_;
  int current_ = -1;
  Document doc_;
  Document saved_doc_;  ///< has_unsaved_changes() compares with this
  bool baseline_set_ = false;
  ViewSettings view_;
  AvatarView avatar_;
  std::optional<Comparison> comparison_;
  History<Document> history_{200};
  bool dragging_ = false;
  std::uint64_t revision_ = 0;
  MessageLog log_{50};
};

}  // namespace caliper::app
