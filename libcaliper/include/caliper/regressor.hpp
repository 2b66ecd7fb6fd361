/// \file regressor.hpp
/// Measurements -> shape regressors.
///
/// LinearRegressor: the paper's R2/R4/R5/R6 (Pujades et al., The Virtual Caliper, TVCG 2019,
/// Sec. 3.4.3): betas = A [f; 1] fitted by least squares over a training set, where the feature
/// vector f holds the input measurements in metres except weight, which enters as the cube root
/// of the volume it implies (weight_feature()).
///   R2: height, weight;  R4: + arm_span_fingertips, inseam_height;  R5: + hip_width;
///   R6: + arm_length.
///
/// NoiseAwareRegressor: a Bayesian linear-Gaussian model. Prior betas ~ N(0, I); a linearised
/// forward model f = M beta + c + e, fitted by least squares of each feature on betas over the
/// training set, with e ~ N(0, diag(s^2)), s^2 = (measurement noise SD)^2 + (RMS residual of the
/// linear fit)^2. For any subset of the six inputs it returns the posterior mean
/// (I + M' N^-1 M)^-1 M' N^-1 (f - c) and covariance (I + M' N^-1 M)^-1. Default noise: the
/// paper's self-measurement MAE (Table 2) times sqrt(pi/2) (Gaussian MAE -> SD); weight 1.0 kg,
/// mapped to cube-root-volume space by the delta method at the given weight.
/// See docs/regressors.md.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/json.hpp"
#include "caliper/measurements.hpp"
#include "caliper/training.hpp"
#include "caliper/weight.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// The paper's regressors.
enum class RegressorKind { R2, R4, R5, R6 };

/// "R2", "R4", "R5", "R6".
std::string to_string(RegressorKind kind);
/// Parses "R2".."R6" (case-insensitive); std::nullopt otherwise.
std::optional<RegressorKind> parse_regressor_kind(const std::string& text);
/// Input ids of a regressor, in order (R6: height, weight, arm_span_fingertips, inseam_height,
/// hip_width, arm_length).
const std::vector<std::string>& regressor_inputs(RegressorKind kind);
/// All four kinds in order.
const std::vector<RegressorKind>& all_regressor_kinds();

/// What a fitted regressor belongs to; a different model is refused.
struct ModelSignature {
  std::string name;    ///< model.meta.name
  std::string gender;  ///< model.meta.gender
  int num_vertices = 0;
  int num_betas = 0;  ///< betas the regressor produces (<= the model's)
  /// Checksum of the template and of the first num_betas shape directions (a fixed weighted
  /// sum; 0 = unknown). Identifies the model's content whatever its file or name.
  double fingerprint = 0.0;

  /// Signature of `model` for a regressor with `betas` outputs (computes the fingerprint).
  static ModelSignature of(const smpl::BodyModel& model, int betas);
  /// Throws ModelMismatchError naming both sides if the model's vertex count differs, it has
  /// fewer betas, or its content differs: by fingerprint when known (a renamed file is
  /// accepted), otherwise by name and gender (each compared only when both are non-empty).
  void check(const smpl::BodyModel& model) const;
};

/// The fingerprint of ModelSignature for the first `betas` shape directions of `model`.
double model_fingerprint(const smpl::BodyModel& model, int betas);

/// Feature of one input: the value itself (metres), or weight_feature() for "weight".
/// Throws InvalidInputError for NaN/inf, a non-positive value or a weight below the formula's
/// intercept.
double input_feature(const std::string& id, double value, const WeightFormula& formula);

