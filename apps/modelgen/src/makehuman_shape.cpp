/// \file makehuman_shape.cpp
/// Target basis, registration of survey subjects and principal components (makehuman_shape.hpp).
///
/// Sections: subjects; basis; fitting; principal components.
#include "makehuman_shape.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <thread>
#include <tuple>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "ansur_stats.hpp"
#include "caliper/circumference.hpp"
#include "caliper/measurements.hpp"
#include "caliper/population.hpp"
#include "caliper/random.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "makehuman_landmarks.hpp"
#include "makehuman_measures.hpp"
#include "protocol_mapping.hpp"
#include "smpl/atomic_file.hpp"
#include "validation.hpp"

namespace modelgen::mh {

// ------------------------------------------------------------------------------------------------
// Subjects
// ------------------------------------------------------------------------------------------------

const std::vector<FitMeasure>& fit_measures() {
  // Tolerances: about the survey's own measurement error (a few mm for lengths, 1 cm for girths
  // taken with a tape, 1 kg for a weight that also depends on the density formula).
  static const std::vector<FitMeasure> m = {{"height", 0.005},
                                            {"weight", 1.0},
                                            {"arm_span_fingertips", 0.01},
                                            {"inseam_height", 0.01},
                                            {"shoulder_width", 0.0075},
                                            {"hip_width", 0.005},
                                            {"chest_circumference", 0.01},
                                            {"waist_circumference", 0.01},
                                            {"hip_circumference", 0.01},
                                            {"iliac_crest_height", 0.01},
                                            {"waist_iliac_circumference", 0.01},
                                            {"neck_circumference", 0.01},
                                            {"thigh_circumference", 0.01},
                                            {"calf_circumference", 0.01},
                                            {"ankle_circumference", 0.005},
                                            {"wrist_circumference", 0.005},
                                            {"knee_height", 0.01},
                                            {"arm_length", 0.0075, 0.005},
                                            {"hand_length", 0.005},
                                            {"acromial_height", 0.01},
                                            // NHANES: mapped (protocol_mapping.hpp); the
                                            // mapping's residual SD is 5-6 mm, plus NHANES's
                                            // own measuring error.
                                            {"upper_arm_length", 0.005, 0.0, 0.01},
                                            // ANSUR II: the flexed biceps mapped onto the
                                            // relaxed girth (read_subjects()).
                                            {"upper_arm_circumference", 0.01},
                                            // NHANES: mapped (read_subjects()); at equal
                                            // stature and weight it varies 2.3-2.4 cm from
                                            // person to person, ANSUR II's 1.7-2.1 cm: the
                                            // inguinal crease is hard to find.
                                            {"upper_leg_length", 0.01, 0.0, 0.015}};
  return m;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// fit_measures() index of "upper_arm_length".
constexpr int kUpperArmLength = 20;
/// fit_measures() index of "upper_arm_circumference".
constexpr int kUpperArmCircumference = 21;
/// fit_measures() index of "upper_leg_length".
constexpr int kUpperLegLength = 22;

void add_survey(const std::string& path, const std::string& sex, const std::string& source,
                const std::vector<std::string>& columns, const std::vector<int>& measure,
                const std::vector<double>& scale, std::vector<Subject>& out) {
  const Eigen::MatrixXd t = read_survey_columns(path, columns);
  const int m = static_cast<int>(fit_measures().size());
  for (Eigen::Index r = 0; r < t.rows(); ++r) {
    Subject s;
    s.sex = sex;
    s.source = source;
    s.values = Eigen::VectorXd::Constant(m, kNaN);
    for (size_t c = 0; c < columns.size(); ++c) {
      // Columns that share a measure add up (ANSUR II's arm: acromion-radiale plus
      // radiale-stylion length); a missing part (NaN) leaves the sum missing.
      const double x = t(r, static_cast<Eigen::Index>(c)) * scale[c];
      const auto before = measure.begin() + static_cast<std::ptrdiff_t>(c);
      double& value = s.values[measure[c]];
      value = std::find(measure.begin(), before, measure[c]) == before ? x : value + x;
    }
    out.push_back(s);
  }
}

/// What one sex's ANSUR II and NHANES files give the measurements NHANES takes by another
/// protocol than ANSUR II (protocol_mapping.hpp), each file read once.
struct Protocols {
  UpperArmMapping upper_arm;  ///< NHANES's upper arm length onto ANSUR II's acromion-radiale
  /// What to add to an ANSUR II subject's flexed biceps circumference to have the relaxed
  /// mid-upper-arm girth NHANES measures (`BMXARMC`) at equal stature and weight (metres,
  /// negative; protocol_offset()).
  double biceps_offset = 0.0;
  Eigen::VectorXd nhanes_upper_arm;  ///< every NHANES person's `BMXARML` (metres), file order
  /// What to subtract from NHANES's upper leg length (`BMXLEG`: the inguinal crease to the
  /// kneecap's upper edge, seated, along the thigh) to have ANSUR II's trochanterion height over
  /// the lateral femoral epicondyle at equal stature and weight (metres; protocol_offset()).
  double leg_offset = 0.0;
  Eigen::VectorXd nhanes_upper_leg;  ///< every NHANES person's `BMXLEG` (metres), file order
};

/// Throws std::runtime_error naming the file, the data row and the column of the first value of
/// `t` (read from `path`'s `columns`) that is not a positive number.
void require_positive(const Eigen::MatrixXd& t, const std::string& path,
                      const std::vector<std::string>& columns) {
  for (Eigen::Index r = 0; r < t.rows(); ++r) {
    for (Eigen::Index c = 0; c < t.cols(); ++c) {
      if (!(std::isfinite(t(r, c)) && t(r, c) > 0.0)) {
        throw std::runtime_error("survey file '" + path + "' data row " + std::to_string(r + 1) +
                                 ": column '" + columns[static_cast<size_t>(c)] +
                                 "' is not a positive number; use the survey's file as published");
      }
    }
  }
}

Protocols protocols_of(const std::string& ansur_path, const std::string& nhanes_path) {
  const std::vector<std::string> ansur_columns = {"stature",
                                                  "weightkg",
                                                  "shoulderelbowlength",
                                                  "acromionradialelength",
                                                  "bicepscircumferenceflexed",
                                                  "trochanterionheight",
                                                  "lateralfemoralepicondyleheight"};
  const std::vector<std::string> nhanes_columns = {"BMXHT", "BMXWT", "BMXARML", "BMXARMC",
                                                   "BMXLEG"};
  Eigen::MatrixXd a = read_survey_columns(ansur_path, ansur_columns);
  Eigen::MatrixXd n = read_survey_columns(nhanes_path, nhanes_columns);
  require_positive(a, ansur_path, ansur_columns);
  require_positive(n, nhanes_path, nhanes_columns);
  a.col(0) *= 1e-3;
  a.col(1) *= 0.1;
  for (Eigen::Index c = 2; c < 7; ++c) a.col(c) *= 1e-3;
  n.col(0) *= 1e-2;
  for (Eigen::Index c = 2; c < 5; ++c) n.col(c) *= 1e-2;
  Protocols out;
  try {
    out.upper_arm = upper_arm_mapping(a.leftCols(4), n.leftCols(3));
    Eigen::MatrixXd biceps_a(a.rows(), 3), biceps_n(n.rows(), 3);
    biceps_a << a.leftCols(2), a.col(4);
    biceps_n << n.leftCols(2), n.col(3);
    out.biceps_offset = protocol_offset(biceps_a, biceps_n).offset;
    // Both from bony landmarks, so neither grows with the thigh's fat: the offset is the same in
    // every BMI bin to a few mm (docs/models.md).
    Eigen::MatrixXd leg_a(a.rows(), 3), leg_n(n.rows(), 3);
    leg_a << a.leftCols(2), a.col(5) - a.col(6);
    leg_n << n.leftCols(2), n.col(4);
    out.leg_offset = protocol_offset(leg_a, leg_n).offset;
  } catch (const std::invalid_argument& e) {  // too few people: the files are not the surveys'
    throw std::runtime_error("survey files '" + ansur_path + "' and '" + nhanes_path +
                             "': " + e.what() + "; use the surveys' files as published");
  }
  out.nhanes_upper_arm = n.col(2);
  out.nhanes_upper_leg = n.col(4);
  return out;
}

}  // namespace

std::vector<Subject> read_subjects(const std::string& ansur_dir, const std::string& nhanes_dir) {
  std::vector<Subject> out;
  // Survey column -> fit_measures() index (ANSUR II: millimetres, weightkg in 0.1 kg).
  const std::vector<std::string> ansur = {"stature",
                                          "weightkg",
                                          "span",
                                          "crotchheight",
                                          "biacromialbreadth",
                                          "hipbreadth",
                                          "chestcircumference",
                                          "waistcircumference",
                                          "buttockcircumference",
                                          "iliocristaleheight",
                                          "neckcircumference",
                                          "thighcircumference",
                                          "calfcircumference",
                                          "anklecircumference",
                                          "wristcircumference",
                                          "lateralfemoralepicondyleheight",
                                          "acromionradialelength",
                                          "radialestylionlength",
                                          "handlength",
                                          "acromialheight",
                                          "acromionradialelength",
                                          "bicepscircumferenceflexed",
                                          "trochanterionheight",
                                          "lateralfemoralepicondyleheight"};
  const std::vector<int> ansur_measure = {0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  11, 12,
                                          13, 14, 15, 16, 17, 17, 18, 19, 20, 21, 22, 22};
  std::vector<double> ansur_scale(ansur.size(), 1e-3);
  ansur_scale[1] = 0.1;
  ansur_scale.back() = -1e-3;  // the upper leg: trochanterion minus epicondyle height
  add_survey(ansur_dir + "/ANSUR_II_FEMALE_Public.csv", "female", "ANSUR II", ansur, ansur_measure,
             ansur_scale, out);
  add_survey(ansur_dir + "/ANSUR_II_MALE_Public.csv", "male", "ANSUR II", ansur, ansur_measure,
             ansur_scale, out);
  const std::vector<std::string> nhanes = {"BMXHT", "BMXWT", "BMXHIP", "BMXWAIST", "BMXARMC"};
  const std::vector<int> nhanes_measure = {0, 1, 8, 10, kUpperArmCircumference};
  const std::vector<double> nhanes_scale = {1e-2, 1.0, 1e-2, 1e-2, 1e-2};
  for (const auto& [sex, ansur_file, nhanes_file] :
       {std::tuple<std::string, std::string, std::string>{"female", "ANSUR_II_FEMALE_Public.csv",
                                                          "NHANES_2017_2020_FEMALE_dev.csv"},
        {"male", "ANSUR_II_MALE_Public.csv", "NHANES_2017_2020_MALE_dev.csv"}}) {
    const size_t first = out.size();
    add_survey(nhanes_dir + "/" + nhanes_file, sex, "NHANES", nhanes, nhanes_measure, nhanes_scale,
               out);
    const Protocols p = protocols_of(ansur_dir + "/" + ansur_file, nhanes_dir + "/" + nhanes_file);
    const Eigen::VectorXd& length = p.nhanes_upper_arm;
    if (static_cast<size_t>(length.size()) != out.size() - first) {
      throw std::runtime_error(nhanes_dir + "/" + nhanes_file + ": " +
                               std::to_string(length.size()) + " upper arm lengths for " +
                               std::to_string(out.size() - first) + " people");
    }
    for (Eigen::Index r = 0; r < length.size(); ++r) {
      Eigen::VectorXd& values = out[first + static_cast<size_t>(r)].values;
      values[kUpperArmLength] = p.upper_arm.acromion_radiale(length[r]);
      values[kUpperLegLength] = p.nhanes_upper_leg[r] - p.leg_offset;
    }
    for (Subject& s : out) {
      if (s.source == "ANSUR II" && s.sex == sex) {
        s.values[kUpperArmCircumference] += p.biceps_offset;
      }
    }
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// Basis
// ------------------------------------------------------------------------------------------------

namespace {

/// Direction names of one sex ("+" joins a left/right pair applied together).
std::vector<std::string> direction_names(const std::string& sex) {
  std::vector<std::string> d;
  for (const char* m : {"min", "average", "max"}) {
    for (const char* w : {"min", "average", "max"}) {
      if (std::string(m) == "average" && std::string(w) == "average") continue;
      d.push_back("macrodetails/universal-" + sex + "-young-" + m + "muscle-" + w +
                  "weight.target");
    }
  }
  for (const char* h : {"min", "max"}) {
    d.push_back("macrodetails/height/" + sex + "-young-averagemuscle-averageweight-" + h +
                "height.target");
  }
  for (const char* p : {"ideal", "uncommon"}) {
    d.push_back("macrodetails/proportions/" + sex + "-young-averagemuscle-averageweight-" + p +
                "proportions.target");
  }
  const std::vector<std::string> shapes =
      sex == "female"
          ? std::vector<std::string>{"fem-adrenal",        "fem-apple",           "fem-diamond",
                                     "fem-full-hourglass", "fem-invert-triangle", "fem-lean-column",
                                     "fem-liver",          "fem-neat-hourglass",  "fem-ovary",
                                     "fem-rectangle",      "fem-thyroid",         "fem-triangle"}
          : std::vector<std::string>{"man-adrenal",         "man-apple",       "man-gonadal",
                                     "man-invert-triangle", "man-lean-column", "man-liver",
                                     "man-rectangle",       "man-thyroid",     "man-trapezoid",
                                     "man-triangle"};
  for (const std::string& s : shapes) d.push_back("bodyshapes/bodyshapes-elvs-" + s + ".target");
  for (const std::string& m : measure_targets()) d.push_back(m);
  for (const char* s : {"decr", "incr"}) {
    d.push_back(std::string("stomach/stomach-pregnant-") + s + ".target");
    d.push_back(std::string("buttocks/buttocks-volume-") + s + ".target");
    d.push_back(std::string("hip/hip-scale-horiz-") + s + ".target");
    d.push_back(std::string("hip/hip-scale-depth-") + s + ".target");
    for (const char* part : {"upperarm", "upperleg", "lowerleg"}) {
      d.push_back(std::string("armslegs/l-") + part + "-fat-" + s + ".target+armslegs/r-" + part +
                  "-fat-" + s + ".target");
    }
    d.push_back(std::string("armslegs/l-hand-scale-") + s + ".target+armslegs/r-hand-scale-" + s +
                ".target");
  }
  return d;
}

/// T-posed skin of base-mesh positions `p`, metres, with its own pelvis joint (row 0 of the
/// template's regressor) at the origin.
smpl::Vertices centred_t_pose(const Assets& assets, const smpl::BodyModel& tmpl,
                              const Positions& p) {
  smpl::Vertices v = skin_vertices(assets.skin, t_pose(assets, p).positions);
  const Eigen::RowVector3d pelvis = (tmpl.j_regressor.row(0) * v).eval();
  for (Eigen::Index i = 0; i < v.rows(); ++i) v.row(i) -= pelvis;
  return v;
}

Eigen::VectorXd flat(const smpl::Vertices& v) {
  Eigen::VectorXd f(3 * v.rows());
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    for (int c = 0; c < 3; ++c) f[3 * i + c] = v(i, c);
  }
  return f;
}

}  // namespace

smpl::Vertices ShapeBasis::body(const std::string& s, const Eigen::VectorXd& w) const {
  const Eigen::VectorXd f = dirs * w;
  smpl::Vertices v = s == "male" ? male_mean : female_mean;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    for (int c = 0; c < 3; ++c) v(i, c) += f[3 * i + c];
  }
  return v;
}

ShapeBasis shape_basis(const Assets& assets, const smpl::BodyModel& tmpl) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  ShapeBasis b;
  std::map<std::string, Target> cache;
  auto target = [&](const std::string& rel) -> const Target& {
    auto it = cache.find(rel);
    if (it == cache.end()) it = cache.emplace(rel, read_asset_target(assets, rel)).first;
    return it->second;
  };
  std::vector<Eigen::VectorXd> cols;
  for (const std::string sex : {"female", "male"}) {
    // The sex's average young adult: the base plus the mean of its three ethnic targets.
    Positions mean = assets.base.vertices;
    for (const char* e : {"african", "asian", "caucasian"}) {
      add_target(target("macrodetails/" + std::string(e) + "-" + sex + "-young.target"), 1.0 / 3.0,
                 mean);
    }
    // Every body of the basis exactly left/right symmetric (the T-pose bake and the targets leave
    // micrometres of asymmetry), so that the registered bodies and their principal components
    // are symmetric too.
    smpl::Vertices m = centred_t_pose(assets, tmpl, mean);
    symmetrize(m, assets.skin.mirror);
    (sex == "female" ? b.female_mean : b.male_mean) = m;
    const Eigen::VectorXd fm = flat(m);
    for (const std::string& name : direction_names(sex)) {
      Positions p = mean;
      size_t start = 0;
      while (start <= name.size()) {
        const size_t plus = name.find('+', start);
        const std::string part =
            name.substr(start, plus == std::string::npos ? std::string::npos : plus - start);
        add_target(target(part), 1.0, p);
        if (plus == std::string::npos) break;
        start = plus + 1;
      }
      smpl::Vertices body = centred_t_pose(assets, tmpl, p);
      symmetrize(body, assets.skin.mirror);
      cols.push_back(flat(body) - fm);
      b.names.push_back(name);
      b.sex.push_back(sex);
    }
  }
  b.dirs.resize(cols.front().size(), static_cast<Eigen::Index>(cols.size()));
  for (size_t k = 0; k < cols.size(); ++k) b.dirs.col(static_cast<Eigen::Index>(k)) = cols[k];
  return b;
}

