/// \file validation.cpp
/// The open models' validation measurements and figures, the RNG and the arithmetic guard (see
/// validation.hpp).
#include "validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "caliper/circumference.hpp"
#include "caliper/portable_math.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "smpl/constants.hpp"

namespace modelgen {

// libm's transcendental functions differ in the last bit between CPUs (portable_math.hpp).
namespace pm = caliper::portable;

// ------------------------------------------------------------------------------------ RNG

double Rng::uniform() {
  return (static_cast<double>(next() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = uniform(), u2 = uniform();
  const double r = std::sqrt(-2.0 * pm::log(u1));
  const double t = 2.0 * smpl::kPi * u2;
  spare_ = r * pm::sin(t);
  has_spare_ = true;
  return r * pm::cos(t);
}

// ------------------------------------------------------------------------------------ measurements

namespace {

// The validation measurements in table order, each with its survey dimension (-1: arm_length,
// which is kAcromionRadiale + kRadialeStylion).
struct ValidationMeasure {
  const char* id;
  int dim;
};
constexpr ValidationMeasure kValidationMeasures[] = {{"stature", kStature},
                                                     {"weight", kWeight},
                                                     {"span", kSpan},
                                                     {"crotch_height", kCrotchHeight},
                                                     {"hip_breadth", kHipBreadth},
                                                     {"arm_length", -1},
                                                     {"upper_arm_length", kAcromionRadiale},
                                                     {"biacromial", kBiacromial},
                                                     {"chest_circ", kChestCirc},
                                                     {"waist_circ", kWaistCirc},
                                                     {"buttock_circ", kButtockCirc}};

}  // namespace

const std::vector<std::string>& validation_ids() {
  static const std::vector<std::string> kIds = [] {
    std::vector<std::string> ids;
    for (const ValidationMeasure& m : kValidationMeasures) ids.emplace_back(m.id);
    return ids;
  }();
  return kIds;
}

int validation_dim(const std::string& id) {
  for (const ValidationMeasure& m : kValidationMeasures) {
    if (id == m.id) {
      return m.dim;
    }
  }
  return -1;
}

std::map<std::string, double> validation_measurements(const smpl::BodyModel& model,
                                                      const smpl::Vertices& vertices) {
  const caliper::LandmarkTable& lm = model.landmarks;
  const caliper::MeasurementMap m = caliper::measure(vertices, lm);
  const caliper::MeasurementMap c = caliper::circumferences(vertices, model.faces, lm);
  const double volume = caliper::mesh_volume(vertices, model.faces);
  std::map<std::string, double> out;
  auto get = [](const caliper::MeasurementMap& mm, const std::string& k) {
    const auto it = mm.find(k);
    return it == mm.end() ? std::nan("") : it->second;
  };
  out["stature"] = get(m, "height");
  out["weight"] = caliper::weight_from_volume(volume, caliper::weight_formula_of(model));
  out["span"] = get(m, "arm_span_fingertips");
  out["crotch_height"] = get(m, "inseam_height");
  out["hip_breadth"] = get(m, "hip_width");
  out["arm_length"] = hanging_arm_length(model, vertices);
  if (const double upper = hanging_upper_arm_length(model, vertices); std::isfinite(upper)) {
    out["upper_arm_length"] = upper;
  }
  out["arm_length_tpose"] = get(m, "arm_length");
  out["biacromial"] = get(m, "shoulder_width");
  out["chest_circ"] = get(c, "chest_circumference");
  out["waist_circ"] = get(c, "waist_circumference");
  out["buttock_circ"] = get(c, "hip_circumference");
  return out;
}

// ------------------------------------------------------------------------------------ numerics

DeterministicNumerics::DeterministicNumerics()
    : l1_(Eigen::l1CacheSize()), l2_(Eigen::l2CacheSize()), l3_(Eigen::l3CacheSize()) {
  Eigen::setCpuCacheSizes(std::ptrdiff_t{32} * 1024, std::ptrdiff_t{512} * 1024,
                          std::ptrdiff_t{4} * 1024 * 1024);
}

DeterministicNumerics::~DeterministicNumerics() {
  Eigen::setCpuCacheSizes(l1_, l2_, l3_);
}

// ------------------------------------------------------------------------------------ validation

ValidationFigures survey_figures(const SurveyStats& stats, const std::string& gender) {
  Eigen::VectorXd mu;
  Eigen::MatrixXd cov;
  int count = 0;
  if (gender == "neutral") {
    const Eigen::VectorXd df = stats.female.mean - stats.male.mean;
    mu = 0.5 * (stats.female.mean + stats.male.mean);
    cov = 0.5 * (stats.female.covariance() + stats.male.covariance()) + 0.25 * df * df.transpose();
    count = stats.female.count + stats.male.count;
  } else {
    const SexStats& s = stats.of(gender);
    mu = s.mean;
    cov = s.covariance();
    count = s.count;
  }
  ValidationFigures f;
  f.count = count;
  for (const std::string& id : validation_ids()) {
    const int d = validation_dim(id);
    if (d >= 0) {
      f.mean[id] = mu[d];
      f.sd[id] = std::sqrt(cov(d, d));
    } else {
      f.mean[id] = mu[kAcromionRadiale] + mu[kRadialeStylion];
      f.sd[id] = std::sqrt(cov(kAcromionRadiale, kAcromionRadiale) +
                           cov(kRadialeStylion, kRadialeStylion) +
                           2 * cov(kAcromionRadiale, kRadialeStylion));
    }
  }
  auto corr = [&](int a, int b) { return cov(a, b) / std::sqrt(cov(a, a) * cov(b, b)); };
  f.corr_stature_span = corr(kStature, kSpan);
  f.corr_stature_weight = corr(kStature, kWeight);
  return f;
}

ValidationFigures model_figures(const smpl::BodyModel& model, int samples, std::uint64_t seed,
                                const caliper::SurveyPopulation* population) {
  const DeterministicNumerics pinned;
  Rng rng(seed);
  std::map<std::string, std::vector<double>> vals;
  Eigen::VectorXd betas(model.num_betas());
  const Eigen::MatrixXd factor =
      population ? caliper::sampling_factor(population->cov) : Eigen::MatrixXd();
  for (int b = 0; b < samples; ++b) {
    for (int k = 0; k < betas.size(); ++k) {
      betas[k] = rng.normal();
    }
    if (population) betas = population->mean + factor * betas;
    const Eigen::VectorXd flat = model.shapedirs * betas;
    smpl::Vertices v = model.v_template;
    for (int i = 0; i < v.rows(); ++i) {
      for (int c = 0; c < 3; ++c) {
        v(i, c) += flat[3 * i + c];
      }
    }
    for (const auto& [k, x] : validation_measurements(model, v)) {
      vals[k].push_back(x);
    }
  }
  ValidationFigures f;
  f.count = samples;
  auto moments = [](const std::vector<double>& x, double& mean, double& sd) {
    mean = 0;
    for (double v : x) {
      mean += v;
    }
    mean /= static_cast<double>(x.size());
    double var = 0;
    for (double v : x) {
      var += (v - mean) * (v - mean);
    }
    sd = std::sqrt(var / static_cast<double>(x.size() - 1));
  };
  for (const auto& [k, x] : vals) {
    moments(x, f.mean[k], f.sd[k]);
  }
  auto corr = [&](const std::string& a, const std::string& b) {
    const auto& xa = vals[a];
    const auto& xb = vals[b];
    double c = 0;
    for (std::size_t i = 0; i < xa.size(); ++i) {
      c += (xa[i] - f.mean[a]) * (xb[i] - f.mean[b]);
    }
    c /= static_cast<double>(xa.size() - 1);
    return c / (f.sd[a] * f.sd[b]);
  };
  f.corr_stature_span = corr("stature", "span");
  f.corr_stature_weight = corr("stature", "weight");
  return f;
}

}  // namespace modelgen
