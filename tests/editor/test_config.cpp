// The editor's settings file (window size, units): round trip, defaults for a missing or
// malformed file, clamping of absurd sizes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "config.hpp"

namespace ce = caliper::editor;

namespace {
std::string temp(const std::string& name) {
  return std::string(CALIPER_TEST_DATA_DIR) + "/editor_config_" + name;
}
}  // namespace

TEST(EditorConfig, RoundTripCreatesTheFolder) {
  const std::string path = temp("dir/sub/editor.json");
  ce::EditorConfig c;
  c.window_width = 1234;
  c.window_height = 777;
  c.units = "imperial";
  ASSERT_TRUE(ce::save_config(path, c));
  const ce::EditorConfig r = ce::load_config(path);
  EXPECT_EQ(r.window_width, 1234);
  EXPECT_EQ(r.window_height, 777);
  EXPECT_EQ(r.units, "imperial");
}

TEST(EditorConfig, MissingOrMalformedFileGivesDefaults) {
  const ce::EditorConfig d;
  EXPECT_EQ(ce::load_config(temp("missing.json")).window_width, d.window_width);
  const std::string bad = temp("bad.json");
  std::ofstream(bad) << "{ window_width: ";
  EXPECT_EQ(ce::load_config(bad).window_height, d.window_height);
  const std::string absurd = temp("absurd.json");
  std::ofstream(absurd) << R"({"window_width": 5, "window_height": 999999})";
  const ce::EditorConfig a = ce::load_config(absurd);
  EXPECT_EQ(a.window_width, 320);     // clamped to the smallest usable window
  EXPECT_EQ(a.window_height, 16384);  // and to the largest
}

TEST(EditorConfig, PathFollowsXdgConfigHome) {
  const char* old = std::getenv("XDG_CONFIG_HOME");
  const std::string keep = old ? old : "";
  setenv("XDG_CONFIG_HOME", "/tmp/xdg-test", 1);
  EXPECT_EQ(ce::config_path(), "/tmp/xdg-test/caliper/editor.json");
  unsetenv("XDG_CONFIG_HOME");
  const char* home = std::getenv("HOME");
  if (home != nullptr) {
    EXPECT_EQ(ce::config_path(), std::string(home) + "/.config/caliper/editor.json");
  }
  if (old) setenv("XDG_CONFIG_HOME", keep.c_str(), 1);
}
