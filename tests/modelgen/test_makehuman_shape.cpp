/// \file test_makehuman_shape.cpp
/// The shape space of the open model v2 from real people (issue 11): survey subjects registered
/// to MakeHuman's targets reproduce their measurements, and the principal components reproduce
/// the registered population. On a subset of the surveys (the whole run is caliper-modelgen
/// caliper-modelgen, about 6 CPU minutes; figures in docs/models.md).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "caliper/circumference.hpp"
#include "caliper/measurements.hpp"
#include "caliper/population.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper/weight.hpp"
#include "makehuman_measures.hpp"
#include "makehuman_rig.hpp"
#include "makehuman_shape.hpp"
#include "makehuman_test_data.hpp"
#include "smpl/simd.hpp"

namespace {

using makehuman_test::kMh;
const std::string kData = kMh + "/..";

#define REQUIRE_DATA()                                                                         \
  if (!std::ifstream(kMh + "/3dobjs/base.obj") ||                                              \
      !std::ifstream(kData + "/nhanes/NHANES_2017_2020_FEMALE_dev.csv")) {                     \
    GTEST_SKIP() << "MakeHuman assets or surveys not found under " << kData << " (../shared)"; \
  }

namespace mh = modelgen::mh;

struct Registered {
  mh::Assets assets;
  smpl::BodyModel tmpl;
  mh::ShapeBasis basis;
  std::vector<mh::Subject> subjects;
  mh::FitResult fit;
};

double bmi(const mh::Subject& s) {
  return s.values[1] / (s.values[0] * s.values[0]);
}

/// 100 ANSUR II subjects per sex (more than the 80 directions of a sex, so that the NHANES
/// subjects get the population prior), 10 NHANES subjects per sex and the NHANES subject of each
/// sex with the highest BMI.
const Registered& registered() {
  static const Registered s = [] {
    Registered x;
    x.assets = mh::read_assets(kMh);
    x.tmpl = mh::template_model(x.assets, mh::default_regressor_targets());
    x.basis = mh::shape_basis(x.assets, x.tmpl);
    const std::vector<mh::Subject> all = mh::read_subjects(kData + "/ansur2", kData + "/nhanes");
    for (const char* source : {"ANSUR II", "NHANES"}) {
      for (const char* sex : {"female", "male"}) {
        const int take = std::string(source) == "NHANES" ? 10 : 100;
        int n = 0;
        const mh::Subject* heaviest = nullptr;
        for (const mh::Subject& subj : all) {
          if (subj.source != source || subj.sex != sex) continue;
          if (n++ < take) x.subjects.push_back(subj);
          if (heaviest == nullptr || bmi(subj) > bmi(*heaviest)) heaviest = &subj;
        }
        if (std::string(source) == "NHANES") x.subjects.push_back(*heaviest);
      }
    }
    x.fit = mh::fit_subjects(x.basis, x.tmpl, x.subjects, 2);
    return x;
  }();
  return s;
}

TEST(MakeHumanShape, ReadsBothSurveysWithTheirUnits) {
  REQUIRE_DATA();
  const std::vector<mh::Subject> all = mh::read_subjects(kData + "/ansur2", kData + "/nhanes");
  int counts[2][2] = {{0, 0}, {0, 0}};
  double max_bmi = 0.0;
  for (const mh::Subject& s : all) {
    ++counts[s.source == "NHANES"][s.sex == "male"];
    EXPECT_GT(s.values[0], 1.3) << "height in metres";
    EXPECT_LT(s.values[0], 2.2) << "height in metres";
    EXPECT_GT(s.values[1], 30.0) << "weight in kg";
    // The upper arm (acromion-radiale) of both surveys, NHANES's mapped onto ANSUR II's
    // protocol: 0.26 to 0.40 m for adults.
    EXPECT_EQ(mh::fit_measures()[20].id, "upper_arm_length");
    EXPECT_GT(s.values[20], 0.24) << s.source;
    EXPECT_LT(s.values[20], 0.42) << s.source;
    // The relaxed mid-upper-arm girth of both surveys, ANSUR II's mapped from the flexed
    // biceps: NHANES 2017-2020 (development half) 17.9 to 57.2 cm, ANSUR II flexed 21.6 to 49.0.
    EXPECT_EQ(mh::fit_measures()[21].id, "upper_arm_circumference");
    EXPECT_GT(s.values[21], 0.165) << s.source;
    EXPECT_LT(s.values[21], 0.65) << s.source;
    // The upper leg, trochanterion to lateral femoral epicondyle height, NHANES's (inguinal
    // crease to kneecap, seated) mapped onto it: 0.266 to 0.521 m in the surveys.
    EXPECT_EQ(mh::fit_measures()[22].id, "upper_leg_length");
    EXPECT_GT(s.values[22], 0.25) << s.source;
    EXPECT_LT(s.values[22], 0.55) << s.source;
    if (s.source == "NHANES") {
      EXPECT_TRUE(std::isnan(s.values[2])) << "NHANES has no arm span";
      max_bmi = std::max(max_bmi, bmi(s));
    }
  }
  EXPECT_EQ(counts[0][0], 1986);  // ANSUR II women
  EXPECT_EQ(counts[0][1], 4082);  // ANSUR II men
  EXPECT_EQ(counts[1][0], 2111);  // NHANES women (development half)
  EXPECT_EQ(counts[1][1], 2041);  // NHANES men
  EXPECT_GT(max_bmi, 50.0);       // the general population reaches far beyond the soldiers
  EXPECT_THROW(mh::read_subjects("/nonexistent", kData + "/nhanes"), std::runtime_error);
}

// NHANES's upper leg length (the inguinal crease to the kneecap's upper edge, seated) mapped onto
// ANSUR II's trochanterion-to-epicondyle height: at equal stature and cube root of weight the
// mapped values are ANSUR II's (the mean difference under BMI 35 is what the mapping removes:
// 0.3 mm women, 9.1 mm men), and the difference stays small in every BMI bin under 40 (at most
// 5.2 mm, the men of BMI 35-40), because both ends of both measurements are bony; ANSUR II's
// crotch height in place of the trochanterion drifts by 14-21 mm from the thinnest bin to the
// BMI 35-40 one (the crotch sinks into a fuller thigh).
TEST(MakeHumanShape, NhanesUpperLegIsAnsurIisTrochanterToKneeAtEveryBmi) {
  REQUIRE_DATA();
  const std::vector<mh::Subject> all = mh::read_subjects(kData + "/ansur2", kData + "/nhanes");
  const auto features = [](const mh::Subject& s) {
    return Eigen::RowVector3d(1.0, s.values[0], std::cbrt(s.values[1]));
  };
  for (const char* sex : {"female", "male"}) {
    std::vector<const mh::Subject*> ansur;
    for (const mh::Subject& s : all) {
      if (s.sex == sex && s.source == "ANSUR II") ansur.push_back(&s);
    }
    Eigen::MatrixXd x(static_cast<Eigen::Index>(ansur.size()), 3);
    Eigen::VectorXd y(x.rows());
    for (Eigen::Index r = 0; r < x.rows(); ++r) {
      x.row(r) = features(*ansur[static_cast<size_t>(r)]);
      y[r] = ansur[static_cast<size_t>(r)]->values[22];
    }
    const Eigen::Vector3d fit = x.householderQr().solve(y);
    const double edges[] = {0.0, 20.0, 25.0, 30.0, 35.0, 40.0};
    double sum[5] = {0, 0, 0, 0, 0};
    int count[5] = {0, 0, 0, 0, 0};
    for (const mh::Subject& s : all) {
      if (s.sex != std::string(sex) || s.source != "NHANES") continue;
      for (int b = 0; b < 5; ++b) {
        if (bmi(s) >= edges[b] && bmi(s) < edges[b + 1]) {
          sum[b] += s.values[22] - features(s).dot(fit);
          ++count[b];
        }
      }
    }
    double under35 = 0.0;
    int n35 = 0;
    for (int b = 0; b < 5; ++b) {
      ASSERT_GT(count[b], 20) << sex << " bin " << b;
      const double mean = sum[b] / count[b];
      std::printf("%-6s BMI %2.0f-%2.0f: NHANES mapped minus ANSUR II %+.1f mm (%d people)\n", sex,
                  edges[b], edges[b + 1], mean * 1000.0, count[b]);
      EXPECT_LT(std::abs(mean), 0.0075) << sex << " BMI bin " << b;
      if (b < 4) {
        under35 += sum[b];
        n35 += count[b];
      }
    }
    EXPECT_LT(std::abs(under35 / n35), 1e-9) << sex << ": the mapping removes the mean under 35";
  }
}

// A survey file whose arm value is not a positive number (here a woman's BMXARMC set to 0) is
// refused with the file, the row and the column named, not taken into the arm's protocol maps.
TEST(MakeHumanShape, ABadArmValueInASurveyIsRefusedNamingFileRowAndColumn) {
  REQUIRE_DATA();
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("caliper-bad-survey-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy(kData + "/ansur2", dir / "ansur2", fs::copy_options::recursive);
  fs::copy(kData + "/nhanes", dir / "nhanes", fs::copy_options::recursive);
  const fs::path file = dir / "nhanes" / "NHANES_2017_2020_FEMALE_dev.csv";
  std::vector<std::string> lines;
  {
    std::ifstream in(file);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  size_t header = 0;
  while (header < lines.size() && (lines[header].empty() || lines[header][0] == '#')) ++header;
  ASSERT_LT(header + 3, lines.size());
  const auto split = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream in(line);
    std::string cell;
    while (std::getline(in, cell, ',')) out.push_back(cell);
    return out;
  };
  const std::vector<std::string> names = split(lines[header]);
  std::vector<std::string> cells = split(lines[header + 3]);
  const auto col = std::find_if(names.begin(), names.end(), [](const std::string& n) {
    return n.find("BMXARMC") != std::string::npos;
  });
  ASSERT_NE(col, names.end());
  cells[static_cast<size_t>(col - names.begin())] = "0";
  std::string row;
  for (size_t c = 0; c < cells.size(); ++c) row += (c ? "," : "") + cells[c];
  lines[header + 3] = row;
  {
    std::ofstream out(file);
    for (const std::string& l : lines) out << l << "\n";
  }
  try {
    mh::read_subjects((dir / "ansur2").string(), (dir / "nhanes").string());
    ADD_FAILURE() << "a zero arm circumference was accepted";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(file.string()), std::string::npos) << m;
    EXPECT_NE(m.find("data row 3"), std::string::npos) << m;
    EXPECT_NE(m.find("BMXARMC"), std::string::npos) << m;
    EXPECT_NE(m.find("as published"), std::string::npos) << m;
  }
  fs::remove_all(dir);
}

// Every registered body measures what its subject measured: heights and lengths to a few mm,
// girths to about a centimetre, the weight from the body's volume to well under a kilogram;
// also the NHANES subject of each sex with the highest BMI (over 50).
void check_residuals(const Registered& s) {
  // Bounds on |fitted - survey| and on the RMS over these subjects, fit_measures() order:
  // height, weight (kg), span, crotch height, biacromial, hip breadth, chest, waist (navel),
  // buttock circumference, iliac crest height, waist at the iliac crest, neck, thigh, calf,
  // ankle and wrist circumferences, knee height, hanging arm, hand length, acromial height, upper
  // arm (acromion-radiale; NHANES's mapped from its own protocol, 4.9 mm RMS, 24 mm worst), upper
  // arm girth (ANSUR II's flexed biceps mapped onto the relaxed girth; 3.8 mm RMS, 30 mm worst),
  // upper leg (trochanterion to epicondyle height; NHANES's mapped, 9.1 mm RMS, 42 mm worst).
  // Crotch and knee height share their residual with the upper leg since it is fitted too (the
  // mesh's hip keeps its height over the crotch, ANSUR II's trochanterion does not: 2.4-2.9 mm
  // RMS, 10.4 mm worst, from 0.3-1.2 and 2.9).
  // About twice the worst and twice the RMS seen over the whole surveys (docs/models.md), so that a
  // change that makes the fits worse fails. Span and biacromial breadth are met less closely
  // since the hanging arm is fitted too (ANSUR II's span is shorter than its shoulders, arms and
  // hands laid end to end; the fit shares the difference: span +4.8 mm, biacromial -4.5 mm,
  // arm -9.7 mm on the men's mean).
  const double bound[] = {0.005, 6.0,   0.027, 0.021, 0.024, 0.020, 0.125, 0.125,
                          0.050, 0.007, 0.060, 0.090, 0.100, 0.023, 0.013, 0.009,
                          0.021, 0.055, 0.015, 0.015, 0.048, 0.060, 0.085};
  const double rms_bound[] = {0.001, 1.2,    0.011,  0.006,  0.0097, 0.010, 0.019,  0.017,
                              0.008, 0.002,  0.007,  0.004,  0.024,  0.003, 0.0025, 0.002,
                              0.006, 0.0215, 0.0055, 0.0035, 0.006,  0.008, 0.012};
  ASSERT_EQ(std::size(bound), mh::fit_measures().size());
  std::vector<double> sq(mh::fit_measures().size(), 0.0);
  std::vector<int> n(mh::fit_measures().size(), 0);
  for (Eigen::Index i = 0; i < s.fit.residuals.rows(); ++i) {
    for (Eigen::Index j = 0; j < s.fit.residuals.cols(); ++j) {
      const double r = s.fit.residuals(i, j);
      if (!std::isfinite(s.subjects[i].values[j])) {
        EXPECT_TRUE(std::isnan(r));
        continue;
      }
      sq[j] += r * r;
      ++n[j];
      EXPECT_LT(std::abs(r), bound[j])
          << s.subjects[i].source << " " << s.subjects[i].sex << " subject " << i << ", "
          << mh::fit_measures()[j].id << ": " << r;
    }
  }
  for (size_t j = 0; j < sq.size(); ++j) {
    ASSERT_GT(n[j], 0) << mh::fit_measures()[j].id;
    EXPECT_LT(std::sqrt(sq[j] / n[j]), rms_bound[j]) << mh::fit_measures()[j].id;
  }
}

// The model of a sex: its template is the mean registered body, and its betas ~ N(0, I) over
// the registered population (the subjects mh::registered() accepts) (the projections of the bodies
// on the components have unit variance and no correlation); the components are orthogonal.
void check_principal_components(const Registered& s) {
  const smpl::BodyModel m = mh::shape_model(s.basis, s.tmpl, s.subjects, s.fit, "female", 16);
  // The women are registered from 16 (ANSUR II) and 4 (NHANES) measurements: the ANSUR II fits
  // span 16 directions, and the NHANES fits move within them (their prior's covariance is the
  // ANSUR II fits', up to a small floor) plus the prior's offset: 16 or 17, of which 16 are kept.
  const int kBetas = m.num_betas();
  EXPECT_EQ(kBetas, 16);
  std::vector<Eigen::VectorXd> bodies;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(m.num_vertices()));
  int left_out = 0;
  for (size_t i = 0; i < s.subjects.size(); ++i) {
    if (s.subjects[i].sex != "female") continue;
    if (!mh::registered(s.fit, i)) {  // beyond 3 tolerances: not in the population
      ++left_out;
      continue;
    }
    const smpl::Vertices v =
        s.basis.body("female", s.fit.weights.row(static_cast<Eigen::Index>(i)).transpose());
    Eigen::VectorXd f(3 * v.rows());
    for (Eigen::Index r = 0; r < v.rows(); ++r) {
      for (int c = 0; c < 3; ++c) f[3 * r + c] = v(r, c);
    }
    bodies.push_back(f);
    mean += f;
  }
  mean /= static_cast<double>(bodies.size());
  EXPECT_LE(left_out, 2) << "of " << bodies.size() + static_cast<size_t>(left_out) << " women";
  double worst = 0.0;
  for (Eigen::Index r = 0; r < m.v_template.rows(); ++r) {
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(m.v_template(r, c) - mean[3 * r + c]));
  }
  EXPECT_LT(worst, 1e-9) << "the template is not the mean registered body";
  // Left/right symmetric: the template exactly, every component to rounding (the basis is).
  ASSERT_EQ(static_cast<Eigen::Index>(m.mirror.size()), m.num_vertices());
  for (Eigen::Index r = 0; r < m.num_vertices(); ++r) {
    const auto k = static_cast<Eigen::Index>(m.mirror[static_cast<size_t>(r)]);
    ASSERT_EQ(m.v_template(r, 0), -m.v_template(k, 0)) << r;
    ASSERT_EQ(m.v_template(r, 1), m.v_template(k, 1)) << r;
    for (int b = 0; b < m.num_betas(); ++b) {
      constexpr double kRounding = 1e-12;  // metres per unit beta
      ASSERT_NEAR(m.shapedirs(3 * r, b), -m.shapedirs(3 * k, b), kRounding) << r << " " << b;
      ASSERT_NEAR(m.shapedirs(3 * r + 2, b), m.shapedirs(3 * k + 2, b), kRounding) << r << " " << b;
    }
  }
  // The iliac crest landmarks (the NHANES and WHO waist): a left/right pair at one height on the
  // torso sides, so that libcaliper measures waist_iliac_circumference on the model.
  ASSERT_TRUE(m.landmarks.count("left_iliac_crest") && m.landmarks.count("right_iliac_crest"));
  const Eigen::RowVector3d l = m.v_template.row(m.landmarks.at("left_iliac_crest").at(0));
  const Eigen::RowVector3d r = m.v_template.row(m.landmarks.at("right_iliac_crest").at(0));
  EXPECT_EQ(l.y(), r.y());  // mirror vertices of a symmetric template
  EXPECT_EQ(l.x(), -r.x());
  EXPECT_GT(l.x(), 0.1);  // the subject's left is +x, at the side of the torso
  const caliper::MeasurementMap girths =
      caliper::circumferences(m.v_template, m.faces, caliper::landmarks_for(m));
  ASSERT_TRUE(girths.count("waist_iliac_circumference"));
  EXPECT_GT(girths.at("waist_iliac_circumference"), 0.6);
  EXPECT_LT(girths.at("waist_iliac_circumference"), 1.3);
  const Eigen::MatrixXd& S = m.shapedirs;
  const Eigen::MatrixXd gram = S.transpose() * S;
  for (int a = 0; a < kBetas; ++a) {
    for (int b = 0; b < kBetas; ++b) {
      if (a != b) {
        EXPECT_LT(std::abs(gram(a, b)), 1e-9 * gram(a, a)) << a << " " << b;
      }
    }
    if (a > 0) {
      EXPECT_LE(gram(a, a), gram(a - 1, a - 1) * (1 + 1e-12)) << "components not sorted";
    }
  }
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(kBetas, kBetas);
  for (const Eigen::VectorXd& f : bodies) {
    const Eigen::VectorXd beta = gram.ldlt().solve(S.transpose() * (f - mean));
    cov += beta * beta.transpose();
  }
  cov /= static_cast<double>(bodies.size());
  for (int a = 0; a < kBetas; ++a) {
    for (int b = 0; b < kBetas; ++b) {
      EXPECT_NEAR(cov(a, b), a == b ? 1.0 : 0.0, 1e-6) << a << " " << b;
    }
  }
}

