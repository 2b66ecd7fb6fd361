#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <optional>
#include <sstream>

#include "caliper/circumference.hpp"
#include "smpl/text.hpp"

namespace caliper::cli {

const std::vector<std::string>& report_ids() {
  static const std::vector<std::string> ids = [] {
    std::vector<std::string> v = {"height", "weight"};
    for (const auto& d : paper_measurements())
      if (d.id != "height") v.push_back(d.id);
    for (const auto& c : circumference_ids()) v.push_back(c);
    v.push_back("volume");
    return v;
  }();
  return ids;
}

std::string label_of(const std::string& id) {
  if (id == "weight") return "Weight";
  if (id == "volume") return "Volume";
  if (id == "chest_circumference") return "Chest circumference";
  if (id == "waist_circumference") return "Waist circumference";
  if (id == "hip_circumference") return "Hip circumference";
  if (id == "waist_iliac_circumference") return "Waist circumference (iliac crest)";
  if (id == "thigh_circumference") return "Thigh circumference";
  for (const auto& d : paper_measurements())
    if (d.id == id) return d.label;
  return id;
}

std::pair<std::string, double> display_unit(const std::string& id) {
  if (id == "weight") return {"kg", 1.0};
  if (id == "volume") return {"L", 1000.0};
  return {"cm", 100.0};
}

std::string format_number(double v, int decimals) {
  if (std::isnan(v)) return "nan";  // never "-nan"
  return smpl::format_fixed_or_short(v, std::clamp(decimals, 0, 17));
}

std::string format_value(const std::string& id, double si_value, int decimals) {
  const auto [unit, factor] = display_unit(id);
  return format_number(si_value * factor, decimals) + " " + unit;
}

std::string format_difference(const std::string& id, double si_difference, int decimals) {
  const auto [unit, factor] = display_unit(id);
  double v = si_difference * factor;
  if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0.0;  // no "-0.0"
  const std::string n = format_number(v, decimals);
  return (v >= 0.0 || std::isnan(v) ? "+" : "") + n + " " + unit;
}

bool is_imperial_text(const std::string& text) {
  const std::string t = smpl::to_lower(text);
  for (const char* u : {"in", "ft", "feet", "foot", "inch", "lb", "'", "\""}) {
    if (t.find(u) != std::string::npos) return true;
  }
  return false;
}

namespace {
/// Imperial display of a value: inches for lengths, pounds for weight; nothing for the rest.
std::optional<std::pair<std::string, double>> imperial_unit(const std::string& id) {
  const auto [unit, factor] = display_unit(id);
  (void)factor;
  if (unit == "cm") return std::make_pair(std::string("in"), 1.0 / 0.0254);
  if (unit == "kg") return std::make_pair(std::string("lb"), 1.0 / 0.45359237);
  return std::nullopt;
}
}  // namespace

std::string measurement_table(const MeasurementMap& input, const MeasurementMap& achieved,
                              bool imperial) {
  std::ostringstream s;
  const bool with_input = !input.empty();
  s << std::left << std::setw(38) << "measurement";
  if (with_input) s << std::right << std::setw(imperial ? 22 : 12) << "input";
  s << std::right << std::setw(imperial ? 22 : 12) << "achieved";
  if (with_input) s << std::setw(12) << "difference";
  s << "\n";
  const int width = imperial ? 22 : 12;
  auto value = [&](const std::string& id, double si) {
    std::string v = format_value(id, si);
    if (const auto u = imperial ? imperial_unit(id) : std::nullopt) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.1f %s", si * u->second, u->first.c_str());
      v = std::string(buf) + " (" + v + ")";
    }
    return v;
  };
  auto difference = [&](const std::string& id, double si) {
    if (const auto u = imperial ? imperial_unit(id) : std::nullopt) {
      char buf[64];
      double d = si * u->second;
      if (std::abs(d) < 0.05) d = 0.0;
      std::snprintf(buf, sizeof buf, "%+.1f %s", d, u->first.c_str());
      return std::string(buf);
    }
    return format_difference(id, si);
  };
  auto row = [&](const std::string& id) {
    auto a = achieved.find(id);
    auto in = input.find(id);
    if (a == achieved.end() && in == input.end()) return;
    s << std::left << std::setw(38) << label_of(id);
    if (with_input)
      s << std::right << std::setw(width) << (in != input.end() ? value(id, in->second) : "-");
    s << std::right << std::setw(width) << (a != achieved.end() ? value(id, a->second) : "-");
    if (with_input && in != input.end() && a != achieved.end())
      s << std::setw(12) << difference(id, a->second - in->second);
    s << "\n";
  };
  for (const auto& id : report_ids()) row(id);
  for (const auto& [id, v] : achieved) {
    (void)v;
    bool listed = false;
    for (const auto& r : report_ids()) listed = listed || r == id;
    if (!listed) row(id);
  }
  return s.str();
}

std::string format_betas(const Eigen::VectorXd& betas) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(3);
  for (Eigen::Index i = 0; i < betas.size(); ++i) s << (i ? " " : "") << betas[i];
  return s.str();
}

namespace {
std::string index_list(const std::vector<int>& v) {
  // "none", or the count and the components by name: "1 (b0)", "2 (b1, b3)".
  if (v.empty()) return "none";
  std::string s = std::to_string(v.size()) + " (";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", b" : "b") + std::to_string(v[i]);
  return s + ")";
}
}  // namespace

std::string format_plausibility(const Plausibility& p) {
  std::ostringstream s;
  s << "Mahalanobis distance " << format_number(p.mahalanobis, 2) << " over " << p.dof
    << " components, chi-square p = " << std::fixed << std::setprecision(3) << p.p_value
    << (p.plausible ? " (plausible body shape)" : " (unusual body shape: outside the usual range)")
    << "\n"
    << "components beyond 2 SD: " << index_list(p.beyond_2sd)
    << "; beyond 3 SD: " << index_list(p.beyond_3sd) << "\n"
    << "(the distance counts the shape components b0, b1, ... in standard deviations (SD) of "
       "the population; p is the share of people at least this far from the average body; "
       "plausible: p >= 0.001 and no component beyond 3 SD)\n";
  return s.str();
}

Json measurements_json(const MeasurementMap& values) {
  Json j = Json::object();
  for (const auto& id : report_ids()) {
    auto it = values.find(id);
    if (it != values.end()) j.set(id, it->second);
  }
  for (const auto& [id, v] : values)
    if (!j.contains(id)) j.set(id, v);
  return j;
}

Json plausibility_json(const Plausibility& p) {
  Json b2 = Json::array(), b3 = Json::array();
  for (int i : p.beyond_2sd) b2.push_back(i);
  for (int i : p.beyond_3sd) b3.push_back(i);
  return Json::object({{"mahalanobis", p.mahalanobis},
                       {"dof", p.dof},
                       {"chi_square_cdf", p.cdf},
                       {"p_value", p.p_value},
                       {"beyond_2sd", b2},
                       {"beyond_3sd", b3},
                       {"plausible", p.plausible}});
}

Json betas_json(const Eigen::VectorXd& betas) {
  return Json(std::vector<double>(betas.data(), betas.data() + betas.size()));
}

}  // namespace caliper::cli
