// Measurements -> shape regressors: Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.4.3
// (R2/R4/R5/R6, least squares), and a Bayesian noise-aware regressor (docs/regressors.md).
// Sections: kinds and signatures; LinearRegressor; NoiseAwareRegressor; RegressorSet; training.
#include "caliper/regressor.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "caliper/errors.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/text.hpp"

namespace caliper {

namespace {

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

Json matrix_json(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    std::vector<double> row(static_cast<std::size_t>(m.cols()));
    for (Eigen::Index c = 0; c < m.cols(); ++c) row[static_cast<std::size_t>(c)] = m(r, c);
    rows.push_back(Json(row));
  }
  return rows;
}

Eigen::MatrixXd json_matrix(const Json& j, Eigen::Index rows, Eigen::Index cols,
                            const std::string& what) {
  if (!j.is_array() || static_cast<Eigen::Index>(j.size()) != rows) {
    throw ModelMismatchError("regressor JSON: '" + what + "' must have " + std::to_string(rows) +
                             " rows, found " + std::to_string(j.size()));
  }
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::vector<double> row = j[static_cast<std::size_t>(r)].as_numbers();
    if (static_cast<Eigen::Index>(row.size()) != cols) {
      throw ModelMismatchError("regressor JSON: row " + std::to_string(r) + " of '" + what +
                               "' has " + std::to_string(row.size()) + " values, expected " +
                               std::to_string(cols));
    }
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = row[static_cast<std::size_t>(c)];
  }
  return m;
}

Eigen::VectorXd json_vector(const Json& j, Eigen::Index size, const std::string& what) {
  const std::vector<double> v = j.as_numbers();
  if (static_cast<Eigen::Index>(v.size()) != size) {
    throw ModelMismatchError("regressor JSON: '" + what + "' has " + std::to_string(v.size()) +
                             " values, expected " + std::to_string(size));
  }
  return Eigen::Map<const Eigen::VectorXd>(v.data(), size);
}

Json strings_json(const std::vector<std::string>& s) {
  Json a = Json::array();
  for (const auto& x : s) a.push_back(Json(x));
  return a;
}

std::vector<std::string> json_strings(const Json& j) {
  std::vector<std::string> out;
  for (const auto& x : j.as_array()) out.push_back(x.as_string());
  return out;
}

Json signature_json(const ModelSignature& s) {
  return Json::object({{"name", s.name},
                       {"gender", s.gender},
                       {"num_vertices", s.num_vertices},
                       {"num_betas", s.num_betas},
                       {"fingerprint", s.fingerprint}});
}

ModelSignature json_signature(const Json& j) {
  ModelSignature s;
  s.name = j.at("name").as_string();
  s.gender = j.at("gender").as_string();
  s.num_vertices = j.at("num_vertices").as_int();
  s.num_betas = j.at("num_betas").as_int();
  if (const Json* f = j.find("fingerprint")) s.fingerprint = f->as_number();
  if (s.num_betas < 1) throw ModelMismatchError("regressor JSON: num_betas must be >= 1");
  return s;
}

Json formula_json(const WeightFormula& f) {
  return Json::object(
      {{"name", f.name}, {"coefficient", f.coefficient}, {"intercept", f.intercept}});
}

WeightFormula json_formula(const Json& j) {
  WeightFormula f;
  f.name = j.at("name").as_string();
  f.coefficient = j.at("coefficient").as_number();
  f.intercept = j.at("intercept").as_number();
  if (!(f.coefficient > 0.0)) throw ModelMismatchError("regressor JSON: bad weight coefficient");
  return f;
}

/// N x inputs feature matrix of a training set.
Eigen::MatrixXd training_features(const TrainingSet& t, const std::vector<std::string>& inputs) {
  Eigen::MatrixXd F(t.size(), static_cast<Eigen::Index>(inputs.size()));
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    F.col(static_cast<Eigen::Index>(i)) =
        t.column(inputs[i] == "weight" ? "weight_feature" : inputs[i]);
  }
  return F;
}

