#include "model_source.hpp"

#include <chrono>
#include <filesystem>

#include "caliper/assets.hpp"
#include "caliper/errors.hpp"
#include "caliper/inputs.hpp"
#include "cli_support.hpp"
#include "smpl/io.hpp"

namespace caliper::cli {

std::string resolve_model_path(const std::optional<std::string>& model_file,
                               const std::string& sex) {
  if (model_file) {
    if (!file_exists(*model_file)) {
      throw RuntimeError(*model_file +
                         ": model file not found (--model expects an SMPL-family "
                         ".npz or .pkl file)");
    }
    return *model_file;
  }
  const std::string model_sex = sex.empty() ? std::string("neutral") : sex;
  const std::string name = default_model_file_name(model_sex);
  const auto assets = find_assets_dir();
  if (!assets) {
    throw RuntimeError("the open default model " + name +
                       " was not found: no assets folder (tried " + tried_assets_dirs() +
                       "). Set CALIPER_ASSETS=/path/to/assets or pass --model FILE");
  }
  std::string path =
      default_model_path((std::filesystem::path(*assets) / "models").string(), model_sex);
  if (!file_exists(path)) {
    throw RuntimeError("the open default model " + path +
                       " does not exist: build it with caliper-modelgen (docs/models.md), set "
                       "CALIPER_ASSETS to an assets folder that has models/" +
                       name + ", or pass --model FILE");
  }
  return path;
}

std::shared_ptr<const ModelBundle> load_bundle(const std::string& model_path,
                                               const std::optional<std::string>& regressors_file,
                                               bool need_regressors, bool shape_curve) {
  auto bundle = std::make_shared<ModelBundle>();
  const auto t0 = std::chrono::steady_clock::now();
  bundle->model = smpl::load_model(model_path);
  bundle->path = model_path;
  try {
    bundle->measure_info.emplace(bundle->model);
  } catch (const LandmarkError&) {
    // left empty: measure_all() throws the same error for each avatar, where it is reported
  }
  if (shape_curve) {
    try {
      bundle->curve = caliper::shape_curve(bundle->model);
    } catch (const std::runtime_error& e) {
      throw RuntimeError(model_path + ": " + e.what() + " (or pass --no-shape-curve)");
    }
  }
  const auto t1 = std::chrono::steady_clock::now();
  bundle->load_seconds = std::chrono::duration<double>(t1 - t0).count();
  if (regressors_file) {
    bundle->regressors = RegressorSet::load(*regressors_file);
    bundle->regressors.check(bundle->model);
  } else if (need_regressors) {
    bundle->regressors = train_regressors(bundle->model);
  }
  bundle->train_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  return bundle;
}

std::shared_ptr<const ModelBundle> BundleCache::get(const std::string& sex) {
  const std::string key = model_file_ ? std::string("<model>") : sex;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = bundles_.find(key);
  if (it != bundles_.end()) return it->second;
  auto b = load_bundle(resolve_model_path(model_file_, sex), regressors_file_, true, shape_curve_);
  bundles_[key] = b;
  return b;
}

std::string default_regressor(const std::map<std::string, double>& inputs) {
  return caliper::default_regressor(inputs);
}

std::string normalise_regressor_name(const std::string& text) {
  try {
    return caliper::normalise_regressor_name(text, "--regressor");
  } catch (const InvalidInputError& e) {
    throw UsageError(e.what());
  }
}

}  // namespace caliper::cli
