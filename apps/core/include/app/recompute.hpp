/// \file recompute.hpp
/// From a Document to the avatar: the body models the editor offers (with their fitted
/// regressors) and the pure function that turns a document into betas, rest-pose vertices,
/// plausibility, the measurements achieved on the avatar and the colour-map values (Pujades et
/// al., The Virtual Caliper, TVCG 2019, Sec. 4 and 5). Values are SI (metres, kilograms).
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "app/document.hpp"
#include "caliper/mapping.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "smpl/body_model.hpp"

namespace caliper::app {

/// A model's map from an arm length taken with a tape on the hanging arm to the model's own arm
/// length (caliper::hanging_arm_map(): virtual = a * hanging + b), worked out on first use and
/// kept: it takes 20-45 ms, so opening a model does not pay for it and no frame pays twice.
/// Thread-safe; the copies of a ModelEntry share one.
class HangingArmMap {
 public:
  explicit HangingArmMap(std::shared_ptr<const smpl::BodyModel> model);
  /// The map, or nullptr when the model cannot make one (then reason() says why).
  const LinearMap* get() const;
  /// Why the model cannot map a hanging arm (what hanging_arm_map() threw); "" when it can.
  const std::string& reason() const;

 private:
  void compute() const;
  std::shared_ptr<const smpl::BodyModel> model_;
  mutable std::once_flag once_;
  mutable std::optional<LinearMap> map_;
  mutable std::string reason_;
};

/// A body model with its fitted regressors, shared read-only.
struct ModelEntry {
  std::string label;  ///< shown in the UI, e.g. "caliper-female" or the file name
  std::shared_ptr<const smpl::BodyModel> model;
  std::shared_ptr<const RegressorSet> regressors;
  LandmarkTable landmarks;  ///< landmarks_for(*model)
  /// The model's landmarks and closedness for measure_all(), made once by make_model_entry();
  /// null: worked out at each complete measurement.
  std::shared_ptr<const ModelMeasureInfo> measure_info;
  /// The model's shape curve (caliper/shape_curve.hpp), if it carries one: R2-R6 start from the
  /// general population's body of the height and weight (linear_betas()).
  std::optional<ShapeCurve> curve;
  /// With a curve: the exact measurer over all the model's betas (up to kMaxMeasurerBetas), so
  /// that a slider event measures the curve's body from precomputed maps instead of shaping and
  /// measuring the mesh (docs/performance.md, the drag frame).
  std::shared_ptr<const ShapeMeasurer> curve_measurer;
  /// The map of an arm length taken hanging onto the model's (Document::arm_taken_hanging),
  /// made by make_model_entry() and worked out on first use; null: the entry has none.
  std::shared_ptr<const HangingArmMap> hanging_arm;
  /// The model's shape directions in single precision, for the previews of a drag
  /// (recompute(..., complete = false)): a slider event reads half the bytes (3.7 MB instead of
  /// 7.4 for the open models), and the body moves by under a micrometre. The complete recompute
  /// at the drag's end uses the model's double-precision directions. Null: always those.
  std::shared_ptr<const Eigen::MatrixXf> preview_shapedirs;
};

/// Builds a ModelEntry: validates the model, computes its landmark table and fits the
/// regressors (train_regressors). Throws smpl::ModelError / caliper::CaliperError naming the
/// problem (e.g. a model without the landmarks the regressors need).
ModelEntry make_model_entry(std::shared_ptr<const smpl::BodyModel> model, const std::string& label,
                            const TrainOptions& options = {});

/// Why `entry` cannot map an arm length taken hanging onto its own ("" when it can: its
/// hanging-arm map is then worked out, once). For the UI: the "taken hanging" toggle is off
/// limits with this as its tooltip.
std::string hanging_arm_unavailable(const ModelEntry& entry);
/// The hanging-arm map of `entry` (worked out once, then kept). Throws
/// caliper::InvalidInputError naming the model and why it has none, and what to do instead.
const LinearMap& hanging_arm(const ModelEntry& entry);

/// The inputs of `doc` as its active regressor takes them on `entry`: the editable inputs, the
/// arm length taken hanging (doc.arm_taken_hanging) mapped onto the model's arm length.
/// Throws caliper::InvalidInputError when an editable input has no value or the hanging arm
/// cannot be mapped (hanging_arm()).
MeasurementMap regression_inputs(const Document& doc, const ModelEntry& entry);

/// `measured` (measured on an avatar of `entry`) in the convention of `doc`'s inputs: with
/// doc.arm_taken_hanging, arm_length becomes the length on the hanging arm that the model's map
/// turns into it ((v - b) / a), or is left out when the model has no map; otherwise unchanged.
MeasurementMap as_typed(const Document& doc, const ModelEntry& entry, MeasurementMap measured);

/// `doc` with the arm length taken hanging (`hanging`) or out sideways, its arm_length value
/// converted by the model's map (hanging = (virtual - b) / a and back) so that the avatar does
/// not change. Without a map: turning the convention off drops an arm_length that is not an
/// input of `doc` (nothing to convert it with); anything else throws what hanging_arm() throws.
Document with_arm_taken_hanging(const Document& doc, const ModelEntry& entry, bool hanging);

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

/// The measurements of the model's mean shape (v_template) for the six R6 inputs, without
/// circumferences: the inputs a new document starts from. Throws caliper::CaliperError when the
/// mean shape cannot be measured.
MeasurementMap mean_shape_inputs(const ModelEntry& entry);

/// The avatar of `doc` on `entry`: betas from the document's active regressor (noise-aware:
/// posterior mean and SD), rest-pose vertices with the floor at y = 0, plausibility and the
/// colour-map values. `complete`: every measurement (circumferences, volume, weight) and the
/// uncertainty map; otherwise lengths only (cheap, for drags; uncertainty all 0). An arm
/// length taken hanging is mapped first (regression_inputs()). Pure: same inputs, same output.
/// Throws caliper::InvalidInputError when an editable input has no value, the hanging arm
/// cannot be mapped, the model lacks the regressor, or the betas are not finite.
AvatarView recompute(const Document& doc, const ModelEntry& entry, bool complete);

}  // namespace caliper::app
