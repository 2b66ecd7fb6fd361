/// \file makehuman_shape.hpp
/// The shape space of the open model v2 from real people (issue 11): MakeHuman's CC0 targets as
/// a linear basis of T-posed bodies, every survey subject (ANSUR II, NHANES) registered to it by
/// fitting the target weights to the subject's measurements, and principal components of the
/// registered bodies per sex (betas ~ N(0, I) over the population).
///
/// The basis: the sex's average body (MakeHuman's base plus the mean of its three young ethnic
/// targets of that sex) and directions, each the T-posed body of that average plus one target
/// (or a left/right pair) minus the T-posed average: the young macro corners (muscle x weight),
/// the height and proportion targets of the average corner, the sex's body-shape targets, every
/// measure target (incr and decr), and belly, buttock, hip and limb-fat targets; each body
/// centred on its own pelvis joint. Bodies are linear in the weights, as SMPL bodies are in
/// betas; the T-pose bake is applied to each target body once (its joints follow the shape), so
/// the basis is the linearisation at the sex's average.
///
/// Fitting: measurements are nearly linear in the weights (the premise of the paper); a linear
/// surrogate of every measurement is fitted over random bodies of the basis, each subject's
/// weights are solved against it (weighted least squares with a Gaussian prior on each weight),
/// and then corrected four times with the true measurements of the fitted body (the surrogate's
/// error at that body subtracted from the targets); a subject still more than three tolerances
/// off on a measurement then takes Gauss-Newton steps on the true measurements (a numerical
/// Jacobian at the fitted body). Subjects measured in part (NHANES) take the
/// fitted population of the fully measured ones (ANSUR II) as their prior. Units: metres,
/// kilograms.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "makehuman_rig.hpp"
#include "smpl/body_model.hpp"

namespace modelgen::mh {

/// The measurements a subject may be fitted on (caliper::measure_all ids), with the tolerance
/// each residual is divided by.
struct FitMeasure {
  std::string id;    ///< e.g. "height", "weight", "hip_circumference"
  double tolerance;  ///< metres (kg for weight): a residual of this size costs 1
  /// The men's tolerance where it differs (0: the same as the women's); registered() keeps
  /// the largest tolerance.
  double male_tolerance = 0.0;
  /// NHANES's tolerance where it differs (0: as above): a value mapped from another measuring
  /// protocol (the upper arm, protocol_mapping.hpp) is held more loosely.
  double nhanes_tolerance = 0.0;

