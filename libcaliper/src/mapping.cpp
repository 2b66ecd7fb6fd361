// Learned real-to-virtual mappings: Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.3.
#include "caliper/mapping.hpp"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "caliper/csv.hpp"
#include "caliper/errors.hpp"
#include "caliper/training.hpp"

namespace caliper {

namespace {

/// The seed of hanging_arm_map()'s bodies.
constexpr std::uint64_t kHangingArmSeed = 20261130;

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

struct Fit {
  double a, b;
};

/// Least squares y = a x + b; `ok` false if the x are all equal.
bool fit_line(const std::vector<double>& x, const std::vector<double>& y, std::size_t skip,
              Fit& out) {
  double n = 0, sx = 0, sy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i == skip) continue;
    n += 1;
    sx += x[i];
    sy += y[i];
  }
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i == skip) continue;
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 1e-18 * (1.0 + mx * mx) * n)) return false;
  out.a = sxy / sxx;
  out.b = my - out.a * mx;
  return true;
}

}  // namespace

std::vector<PairedValue> read_paired_csv(const std::string& path) {
  CsvTable t;
  try {
    t = read_csv(path, CsvOptions{/*per_row_errors=*/false, /*comment_lines=*/true});
  } catch (const CsvError& e) {
    throw InvalidInputError(std::string("mapping CSV: ") + e.what());
  }
  const int col_m = t.column("measurement"), col_r = t.column("real"), col_v = t.column("virtual");
  if (col_m < 0 || col_r < 0 || col_v < 0) {
    std::string found;
    for (const auto& h : t.header) found += (found.empty() ? "" : ",") + h;
    throw InvalidInputError(path +
                            ": the header must name the columns measurement, real and virtual "
                            "(found: " +
                            found + ")");
  }
  std::vector<PairedValue> out;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const std::string where = path + ":" + std::to_string(t.line_numbers[r]);
    const auto cell = [&](int col) { return trim(t.rows[r][static_cast<std::size_t>(col)]); };
    const auto number = [&](int col, const char* what) {
      const std::string c = cell(col);
      char* end = nullptr;
      const double v = std::strtod(c.c_str(), &end);
      if (c.empty() || end != c.c_str() + c.size() || !std::isfinite(v)) {
        throw InvalidInputError(where + ": the " + what + " value '" + c +
                                "' is not a finite number");
      }
      return v;
    };
    PairedValue p;
    p.measurement = cell(col_m);
    p.real = number(col_r, "real");
    p.virtual_value = number(col_v, "virtual");
    if (p.measurement.empty()) throw InvalidInputError(where + ": empty measurement id");
    out.push_back(p);
  }
  if (out.empty()) throw InvalidInputError("mapping CSV '" + path + "' has no data rows");
  return out;
}

MeasurementMapping MeasurementMapping::fit(const std::vector<PairedValue>& pairs) {
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> by_id;
  for (const auto& p : pairs) {
    if (!std::isfinite(p.real) || !std::isfinite(p.virtual_value)) {
      throw InvalidInputError("mapping pair for '" + p.measurement + "' is not a number");
    }
    by_id[p.measurement].first.push_back(p.real);
    by_id[p.measurement].second.push_back(p.virtual_value);
  }
  MeasurementMapping m;
  for (const auto& [id, xy] : by_id) {
    const auto& x = xy.first;
    const auto& y = xy.second;
    if (x.size() < 3) {
      throw InvalidInputError("mapping for '" + id +
                              "' needs at least 3 pairs (leave-one-out), "
                              "got " +
                              std::to_string(x.size()));
    }
    LinearMap lm;
    Fit all{};
    if (!fit_line(x, y, x.size(), all)) {
      throw InvalidInputError("mapping for '" + id +
                              "': all real values are equal, so no line "
                              "can be fitted");
    }
    lm.a = all.a;
    lm.b = all.b;
    lm.count = static_cast<int>(x.size());
    double ss = 0, idsum = 0, loo_sum = 0, loo_max = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double r = lm.apply(x[i]) - y[i];
      ss += r * r;
      idsum += std::abs(x[i] - y[i]);
      Fit loo{};
      if (!fit_line(x, y, i, loo)) {
        throw InvalidInputError("mapping for '" + id + "': leaving out pair " +
                                std::to_string(i + 1) +
                                " leaves all real values equal; "
                                "give more distinct pairs");
      }
      const double e = std::abs(loo.a * x[i] + loo.b - y[i]);
      loo_sum += e;
      loo_max = std::max(loo_max, e);
    }
    const auto n = static_cast<double>(x.size());
    lm.fit_rms = std::sqrt(ss / n);
    lm.identity_mae = idsum / n;
    lm.loo_mae = loo_sum / n;
    lm.loo_max = loo_max;
    m.maps_[id] = lm;
  }
  return m;
}

