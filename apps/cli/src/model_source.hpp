/// \file model_source.hpp
/// Where the `caliper` command gets its body model and regressors: `--model FILE` (any
/// SMPL-family file through smpl::load_model) or the open default model for the sex
/// (assets/models/caliper-<sex>.npz, located by find_assets_dir()); regressors trained in
/// process (the paper's 2^10 corners) or loaded with `--regressors FILE`.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "caliper/measurements.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "smpl/body_model.hpp"

namespace caliper::cli {

/// A loaded model and its regressors (immutable once built; shared between batch threads).
struct ModelBundle {
  smpl::BodyModel model;
  std::string path;  ///< file it was loaded from
  RegressorSet regressors;
  /// The model's landmarks and closedness for measure_all(), made once at load; empty when the
  /// model's landmarks are broken (each avatar then reports the LandmarkError itself).
  std::optional<ModelMeasureInfo> measure_info;
  /// The model's shape curve (caliper/shape_curve.hpp): plain regressors start from the general
  /// population's body of the height and weight. Empty when the model carries none or with
  /// --no-shape-curve (the paper's regressors).
  std::optional<ShapeCurve> curve;
  double load_seconds = 0.0;
  double train_seconds = 0.0;
};

/// The path of the model to use: `model_file` when given, else the open model of `sex`
/// ("female", "male", "neutral") in the assets folder. Throws RuntimeError with a plain
/// explanation (which paths were tried, CALIPER_ASSETS, --model) when it does not exist.
std::string resolve_model_path(const std::optional<std::string>& model_file,
                               const std::string& sex);

/// Loads the model (smpl::load_model; smpl::ModelError propagates) and either loads the
/// regressors from `regressors_file` (checked against the model) or trains them with the
/// paper's defaults.
/// `shape_curve` false leaves ModelBundle::curve empty (--no-shape-curve). A malformed curve
/// entry throws RuntimeError naming the file.
std::shared_ptr<const ModelBundle> load_bundle(const std::string& model_path,
                                               const std::optional<std::string>& regressors_file,
                                               bool need_regressors = true,
                                               bool shape_curve = true);

/// Lazily loads one bundle per sex (or one for an explicit --model), thread-safe, for batch.
class BundleCache {
 public:
  BundleCache(std::optional<std::string> model_file, std::optional<std::string> regressors_file,
              bool shape_curve = true)
      : model_file_(std::move(model_file)),
        regressors_file_(std::move(regressors_file)),
        shape_curve_(shape_curve) {}
  /// The bundle for `sex`; the same for every sex when an explicit model was given.
  std::shared_ptr<const ModelBundle> get(const std::string& sex);

 private:
  std::optional<std::string> model_file_;
  std::optional<std::string> regressors_file_;
  bool shape_curve_ = true;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const ModelBundle>> bundles_;
};

/// Which regressor `create`/`batch` use by default for the given inputs (docs/cli.md;
/// caliper::default_regressor):
/// exactly the inputs of R2, R4 or R5 -> that regressor; all six or any other subset ->
/// "noise-aware" (R6 reproduces every input but amplifies measurement noise into implausible
/// shapes, paper Fig. 9 and docs/evaluation.md).
std::string default_regressor(const std::map<std::string, double>& inputs);

/// Normalises a --regressor value to "R2", "R4", "R5", "R6" or "noise-aware"
/// (caliper::normalise_regressor_name); throws UsageError.
std::string normalise_regressor_name(const std::string& text);

}  // namespace caliper::cli
