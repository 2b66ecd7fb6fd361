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