/// betas = A [features; 1].
class LinearRegressor {
 public:
  /// Least squares over `training` of betas on the features of `inputs` (any measurement ids
  /// of the training set, and "weight"). Throws InvalidInputError if an input is not in the set
  /// or the set has fewer rows than inputs + 1. `intercept_at_mean`: the slopes as fitted, the
  /// intercept with the weight feature at the mean body's value instead of its average over the
  /// set (needs TrainingSet::mean_volume > 0; else the fitted intercept is kept).
  static LinearRegressor fit(const TrainingSet& training, const std::vector<std::string>& inputs,
                             const ModelSignature& signature, const std::string& name = "",
                             bool intercept_at_mean = false);
  /// The paper's regressor `kind`.
  static LinearRegressor fit(const TrainingSet& training, RegressorKind kind,
                             const ModelSignature& signature, bool intercept_at_mean = false);

  const std::string& name() const { return name_; }  ///< e.g. "R5"
  const std::vector<std::string>& inputs() const { return inputs_; }
  const ModelSignature& signature() const { return signature_; }
  const WeightFormula& weight_formula() const { return formula_; }
  /// k x (inputs + 1), the last column is the intercept.
  const Eigen::MatrixXd& coefficients() const { return A_; }
  /// RMS over the training set of each input's residual when its own avatar is re-measured
  /// linearly, in feature units (diagnostic, 0 for a perfectly linear model). Size inputs().
  const Eigen::VectorXd& training_rms() const { return training_rms_; }

  /// Betas (k values) for the inputs in `values` (extra keys are ignored). Throws
  /// InvalidInputError naming a missing input or a bad value (see input_feature()).
  Eigen::VectorXd predict(const MeasurementMap& values) const;
  /// Betas for raw input values in inputs() order.
  Eigen::VectorXd predict(const Eigen::VectorXd& values) const;

  Json to_json() const;
  /// Throws ModelMismatchError (or JsonError) naming the problem for a malformed document.
  static LinearRegressor from_json(const Json& json);

 private:
  std::string name_;
  std::vector<std::string> inputs_;
  ModelSignature signature_;
  WeightFormula formula_;
  Eigen::MatrixXd A_;
  Eigen::VectorXd training_rms_;
};

/// Per-input noise standard deviations: metres, "weight" in kg.
using NoiseLevels = std::map<std::string, double>;

/// Paper Table 2 self-measurement MAE * sqrt(pi/2): height 1.53 cm, arm_span_fingertips
/// 2.01 cm, arm_length 1.29 cm, inseam_height 2.06 cm, hip_width 0.77 cm; weight 1.0 kg.
NoiseLevels self_measurement_noise();
/// Paper Table 2 other-measurement MAE * sqrt(pi/2): 1.47, 1.72, 0.76, 2.46, 0.65 cm; weight
/// 1.0 kg.
NoiseLevels other_measurement_noise();
/// sqrt(pi/2): the SD of a zero-mean Gaussian whose mean absolute value is 1.
constexpr double kMaeToSd = 1.2533141373155001;

/// Posterior over the betas.
/// A population's shape distribution: betas ~ N(mean, covariance), over at least a regressor's
/// betas (its leading block is the regressor's prior; create_avatar() sets the betas beyond the
/// regressor's to their mean given the regressor's). caliper::population_prior() reads one from
/// a model file. Without one, a model's betas ~ N(0, I): the population the model was made for.
struct ShapePrior {
  Eigen::VectorXd mean;        ///< b >= the regressor's k
  Eigen::MatrixXd covariance;  ///< b x b, symmetric, its leading k x k block positive definite
};

struct Posterior {
  Eigen::VectorXd mean;                  ///< k, the avatar's betas
  Eigen::MatrixXd covariance;            ///< k x k
  std::vector<std::string> used_inputs;  ///< the inputs that were given, in model order
  /// Per-beta posterior SD (sqrt of the diagonal of covariance).
  Eigen::VectorXd sd() const { return covariance.diagonal().cwiseSqrt(); }
};

class NoiseAwareRegressor {
 public:
  /// Fits the linearised model of each of `inputs` (default: the six R6 inputs) on the betas of
  /// `training` (least squares, with intercept) and stores the per-input RMS residual.
  static NoiseAwareRegressor fit(
      const TrainingSet& training, const ModelSignature& signature,
      const NoiseLevels& noise = self_measurement_noise(),
      const std::vector<std::string>& inputs = regressor_inputs(RegressorKind::R6));

