/// \file measurements.hpp
/// Body measurements as data (Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.1.2): the
/// paper's 13 measurements, each a Euclidean distance between two landmarks or the height of a
/// landmark above the floor (the floor is the mesh's lowest point, min y). Landmarks are named
/// (shared vocabulary) and map to vertex ids; a landmark's point is the mean of its vertices.
///
/// Landmark tables: a built-in table for the SMPL topology (6890 vertices, see
/// docs/measurements.md for the ids, which ones are verified and how the others were chosen),
/// overridden name by name by the model's own table (BodyModel::landmarks). Side and back
/// landmarks that neither table defines (left/right_waist, left/right_chest, torso_back) are
/// derived from the model's template by a documented geometric rule (derive_torso_landmarks).
///
/// Conventions: metres, +Y up, the body faces +Z, the subject's left is +X; rest pose (T-pose).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/weight.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// Landmark name -> vertex ids (0-based). A landmark's point is the mean of its vertices.
using LandmarkTable = std::map<std::string, std::vector<int>>;

/// Measurement id -> value (metres for lengths, kg for "weight", m^3 for "volume").
using MeasurementMap = std::map<std::string, double>;

/// How a measurement is taken.
enum class MeasurementKind {
  Distance,  ///< |point(from) - point(to)|
  Height,    ///< point(from).y - floor, floor = min y over all vertices
};

/// One measurement definition.
struct MeasurementDef {
  std::string id;        ///< shared-vocabulary id, e.g. "arm_span_fingertips"
  MeasurementKind kind;  ///< Distance or Height
  std::string from;      ///< landmark name
  std::string to;        ///< second landmark name (Distance only; empty for Height)
  std::string label;     ///< human-readable name, e.g. "Arm span (fingertips)"
};

/// Number of vertices of the SMPL / SMPL-H topology.
constexpr int kSmplVertexCount = 6890;

/// The paper's 13 measurements in the paper's order: height, nipple_height, navel_height,
/// inseam_height, shoulder_width, chest_width, waist_width, torso_depth, hip_width,
/// arm_span_fingertips, arm_span_wrists, arm_length, forearm_length.
const std::vector<MeasurementDef>& paper_measurements();

/// Definition by id; throws InvalidInputError naming the id and listing the known ones.
const MeasurementDef& measurement_def(const std::string& id);

/// Every landmark name of the shared vocabulary (head_top ... right_sole).
const std::vector<std::string>& landmark_names();

/// The built-in table for the SMPL topology (0-based vertex ids; see docs/measurements.md).
/// Contains every landmark except left/right_waist, left/right_chest and torso_back, which are
/// derived per model by derive_torso_landmarks().
const LandmarkTable& smpl_landmarks();

/// Adds left_waist/right_waist (body sides at navel height), left_chest/right_chest (body sides
/// at nipple height) and torso_back (back midline at navel height) to `table` when they are
/// missing and navel / left_nipple / right_nipple are present. Rule, on `template_vertices`
/// (rest pose): among vertices within +/- `band` metres of the reference height and with
/// |x - mid| below the shoulder half-width (mid and half-width from left/right_shoulder when
/// present; this excludes T-pose arms), the side landmark is
/// the vertex of largest (left) or smallest (right) x; torso_back is the vertex of smallest z
/// among those with |x - navel.x| < `band`. Existing entries are never replaced. Throws
/// LandmarkError if a landmark vertex id is out of range.
void derive_torso_landmarks(const smpl::Vertices& template_vertices, LandmarkTable& table,
                            double band = 0.015);

/// The mean iliocristale height of ANSUR II as a fraction of stature (0.608, women and men
/// alike; the rule of the v2 generator, apps/modelgen/src/makehuman_measures.hpp).
constexpr double kIliacCrestStatureFraction = 0.608;

