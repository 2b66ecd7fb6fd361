/// \file shape_curve.cpp
/// The general population's body for a height and a weight (shape_curve.hpp). JSON through
/// nlohmann-json. The fit sums in a fixed order with portable arithmetic, so that the generator
/// writes the same bytes on every CPU (docs/models.md, "Same bytes on every CPU").
#include "caliper/shape_curve.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <nlohmann/json.hpp>

#include "caliper/errors.hpp"
#include "caliper/portable_math.hpp"

namespace caliper {

namespace {

constexpr int kFeatures = 6;

Eigen::Vector2d raw_inputs(double height_m, double weight_kg, ShapeCurve::WeightInput input) {
  return {height_m,
          input == ShapeCurve::WeightInput::kKilograms ? weight_kg : portable::cbrt(weight_kg)};
}

// The file's names of the two inputs ("inputs"), one pair per WeightInput.
constexpr const char* kHeightName = "height (m)";
constexpr const char* kCubeRootName = "cube root of weight (kg)";
constexpr const char* kKilogramsName = "weight (kg)";

}  // namespace

Eigen::Matrix<double, 6, 1> shape_curve_features(double h, double w) {
  Eigen::Matrix<double, 6, 1> f;
  f << 1.0, h, w, h * h, h * w, w * w;
  return f;
}

Eigen::VectorXd ShapeCurve::betas(double height_m, double weight_kg) const {
  if (!std::isfinite(height_m) || !std::isfinite(weight_kg) || height_m <= 0.0 ||
      weight_kg <= 0.0) {
    throw InvalidInputError("shape curve: height and weight must be finite and positive (got " +
                            std::to_string(height_m) + " m, " + std::to_string(weight_kg) + " kg)");
  }
  const Eigen::Vector2d x = raw_inputs(height_m, weight_kg, weight_input).cwiseMax(lo).cwiseMin(hi);
  const Eigen::Vector2d s = (x - center).cwiseQuotient(scale);
  return coefficients * shape_curve_features(s[0], s[1]);
}

ShapeCurve fit_shape_curve(const Eigen::VectorXd& heights, const Eigen::VectorXd& weights_kg,
                           const Eigen::MatrixXd& betas, const Eigen::VectorXd& weights,
                           const std::string& population, ShapeCurve::WeightInput weight_input) {
  const Eigen::Index n = heights.size();
  if (weights_kg.size() != n || betas.rows() != n || weights.size() != n) {
    throw std::invalid_argument("fit_shape_curve: " + std::to_string(n) + " heights, " +
                                std::to_string(weights_kg.size()) + " weights, " +
                                std::to_string(betas.rows()) + " rows of betas and " +
                                std::to_string(weights.size()) + " sample weights");
  }
  if (!heights.allFinite() || !weights_kg.allFinite() || !betas.allFinite() ||
      !weights.allFinite() || (weights.array() < 0.0).any() || (heights.array() <= 0.0).any() ||
      (weights_kg.array() <= 0.0).any()) {
    throw std::invalid_argument(
        "fit_shape_curve: non-finite, negative or zero values among the subjects");
  }
  std::vector<Eigen::Vector2d> x(static_cast<size_t>(n));
  ShapeCurve c;
  c.population = population;
  c.weight_input = weight_input;
  c.lo = Eigen::Vector2d::Constant(HUGE_VAL);
  c.hi = Eigen::Vector2d::Constant(-HUGE_VAL);
  double total = 0.0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    x[static_cast<size_t>(i)] = raw_inputs(heights[i], weights_kg[i], weight_input);
    if (weights[i] <= 0.0) continue;
    ++c.subjects;
    total += weights[i];
    sum += weights[i] * x[static_cast<size_t>(i)];
    c.lo = c.lo.cwiseMin(x[static_cast<size_t>(i)]);
    c.hi = c.hi.cwiseMax(x[static_cast<size_t>(i)]);
  }
  if (c.subjects <= kFeatures) {
    throw std::invalid_argument("fit_shape_curve: " + std::to_string(c.subjects) +
                                " weighted subjects, at least 7 needed");
  }
  c.center = sum / total;
  Eigen::Vector2d var = Eigen::Vector2d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d d = x[static_cast<size_t>(i)] - c.center;
    var += weights[i] * d.cwiseProduct(d);
  }
  c.scale = Eigen::Vector2d(std::sqrt(var[0] / total), std::sqrt(var[1] / total));
  if (!(c.scale.array() > 0.0).all()) {
    throw std::invalid_argument("fit_shape_curve: every subject has the same height or weight");
  }
  // Normal equations, summed subject by subject (a fixed order: the same bits on every CPU).
  Eigen::Matrix<double, kFeatures, kFeatures> xtx =
      Eigen::Matrix<double, kFeatures, kFeatures>::Zero();
  Eigen::MatrixXd xty = Eigen::MatrixXd::Zero(kFeatures, betas.cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    if (weights[i] <= 0.0) continue;
    const Eigen::Vector2d s = (x[static_cast<size_t>(i)] - c.center).cwiseQuotient(c.scale);
    const Eigen::Matrix<double, 6, 1> f = shape_curve_features(s[0], s[1]);
    for (int r = 0; r < kFeatures; ++r) {
      for (int q = 0; q < kFeatures; ++q) xtx(r, q) += weights[i] * f[r] * f[q];
      for (Eigen::Index b = 0; b < betas.cols(); ++b) xty(r, b) += weights[i] * f[r] * betas(i, b);
    }
  }
  const Eigen::LDLT<Eigen::Matrix<double, kFeatures, kFeatures>> ldlt(xtx);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) {
    throw std::invalid_argument("fit_shape_curve: the subjects do not determine a quadratic");
  }
  c.coefficients = ldlt.solve(xty).transpose();
  return c;
}