/// The flattened registered body of subject `i`.
Eigen::VectorXd registered_body(const Registered& s, size_t i) {
  const smpl::Vertices v =
      s.basis.body(s.subjects[i].sex, s.fit.weights.row(static_cast<Eigen::Index>(i)).transpose());
  Eigen::VectorXd f(3 * v.rows());
  for (Eigen::Index r = 0; r < v.rows(); ++r) {
    for (int c = 0; c < 3; ++c) f[3 * r + c] = v(r, c);
  }
  return f;
}

/// Largest |template - body| over the coordinates.
double template_offset(const smpl::BodyModel& m, const Eigen::VectorXd& body) {
  double worst = 0.0;
  for (Eigen::Index r = 0; r < m.v_template.rows(); ++r) {
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(m.v_template(r, c) - body[3 * r + c]));
  }
  return worst;
}

// The populations a model may stand for (mh::Population), on the men: survey shares weight the
// surveys' means; the general population's template is the NHANES men's mean body, and the
// NHANES men are part of it: their betas average 0 and vary at most as much as the population
// (covariance <= I), while the soldiers' average is away from 0 (the pooled model's NHANES men
// are not centred: the check that the option changes something).
void check_populations(const Registered& s) {
  Eigen::VectorXd mean_a, mean_n;
  std::vector<Eigen::VectorXd> nhanes;
  std::vector<size_t> nhanes_subject;
  int na = 0;
  for (size_t i = 0; i < s.subjects.size(); ++i) {
    // The models are made of the registered subjects only (mh::registered(): a fit that missed a
    // measurement by more than its bound is left out).
    if (s.subjects[i].sex != "male" || !mh::registered(s.fit, i)) continue;
    const Eigen::VectorXd f = registered_body(s, i);
    if (s.subjects[i].source == "NHANES") {
      nhanes.push_back(f);
      nhanes_subject.push_back(i);
      mean_n = mean_n.size() ? Eigen::VectorXd(mean_n + f) : f;
    } else {
      mean_a = mean_a.size() ? Eigen::VectorXd(mean_a + f) : f;
      ++na;
    }
  }
  mean_a /= na;
  mean_n /= static_cast<double>(nhanes.size());
  constexpr double kExact = 1e-9;  // m: the same sums in another order
  mh::Population shares;
  shares.survey_share = {{"ANSUR II", 0.25}, {"NHANES", 0.75}};
  const smpl::BodyModel shared =
      mh::shape_model(s.basis, s.tmpl, s.subjects, s.fit, "male", 16, shares);
  EXPECT_LT(template_offset(shared, 0.25 * mean_a + 0.75 * mean_n), kExact);
  shares.survey_share.erase("NHANES");
  EXPECT_THROW(mh::shape_model(s.basis, s.tmpl, s.subjects, s.fit, "male", 16, shares),
               std::invalid_argument);
  mh::Population general;
  general.general = true;
  const smpl::BodyModel g =
      mh::shape_model(s.basis, s.tmpl, s.subjects, s.fit, "male", 16, general);
  EXPECT_EQ(g.num_betas(), 16);
  EXPECT_LT(template_offset(g, mean_n), kExact);
  // The waist landmark is the vertex the fit measured the men at (the rule on MakeHuman's
  // average man), whichever population: on the general population's mean man the rule alone
  // picks another vertex (10707 instead of 10772 on the whole surveys, 22 mm less girth).
  const int fitted = mh::survey_vertices(s.basis.male_mean, s.tmpl.faces, s.tmpl.j_regressor,
                                         caliper::landmarks_for(s.tmpl), "male")
                         .iliac_crest;
  EXPECT_EQ(g.landmarks.at("left_iliac_crest").at(0), fitted);
  EXPECT_EQ(shared.landmarks.at("left_iliac_crest").at(0), fitted);
  // The neutral model of the general population (the mixture of the sexes) builds and carries
  // the waist landmarks (placed on the mean of the sexes' averages).
  const smpl::BodyModel neutral =
      mh::shape_model(s.basis, s.tmpl, s.subjects, s.fit, "neutral", 16, general);
  EXPECT_TRUE(neutral.landmarks.count("left_iliac_crest") &&
              neutral.landmarks.count("right_iliac_crest"));
  const smpl::BodyModel pooled = mh::shape_model(s.basis, s.tmpl, s.subjects, s.fit, "male", 16);
  auto betas_of = [](const smpl::BodyModel& m, const Eigen::VectorXd& f) {
    Eigen::VectorXd t(3 * m.v_template.rows());
    for (Eigen::Index r = 0; r < m.v_template.rows(); ++r) {
      for (int c = 0; c < 3; ++c) t[3 * r + c] = m.v_template(r, c);
    }
    const Eigen::MatrixXd gram = m.shapedirs.transpose() * m.shapedirs;
    return Eigen::VectorXd(gram.ldlt().solve(m.shapedirs.transpose() * (f - t)));
  };
  Eigen::VectorXd sum_g = Eigen::VectorXd::Zero(16), sum_p = Eigen::VectorXd::Zero(16);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(16, 16);
  for (const Eigen::VectorXd& f : nhanes) {
    const Eigen::VectorXd b = betas_of(g, f);
    sum_g += b;
    cov += b * b.transpose();
    sum_p += betas_of(pooled, f);
  }
  const double n = static_cast<double>(nhanes.size());
  constexpr double kCentred = 1e-6;  // betas (SD units)
  EXPECT_LT((sum_g / n).norm(), kCentred) << "the NHANES men are not the general population's mean";
  EXPECT_GT((sum_p / n).norm(), 0.1) << "the pooled model already centres the NHANES men";
  cov /= n;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  EXPECT_LT(eig.eigenvalues().maxCoeff(), 1.0 + kCentred)
      << "the NHANES men vary more than the population they belong to";
  EXPECT_GT(betas_of(g, mean_a).norm(), 0.1) << "the soldiers' mean is the population's";
  // The model file carries each survey's population in its betas (population.hpp): NHANES as
  // the general population the model's betas stand for, N(0, I) (not the NHANES men's own
  // moments as projected above: registered from four measurements they vary along a few
  // directions only, and a singular covariance is no prior for `--population nhanes`), and the
  // ANSUR II men's mean is the projected mean body.
  const std::optional<caliper::SurveyPopulation> pn = caliper::survey_population(g, "nhanes");
  const std::optional<caliper::SurveyPopulation> pa = caliper::survey_population(g, "ansur2");
  ASSERT_TRUE(pn && pa);
  EXPECT_EQ(pn->survey, "NHANES");
  EXPECT_EQ(pn->subjects, static_cast<int>(nhanes.size()));
  EXPECT_EQ(pa->subjects, na);
  constexpr double kProjection = 1e-9;  // betas: two ways of the same projection
  EXPECT_LT(pn->mean.norm(), kProjection);
  EXPECT_LT((pn->cov - Eigen::MatrixXd::Identity(16, 16)).norm(), kProjection);
  EXPECT_LT((pa->mean - betas_of(g, mean_a)).norm(), kProjection);
  // And the general population's shape curve (caliper/shape_curve.hpp): the least-squares
  // quadratic of the NHANES men's betas on their surveyed height and weight, so its residuals
  // sum to zero and are orthogonal to every feature.
  const std::optional<caliper::ShapeCurve> curve = caliper::shape_curve(g);
  ASSERT_TRUE(curve);
  EXPECT_EQ(curve->subjects, static_cast<int>(nhanes.size()));
  EXPECT_FALSE(caliper::shape_curve(pooled)) << "only the general population has a curve";
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(6, 16);
  for (size_t j = 0; j < nhanes.size(); ++j) {
    const Eigen::VectorXd& v = s.subjects[nhanes_subject[j]].values;
    // The generator's curve is on the weight itself (the heaviest men; docs/models.md).
    ASSERT_EQ(curve->weight_input, caliper::ShapeCurve::WeightInput::kKilograms);
    const Eigen::Vector2d x(v[0], v[1]);
    const Eigen::Vector2d z = (x - curve->center).cwiseQuotient(curve->scale);
    const Eigen::VectorXd residual = betas_of(g, nhanes[j]) - curve->betas(v[0], v[1]);
    normal += caliper::shape_curve_features(z[0], z[1]) * residual.transpose();
  }
  EXPECT_LT(normal.cwiseAbs().maxCoeff(), kProjection * 100) << normal;
}