Eigen::MatrixXd with_ones(const Eigen::MatrixXd& X) {
  Eigen::MatrixXd out(X.rows(), X.cols() + 1);
  out.leftCols(X.cols()) = X;
  out.col(X.cols()).setOnes();
  return out;
}

void check_training(const TrainingSet& t, std::size_t inputs) {
  if (t.size() < static_cast<int>(inputs) + 2) {
    throw InvalidInputError(
        "the training set has " + std::to_string(t.size()) +
        " bodies; fitting needs more than inputs + 1 = " + std::to_string(inputs + 1));
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Kinds and signatures

std::string to_string(RegressorKind kind) {
  static constexpr std::array<const char*, 4> kNames = {"R2", "R4", "R5", "R6"};
  static_assert(kNames.size() == static_cast<std::size_t>(RegressorKind::R6) + 1);
  return smpl::enum_name(kind, kNames, "R?");
}

std::optional<RegressorKind> parse_regressor_kind(const std::string& text) {
  for (RegressorKind k : all_regressor_kinds()) {
    if (upper(text) == to_string(k)) return k;
  }
  return std::nullopt;
}

const std::vector<std::string>& regressor_inputs(RegressorKind kind) {
  static const std::vector<std::string> r2 = {"height", "weight"};
  static const std::vector<std::string> r4 = {"height", "weight", "arm_span_fingertips",
                                              "inseam_height"};
  static const std::vector<std::string> r5 = {"height", "weight", "arm_span_fingertips",
                                              "inseam_height", "hip_width"};
  static const std::vector<std::string> r6 = {"height",        "weight",    "arm_span_fingertips",
                                              "inseam_height", "hip_width", "arm_length"};
  switch (kind) {
    case RegressorKind::R2:
      return r2;
    case RegressorKind::R4:
      return r4;
    case RegressorKind::R5:
      return r5;
    case RegressorKind::R6:
      return r6;
  }
  return r6;
}

const std::vector<RegressorKind>& all_regressor_kinds() {
  static const std::vector<RegressorKind> kinds = {RegressorKind::R2, RegressorKind::R4,
                                                   RegressorKind::R5, RegressorKind::R6};
  return kinds;
}

double model_fingerprint(const smpl::BodyModel& model, int betas) {
  // A weighted sum with fixed pseudo-random weights in [1, 2): any change of a value beyond
  // rounding changes it; independent of file names.
  std::uint64_t state = 0x2545f4914f6cdd1dULL;
  const auto weight = [&]() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return 1.0 + static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  double sum = 0.0;
  for (Eigen::Index i = 0; i < model.v_template.size(); ++i) {
    sum += weight() * model.v_template.data()[i];
  }
  const int k = std::min(betas, model.num_betas());
  for (int b = 0; b < k; ++b) {
    for (Eigen::Index r = 0; r < model.shapedirs.rows(); ++r)
      sum += weight() * model.shapedirs(r, b);
  }
  return sum == 0.0 ? 1.0 : sum;  // 0 means "unknown"
}

ModelSignature ModelSignature::of(const smpl::BodyModel& model, int betas) {
  return {model.meta.name, model.meta.gender, model.num_vertices(), betas,
          model_fingerprint(model, betas)};
}

void ModelSignature::check(const smpl::BodyModel& model) const {
  const std::string mine = "'" + name + "' (" + (gender.empty() ? "no gender" : gender) + ", " +
                           std::to_string(num_vertices) + " vertices, " +
                           std::to_string(num_betas) + " betas)";
  const std::string theirs = "'" + model.meta.name + "' (" +
                             (model.meta.gender.empty() ? "no gender" : model.meta.gender) + ", " +
                             std::to_string(model.num_vertices()) + " vertices, " +
                             std::to_string(model.num_betas()) + " betas)";
  const auto fail = [&](const std::string& why) {
    throw ModelMismatchError("the regressor was fitted for model " + mine +
                             " and cannot be used with model " + theirs + ": " + why +
                             "; train it for this model (caliper train)");
  };
  if (model.num_vertices() != num_vertices) fail("the vertex counts differ");
  if (model.num_betas() < num_betas) fail("the model has fewer shape components");
  if (fingerprint != 0.0) {
    const double other = model_fingerprint(model, num_betas);
    if (std::abs(other - fingerprint) > 1e-9 * (std::abs(fingerprint) + 1.0)) {
      fail("the template or shape directions differ (fingerprint " +
           smpl::format_general(fingerprint, 6) + " vs " + smpl::format_general(other, 6) + ")");
    }
    return;
  }
  if (!name.empty() && !model.meta.name.empty() && name != model.meta.name) {
    fail("the model names differ");
  }
  if (!gender.empty() && !model.meta.gender.empty() && gender != model.meta.gender) {
    fail("the genders differ");
  }
}

double input_feature(const std::string& id, double value, const WeightFormula& formula) {
  if (!std::isfinite(value)) throw InvalidInputError("input '" + id + "' is not a number");
  if (value <= 0.0) {
    throw InvalidInputError("input '" + id + "' = " + smpl::format_general(value, 6) +
                            " must be positive");
  }
  return id == "weight" ? weight_feature(value, formula) : value;
}

// ---------------------------------------------------------------------------------------------
// LinearRegressor

LinearRegressor LinearRegressor::fit(const TrainingSet& training,
                                     const std::vector<std::string>& inputs,
                                     const ModelSignature& signature, const std::string& name,
                                     bool intercept_at_mean) {
  if (inputs.empty()) throw InvalidInputError("a regressor needs at least one input");
  check_training(training, inputs.size());
  LinearRegressor r;
  r.name_ = name;
  r.inputs_ = inputs;
  r.signature_ = signature;
  r.signature_.num_betas = static_cast<int>(training.betas.cols());
  r.formula_ = training.weight_formula;
  const Eigen::MatrixXd F = training_features(training, inputs);
  const Eigen::MatrixXd X = with_ones(F);
  const auto qr = X.colPivHouseholderQr();
  if (qr.rank() < X.cols()) {
    throw InvalidInputError("regressor " + name +
                            ": the inputs are linearly dependent over the "
                            "training set (rank " +
                            std::to_string(qr.rank()) + " < " + std::to_string(X.cols()) + ")");
  }
  r.A_ = qr.solve(training.betas).transpose();  // k x (m + 1)
  if (intercept_at_mean && training.mean_volume > 0.0) {
    // The weight feature (the cube root of the volume) taken at the mean body instead of its
    // average over the training set; the lengths keep the least-squares intercept (linear in
    // beta, or close: arm length's best secant is the least-squares one).
    const auto m = static_cast<Eigen::Index>(inputs.size());
    for (Eigen::Index i = 0; i < m; ++i) {
      if (inputs[static_cast<std::size_t>(i)] != "weight") continue;
      r.A_.col(m) -= r.A_.col(i) * (std::cbrt(training.mean_volume) - F.col(i).mean());
    }
  }
  // Diagnostic: re-measure each body's avatar with the linear forward model f ~ [beta 1] C.
  const Eigen::MatrixXd Bx = with_ones(training.betas);
  const Eigen::MatrixXd C = Bx.colPivHouseholderQr().solve(F);  // (k + 1) x m
  const Eigen::MatrixXd predicted_betas = X * r.A_.transpose();
  const Eigen::MatrixXd refeatured = with_ones(predicted_betas) * C;
  r.training_rms_ = ((refeatured - F).colwise().squaredNorm() / static_cast<double>(F.rows()))
                        .cwiseSqrt()
                        .transpose();
  return r;
}

LinearRegressor LinearRegressor::fit(const TrainingSet& training, RegressorKind kind,
                                     const ModelSignature& signature, bool intercept_at_mean) {
  return fit(training, regressor_inputs(kind), signature, to_string(kind), intercept_at_mean);
}

Eigen::VectorXd LinearRegressor::predict(const MeasurementMap& values) const {
  Eigen::VectorXd raw(static_cast<Eigen::Index>(inputs_.size()));
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    const auto it = values.find(inputs_[i]);
    if (it == values.end()) {
      std::string need;
      for (const auto& s : inputs_) need += (need.empty() ? "" : ", ") + s;
      throw InvalidInputError("regressor " + name_ + " needs input '" + inputs_[i] +
                              "' (it takes " + need + ")");
    }
    raw(static_cast<Eigen::Index>(i)) = it->second;
  }
  return predict(raw);
}

Eigen::VectorXd LinearRegressor::predict(const Eigen::VectorXd& values) const {
  if (values.size() != static_cast<Eigen::Index>(inputs_.size())) {
    throw InvalidInputError("regressor " + name_ + " takes " + std::to_string(inputs_.size()) +
                            " inputs, got " + std::to_string(values.size()));
  }
  Eigen::VectorXd f(values.size() + 1);
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    f(i) = input_feature(inputs_[static_cast<std::size_t>(i)], values(i), formula_);
  }
  f(values.size()) = 1.0;
  return A_ * f;
}

