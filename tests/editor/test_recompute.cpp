// The pure recomputation of the avatar from a document: deterministic, the floor at 0, the
// inputs reach the body, drags measure lengths only, and documents that cannot be applied
// throw without a half-made avatar.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "app/recompute.hpp"
#include "caliper/errors.hpp"
#include "editor_test_entry.hpp"

namespace ca = caliper::app;
using caliper::test::editor_test_entry;
using caliper::test::editor_test_entry_without_hanging_arm;

namespace {
/// A level-1 document at the mean shape's own measurements.
ca::Document mean_document() {
  ca::Document d;
  d.values = ca::mean_shape_inputs(editor_test_entry());
  return d;
}
}  // namespace

TEST(Recompute, MeanShapeInputsAreTheSixR6Measurements) {
  const caliper::MeasurementMap m = ca::mean_shape_inputs(editor_test_entry());
  EXPECT_EQ(m.size(), ca::choice_inputs(ca::RegressorChoice::R6).size());
  for (const std::string& id : ca::choice_inputs(ca::RegressorChoice::R6))
    EXPECT_GT(m.at(id), 0.0) << id;
}

TEST(Recompute, IsDeterministicAndStandsOnTheFloor) {
  const ca::Document d = mean_document();
  const ca::AvatarView a = ca::recompute(d, editor_test_entry(), true);
  const ca::AvatarView b = ca::recompute(d, editor_test_entry(), true);
  EXPECT_TRUE(a.vertices == b.vertices);
  EXPECT_TRUE(a.betas == b.betas);
  EXPECT_EQ(a.achieved, b.achieved);
  EXPECT_EQ(a.vertices.rows(), editor_test_entry().model->num_vertices());
  EXPECT_EQ(a.betas.size(), editor_test_entry().model->num_betas());
  EXPECT_DOUBLE_EQ(a.vertices.col(1).minCoeff(), 0.0);
  EXPECT_TRUE(a.achieved_complete);
  EXPECT_EQ(a.achieved.count("weight"), 1u);
  EXPECT_EQ(a.beta_sd.size(), 0);  // not noise-aware
  for (float u : a.uncertainty) ASSERT_EQ(u, 0.0f);
}

TEST(Recompute, ATallerInputGivesATallerAvatar) {
  ca::Document d = mean_document();
  const double h0 = ca::recompute(d, editor_test_entry(), true).achieved.at("height");
  d.values["height"] = h0 + 0.10;
  const ca::AvatarView a = ca::recompute(d, editor_test_entry(), true);
  // The random test model's regressor is only roughly right, so ask for more than half of the
  // 10 cm typed, not for the typed height.
  EXPECT_GT(a.achieved.at("height"), h0 + 0.05);
}

TEST(Recompute, ADragMeasuresLengthsOnly) {
  const ca::AvatarView a = ca::recompute(mean_document(), editor_test_entry(), false);
  EXPECT_FALSE(a.achieved_complete);
  EXPECT_EQ(a.achieved.count("weight"), 0u);
  EXPECT_EQ(a.achieved.count("height"), 1u);
}

TEST(Recompute, NoiseAwareGivesSdsAndAnUncertaintyMap) {
  ca::Document d = mean_document();
  d.regressor = ca::RegressorChoice::NoiseAware;
  const ca::AvatarView a = ca::recompute(d, editor_test_entry(), true);
  ASSERT_GT(a.beta_sd.size(), 0);
  float largest = 0.0f;
  for (float u : a.uncertainty) largest = std::max(largest, u);
  EXPECT_GT(largest, 0.0f);
}

TEST(Recompute, ImplausibleBodiesShowWhereTheyAreImplausible) {
  ca::Document d = mean_document();
  const ca::AvatarView mean = ca::recompute(d, editor_test_entry(), true);
  for (float x : mean.implausible_displacement) ASSERT_EQ(x, 0.0f);
  d.values["height"] = 2.2;
  d.values["weight"] = 45.0;
  const ca::AvatarView odd = ca::recompute(d, editor_test_entry(), true);
  float largest = 0.0f;
  for (float x : odd.implausible_displacement) largest = std::max(largest, x);
  EXPECT_GT(largest, 0.0f);
}

TEST(Recompute, ADocumentWithoutItsInputsThrows) {
  ca::Document d = mean_document();
  d.values.erase("weight");
  EXPECT_THROW(ca::recompute(d, editor_test_entry(), true), caliper::InvalidInputError);
  d = mean_document();
  d.level = 3;
  d.values.erase("hip_width");
  EXPECT_THROW(ca::recompute(d, editor_test_entry(), true), caliper::InvalidInputError);
}

// ---- The arm length taken hanging ------------------------------------------------------------
namespace {
/// A level-3 document at the mean shape's own measurements (the arm out sideways).
ca::Document level_three() {
  ca::Document d = mean_document();
  d.level = 3;
  return d;
}

/// The largest difference between two avatars' vertices, metres.
double largest_move(const ca::AvatarView& a, const ca::AvatarView& b) {
  return (a.vertices - b.vertices).cwiseAbs().maxCoeff();
}

}  // namespace

