// The convenience pipeline: measurements -> (mapping) -> regressor -> avatar and its report.
#include "caliper/avatar.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "caliper/errors.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/training.hpp"
#include "caliper/volume.hpp"

namespace caliper {

namespace {

MeasurementMap prepare(const MeasurementMap& input, const AvatarOptions& options,
                       std::vector<ValidationMessage>& messages) {
  messages = validate_measurements(input);
  if (options.refuse_invalid && has_errors(messages)) {
    std::string text = "the measurements are not plausible:";
    for (const auto& m : messages) {
      if (m.severity == Severity::Error) text += "\n  " + m.message;
    }
    throw InvalidInputError(text);
  }
  return options.mapping ? options.mapping->apply(input) : input;
}

// `betas` (at most the model's), the first `judged` of them the regressor's, whose plausibility
// is reported (all of them when `judged` < 0).
void finish(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
            const AvatarOptions& options, Avatar& a, Eigen::Index judged = -1,
            smpl::Vertices shaped = {}) {
  a.betas = Eigen::VectorXd::Zero(model.num_betas());
  a.betas.head(betas.size()) = betas;
  a.plausibility = plausibility(judged < 0 ? betas : betas.head(judged).eval());
  // `shaped`: the body of these betas when the caller has made it already (the same values).
  a.vertices = shaped.rows() > 0 ? std::move(shaped) : shaped_vertices(model, a.betas);
  MeasureOptions mo;
  mo.circumferences = options.circumferences;
  a.achieved = options.model_info ? measure_all(model, a.vertices, *options.model_info, mo)
                                  : measure_all(model, a.vertices, mo);
}

// linear_betas(): at most this many further steps on the lengths, until every length input is
// within kLengthTolerance (m) of its value.
constexpr int kLengthSteps = 3;
constexpr double kLengthTolerance = 1e-5;

// linear_betas(), and in `shaped` the body of the betas returned when it was made on the way
// (the mesh path, whose last check found every length in place), else left empty.
Eigen::VectorXd linear_betas_shaped(const smpl::BodyModel& model, const LinearRegressor& regressor,
                                    const MeasurementMap& inputs, const ShapeCurve* curve,
                                    const LandmarkTable& landmarks, const ShapeMeasurer* measurer,
                                    smpl::Vertices* shaped);

}  // namespace

Avatar create_avatar(const smpl::BodyModel& model, const LinearRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options) {
  if (options.prior) {
    throw InvalidInputError("regressor " + regressor.name() +
                            " cannot take a population prior; use the noise-aware regressor");
  }
  if (options.check_model) regressor.signature().check(model);
  Avatar a;
  a.input = measurements;
  a.mapped = prepare(measurements, options, a.messages);
  const std::optional<ShapeCurve> curve =
      options.shape_curve ? caliper::shape_curve(model) : std::nullopt;
  smpl::Vertices shaped;  // the avatar's body, when linear_betas made it on the way
  Eigen::VectorXd betas =
      curve ? linear_betas_shaped(
                  model, regressor, a.mapped, &*curve,
                  options.model_info ? options.model_info->landmarks : landmarks_for(model),
                  nullptr, &shaped)
            : regressor.predict(a.mapped);
  if (options.exact_inputs) {
    MeasurementMap targets;
    for (const auto& id : regressor.inputs()) targets[id] = a.mapped.at(id);
    betas = refine_to_inputs(model, betas, targets, regressor.weight_formula());
    shaped = smpl::Vertices();
  }
  finish(model, betas, options, a, -1, std::move(shaped));
  return a;
}

Avatar create_avatar(const smpl::BodyModel& model, const NoiseAwareRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options,
                     const NoiseLevels& noise) {
  if (options.check_model) regressor.signature().check(model);
  Avatar a;
  a.input = measurements;
  a.mapped = prepare(measurements, options, a.messages);
  const Posterior post = regressor.predict(a.mapped, noise, options.prior);
  a.covariance = post.covariance;
  const ShapePrior* p = options.prior;
  const Eigen::Index k = post.mean.size();
  Eigen::VectorXd betas = post.mean;
  if (p != nullptr && p->mean.size() > k) {
    // The population's betas beyond the regressor's: their mean given the regressor's,
    // mu_r + S_rk S_kk^-1 (beta_k - mu_k) (the model's own N(0, I) would leave them at 0).
    const Eigen::Index rest = std::min<Eigen::Index>(p->mean.size(), model.num_betas()) - k;
    betas.conservativeResize(k + rest);
    const Eigen::LLT<Eigen::MatrixXd> s(p->covariance.topLeftCorner(k, k));
    betas.tail(rest) = p->mean.segment(k, rest) +
                       p->covariance.block(k, 0, rest, k) * s.solve(post.mean - p->mean.head(k));
  }
  if (options.exact_inputs && !post.used_inputs.empty()) {  // every given input, from the mean
    MeasurementMap targets;
    for (const auto& id : post.used_inputs) targets[id] = a.mapped.at(id);
    betas = refine_to_inputs(model, betas, targets, regressor.weight_formula());
  }
  finish(model, betas, options, a, k);
  return a;
}

Eigen::VectorXd linear_betas(const smpl::BodyModel& model, const LinearRegressor& regressor,
                             const MeasurementMap& inputs, const ShapeCurve* curve,
                             const LandmarkTable& landmarks, const ShapeMeasurer* measurer) {
  return linear_betas_shaped(model, regressor, inputs, curve, landmarks, measurer, nullptr);
}

namespace {

Eigen::VectorXd linear_betas_shaped(const smpl::BodyModel& model, const LinearRegressor& regressor,
                                    const MeasurementMap& inputs, const ShapeCurve* curve,
                                    const LandmarkTable& landmarks, const ShapeMeasurer* measurer,
                                    smpl::Vertices* shaped) {
  const std::vector<std::string>& ids = regressor.inputs();
  const auto has = [&ids](const char* id) {
    return std::find(ids.begin(), ids.end(), id) != ids.end();
  };
  Eigen::VectorXd paper = regressor.predict(inputs);  // also names a missing or bad input
  const Eigen::Index k = regressor.coefficients().rows();
  if (!curve || !has("height") || !has("weight") || curve->coefficients.rows() < k) return paper;
  const auto m = static_cast<Eigen::Index>(ids.size());
  const auto A = regressor.coefficients().leftCols(m);  // the slopes, not the intercept
  Eigen::VectorXd want(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const std::string& id = ids[static_cast<size_t>(i)];
    want[i] = input_feature(id, inputs.at(id), regressor.weight_formula());
  }
  // beta = c + A (f - f(c)): c the curve's betas, A the regressor's slopes, f the inputs'
  // features and f(c) the same features measured on the curve's body.
  Eigen::VectorXd c = curve->betas(inputs.at("height"), inputs.at("weight"));
  const bool fast = measurer != nullptr && measurer->num_betas() >= c.size();
  smpl::Vertices v;  // the mesh path's last body
  const auto features = [&](const Eigen::VectorXd& betas, bool with_weight) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(m);
    Eigen::VectorXd lengths;  // the measurer's definitions
    if (fast) {
      lengths = measurer->measure(betas);
    } else {
      v = shaped_vertices(model, betas);
    }
    for (Eigen::Index i = 0; i < m; ++i) {
      const std::string& id = ids[static_cast<size_t>(i)];
      if (id == "weight") {  // without the weight: taken as given (nothing to correct)
        f[i] = with_weight ? std::cbrt(fast ? measurer->volume(betas) : mesh_volume(v, model.faces))
                           : want[i];
      } else if (fast) {
        const auto& defs = measurer->definitions();
        const auto it = std::find_if(defs.begin(), defs.end(),
                                     [&](const MeasurementDef& d) { return d.id == id; });
        if (it == defs.end()) {
          throw InvalidInputError("linear_betas: the measurer does not measure " + id);
        }
        f[i] = lengths[it - defs.begin()];
      } else {
        f[i] = measure(v, landmarks, measurement_def(id));
      }
    }
    return f;
  };
  c.head(k) += A * (want - features(c, true));
  // Where a length is not quite linear in the betas (the neutral model's arm length: up to
  // 4.7 mm after the step above), the same step again from the body just made, on the lengths
  // only: the weight keeps the first step's compromise, as the paper's prediction does.
  for (int step = 0; step < kLengthSteps; ++step) {
    const Eigen::VectorXd miss = want - features(c, false);
    if (miss.cwiseAbs().maxCoeff() <= kLengthTolerance) {
      if (shaped != nullptr && !fast && c.size() == model.num_betas()) *shaped = std::move(v);
      break;
    }
    c.head(k) += A * miss;
  }
  return c;
}

}  // namespace

