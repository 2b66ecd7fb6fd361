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
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "app/units.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"
#include "caliper/regressor.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/body_model.hpp"

namespace caliper::app {

/// Every avatar file format the editor exports, in the order a file dialog should offer them
/// (extension, description, rigged): smpl::export_formats().
const std::vector<smpl::ExportFormat>& export_formats();

/// Which regressor turns the measurements into betas.
enum class RegressorChoice { R2, R4, R5, R6, NoiseAware };
std::string to_string(RegressorChoice choice);  ///< "R2" .. "R6", "noise-aware"
/// Parses "R2".."R6", "noise-aware"/"noise_aware"/"NA" (case-insensitive).
std::optional<RegressorChoice> parse_regressor_choice(const std::string& text);
/// Input ids of a choice (noise-aware: the six R6 inputs).
const std::vector<std::string>& choice_inputs(RegressorChoice choice);

/// A body model with its fitted regressors, shared read-only.
struct ModelEntry {
  std::string label;  ///< shown in the UI, e.g. "caliper-female" or the file name
  std::shared_ptr<const smpl::BodyModel> model;
  std::shared_ptr<const RegressorSet> regressors;
  LandmarkTable landmarks;  ///< landmarks_for(*model)
};

/// Builds a ModelEntry: validates the model, computes its landmark table and fits the
/// regressors (train_regressors). Throws smpl::ModelError / caliper::CaliperError naming the
/// problem (e.g. a model without the landmarks the regressors need).
ModelEntry make_model_entry(std::shared_ptr<const smpl::BodyModel> model, const std::string& label,
                            const TrainOptions& options = {});

/// The undoable part of the editor state.
struct Document {
  MeasurementMap values;  ///< typed or dragged inputs, SI
  RegressorChoice regressor = RegressorChoice::R2;
  bool hierarchical = true;
  int level = 1;  ///< 1..3, used when hierarchical
  bool operator==(const Document& o) const {
    return values == o.values && regressor == o.regressor && hierarchical == o.hierarchical &&
           level == o.level;
  }
  bool operator!=(const Document& o) const { return !(*this == o); }
};

/// The human name of a measurement for the UI ("Arm span (fingertips)"; "Weight", "Volume").
std::string measurement_label(const std::string& id);
/// One line describing a regressor choice, e.g. "R4: height, weight, inseam, arm span".
std::string describe_regressor(RegressorChoice choice);

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

/// The current avatar and what is derived from it.
struct AvatarView {
  Eigen::VectorXd betas;    ///< model.num_betas() (zeros beyond the regressor's outputs)
  Eigen::VectorXd beta_sd;  ///< posterior SD per beta (noise-aware), else empty
  smpl::Vertices vertices;  ///< rest pose, translated so that the floor (min y) is at y = 0
  Plausibility plausibility;
  MeasurementMap achieved;         ///< measured on the avatar (13 + volume + weight when final)
  bool achieved_complete = false;  ///< false during a drag (lengths only; cheap)
  /// Per-vertex colour-map values: plausibility (metres of displacement due to components
  /// beyond 2 SD) and uncertainty (posterior positional SD in metres; 0 without noise-aware).
  std::vector<float> implausible_displacement;
  std::vector<float> uncertainty;
};

/// A comparison avatar pinned from an earlier state.
struct Comparison {
  std::string label;
  smpl::Vertices vertices;  ///< floor at y = 0
  MeasurementMap values;
  std::vector<float> difference;  ///< per-vertex |current - pinned|, metres (same model only)
};

/// A message for the window's status area.
struct Message {
  enum class Level { Info, Warning, Error } level = Level::Info;
  std::string text;
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
  /// The value shown for `id`: the input when it is editable, else the avatar's measurement.
  std::optional<double> shown_value(const std::string& id) const;

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
  bool can_undo() const { return !undo_.empty(); }
  bool can_redo() const { return !redo_.empty(); }
  bool undo();
  bool redo();

  // ---- Files ---------------------------------------------------------------------------
  /// Measurement profile JSON (docs/editor.md): {"format": "caliper-profile", "version": 1,
  /// "units", "sex", "model", "regressor", "hierarchical", "level", "measurements": {id: SI}}.
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
  const std::deque<Message>& messages() const { return messages_; }
  void post(Message::Level level, const std::string& text);
  /// Drops the errors and warnings of earlier commands (each edit starts with a clean status).
  void clear_stale_messages();

  /// Runs one text command (the headless script language, docs/editor.md), e.g.
  /// "set height 180 cm", "units imperial", "level 2", "undo". Returns false (with a
  /// message) for an unknown or malformed command. View-only commands that need a renderer
  /// (screenshot) are not handled here: the caller handles them first.
  bool run_command(const std::string& line);

 private:
  /// Pushes the current document onto the undo history (before an edit that changes it).
  void push_undo();
  /// Pushes `before` onto the undo history (at most kMaxUndo steps) and clears the redo history.
  void remember(const Document& before);
  /// Applies `d` as one undoable step; when apply() throws, state and history are unchanged.
  void commit(const Document& d);
  void apply(const Document& doc, bool complete);
  /// Moves one document from the back of `from` to the current state, pushing the current one
  /// onto `to` (undo: from = undo_, to = redo_; redo: the reverse). False when `from` is empty
  /// or the document cannot be applied (a message is posted naming `what`).
  bool step_history(std::vector<Document>& from, std::vector<Document>& to, const char* what);
  void recompute(bool complete);
  bool check_value(const std::string& id, double value_si);
  /// A short account of what differs between two documents, for undo/redo messages.
  std::string describe_change(const Document& from, const Document& to) const;

  std::vector<ModelEntry> models_;
  int current_ = -1;
  Document doc_;
  Document saved_doc_;  ///< has_unsaved_changes() compares with this
  bool baseline_set_ = false;
  ViewSettings view_;
  AvatarView avatar_;
  std::optional<Comparison> comparison_;
  std::vector<Document> undo_, redo_;
  bool dragging_ = false;
  std::uint64_t revision_ = 0;
  std::deque<Message> messages_;
  Eigen::VectorXd shaped_;  // scratch: 3V
};

}  // namespace caliper::app
