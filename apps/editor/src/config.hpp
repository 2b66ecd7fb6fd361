/// \file config.hpp
/// The editor's small settings file: window size and units, kept in
/// $XDG_CONFIG_HOME/caliper/editor.json (or ~/.config/caliper/editor.json).
#pragma once

#include <string>

namespace caliper::editor {

struct EditorConfig {
  int window_width = 1600;
  int window_height = 1000;
  std::string units = "metric";
};

/// The settings file path ("" when neither XDG_CONFIG_HOME nor HOME is set).
std::string config_path();
/// Reads the settings; a missing or malformed file gives the defaults (never throws).
EditorConfig load_config(const std::string& path);
/// Writes the settings (creating the folder); returns false on failure (never throws).
bool save_config(const std::string& path, const EditorConfig& config);

}  // namespace caliper::editor
