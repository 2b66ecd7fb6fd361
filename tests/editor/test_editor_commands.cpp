// The text command language on its own: every command name, what malformed commands say, and
// that view commands change only the view.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/editor_core.hpp"
#include "editor_test_entry.hpp"

namespace ca = caliper::app;

namespace {
ca::EditorCore make_core() {
  ca::EditorCore c;
  c.add_model(caliper::test::editor_test_entry());
  return c;
}
std::string last(const ca::EditorCore& c) {
  return c.messages().empty() ? "" : c.messages().back().text;
}
}  // namespace

TEST(EditorCommands, KnowsEveryCommandOfTheScriptLanguage) {
  const std::vector<std::string> expected = {
      "arm-hanging",  "color",     "colour", "compare",      "drag",         "export",
      "hierarchical", "level",     "model",  "open-profile", "open-session", "overlay",
      "redo",         "regressor", "reset",  "save-profile", "scale",        "set",
      "sex",          "undo",      "units",  "wireframe"};
  EXPECT_EQ(ca::command_names(), expected);
}

TEST(EditorCommands, MalformedCommandsSayWhatWasExpected) {
  ca::EditorCore c = make_core();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"fly away", "unknown command"},
      {"set height", "expected: set <id> <value> [unit]"},
      {"drag weight", "expected: drag <id> <value> [unit]"},
      {"set height 70 kg", "unit 'kg' does not fit height"},
      {"units furlongs", "units are metric or imperial"},
      {"regressor R7", "regressor is R2, R4, R5, R6 or noise-aware"},
      {"hierarchical maybe", "expected on or off"},
      {"arm-hanging maybe", "expected on or off"},
      {"level two", "expected a level 1..3"},
      {"model", "expected a model index or file"},
      {"open-profile", "expected a file"},
      {"export", "expected a file"},
      {"wireframe sometimes", "expected on or off"},
      {"scale huge", "scale is fixed or fit"},
      {"colour blue", "colour is skin, plausibility or uncertainty"},
      {"compare side", "pin an avatar first (compare pin)"},
      {"compare sideways", "compare pin|side|difference|off|clear"},
      {"redo", "nothing to redo"},
  };
  for (const auto& [line, why] : cases) {
    EXPECT_FALSE(c.run_command(line)) << line;
    EXPECT_EQ(last(c), "command '" + line + "': " + why);
  }
  EXPECT_TRUE(ca::run_command(c, "   "));
  EXPECT_TRUE(ca::run_command(c, "#set height 3"));
}

TEST(EditorCommands, ViewCommandsChangeTheViewOnly) {
  ca::EditorCore c = make_core();
  const ca::Document before = c.state();
  ASSERT_TRUE(ca::run_command(c, "wireframe on"));
  ASSERT_TRUE(ca::run_command(c, "overlay 0"));
  ASSERT_TRUE(ca::run_command(c, "scale fixed"));
  ASSERT_TRUE(ca::run_command(c, "color uncertainty"));
  ASSERT_TRUE(ca::run_command(c, "units imperial"));
  EXPECT_TRUE(c.view().wireframe);
  EXPECT_FALSE(c.view().overlay);
  EXPECT_TRUE(c.view().fixed_scale);
  EXPECT_EQ(c.view().colour, ca::ColourMode::Uncertainty);
  EXPECT_EQ(c.view().units, ca::UnitSystem::Imperial);
  EXPECT_EQ(c.state(), before);
  EXPECT_FALSE(c.can_undo());
}

TEST(EditorCommands, EditsGoThroughTheCoreAndItsHistory) {
  ca::EditorCore c = make_core();
  ASSERT_TRUE(ca::run_command(c, "units imperial"));
  ASSERT_TRUE(ca::run_command(c, "set height 70"));                   // display units: inches
  EXPECT_EQ(c.state().values.at("height"), 70 * ca::kMetresPerInch);  // one multiplication
  ASSERT_TRUE(ca::run_command(c, "drag weight 80 kg"));
  EXPECT_DOUBLE_EQ(c.state().values.at("weight"), 80.0);
  EXPECT_TRUE(c.avatar().achieved_complete);  // a scripted drag ends
  ASSERT_TRUE(ca::run_command(c, "level 2"));
  ASSERT_TRUE(ca::run_command(c, "compare pin before"));
  ASSERT_TRUE(ca::run_command(c, "compare difference"));
  EXPECT_EQ(c.view().compare, ca::CompareMode::Difference);
  ASSERT_TRUE(ca::run_command(c, "compare clear"));
  EXPECT_FALSE(c.comparison().has_value());
  EXPECT_EQ(c.view().compare, ca::CompareMode::Off);
  ASSERT_TRUE(ca::run_command(c, "undo"));
  EXPECT_EQ(c.state().level, 1);
  EXPECT_FALSE(ca::run_command(c, "level 4"));  // the core's own error
  EXPECT_EQ(last(c), "level must be 1, 2 or 3, not 4");
  EXPECT_FALSE(ca::run_command(c, "model 7"));
  EXPECT_EQ(last(c), "no model number 7");
}
