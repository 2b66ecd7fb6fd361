/// \file document.hpp
/// The editor's document: what the user edits and what undo/redo restore (the typed or dragged
/// measurement inputs, the regressor choice and the hierarchy level), and the rules that follow
/// from it alone: which regressor turns it into betas and which inputs the user may edit
/// (Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 4: level 1 edits height and weight
/// (R2), level 2 adds inseam height and arm span (R4), level 3 adds arm length and hip width
/// (R6)). Values are SI (metres, kilograms). No model, avatar, file or message here.
///
/// The current body model is not part of the document: choosing another model is not an undo
/// step (the inputs are kept and apply to the new model).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "app/units.hpp"
#include "caliper/measurements.hpp"

namespace caliper::app {

/// Which regressor turns the measurements into betas.
enum class RegressorChoice { R2, R4, R5, R6, NoiseAware };
std::string to_string(RegressorChoice choice);  ///< "R2" .. "R6", "noise-aware"
/// Parses "R2".."R6", "noise-aware"/"noise_aware"/"NA" (case-insensitive).
std::optional<RegressorChoice> parse_regressor_choice(const std::string& text);
/// Input ids of a choice (noise-aware: the six R6 inputs).
const std::vector<std::string>& choice_inputs(RegressorChoice choice);
/// Input ids of hierarchy level 1..3 (below 1 counts as 1, above 3 as 3): those of R2, R4, R6.
const std::vector<std::string>& level_inputs(int level);

/// The undoable part of the editor state.
struct Document {
  MeasurementMap values;  ///< typed or dragged inputs, SI
  RegressorChoice regressor = RegressorChoice::R2;
  bool hierarchical = true;
  int level = 1;  ///< 1..3, used when hierarchical
  /// values["arm_length"] was taken with a tape on the relaxed hanging arm (shoulder tip over
  /// the elbow to the wrist), not with the arm out sideways as the model's arm length is: the
  /// recomputation maps it with the model's hanging_arm_map() (app/recompute.hpp).
  bool arm_taken_hanging = false;
  bool operator==(const Document& o) const {
    return values == o.values && regressor == o.regressor && hierarchical == o.hierarchical &&
           level == o.level && arm_taken_hanging == o.arm_taken_hanging;
  }
  bool operator!=(const Document& o) const { return !(*this == o); }
};

/// The regressor that turns the inputs of `doc` into betas: the chosen one, or the hierarchy
/// level's (R2, R4, R6) when hierarchical mode is on with R2-R6.
RegressorChoice active_regressor(const Document& doc);
/// Ids the user can edit in `doc`: the hierarchy level's inputs when hierarchical, else the
/// chosen regressor's.
const std::vector<std::string>& editable_inputs(const Document& doc);
/// Starts every id of `ids` that is not in `kept` from the avatar's own measurement in
/// `achieved` (when it has one), so that a new input does not make the avatar jump.
void start_from_avatar(Document& doc, const std::vector<std::string>& ids,
                       const std::vector<std::string>& kept, const MeasurementMap& achieved);

/// The human name of a measurement for the UI ("Arm span (fingertips)"; "Weight", "Volume"):
/// measurement_name (app/units.hpp), under the name the editor uses.
std::string measurement_label(const std::string& id);
/// The name of input `id` in `doc`: measurement_label(id), but "Arm length (hanging)" for the
/// arm length when doc.arm_taken_hanging (short enough for the panel's name column).
std::string input_label(const Document& doc, const std::string& id);
/// How to take measurement `id` (a tooltip for the editor's input rows), e.g. for the arm
/// length that it is taken with the arm out sideways and what a tape on the hanging arm reads;
/// "" for an id without a hint.
std::string measurement_hint(const std::string& id);
/// One line describing a regressor choice, e.g. "R4: height, weight, inseam, arm span".
std::string describe_regressor(RegressorChoice choice);
/// A short account of what differs between two documents, values shown in `units`, for
/// undo/redo messages ("Overall height 170.0 -> 165.2 cm; hierarchical level 2"; "arm length
/// taken hanging" / "arm length out sideways" when the arm's convention changed); "no visible
/// change" when nothing the user sees differs.
std::string describe_change(const Document& from, const Document& to, UnitSystem units);

}  // namespace caliper::app