  const std::vector<std::string>& inputs() const { return inputs_; }
  const ModelSignature& signature() const { return signature_; }
  const WeightFormula& weight_formula() const { return formula_; }
  const NoiseLevels& noise() const { return noise_; }
  /// inputs x k forward matrix M and inputs offsets c (feature units).
  const Eigen::MatrixXd& forward_matrix() const { return M_; }
  const Eigen::VectorXd& forward_offset() const { return c_; }
  const Eigen::VectorXd& linearisation_rms() const { return lin_rms_; }

  /// Posterior for whichever of inputs() appear in `values` (extra keys ignored; none at all
  /// gives the prior). `noise` overrides the stored levels per id. `prior`: the population the
  /// person comes from (default N(0, I), the model's own; its leading k x k block is used); the
  /// posterior mean is then the population's likeliest body given the inputs. Throws
  /// InvalidInputError for bad values, a non-positive noise level, or a prior over fewer betas
  /// or not positive definite.
  Posterior predict(const MeasurementMap& values, const NoiseLevels& noise = {},
                    const ShapePrior* prior = nullptr) const;

  Json to_json() const;
  static NoiseAwareRegressor from_json(const Json& json);

 private:
  std::vector<std::string> inputs_;
  ModelSignature signature_;
  WeightFormula formula_;
  NoiseLevels noise_;
  Eigen::MatrixXd M_;
  Eigen::VectorXd c_;
  Eigen::VectorXd lin_rms_;
};

/// All regressors of one model, as `caliper train` writes them.
struct RegressorSet {
  std::vector<LinearRegressor> linear;  ///< R2, R4, R5, R6 (in that order)
  std::optional<NoiseAwareRegressor> noise_aware;

  /// The linear regressor called `name` ("R5", case-insensitive); nullptr if absent.
  const LinearRegressor* find(const std::string& name) const;

  /// {"format": "caliper-regressors", "version": 1, "linear": [...], "noise_aware": {...}}.
  Json to_json() const;
  static RegressorSet from_json(const Json& json);
  /// write_json_file / read_json_file; errors name the file.
  void save(const std::string& path) const;
  static RegressorSet load(const std::string& path);
  /// Throws ModelMismatchError if any regressor does not belong to `model`.
  void check(const smpl::BodyModel& model) const;
};

/// Options of train_regressors().
struct TrainOptions {
  int num_betas = 0;      ///< <= 0: min(10, model.num_betas())
  bool gaussian = false;  ///< false: the paper's 2^k corners at +/- corner_sd
  double corner_sd = 2.0;
  int gaussian_count = 1024;  ///< used when gaussian
  std::uint64_t seed = 1;     ///< used when gaussian
  bool noise_aware = true;    ///< also fit the noise-aware regressor
  /// The linear regressors' intercept with the weight at the mean body (LinearRegressor::fit):
  /// their slopes are the paper's; the paper's least-squares intercept over the corners (false)
  /// carries the curvature of the cube root of the volume at the corners (+/-2 SD in all 10
  /// components at once) into the weight of every avatar (docs/regressors.md).
  bool intercept_at_mean = true;
  NoiseLevels noise = self_measurement_noise();
};

/// Builds a ShapeMeasurer for landmarks_for(model) with the six regressor inputs, a training
/// set, and fits R2, R4, R5, R6 (and the noise-aware regressor). Throws LandmarkError if the
/// model lacks a landmark the inputs need.
RegressorSet train_regressors(const smpl::BodyModel& model, const TrainOptions& options = {});

/// Same from an existing training set (must contain the six regressor inputs).
RegressorSet train_regressors(const TrainingSet& training, const ModelSignature& signature,
                              const TrainOptions& options = {});

}  // namespace caliper