/// mh::check_fit() (caliper-modelgen --check-fit): every 25th subject of each stage and sex refits
/// to the same bits as the whole fit, with this CPU's best kernels and with the baseline ones (the
/// second stage's prior from the given fit's first stage); a residual changed in its last bit is
/// found in a refitted subject and not looked at in the others.
void check_refits(const Registered& s) {
  // 100 + 100 ANSUR II subjects (every 25th: 4 + 4), 11 + 11 NHANES (the first: 1 + 1).
  const mh::FitCheckReport same = mh::check_fit(s.basis, s.tmpl, s.subjects, s.fit, 25, 2);
  EXPECT_EQ(same.checked, 10);
  EXPECT_TRUE(same.differing.empty()) << same.differing.size() << " refits differ";
  mh::FitResult changed = s.fit;
  double* stature = changed.residuals.data();  // column 0 (column-major): subjects 0, 1, ...
  ASSERT_NE(stature, nullptr);
  ASSERT_TRUE(std::isfinite(stature[0]));
  stature[0] = std::nextafter(stature[0], 1.0);  // subject 0: refitted
  stature[1] = std::nextafter(stature[1], 1.0);  // subject 1: not refitted
  const mh::FitCheckReport found = mh::check_fit(s.basis, s.tmpl, s.subjects, changed, 25, 2);
  EXPECT_EQ(found.checked, 10);
  EXPECT_EQ(found.differing, std::vector<size_t>{0});
  EXPECT_THROW(mh::check_fit(s.basis, s.tmpl, s.subjects, changed, 0), std::invalid_argument);
  // As on a CPU without AVX2 (libsmpl's baseline kernels) with a laptop's caches: the same bits
  // as the fit made with this CPU's best kernels (docs/models.md, "Same bytes on every CPU").
  const std::ptrdiff_t l1 = Eigen::l1CacheSize(), l2 = Eigen::l2CacheSize(),
                       l3 = Eigen::l3CacheSize();
  constexpr std::ptrdiff_t kKiB = 1024;
  Eigen::setCpuCacheSizes(16 * kKiB, 256 * kKiB, 1024 * kKiB);
  {
    const smpl::ScopedSimdLevel pin(smpl::SimdLevel::kBaseline);
    const mh::FitCheckReport baseline = mh::check_fit(s.basis, s.tmpl, s.subjects, s.fit, 25, 2);
    EXPECT_EQ(baseline.checked, 10);
    EXPECT_TRUE(baseline.differing.empty())
        << baseline.differing.size() << " refits with the baseline kernels differ";
  }
  Eigen::setCpuCacheSizes(l1, l2, l3);
}

