// NHANES's upper arm on ANSUR II's acromion-radiale scale (protocol_mapping.hpp), on made-up
// surveys with a known protocol offset and a known shoulder-elbow to acromion-radiale relation.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <Eigen/Core>

#include "protocol_mapping.hpp"

namespace {

// The made-up laws: shoulder-elbow = 0.05 + 0.15 stature + 0.02 cbrt(weight); acromion-radiale
// = -0.01 + 0.95 shoulder-elbow; NHANES reads 3 cm more than that shoulder-elbow below BMI 35
// and 8 cm more above it (which the offset must not see).
double shoulder_elbow(double stature, double weight) {
  return 0.05 + 0.15 * stature + 0.02 * std::cbrt(weight);
}

Eigen::MatrixXd made_up_ansur() {
  Eigen::MatrixXd a(40, 4);
  for (int r = 0; r < 40; ++r) {
    const double h = 1.50 + 0.01 * r, w = 50.0 + 0.37 * ((r * 7) % 40);
    const double sel = shoulder_elbow(h, w) + (r % 2 == 0 ? 0.004 : -0.004);
    a.row(r) << h, w, sel, -0.01 + 0.95 * sel;
  }
  return a;
}

Eigen::MatrixXd made_up_nhanes() {
  Eigen::MatrixXd n(6, 3);
  n << 1.60, 60.0, 0.0, 1.70, 70.0, 0.0, 1.80, 80.0, 0.0,   // BMI 23.4, 24.2, 24.7
      1.60, 120.0, 0.0, 1.70, 130.0, 0.0, 1.65, 70.0, 0.0;  // BMI 46.9, 45.0, 25.7
  for (int r = 0; r < 6; ++r) {
    const double bmi = n(r, 1) / (n(r, 0) * n(r, 0));
    n(r, 2) = shoulder_elbow(n(r, 0), n(r, 1)) + (bmi < 35 ? 0.03 : 0.08);
  }
  return n;
}

TEST(UpperArmMapping, RecoversTheProtocolOffsetAndTheRelation) {
  const modelgen::UpperArmMapping m =
      modelgen::upper_arm_mapping(made_up_ansur(), made_up_nhanes());
  EXPECT_EQ(m.nhanes_people, 4);  // the two above BMI 35 are left out of the offset
  // The noise (+/-4 mm alternating) is not a function of stature and weight, so the fit of
  // shoulder-elbow is off by a little; the acromion-radiale relation is exact.
  EXPECT_NEAR(m.offset, 0.03, 5e-4);
  EXPECT_NEAR(m.slope, 0.95, 1e-9);
  EXPECT_NEAR(m.intercept, -0.01, 1e-9);
  EXPECT_LT(m.residual_sd, 1e-9);
  // An NHANES person's value becomes the acromion-radiale length of ANSUR II's protocol.
  const double bmxarml = shoulder_elbow(1.70, 70.0) + 0.03;
  EXPECT_NEAR(m.acromion_radiale(bmxarml), -0.01 + 0.95 * shoulder_elbow(1.70, 70.0), 5e-4);
  // Without the BMI filter the heavy people's 8 cm would pull the offset up.
  EXPECT_GT(modelgen::upper_arm_mapping(made_up_ansur(), made_up_nhanes(), 100.0).offset, 0.04);
}

// Step 1 alone, as the generator maps ANSUR II's flexed biceps onto NHANES's relaxed girth: a
// made-up relaxed girth 2 cm under the flexed one at equal stature and weight.
TEST(ProtocolOffset, IsTheMeanDifferenceAtEqualStatureAndWeightUnderTheBmiCut) {
  const Eigen::MatrixXd a = made_up_ansur().leftCols(3);
  Eigen::MatrixXd n = made_up_nhanes();
  for (Eigen::Index r = 0; r < n.rows(); ++r) n(r, 2) = shoulder_elbow(n(r, 0), n(r, 1)) - 0.02;
  const modelgen::ProtocolOffset o = modelgen::protocol_offset(a, n);
  EXPECT_EQ(o.nhanes_people, 4);
  EXPECT_NEAR(o.offset, -0.02, 5e-4);
  // The same step inside the upper arm's mapping gives the same offset, to the last bit.
  const Eigen::MatrixXd m = made_up_nhanes();
  EXPECT_EQ(modelgen::protocol_offset(a, m).offset,
            modelgen::upper_arm_mapping(made_up_ansur(), m).offset);
  EXPECT_THROW(modelgen::protocol_offset(made_up_ansur(), n), std::invalid_argument);
  EXPECT_THROW(modelgen::protocol_offset(a.topRows(9), n), std::invalid_argument);
  EXPECT_THROW(modelgen::protocol_offset(a, n, 20.0), std::invalid_argument);
}

TEST(UpperArmMapping, RefusesTablesItCannotUse) {
  const Eigen::MatrixXd a = made_up_ansur(), n = made_up_nhanes();
  EXPECT_THROW(modelgen::upper_arm_mapping(a.leftCols(3), n), std::invalid_argument);
  EXPECT_THROW(modelgen::upper_arm_mapping(a, n.leftCols(2)), std::invalid_argument);
  Eigen::MatrixXd bad = a;
  bad(3, 2) = std::nan("");
  EXPECT_THROW(modelgen::upper_arm_mapping(bad, n), std::invalid_argument);
  EXPECT_THROW(modelgen::upper_arm_mapping(a.topRows(5), n), std::invalid_argument);
  EXPECT_THROW(modelgen::upper_arm_mapping(a, n, 20.0), std::invalid_argument);  // nobody under
}

}  // namespace
