// Learned real-to-virtual mappings and shape plausibility (incomplete gamma, chi-square).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "caliper/errors.hpp"
#include "caliper/mapping.hpp"
#include "caliper/plausibility.hpp"
#include "smpl/io.hpp"

namespace caliper {
namespace {

constexpr double kExactTol = 1e-12;

std::string write_temp(const std::string& name, const std::string& text) {
  std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(Mapping, IdentityUntilFitted) {
  const MeasurementMapping m;
  EXPECT_TRUE(m.is_identity());
  EXPECT_EQ(m.apply("hip_width", 0.31), 0.31);
  const MeasurementMap in = {{"height", 1.8}, {"hip_width", 0.3}};
  EXPECT_EQ(m.apply(in), in);
}

TEST(Mapping, ExactLineIsRecoveredWithZeroLeaveOneOutError) {
  std::vector<PairedValue> pairs;
  for (double x : {0.30, 0.32, 0.35, 0.37, 0.41}) pairs.push_back({"hip_width", x, 0.9 * x + 0.05});
  for (double x : {1.6, 1.7, 1.9}) pairs.push_back({"height", x, x - 0.01});
  const MeasurementMapping m = MeasurementMapping::fit(pairs);
  const LinearMap& hw = m.maps().at("hip_width");
  EXPECT_NEAR(hw.a, 0.9, kExactTol);
  EXPECT_NEAR(hw.b, 0.05, kExactTol);
  EXPECT_EQ(hw.count, 5);
  EXPECT_NEAR(hw.loo_mae, 0.0, kExactTol);
  EXPECT_NEAR(hw.fit_rms, 0.0, kExactTol);
  // Without the mapping the error is |0.1 x - 0.05| on average.
  EXPECT_NEAR(hw.identity_mae, (0.02 + 0.018 + 0.015 + 0.013 + 0.009) / 5, kExactTol);
  EXPECT_NEAR(m.apply("hip_width", 0.5), 0.5, kExactTol);
  EXPECT_NEAR(m.apply("height", 2.0), 1.99, kExactTol);
  EXPECT_EQ(m.apply("arm_length", 0.6), 0.6);  // not fitted: identity
}

TEST(Mapping, LeaveOneOutByHand) {
  // Points (0,0), (1,1), (2,0): leaving out (1,1), the line through the others is y = 0, so the
  // error at x = 1 is 1; leaving out (0,0), the line is y = 2 - x: error 2 at x = 0; by symmetry 2.
  const MeasurementMapping m =
      MeasurementMapping::fit({{"hip_width", 0, 0}, {"hip_width", 1, 1}, {"hip_width", 2, 0}});
  const LinearMap& l = m.maps().at("hip_width");
  EXPECT_NEAR(l.a, 0.0, kExactTol);
  EXPECT_NEAR(l.b, 1.0 / 3.0, kExactTol);
  EXPECT_NEAR(l.loo_mae, 5.0 / 3.0, kExactTol);
  EXPECT_NEAR(l.loo_max, 2.0, kExactTol);
}

TEST(Mapping, TooFewOrDegeneratePairs) {
  EXPECT_THROW(MeasurementMapping::fit({{"hip_width", 0.3, 0.3}, {"hip_width", 0.4, 0.4}}),
               InvalidInputError);
  EXPECT_THROW(MeasurementMapping::fit(
                   {{"hip_width", 0.3, 0.3}, {"hip_width", 0.3, 0.4}, {"hip_width", 0.3, 0.5}}),
               InvalidInputError);
  EXPECT_THROW(MeasurementMapping::fit({{"hip_width", 0.3, 0.3},
                                        {"hip_width", 0.3, 0.4},
                                        {"hip_width", 0.3, 0.5},
                                        {"hip_width", 0.4, 0.5}}),
               InvalidInputError);  // leaving out the 0.4 leaves equal reals
  EXPECT_THROW(MeasurementMapping::fit({{"hip_width", std::nan(""), 0.3}}), InvalidInputError);
}

TEST(Mapping, CsvAndJson) {
  const std::string path =
      write_temp("c1_pairs.csv",
                 "# paired values, metres\nsubject,measurement,virtual,real\n"
                 "1,hip_width,0.32,0.30\n2,hip_width,0.338,0.32\n\n3,hip_width,0.365,0.35\n"
                 "4, hip_width , 0.383 , 0.37 \n");
  const auto pairs = read_paired_csv(path);
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_EQ(pairs[3].measurement, "hip_width");
  EXPECT_DOUBLE_EQ(pairs[0].real, 0.30);
  EXPECT_DOUBLE_EQ(pairs[0].virtual_value, 0.32);
  const MeasurementMapping m = MeasurementMapping::fit(pairs);
  EXPECT_NEAR(m.maps().at("hip_width").a, 0.9, 1e-9);
  const std::string jpath = std::string(CALIPER_TEST_DATA_DIR) + "/c1_mapping.json";
  m.save(jpath);
  const MeasurementMapping back = MeasurementMapping::load(jpath);
  EXPECT_EQ(back.apply("hip_width", 0.33), m.apply("hip_width", 0.33));
  EXPECT_EQ(back.maps().at("hip_width").loo_mae, m.maps().at("hip_width").loo_mae);
  Json bad = m.to_json();
  bad.set("format", "caliper-regressors");
  EXPECT_THROW(MeasurementMapping::from_json(bad), InvalidInputError);
  // Bad files name the file and line.
  const std::string nohead = write_temp("c1_bad1.csv", "measurement,real\nhip_width,0.3\n");
  EXPECT_THROW(read_paired_csv(nohead), InvalidInputError);
  const std::string badnum =
      write_temp("c1_bad2.csv", "measurement,real,virtual\nhip_width,0.3,abc\n");
  try {
    read_paired_csv(badnum);
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("c1_bad2.csv:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_paired_csv(write_temp("c1_bad3.csv", "")), InvalidInputError);
  EXPECT_THROW(read_paired_csv(path + ".missing"), InvalidInputError);
  for (const char* f :
       {"c1_pairs.csv", "c1_mapping.json", "c1_bad1.csv", "c1_bad2.csv", "c1_bad3.csv"}) {
    std::remove((std::string(CALIPER_TEST_DATA_DIR) + "/" + f).c_str());
  }
}

// ---------------------------------------------------------------------------------------------
// Plausibility

TEST(IncompleteGamma, AnalyticCases) {
  // P(1, x) = 1 - e^-x; P(1/2, x) = erf(sqrt x); P(n, x) = 1 - e^-x sum_{k<n} x^k / k!.
  for (double x : {0.01, 0.5, 1.0, 2.0, 5.0, 20.0, 60.0}) {
    EXPECT_NEAR(regularized_gamma_p(1.0, x), 1.0 - std::exp(-x), 1e-14) << x;
    EXPECT_NEAR(regularized_gamma_p(0.5, x), std::erf(std::sqrt(x)), 1e-14) << x;
    EXPECT_NEAR(regularized_gamma_q(0.5, x), std::erfc(std::sqrt(x)),
                1e-13 * std::erfc(std::sqrt(x)) + 1e-300)
        << x;
    double sum = 0.0, term = 1.0;
    for (int k = 0; k < 5; ++k) {
      sum += term;
      term *= x / (k + 1);
    }
    EXPECT_NEAR(regularized_gamma_q(5.0, x), std::exp(-x) * sum, 1e-14) << x;
  }
  EXPECT_EQ(regularized_gamma_p(3.0, 0.0), 0.0);
  EXPECT_EQ(regularized_gamma_q(3.0, 0.0), 1.0);
  EXPECT_THROW(regularized_gamma_p(0.0, 1.0), InvalidInputError);
  EXPECT_THROW(regularized_gamma_p(1.0, -1.0), InvalidInputError);
  EXPECT_THROW(regularized_gamma_q(1.0, std::nan("")), InvalidInputError);
}

TEST(ChiSquare, KnownQuantiles) {
  // Standard table values (5 significant digits): 95 % quantiles for k = 1, 2, 10 and the 99.9 %
  // quantile for k = 10.
  EXPECT_NEAR(chi_square_cdf(3.8415, 1), 0.95, 1e-5);
  EXPECT_NEAR(chi_square_cdf(5.9915, 2), 0.95, 1e-5);
  EXPECT_NEAR(chi_square_cdf(18.307, 10), 0.95, 1e-5);
  EXPECT_NEAR(chi_square_sf(29.588, 10), 0.001, 1e-6);
  // k = 2 is exponential: cdf = 1 - e^{-x/2}.
  EXPECT_NEAR(chi_square_cdf(3.0, 2), 1.0 - std::exp(-1.5), 1e-15);
  EXPECT_EQ(chi_square_cdf(-1.0, 3), 0.0);
  EXPECT_EQ(chi_square_sf(0.0, 3), 1.0);
  EXPECT_THROW(chi_square_cdf(1.0, 0.0), InvalidInputError);
}

TEST(Plausibility, FlagsAndDistance) {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(10);
  Plausibility p = plausibility(b);
  EXPECT_TRUE(p.plausible);
  EXPECT_EQ(p.mahalanobis, 0.0);
  EXPECT_EQ(p.p_value, 1.0);
  b(2) = 2.5;
  b(7) = -3.5;
  p = plausibility(b);
  EXPECT_EQ(p.beyond_2sd, (std::vector<int>{2, 7}));
  EXPECT_EQ(p.beyond_3sd, (std::vector<int>{7}));
  EXPECT_FALSE(p.plausible);
  EXPECT_NEAR(p.mahalanobis, std::sqrt(2.5 * 2.5 + 3.5 * 3.5), kExactTol);
  EXPECT_EQ(p.dof, 10);
  EXPECT_NEAR(p.cdf + p.p_value, 1.0, 1e-14);
  EXPECT_NEAR(p.cdf, chi_square_cdf(18.5, 10), 1e-15);
  // Within 3 SD per component but far overall: implausible by the chi-square tail.
  p = plausibility(Eigen::VectorXd::Constant(10, 2.9));
  EXPECT_TRUE(p.beyond_3sd.empty());
  EXPECT_LT(p.p_value, 1e-3);
  EXPECT_FALSE(p.plausible);
  EXPECT_THROW(plausibility(Eigen::VectorXd()), InvalidInputError);
  EXPECT_THROW(plausibility(Eigen::VectorXd::Constant(2, std::nan(""))), InvalidInputError);
}

// The arm a tape takes on the hanging arm (ANSUR II's acromion-radiale plus radiale-stylion)
// mapped onto the open female model's virtual arm_length (shoulder to wrist landmark in the
// T-pose): about 7 cm shorter, so taking one for the other (identity_mae) misses by far more than
// the map's residual; the map gives the mean body's own virtual arm back from its hanging arm.
TEST(HangingArmMap, MapsTheSurveysArmOntoTheOpenModelsVirtualArm) {
  const smpl::BodyModel model =
      smpl::load_model(std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-female.npz");
  const LinearMap map = hanging_arm_map(model);
  EXPECT_EQ(map.count, 200);
  EXPECT_GT(map.a, 0.8);
  EXPECT_LT(map.a, 1.05);
  EXPECT_LT(map.fit_rms, 0.010);
  EXPECT_GT(map.identity_mae, 0.05);
  EXPECT_LT(map.loo_mae, 0.010);
  const smpl::Vertices mean = model.v_template;
  const double virtual_arm = measure(mean, landmarks_for(model), measurement_def("arm_length"));
  EXPECT_NEAR(map.apply(hanging_arm_length(model, mean)), virtual_arm, 0.01);
  // The same map on every run (fixed seed).
  EXPECT_EQ(hanging_arm_map(model).a, map.a);
  EXPECT_THROW(hanging_arm_map(model, 2), InvalidInputError);
}

}  // namespace
}  // namespace caliper