/// Adds left_iliac_crest / right_iliac_crest (the top of the iliac crest at the body's sides:
/// the waist level of NHANES and the WHO, caliper::circumferences()) to `table` when missing, by
/// a rule on `template_vertices` (rest pose): among vertices within +/- `band` metres of
/// floor + `stature_fraction` * stature and with |x - mid| below the shoulder half-width (from
/// left/right_shoulder, which must be present), the vertex of largest (left) or smallest (right)
/// x. Never called by landmarks_for(): a model carries these landmarks or the caller asks for
/// the rule explicitly (`caliper evaluate nhanes --derive-iliac-crest`). Throws LandmarkError
/// when the shoulders are missing or no vertex lies in the band.
void derive_iliac_crest_landmarks(const smpl::Vertices& template_vertices, LandmarkTable& table,
                                  double stature_fraction = kIliacCrestStatureFraction,
                                  double band = 0.01);

/// The landmark table for a model: smpl_landmarks() when the model has 6890 vertices (else
/// empty), overridden name by name by model.landmarks, then derive_torso_landmarks() on
/// model.v_template. Throws LandmarkError if an id is out of range for the model.
LandmarkTable landmarks_for(const smpl::BodyModel& model);

/// Mean of the vertices of `ids`. Throws LandmarkError if `ids` is empty or out of range.
Eigen::Vector3d landmark_point(const smpl::Vertices& vertices, const std::vector<int>& ids);

/// The floor: min y over all vertices. Throws InvalidInputError for an empty array.
double floor_height(const smpl::Vertices& vertices);

/// True when every landmark `def` needs is in `landmarks`.
bool is_available(const MeasurementDef& def, const LandmarkTable& landmarks);

/// The subset of `defs` whose landmarks are all available.
std::vector<MeasurementDef> available_measurements(
    const LandmarkTable& landmarks, const std::vector<MeasurementDef>& defs = paper_measurements());

/// One measurement on `vertices` (rest pose). Throws LandmarkError naming the missing
/// landmark and the measurement.
double measure(const smpl::Vertices& vertices, const LandmarkTable& landmarks,
               const MeasurementDef& def);

/// Every measurement of `defs` whose landmarks are available (the others are left out).
MeasurementMap measure(const smpl::Vertices& vertices, const LandmarkTable& landmarks,
                       const std::vector<MeasurementDef>& defs = paper_measurements());

/// Options of measure_all().
struct MeasureOptions {
  bool circumferences = true;  ///< also chest/waist/hip/thigh_circumference (plane slicing)
  bool convex_hull = true;     ///< circumference as convex-hull perimeter (tape) or loop length
};

/// What measure_all() needs to know of the model itself, worked out once: its landmark table
/// (landmarks_for()), whether its faces close the surface (open_edge_count() == 0, a pass
/// over every edge through a hash table: milliseconds for a 25,000-face mesh, more than the
/// rest of a body's measurements) and the formula that weighs its bodies (weight_formula_of(),
/// which parses the model's own entry when it has one). A caller that measures many bodies of
/// one model makes it once and passes it to every call. Throws what landmarks_for() and
/// weight_formula_of() throw.
struct ModelMeasureInfo {
  explicit ModelMeasureInfo(const smpl::BodyModel& model);
  LandmarkTable landmarks;
  bool closed = false;           ///< the faces close the surface: volume and weight can be measured
  WeightFormula weight_formula;  ///< weight_formula_of(model)
};

/// Everything `caliper measure` reports for a rest-pose body of `model` with vertices
/// `vertices` (#V x 3 = model.num_vertices()): the available paper measurements, "volume"
/// (m^3), "weight" (kg, by weight_formula_of(model)) and, if asked, the
/// circumferences that can be computed. "volume" and "weight" only when the model's faces close
/// the surface (open_edge_count() == 0): an open mesh such as a hand has no volume, and they are
/// left out. Throws InvalidInputError for a vertex count mismatch.
MeasurementMap measure_all(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                           const MeasureOptions& options = {});

/// measure_all() with the model's `info` made beforehand (ModelMeasureInfo(model): it must
/// have been made from this same model); the same values.
MeasurementMap measure_all(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                           const ModelMeasureInfo& info, const MeasureOptions& options = {});

/// Rest-pose vertices of `model` for `betas`: v_template + shapedirs * betas (betas may be
/// shorter than model.num_betas(); missing ones are 0). Throws InvalidInputError if longer or
/// non-finite.
smpl::Vertices shaped_vertices(const smpl::BodyModel& model, const Eigen::VectorXd& betas);

