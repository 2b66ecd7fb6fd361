// Kernel variants (smpl/simd.hpp): every instruction-set variant this CPU runs gives the same
// bits as the baseline one, for the shape blend, both pose-blend-shape paths and skinning; level
// names parse and print; a level the CPU lacks cannot be forced.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/simd.hpp"

namespace {

using caliper::test::random_betas;
using caliper::test::random_pose;

using caliper::test::same_bits;

// One body's outputs, for a bitwise comparison.
struct Outputs {
  smpl::Body shaped, posed, posed_float;
  smpl::BodyBatch shape_batch, batch, batch_float;
  smpl::BodyBatchF shape_batch_float;
};

Outputs run(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
            const Eigen::VectorXd& pose) {
  Outputs o;
  o.shaped = smpl::shape(model, betas);
  o.posed = smpl::evaluate(model, betas, pose, Eigen::Vector3d(0.1, -0.2, 0.3));
  smpl::Workspace ws;
  ws.single_precision_pose_blend_shapes = true;
  smpl::evaluate(model, betas, pose, Eigen::Vector3d(0.1, -0.2, 0.3), ws, o.posed_float);
  // Batches of 5 (a group of 4 and a tail): the second body is the one above, the others vary.
  smpl::RowMatrixXd b(5, betas.size()), p(5, pose.size()), t(5, 3);
  for (int n = 0; n < 5; ++n) {
    b.row(n) = betas.transpose() * (0.5 + 0.25 * n);
    p.row(n) = pose.transpose() * (1.0 - 0.1 * n);
    t.row(n) = Eigen::RowVector3d(0.1, -0.2, 0.3 * n);
  }
  smpl::shape_batch(model, b, o.shape_batch);
  smpl::Workspace bws;
  smpl::shape_batch(model, b, bws, o.shape_batch_float);
  smpl::evaluate_batch(model, b, p, t, bws, o.batch);
  bws.single_precision_pose_blend_shapes = true;
  smpl::evaluate_batch(model, b, p, t, bws, o.batch_float, 2);
  return o;
}

TEST(Simd, EveryVariantGivesTheSameBits) {
  // 84 x 82 rings + 2 poles: 3V is not a multiple of the 32-row block, so the tails run too.
  caliper::test::RandomModelOptions mo;
  mo.num_betas = 13;
  const smpl::BodyModel model = caliper::test::make_random_model(mo);
  ASSERT_NE(model.v_template.rows() * 3 % 32, 0);
  const Eigen::VectorXd betas = random_betas(13, 2.0, 5);
  const Eigen::VectorXd pose = random_pose(24, 0.8, 6);
  Outputs base;
  {
    const smpl::ScopedSimdLevel pin(smpl::SimdLevel::kBaseline);
    base = run(model, betas, pose);
  }
  const std::vector<smpl::SimdLevel> levels = smpl::supported_simd_levels();
  for (smpl::SimdLevel level : levels) {
    const smpl::ScopedSimdLevel pin(level);
    ASSERT_EQ(smpl::simd_level(), level);
    const Outputs o = run(model, betas, pose);
    const Eigen::Index n = base.posed.vertices.size();
    EXPECT_TRUE(same_bits(base.shaped.vertices.data(), o.shaped.vertices.data(), n))
        << smpl::simd_level_name(level) << ": shape blend differs from baseline";
    EXPECT_TRUE(
        same_bits(base.shaped.joints.data(), o.shaped.joints.data(), base.shaped.joints.size()))
        << smpl::simd_level_name(level);
    EXPECT_TRUE(same_bits(base.posed.vertices.data(), o.posed.vertices.data(), n))
        << smpl::simd_level_name(level) << ": posed (double) differs from baseline";
    EXPECT_TRUE(same_bits(base.posed_float.vertices.data(), o.posed_float.vertices.data(), n))
        << smpl::simd_level_name(level) << ": posed (float pose blend) differs from baseline";
    const Eigen::Index nb = base.batch.vertices.size();
    EXPECT_TRUE(same_bits(base.shape_batch.vertices.data(), o.shape_batch.vertices.data(), nb))
        << smpl::simd_level_name(level) << ": shape_batch differs from baseline";
    EXPECT_TRUE(
        same_bits(base.shape_batch_float.vertices.data(), o.shape_batch_float.vertices.data(), nb))
        << smpl::simd_level_name(level) << ": shape_batch (float) differs from baseline";
    EXPECT_TRUE(same_bits(base.shape_batch_float.joints.data(), o.shape_batch_float.joints.data(),
                          base.shape_batch_float.joints.size()))
        << smpl::simd_level_name(level) << ": shape_batch (float) joints differ from baseline";
    EXPECT_TRUE(same_bits(base.batch.vertices.data(), o.batch.vertices.data(), nb))
        << smpl::simd_level_name(level) << ": evaluate_batch (double) differs from baseline";
    EXPECT_TRUE(same_bits(base.batch_float.vertices.data(), o.batch_float.vertices.data(), nb))
        << smpl::simd_level_name(level) << ": evaluate_batch (float) differs from baseline";
  }
  std::printf("[ simd ] variants compared on this CPU:");
  for (smpl::SimdLevel level : levels) std::printf(" %s", smpl::simd_level_name(level));
  std::printf("\n");
}

TEST(Simd, NamesRoundTripAndUnknownNamesAreRefused) {
  for (smpl::SimdLevel l :
       {smpl::SimdLevel::kBaseline, smpl::SimdLevel::kAvx2, smpl::SimdLevel::kAvx512}) {
    EXPECT_EQ(smpl::parse_simd_level(smpl::simd_level_name(l)), l);
  }
  EXPECT_EQ(smpl::parse_simd_level("SSE2"), smpl::SimdLevel::kBaseline);
  try {
    smpl::parse_simd_level("avx3");
    FAIL() << "avx3 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("baseline, avx2 or avx512"), std::string::npos);
  }
}

TEST(Simd, ScopesNestAndALevelTheCpuLacksIsRefused) {
  const smpl::SimdLevel outer = smpl::simd_level();
  {
    const smpl::ScopedSimdLevel a(smpl::SimdLevel::kBaseline);
    EXPECT_EQ(smpl::simd_level(), smpl::SimdLevel::kBaseline);
  }
  EXPECT_EQ(smpl::simd_level(), outer);
  const std::vector<smpl::SimdLevel> levels = smpl::supported_simd_levels();
  ASSERT_FALSE(levels.empty());
  EXPECT_EQ(levels.front(), smpl::SimdLevel::kBaseline);
  if (levels.back() != smpl::SimdLevel::kAvx512) {
    EXPECT_THROW(smpl::ScopedSimdLevel{smpl::SimdLevel::kAvx512}, std::invalid_argument);
  }
}

}  // namespace
