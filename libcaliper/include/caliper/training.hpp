/// \file training.hpp
/// Training sets for the shape regressors (Pujades et al., The Virtual Caliper, TVCG 2019,
/// Sec. 3.4.3): the 2^10 corners of the +/-2 SD cube over the first 10 betas, or Gaussian
/// samples betas ~ N(0, I), each body measured in the rest pose together with its volume.
///
/// Speed: only the shape changes (v = T + S beta), so ShapeMeasurer precomputes what every
/// measurement needs: the affine maps beta -> landmark point, the floor candidates (every vertex
/// that can be the lowest one for |beta| <= R, exactly, by an interval bound) and the volume as
/// an exact cubic polynomial in beta (the divergence-theorem face sum expanded once).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/measurements.hpp"
#include "caliper/weight.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// Largest number of betas the regressors are trained over (2^n training corners).
constexpr int kMaxTrainingBetas = 20;

/// Largest number of betas a ShapeMeasurer handles (the volume cubic has
/// (B + 1) (B + 1) (B + 2) / 2 coefficients: 18,513 for 32). More than kMaxTrainingBetas, so that
/// the measurer of a model's shape curve covers every component of the open models (21).
constexpr int kMaxMeasurerBetas = 32;

/// The 2^n corners of the cube [-sd, sd]^n, one per row (2^n x n), row r having beta_i = +sd
/// when bit i of r is set. 1 <= n <= 20, else InvalidInputError.
Eigen::MatrixXd corner_betas(int num_betas = 10, double sd = 2.0);

/// `count` x `num_betas` standard normal samples, deterministic for a given seed on every
/// platform (own xoshiro256** generator and Box-Muller transform, not <random>'s
/// distributions). count >= 1 and num_betas >= 1, else InvalidInputError.
Eigen::MatrixXd gaussian_betas(int count, int num_betas, std::uint64_t seed);

/// Fast, exact measurements of rest-pose bodies of one model for the first `num_betas` shape
/// components. Keeps copies of what it needs, not a reference to the model.
class ShapeMeasurer {
 public:
  /// `defs`: measurements to evaluate (those whose landmarks are missing throw LandmarkError
  /// here). `num_betas` <= 0 means min(10, model.num_betas()); more than model.num_betas() or
  /// kMaxMeasurerBetas throws InvalidInputError; all-zero shapedirs (a broken model) throw
  /// smpl::ModelError. Cost: one pass over the faces, about
  /// 10 M multiply-adds for SMPL with 10 betas.
  ShapeMeasurer(const smpl::BodyModel& model, const LandmarkTable& landmarks,
                std::vector<MeasurementDef> defs = paper_measurements(), int num_betas = 0);

  int num_betas() const { return num_betas_; }
  const std::vector<MeasurementDef>& definitions() const { return defs_; }

  /// Measurements of one body, in definitions() order. `betas`: up to num_betas() values
  /// (missing ones are 0).
  Eigen::VectorXd measure(const Eigen::VectorXd& betas) const;

  /// Exact volume (m^3) of the rest-pose body for `betas` (same value as mesh_volume() of
  /// shaped_vertices(), to rounding).
  double volume(const Eigen::VectorXd& betas) const;

  /// Lowest y of the body for `betas` (exact; the candidate set is widened when |betas| exceeds
  /// what was prepared).
  double floor(const Eigen::VectorXd& betas) const;

  /// Batch version: `betas` N x k (k <= num_betas()); writes N x definitions().size()
  /// measurements and N volumes.
  void measure_batch(const Eigen::MatrixXd& betas, Eigen::MatrixXd& measurements,
                     Eigen::VectorXd& volumes) const;

 private:
  struct Affine {
    Eigen::Vector3d p0;
    Eigen::Matrix<double, 3, Eigen::Dynamic> P;
  };
  std::vector<int> floor_candidates(double radius) const;
  double floor_over(const Eigen::VectorXd& b, const std::vector<int>& candidates) const;

  int num_betas_ = 0;
  std::vector<MeasurementDef> defs_;
  std::vector<int> from_, to_;    // landmark indices into points_ (-1 for none)
  std::vector<Affine> points_;    // landmark point = p0 + P beta
  Eigen::VectorXd y0_;            // V template heights
  Eigen::MatrixXd ydirs_;         // V x k height blend rows
  Eigen::VectorXd ydir_norms_;    // V row norms of ydirs_
  std::vector<int> floor_refs_;   // the template's lowest vertices (candidate test)
  double prepared_radius_ = 0.0;  // candidates below are exact for |beta| <= this
  std::vector<int> candidates_;
  Eigen::MatrixXd cubic_;  // (k+1) x (k+1)(k+2)/2 volume coefficients
};

/// Measured bodies for training.
struct TrainingSet {
  Eigen::MatrixXd betas;         ///< N x k
  std::vector<std::string> ids;  ///< measurement ids of the columns of `measurements`
  Eigen::MatrixXd measurements;  ///< N x ids.size(), metres
  Eigen::VectorXd volumes;       ///< N, m^3
  WeightFormula weight_formula;  ///< used for `weights`
  Eigen::VectorXd weights;       ///< N, kg (weight_from_volume of `volumes`)
  /// The mean body's (betas 0) volume, m^3 (make_training_set measures it; 0 in a set made
  /// otherwise).
  double mean_volume = 0.0;

  int size() const { return static_cast<int>(betas.rows()); }
  /// Column of a measurement id, or of the derived ids "weight" (kg), "volume" (m^3) and
  /// "weight_feature" (cube root of volume, m). Throws InvalidInputError for an unknown id.
  Eigen::VectorXd column(const std::string& id) const;
};

/// Measures every row of `betas` (N x k) with `measurer`, and the mean body's volume; weights
/// by `formula`.
TrainingSet make_training_set(const ShapeMeasurer& measurer, const Eigen::MatrixXd& betas,
                              const WeightFormula& formula);

/// Convenience: the paper's set, corner_betas(min(10, B), 2.0), for `model` with
/// landmarks_for(model), the measurements available on it, and
/// weight_formula_of(model).
TrainingSet paper_training_set(const smpl::BodyModel& model);

}  // namespace caliper
