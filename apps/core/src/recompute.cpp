// From a Document to the avatar: model entries and the pure recomputation.
#include "app/recompute.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "caliper/avatar.hpp"
#include "caliper/errors.hpp"
#include "smpl/io.hpp"

namespace caliper::app {

// ---------------------------------------------------------------------------------------------
// The hanging arm
HangingArmMap::HangingArmMap(std::shared_ptr<const smpl::BodyModel> model)
    : model_(std::move(model)) {}

void HangingArmMap::compute() const {
  std::call_once(once_, [this] {
    try {
      map_ = hanging_arm_map(*model_);
    } catch (const std::exception& e) {
      reason_ = e.what();
    }
  });
}

const LinearMap* HangingArmMap::get() const {
  compute();
  return map_ ? &*map_ : nullptr;
}

const std::string& HangingArmMap::reason() const {
  compute();
  return reason_;
}

std::string hanging_arm_unavailable(const ModelEntry& entry) {
  if (!entry.hanging_arm) return "the model entry was made without a hanging-arm map";
  return entry.hanging_arm->reason();
}

const LinearMap& hanging_arm(const ModelEntry& entry) {
  if (const LinearMap* map = entry.hanging_arm ? entry.hanging_arm->get() : nullptr) return *map;
  throw InvalidInputError("the arm length is taken hanging, but model " + entry.label +
                          " cannot map a hanging arm onto its own (" +
                          hanging_arm_unavailable(entry) +
                          "); untick 'taken hanging' and give the arm length out sideways");
}

namespace {
bool is_input(const Document& doc, const std::string& id) {
  const std::vector<std::string>& inputs = editable_inputs(doc);
  return std::find(inputs.begin(), inputs.end(), id) != inputs.end();
}
}  // namespace

MeasurementMap regression_inputs(const Document& doc, const ModelEntry& entry) {
  MeasurementMap in;
  for (const std::string& id : editable_inputs(doc)) {
    auto it = doc.values.find(id);
    if (it == doc.values.end()) throw InvalidInputError("no value for " + id);
    in[id] = it->second;
  }
  if (auto arm = in.find("arm_length"); arm != in.end() && doc.arm_taken_hanging)
    arm->second = hanging_arm(entry).apply(arm->second);
  return in;
}

MeasurementMap as_typed(const Document& doc, const ModelEntry& entry, MeasurementMap measured) {
  auto arm = measured.find("arm_length");
  if (!doc.arm_taken_hanging || arm == measured.end()) return measured;
  if (const LinearMap* map = entry.hanging_arm ? entry.hanging_arm->get() : nullptr) {
    arm->second = (arm->second - map->b) / map->a;
  } else {
    measured.erase(arm);
  }
  return measured;
}

Document with_arm_taken_hanging(const Document& doc, const ModelEntry& entry, bool hanging) {
  Document d = doc;
  d.arm_taken_hanging = hanging;
  if (doc.arm_taken_hanging == hanging) return d;
  auto arm = d.values.find("arm_length");
  if (arm == d.values.end()) return d;
  const LinearMap* map = entry.hanging_arm ? entry.hanging_arm->get() : nullptr;
  if (map == nullptr && !hanging && !is_input(doc, "arm_length")) {
    d.values.erase(arm);  // not in use, and nothing to convert it with
    return d;
  }
  const LinearMap& m = map != nullptr ? *map : hanging_arm(entry);  // throws without one
  arm->second = hanging ? (arm->second - m.b) / m.a : m.apply(arm->second);
  return d;
}

// ---------------------------------------------------------------------------------------------
// Model entries and the avatar
ModelEntry make_model_entry(std::shared_ptr<const smpl::BodyModel> model, const std::string& label,
                            const TrainOptions& options) {
  smpl::validate(*model, label);
  ModelEntry e;
  e.label = label;
  e.measure_info = std::make_shared<const ModelMeasureInfo>(*model);
  e.landmarks = e.measure_info->landmarks;
  e.regressors = std::make_shared<const RegressorSet>(train_regressors(*model, options));
  e.curve = shape_curve(*model);
  if (e.curve) {
    e.curve_measurer = std::make_shared<const ShapeMeasurer>(
        *model, e.landmarks, available_measurements(e.landmarks),
        std::min(model->num_betas(), kMaxMeasurerBetas));
  }
  e.hanging_arm = std::make_shared<const HangingArmMap>(model);  // worked out on first use
  e.preview_shapedirs = std::make_shared<const Eigen::MatrixXf>(model->shapedirs.cast<float>());
  e.model = std::move(model);
  return e;
}

MeasurementMap mean_shape_inputs(const ModelEntry& entry) {
  MeasureOptions mo;
  mo.circumferences = false;
  const MeasurementMap all = measure_all(*entry.model, entry.model->v_template, mo);
  MeasurementMap inputs;
  for (const std::string& id : choice_inputs(RegressorChoice::R6)) {
    auto it = all.find(id);
    if (it != all.end()) inputs[id] = it->second;
  }
  return inputs;
}

namespace {

/// The betas the active regressor of `doc` predicts (model.num_betas() of them, zeros beyond
/// the regressor's outputs); the posterior SD and covariance for the noise-aware one.
struct Prediction {
  Eigen::VectorXd betas;  ///< the regressor's outputs only
  Eigen::VectorXd sd;
  std::optional<Eigen::MatrixXd> covariance;
};

Prediction predict(const Document& doc, const ModelEntry& e) {
  const MeasurementMap in = regression_inputs(doc, e);
  Prediction p;
  const RegressorChoice choice = active_regressor(doc);
  if (choice == RegressorChoice::NoiseAware) {
    if (!e.regressors->noise_aware)
      throw InvalidInputError("this model has no noise-aware regressor");
    Posterior post = e.regressors->noise_aware->predict(in);
    p.betas = post.mean;
    p.sd = post.sd();
    p.covariance = post.covariance;
  } else {
    const LinearRegressor* r = e.regressors->find(to_string(choice));
    if (r == nullptr) throw InvalidInputError("this model has no regressor " + to_string(choice));
    p.betas = linear_betas(*e.model, *r, in, e.curve ? &*e.curve : nullptr, e.landmarks,
                           e.curve_measurer.get());
  }
  if (!p.betas.allFinite()) throw InvalidInputError("the regressor returned non-finite betas");
  return p;
}

/// Metres each vertex moves because of the beta components beyond +-2 SD.
std::vector<float> implausible_displacement(const smpl::BodyModel& m, const Eigen::VectorXd& b) {
  const Eigen::Index k = b.size();
  const Eigen::VectorXd excess = b - b.cwiseMax(-2.0).cwiseMin(2.0);
  std::vector<float> out(static_cast<size_t>(m.num_vertices()), 0.0f);
  if (excess.cwiseAbs().maxCoeff() > 0) {
    const Eigen::VectorXd d = m.shapedirs.leftCols(k) * excess;
    for (int v = 0; v < m.num_vertices(); ++v) {
      out[static_cast<size_t>(v)] = static_cast<float>(d.segment<3>(3 * Eigen::Index{v}).norm());
    }
  }
  return out;
}

/// Posterior positional SD of each vertex (metres) for the beta covariance `s`.
std::vector<float> uncertainty(const smpl::BodyModel& m, const Eigen::MatrixXd& s) {
  const Eigen::Index k = s.rows();
  std::vector<float> out(static_cast<size_t>(m.num_vertices()), 0.0f);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const auto block = m.shapedirs.block(3 * Eigen::Index{v}, 0, 3, k);
    const double trace = (block * s * block.transpose()).trace();
    out[static_cast<size_t>(v)] = static_cast<float>(std::sqrt(std::max(0.0, trace)));
  }
  return out;
}

}  // namespace

