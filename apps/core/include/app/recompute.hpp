/// \file recompute.hpp
/// From a Document to the avatar: the body models the editor offers (with their fitted
/// regressors) and the pure function that turns a document into betas, rest-pose vertices,
/// plausibility, the measurements achieved on the avatar and the colour-map values (Pujades et
/// al., The Virtual Caliper, TVCG 2019, Sec. 4 and 5). Values are SI (metres, kilograms).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "app/document.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "smpl/body_model.hpp"

namespace caliper::app {

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
};

/// Builds a ModelEntry: validates the model, computes its landmark table and fits the
/// regressors (train_regressors). Throws smpl::ModelError / caliper::CaliperError naming the
/// problem (e.g. a model without the landmarks the regressors need).
ModelEntry make_model_entry(std::shared_ptr<const smpl::BodyModel> model, const std::string& label,
                            const TrainOptions& options = {});

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
/// uncertainty map; otherwise lengths only (cheap, for drags; uncertainty all 0). Pure: same
/// inputs, same output. Throws caliper::InvalidInputError when an editable input has no value,
/// the model lacks the regressor, or the betas are not finite.
AvatarView recompute(const Document& doc, const ModelEntry& entry, bool complete);

}  // namespace caliper::app