// One test for both: the registration of the 242 subjects is most of the time (about 15 s of
// CPU in Release, over two minutes under AddressSanitizer; the refits of check_refits() an eighth
// of it), and each test runs in a process of its own.
TEST(MakeHumanShape, RegisteredBodiesAndTheirPrincipalComponents) {
  REQUIRE_DATA();
  const Registered& s = registered();
  check_residuals(s);
  check_principal_components(s);
  check_populations(s);
  check_refits(s);
}

// The men's hanging arm is fitted tighter than the women's (docs/models.md: 7.5 mm for both left
// the men's sampled arm 1.10 % short; 5 mm for both cost the women's chest SD), and NHANES's upper
// arm and leg, mapped from other measuring protocols (protocol_mapping.hpp), looser than ANSUR
// II's;
// every other measure has one tolerance, and registered() keeps the largest.
TEST(MakeHumanShape, TolerancesDifferOnlyWhereDocumented) {
  for (const mh::FitMeasure& m : mh::fit_measures()) {
    EXPECT_GT(m.tolerance, 0.0) << m.id;
    if (m.id == "arm_length") {
      EXPECT_EQ(m.tolerance_for("female", "ANSUR II"), 0.0075);
      EXPECT_EQ(m.tolerance_for("male", "ANSUR II"), 0.005);
    } else if (m.id == "upper_arm_length") {
      EXPECT_EQ(m.tolerance_for("male", "ANSUR II"), 0.005);
      EXPECT_EQ(m.tolerance_for("female", "NHANES"), 0.01);
      EXPECT_EQ(m.tolerance_for("male", "NHANES"), 0.01);
    } else if (m.id == "upper_leg_length") {
      EXPECT_EQ(m.tolerance_for("male", "ANSUR II"), 0.01);
      EXPECT_EQ(m.tolerance_for("female", "NHANES"), 0.015);
      EXPECT_EQ(m.tolerance_for("male", "NHANES"), 0.015);
    } else {
      EXPECT_EQ(m.tolerance_for("male", "ANSUR II"), m.tolerance_for("female", "ANSUR II")) << m.id;
      EXPECT_EQ(m.tolerance_for("male", "NHANES"), m.tolerance_for("female", "ANSUR II")) << m.id;
    }
  }
}