// ------------------------------------------------------------------------------------------------
// Fitting
// ------------------------------------------------------------------------------------------------

namespace {

/// Prior standard deviation of a direction's weight: macro, height, proportion, body-shape and
/// measure targets may be used fully (and beyond, for bodies outside MakeHuman's range); local
/// targets less. The measure targets are MakeHuman's controls of one measurement each: held to
/// 0.5, the women's limb girths (thinner on MakeHuman's average woman than on ANSUR II's) could
/// only be met by making the whole body heavier (chest +15 mm on average over 120 women). The
/// hip and buttock targets too: held to 0.5, the men's hips came out 6.4 mm too broad and 8.3 mm
/// too small around on average (MakeHuman's man is broad and flat at the hip), with them at 1.0
/// +3.8 and -4.3 mm (docs/models.md).
double prior_sd(const std::string& name) {
  if (name.rfind("macrodetails/", 0) == 0 || name.rfind("bodyshapes/", 0) == 0) return 1.0;
  if (name.rfind("measure/", 0) == 0) return 1.0;
  if (name.rfind("hip/", 0) == 0 || name.rfind("buttocks/", 0) == 0) return 1.0;
  return 0.5;
}

/// Index of the weight in fit_measures(). The fit works on the weight's cube-root volume (the
/// paper's weight feature, metres), which is nearly linear in the shape; the weight itself, a
/// cubic, is not.
constexpr int kWeight = 1;

/// `m` (fit_measures() order, kg) with the weight replaced by its feature.
Eigen::VectorXd fit_space(const Eigen::VectorXd& m, const caliper::WeightFormula& formula) {
  Eigen::VectorXd out = m;
  if (out.size() > kWeight && std::isfinite(out[kWeight])) {
    out[kWeight] = caliper::weight_feature(out[kWeight], formula);
  }
  return out;
}

/// The linear surrogate of one sex: measurements ~ a + B w over the sex's directions.
struct Surrogate {
  std::vector<int> columns;  ///< basis columns of the sex
  Eigen::VectorXd a;         ///< M
  Eigen::MatrixXd B;         ///< M x columns
};

constexpr int kSurrogateBodies = 400;
constexpr std::uint64_t kSeed = 20261124;

Surrogate surrogate(const ShapeBasis& basis, const Measurer& measure, const std::string& sex) {
  Surrogate s;
  for (int k = 0; k < static_cast<int>(basis.names.size()); ++k) {
    if (basis.sex[k] == sex) s.columns.push_back(k);
  }
  const int k = static_cast<int>(s.columns.size());
  const int m = static_cast<int>(fit_measures().size());
  caliper::Xoshiro256 rng(kSeed + (sex == "male" ? 1 : 0));
  Eigen::MatrixXd X(kSurrogateBodies, k + 1);
  Eigen::MatrixXd Y(kSurrogateBodies, m);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(basis.names.size()));
  int rejected = 0;
  for (int n = 0; n < kSurrogateBodies; ++n) {
    X(n, 0) = 1.0;
    for (int j = 0; j < k; ++j) {
      const double u = static_cast<double>(rng.next() >> 11) * 0x1.0p-53;
      // Uniform with the prior's SD, half of it: bodies within the usual range.
      w[s.columns[j]] =
          0.5 * prior_sd(basis.names[s.columns[j]]) * 1.7320508075688772 * (2 * u - 1);
      X(n, j + 1) = w[s.columns[j]];
    }
    const Eigen::VectorXd y = fit_space(measure(basis.body(sex, w)), measure.formula);
    if (!y.allFinite()) {  // a measurement the body does not allow (e.g. no hip loop): draw again
      if (++rejected > kSurrogateBodies) {
        throw std::runtime_error("MakeHuman shape: most random " + sex +
                                 " bodies cannot be measured; check the targets");
      }
      --n;
      continue;
    }
    Y.row(n) = y.transpose();
  }
  const Eigen::MatrixXd coef = X.colPivHouseholderQr().solve(Y);  // (k + 1) x m
  s.a = coef.row(0).transpose();
  s.B = coef.bottomRows(k).transpose();
  return s;
}

}  // namespace