Json LinearRegressor::to_json() const {
  Json j = Json::object();
  j.set("kind", "linear");
  j.set("name", name_);
  j.set("model", signature_json(signature_));
  j.set("weight_formula", formula_json(formula_));
  j.set("inputs", strings_json(inputs_));
  j.set("coefficients", matrix_json(A_));
  j.set("training_rms", Json(std::vector<double>(training_rms_.data(),
                                                 training_rms_.data() + training_rms_.size())));
  return j;
}

LinearRegressor LinearRegressor::from_json(const Json& j) {
  if (!j.is_object() || !j.contains("kind") || j.at("kind").as_string() != "linear") {
    throw ModelMismatchError("regressor JSON: expected an object with \"kind\": \"linear\"");
  }
  LinearRegressor r;
  r.name_ = j.at("name").as_string();
  r.signature_ = json_signature(j.at("model"));
  r.formula_ = json_formula(j.at("weight_formula"));
  r.inputs_ = json_strings(j.at("inputs"));
  if (r.inputs_.empty()) throw ModelMismatchError("regressor JSON: no inputs");
  const auto m = static_cast<Eigen::Index>(r.inputs_.size());
  r.A_ = json_matrix(j.at("coefficients"), r.signature_.num_betas, m + 1, "coefficients");
  r.training_rms_ = j.contains("training_rms")
                        ? json_vector(j.at("training_rms"), m, "training_rms")
                        : Eigen::VectorXd::Zero(m);
  return r;
}