// The general population conditions ANSUR II's spread on the directions the NHANES subjects'
// measurements determine, not on the non-linear fit's tail (docs/models.md, Limits). A made-up
// fit: 600 subjects' weights in 20 directions driven by 6 measurements (variances 1 to 0.02 of
// the largest) plus small quadratic departures in every direction (a tail of 1e-4 and below).
TEST(MakeHumanShape, NhanesSpreadRankIsTheNumberOfMeasurementsNotTheFitsTail) {
  constexpr int kDirs = 20, kMeasures = 6, kSubjects = 600;
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(kDirs, kMeasures), b(kDirs, kMeasures * kMeasures);
  for (Eigen::Index r = 0; r < a.size(); ++r) a.data()[r] = normal(rng);
  for (Eigen::Index r = 0; r < b.size(); ++r) b.data()[r] = normal(rng);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(kDirs, kMeasures);
  Eigen::MatrixXd w(kSubjects, kDirs);
  for (int i = 0; i < kSubjects; ++i) {
    Eigen::VectorXd m(kMeasures), mm(kMeasures * kMeasures);
    for (int j = 0; j < kMeasures; ++j) m[j] = normal(rng) * std::pow(0.14, j / 5.0);
    for (int j = 0; j < kMeasures * kMeasures; ++j) mm[j] = m[j / kMeasures] * m[j % kMeasures];
    w.row(i) = (q * m + 2e-3 * b * mm).transpose();
  }
  const Eigen::MatrixXd c = w.rowwise() - w.colwise().mean();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> spread(c.transpose() * c /
                                                              (kSubjects - 1.0));
  const Eigen::VectorXd& ev = spread.eigenvalues();
  EXPECT_EQ(mh::nhanes_spread_rank(ev), kMeasures);
  // The tail is there: every direction varies by more than the numerical noise's 1e-9.
  EXPECT_GT(ev[0], 1e-9 * ev[kDirs - 1]);
  EXPECT_EQ(mh::nhanes_spread_rank(Eigen::VectorXd()), 0);
  EXPECT_EQ(mh::nhanes_spread_rank(Eigen::VectorXd::Ones(3)), 3);
}