namespace {

/// A Gaussian prior on the weights of one sex's directions: precision and mean.
struct Prior {
  Eigen::MatrixXd precision;  ///< k x k
  Eigen::VectorXd mean;       ///< k
};

/// A subject the surrogate's passes leave with a residual beyond this many tolerances gets
/// refine()'s Gauss-Newton steps on the true measurements.
constexpr double kRefineBeyond = 3.0;
constexpr int kRefineSteps = 4;
/// Forward-difference step of refine()'s Jacobian, in units of weight.
constexpr double kJacobianStep = 0.02;

/// Gauss-Newton steps on the subject's cost (squared residuals in tolerances of the true
/// measurements plus the prior) from `w` (K, the sex's columns set), with the Jacobian of the
/// true measurements by forward differences at `w` and Broyden's update after each step, each
/// step halved up to three times until the cost falls; `w` and `measured` (M, kg) are replaced
/// when it does. For the subjects whose bodies the linear surrogate describes badly (the bust of
/// fuller women, a slice that meets another limb), where the corrected passes stall far from the
/// target: over the ANSUR II women, chest residual RMS 32.5 -> 12.8 mm, 480 -> 6 beyond 3 cm
/// (docs/models.md). The surrogate's matrix as the first Jacobian instead of the numerical one
/// was tried: it halves the cost but leaves 400 women beyond 3 cm.
void refine(const ShapeBasis& basis, const Measurer& measure, const Surrogate& s,
            const Prior& prior, const std::string& sex, const std::vector<int>& rows,
            const Eigen::VectorXd& target, const Eigen::VectorXd& tol, Eigen::VectorXd& w,
            Eigen::VectorXd& measured) {
  const int k = static_cast<int>(s.columns.size());
  const Eigen::Index nr = static_cast<Eigen::Index>(rows.size());
  auto scaled = [&](const Eigen::VectorXd& m) {  // residuals in tolerances
    const Eigen::VectorXd f = fit_space(m, measure.formula);
    Eigen::VectorXd r(nr);
    for (Eigen::Index q = 0; q < nr; ++q) r[q] = (f[rows[q]] - target[rows[q]]) / tol[q];
    return r;
  };
  auto own = [&](const Eigen::VectorXd& full) {
    Eigen::VectorXd x(k);
    for (int j = 0; j < k; ++j) x[j] = full[s.columns[j]];
    return x;
  };
  auto cost = [&](const Eigen::VectorXd& r, const Eigen::VectorXd& x) {
    const Eigen::VectorXd d = x - prior.mean;
    const double c = r.squaredNorm() + d.dot(prior.precision * d);
    return std::isfinite(c) ? c : std::numeric_limits<double>::infinity();
  };
  Eigen::VectorXd r = scaled(measured);
  if (!r.allFinite() || r.cwiseAbs().maxCoeff() <= kRefineBeyond) return;
  Eigen::VectorXd x = own(w);
  double c = cost(r, x);
  Eigen::MatrixXd J(nr, k);
  for (int j = 0; j < k; ++j) {
    Eigen::VectorXd wj = w;
    wj[s.columns[j]] += kJacobianStep;
    const Eigen::VectorXd rj = scaled(measure(basis.body(sex, wj)));
    J.col(j) =
        rj.allFinite() ? Eigen::VectorXd((rj - r) / kJacobianStep) : Eigen::VectorXd::Zero(nr);
  }
  for (int step = 0; step < kRefineSteps; ++step) {
    const Eigen::MatrixXd N = J.transpose() * J + prior.precision;
    const Eigen::VectorXd g = J.transpose() * r + prior.precision * (x - prior.mean);
    const Eigen::VectorXd delta = -N.ldlt().solve(g);
    bool improved = false;
    for (double a = 1.0; a >= 0.125 && !improved; a *= 0.5) {
      Eigen::VectorXd wt = w;
      for (int j = 0; j < k; ++j) wt[s.columns[j]] += a * delta[j];
      const Eigen::VectorXd mt = measure(basis.body(sex, wt));
      const Eigen::VectorXd rt = scaled(mt);
      const double ct = cost(rt, own(wt));
      if (ct < c) {
        improved = true;
        // Broyden's update of the Jacobian by the step taken (one numerical Jacobian only).
        const Eigen::VectorXd st = a * delta;
        J += ((rt - r) - J * st) * st.transpose() / st.squaredNorm();
        w = wt;
        measured = mt;
        r = rt;
        x = own(wt);
        c = ct;
      }
    }
    if (!improved || !(r.cwiseAbs().maxCoeff() > 1.0)) break;
  }
}

/// Fits one subject: weighted least squares against the surrogate with the prior, then
/// kCorrections passes with the surrogate's error at the fitted body taken off the targets.
/// Writes the sex's weights into `w` (all K) and true-minus-survey residuals into `residual`.
void fit_one(const ShapeBasis& basis, const Measurer& measure, const Surrogate& s,
             const Prior& prior, const Subject& subj,
             Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> w_out,
             Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> residual) {
  const int m = static_cast<int>(fit_measures().size());
  const int k = static_cast<int>(s.columns.size());
  std::vector<int> rows;
  for (int j = 0; j < m; ++j) {
    if (std::isfinite(subj.values[j])) rows.push_back(j);
  }
  const Eigen::Index nr = static_cast<Eigen::Index>(rows.size());
  const Eigen::VectorXd target = fit_space(subj.values, measure.formula);
  Eigen::MatrixXd A(nr, k);
  Eigen::VectorXd tol(nr);
  for (Eigen::Index q = 0; q < nr; ++q) {
    const int j = rows[q];
    tol[q] = fit_measures()[j].tolerance_for(subj.sex, subj.source);
    if (j == kWeight) {  // the tolerance in kg as a change of the feature at this weight
      tol[q] = caliper::weight_feature(subj.values[j] + tol[q], measure.formula) - target[j];
    }
    A.row(q) = s.B.row(j) / tol[q];
  }
  Eigen::MatrixXd N = A.transpose() * A + prior.precision;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(N);
  const Eigen::VectorXd prior_term = prior.precision * prior.mean;
  Eigen::VectorXd correction = Eigen::VectorXd::Zero(m);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(basis.names.size()));
  Eigen::VectorXd measured, best_w, best_measured;
  double best_cost = std::numeric_limits<double>::infinity();
  // Four passes: the limb girths' slices follow landmark vertices that move with the shape, so
  // the surrogate's error varies more between passes; with two, the women's chest and waist
  // missed by 6.7 mm RMS (120 women), with four by 4.2 mm.
  constexpr int kCorrections = 4;
  for (int pass = 0; pass <= kCorrections; ++pass) {
    Eigen::VectorXd rhs(nr);
    for (Eigen::Index q = 0; q < nr; ++q) {
      const int j = rows[q];
      rhs[q] = (target[j] - s.a[j] - correction[j]) / tol[q];
    }
    const Eigen::VectorXd x = ldlt.solve(A.transpose() * rhs + prior_term);
    for (int j = 0; j < k; ++j) w[s.columns[j]] = x[j];
    measured = measure(basis.body(subj.sex, w));
    const Eigen::VectorXd measured_fit = fit_space(measured, measure.formula);
    const Eigen::VectorXd linear = s.a + s.B * x;
    for (int j = 0; j < m; ++j) {
      if (std::isfinite(measured_fit[j])) correction[j] = measured_fit[j] - linear[j];
    }
    // Keep the best pass: a body whose measurements are far from the surrogate's (a slice
    // meeting another limb, say) can make a correction overshoot.
    double cost = 0.0;
    for (Eigen::Index q = 0; q < nr; ++q) {
      const double r = (measured_fit[rows[q]] - target[rows[q]]) / tol[q];
      cost += std::isfinite(r) ? r * r : std::numeric_limits<double>::infinity();
    }
    if (pass == 0 || cost < best_cost) {
      best_cost = cost;
      best_w = w;
      best_measured = measured;
    }
  }
  refine(basis, measure, s, prior, subj.sex, rows, target, tol, best_w, best_measured);
  w_out = best_w.transpose();
  for (int j : rows) residual[j] = best_measured[j] - subj.values[j];
}