  /// The tolerance for a subject of `sex` ("female" or "male") from `source` ("ANSUR II",
  /// "NHANES").
  [[nodiscard]] double tolerance_for(const std::string& sex, const std::string& source) const {
    if (source == "NHANES" && nhanes_tolerance > 0.0) return nhanes_tolerance;
    return sex == "male" && male_tolerance > 0.0 ? male_tolerance : tolerance;
  }
};

/// One survey subject: sex, and values (metres, kg) of some FitMeasure ids; NaN = not measured.
struct Subject {
  std::string sex;         ///< "female" or "male"
  std::string source;      ///< "ANSUR II" or "NHANES"
  Eigen::VectorXd values;  ///< one per fit_measures(), NaN where the survey has none
};

/// The measurements fitted, in Subject::values order: height, weight, arm span, crotch height,
/// shoulder (biacromial) width, hip width, chest, waist (navel level) and hip (buttock)
/// circumferences, iliac crest height, the waist at the iliac crest (the NHANES and WHO waist),
/// neck, thigh (gluteal furrow), calf, ankle and wrist circumferences, knee height, the hanging
/// arm's length, the hand's and the acromion's height, the hanging arm's acromion-radiale length,
/// the mid-upper-arm girth and the upper leg length (from the iliac crest height on defined in
/// makehuman_measures.hpp and validation.hpp, the others are libcaliper's).
const std::vector<FitMeasure>& fit_measures();

/// ANSUR II subjects of both files under `ansur_dir` (stature, weightkg, span, crotchheight,
/// biacromialbreadth, hipbreadth, chest-, waist- and buttockcircumference, iliocristaleheight,
/// neck-, thigh-, calf-, ankle- and wristcircumference, lateralfemoralepicondyleheight,
/// acromionradialelength + radialestylionlength, handlength, acromialheight,
/// acromionradialelength, bicepscircumferenceflexed plus the offset to the relaxed girth,
/// trochanterionheight - lateralfemoralepicondyleheight) and NHANES subjects of both development
/// files under `nhanes_dir` (BMXHT, BMXWT, BMXHIP, BMXWAIST, BMXARMC, BMXARML as an
/// acromion-radiale length through upper_arm_mapping() of the sex, from ANSUR II's
/// shoulderelbowlength, and BMXLEG minus the offset to ANSUR II's trochanterion-to-epicondyle
/// height at equal stature and weight, protocol_offset()). Throws std::runtime_error naming the
/// file for a missing or malformed one.
std::vector<Subject> read_subjects(const std::string& ansur_dir, const std::string& nhanes_dir);

/// The target basis (see the file comment).
struct ShapeBasis {
  std::vector<std::string> names;  ///< K direction names (target paths, "a+b" for pairs)
  std::vector<std::string> sex;    ///< K: the sex whose average the direction was taken at
  smpl::Vertices female_mean;      ///< V x 3, T-posed, metres, origin as the template's
  smpl::Vertices male_mean;
  Eigen::MatrixXd dirs;  ///< 3V x K (row 3 v + c), metres per unit weight
  /// Vertices of a body of `sex` with weights `w` (K; the other sex's directions must be 0).
  smpl::Vertices body(const std::string& sex, const Eigen::VectorXd& w) const;
};

/// Builds the basis from `assets`, in the frame of `tmpl` (template_model(): the T-posed base
/// with its pelvis joint at the origin).
ShapeBasis shape_basis(const Assets& assets, const smpl::BodyModel& tmpl);

/// Per-subject fit result.
struct FitResult {
  Eigen::MatrixXd weights;    ///< N x K, one row per subject
  Eigen::MatrixXd residuals;  ///< N x M true measurement minus survey value (NaN: not measured)
};

/// Registers every subject (see the file comment). `tmpl` supplies faces and landmarks.
/// Subjects measured on more than half of the fit_measures() ids (ANSUR II) are fitted first,
/// each weight with an independent prior; the others (NHANES) then with the population of the first
/// as their prior (mean and covariance of its weights), so that what they were not measured on
/// follows from what they were. `threads` >= 1 share the subjects; the result does not depend on
/// it.
FitResult fit_subjects(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                       const std::vector<Subject>& subjects, int threads = 1);

/// What check_fit() refits: the fit to compare with and the stride.
struct FitCheckInput {
  const FitResult* fit = nullptr;
  int every = 1;
};

/// What check_fit() found: how many subjects it refitted and those whose weights or residuals
/// differ from the given fit in any bit (subject indices).
struct FitCheckReport {
  int checked = 0;
  std::vector<size_t> differing;
};

/// Refits every `every`-th subject of each stage and sex of fit_subjects() with this process's
/// arithmetic (its kernels, its libm), the second stage's prior made from `fit`'s first-stage
/// weights, and compares the bits with `fit`: how caliper-modelgen --check-fit shows that a fit
/// cache made on another CPU (or with other kernels) is the fit this CPU would make, at a
/// fraction of the time of a whole fit. Throws std::invalid_argument when `fit` is not of these
/// subjects and basis or `every` < 1.
FitCheckReport check_fit(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                         const std::vector<Subject>& subjects, const FitResult& fit, int every,
                         int threads = 1);

/// Whether subject `i` of `fit` was registered: every measurement it has within 3 tolerances
/// of the survey (fit_measures(); the larger where the men's tolerance differs). The few that are
/// not (a slice meeting another limb, a body the targets cannot reach) are left out of the
/// populations of shape_model(), whose covariance they would widen (docs/models.md).
bool registered(const FitResult& fit, size_t i);

/// A fingerprint (64-bit FNV-1a) of the inputs fit_subjects() reads: the basis (names, sexes,
/// both average bodies, the directions), the version of the survey measurements' definitions
/// (a constant raised when one changes), the fit_measures() ids and tolerances, the subjects
/// (sex, source, values, in order) and the template's faces. Not the fitting code: a cache of a
/// fit must be deleted by hand when the code of the fit changes in another way.
std::uint64_t fit_fingerprint(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                              const std::vector<Subject>& subjects);

/// Writes `fit` and its `fingerprint` to `path` (binary, the machine's doubles, deterministic to
/// the byte; atomically; a cache on one machine, not an exchange format). Throws std::runtime_error
/// naming the file when it cannot be written.
void save_fit(const std::string& path, std::uint64_t fingerprint, const FitResult& fit);

/// The fit saved at `path` by save_fit() when the file exists and its fingerprint and shape
/// (`rows` subjects, `cols` basis directions, fit_measures().size() measurements) match;
/// nullopt when the file does not exist or was made from other inputs. Throws
/// std::runtime_error naming the file when it exists but is not a fit file or is truncated.
std::optional<FitResult> load_fit(const std::string& path, std::uint64_t fingerprint,
                                  Eigen::Index rows, Eigen::Index cols);

/// How many directions of the NHANES subjects' registered weights their measurements determine,
/// from the eigenvalues of the weights' covariance (ascending, as Eigen gives them): those above
/// 1e-3 of the largest. The subjects are fitted on six measurements through a non-linear mesh, so
/// below about six real directions lies a tail of the fit's small departures (2e-3 down to
/// 1e-10), which Population::general must not condition ANSUR II's spread on (docs/models.md).
Eigen::Index nhanes_spread_rank(const Eigen::VectorXd& eigenvalues_ascending);

/// Which population a model's betas ~ N(0, I) stand for (each sex; the neutral model: both
/// sexes, each weighted to half).
struct Population {
  /// false: the registered subjects of the sex, pooled (each survey in proportion to its
  /// size, or to `survey_share`). true: the general adult population, "NHANES for what NHANES
  /// measures, ANSUR II for the rest": the mean and covariance of the NHANES subjects' weights
  /// (they vary only along the directions their six measurements move the fit, through the
  /// ANSUR II prior) plus the covariance of the ANSUR II subjects' weights given those six
  /// measurements (their population covariance minus the part the measurements explain
  /// linearly). Needs subjects of both surveys of the sex, else std::invalid_argument.
  bool general = false;
  /// Pooled only (ignored when empty): the share of the sex's population each survey
  /// (Subject::source) stands for, e.g. {{"ANSUR II", 0.5}, {"NHANES", 0.5}}; every subject of a
  /// survey is weighted share / count of that survey and sex. A survey with subjects of the sex
  /// and no share throws std::invalid_argument.
  std::map<std::string, double> survey_share;
};

/// An SMPL-structured model of `sex` ("female", "male", or "neutral": both sexes, each weighted
/// to half) from the registered subjects: v_template the mean body of `population`, shapedirs
/// the first `num_betas` principal components of its bodies' vertices, scaled so that betas ~
/// N(0, I) over it (fewer when the population varies along fewer directions: a subject
/// measured on m values is registered within an m-dimensional family); faces, weights,
/// regressor, texture coordinates and landmarks from `tmpl`.
smpl::BodyModel shape_model(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                            const std::vector<Subject>& subjects, const FitResult& fit,
                            const std::string& sex, int num_betas,
                            const Population& population = {});

/// Levels the soles: every shape component moves the vertices within `full` metres of the mean
/// body's floor (its lowest vertex) up or down as much as that lowest vertex, and those up to
/// `fade` metres above it by a share fading smoothly to none (their own motion keeps the rest).
/// The soles then keep their shape in height under every beta, so the lowest vertex, the floor
/// that height and inseam are measured from, is the same one for every body near the mean and
/// those measurements stay linear in the betas (the regressors' premise). Without it the
/// neutral model's first component (mostly the sex) tilts the feet: 12 different lowest
/// vertices over the 1,024 training corners, the floor 2.1 mm RMS (10.9 mm at most) off its best
/// linear fit. Moves only height (y); the model must have shapedirs and a non-empty mesh.
void level_soles(smpl::BodyModel& model, double full = 0.02, double fade = 0.05);

}  // namespace modelgen::mh
