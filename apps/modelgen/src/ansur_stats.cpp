/// \file ansur_stats.cpp
/// ANSUR II statistics: survey parsing and the committed table.
#include "ansur_stats.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "caliper/csv.hpp"
#include "smpl/atomic_file.hpp"
#include "smpl/text.hpp"

namespace modelgen {

const std::array<const char*, kNumDims>& dim_columns() {
  static const std::array<const char*, kNumDims> kColumns = {
      "stature",
      "crotchheight",
      "span",
      "acromionradialelength",
      "radialestylionlength",
      "biacromialbreadth",
      "chestbreadth",
      "chestdepth",
      "waistbreadth",
      "waistdepth",
      "hipbreadth",
      "buttockdepth",
      "chestcircumference",
      "waistcircumference",
      "buttockcircumference",
      "thighcircumference",
      "lowerthighcircumference",
      "calfcircumference",
      "anklecircumference",
      "bicepscircumferenceflexed",
      "forearmcircumferenceflexed",
      "wristcircumference",
      "neckcircumference",
      "headcircumference",
      "headbreadth",
      "headlength",
      "tragiontopofhead",
      "handlength",
      "handbreadth",
      "footlength",
      "footbreadthhorizontal",
      "chestheight",
      "waistheightomphalion",
      "acromialheight",
      "axillaheight",
      "cervicaleheight",
      "buttockheight",
      "kneeheightmidpatella",
      "lateralmalleolusheight",
      "weightkg",
  };
  return kColumns;
}

Eigen::MatrixXd SexStats::covariance() const {
  return sd.asDiagonal() * correlation * sd.asDiagonal();
}

Eigen::MatrixXd read_survey_columns(const std::string& csv_path,
                                    const std::vector<std::string>& columns) {
  const caliper::CsvTable t =
      caliper::read_csv(csv_path, caliper::CsvOptions{/*per_row_errors=*/false,
                                                      /*comment_lines=*/true});
  std::vector<int> col(columns.size(), -1);
  for (size_t d = 0; d < columns.size(); ++d) {
    col[d] = t.column(columns[d]);
    if (col[d] < 0) {
      throw std::runtime_error("survey file '" + csv_path + "' has no column '" + columns[d] + "'");
    }
  }
  Eigen::MatrixXd out(static_cast<Eigen::Index>(t.rows.size()),
                      static_cast<Eigen::Index>(columns.size()));
  for (size_t r = 0; r < t.rows.size(); ++r) {
    for (size_t d = 0; d < columns.size(); ++d) {
      const std::string& cell = t.rows[r][static_cast<size_t>(col[d])];
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (end == cell.c_str() || !std::isfinite(v)) {
        throw std::runtime_error("survey file '" + csv_path + "' line " +
                                 std::to_string(t.line_numbers[r]) + ": column '" + columns[d] +
                                 "' is not a number: '" + cell + "'");
      }
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(d)) = v;
    }
  }
  return out;
}