/// Runs `job(i)` for every i in `items` on `threads` threads (i strided over the threads, so
/// the assignment does not depend on timing; each job writes only its own rows).
void parallel_for(const std::vector<size_t>& items, int threads,
                  const std::function<void(size_t)>& job) {
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(threads));
  std::vector<std::exception_ptr> errors(static_cast<size_t>(threads));
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      try {
        for (size_t n = static_cast<size_t>(t); n < items.size();
             n += static_cast<size_t>(threads)) {
          job(items[n]);
        }
      } catch (...) {
        errors[static_cast<size_t>(t)] = std::current_exception();
      }
    });
  }
  for (std::thread& th : pool) th.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

/// Spread of the ANSUR-fitted weights kept in the NHANES prior beyond their covariance
/// (a fraction of each weight's own prior SD), so that the prior is proper in every direction.
constexpr double kPriorFloor = 0.1;

}  // namespace

namespace {

/// The two stages of fit_subjects() for every subject, or, with `check`, for every
/// `check->every`-th subject of each stage and sex, the second stage's prior then made from the
/// first stage's weights in `check->fit` (check_fit()). Fills the rows it fits.
void fit_stages(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                const std::vector<Subject>& subjects, int threads, const FitCheckInput* check,
                FitResult& r) {
  threads = std::max(1, threads);
  for (const std::string sex : {"female", "male"}) {
    const Measurer measure(tmpl, sex == "female" ? basis.female_mean : basis.male_mean, sex);
    const Surrogate s = surrogate(basis, measure, sex);
    const int k = static_cast<int>(s.columns.size());
    // Stage 1: the subjects measured on most ids (ANSUR II), each weight with its own prior.
    Prior independent{Eigen::MatrixXd::Zero(k, k), Eigen::VectorXd::Zero(k)};
    for (int j = 0; j < k; ++j) {
      const double sd = prior_sd(basis.names[s.columns[j]]);
      independent.precision(j, j) = 1.0 / (sd * sd);
    }
    std::vector<size_t> full, partial;
    for (size_t i = 0; i < subjects.size(); ++i) {
      if (subjects[i].sex != sex) continue;
      const Eigen::Index measured =
          (subjects[i].values.array() == subjects[i].values.array()).count();
      (2 * measured > subjects[i].values.size() ? full : partial).push_back(i);
    }
    auto run = [&](const std::vector<size_t>& all, const Prior& prior) {
      std::vector<size_t> items;
      for (size_t n = 0; n < all.size(); ++n) {
        if (check == nullptr || n % static_cast<size_t>(check->every) == 0) items.push_back(all[n]);
      }
      parallel_for(items, threads, [&](size_t i) {
        const Eigen::Index row = static_cast<Eigen::Index>(i);
        fit_one(basis, measure, s, prior, subjects[i], r.weights.row(row), r.residuals.row(row));
      });
    };
    run(full, independent);
    // Stage 2: the subjects measured in part (NHANES: height, weight, hip), with the population
    // of stage 1 as the prior, so that what they were not measured on (span, shoulders, ...)
    // follows from what they were, as in the fully measured people.
    const Eigen::MatrixXd& stage1 = check != nullptr ? check->fit->weights : r.weights;
    Prior population = independent;
    if (full.size() > static_cast<size_t>(k)) {
      Eigen::VectorXd mean = Eigen::VectorXd::Zero(k);
      for (size_t i : full) {
        for (int j = 0; j < k; ++j) mean[j] += stage1(static_cast<Eigen::Index>(i), s.columns[j]);
      }
      mean /= static_cast<double>(full.size());
      Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(k, k);
      for (size_t i : full) {
        Eigen::VectorXd d(k);
        for (int j = 0; j < k; ++j)
          d[j] = stage1(static_cast<Eigen::Index>(i), s.columns[j]) - mean[j];
        cov += d * d.transpose();
      }
      cov /= static_cast<double>(full.size() - 1);
      for (int j = 0; j < k; ++j) {
        const double floor = kPriorFloor * prior_sd(basis.names[s.columns[j]]);
        cov(j, j) += floor * floor;
      }
      population.precision = cov.ldlt().solve(Eigen::MatrixXd::Identity(k, k));
      population.mean = mean;
    }
    run(partial, population);
  }
}

/// Whether two doubles have the same bits (NaN included).
bool same_bits(double a, double b) {
  std::uint64_t x = 0, y = 0;
  static_assert(sizeof x == sizeof a);
  std::memcpy(&x, &a, sizeof a);
  std::memcpy(&y, &b, sizeof b);
  return x == y;
}

}  // namespace