const char* shape_curve_meta_key() {
  return "shape_curve";
}

void set_shape_curve(smpl::BodyModel& model, const ShapeCurve& c) {
  const Eigen::Index b = model.num_betas();
  if (c.coefficients.rows() != b || c.coefficients.cols() != kFeatures) {
    throw std::invalid_argument("set_shape_curve: the curve has " +
                                std::to_string(c.coefficients.rows()) + " betas, the model " +
                                std::to_string(b));
  }
  const auto pair = [](const Eigen::Vector2d& v) { return std::vector<double>{v[0], v[1]}; };
  nlohmann::json j;
  j["population"] = c.population;
  j["subjects"] = c.subjects;
  j["inputs"] = {kHeightName, c.weight_input == ShapeCurve::WeightInput::kKilograms
                                  ? kKilogramsName
                                  : kCubeRootName};
  j["features"] =
      "1, h, w, h^2, h w, w^2 of h, w = (input - center) / scale, inputs within [lo, hi]";
  j["center"] = pair(c.center);
  j["scale"] = pair(c.scale);
  j["lo"] = pair(c.lo);
  j["hi"] = pair(c.hi);
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < b; ++r) {
    rows.push_back(std::vector<double>(kFeatures));
    for (int q = 0; q < kFeatures; ++q) rows.back()[static_cast<size_t>(q)] = c.coefficients(r, q);
  }
  j["coefficients"] = rows;
  model.meta.extra[shape_curve_meta_key()] = j.dump();
}

std::optional<ShapeCurve> shape_curve(const smpl::BodyModel& model) {
  const auto it = model.meta.extra.find(shape_curve_meta_key());
  if (it == model.meta.extra.end()) return std::nullopt;
  const auto bad = [](const std::string& what) {
    return std::runtime_error(std::string("the model's '") + shape_curve_meta_key() +
                              "' metadata " + what +
                              "; regenerate the model with caliper-modelgen");
  };
  const Eigen::Index b = model.num_betas();
  ShapeCurve c;
  try {
    const nlohmann::json j = nlohmann::json::parse(it->second);
    c.population = j.at("population").get<std::string>();
    c.subjects = j.at("subjects").get<int>();
    if (const auto in = j.find("inputs"); in != j.end()) {
      const std::vector<std::string> names = in->get<std::vector<std::string>>();
      const std::vector<std::string> cube_root{kHeightName, kCubeRootName},
          kilograms{kHeightName, kKilogramsName};
      if (names == kilograms) {
        c.weight_input = ShapeCurve::WeightInput::kKilograms;
      } else if (names != cube_root) {
        throw bad("has inputs this program does not know (it knows " +
                  nlohmann::json(cube_root).dump() + " and " + nlohmann::json(kilograms).dump() +
                  "): " + in->dump());
      }
    }
    const auto pair = [&](const char* key) {
      const auto v = j.at(key).get<std::vector<double>>();
      if (v.size() != 2)
        throw bad(std::string("has ") + key + " of " + std::to_string(v.size()) + " values, not 2");
      return Eigen::Vector2d(v[0], v[1]);
    };
    c.center = pair("center");
    c.scale = pair("scale");
    c.lo = pair("lo");
    c.hi = pair("hi");
    const auto rows = j.at("coefficients").get<std::vector<std::vector<double>>>();
    if (static_cast<Eigen::Index>(rows.size()) != b) {
      throw bad("is for " + std::to_string(rows.size()) + " betas, the model has " +
                std::to_string(b));
    }
    c.coefficients.resize(b, kFeatures);
    for (Eigen::Index r = 0; r < b; ++r) {
      const auto& row = rows[static_cast<size_t>(r)];
      if (row.size() != static_cast<size_t>(kFeatures)) {
        throw bad("has a row of " + std::to_string(row.size()) + " coefficients, not 6");
      }
      for (int q = 0; q < kFeatures; ++q) c.coefficients(r, q) = row[static_cast<size_t>(q)];
    }
  } catch (const nlohmann::json::exception& e) {
    throw bad(std::string("is not a shape curve (population, subjects, center, scale, lo, hi, "
                          "coefficients): ") +
              e.what());
  }
  if (!c.center.allFinite() || !c.scale.allFinite() || !c.lo.allFinite() || !c.hi.allFinite() ||
      !c.coefficients.allFinite()) {
    throw bad("holds NaN or infinity");
  }
  if (!(c.scale.array() > 0.0).all()) throw bad("has a scale that is not positive");
  if (!(c.lo.array() <= c.hi.array()).all()) throw bad("has an empty range (lo above hi)");
  return c;
}

}  // namespace caliper
