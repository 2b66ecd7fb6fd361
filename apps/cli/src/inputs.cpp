#include "inputs.hpp"
#include "caliper/inputs.hpp"
#include "smpl/text.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace caliper::cli {

std::optional<std::pair<std::string, double>> measurement_column(const std::string& header_in) {
  const std::string header = smpl::to_lower(header_in);
  const size_t us = header.rfind('_');
  if (us == std::string::npos) return std::nullopt;
  std::string id = header.substr(0, us);
  const std::string unit = header.substr(us + 1);
  const auto scale = caliper::unit_scale(unit);
  if (!scale) return std::nullopt;
  static const std::map<std::string, std::string> kAliases = {
      {"stature", "height"},           {"arm_span", "arm_span_fingertips"},
      {"span", "arm_span_fingertips"}, {"inseam", "inseam_height"},
      {"hips_width", "hip_width"},     {"mass", "weight"},
  };
  if (auto it = kAliases.find(id); it != kAliases.end()) id = it->second;
  static const char* kIds[] = {"height",
                               "weight",
                               "nipple_height",
                               "navel_height",
                               "inseam_height",
                               "shoulder_width",
                               "chest_width",
                               "waist_width",
                               "torso_depth",
                               "hip_width",
                               "arm_span_fingertips",
                               "arm_span_wrists",
                               "arm_length",
                               "arm_length_hanging",
                               "forearm_length",
                               "chest_circumference",
                               "waist_circumference",
                               "hip_circumference",
                               "thigh_circumference"};
  bool known = false;
  for (const char* k : kIds) known = known || id == k;
  if (!known) return std::nullopt;
  const bool mass_unit = unit == "kg" || unit == "g" || unit == "lb" || unit == "lbs";
  if ((id == "weight") != mass_unit) return std::nullopt;
  return std::make_pair(id, *scale);
}

std::string normalise_sex(const std::string& value) {
  std::string v;
  for (char c : value)
    if (!std::isspace(static_cast<unsigned char>(c))) v += c;
  v = smpl::to_lower(v);
  if (v.empty()) return "";
  if (v == "f" || v == "female" || v == "woman" || v == "w") return "female";
  if (v == "m" || v == "male" || v == "man") return "male";
  if (v == "n" || v == "neutral") return "neutral";
  throw UsageError("sex '" + value + "': expected female, male or neutral");
}

namespace {

bool parse_cell(const std::string& cell, double& out) {
  const char* b = cell.c_str();
  while (*b == ' ' || *b == '\t') ++b;
  char* e = nullptr;
  out = std::strtod(b, &e);
  if (e == b) return false;
  while (*e == ' ' || *e == '\t') ++e;
  return *e == '\0';
}

}  // namespace

std::vector<Person> read_people_csv(const std::string& path) {
  const CsvTable t = read_csv(path, CsvOptions{/*per_row_errors=*/true});
  std::vector<std::pair<int, std::pair<std::string, double>>> cols;
  for (size_t c = 0; c < t.header.size(); ++c) {
    if (auto m = measurement_column(t.header[c])) cols.emplace_back(static_cast<int>(c), *m);
  }
  const auto has_column = [&cols](const char* id) {
    return std::any_of(cols.begin(), cols.end(),
                       [id](const auto& c) { return c.second.first == id; });
  };
  if (has_column("arm_length") && has_column("arm_length_hanging")) {
    throw RuntimeError(path +
                       ": both an arm_length column (arm out sideways) and an arm_length_hanging "
                       "column (arm hanging); keep one of them");
  }
  if (cols.empty()) {
    throw RuntimeError(path +
                       ": no measurement column in the header; name columns by measurement id "
                       "and unit, e.g. height_cm,weight_kg,arm_span_fingertips_cm");
  }
  const int id_col = t.column("id") >= 0 ? t.column("id") : t.column("subjectid");
  const int sex_col = t.column("sex") >= 0 ? t.column("sex") : t.column("gender");
  std::vector<Person> people;
  people.reserve(t.rows.size());
  for (size_t r = 0; r < t.rows.size(); ++r) {
    Person p;
    p.line = t.line_numbers[r];
    p.id = id_col >= 0 ? t.rows[r][static_cast<size_t>(id_col)] : std::to_string(r + 1);
    p.error = t.row_errors[r];
    try {
      if (sex_col >= 0) p.sex = normalise_sex(t.rows[r][static_cast<size_t>(sex_col)]);
    } catch (const UsageError& e) {
      if (p.error.empty()) p.error = e.what();
    }
    for (const auto& [c, m] : cols) {
      const std::string& cell = t.rows[r][static_cast<size_t>(c)];
      if (cell.find_first_not_of(" \t") == std::string::npos) continue;  // empty: not given
      double v = 0.0;
      if (!parse_cell(cell, v)) {
        if (p.error.empty())
          p.error = t.header[static_cast<size_t>(c)] + " '" + cell + "' is not a number";
        continue;
      }
      p.inputs[m.first] = v * m.second;
    }
    // A tape on the hanging arm: the model's arm length is mapped from it (model_inputs()).
    if (const auto h = p.inputs.find("arm_length_hanging"); h != p.inputs.end()) {
      p.inputs["arm_length"] = h->second;
      p.inputs.erase(h);
      p.hanging_arm = true;
    }
    people.push_back(std::move(p));
  }
  return people;
}

