/// \file shape_curve.hpp
/// The general population's body for a height and a weight, as a smooth curve in a model's
/// shape space (issue 11, Must show 4).
///
/// The paper's regressors are linear in (height, cube root of the weight's volume), so the girths
/// of an R2 avatar are linear in those two features too. Real people's are not: over NHANES the
/// hip grows about linearly with the weight and the waist with its cube root, so any linear map
/// misses the thinnest and the heaviest by 2-12 cm (docs/evaluation.md, section 4). The curve is
/// E[betas | height, weight] over the registered general-population subjects (NHANES), a full
/// quadratic in the standardised height and cube root of the weight (or the weight itself:
/// ShapeCurve::weight_input), fitted by the generator and stored in the model file
/// (`BodyModel::meta.extra["shape_curve"]`, JSON). A linear regressor then starts from the
/// curve's body instead of the mean body (create_avatar(), AvatarOptions::shape_curve): the
/// inputs still decide the betas along the directions they measure, the curve the rest.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "smpl/body_model.hpp"

namespace caliper {

/// A quadratic curve betas(height, weight) over a model's betas.
struct ShapeCurve {
  /// The curve's second input: the cube root of the weight (the paper's feature; every model
  /// made so far) or the weight itself, which follows the heaviest people's bodies more closely
  /// (docs/models.md, Limits). The file names it ("inputs"); a file without the name is the
  /// cube root's.
  enum class WeightInput { kCubeRoot, kKilograms };
  WeightInput weight_input = WeightInput::kCubeRoot;
  std::string population;        ///< e.g. "NHANES 2017-2020 development half"
  int subjects = 0;              ///< how many registered subjects it was fitted to
  Eigen::Vector2d center;        ///< of (height m, the weight input)
  Eigen::Vector2d scale;         ///< > 0: the standardised features are (x - center) / scale
  Eigen::Vector2d lo;            ///< the subjects' smallest (height, weight input) ...
  Eigen::Vector2d hi;            ///< ... and largest: the curve is not extrapolated beyond them
  Eigen::MatrixXd coefficients;  ///< B x 6: betas = C [1, h, w, h^2, h w, w^2]'

  /// The curve's betas (B values) for a height (m) and a weight (kg). Inputs beyond the
  /// subjects' range are taken at its edge (a quadratic turns outside its data); the regressor's
  /// correction carries the rest. Throws InvalidInputError for a non-finite or non-positive input.
  Eigen::VectorXd betas(double height_m, double weight_kg) const;
};

/// The six features [1, h, w, h^2, h w, w^2] of standardised (h, w).
Eigen::Matrix<double, 6, 1> shape_curve_features(double h, double w);

/// Least-squares fit of `betas` (n x B, one subject per row) on the quadratic features of
/// (height m, `weight_input` of the weight kg) with sample weights `weights` (n, >= 0). Throws
/// std::invalid_argument for mismatched sizes, fewer than 7 weighted subjects (the quadratic has
/// 6 coefficients), non-finite values or subjects that do not determine a quadratic.
ShapeCurve fit_shape_curve(
    const Eigen::VectorXd& heights, const Eigen::VectorXd& weights_kg, const Eigen::MatrixXd& betas,
    const Eigen::VectorXd& weights, const std::string& population,
    ShapeCurve::WeightInput weight_input = ShapeCurve::WeightInput::kCubeRoot);

/// The model metadata key: "shape_curve".
const char* shape_curve_meta_key();

/// Stores `c` in `model`'s metadata (JSON, doubles round-trip exactly). Throws
/// std::invalid_argument when its size is not the model's betas.
void set_shape_curve(smpl::BodyModel& model, const ShapeCurve& c);

/// The model's curve, nullopt when it carries none (SMPL files, older open models). Throws
/// std::runtime_error naming the entry and what to do when it is malformed (sizes, non-finite
/// numbers, a scale that is not positive, a range that is empty).
std::optional<ShapeCurve> shape_curve(const smpl::BodyModel& model);

}  // namespace caliper