FitResult fit_subjects(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                       const std::vector<Subject>& subjects, int threads) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  FitResult r;
  r.weights = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(subjects.size()),
                                    static_cast<Eigen::Index>(basis.names.size()));
  r.residuals = Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(subjects.size()),
                                          static_cast<Eigen::Index>(fit_measures().size()), kNaN);
  fit_stages(basis, tmpl, subjects, threads, nullptr, r);
  return r;
}

FitCheckReport check_fit(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                         const std::vector<Subject>& subjects, const FitResult& fit, int every,
                         int threads) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  if (every < 1) throw std::invalid_argument("check_fit: every must be at least 1");
  const Eigen::Index n = static_cast<Eigen::Index>(subjects.size());
  if (fit.weights.rows() != n ||
      fit.weights.cols() != static_cast<Eigen::Index>(basis.names.size()) ||
      fit.residuals.rows() != n ||
      fit.residuals.cols() != static_cast<Eigen::Index>(fit_measures().size())) {
    throw std::invalid_argument("check_fit: the fit is not of these subjects and this basis");
  }
  // Rows not refitted keep a marker no fit gives, so that they are told apart from fitted ones.
  const double unfitted = std::numeric_limits<double>::infinity();
  FitResult again{Eigen::MatrixXd::Constant(n, fit.weights.cols(), unfitted),
                  Eigen::MatrixXd::Constant(n, fit.residuals.cols(), kNaN)};
  const FitCheckInput input{&fit, every};
  fit_stages(basis, tmpl, subjects, threads, &input, again);
  FitCheckReport report;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (again.weights.cols() > 0 && again.weights(i, 0) == unfitted) continue;
    ++report.checked;
    bool same = true;
    for (Eigen::Index j = 0; j < fit.weights.cols(); ++j)
      same &= same_bits(again.weights(i, j), fit.weights(i, j));
    for (Eigen::Index j = 0; j < fit.residuals.cols(); ++j) {
      same &= same_bits(again.residuals(i, j), fit.residuals(i, j));
    }
    if (!same) report.differing.push_back(static_cast<size_t>(i));
  }
  return report;
}

// ------------------------------------------------------------------------------------------------
// Cache of a fit
// ------------------------------------------------------------------------------------------------

namespace {

/// FNV-1a over bytes.
struct Fnv {
  std::uint64_t h = 14695981039346656037ull;
  void bytes(const void* p, size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) {
      h ^= c[i];
      h *= 1099511628211ull;
    }
  }
  void text(const std::string& s) {
    const std::uint64_t n = s.size();
    bytes(&n, sizeof n);
    bytes(s.data(), s.size());
  }
  template <typename Derived>
  void matrix(const Eigen::DenseBase<Derived>& m) {
    const std::int64_t r = m.rows(), c = m.cols();
    bytes(&r, sizeof r);
    bytes(&c, sizeof c);
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      for (Eigen::Index j = 0; j < m.cols(); ++j) {
        const auto x = m(i, j);
        bytes(&x, sizeof x);
      }
    }
  }
};

/// The first 8 bytes of a fit file (the last two: the format's version).
constexpr char kFitMagic[9] = "CMHFIT01";

}  // namespace

std::uint64_t fit_fingerprint(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                              const std::vector<Subject>& subjects) {
  Fnv f;
  for (const std::string& n : basis.names) f.text(n);
  for (const std::string& s : basis.sex) f.text(s);
  f.matrix(basis.female_mean);
  f.matrix(basis.male_mean);
  f.matrix(basis.dirs);
  f.matrix(tmpl.faces);
  // The version of the survey measurements' definitions and of the rules that place their
  // levels (makehuman_measures.cpp, caliper::thigh_fold_level(); raise it when one changes), and
  // the thigh's floor under the crotch: a changed definition makes another fit.
  // 2: the thigh at least 3 cm under the crotch; 3: the chest clipped between the acromia;
  // 4: the radiale landmark (the upper arm's acromion-radiale length); 5: the mid-upper-arm
  // girth, and the weight of the open models' own formula (open_model_weight_formula()); 6: the
  // upper leg length (the trochanterion)
  constexpr std::int32_t kMeasuresVersion = 6;
  f.bytes(&kMeasuresVersion, sizeof kMeasuresVersion);
  for (const char* sex : {"female", "male"}) {
    const caliper::WeightFormula w = open_model_weight_formula(sex);
    f.bytes(&w.coefficient, sizeof w.coefficient);
    f.bytes(&w.intercept, sizeof w.intercept);
  }
  f.bytes(&caliper::kThighBelowCrotch, sizeof caliper::kThighBelowCrotch);
  for (const FitMeasure& m : fit_measures()) {
    f.text(m.id);
    f.bytes(&m.tolerance, sizeof m.tolerance);
    f.bytes(&m.male_tolerance, sizeof m.male_tolerance);
    f.bytes(&m.nhanes_tolerance, sizeof m.nhanes_tolerance);
  }
  for (const Subject& s : subjects) {
    f.text(s.sex);
    f.text(s.source);
    // NaN (not measured) is hashed by its bit pattern, the same on every read of the surveys.
    f.matrix(s.values);
  }
  return f.h;
}

