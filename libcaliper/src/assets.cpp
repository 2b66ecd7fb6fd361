#include "caliper/assets.hpp"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace caliper {

namespace fs = std::filesystem;

std::vector<std::string> assets_dir_candidates() {
  if (const char* env = std::getenv("CALIPER_ASSETS"); env && *env) return {env};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  std::vector<std::string> out;
  for (const char* rel : {"../../assets", "../share/virtual-caliper/assets", "../assets"}) {
    out.push_back((exe.parent_path() / rel).lexically_normal().string());
  }
  return out;
}

std::optional<std::string> find_assets_dir() {
  for (const std::string& dir : assets_dir_candidates()) {
    std::error_code ec;
    if (fs::is_directory(dir, ec)) return dir;
  }
  return std::nullopt;
}

std::string default_model_file_name(const std::string& sex) {
  return "caliper-" + sex + ".npz";
}

std::string default_model_path(const std::string& models_dir, const std::string& sex) {
  return (fs::path(models_dir) / default_model_file_name(sex)).string();
}

}  // namespace caliper