// ---------------------------------------------------------------------------------------------
// NoiseAwareRegressor

namespace {
NoiseLevels noise_from_mae(double h, double as, double al, double in, double hw) {
  return {{"height", h * kMaeToSd},      {"arm_span_fingertips", as * kMaeToSd},
          {"arm_length", al * kMaeToSd}, {"inseam_height", in * kMaeToSd},
          {"hip_width", hw * kMaeToSd},  {"weight", 1.0}};
}
}  // namespace

NoiseLevels self_measurement_noise() {
  return noise_from_mae(0.0153, 0.0201, 0.0129, 0.0206, 0.0077);
}

NoiseLevels other_measurement_noise() {
  return noise_from_mae(0.0147, 0.0172, 0.0076, 0.0246, 0.0065);
}

NoiseAwareRegressor NoiseAwareRegressor::fit(const TrainingSet& training,
                                             const ModelSignature& signature,
                                             const NoiseLevels& noise,
                                             const std::vector<std::string>& inputs) {
  if (inputs.empty()) throw InvalidInputError("the noise-aware regressor needs inputs");
  check_training(training, static_cast<std::size_t>(training.betas.cols()));
  NoiseAwareRegressor r;
  r.inputs_ = inputs;
  r.signature_ = signature;
  r.signature_.num_betas = static_cast<int>(training.betas.cols());
  r.formula_ = training.weight_formula;
  r.noise_ = noise;
  for (const auto& [id, sd] : noise) {
    if (!std::isfinite(sd) || sd < 0.0) {
      throw InvalidInputError("noise level of '" + id + "' = " + smpl::format_general(sd, 6) +
                              " must be finite and >= 0");
    }
  }
  const Eigen::MatrixXd F = training_features(training, inputs);
  const Eigen::MatrixXd X = with_ones(training.betas);
  const auto qr = X.colPivHouseholderQr();
  if (qr.rank() < X.cols()) {
    throw InvalidInputError(
        "the training betas are rank deficient; use corners or Gaussian "
        "samples with more bodies than betas");
  }
  const Eigen::MatrixXd C = qr.solve(F);  // (k + 1) x m
  const Eigen::Index k = training.betas.cols();
  r.M_ = C.topRows(k).transpose();
  r.c_ = C.row(k).transpose();
  r.lin_rms_ =
      ((X * C - F).colwise().squaredNorm() / static_cast<double>(F.rows())).cwiseSqrt().transpose();
  return r;
}