AvatarView recompute(const Document& doc, const ModelEntry& entry, bool complete) {
  const smpl::BodyModel& m = *entry.model;
  Prediction p = predict(doc, entry);
  const Eigen::VectorXd& b = p.betas;
  const Eigen::Index k = b.size();
  AvatarView a;
  a.beta_sd = std::move(p.sd);
  a.betas = Eigen::VectorXd::Zero(m.num_betas());
  a.betas.head(k) = b;
  // Rest-pose vertices: v_template + shapedirs * betas.
  const Eigen::Index n3 = m.v_template.size();
  const bool preview = !complete && entry.preview_shapedirs &&
                       entry.preview_shapedirs->rows() == n3 &&
                       entry.preview_shapedirs->cols() >= k;
  const Eigen::VectorXd shaped =
      preview
          ? Eigen::VectorXd((entry.preview_shapedirs->leftCols(k) * b.cast<float>()).cast<double>())
          : Eigen::VectorXd(m.shapedirs.leftCols(k) * b);
  a.vertices.resize(m.num_vertices(), 3);
  Eigen::Map<Eigen::VectorXd>(a.vertices.data(), n3) =
      Eigen::Map<const Eigen::VectorXd>(m.v_template.data(), n3) + shaped;
  const double floor = a.vertices.col(1).minCoeff();
  a.vertices.col(1).array() -= floor;
  a.plausibility = plausibility(b);
  if (complete) {
    MeasureOptions mo;
    mo.circumferences = true;
    a.achieved = entry.measure_info ? measure_all(m, a.vertices, *entry.measure_info, mo)
                                    : measure_all(m, a.vertices, mo);
    a.achieved_complete = true;
  } else {
    a.achieved = measure(a.vertices, entry.landmarks);
  }
  a.implausible_displacement = implausible_displacement(m, b);
  if (p.covariance && complete) {
    a.uncertainty = uncertainty(m, *p.covariance);
  } else {
    a.uncertainty.assign(static_cast<size_t>(m.num_vertices()), 0.0f);
  }
  return a;
}

}  // namespace caliper::app