void save_fit(const std::string& path, std::uint64_t fingerprint, const FitResult& fit) {
  std::string out(kFitMagic, 8);
  auto put = [&out](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
  put(&fingerprint, sizeof fingerprint);
  const std::int64_t dims[3] = {fit.weights.rows(), fit.weights.cols(), fit.residuals.cols()};
  put(dims, sizeof dims);
  for (const Eigen::MatrixXd* m : {&fit.weights, &fit.residuals}) {
    for (Eigen::Index i = 0; i < m->rows(); ++i) {
      for (Eigen::Index j = 0; j < m->cols(); ++j) {
        const double x = (*m)(i, j);
        put(&x, sizeof x);
      }
    }
  }
  try {
    smpl::write_file_atomic(path, out);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write the fit cache " + path + ": " + e.what());
  }
}

std::optional<FitResult> load_fit(const std::string& path, std::uint64_t fingerprint,
                                  Eigen::Index rows, Eigen::Index cols) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string data(static_cast<size_t>(std::max<std::streamoff>(size, 0)), '\0');
  if (!in.read(data.data(), static_cast<std::streamsize>(data.size()))) {
    throw std::runtime_error("cannot read the fit cache " + path);
  }
  const std::int64_t m = static_cast<std::int64_t>(fit_measures().size());
  const size_t header = 8 + sizeof(std::uint64_t) + 3 * sizeof(std::int64_t);
  if (data.size() < header || data.compare(0, 8, kFitMagic, 8) != 0) {
    throw std::runtime_error("fit cache " + path +
                             " is not a fit file of this version (delete it to fit again)");
  }
  std::uint64_t stored = 0;
  std::int64_t dims[3] = {0, 0, 0};
  std::memcpy(&stored, data.data() + 8, sizeof stored);
  std::memcpy(dims, data.data() + 16, sizeof dims);
  if (stored != fingerprint || dims[0] != rows || dims[1] != cols || dims[2] != m)
    return std::nullopt;
  const size_t n = static_cast<size_t>(rows * cols + rows * m);
  if (data.size() != header + n * sizeof(double)) {
    throw std::runtime_error("fit cache " + path + " is truncated (" + std::to_string(data.size()) +
                             " bytes, " + std::to_string(header + n * sizeof(double)) +
                             " expected; delete it to fit again)");
  }
  FitResult r;
  r.weights.resize(rows, cols);
  r.residuals.resize(rows, m);
  const char* p = data.data() + header;
  for (Eigen::MatrixXd* mat : {&r.weights, &r.residuals}) {
    for (Eigen::Index i = 0; i < mat->rows(); ++i) {
      for (Eigen::Index j = 0; j < mat->cols(); ++j) {
        std::memcpy(&(*mat)(i, j), p, sizeof(double));
        p += sizeof(double);
      }
    }
  }
  return r;
}

// ------------------------------------------------------------------------------------------------
// Principal components
// ------------------------------------------------------------------------------------------------

