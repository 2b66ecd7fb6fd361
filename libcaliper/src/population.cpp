/// \file population.cpp
/// Survey populations in a model's metadata (population.hpp). JSON through nlohmann-json.
#include "caliper/population.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "caliper/errors.hpp"

namespace caliper {

std::string population_meta_key(const std::string& key) {
  return "population." + key;
}

void set_survey_population(smpl::BodyModel& model, const std::string& key,
                           const SurveyPopulation& p) {
  const Eigen::Index b = model.num_betas();
  if (p.mean.size() != b || p.cov.rows() != b || p.cov.cols() != b) {
    throw std::invalid_argument("set_survey_population: population '" + key + "' has " +
                                std::to_string(p.mean.size()) + " betas, the model " +
                                std::to_string(b));
  }
  nlohmann::json j;
  j["survey"] = p.survey;
  j["subjects"] = p.subjects;
  j["mean"] = std::vector<double>(p.mean.data(), p.mean.data() + b);
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < b; ++r) {
    std::vector<double> row(static_cast<size_t>(b));
    for (Eigen::Index c = 0; c < b; ++c) row[static_cast<size_t>(c)] = p.cov(r, c);
    rows.push_back(row);
  }
  j["cov"] = rows;
  model.meta.extra[population_meta_key(key)] = j.dump();
}

std::optional<SurveyPopulation> survey_population(const smpl::BodyModel& model,
                                                  const std::string& key) {
  const auto it = model.meta.extra.find(population_meta_key(key));
  if (it == model.meta.extra.end()) return std::nullopt;
  const std::string where = "the model's '" + population_meta_key(key) + "' metadata";
  const Eigen::Index b = model.num_betas();
  // Every error says what to do: the entry is the generator's, so a new file replaces it.
  const auto bad = [&where](const std::string& what) {
    return std::runtime_error(where + what + "; regenerate the model with caliper-modelgen");
  };
  SurveyPopulation p;
  try {
    const nlohmann::json j = nlohmann::json::parse(it->second);
    p.survey = j.at("survey").get<std::string>();
    p.subjects = j.at("subjects").get<int>();
    const auto mean = j.at("mean").get<std::vector<double>>();
    const auto cov = j.at("cov").get<std::vector<std::vector<double>>>();
    if (static_cast<Eigen::Index>(mean.size()) != b || static_cast<Eigen::Index>(cov.size()) != b) {
      throw bad(" is for " + std::to_string(mean.size()) + " betas, the model has " +
                std::to_string(b));
    }
    p.mean = Eigen::Map<const Eigen::VectorXd>(mean.data(), b);
    p.cov.resize(b, b);
    for (Eigen::Index r = 0; r < b; ++r) {
      if (static_cast<Eigen::Index>(cov[static_cast<size_t>(r)].size()) != b) {
        throw bad(": covariance row " + std::to_string(r) + " is not " + std::to_string(b) +
                  " long");
      }
      for (Eigen::Index c = 0; c < b; ++c)
        p.cov(r, c) = cov[static_cast<size_t>(r)][static_cast<size_t>(c)];
    }
  } catch (const nlohmann::json::exception& e) {
    throw bad(std::string(" is not a population (survey, subjects, mean, cov): ") + e.what());
  }
  if (!p.mean.allFinite() || !p.cov.allFinite()) {
    throw bad(" holds NaN or infinity");
  }
  for (Eigen::Index r = 0; r < b; ++r) {
    if (p.cov(r, r) < 0.0) throw bad(": a negative variance");
    for (Eigen::Index c = 0; c < r; ++c) {
      if (p.cov(r, c) != p.cov(c, r)) throw bad(": covariance not symmetric");
    }
  }
  return p;
}

Eigen::MatrixXd sampling_factor(const Eigen::MatrixXd& cov) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  const Eigen::VectorXd root = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return eig.eigenvectors() * root.asDiagonal() * eig.eigenvectors().transpose();
}

std::vector<std::string> population_keys(const smpl::BodyModel& model) {
  const std::string prefix = population_meta_key("");
  std::vector<std::string> keys;
  for (const auto& [key, value] : model.meta.extra) {
    if (key.compare(0, prefix.size(), prefix) == 0) keys.push_back(key.substr(prefix.size()));
  }
  return keys;  // meta.extra is a sorted map
}

ShapePrior population_prior(const smpl::BodyModel& model, const std::string& key) {
  const std::optional<SurveyPopulation> p = survey_population(model, key);
  if (!p) {
    std::string have;
    for (const std::string& s : population_keys(model)) have += (have.empty() ? "" : ", ") + s;
    throw InvalidInputError("the model '" + model.meta.name + "' carries no population '" + key +
                            "' (" + (have.empty() ? "it carries none" : "it carries: " + have) +
                            "; the open models carry ansur2 and nhanes)");
  }
  return {p->mean, p->cov};
}

}  // namespace caliper
