// Batch evaluation (smpl::shape_batch, smpl::evaluate_batch): every body of a batch equals a
// single call (the same bits where the same columns of posedirs are read, within 1e-12 m
// otherwise), for any thread count, with both pose-blend-shape precisions; bad sizes are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"

namespace {

using caliper::test::random_betas;
using caliper::test::random_pose;
using smpl::RowMatrixXd;

// Batch against single calls when a body's skipped joint columns differ from the batch's (the
// batch skips a joint only when it is at rest in every body, so it adds zero products that the
// single call skips, which changes where partial sums round): a few ulps of metre-sized values.
constexpr double kBatchVsSingle = 1e-12;

// The same with the float pose blend shapes: float partial sums (float epsilon 6e-8 relative) of
// 207 products each, summed over different runs of columns; both paths are documented to be
// within 1e-7 m of the double path, so they are within that of each other.
constexpr double kFloatBatchVsSingle = 1e-7;

using caliper::test::same_bits;

double max_abs_diff(const double* a, const double* b, Eigen::Index n) {
  double m = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

struct Inputs {
  RowMatrixXd betas, poses, translations;
};

// N bodies; when `sparse`, body n leaves joints with (k + n) % 3 == 0 at rest, so the bodies'
// skipped columns differ.
Inputs make_inputs(int n_bodies, int n_betas, int K, bool sparse, std::uint64_t seed) {
  Inputs in;
  in.betas.resize(n_bodies, n_betas);
  in.poses.resize(n_bodies, 3 * static_cast<Eigen::Index>(K));
  in.translations.resize(n_bodies, 3);
  for (int n = 0; n < n_bodies; ++n) {
    in.betas.row(n) = random_betas(n_betas, 1.5, seed + 3 * static_cast<std::uint64_t>(n));
    Eigen::VectorXd pose = random_pose(K, 0.9, seed + 3 * static_cast<std::uint64_t>(n) + 1);
    if (sparse) {
      for (int k = 1; k < K; ++k) {
        if ((k + n) % 3 == 0) pose.segment<3>(3 * static_cast<Eigen::Index>(k)).setZero();
      }
    }
    in.poses.row(n) = pose.transpose();
    in.translations.row(n) = Eigen::RowVector3d(0.1 * n, -0.05, 0.02 * n);
  }
  return in;
}

TEST(Batch, ShapeBatchHasTheBitsOfSingleCallsForAnyThreadCount) {
  caliper::test::RandomModelOptions mo;
  mo.num_betas = 13;
  const smpl::BodyModel model = caliper::test::make_random_model(mo);
  // Bodies share each loaded vector of shapedirs in groups of 4: 9 bodies on 1, 2 and 3 threads
  // give shares of 9, 4 + 5 and 3 + 3 + 3 bodies, so every group size (4, then 1, 2 or 3) runs.
  const int N = 9;
  const Inputs in = make_inputs(N, 11, 24, false, 40);  // fewer betas than the model's
  for (int threads : {1, 2, 3}) {
    smpl::BodyBatch batch;
    smpl::shape_batch(model, in.betas, batch, threads);
    ASSERT_EQ(batch.vertices.rows(), N);
    ASSERT_EQ(batch.vertices.cols(), 3 * model.num_vertices());
    ASSERT_EQ(batch.joints.cols(), 3 * model.num_joints());
    for (int n = 0; n < N; ++n) {
      const smpl::Body one = smpl::shape(model, in.betas.row(n).transpose());
      EXPECT_TRUE(same_bits(one.vertices.data(), batch.vertices.row(n).data(), one.vertices.size()))
          << "body " << n << ", " << threads << " threads";
      EXPECT_TRUE(same_bits(one.joints.data(), batch.joints.row(n).data(), one.joints.size()))
          << "body " << n << ", " << threads << " threads";
    }
  }
  // Betas as a block of a wider matrix (rows 11 apart in memory): the rows are read with their
  // stride.
  smpl::BodyBatch strided;
  smpl::shape_batch(model, in.betas.leftCols(6), strided);
  for (int n = 0; n < N; ++n) {
    const smpl::Body one = smpl::shape(model, in.betas.row(n).head(6).transpose());
    EXPECT_TRUE(same_bits(one.vertices.data(), strided.vertices.row(n).data(), one.vertices.size()))
        << "body " << n << " of the strided betas";
  }
}

TEST(Batch, FloatShapeBatchIsWithinAMicrometreOfDoubleForAnyThreadCount) {
  caliper::test::RandomModelOptions mo;
  mo.num_betas = 13;
  const smpl::BodyModel model = caliper::test::make_random_model(mo);
  const int N = 9;  // every group size, as above
  const Inputs in = make_inputs(N, 11, 24, false, 41);
  smpl::BodyBatch ref;
  smpl::shape_batch(model, in.betas, ref);
  smpl::Workspace ws;
  smpl::BodyBatchF first;
  for (int threads : {1, 2, 3}) {
    smpl::BodyBatchF batch;
    smpl::shape_batch(model, in.betas, ws, batch, threads);
    ASSERT_EQ(batch.vertices.rows(), N);
    ASSERT_EQ(batch.vertices.cols(), 3 * model.num_vertices());
    ASSERT_EQ(batch.joints.cols(), 3 * model.num_joints());
    EXPECT_TRUE(caliper::test::matrices_near(batch.vertices, ref.vertices, 1e-6)) << threads;
    EXPECT_TRUE(caliper::test::matrices_near(batch.joints, ref.joints, 1e-6)) << threads;
    if (threads == 1) {
      first = batch;
      continue;
    }
    EXPECT_TRUE(same_bits(first.vertices.data(), batch.vertices.data(), first.vertices.size()))
        << threads << " threads changed the result";
    EXPECT_TRUE(same_bits(first.joints.data(), batch.joints.data(), first.joints.size()))
        << threads << " threads changed the result";
  }
  // Strided betas, and the same workspace with another model: its float copies are remade.
  caliper::test::RandomModelOptions mo2;
  mo2.num_betas = 8;
  const smpl::BodyModel other = caliper::test::make_random_model(mo2);
  smpl::BodyBatch ref2;
  smpl::shape_batch(other, in.betas.leftCols(6), ref2);
  smpl::BodyBatchF strided;
  smpl::shape_batch(other, in.betas.leftCols(6), ws, strided);
  EXPECT_TRUE(caliper::test::matrices_near(strided.vertices, ref2.vertices, 1e-6));
  EXPECT_TRUE(caliper::test::matrices_near(strided.joints, ref2.joints, 1e-6));
  EXPECT_THROW(smpl::shape_batch(other, in.betas, ws, strided), std::invalid_argument)
      << "11 betas for a model of 8";
  EXPECT_THROW(smpl::shape_batch(other, in.betas.leftCols(6), ws, strided, -1),
               std::invalid_argument);
}

void check_evaluate_batch(bool single_precision, bool sparse) {
  const smpl::BodyModel model = caliper::test::make_random_model(10, 24, true, 3);
  const int N = 9;  // two groups of 4 bodies and a tail of 1
  const Inputs in = make_inputs(N, 10, 24, sparse, 70);
  smpl::BodyBatch b1, b2;
  smpl::Workspace ws;
  ws.single_precision_pose_blend_shapes = single_precision;
  smpl::evaluate_batch(model, in.betas, in.poses, in.translations, ws, b1, 1);
  smpl::evaluate_batch(model, in.betas, in.poses, in.translations, ws, b2, 2);
  EXPECT_TRUE(same_bits(b1.vertices.data(), b2.vertices.data(), b1.vertices.size()))
      << "thread count changed the result";
  smpl::Workspace single_ws;
  single_ws.single_precision_pose_blend_shapes = single_precision;
  smpl::Body one;
  double worst = 0.0;
  for (int n = 0; n < N; ++n) {
    smpl::evaluate(model, in.betas.row(n).transpose(), in.poses.row(n).transpose(),
                   in.translations.row(n).transpose(), single_ws, one);
    const double dv =
        max_abs_diff(one.vertices.data(), b1.vertices.row(n).data(), one.vertices.size());
    const double dj = max_abs_diff(one.joints.data(), b1.joints.row(n).data(), one.joints.size());
    EXPECT_EQ(dj, 0.0) << "joints do not depend on the pose blend shapes";
    worst = std::max(worst, dv);
    if (!sparse) {
      EXPECT_TRUE(same_bits(one.vertices.data(), b1.vertices.row(n).data(), one.vertices.size()))
          << "body " << n << ": every joint rotated, so the batch reads the same columns";
    }
  }
  EXPECT_LE(worst, single_precision ? kFloatBatchVsSingle : kBatchVsSingle);
  std::printf("[ batch ] %s, %s: max |batch - single| = %.3g m\n",
              single_precision ? "float" : "double", sparse ? "sparse poses" : "all rotated",
              worst);
}

TEST(Batch, EvaluateBatchEqualsSingleCallsDouble) {
  check_evaluate_batch(false, false);
  check_evaluate_batch(false, true);
}

TEST(Batch, EvaluateBatchEqualsSingleCallsFloat) {
  check_evaluate_batch(true, false);
  check_evaluate_batch(true, true);
}

// Correctives that act near their joint only, as the open v2 models' (each joint's 9 columns
// non-zero on a sixth of the rows, a different sixth per joint): the workspace's map of the rows
// each joint touches skips the rest.
smpl::BodyModel local_correctives_model() {
  smpl::BodyModel m = caliper::test::make_random_model(10, 24, true, 3);
  const Eigen::Index rows = m.posedirs.rows();
  for (Eigen::Index j = 0; j < 23; ++j) {
    const Eigen::Index first = j * rows / 23, length = rows / 6;
    for (Eigen::Index r = 0; r < rows; ++r) {
      const Eigen::Index from_first = (r - first + rows) % rows;
      if (from_first >= length) m.posedirs.block(r, 9 * j, 1, 9).setZero();
    }
  }
  return m;
}

int unequal_values(const double* a, const double* b, Eigen::Index n) {
  int count = 0;
  for (Eigen::Index i = 0; i < n; ++i) count += a[i] == b[i] ? 0 : 1;
  return count;
}

TEST(Batch, CorrectivesNearTheirJointsSkipTheRowsTheyDoNotTouch) {
  const smpl::BodyModel model = local_correctives_model();
  const int N = 9;
  for (const bool sparse : {false, true}) {
    const Inputs in = make_inputs(N, 10, 24, sparse, 90);
    for (const bool single_precision : {false, true}) {
      smpl::Workspace mapped, plain;
      mapped.single_precision_pose_blend_shapes = single_precision;
      plain.single_precision_pose_blend_shapes = single_precision;
      plain.skip_zero_pose_rows = false;
      smpl::BodyBatch batch;
      smpl::evaluate_batch(model, in.betas, in.poses, in.translations, mapped, batch, 2);
      ASSERT_FALSE(mapped.pose_row_chunks.empty()) << "the map skips rows of this model";
      smpl::Body with_map, without;
      double worst = 0.0;
      for (int n = 0; n < N; ++n) {
        smpl::evaluate(model, in.betas.row(n).transpose(), in.poses.row(n).transpose(),
                       in.translations.row(n).transpose(), mapped, with_map);
        smpl::evaluate(model, in.betas.row(n).transpose(), in.poses.row(n).transpose(),
                       in.translations.row(n).transpose(), plain, without);
        // joint by joint, every zero product skipped or added exactly: batch equals single
        EXPECT_EQ(unequal_values(with_map.vertices.data(), batch.vertices.row(n).data(),
                                 with_map.vertices.size()),
                  0)
            << "body " << n << (single_precision ? ", float" : ", double");
        worst = std::max(worst, max_abs_diff(with_map.vertices.data(), without.vertices.data(),
                                             with_map.vertices.size()));
      }
      // against the runs of joints without the map: the sums grouped differently
      EXPECT_LE(worst, single_precision ? kFloatBatchVsSingle : kBatchVsSingle);
      EXPECT_GT(worst, 0.0) << "the correctives were applied";
    }
  }
  // dense correctives (every chunk touched): nothing to skip, the bits of a workspace without
  // the map
  const smpl::BodyModel dense = caliper::test::make_random_model(10, 24, true, 3);
  const Inputs in = make_inputs(3, 10, 24, true, 91);
  smpl::Workspace mapped, plain;
  plain.skip_zero_pose_rows = false;
  smpl::Body a, b;
  for (int n = 0; n < 3; ++n) {
    smpl::evaluate(dense, in.betas.row(n).transpose(), in.poses.row(n).transpose(),
                   in.translations.row(n).transpose(), mapped, a);
    smpl::evaluate(dense, in.betas.row(n).transpose(), in.poses.row(n).transpose(),
                   in.translations.row(n).transpose(), plain, b);
    EXPECT_TRUE(same_bits(a.vertices.data(), b.vertices.data(), a.vertices.size()));
  }
  EXPECT_TRUE(mapped.pose_row_chunks.empty());
  // another model in the same workspace: the map is remade for it
  smpl::evaluate(model, in.betas.row(0).transpose(), in.poses.row(0).transpose(),
                 in.translations.row(0).transpose(), mapped, a);
  EXPECT_FALSE(mapped.pose_row_chunks.empty());
}

TEST(Batch, SmallBatchesGiveTheBitsOfTheirBodiesInALargeBatch) {
  // Fewer than 4 bodies take the streaming kernels, more the packed ones: same operations.
  const smpl::BodyModel model = caliper::test::make_random_model(10, 24, true, 3);
  const Inputs in = make_inputs(6, 10, 24, false, 20);
  for (bool single_precision : {false, true}) {
    smpl::Workspace ws;
    ws.single_precision_pose_blend_shapes = single_precision;
    smpl::BodyBatch large, small;
    smpl::evaluate_batch(model, in.betas, in.poses, in.translations, ws, large);
    smpl::evaluate_batch(model, in.betas.topRows(2), in.poses.topRows(2),
                         in.translations.topRows(2), ws, small, 2);
    EXPECT_TRUE(same_bits(large.vertices.data(), small.vertices.data(), small.vertices.size()))
        << (single_precision ? "float" : "double");
  }
}

TEST(Batch, RestPoseAndNoTranslationEqualShape) {
  const smpl::BodyModel model = caliper::test::make_random_model(10, 24, true, 5);
  const Inputs in = make_inputs(3, 10, 24, false, 90);
  smpl::BodyBatch batch;
  smpl::Workspace ws;
  smpl::evaluate_batch(model, in.betas, RowMatrixXd(0, 0), RowMatrixXd(0, 3), ws, batch);
  for (int n = 0; n < 3; ++n) {
    const smpl::Body one = smpl::evaluate(model, in.betas.row(n).transpose(), Eigen::VectorXd());
    EXPECT_TRUE(same_bits(one.vertices.data(), batch.vertices.row(n).data(), one.vertices.size()));
  }
}

TEST(Batch, WrongSizesAreRefusedWithTheReason) {
  const smpl::BodyModel model = caliper::test::make_random_model(10, 24, true, 5);
  const Inputs in = make_inputs(3, 10, 24, false, 90);
  smpl::BodyBatch batch;
  smpl::Workspace ws;
  auto message = [&](auto&& call) {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] {
              smpl::evaluate_batch(model, in.betas, in.poses.topRows(2), in.translations, ws,
                                   batch);
            }).find("rows of poses"),
            std::string::npos);
  EXPECT_NE(message([&] {
              smpl::evaluate_batch(model, in.betas, in.poses.leftCols(9), in.translations, ws,
                                   batch);
            }).find("axis-angle"),
            std::string::npos);
  EXPECT_NE(message([&] {
              smpl::evaluate_batch(model, in.betas, in.poses, in.translations.leftCols(2), ws,
                                   batch);
            }).find("translations"),
            std::string::npos);
  EXPECT_NE(message([&] {
              smpl::shape_batch(model, RowMatrixXd::Zero(2, 11), batch);
            }).find("shape components"),
            std::string::npos);
  EXPECT_NE(message([&] { smpl::shape_batch(model, in.betas, batch, -1); }).find("threads"),
            std::string::npos);
}

}  // namespace
