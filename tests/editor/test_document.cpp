// The editor's document alone: regressor choices, the hierarchy's inputs, which inputs a
// document edits, starting new inputs from the avatar, and the undo/redo descriptions.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "app/document.hpp"

namespace ca = caliper::app;

namespace {
bool contains(const std::vector<std::string>& v, const std::string& id) {
  return std::find(v.begin(), v.end(), id) != v.end();
}
}  // namespace

TEST(Document, RegressorChoicesRoundTripThroughText) {
  for (ca::RegressorChoice c :
       {ca::RegressorChoice::R2, ca::RegressorChoice::R4, ca::RegressorChoice::R5,
        ca::RegressorChoice::R6, ca::RegressorChoice::NoiseAware}) {
    EXPECT_EQ(ca::parse_regressor_choice(ca::to_string(c)), c) << ca::to_string(c);
  }
  EXPECT_EQ(ca::parse_regressor_choice("na"), ca::RegressorChoice::NoiseAware);
  EXPECT_EQ(ca::parse_regressor_choice("Noise_Aware"), ca::RegressorChoice::NoiseAware);
  EXPECT_FALSE(ca::parse_regressor_choice("R7"));
  EXPECT_FALSE(ca::parse_regressor_choice(""));
}

TEST(Document, HierarchyLevelsAddInputsAsInThePaper) {
  // Level 1: height and weight (R2); level 2 adds inseam and arm span (R4); level 3 adds arm
  // length and hip width (R6).
  EXPECT_EQ(ca::level_inputs(1).size(), 2u);
  EXPECT_EQ(ca::level_inputs(2).size(), 4u);
  EXPECT_EQ(ca::level_inputs(3).size(), 6u);
  EXPECT_TRUE(contains(ca::level_inputs(1), "height"));
  EXPECT_TRUE(contains(ca::level_inputs(1), "weight"));
  EXPECT_TRUE(contains(ca::level_inputs(2), "inseam_height"));
  EXPECT_TRUE(contains(ca::level_inputs(3), "hip_width"));
  EXPECT_FALSE(contains(ca::level_inputs(2), "hip_width"));
  EXPECT_EQ(ca::level_inputs(0), ca::level_inputs(1));  // below 1 counts as 1
  EXPECT_EQ(ca::level_inputs(9), ca::level_inputs(3));
}

TEST(Document, ActiveRegressorAndEditableInputsFollowTheMode) {
  ca::Document d;
  EXPECT_EQ(ca::active_regressor(d), ca::RegressorChoice::R2);
  d.level = 2;
  EXPECT_EQ(ca::active_regressor(d), ca::RegressorChoice::R4);
  EXPECT_EQ(ca::editable_inputs(d), ca::level_inputs(2));
  d.regressor = ca::RegressorChoice::R5;  // hierarchical: the level decides
  EXPECT_EQ(ca::active_regressor(d), ca::RegressorChoice::R4);
  d.hierarchical = false;
  EXPECT_EQ(ca::active_regressor(d), ca::RegressorChoice::R5);
  EXPECT_EQ(ca::editable_inputs(d), ca::choice_inputs(ca::RegressorChoice::R5));
  d.hierarchical = true;
  d.regressor = ca::RegressorChoice::NoiseAware;  // noise-aware wins over the level
  EXPECT_EQ(ca::active_regressor(d), ca::RegressorChoice::NoiseAware);
  EXPECT_EQ(ca::choice_inputs(ca::RegressorChoice::NoiseAware),
            ca::choice_inputs(ca::RegressorChoice::R6));
}

TEST(Document, NewInputsStartFromTheAvatarAndKeptOnesStay) {
  ca::Document d;
  d.values = {{"height", 1.80}, {"weight", 80.0}};
  const caliper::MeasurementMap achieved = {
      {"height", 1.79}, {"weight", 79.0}, {"inseam_height", 0.83}};
  ca::start_from_avatar(d, ca::level_inputs(2), ca::level_inputs(1), achieved);
  EXPECT_DOUBLE_EQ(d.values.at("height"), 1.80);  // kept: the typed value stays
  EXPECT_DOUBLE_EQ(d.values.at("weight"), 80.0);
  EXPECT_DOUBLE_EQ(d.values.at("inseam_height"), 0.83);  // new: the avatar's own value
  EXPECT_EQ(d.values.count("arm_span_fingertips"), 0u);  // the avatar has none
}

