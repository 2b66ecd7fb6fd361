/// \file ansur_stats.cpp
/// ANSUR II statistics: survey parsing and the committed table.
#include "ansur_stats.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

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

namespace {

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r' && c != '\n') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

}  // namespace

Eigen::MatrixXd read_survey_columns(const std::string& csv_path,
                                    const std::vector<std::string>& columns) {
  std::ifstream in(csv_path, std::ios::binary);
  if (!in) {
    throw std::runtime_error("cannot open survey file '" + csv_path + "'");
  }
  std::string line;
  int line_no = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] != '#') {
      have_header = true;
      break;
    }
  }
  if (!have_header) {
    throw std::runtime_error("empty survey file '" + csv_path + "'");
  }
  std::vector<std::string> header = split_csv_line(line);
  for (std::string& h : header) {
    if (h.size() >= 2 && h.front() == '"' && h.back() == '"') {
      h = h.substr(1, h.size() - 2);
    }
  }
  std::vector<int> col(columns.size(), -1);
  for (size_t d = 0; d < columns.size(); ++d) {
    for (int h = 0; h < static_cast<int>(header.size()); ++h) {
      if (smpl::to_lower(header[h]) == smpl::to_lower(columns[d])) {
        col[d] = h;
      }
    }
    if (col[d] < 0) {
      throw std::runtime_error("survey file '" + csv_path + "' has no column '" + columns[d] + "'");
    }
  }
  std::vector<Eigen::VectorXd> rows;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") {
      continue;
    }
    const std::vector<std::string> f = split_csv_line(line);
    Eigen::VectorXd r(static_cast<Eigen::Index>(columns.size()));
    for (size_t d = 0; d < columns.size(); ++d) {
      if (col[d] >= static_cast<int>(f.size())) {
        throw std::runtime_error("survey file '" + csv_path + "' line " + std::to_string(line_no) +
                                 ": too few fields");
      }
      char* end = nullptr;
      const double v = std::strtod(f[col[d]].c_str(), &end);
      if (end == f[col[d]].c_str() || !std::isfinite(v)) {
        throw std::runtime_error("survey file '" + csv_path + "' line " + std::to_string(line_no) +
                                 ": column '" + columns[d] + "' is not a number: '" + f[col[d]] +
                                 "'");
      }
      r[static_cast<Eigen::Index>(d)] = v;
    }
    rows.push_back(r);
  }
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()),
                      static_cast<Eigen::Index>(columns.size()));
  for (size_t i = 0; i < rows.size(); ++i) {
    out.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
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
  std::string line;
  int line_no = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') {
      continue;
    }
    if (!header_seen) {
      header_seen = true;
      continue;
    }
    const std::vector<std::string> f = split_csv_line(line);
    const std::string where = "statistics table '" + path + "' line " + std::to_string(line_no);
    if (f.size() != static_cast<std::size_t>(5 + kNumDims)) {
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