Posterior NoiseAwareRegressor::predict(const MeasurementMap& values, const NoiseLevels& noise,
                                       const ShapePrior* prior) const {
  const Eigen::Index k = M_.cols();
  std::vector<Eigen::Index> rows;
  std::vector<double> f, var;
  Posterior post;
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    const std::string& id = inputs_[i];
    const auto it = values.find(id);
    if (it == values.end()) continue;
    const double feature = input_feature(id, it->second, formula_);
    const auto given = noise.find(id);
    const auto stored = noise_.find(id);
    if (given == noise.end() && stored == noise_.end()) {
      throw InvalidInputError("no noise level for input '" + id +
                              "'; give one (metres, weight in kg)");
    }
    double sd = given != noise.end() ? given->second : stored->second;
    if (!std::isfinite(sd) || sd < 0.0) {
      throw InvalidInputError("noise level of '" + id + "' = " + smpl::format_general(sd, 6) +
                              " must be finite and >= 0");
    }
    if (id == "weight") sd /= 3.0 * formula_.coefficient * feature * feature;  // delta method
    const double lin = lin_rms_(static_cast<Eigen::Index>(i));
    rows.push_back(static_cast<Eigen::Index>(i));
    f.push_back(feature);
    var.push_back(std::max(sd * sd + lin * lin, 1e-12));
    post.used_inputs.push_back(id);
  }
  Eigen::MatrixXd precision = Eigen::MatrixXd::Identity(k, k);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(k);
  if (prior) {  // N(mean, S): precision S^-1, and S^-1 mean on the right-hand side
    const Eigen::Index b = prior->mean.size();
    if (b < k || prior->covariance.rows() != b || prior->covariance.cols() != b) {
      throw InvalidInputError("the shape prior is over " + std::to_string(b) +
                              " betas, the regressor has " + std::to_string(k));
    }
    const Eigen::LLT<Eigen::MatrixXd> s(prior->covariance.topLeftCorner(k, k));
    if (s.info() != Eigen::Success || !prior->mean.allFinite()) {
      throw InvalidInputError(
          "the shape prior's covariance is not positive definite (or holds NaN): a population "
          "read from a model file (population_prior) comes from caliper-modelgen; regenerate the "
          "model, or make the avatar without the population");
    }
    precision = s.solve(Eigen::MatrixXd::Identity(k, k));
    rhs = precision * prior->mean.head(k);
  }
  for (std::size_t u = 0; u < rows.size(); ++u) {
    const Eigen::VectorXd m = M_.row(rows[u]).transpose();
    precision.noalias() += m * m.transpose() / var[u];
    rhs += m * ((f[u] - c_(rows[u])) / var[u]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(precision);
  post.mean = llt.solve(rhs);
  post.covariance = llt.solve(Eigen::MatrixXd::Identity(k, k));
  return post;
}

Json NoiseAwareRegressor::to_json() const {
  Json j = Json::object();
  j.set("kind", "noise_aware");
  j.set("model", signature_json(signature_));
  j.set("weight_formula", formula_json(formula_));
  j.set("inputs", strings_json(inputs_));
  Json n = Json::object();
  for (const auto& [id, sd] : noise_) n.set(id, sd);
  j.set("noise_sd", n);
  j.set("forward_matrix", matrix_json(M_));
  j.set("forward_offset", Json(std::vector<double>(c_.data(), c_.data() + c_.size())));
  j.set("linearisation_rms",
        Json(std::vector<double>(lin_rms_.data(), lin_rms_.data() + lin_rms_.size())));
  return j;
}

NoiseAwareRegressor NoiseAwareRegressor::from_json(const Json& j) {
  if (!j.is_object() || !j.contains("kind") || j.at("kind").as_string() != "noise_aware") {
    throw ModelMismatchError("regressor JSON: expected an object with \"kind\": \"noise_aware\"");
  }
  NoiseAwareRegressor r;
  r.signature_ = json_signature(j.at("model"));
  r.formula_ = json_formula(j.at("weight_formula"));
  r.inputs_ = json_strings(j.at("inputs"));
  const auto m = static_cast<Eigen::Index>(r.inputs_.size());
  if (m == 0) throw ModelMismatchError("regressor JSON: no inputs");
  for (const auto& [id, v] : j.at("noise_sd").as_object()) r.noise_[id] = v.as_number();
  r.M_ = json_matrix(j.at("forward_matrix"), m, r.signature_.num_betas, "forward_matrix");
  r.c_ = json_vector(j.at("forward_offset"), m, "forward_offset");
  r.lin_rms_ = json_vector(j.at("linearisation_rms"), m, "linearisation_rms");
  return r;
}

// ---------------------------------------------------------------------------------------------
// RegressorSet

const LinearRegressor* RegressorSet::find(const std::string& name) const {
  for (const auto& r : linear) {
    if (upper(r.name()) == upper(name)) return &r;
  }
  return nullptr;
}

Json RegressorSet::to_json() const {
  Json j = format_header("caliper-regressors");
  Json lin = Json::array();
  for (const auto& r : linear) lin.push_back(r.to_json());
  j.set("linear", lin);
  j.set("noise_aware", noise_aware ? noise_aware->to_json() : Json());
  return j;
}

RegressorSet RegressorSet::from_json(const Json& j) {
  check_format_version<ModelMismatchError>(j, "caliper-regressors", "regressor file");
  RegressorSet s;
  for (const auto& r : j.at("linear").as_array()) s.linear.push_back(LinearRegressor::from_json(r));
  const Json* na = j.find("noise_aware");
  if (na && !na->is_null()) s.noise_aware = NoiseAwareRegressor::from_json(*na);
  return s;
}

void RegressorSet::save(const std::string& path) const {
  write_json_file(path, to_json());
}

RegressorSet RegressorSet::load(const std::string& path) {
  return read_json_file_as<ModelMismatchError, ModelMismatchError>(path, from_json);
}

void RegressorSet::check(const smpl::BodyModel& model) const {
  for (const auto& r : linear) r.signature().check(model);
  if (noise_aware) noise_aware->signature().check(model);
}

// ---------------------------------------------------------------------------------------------
// Training

RegressorSet train_regressors(const TrainingSet& training, const ModelSignature& signature,
                              const TrainOptions& options) {
  RegressorSet s;
  for (RegressorKind k : all_regressor_kinds()) {
    s.linear.push_back(LinearRegressor::fit(training, k, signature, options.intercept_at_mean));
  }
  if (options.noise_aware) {
    s.noise_aware = NoiseAwareRegressor::fit(training, signature, options.noise);
  }
  return s;
}

RegressorSet train_regressors(const smpl::BodyModel& model, const TrainOptions& options) {
  const LandmarkTable landmarks = landmarks_for(model);
  std::vector<MeasurementDef> defs;
  for (const auto& id : regressor_inputs(RegressorKind::R6)) {
    if (id != "weight") defs.push_back(measurement_def(id));
  }
  const ShapeMeasurer measurer(model, landmarks, defs, options.num_betas);
  const Eigen::MatrixXd betas =
      options.gaussian ? gaussian_betas(options.gaussian_count, measurer.num_betas(), options.seed)
                       : corner_betas(measurer.num_betas(), options.corner_sd);
  const TrainingSet training = make_training_set(measurer, betas, weight_formula_of(model));
  return train_regressors(training, ModelSignature::of(model, measurer.num_betas()), options);
}

}  // namespace caliper
