/// \file editor_files.hpp
/// The editor's files without the editor: measurement profiles (docs/editor.md), the
/// measurements of VR measuring sessions, and the metadata and formats of exported avatars.
/// Values are SI (metres, kilograms). Readers throw caliper::CaliperError (InvalidInputError,
/// JsonError, JournalError) naming what was wrong; writers write atomically.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "app/document.hpp"
#include "app/recompute.hpp"
#include "app/units.hpp"
#include "caliper/json.hpp"
#include "smpl/avatar_export.hpp"

namespace caliper::app {

// ---- Measurement profiles ---------------------------------------------------------------
/// The profile JSON of `doc`: {"format": "caliper-profile", "version": 1 (2 when
/// doc.arm_taken_hanging, so that editors without the field refuse it), "units", "model",
/// "sex" (both only with a `model`), "regressor", "hierarchical", "level", "arm_taken_hanging":
/// true (only when doc.arm_taken_hanging: measurements' arm_length is then the tape's value on
/// the hanging arm), "measurements": {id: SI} (the editable inputs), "betas"}.
Json profile_json(const Document& doc, UnitSystem units, const ModelEntry* model,
                  const Eigen::VectorXd& betas);

/// A profile as read: the document (fields the file leaves out keep the base document's, but
/// for "arm_taken_hanging": absent is false; its measurements are added to the base's values),
/// and the units and sex it names, if any.
struct Profile {
  Document document;
  std::optional<UnitSystem> units;  ///< absent or not a unit system: std::nullopt
  std::optional<std::string> sex;
};
/// Reads a profile file over `base`. Throws (nothing is changed) when the file is not JSON, not
/// a caliper profile, of a version other than 1 or 2, names an unknown regressor or a level
/// outside 1..3, has an "arm_taken_hanging" that is not true or false, or holds a measurement
/// outside its plausible range (measurement_range's error range).
Profile read_profile(const std::string& path, const Document& base);

// ---- VR measuring sessions --------------------------------------------------------------
/// The measurements of a session file: a JSON object with a "measurements" object ({id: SI} or
/// {id: {"value": SI}}) or array ([{"id", "value"}]), also under "result"; or a JSON Lines
/// journal, where each step's value is the mean of its takes after its last redo. Throws when
/// the file cannot be read or is neither.
MeasurementMap read_session_measurements(const std::string& path);

/// `base` with the usable session measurements (known ids within their plausible range) as
/// inputs, at the most detailed hierarchy level they provide (never lower than base's), and
/// the other inputs the result edits started from `achieved` (the avatar's own values, in the
/// convention of base's inputs: as_typed()). A session's arm length was taken out sideways
/// (the VR protocol): with one, the result's arm_taken_hanging is false.
struct SessionInputs {
  Document document;
  int used = 0;  ///< how many measurements were usable
};
/// Throws caliper::InvalidInputError when no measurement is usable.
SessionInputs session_inputs(const Document& base, const MeasurementMap& found,
                             const MeasurementMap& achieved);

// ---- Exported avatars -------------------------------------------------------------------
/// Every avatar file format the editor exports, in the order a file dialog should offer them
/// (extension, description, rigged): smpl::export_formats().
const std::vector<smpl::ExportFormat>& export_formats();
/// Their extensions (lower case with the dot, the first is the default).
std::vector<std::string> export_extensions();
/// The metadata `caliper create` writes, for `avatar` made from `doc` on `entry`: generator,
/// regressor, model, betas and measurements (JSON text), and open_model_sex for an open default
/// model (made by caliper-modelgen), so that `caliper measure` on the file picks that model.
std::map<std::string, std::string> export_metadata(const ModelEntry& entry, const Document& doc,
                                                   const AvatarView& avatar);

}  // namespace caliper::app