// A hanging arm length is the model's map of it: the same avatar as the mapped value taken out
// sideways, for the linear regressors and the noise-aware one.
TEST(Recompute, AnArmTakenHangingIsMappedWithTheModelsMap) {
  const caliper::LinearMap& map = ca::hanging_arm(editor_test_entry());
  for (ca::RegressorChoice c : {ca::RegressorChoice::R6, ca::RegressorChoice::NoiseAware}) {
    ca::Document hanging = level_three();
    hanging.regressor = c;
    hanging.arm_taken_hanging = true;
    hanging.values["arm_length"] = 0.60;
    ca::Document sideways = hanging;
    sideways.arm_taken_hanging = false;
    sideways.values["arm_length"] = map.apply(0.60);
    EXPECT_DOUBLE_EQ(ca::regression_inputs(hanging, editor_test_entry()).at("arm_length"),
                     map.apply(0.60));
    const ca::AvatarView a = ca::recompute(hanging, editor_test_entry(), true);
    const ca::AvatarView b = ca::recompute(sideways, editor_test_entry(), true);
    EXPECT_LE((a.betas - b.betas).cwiseAbs().maxCoeff(), 1e-9) << ca::to_string(c);
    EXPECT_LE(largest_move(a, b), 1e-9) << ca::to_string(c);
    // Taken as it is (not mapped), the value makes another body.
    ca::Document unmapped = sideways;
    unmapped.values["arm_length"] = 0.60;
    EXPECT_GT(largest_move(a, ca::recompute(unmapped, editor_test_entry(), true)), 1e-4);
  }
  // Below level 3 the arm length is no input: the convention changes nothing.
  ca::Document low = mean_document();
  const ca::AvatarView before = ca::recompute(low, editor_test_entry(), true);
  low.arm_taken_hanging = true;
  EXPECT_EQ(largest_move(before, ca::recompute(low, editor_test_entry(), true)), 0.0);
}

// Toggling converts the value (hanging = (virtual - b) / a and back), so the avatar stays; the
// avatar's arm shown as typed is the hanging value the map turns into it.
TEST(Recompute, TogglingTheArmsConventionConvertsTheValue) {
  const caliper::LinearMap& map = ca::hanging_arm(editor_test_entry());
  const ca::Document sideways = level_three();
  const double v = sideways.values.at("arm_length");
  const ca::Document hanging = ca::with_arm_taken_hanging(sideways, editor_test_entry(), true);
  EXPECT_TRUE(hanging.arm_taken_hanging);
  EXPECT_NEAR(hanging.values.at("arm_length"), (v - map.b) / map.a, 1e-15);
  EXPECT_NE(hanging.values.at("arm_length"), v);
  EXPECT_LE(largest_move(ca::recompute(sideways, editor_test_entry(), true),
                         ca::recompute(hanging, editor_test_entry(), true)),
            1e-9);
  const ca::Document back = ca::with_arm_taken_hanging(hanging, editor_test_entry(), false);
  EXPECT_FALSE(back.arm_taken_hanging);
  EXPECT_NEAR(back.values.at("arm_length"), v, 1e-15);
  EXPECT_EQ(ca::with_arm_taken_hanging(hanging, editor_test_entry(), true), hanging);

  const caliper::MeasurementMap measured = {{"height", 1.7}, {"arm_length", 0.5}};
  EXPECT_EQ(ca::as_typed(sideways, editor_test_entry(), measured), measured);
  const caliper::MeasurementMap typed = ca::as_typed(hanging, editor_test_entry(), measured);
  EXPECT_DOUBLE_EQ(typed.at("height"), 1.7);
  EXPECT_NEAR(map.apply(typed.at("arm_length")), 0.5, 1e-15);
}

// The map is worked out once per model and shared by the entry's copies.
TEST(Recompute, TheHangingArmMapIsWorkedOutOnce) {
  // NOLINTNEXTLINE(performance-unnecessary-copy-initialization): the copy is what is tested
  const ca::ModelEntry copy = editor_test_entry();
  EXPECT_EQ(&ca::hanging_arm(copy), &ca::hanging_arm(editor_test_entry()));
  EXPECT_EQ(ca::hanging_arm_unavailable(copy), "");
  EXPECT_EQ(ca::hanging_arm(copy).count, 200);
}

// A model that cannot swing its arms down has no map: a document with the arm taken hanging
// gives a message naming the model, the reason and what to do; turning the convention on is
// refused; an arm length that is no input is dropped when the convention goes off.
TEST(Recompute, AModelWithoutAHangingArmMapSaysWhy) {
  const ca::ModelEntry& e = editor_test_entry_without_hanging_arm();
  const std::string why = ca::hanging_arm_unavailable(e);
  EXPECT_NE(why.find("shoulder"), std::string::npos) << why;
  ca::Document d;
  d.values = ca::mean_shape_inputs(e);
  d.level = 3;
  EXPECT_NO_THROW(ca::recompute(d, e, true));
  d.arm_taken_hanging = true;
  try {
    ca::recompute(d, e, true);
    ADD_FAILURE() << "no error";
  } catch (const caliper::InvalidInputError& x) {
    const std::string m = x.what();
    EXPECT_NE(m.find("sixteen-joints cannot map a hanging arm"), std::string::npos) << m;
    EXPECT_NE(m.find(why), std::string::npos) << m;
    EXPECT_NE(m.find("untick 'taken hanging'"), std::string::npos) << m;
  }
  EXPECT_THROW(ca::with_arm_taken_hanging(d, e, false), caliper::InvalidInputError);
  d.arm_taken_hanging = false;
  EXPECT_THROW(ca::with_arm_taken_hanging(d, e, true), caliper::InvalidInputError);
  // Not an input: nothing to convert, and nothing to convert it with.
  d.level = 1;
  d.arm_taken_hanging = true;
  const ca::Document off = ca::with_arm_taken_hanging(d, e, false);
  EXPECT_FALSE(off.arm_taken_hanging);
  EXPECT_EQ(off.values.count("arm_length"), 0u);
  EXPECT_EQ(ca::as_typed(d, e, {{"arm_length", 0.5}}).count("arm_length"), 0u);
}
