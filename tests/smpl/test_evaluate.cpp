// smpl::evaluate, smpl::shape, smpl::rodrigues: analytic and invariant tests.
#include <gtest/gtest.h>

#include "caliper_test/matrix_compare.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"

namespace {

TEST(Evaluate, Smoke) {
  const auto m = caliper::test::make_random_model(10);
  const auto b = smpl::evaluate(m, Eigen::VectorXd::Zero(10), Eigen::VectorXd::Zero(72));
  EXPECT_MATRIX_NEAR(b.vertices, m.v_template, 1e-12);
}

}  // namespace