double MeasurementMapping::apply(const std::string& id, double real) const {
  const auto it = maps_.find(id);
  return it == maps_.end() ? real : it->second.apply(real);
}

MeasurementMap MeasurementMapping::apply(const MeasurementMap& real) const {
  MeasurementMap out;
  for (const auto& [id, v] : real) out[id] = apply(id, v);
  return out;
}

Json MeasurementMapping::to_json() const {
  Json j = format_header("caliper-mapping");
  Json maps = Json::object();
  for (const auto& [id, m] : maps_) {
    maps.set(id, Json::object({{"a", m.a},
                               {"b", m.b},
                               {"count", m.count},
                               {"fit_rms", m.fit_rms},
                               {"loo_mae", m.loo_mae},
                               {"loo_max", m.loo_max},
                               {"identity_mae", m.identity_mae}}));
  }
  j.set("maps", maps);
  return j;
}

MeasurementMapping MeasurementMapping::from_json(const Json& j) {
  check_format_version<InvalidInputError>(j, "caliper-mapping", "mapping file");
  MeasurementMapping m;
  for (const auto& [id, e] : j.at("maps").as_object()) {
    LinearMap lm;
    lm.a = e.at("a").as_number();
    lm.b = e.at("b").as_number();
    if (const Json* c = e.find("count")) lm.count = c->as_int();
    if (const Json* c = e.find("fit_rms")) lm.fit_rms = c->as_number();
    if (const Json* c = e.find("loo_mae")) lm.loo_mae = c->as_number();
    if (const Json* c = e.find("loo_max")) lm.loo_max = c->as_number();
    if (const Json* c = e.find("identity_mae")) lm.identity_mae = c->as_number();
    m.maps_[id] = lm;
  }
  return m;
}

void MeasurementMapping::save(const std::string& path) const {
  write_json_file(path, to_json());
}

MeasurementMapping MeasurementMapping::load(const std::string& path) {
  return read_json_file_as<InvalidInputError, CaliperError>(path, from_json);
}

LinearMap hanging_arm_map(const smpl::BodyModel& model, int bodies) {
  if (bodies < 3) {
    throw InvalidInputError("hanging_arm_map: at least 3 bodies are needed, got " +
                            std::to_string(bodies));
  }
  const LandmarkTable landmarks = landmarks_for(model);
  const MeasurementDef& arm = measurement_def("arm_length");
  const Eigen::MatrixXd betas = gaussian_betas(bodies, model.num_betas(), kHangingArmSeed);
  std::vector<PairedValue> pairs;
  pairs.reserve(static_cast<std::size_t>(bodies));
  for (int i = 0; i < bodies; ++i) {
    const smpl::Vertices v = shaped_vertices(model, betas.row(i).transpose());
    pairs.push_back(
        {"arm_length", hanging_arm_length(model, v, landmarks), measure(v, landmarks, arm)});
  }
  return MeasurementMapping::fit(pairs).maps().at("arm_length");
}

}  // namespace caliper