bool registered(const FitResult& fit, size_t i) {
  for (size_t j = 0; j < fit_measures().size(); ++j) {
    const double r = fit.residuals(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    const FitMeasure& m = fit_measures()[j];
    if (std::isfinite(r) && std::abs(r) > kRefineBeyond * std::max({m.tolerance, m.male_tolerance,
                                                                    m.nhanes_tolerance})) {
      return false;
    }
  }
  return true;
}

namespace {

/// Mean and covariance of a population over z = (w, female?) (K + 1).
struct Moments {
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
};

/// Weighted moments of the rows of `z` (one subject per row) with weights `wt`.
Moments weighted_moments(const std::vector<std::pair<Eigen::VectorXd, double>>& rows) {
  const Eigen::Index n = rows.front().first.size();
  double total = 0.0;
  Moments m{Eigen::VectorXd::Zero(n), Eigen::MatrixXd::Zero(n, n)};
  for (const auto& [z, wt] : rows) {
    m.mean += wt * z;
    total += wt;
  }
  m.mean /= total;
  for (const auto& [z, wt] : rows) m.cov += wt * (z - m.mean) * (z - m.mean).transpose();
  m.cov /= total;
  return m;
}

/// The coordinates z = (w, female?) of subject `i`.
Eigen::VectorXd coordinates(const std::vector<Subject>& subjects, const FitResult& fit, size_t i) {
  const Eigen::Index kall = fit.weights.cols();
  Eigen::VectorXd z(kall + 1);
  z.head(kall) = fit.weights.row(static_cast<Eigen::Index>(i)).transpose();
  z[kall] = subjects[i].sex == "female" ? 1.0 : 0.0;
  return z;
}

/// Variance below this fraction of the largest is numerical noise.
constexpr double kRankTolerance = 1e-9;

/// nhanes_spread_rank()'s cut. At 1e-9 (the numerical noise's) the women's ANSUR II spread was
/// conditioned on 23 directions, vanished after the sixth component, and R4 drove the held-out
/// soldiers' betas to 10 SD (docs/models.md, Limits).
constexpr double kNhanesSpreadTolerance = 1e-3;

}  // namespace

Eigen::Index nhanes_spread_rank(const Eigen::VectorXd& eigenvalues_ascending) {
  const Eigen::Index k = eigenvalues_ascending.size();
  if (k == 0) return 0;
  const double largest = eigenvalues_ascending[k - 1];
  Eigen::Index rank = 0;
  while (rank < k && eigenvalues_ascending[k - 1 - rank] > kNhanesSpreadTolerance * largest) {
    ++rank;
  }
  return rank;
}

namespace {

/// The general adult population of one sex (Population::general): the NHANES subjects' moments
/// plus the ANSUR II subjects' covariance given the NHANES measurements. The NHANES subjects
/// were fitted with the ANSUR II population P (covariance plus the prior floor) as their prior,
/// so their weights lie in mean + span(P C') for the linearised NHANES measurements C: the span
/// D of their spread gives C' up to a change of basis, C' ~ P^-1 D, and the ANSUR II covariance S
/// given C z is S - S C' (C S C')^-1 C S.
Moments general_moments(const ShapeBasis& basis, const std::vector<Subject>& subjects,
                        const FitResult& fit, const std::string& sex) {
  std::vector<std::pair<Eigen::VectorXd, double>> ansur, nhanes;
  for (size_t i = 0; i < subjects.size(); ++i) {
    if (subjects[i].sex != sex || !registered(fit, i)) continue;
    (subjects[i].source == "NHANES" ? nhanes : ansur)
        .emplace_back(coordinates(subjects, fit, i), 1.0);
  }
  if (ansur.size() < 2 || nhanes.size() < 2) {
    throw std::invalid_argument("shape_model: the general population of sex " + sex +
                                " needs ANSUR II and NHANES subjects (" +
                                std::to_string(ansur.size()) + " and " +
                                std::to_string(nhanes.size()) + ")");
  }
  std::vector<Eigen::Index> cols;  // the sex's directions
  for (size_t k = 0; k < basis.sex.size(); ++k) {
    if (basis.sex[k] == sex) cols.push_back(static_cast<Eigen::Index>(k));
  }
  const Eigen::Index k = static_cast<Eigen::Index>(cols.size());
  const Moments a = weighted_moments(ansur);
  Moments g = weighted_moments(nhanes);
  Eigen::MatrixXd S(k, k), N(k, k);
  for (Eigen::Index r = 0; r < k; ++r) {
    for (Eigen::Index c = 0; c < k; ++c) {
      S(r, c) = a.cov(cols[r], cols[c]);
      N(r, c) = g.cov(cols[r], cols[c]);
    }
  }
  Eigen::MatrixXd P = S;
  for (Eigen::Index j = 0; j < k; ++j) {
    const double floor = kPriorFloor * prior_sd(basis.names[static_cast<size_t>(cols[j])]);
    P(j, j) += floor * floor;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> spread(N);
  const Eigen::Index rank = nhanes_spread_rank(spread.eigenvalues());
  const Eigen::MatrixXd D = spread.eigenvectors().rightCols(rank);
  const Eigen::MatrixXd Ct = P.ldlt().solve(D);  // k x rank
  const Eigen::MatrixXd SC = S * Ct;
  const Eigen::MatrixXd given = S - SC * (Ct.transpose() * SC).ldlt().solve(SC.transpose());
  for (Eigen::Index r = 0; r < k; ++r) {
    for (Eigen::Index c = 0; c < k; ++c) g.cov(cols[r], cols[c]) += given(r, c);
  }
  return g;
}

/// The general adult population of `sex` (general_moments()); "neutral": the mixture of the
/// sexes, each half.
Moments general_population(const ShapeBasis& basis, const std::vector<Subject>& subjects,
                           const FitResult& fit, const std::string& sex) {
  if (sex != "neutral") return general_moments(basis, subjects, fit, sex);
  const Moments f = general_moments(basis, subjects, fit, "female");
  const Moments m = general_moments(basis, subjects, fit, "male");
  Moments out;
  out.mean = 0.5 * (f.mean + m.mean);
  const Eigen::VectorXd d = f.mean - m.mean;
  out.cov = 0.5 * (f.cov + m.cov) + 0.25 * d * d.transpose();
  return out;
}

/// The pooled population of `sex` (Population::general false; "neutral": both sexes, each
/// half): every registered subject of the sex alike, or each survey weighted to its share.
Moments pooled_moments(const std::vector<Subject>& subjects, const FitResult& fit,
                       const std::string& sex, const std::map<std::string, double>& survey_share) {
  int n_female = 0, n_male = 0;
  std::map<std::pair<std::string, std::string>, int> n_survey;  // (sex, source) -> subjects
  for (size_t i = 0; i < subjects.size(); ++i) {
    if (!registered(fit, i)) continue;
    const Subject& s = subjects[i];
    (s.sex == "male" ? n_male : n_female) += 1;
    ++n_survey[{s.sex, s.source}];
  }
  // A subject's weight within its sex (the sexes' totals are 1 each).
  auto within_sex = [&](const Subject& s) {
    if (survey_share.empty()) return 1.0 / (s.sex == "male" ? n_male : n_female);
    const auto it = survey_share.find(s.source);
    if (it == survey_share.end()) {
      throw std::invalid_argument("shape_model: no population share for the survey " + s.source);
    }
    return it->second / n_survey.at({s.sex, s.source});
  };
  std::vector<std::pair<Eigen::VectorXd, double>> rows;
  for (size_t i = 0; i < subjects.size(); ++i) {
    const Subject& s = subjects[i];
    if ((sex != "neutral" && s.sex != sex) || !registered(fit, i)) continue;
    // Without shares the arithmetic is the original one (1 per subject of a sex), so that the
    // files stay the same to the byte.
    const double weight = survey_share.empty() && sex != "neutral"
                              ? 1.0
                              : (sex != "neutral" ? 1.0 : 0.5) * within_sex(s);
    rows.emplace_back(coordinates(subjects, fit, i), weight);
  }
  if (rows.size() < 2) {
    throw std::invalid_argument("shape_model: too few subjects of sex " + sex);
  }
  return weighted_moments(rows);
}

/// Writes each survey's population in the model's betas (population.hpp; keys "ansur2",
/// "nhanes"). ANSUR II: the moments of the betas of its registered subjects of `sex` (the
/// neutral model: both sexes, each weighted to half, as its own population). NHANES: the general
/// adult population (general_population(): the NHANES subjects' moments plus ANSUR II's spread
/// given their measurements), not the NHANES subjects' own moments: registered from four
/// measurements, those vary along only the few directions the four move the fit, so their
/// covariance is singular and no prior for a person (`caliper create --population nhanes` was
/// refused with it). On a model of the general population (Population::general) this is the
/// model's own N(0, I), to rounding.
void store_survey_populations(const ShapeBasis& basis, const std::vector<Subject>& subjects,
                              const FitResult& fit, const std::string& sex,
                              const Eigen::VectorXd& mean, const Eigen::MatrixXd& to_betas,
                              smpl::BodyModel& model) {
  for (const auto& [key, survey] : {std::pair<const char*, const char*>{"ansur2", "ANSUR II"},
                                    std::pair<const char*, const char*>{"nhanes", "NHANES"}}) {
    std::map<std::string, int> per_sex;
    for (size_t i = 0; i < subjects.size(); ++i) {
      const Subject& s = subjects[i];
      if (s.source == survey && (sex == "neutral" || s.sex == sex) && registered(fit, i)) {
        ++per_sex[s.sex];
      }
    }
    std::vector<std::pair<Eigen::VectorXd, double>> rows;
    for (size_t i = 0; i < subjects.size(); ++i) {
      const Subject& s = subjects[i];
      if (s.source != survey || (sex != "neutral" && s.sex != sex) || !registered(fit, i)) {
        continue;
      }
      const double weight = sex == "neutral" ? 0.5 / per_sex.at(s.sex) : 1.0;
      rows.emplace_back(to_betas * (coordinates(subjects, fit, i) - mean), weight);
    }
    if (rows.size() < 2) continue;
    caliper::SurveyPopulation p;
    p.survey = survey;
    p.subjects = static_cast<int>(rows.size());
    if (std::string(key) == "nhanes") {
      // The general population needs ANSUR II subjects of each sex it covers too.
      std::map<std::string, int> soldiers;
      for (size_t i = 0; i < subjects.size(); ++i) {
        if (subjects[i].source == "ANSUR II" && registered(fit, i)) ++soldiers[subjects[i].sex];
      }
      const bool both =
          sex != "neutral" ? soldiers[sex] >= 2 : soldiers["female"] >= 2 && soldiers["male"] >= 2;
      if (!both || (sex == "neutral" && (per_sex["female"] < 2 || per_sex["male"] < 2))) continue;
      const Moments g = general_population(basis, subjects, fit, sex);
      p.mean = to_betas * (g.mean - mean);
      const Eigen::MatrixXd cov = to_betas * g.cov * to_betas.transpose();
      p.cov = 0.5 * (cov + cov.transpose());  // symmetric to the bit
    } else {
      const Moments m = weighted_moments(rows);
      p.mean = m.mean;
      p.cov = 0.5 * (m.cov + m.cov.transpose());
    }
    caliper::set_survey_population(model, key, p);
  }
}

/// The general population's body for a height and a weight (caliper/shape_curve.hpp): the
/// quadratic curve of the NHANES subjects' betas on their surveyed height and weight (the
/// neutral model: both sexes, each weighted to half). NHANES, not ANSUR II: the curve is the
/// general adult population's, whose betas ~ N(0, I) the model's are.
void store_shape_curve(const std::vector<Subject>& subjects, const FitResult& fit,
                       const std::string& sex, const Eigen::VectorXd& mean,
                       const Eigen::MatrixXd& to_betas, smpl::BodyModel& model) {
  std::map<std::string, int> per_sex;
  std::vector<size_t> rows;
  for (size_t i = 0; i < subjects.size(); ++i) {
    const Subject& s = subjects[i];
    if (s.source == "NHANES" && (sex == "neutral" || s.sex == sex) && registered(fit, i)) {
      ++per_sex[s.sex];
      rows.push_back(i);
    }
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  Eigen::VectorXd height(n), weight(n), wt(n);
  Eigen::MatrixXd betas(n, to_betas.rows());
  for (Eigen::Index r = 0; r < n; ++r) {
    const size_t i = rows[static_cast<size_t>(r)];
    height[r] = subjects[i].values[0];
    weight[r] = subjects[i].values[1];
    wt[r] = sex == "neutral" ? 0.5 / per_sex.at(subjects[i].sex) : 1.0;
    betas.row(r) = (to_betas * (coordinates(subjects, fit, i) - mean)).transpose();
  }
  caliper::set_shape_curve(model,
                           caliper::fit_shape_curve(height, weight, betas, wt,
                                                    "NHANES 2017-2020 development half, registered",
                                                    caliper::ShapeCurve::WeightInput::kKilograms));
}

}  // namespace

smpl::BodyModel shape_model(const ShapeBasis& basis, const smpl::BodyModel& tmpl,
                            const std::vector<Subject>& subjects, const FitResult& fit,
                            const std::string& sex, int num_betas, const Population& population) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  const Eigen::Index kall = static_cast<Eigen::Index>(basis.names.size());
  // Coordinates z = (w, female?) of every body: body = male_mean + A z, A = [dirs | f - m].
  Eigen::MatrixXd A(basis.dirs.rows(), kall + 1);
  A.leftCols(kall) = basis.dirs;
  A.col(kall) = flat(basis.female_mean) - flat(basis.male_mean);
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
  if (population.general) {
    Moments m = general_population(basis, subjects, fit, sex);
    mean = std::move(m.mean);
    cov = std::move(m.cov);
  } else {
    Moments m = pooled_moments(subjects, fit, sex, population.survey_share);
    mean = std::move(m.mean);
    cov = std::move(m.cov);
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(kall + 1).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(A.rows(), kall + 1);
  const Eigen::MatrixXd M = R * cov * R.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(M);
  smpl::BodyModel model = tmpl;
  const Eigen::VectorXd v = flat(basis.male_mean) + A * mean;
  for (Eigen::Index i = 0; i < model.v_template.rows(); ++i) {
    for (int c = 0; c < 3; ++c) model.v_template(i, c) = v[3 * i + c];
  }
  // Components the registered population does not vary along (the population spans at most as
  // many directions as its subjects have measurements) are left out.
  const double largest = std::max(eig.eigenvalues()[kall], 0.0);
  int kept = 0;
  while (kept < num_betas && kept <= kall &&
         eig.eigenvalues()[kall - kept] > kRankTolerance * largest) {
    ++kept;
  }
  model.shapedirs.resize(A.rows(), kept);
  // A subject's betas: beta_b = e_b' R (z - mean) / sqrt(lambda_b), signed as the component.
  Eigen::MatrixXd to_betas(kept, kall + 1);
  for (int b = 0; b < kept; ++b) {
    const Eigen::Index e = kall - b;  // eigenvalues ascending: the largest last
    const double lambda = std::max(eig.eigenvalues()[e], 0.0);
    Eigen::VectorXd dir = Q * eig.eigenvectors().col(e) * std::sqrt(lambda);
    // Sign convention (an eigenvector's sign is arbitrary): the offsets of +1 SD sum to a
    // positive number, so that +beta means the same on every machine.
    const double sign = dir.sum() < 0.0 ? -1.0 : 1.0;
    model.shapedirs.col(b) = sign * dir;
    to_betas.row(b) = sign / std::sqrt(lambda) * eig.eigenvectors().col(e).transpose() * R;
  }
  store_survey_populations(basis, subjects, fit, sex, mean, to_betas, model);
  if (population.general) store_shape_curve(subjects, fit, sex, mean, to_betas, model);
  // The formula the fit weighed the bodies with, so that the product weighs them alike.
  caliper::set_weight_formula(model, open_model_weight_formula(sex));
  // The basis is symmetric, so the mean and the components are to rounding; made exact here
  // (mirrored landmarks then agree to the last bit).
  const Eigen::Index nv = model.v_template.rows();
  symmetrize(model.v_template, model.mirror);
  for (int b = 0; b < kept; ++b) {
    symmetrize(Eigen::Map<smpl::Vertices>(model.shapedirs.col(b).data(), nv, 3), model.mirror);
  }
  model.posedirs = Eigen::MatrixXd::Zero(A.rows(), 0);
  // The iliac crest (the NHANES and WHO waist level) as landmarks: the vertex the fit measured
  // every subject of the sex at (the rule placed on the sex's MakeHuman average, as the fit's
  // Measurer does), so that the model measures the waist it was fitted to; placed on this
  // model's mean body, the rule can pick another vertex (the general population's mean man:
  // vertex 10707 instead of the fit's 10772, 22 mm less girth at the mean; docs/evaluation.md).
  // The neutral model, fitted through both sexes, takes the rule on the mean of the two
  // averages (on the general population's neutral mean body the knee rule finds no vertex).
  // The right one is the left's mirror vertex (the template's exact mirror map).
  const smpl::Vertices both = 0.5 * (basis.female_mean + basis.male_mean);
  const smpl::Vertices& rest = sex == "female" ? basis.female_mean
                               : sex == "male" ? basis.male_mean
                                               : both;
  const SurveyVertices at =
      survey_vertices(rest, tmpl.faces, tmpl.j_regressor, caliper::landmarks_for(tmpl), sex);
  model.landmarks["left_iliac_crest"] = {at.iliac_crest};
  model.landmarks["right_iliac_crest"] = {model.mirror[static_cast<std::size_t>(at.iliac_crest)]};
  // The thigh's level, ANSUR II's gluteal furrow, the same way (the vertex the fit measured the
  // thigh at; caliper::circumferences() slices there when a model carries it).
  model.landmarks["left_gluteal_fold"] = {at.gluteal_fold};
  model.landmarks["right_gluteal_fold"] = {model.mirror[static_cast<std::size_t>(at.gluteal_fold)]};
  // The upper leg's ends the fit measured, the same way: the trochanterion (16 ids, a point on
  // an edge; makehuman_measures.hpp) and the knee's lateral vertex (the knee height's).
  model.landmarks["left_trochanterion"] = at.trochanterion;
  std::vector<int>& right = model.landmarks["right_trochanterion"];
  for (const int i : at.trochanterion) right.push_back(model.mirror[static_cast<std::size_t>(i)]);
  model.landmarks["left_knee_lateral"] = {at.knee_lateral};
  model.landmarks["right_knee_lateral"] = {model.mirror[static_cast<std::size_t>(at.knee_lateral)]};
  model.meta.name = "caliper-open-" + sex;
  model.meta.gender = sex;
  model.meta.source =
      "caliper-modelgen: MakeHuman hm08 CC0 targets fitted to ANSUR II and "
      "NHANES subjects, principal components";
  smpl::validate(model, "MakeHuman shape model");
  return model;
}

void level_soles(smpl::BodyModel& model, double full, double fade) {
  if (model.v_template.rows() == 0 || !(fade > full) || !(full >= 0.0)) {
    throw std::invalid_argument("level_soles: needs a mesh and 0 <= full < fade");
  }
  Eigen::Index lowest = 0;
  const double floor = model.v_template.col(1).minCoeff(&lowest);
  const Eigen::Index nv = model.v_template.rows();
  for (Eigen::Index v = 0; v < nv; ++v) {
    const double h = model.v_template(v, 1) - floor;
    if (h >= fade) continue;
    const double t = std::clamp((fade - h) / (fade - full), 0.0, 1.0);
    const double w = t * t * (3.0 - 2.0 * t);  // smoothstep: 1 up to `full`, 0 from `fade`
    for (Eigen::Index b = 0; b < model.shapedirs.cols(); ++b) {
      double& y = model.shapedirs(3 * v + 1, b);
      y = (1.0 - w) * y + w * model.shapedirs(3 * lowest + 1, b);
    }
  }
}

}  // namespace modelgen::mh