SexStats stats_from_survey_file(const std::string& csv_path, const std::string& sex) {
  const std::vector<std::string> names(dim_columns().begin(), dim_columns().end());
  const Eigen::MatrixXd table = read_survey_columns(csv_path, names);
  std::vector<Eigen::VectorXd> rows;
  for (Eigen::Index i = 0; i < table.rows(); ++i) {
    Eigen::VectorXd r = table.row(i).transpose();
    for (int d = 0; d < kNumDims; ++d) {
      r[d] = d == kWeight ? r[d] / 10.0 : r[d] / 1000.0;  // 0.1 kg -> kg, mm -> m
    }
    rows.push_back(r);
  }
  if (rows.size() < 10) {
    throw std::runtime_error("survey file '" + csv_path + "': too few rows");
  }
  SexStats s;
  s.sex = sex;
  s.count = static_cast<int>(rows.size());
  s.mean = Eigen::VectorXd::Zero(kNumDims);
  for (const auto& r : rows) {
    s.mean += r;
  }
  s.mean /= static_cast<double>(rows.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(kNumDims, kNumDims);
  for (const auto& r : rows) {
    const Eigen::VectorXd c = r - s.mean;
    cov += c * c.transpose();
  }
  cov /= static_cast<double>(rows.size() - 1);
  s.sd = cov.diagonal().cwiseSqrt();
  s.correlation = s.sd.cwiseInverse().asDiagonal() * cov * s.sd.cwiseInverse().asDiagonal();
  return s;
}

SurveyStats stats_from_survey(const std::string& dir) {
  SurveyStats s;
  s.female = stats_from_survey_file(dir + "/ANSUR_II_FEMALE_Public.csv", "female");
  s.male = stats_from_survey_file(dir + "/ANSUR_II_MALE_Public.csv", "male");
  return s;
}

void write_stats_table(const SurveyStats& stats, const std::string& path) {
  std::ostringstream out;  // written atomically at the end (smpl/atomic_file.hpp)
  out << "# ANSUR II (2012) statistics used by caliper-modelgen; metres, weight in kg.\n"
         "# Recompute: caliper-modelgen --stats-from <ansur2 dir> --stats-out <this file>\n";
  out << "sex,dim,count,mean,sd";
  for (int d = 0; d < kNumDims; ++d) {
    out << ",r_" << dim_columns()[d];
  }
  out << "\n";
  char buf[64];
  for (const SexStats* s : {&stats.female, &stats.male}) {
    for (int d = 0; d < kNumDims; ++d) {
      out << s->sex << "," << dim_columns()[d] << "," << s->count;
      std::snprintf(buf, sizeof buf, ",%.9g,%.9g", s->mean[d], s->sd[d]);
      out << buf;
      for (int e = 0; e < kNumDims; ++e) {
        std::snprintf(buf, sizeof buf, ",%.6f", s->correlation(d, e));
        out << buf;
      }
      out << "\n";
    }
  }
  smpl::write_file_atomic(path, out.str());
}

SurveyStats read_stats_table(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::runtime_error("cannot open statistics table '" + path +
                             "' (pass --stats <file>, e.g. assets/models/ansur_stats.csv)");
  }
  SurveyStats s;
  for (SexStats* x : {&s.female, &s.male}) {
    x->mean = Eigen::VectorXd::Constant(kNumDims, std::nan(""));
    x->sd = Eigen::VectorXd::Constant(kNumDims, std::nan(""));
    x->correlation = Eigen::MatrixXd::Constant(kNumDims, kNumDims, std::nan(""));
  }
  s.female.sex = "female";
  s.male.sex = "male";
  const caliper::CsvTable t = caliper::read_csv(
      path, caliper::CsvOptions{/*per_row_errors=*/false, /*comment_lines=*/true});
  for (size_t r = 0; r < t.rows.size(); ++r) {
    const std::vector<std::string>& f = t.rows[r];
    const std::string where =
        "statistics table '" + path + "' line " + std::to_string(t.line_numbers[r]);
    if (f.size() != 5 + static_cast<std::size_t>(kNumDims)) {
      throw std::runtime_error(where + ": expected " + std::to_string(5 + kNumDims) +
                               " fields, found " + std::to_string(f.size()));
    }
    SexStats* x = f[0] == "female" ? &s.female : f[0] == "male" ? &s.male : nullptr;
    if (x == nullptr) {
      throw std::runtime_error(where + ": unknown sex '" + f[0] + "'");
    }
    int d = -1;
    for (int k = 0; k < kNumDims; ++k) {
      if (f[1] == dim_columns()[k]) {
        d = k;
      }
    }
    if (d < 0) {
      throw std::runtime_error(where + ": unknown dimension '" + f[1] + "'");
    }
    x->count = std::atoi(f[2].c_str());
    x->mean[d] = std::strtod(f[3].c_str(), nullptr);
    x->sd[d] = std::strtod(f[4].c_str(), nullptr);
    for (int e = 0; e < kNumDims; ++e) {
      x->correlation(d, e) = std::strtod(f[5 + e].c_str(), nullptr);
    }
  }
  for (const SexStats* x : {&s.female, &s.male}) {
    if (!x->mean.allFinite() || !x->sd.allFinite() || !x->correlation.allFinite()) {
      throw std::runtime_error("statistics table '" + path + "' misses rows for " + x->sex);
    }
  }
  return s;
}

}  // namespace modelgen
