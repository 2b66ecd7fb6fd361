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

HangingArms hanging_arms(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  const caliper::LandmarkTable& lm = model.landmarks;
  const int kShoulder[2] = {16, 17};  // SMPL left_shoulder, right_shoulder
  const char* kAcromion[2] = {"left_shoulder", "right_shoulder"};
  const char* kWrist[2] = {"left_wrist", "right_wrist"};
  const char* kRadiale[2] = {"left_radiale", "right_radiale"};
  if (model.parents.size() <= 17 || model.j_regressor.rows() <= 17 ||
      model.weights.cols() != static_cast<Eigen::Index>(model.parents.size()) ||
      model.weights.rows() != vertices.rows() || model.j_regressor.cols() != vertices.rows()) {
    throw std::invalid_argument(
        "hanging arms: the model needs SMPL's joints (left and right shoulder are joints 16 and "
        "17) with a joint regressor and skinning weights for its " +
        std::to_string(vertices.rows()) + " vertices");
  }
  // Joints whose motion follows a shoulder rotation: the shoulder and its descendants.
  std::vector<char> follows[2];
  for (int s = 0; s < 2; ++s) {
    follows[s].assign(model.parents.size(), 0);
    follows[s][static_cast<std::size_t>(kShoulder[s])] = 1;
    for (std::size_t j = 0; j < model.parents.size(); ++j) {
      const int p = model.parents[j];
      if (p >= 0 && follows[s][static_cast<std::size_t>(p)]) {
        follows[s][j] = 1;
      }
    }
  }
  auto landmark = [&](const char* name) -> std::vector<int> {
    const auto it = lm.find(name);
    if (it == lm.end() || it->second.empty()) {
      throw std::invalid_argument(std::string("hanging arms: the model has no landmark '") + name +
                                  "'");
    }
    return it->second;
  };
  HangingArms out;
  for (int s = 0; s < 2; ++s) {
    Eigen::Vector3d joint = Eigen::Vector3d::Zero();
    for (smpl::SparseMatrix::InnerIterator it(model.j_regressor, kShoulder[s]); it; ++it) {
      joint += it.value() * vertices.row(it.col()).transpose();
    }
    // T-pose arm along +x (left) or -x (right); hanging: rotated 90 degrees down about z.
    const double sign = s == 0 ? -1.0 : 1.0;
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(sign * 0.5 * smpl::kPi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::Vector3d acromion = Eigen::Vector3d::Zero();
    const std::vector<int> a = landmark(kAcromion[s]);
    for (int v : a) {
      acromion += vertices.row(v).transpose() / static_cast<double>(a.size());
    }
    // Linear blend skinning restricted to the shoulder rotation: the share of a vertex's
    // weight on joints that follow the shoulder moves with it.
    auto hanging = [&](const std::vector<int>& ids) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int v : ids) {
        double moving = 0;
        for (smpl::SparseMatrix::InnerIterator it(model.weights, v); it; ++it) {
          if (follows[s][static_cast<std::size_t>(it.col())]) {
            moving += it.value();
          }
        }
        const Eigen::Vector3d p = vertices.row(v).transpose();
        sum += (p + moving * (r * (p - joint) + joint - p)) / static_cast<double>(ids.size());
      }
      return sum;
    };
    const Eigen::Vector3d wrist = hanging(landmark(kWrist[s]));
    const auto radiale = lm.find(kRadiale[s]);
    out.radiale[s] = radiale == lm.end() || radiale->second.empty()
                         ? Eigen::Vector3d::Constant(std::nan(""))
                         : hanging(radiale->second);
    out.acromion[s] = acromion;
    out.wrist[s] = wrist;
  }
  return out;
}

double hanging_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  const HangingArms h = hanging_arms(model, vertices);
  return 0.5 * ((h.wrist[0] - h.acromion[0]).norm() + (h.wrist[1] - h.acromion[1]).norm());
}

double hanging_upper_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  const HangingArms h = hanging_arms(model, vertices);
  return 0.5 * ((h.radiale[0] - h.acromion[0]).norm() + (h.radiale[1] - h.acromion[1]).norm());
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
  out["weight"] =
      caliper::weight_from_volume(volume, caliper::weight_formula_for(model.meta.gender));
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
