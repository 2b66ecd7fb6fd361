// The comparison avatar: pinned at zero difference, the distance grows with the change, and
// another model (other vertex count) has no difference map.
#include <gtest/gtest.h>

#include "app/comparison.hpp"

namespace ca = caliper::app;

namespace {
ca::AvatarView avatar_with(int rows) {
  ca::AvatarView a;
  a.vertices = smpl::Vertices::Zero(rows, 3);
  a.achieved["height"] = 1.7;
  return a;
}
}  // namespace

TEST(Comparison, APinnedAvatarStartsAtZeroDifference) {
  const ca::AvatarView a = avatar_with(4);
  const ca::Comparison c = ca::pin("before", a);
  EXPECT_EQ(c.label, "before");
  EXPECT_TRUE(c.vertices == a.vertices);
  EXPECT_EQ(c.values, a.achieved);
  ASSERT_EQ(c.difference.size(), 4u);
  for (float d : c.difference) EXPECT_EQ(d, 0.0f);
}

TEST(Comparison, DifferenceIsThePerVertexDistance) {
  ca::Comparison c = ca::pin("before", avatar_with(3));
  smpl::Vertices now = smpl::Vertices::Zero(3, 3);
  now.row(1) << 0.03, 0.04, 0.0;  // 5 cm away
  now.row(2) << 0.0, 0.0, -0.01;
  ca::update_difference(c, now);
  ASSERT_EQ(c.difference.size(), 3u);
  EXPECT_FLOAT_EQ(c.difference[0], 0.0f);
  EXPECT_FLOAT_EQ(c.difference[1], 0.05f);
  EXPECT_FLOAT_EQ(c.difference[2], 0.01f);
}

TEST(Comparison, AnotherModelHasNoDifferenceMap) {
  ca::Comparison c = ca::pin("before", avatar_with(3));
  ca::update_difference(c, smpl::Vertices::Zero(5, 3));
  EXPECT_TRUE(c.difference.empty());
  ca::update_difference(c, smpl::Vertices::Zero(3, 3));  // back on the pinned model
  EXPECT_EQ(c.difference.size(), 3u);
}