std::vector<Person> read_ansur_csv(const std::string& path) {
  const CsvTable t = read_csv(path, CsvOptions{/*per_row_errors=*/true});
  auto need = [&](const char* name) {
    const int c = t.column(name);
    if (c < 0) {
      throw RuntimeError(path + ": column '" + name +
                         "' is missing; is this an ANSUR II public CSV file?");
    }
    return static_cast<size_t>(c);
  };
  const int id_col = t.column("subjectid");
  const size_t stature = need("stature"), weight = need("weightkg"), span = need("span"),
               crotch = need("crotchheight"), hip = need("hipbreadth"),
               acr = need("acromionradialelength"), rad = need("radialestylionlength");
  const int gender_col = t.column("gender");
  const char* extras[] = {"chestcircumference", "waistcircumference", "buttockcircumference",
                          "thighcircumference", "biacromialbreadth"};
  std::vector<Person> people;
  people.reserve(t.rows.size());
  for (size_t r = 0; r < t.rows.size(); ++r) {
    const auto& row = t.rows[r];
    Person p;
    p.line = t.line_numbers[r];
    p.id = id_col >= 0 ? row[static_cast<size_t>(id_col)] : std::to_string(r + 1);
    p.error = t.row_errors[r];
    if (gender_col >= 0) {
      const std::string g = row[static_cast<size_t>(gender_col)];
      p.sex = (g == "Male" || g == "male" || g == "M")       ? "male"
              : (g == "Female" || g == "female" || g == "F") ? "female"
                                                             : "";
    }
    auto num = [&](size_t c, const char* name, double& v) {
      if (!parse_cell(row[c], v) && p.error.empty())
        p.error = std::string(name) + " '" + row[c] + "' is not a number";
    };
    double s = 0, w = 0, sp = 0, cr = 0, hb = 0, a = 0, b = 0;
    num(stature, "stature", s);
    num(weight, "weightkg", w);
    num(span, "span", sp);
    num(crotch, "crotchheight", cr);
    num(hip, "hipbreadth", hb);
    num(acr, "acromionradialelength", a);
    num(rad, "radialestylionlength", b);
    p.inputs = {{"height", s / 1000.0},
                {"weight", w / 10.0},
                {"arm_span_fingertips", sp / 1000.0},
                {"inseam_height", cr / 1000.0},
                {"hip_width", hb / 1000.0},
                {"arm_length", (a + b) / 1000.0}};
    p.hanging_arm = true;
    for (const char* e : extras) {
      const int c = t.column(e);
      double v = 0.0;
      if (c >= 0 && parse_cell(row[static_cast<size_t>(c)], v)) p.extra[e] = v / 1000.0;
    }
    people.push_back(std::move(p));
  }
  return people;
}

MeasurementValues model_inputs(const Person& p, const LinearMap* arm_map) {
  MeasurementValues in = p.inputs;
  const auto arm = in.find("arm_length");
  if (!p.hanging_arm || arm == in.end()) return in;
  if (arm_map == nullptr) {
    throw std::logic_error("model_inputs: person " + p.id +
                           "'s arm length was taken hanging and needs the model's arm map");
  }
  arm->second = arm_map->apply(arm->second);
  return in;
}

}  // namespace caliper::cli
