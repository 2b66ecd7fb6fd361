#include "config.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "caliper/json.hpp"

namespace caliper::editor {

std::string config_path() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  if (xdg != nullptr && *xdg != '\0') return std::string(xdg) + "/caliper/editor.json";
  const char* home = std::getenv("HOME");
  if (home != nullptr && *home != '\0') return std::string(home) + "/.config/caliper/editor.json";
  return "";
}

EditorConfig load_config(const std::string& path) {
  EditorConfig c;
  if (path.empty() || !std::filesystem::exists(path)) return c;
  try {
    const Json j = read_json_file(path);
    if (const Json* w = j.find("window_width"))
      c.window_width = std::clamp(w->as_int(), 320, 16384);
    if (const Json* h = j.find("window_height")) {
      c.window_height = std::clamp(h->as_int(), 240, 16384);
    }
    if (const Json* u = j.find("units")) c.units = u->as_string();
  } catch (const std::exception&) {
    return EditorConfig{};
  }
  return c;
}

bool save_config(const std::string& path, const EditorConfig& config) {
  if (path.empty()) return false;
  try {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    Json j = Json::object();
    j.set("window_width", config.window_width);
    j.set("window_height", config.window_height);
    j.set("units", config.units);
    write_json_file(path, j);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace caliper::editor
