/// \file validation.hpp
/// What the open models are validated on: the survey measurements of a body (libcaliper's
/// definitions, the hanging arm as ANSUR II measures it), the survey's figures per sex from the
/// committed statistics table, and a model's figures over bodies drawn from its shape space;
/// plus the deterministic RNG and the guard that makes the generator's arithmetic independent of
/// the CPU (docs/models.md, "Same bytes on every CPU").
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ansur_stats.hpp"
#include "caliper/measurements.hpp"
#include "caliper/population.hpp"
#include "caliper/random.hpp"
#include "smpl/body_model.hpp"

namespace modelgen {

/// Small deterministic RNG: caliper::Xoshiro256 bits, uniforms in (0, 1), normals by Box-Muller.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : bits_(seed) {}
  std::uint64_t next() { return bits_.next(); }
  double uniform();  ///< in (0, 1)
  double normal();   ///< standard normal
 private:
  caliper::Xoshiro256 bits_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

/// The hanging arm (caliper::hanging_arms(), caliper::hanging_arm_length(),
/// caliper::hanging_upper_arm_length(): libcaliper's since 2026-11-30).
using caliper::hanging_arm_length;
using caliper::hanging_arms;
using caliper::hanging_upper_arm_length;
using caliper::HangingArms;

/// The measurements the model is validated on (ids below), for one body.
/// Ids: stature, weight, span, crotch_height, hip_breadth, arm_length (hanging_arm_length),
/// upper_arm_length (hanging_upper_arm_length; only for a model with radiale landmarks),
/// biacromial, chest_circ, waist_circ, buttock_circ; plus arm_length_tpose, the caliper's
/// virtual arm length (shoulder to wrist landmark in the T-pose), which has no survey
/// counterpart and is reported for information.
std::map<std::string, double> validation_measurements(const smpl::BodyModel& model,
                                                      const smpl::Vertices& vertices);

/// Survey value of each validation measurement id: the Dim it corresponds to (arm_length is
/// kAcromionRadiale + kRadialeStylion, marked by -1).
int validation_dim(const std::string& id);

/// Ids of validation_measurements(), in table order.
const std::vector<std::string>& validation_ids();

/// Population figures of the validation measurements: means, SDs and two correlations.
struct ValidationFigures {
  std::map<std::string, double> mean;  ///< by validation id (metres, kg)
  std::map<std::string, double> sd;    ///< sample standard deviations
  double corr_stature_span = 0.0;
  double corr_stature_weight = 0.0;
  int count = 0;  ///< bodies (model samples) or subjects (survey)
};

/// The survey's figures for `gender` ("female", "male"; "neutral" = the 50/50 mixture of both
/// sexes, its moments computed from the two sexes' means and covariances). arm_length is
/// acromion-radiale + radiale-stylion length.
ValidationFigures survey_figures(const SurveyStats& stats, const std::string& gender);

/// Samples `samples` bodies with betas ~ N(0, I) (fixed seed), or ~ N(population->mean,
/// population->cov) when `population` is given (a survey's subjects in the model's shape space,
/// population.hpp), and measures them with libcaliper (validation_measurements()).
ValidationFigures model_figures(const smpl::BodyModel& model, int samples, std::uint64_t seed,
                                const caliper::SurveyPopulation* population = nullptr);

/// Makes the generator's arithmetic independent of the CPU it runs on, for its lifetime, so the
/// models come out byte-identical on every x86-64 machine (issue 18; docs/models.md):
/// - Eigen's matrix products split their inner dimension into blocks sized from the cache sizes
///   it detects at run time, and a different split sums in a different order; the guard sets
///   fixed sizes (32 KiB, 512 KiB, 4 MiB) and restores the previous ones when it ends.
/// - libsmpl's kernels give the same bits on every instruction-set variant by contract
///   (smpl/simd.hpp), so the variant the CPU picks does not matter.
/// The v2 generator's top-level steps each hold one (template_model(), shape_basis(),
/// fit_subjects(), shape_model(), the contact steps, pose_correctives()); model_figures() too.
class DeterministicNumerics {
 public:
  DeterministicNumerics();
  ~DeterministicNumerics();
  DeterministicNumerics(const DeterministicNumerics&) = delete;
  DeterministicNumerics& operator=(const DeterministicNumerics&) = delete;

 private:
  std::ptrdiff_t l1_, l2_, l3_;
};

}  // namespace modelgen
