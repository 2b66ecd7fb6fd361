/// \file avatar.hpp
/// The convenience pipeline apps share: measurements (optionally mapped real -> virtual) ->
/// regressor -> betas -> rest-pose body -> achieved measurements and plausibility.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "caliper/mapping.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// Result of create_avatar().
struct Avatar {
  Eigen::VectorXd betas;  ///< model.num_betas() values (zeros beyond the regressor's outputs)
  /// Posterior covariance of the regressor's betas (noise-aware regressor only).
  std::optional<Eigen::MatrixXd> covariance;
  MeasurementMap input;       ///< the inputs as given
  MeasurementMap mapped;      ///< the inputs after the mapping (equal to input without mapping)
  MeasurementMap achieved;    ///< measure_all() of the avatar (13 + volume + weight + circumf.)
  Plausibility plausibility;  ///< of the regressor's betas
  std::vector<ValidationMessage> messages;  ///< validate_measurements(input)
  smpl::Vertices vertices;                  ///< rest-pose vertices of the avatar
};

/// Options of create_avatar().
struct AvatarOptions {
  const MeasurementMapping* mapping = nullptr;  ///< applied to the inputs first, if given
  bool circumferences = true;                   ///< in `achieved`
  bool refuse_invalid = true;  ///< throw InvalidInputError when validation finds an Error
  /// After the regressor's prediction (the paper's linear one, or the noise-aware posterior
  /// mean), refine the betas with refine_to_inputs() so that every given input (weight included)
  /// is reproduced exactly. Off by default (the paper's behaviour).
  bool exact_inputs = false;
  /// Plain (linear) regressors: start from the general population's body for the given height
  /// and weight when the model carries a shape curve (shape_curve.hpp; the open models do),
  /// instead of from the mean body. The inputs are reproduced as by the paper's regressor; the
  /// directions they do not measure follow real people of that height and weight (the hip of
  /// the heaviest and thinnest: docs/evaluation.md, section 4). false: the paper's regressor.
  bool shape_curve = true;
  /// Check the regressor's model signature against `model` (ModelMismatchError). The check
  /// computes the model's fingerprint (a pass over the template and shape directions); a caller
  /// that makes many avatars with one model and regressor checks once (`regressor.signature()
  /// .check(model)`) and sets this to false for every avatar.
  bool check_model = true;
  /// The model's landmarks and closedness made once (ModelMeasureInfo(model), from this same
  /// model) by a caller that makes many avatars of one model; null: worked out per avatar.
  const ModelMeasureInfo* model_info = nullptr;
  /// Noise-aware regressor only: the population the person comes from (population_prior()),
  /// instead of the model's own N(0, I). A plain regressor refuses it (InvalidInputError).
  const ShapePrior* prior = nullptr;
};

/// The betas of a plain (linear) regressor for `inputs` (its inputs; extra keys ignored). Without
/// `curve`, or for a regressor whose inputs lack height or weight: the paper's prediction,
/// regressor.predict(inputs) (its k betas). With the model's shape curve (shape_curve.hpp):
/// beta = c + A (f - f(c)) over the regressor's k betas, c the curve's betas for the height and
/// weight (all the model's betas, which is what is returned), A the regressor's slopes, f the
/// inputs' features and f(c) the same features measured on the curve's body. To first order the
/// body reproduces the inputs as the paper's prediction does (A is the minimum-norm inverse of
/// the linearised measurements), and where the inputs measure nothing it is the general
/// population's body of that height and weight. Where a length is not linear in the betas (the
/// neutral model's arm length), the step is repeated from the body it made on the lengths alone
/// (the weight keeps the first step's compromise), at most 3 times, until every length input is
/// within 0.01 mm. `landmarks`: landmarks_for(model).
/// `measurer`: used for f(c) when it covers the model's betas (exact and faster; its
/// definitions must hold the regressor's length inputs), else the mesh is shaped and measured.
/// Throws what predict() throws for a missing or bad input.
Eigen::VectorXd linear_betas(const smpl::BodyModel& model, const LinearRegressor& regressor,
                             const MeasurementMap& inputs, const ShapeCurve* curve,
                             const LandmarkTable& landmarks,
                             const ShapeMeasurer* measurer = nullptr);

/// Gauss-Newton refinement of `betas` (k <= model.num_betas() values) so that the rest-pose
/// body reproduces every value in `targets` (paper measurement ids and "weight"; other keys
/// ignored): each step is the minimum-norm update J'(J J')^-1 (target - current) in feature
/// space (weight as the cube root of its volume by `formula`), with analytic Jacobians (landmark
/// shape rows; the lowest vertex for heights; the volume gradient from the faces). Stops after
/// `max_iterations` or when every residual is below 1e-9 m. Starting from a regressor's output
/// the changes are small (the paper's linear fit is already close). Throws InvalidInputError for
/// bad targets, more targets than betas, or LandmarkError for a missing landmark.
Eigen::VectorXd refine_to_inputs(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
                                 const MeasurementMap& targets, const WeightFormula& formula,
                                 int max_iterations = 6);

/// Avatar from a plain regressor. Checks the regressor against the model (ModelMismatchError),
/// validates the inputs (InvalidInputError listing every Error message when refuse_invalid),
/// and throws InvalidInputError naming a missing input.
Avatar create_avatar(const smpl::BodyModel& model, const LinearRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options = {});

/// Avatar from the noise-aware regressor (any subset of its inputs; covariance filled).
Avatar create_avatar(const smpl::BodyModel& model, const NoiseAwareRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options = {},
                     const NoiseLevels& noise = {});

}  // namespace caliper