TEST(Document, EqualityCoversEveryField) {
  ca::Document a;
  a.values["height"] = 1.7;
  ca::Document b = a;
  EXPECT_EQ(a, b);
  b.level = 2;
  EXPECT_NE(a, b);
  b = a;
  b.hierarchical = false;
  EXPECT_NE(a, b);
  b = a;
  b.regressor = ca::RegressorChoice::R6;
  EXPECT_NE(a, b);
  b = a;
  b.values["height"] = 1.71;
  EXPECT_NE(a, b);
  b = a;
  b.arm_taken_hanging = true;  // undo/redo restore the arm's convention too
  EXPECT_NE(a, b);
}

TEST(Document, ChangesAreDescribedInTheDisplayUnits) {
  ca::Document from;
  from.values = {{"height", 1.70}, {"weight", 60.0}};
  ca::Document to = from;
  EXPECT_EQ(ca::describe_change(from, to, ca::UnitSystem::Metric), "no visible change");
  to.values["height"] = 1.652;
  EXPECT_EQ(ca::describe_change(from, to, ca::UnitSystem::Metric),
            "Overall height 170.0 -> 165.2 cm");
  to.level = 2;
  to.values["inseam_height"] = 0.80;
  const std::string s = ca::describe_change(from, to, ca::UnitSystem::Imperial);
  EXPECT_EQ(s.rfind("hierarchical level 2; ", 0), 0u) << s;
  EXPECT_NE(s.find(" in"), std::string::npos) << s;
  EXPECT_EQ(s.find("cm"), std::string::npos) << s;
  to.hierarchical = false;
  EXPECT_EQ(ca::describe_change(from, to, ca::UnitSystem::Metric).rfind("regressor R2", 0), 0u);
}

// Toggling how the arm length was taken says so, before the converted value, which is named as
// it is now taken.
TEST(Document, TheArmsConventionIsDescribed) {
  ca::Document from;
  from.values = {{"height", 1.70}, {"arm_length", 0.468}};
  ca::Document to = from;
  to.arm_taken_hanging = true;
  EXPECT_EQ(ca::describe_change(from, to, ca::UnitSystem::Metric), "arm length taken hanging");
  EXPECT_EQ(ca::describe_change(to, from, ca::UnitSystem::Metric), "arm length out sideways");
  to.values["arm_length"] = 0.539;
  EXPECT_EQ(ca::describe_change(from, to, ca::UnitSystem::Metric),
            "arm length taken hanging; Arm length (hanging) 46.8 -> 53.9 cm");
  EXPECT_EQ(ca::describe_change(to, from, ca::UnitSystem::Metric),
            "arm length out sideways; Arm length (shoulder to wrist) 53.9 -> 46.8 cm");
  EXPECT_EQ(ca::input_label(to, "arm_length"), "Arm length (hanging)");
  EXPECT_EQ(ca::input_label(from, "arm_length"), "Arm length (shoulder to wrist)");
  EXPECT_EQ(ca::input_label(to, "height"), "Overall height");
}

TEST(Document, LabelsAndDescriptions) {
  EXPECT_EQ(ca::measurement_label("weight"), "Weight");
  EXPECT_EQ(ca::measurement_label("height"), "Overall height");
  EXPECT_EQ(ca::measurement_label("not_an_id"), "not_an_id");
  // Every input a regressor takes says how to measure it; the arm length which way.
  for (const std::string& id : ca::choice_inputs(ca::RegressorChoice::R6)) {
    EXPECT_FALSE(ca::measurement_hint(id).empty()) << id;
  }
  EXPECT_NE(ca::measurement_hint("arm_length").find("hanging"), std::string::npos);
  EXPECT_NE(ca::measurement_hint("arm_length").find("'taken hanging'"), std::string::npos);
  EXPECT_EQ(ca::measurement_hint("not_an_id"), "");
  EXPECT_EQ(ca::describe_regressor(ca::RegressorChoice::R2), "R2: Overall height, Weight");
  EXPECT_NE(ca::describe_regressor(ca::RegressorChoice::NoiseAware).find("uncertainty"),
            std::string::npos);
}