// The open models weigh a body with the paper's formula of the sex on the skin's volume plus
// 4 L (makehuman_measures.hpp), the fit and the models alike.
TEST(MakeHumanShape, OpenModelWeightFormulaIsThePapersOnTheVolumePlusTheAllowance) {
  for (const char* sex : {"female", "male", "neutral"}) {
    const caliper::WeightFormula paper = caliper::weight_formula_for(sex);
    const caliper::WeightFormula open = mh::open_model_weight_formula(sex);
    EXPECT_EQ(open.coefficient, paper.coefficient) << sex;
    EXPECT_NEAR(caliper::weight_from_volume(0.060, open), caliper::weight_from_volume(0.064, paper),
                1e-9)
        << sex;
    EXPECT_NE(open.name.find("4 L"), std::string::npos) << open.name;
  }
}

// The cache of a fit (caliper-modelgen --fit-cache): a saved fit reads back bit for bit, a fit of
// other inputs (one survey value changed) is not taken for it, and a foreign or cut file is an
// error, not a fit. On a hand-made basis: no data needed.
TEST(MakeHumanShape, FitCacheRoundTripAndFingerprint) {
  mh::ShapeBasis basis;
  basis.names = {"a", "b"};
  basis.sex = {"female", "female"};
  basis.female_mean = smpl::Vertices::Random(4, 3);
  basis.male_mean = smpl::Vertices::Random(4, 3);
  basis.dirs = Eigen::MatrixXd::Random(12, 2);
  smpl::BodyModel tmpl;
  tmpl.faces.resize(1, 3);
  tmpl.faces << 0, 1, 2;
  std::vector<mh::Subject> subjects(3);
  for (mh::Subject& x : subjects) {
    x.sex = "female";
    x.source = "NHANES";
    x.values = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(mh::fit_measures().size()),
                                         std::nan(""));
    x.values[0] = 1.6;
  }
  mh::FitResult fit;
  fit.weights = Eigen::MatrixXd::Random(3, 2);
  fit.residuals = Eigen::MatrixXd::Random(3, static_cast<Eigen::Index>(mh::fit_measures().size()));
  fit.residuals(1, 4) = std::nan("");
  const std::uint64_t key = mh::fit_fingerprint(basis, tmpl, subjects);
  EXPECT_EQ(key, mh::fit_fingerprint(basis, tmpl, subjects));
  const std::string path =
      (std::filesystem::temp_directory_path() / ("mh_fit_cache_test_" + std::to_string(::getpid())))
          .string();
  std::remove(path.c_str());
  EXPECT_FALSE(mh::load_fit(path, key, 3, 2).has_value());  // no file yet
  mh::save_fit(path, key, fit);
  std::optional<mh::FitResult> back = mh::load_fit(path, key, 3, 2);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->weights, fit.weights);
  EXPECT_TRUE(std::isnan(back->residuals(1, 4)));
  back->residuals(1, 4) = fit.residuals(1, 4) = 0.0;
  EXPECT_EQ(back->residuals, fit.residuals);
  std::vector<mh::Subject> other = subjects;
  other[2].values[0] = 1.61;
  const std::uint64_t other_key = mh::fit_fingerprint(basis, tmpl, other);
  EXPECT_NE(other_key, key);
  EXPECT_FALSE(mh::load_fit(path, other_key, 3, 2).has_value());
  EXPECT_FALSE(mh::load_fit(path, key, 4, 2).has_value());
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 8);
  EXPECT_THROW(mh::load_fit(path, key, 3, 2), std::runtime_error);
  std::ofstream(path, std::ios::binary) << "not a fit file at all, but long enough to read";
  EXPECT_THROW(mh::load_fit(path, key, 3, 2), std::runtime_error);
  std::remove(path.c_str());
}

}  // namespace