Eigen::VectorXd refine_to_inputs(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
                                 const MeasurementMap& targets, const WeightFormula& formula,
                                 int max_iterations) {
  const auto k = betas.size();
  if (k > model.num_betas() || k == 0) {
    throw InvalidInputError("refine_to_inputs: " + std::to_string(k) +
                            " betas given, the model has " + std::to_string(model.num_betas()));
  }
  const LandmarkTable landmarks = landmarks_for(model);
  struct Target {
    const MeasurementDef* def;  // nullptr for weight
    double value;               // feature units
  };
  std::vector<Target> t;
  for (const auto& [id, value] : targets) {
    if (id == "weight") {
      t.push_back({nullptr, input_feature(id, value, formula)});
      continue;
    }
    const MeasurementDef* def = nullptr;
    for (const auto& d : paper_measurements()) {
      if (d.id == id) def = &d;
    }
    if (def) t.push_back({def, input_feature(id, value, formula)});
  }
  const auto m = static_cast<Eigen::Index>(t.size());
  if (m > k) {
    throw InvalidInputError("refine_to_inputs: " + std::to_string(m) + " targets but only " +
                            std::to_string(k) + " betas");
  }
  const auto rows = [&](const std::vector<int>& ids) {  // 3 x k mean shape rows
    Eigen::MatrixXd P = Eigen::MatrixXd::Zero(3, k);
    for (int v : ids) P += model.shapedirs.block(3 * static_cast<Eigen::Index>(v), 0, 3, k);
    return Eigen::MatrixXd(P / static_cast<double>(ids.size()));
  };
  const auto lookup = [&](const std::string& name,
                          const std::string& id) -> const std::vector<int>& {
    const auto it = landmarks.find(name);
    if (it == landmarks.end()) {
      throw LandmarkError("measurement '" + id + "' needs landmark '" + name +
                          "', which the model '" + model.meta.name + "' does not define");
    }
    return it->second;
  };
  Eigen::VectorXd beta = betas;
  Eigen::VectorXd full = Eigen::VectorXd::Zero(model.num_betas());
  for (int it = 0; it < max_iterations && m > 0; ++it) {
    full.head(k) = beta;
    const smpl::Vertices v = shaped_vertices(model, full);
    Eigen::Index lowest = 0;
    const double floor = v.col(1).minCoeff(&lowest);
    Eigen::MatrixXd J(m, k);
    Eigen::VectorXd r(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const Target& q = t[static_cast<std::size_t>(i)];
      if (!q.def) {
        // Volume gradient: dV/dx_a = (x_b x x_c) / 6 for every face (a, b, c), cyclically.
        smpl::Vertices grad = smpl::Vertices::Zero(v.rows(), 3);
        for (Eigen::Index f = 0; f < model.faces.rows(); ++f) {
          const int a = model.faces(f, 0), b = model.faces(f, 1), c = model.faces(f, 2);
          const Eigen::Vector3d xa = v.row(a), xb = v.row(b), xc = v.row(c);
          grad.row(a) += xb.cross(xc).transpose() / 6.0;
          grad.row(b) += xc.cross(xa).transpose() / 6.0;
          grad.row(c) += xa.cross(xb).transpose() / 6.0;
        }
        const double volume = mesh_volume(v, model.faces);
        if (!(volume > 0.0)) throw InvalidInputError("refine_to_inputs: non-positive volume");
        Eigen::RowVectorXd g = Eigen::RowVectorXd::Zero(k);
        for (Eigen::Index p = 0; p < v.rows(); ++p) {
          g += grad.row(p) * model.shapedirs.block(3 * p, 0, 3, k);
        }
        const double f = std::cbrt(volume);
        J.row(i) = g / (3.0 * f * f);
        r(i) = q.value - f;
        continue;
      }
      const auto& from = lookup(q.def->from, q.def->id);
      const Eigen::Vector3d pa = landmark_point(v, from);
      if (q.def->kind == MeasurementKind::Height) {
        J.row(i) = rows(from).row(1) - model.shapedirs.block(3 * lowest + 1, 0, 1, k);
        r(i) = q.value - (pa.y() - floor);
      } else {
        const auto& to = lookup(q.def->to, q.def->id);
        const Eigen::Vector3d d = pa - landmark_point(v, to);
        const double len = d.norm();
        J.row(i) = (d / len).transpose() * (rows(from) - rows(to));
        r(i) = q.value - len;
      }
    }
    if (r.cwiseAbs().maxCoeff() < 1e-9) break;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(J * J.transpose());
    if (ldlt.info() != Eigen::Success || ldlt.vectorD().cwiseAbs().minCoeff() < 1e-14) {
      throw InvalidInputError("refine_to_inputs: the targets are not independent on this model");
    }
    beta += J.transpose() * ldlt.solve(r);
  }
  return beta;
}

}  // namespace caliper