// ---------------------------------------------------------------------------------------------
// The arm as surveys measure it (ANSUR II): hanging straight at the side.

/// The landmarks behind hanging_arm_length(): per side (0 left, 1 right) the acromion at rest
/// and the wrist and radiale with the arm hanging (radiale NaN when the model has no
/// left/right_radiale landmark). Each shoulder joint (SMPL joints 16 and 17) is rotated 90
/// degrees down about the body's front axis and a vertex follows by the share of its skinning
/// weight on that shoulder and the joints below it; the acromion, a bony point of the scapula
/// that a rotation of the shoulder joint leaves in place, stays where it is. Needs the model's
/// joint regressor, parents, skinning weights and the shoulder and wrist landmarks of its own
/// table (BodyModel::landmarks, or the table given): ModelMismatchError without SMPL's joints,
/// regressor or weights for these vertices, LandmarkError naming a missing landmark.
struct HangingArms {
  Eigen::Vector3d acromion[2];
  Eigen::Vector3d wrist[2];
  Eigen::Vector3d radiale[2];
};
HangingArms hanging_arms(const smpl::BodyModel& model, const smpl::Vertices& vertices);
/// The same with the landmarks of `landmarks` (e.g. landmarks_for(model), for an SMPL file
/// that carries no table of its own) instead of the model's own table.
HangingArms hanging_arms(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                         const LandmarkTable& landmarks);

/// Shoulder-to-wrist length as ANSUR II measures acromion-radiale plus radiale-stylion length:
/// acromion to wrist with the arm hanging (hanging_arms()). Mean of left and right, metres.
/// Longer than the paper's virtual arm_length (shoulder to wrist landmark in the T-pose) by
/// about 7 cm on the open models: the acromion sits above the shoulder joint.
double hanging_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices);
/// The same with the landmarks of `landmarks` (hanging_arms()).
double hanging_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                          const LandmarkTable& landmarks);

/// Acromion-radiale length as ANSUR II measures it: acromion to radiale with the arm hanging.
/// Mean of left and right, metres; NaN when the model has no radiale landmarks (SMPL files).
double hanging_upper_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices);

// ---------------------------------------------------------------------------------------------
// Input validation (for apps: CLI, editor, VR session).

/// Severity of a validation message.
enum class Severity { Warning, Error };

/// One problem with an input measurement.
struct ValidationMessage {
  Severity severity = Severity::Error;
  std::string id;      ///< measurement id (or "arm_span_fingertips/height" for a ratio)
  double value = 0.0;  ///< the offending value (or ratio)
  double min = 0.0;    ///< expected range, same unit as value
  double max = 0.0;
  std::string message;  ///< plain words naming the value and the expected range, with units
};

/// Expected range of one measurement (metres; weight kg).
struct MeasurementRange {
  double error_min, error_max;      ///< outside: an error (not a plausible human)
  double warning_min, warning_max;  ///< outside: a warning (unusual adult)
};

/// The range used by validate_measurements() for `id` (all 13, weight, circumferences).
/// Throws InvalidInputError for an unknown id.
MeasurementRange measurement_range(const std::string& id);

/// Checks input measurements: NaN/infinite or non-positive values are errors, unknown ids are
/// warnings (they are ignored by the regressors);
/// values outside measurement_range() are errors or warnings (e.g. height 0.5-2.5 m is the error
/// range, 1.4-2.1 m the warning range); inconsistent pairs are checked when both are present:
/// arm_span_fingertips/height (error outside 0.7-1.3, warning outside 0.9-1.12),
/// inseam_height/height (0.3-0.6; 0.38-0.52), arm_length/height (0.2-0.45; 0.27-0.38),
/// hip_width/height (0.1-0.35; 0.14-0.28) and the BMI from weight and height (id "bmi": error
/// outside 10-80, warning outside 15-45 kg/m^2). Returns an empty vector when all is well.
std::vector<ValidationMessage> validate_measurements(const MeasurementMap& values);

/// True when any message is an Error.
bool has_errors(const std::vector<ValidationMessage>& messages);

}  // namespace caliper
