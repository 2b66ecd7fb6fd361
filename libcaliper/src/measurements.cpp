// Body measurements as data: Pujades et al., The Virtual Caliper, TVCG 2019, Sec. 3.1.2.
// Sections: definitions and landmark tables; derived torso landmarks; measuring; validation;
// the hanging arm.
#include "caliper/measurements.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "caliper/circumference.hpp"
#include "caliper/errors.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "smpl/constants.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/text.hpp"

namespace caliper {

// ---------------------------------------------------------------------------------------------
// Definitions and landmark tables

const std::vector<MeasurementDef>& paper_measurements() {
  static const std::vector<MeasurementDef> defs = {
      {"height", MeasurementKind::Height, "head_top", "", "Overall height"},
      {"nipple_height", MeasurementKind::Height, "left_nipple", "", "Nipple height"},
      {"navel_height", MeasurementKind::Height, "navel", "", "Navel height"},
      {"inseam_height", MeasurementKind::Height, "crotch", "", "Inseam height"},
      {"shoulder_width", MeasurementKind::Distance, "left_shoulder", "right_shoulder",
       "Shoulder width"},
      {"chest_width", MeasurementKind::Distance, "left_chest", "right_chest", "Chest width"},
      {"waist_width", MeasurementKind::Distance, "left_waist", "right_waist", "Waist width"},
      {"torso_depth", MeasurementKind::Distance, "navel", "torso_back", "Torso depth"},
      {"hip_width", MeasurementKind::Distance, "left_hip", "right_hip", "Hip width"},
      {"arm_span_fingertips", MeasurementKind::Distance, "left_fingertip", "right_fingertip",
       "Arm span (fingertips)"},
      {"arm_span_wrists", MeasurementKind::Distance, "left_wrist", "right_wrist",
       "Arm span (wrists)"},
      {"arm_length", MeasurementKind::Distance, "left_shoulder", "left_wrist",
       "Arm length (shoulder to wrist)"},
      {"forearm_length", MeasurementKind::Distance, "left_elbow", "left_wrist",
       "Forearm length (inner elbow to wrist)"},
  };
  return defs;
}

const MeasurementDef& measurement_def(const std::string& id) {
  for (const auto& d : paper_measurements()) {
    if (d.id == id) return d;
  }
  std::string known;
  for (const auto& d : paper_measurements()) known += (known.empty() ? "" : ", ") + d.id;
  throw InvalidInputError("unknown measurement id '" + id + "'; known ids: " + known);
}

const std::vector<std::string>& landmark_names() {
  static const std::vector<std::string> names = {
      "head_top",      "left_fingertip", "right_fingertip", "left_wrist",   "right_wrist",
      "left_shoulder", "right_shoulder", "left_elbow",      "right_elbow",  "crotch",
      "left_hip",      "right_hip",      "left_nipple",     "right_nipple", "navel",
      "left_waist",    "right_waist",    "left_chest",      "right_chest",  "torso_back",
      "left_heel",     "right_heel",     "left_sole",       "right_sole"};
  return names;
}

const LandmarkTable& smpl_landmarks() {
  // 0-based ids on the SMPL topology; see docs/measurements.md for which ones are verified.
  static const LandmarkTable table = {
      {"head_top", {411}},        {"left_fingertip", {2445}}, {"right_fingertip", {5905}},
      {"left_wrist", {2241}},     {"right_wrist", {5702}},    {"left_shoulder", {3011}},
      {"right_shoulder", {5290}}, {"left_elbow", {1657}},     {"right_elbow", {5126}},
      {"crotch", {1209}},         {"left_hip", {3129}},       {"right_hip", {6550}},
      {"left_nipple", {3042}},    {"right_nipple", {6489}},   {"navel", {3501}},
      {"left_heel", {3387}},      {"right_heel", {6786}},     {"left_sole", {3264}},
      {"right_sole", {6664}},
  };
  return table;
}

Eigen::Vector3d landmark_point(const smpl::Vertices& vertices, const std::vector<int>& ids) {
  if (ids.empty()) throw LandmarkError("landmark has no vertices");
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int id : ids) {
    if (id < 0 || id >= vertices.rows()) {
      throw LandmarkError("landmark vertex id " + std::to_string(id) + " is out of range [0, " +
                          std::to_string(vertices.rows()) +
                          "); the landmark table does not fit this mesh");
    }
    p += vertices.row(id).transpose();
  }
  return p / static_cast<double>(ids.size());
}

// ---------------------------------------------------------------------------------------------
// Derived torso landmarks

void derive_torso_landmarks(const smpl::Vertices& v, LandmarkTable& table, double band) {
  const auto has = [&](const char* n) { return table.count(n) > 0; };
  double mid = 0.0;
  double half = std::numeric_limits<double>::infinity();
  if (has("left_shoulder") && has("right_shoulder")) {
    const Eigen::Vector3d l = landmark_point(v, table.at("left_shoulder"));
    const Eigen::Vector3d r = landmark_point(v, table.at("right_shoulder"));
    mid = 0.5 * (l.x() + r.x());
    half = 0.5 * std::abs(l.x() - r.x());
  } else if (has("navel")) {
    mid = landmark_point(v, table.at("navel")).x();
  }
  const auto sides = [&](double y, const char* left, const char* right) {
    int best_l = -1, best_r = -1;
    for (Eigen::Index i = 0; i < v.rows(); ++i) {
      if (std::abs(v(i, 1) - y) > band || std::abs(v(i, 0) - mid) >= half) continue;
      if (best_l < 0 || v(i, 0) > v(best_l, 0)) best_l = static_cast<int>(i);
      if (best_r < 0 || v(i, 0) < v(best_r, 0)) best_r = static_cast<int>(i);
    }
    if (best_l >= 0 && !has(left)) table[left] = {best_l};
    if (best_r >= 0 && !has(right)) table[right] = {best_r};
  };
  if (has("navel")) {
    const Eigen::Vector3d navel = landmark_point(v, table.at("navel"));
    sides(navel.y(), "left_waist", "right_waist");
    if (!has("torso_back")) {
      int best = -1;
      for (Eigen::Index i = 0; i < v.rows(); ++i) {
        if (std::abs(v(i, 1) - navel.y()) > band || std::abs(v(i, 0) - navel.x()) > band) continue;
        if (best < 0 || v(i, 2) < v(best, 2)) best = static_cast<int>(i);
      }
      if (best >= 0) table["torso_back"] = {best};
    }
  }
  if (has("left_nipple") && has("right_nipple")) {
    const double y = 0.5 * (landmark_point(v, table.at("left_nipple")).y() +
                            landmark_point(v, table.at("right_nipple")).y());
    sides(y, "left_chest", "right_chest");
  }
}

void derive_iliac_crest_landmarks(const smpl::Vertices& v, LandmarkTable& table,
                                  double stature_fraction, double band) {
  if (table.count("left_iliac_crest") && table.count("right_iliac_crest")) return;
  if (!table.count("left_shoulder") || !table.count("right_shoulder"))
    throw LandmarkError(
        "the iliac crest rule needs the left_shoulder and right_shoulder landmarks");
  const Eigen::Vector3d l = landmark_point(v, table.at("left_shoulder"));
  const Eigen::Vector3d r = landmark_point(v, table.at("right_shoulder"));
  const double mid = 0.5 * (l.x() + r.x()), half = 0.5 * std::abs(l.x() - r.x());
  const double floor = floor_height(v);
  const double y = floor + stature_fraction * (v.col(1).maxCoeff() - floor);
  int best_l = -1, best_r = -1;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    if (std::abs(v(i, 1) - y) > band || std::abs(v(i, 0) - mid) >= half) continue;
    if (v(i, 0) > mid && (best_l < 0 || v(i, 0) > v(best_l, 0))) best_l = static_cast<int>(i);
    if (v(i, 0) < mid && (best_r < 0 || v(i, 0) < v(best_r, 0))) best_r = static_cast<int>(i);
  }
  if (best_l < 0 || best_r < 0)
    throw LandmarkError("the iliac crest rule found no torso vertex within " +
                        std::to_string(band) + " m of the height " + std::to_string(y) + " m");
  if (!table.count("left_iliac_crest")) table["left_iliac_crest"] = {best_l};
  if (!table.count("right_iliac_crest")) table["right_iliac_crest"] = {best_r};
}

LandmarkTable landmarks_for(const smpl::BodyModel& model) {
  LandmarkTable table;
  if (model.num_vertices() == kSmplVertexCount) table = smpl_landmarks();
  for (const auto& [name, ids] : model.landmarks) table[name] = ids;
  for (const auto& [name, ids] : table) {
    if (ids.empty())
      throw LandmarkError("landmark '" + name + "' of model '" + model.meta.name +
                          "' has no vertices");
    for (int id : ids) {
      if (id < 0 || id >= model.num_vertices()) {
        throw LandmarkError("landmark '" + name + "' of model '" + model.meta.name +
                            "' uses vertex " + std::to_string(id) + ", out of range [0, " +
                            std::to_string(model.num_vertices()) + ")");
      }
    }
  }
  if (model.v_template.rows() > 0) derive_torso_landmarks(model.v_template, table);
  return table;
}

// ---------------------------------------------------------------------------------------------
// Measuring

double floor_height(const smpl::Vertices& vertices) {
  if (vertices.rows() == 0) throw InvalidInputError("floor_height: the mesh has no vertices");
  // Four running minima instead of one chain (a minimum does not depend on the order).
  const double* y = vertices.data() + 1;
  const Eigen::Index n = vertices.rows();
  double m[4] = {y[0], y[0], y[0], y[0]};
  Eigen::Index i = 0;
  for (; i + 4 <= n; i += 4) {
    for (int k = 0; k < 4; ++k) m[k] = std::min(m[k], y[3 * (i + k)]);
  }
  for (; i < n; ++i) m[0] = std::min(m[0], y[3 * i]);
  return std::min(std::min(m[0], m[1]), std::min(m[2], m[3]));
}

bool is_available(const MeasurementDef& def, const LandmarkTable& landmarks) {
  if (landmarks.count(def.from) == 0) return false;
  return def.kind == MeasurementKind::Height || landmarks.count(def.to) > 0;
}

std::vector<MeasurementDef> available_measurements(const LandmarkTable& landmarks,
                                                   const std::vector<MeasurementDef>& defs) {
  std::vector<MeasurementDef> out;
  for (const auto& d : defs) {
    if (is_available(d, landmarks)) out.push_back(d);
  }
  return out;
}

namespace {
const std::vector<int>& lookup(const LandmarkTable& landmarks, const std::string& name,
                               const std::string& measurement) {
  const auto it = landmarks.find(name);
  if (it == landmarks.end()) {
    throw LandmarkError("measurement '" + measurement + "' needs landmark '" + name +
                        "', which the model does not define; add it to the model's landmarks");
  }
  return it->second;
}
}  // namespace

double measure(const smpl::Vertices& vertices, const LandmarkTable& landmarks,
               const MeasurementDef& def) {
  const Eigen::Vector3d a = landmark_point(vertices, lookup(landmarks, def.from, def.id));
  if (def.kind == MeasurementKind::Height) return a.y() - floor_height(vertices);
  const Eigen::Vector3d b = landmark_point(vertices, lookup(landmarks, def.to, def.id));
  return (a - b).norm();
}

MeasurementMap measure(const smpl::Vertices& vertices, const LandmarkTable& landmarks,
                       const std::vector<MeasurementDef>& defs) {
  MeasurementMap out;
  double floor = 0.0;  // the lowest vertex, found once for all heights
  bool have_floor = false;
  for (const auto& d : defs) {
    if (!is_available(d, landmarks)) continue;
    if (d.kind != MeasurementKind::Height) {
      out[d.id] = measure(vertices, landmarks, d);
      continue;
    }
    if (!have_floor) floor = floor_height(vertices);
    have_floor = true;
    out[d.id] = landmark_point(vertices, lookup(landmarks, d.from, d.id)).y() - floor;
  }
  return out;
}

ModelMeasureInfo::ModelMeasureInfo(const smpl::BodyModel& model)
    : landmarks(landmarks_for(model)),
      closed(open_edge_count(model.faces) == 0),
      weight_formula(weight_formula_of(model)) {}

namespace {

void check_vertex_count(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  if (vertices.rows() != model.num_vertices()) {
    throw InvalidInputError("measure_all: " + std::to_string(vertices.rows()) +
                            " vertices given, the model '" + model.meta.name + "' has " +
                            std::to_string(model.num_vertices()));
  }
}

}  // namespace

MeasurementMap measure_all(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                           const MeasureOptions& options) {
  check_vertex_count(model, vertices);
  return measure_all(model, vertices, ModelMeasureInfo(model), options);
}

MeasurementMap measure_all(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                           const ModelMeasureInfo& info, const MeasureOptions& options) {
  check_vertex_count(model, vertices);
  const LandmarkTable& landmarks = info.landmarks;
  MeasurementMap out = measure(vertices, landmarks);
  if (info.closed) {  // a volume needs a closed surface
    const double volume = mesh_volume(vertices, model.faces);
    out["volume"] = volume;
    out["weight"] = weight_from_volume(volume, info.weight_formula);
  }
  if (options.circumferences) {
    for (const auto& [id, value] :
         circumferences(vertices, model.faces, landmarks, options.convex_hull)) {
      out[id] = value;
    }
  }
  return out;
}

smpl::Vertices shaped_vertices(const smpl::BodyModel& model, const Eigen::VectorXd& betas) {
  if (betas.size() > model.num_betas()) {
    throw InvalidInputError(std::to_string(betas.size()) + " betas given, the model '" +
                            model.meta.name + "' has only " + std::to_string(model.num_betas()));
  }
  if (!betas.allFinite()) throw InvalidInputError("betas contain NaN or infinity");
  // Trailing zero betas (an avatar's betas are the regressor's k padded with zeros to the
  // model's count) add nothing: their columns are not read (6 of the open models' 16 columns,
  // 1.8 MB per body). libsmpl's shape kernel then gives the same bits as the exporters' own
  // smpl::shape() of the full betas (a validated model's shape directions are finite), so that
  // an avatar file can be written from these vertices (smpl::ExportOptions::rest_vertices).
  Eigen::Index n = betas.size();
  while (n > 0 && betas[n - 1] == 0.0) --n;
  smpl::Body body;
  smpl::shape(model, betas.head(n), body);
  return std::move(body.vertices);
}

// ---------------------------------------------------------------------------------------------
// Validation

MeasurementRange measurement_range(const std::string& id) {
  static const std::map<std::string, MeasurementRange> ranges = {
      {"height", {0.5, 2.5, 1.4, 2.1}},
      {"weight", {10.0, 300.0, 40.0, 150.0}},
      {"nipple_height", {0.3, 2.0, 1.0, 1.55}},
      {"navel_height", {0.25, 1.7, 0.85, 1.3}},
      {"inseam_height", {0.2, 1.3, 0.6, 0.98}},
      {"shoulder_width", {0.15, 0.7, 0.28, 0.48}},
      {"chest_width", {0.12, 0.7, 0.22, 0.45}},
      {"waist_width", {0.1, 0.8, 0.2, 0.45}},
      {"torso_depth", {0.08, 0.7, 0.15, 0.4}},
      {"hip_width", {0.12, 0.8, 0.26, 0.48}},
      {"arm_span_fingertips", {0.5, 2.6, 1.35, 2.15}},
      {"arm_span_wrists", {0.4, 2.2, 1.0, 1.85}},
      {"arm_length", {0.2, 1.0, 0.42, 0.75}},
      {"forearm_length", {0.1, 0.6, 0.18, 0.35}},
      {"chest_circumference", {0.4, 2.0, 0.7, 1.35}},
      {"waist_circumference", {0.35, 2.2, 0.55, 1.35}},
      {"hip_circumference", {0.45, 2.2, 0.78, 1.4}},
      {"thigh_circumference", {0.2, 1.2, 0.4, 0.78}},
  };
  const auto it = ranges.find(id);
  if (it == ranges.end()) throw InvalidInputError("no plausible range known for '" + id + "'");
  return it->second;
}

std::vector<ValidationMessage> validate_measurements(const MeasurementMap& values) {
  std::vector<ValidationMessage> out;
  const auto unit = [](const std::string& id) { return id == "weight" ? " kg" : " m"; };
  for (const auto& [id, value] : values) {
    MeasurementRange r{};
    try {
      r = measurement_range(id);
    } catch (const InvalidInputError&) {
      out.push_back(
          {Severity::Warning, id, value, 0.0, 0.0, "unknown measurement '" + id + "' is ignored"});
      continue;
    }
    const std::string u = unit(id);
    if (!std::isfinite(value)) {
      out.push_back({Severity::Error, id, value, r.error_min, r.error_max,
                     id + " is not a number; expected " + smpl::format_general(r.error_min, 4) +
                         " to " + smpl::format_general(r.error_max, 4) + u});
    } else if (value <= 0.0) {
      out.push_back({Severity::Error, id, value, r.error_min, r.error_max,
                     id + " = " + smpl::format_general(value, 4) + u +
                         " must be positive; expected " + smpl::format_general(r.error_min, 4) +
                         " to " + smpl::format_general(r.error_max, 4) + u});
    } else if (value < r.error_min || value > r.error_max) {
      out.push_back({Severity::Error, id, value, r.error_min, r.error_max,
                     id + " = " + smpl::format_general(value, 4) + u +
                         " is outside the plausible range " + smpl::format_general(r.error_min, 4) +
                         " to " + smpl::format_general(r.error_max, 4) + u +
                         " (check the unit: metres and kilograms)"});
    } else if (value < r.warning_min || value > r.warning_max) {
      out.push_back({Severity::Warning, id, value, r.warning_min, r.warning_max,
                     id + " = " + smpl::format_general(value, 4) + u +
                         " is unusual for an adult (typical " +
                         smpl::format_general(r.warning_min, 4) + " to " +
                         smpl::format_general(r.warning_max, 4) + u + ")"});
    }
  }
  const auto good = [&](const char* id) {
    const auto it = values.find(id);
    return it != values.end() && std::isfinite(it->second) && it->second > 0.0;
  };
  struct Ratio {
    const char* num;
    const char* den;
    double emin, emax, wmin, wmax;
  };
  static const Ratio ratios[] = {
      {"arm_span_fingertips", "height", 0.7, 1.3, 0.9, 1.12},
      {"inseam_height", "height", 0.3, 0.6, 0.38, 0.52},
      {"arm_length", "height", 0.2, 0.45, 0.27, 0.38},
      {"hip_width", "height", 0.1, 0.35, 0.14, 0.28},
  };
  for (const auto& q : ratios) {
    if (!good(q.num) || !good(q.den)) continue;
    const double ratio = values.at(q.num) / values.at(q.den);
    const std::string id = std::string(q.num) + "/" + q.den;
    const std::string what = std::string(q.num) + " = " +
                             smpl::format_general(values.at(q.num), 4) + " m is " +
                             smpl::format_general(ratio, 3) + " times " + q.den + " = " +
                             smpl::format_general(values.at(q.den), 4) + " m";
    if (ratio < q.emin || ratio > q.emax) {
      out.push_back({Severity::Error, id, ratio, q.emin, q.emax,
                     what + "; expected " + smpl::format_general(q.emin, 4) + " to " +
                         smpl::format_general(q.emax, 4) + " times"});
    } else if (ratio < q.wmin || ratio > q.wmax) {
      out.push_back({Severity::Warning, id, ratio, q.wmin, q.wmax,
                     what + "; typical " + smpl::format_general(q.wmin, 4) + " to " +
                         smpl::format_general(q.wmax, 4) + " times"});
    }
  }
  if (good("weight") && good("height")) {
    const double h = values.at("height");
    const double bmi = values.at("weight") / (h * h);
    const std::string what = "weight " + smpl::format_general(values.at("weight"), 4) +
                             " kg at height " + smpl::format_general(h, 4) + " m gives a BMI of " +
                             smpl::format_general(bmi, 3) + " kg/m^2";
    if (bmi < 10.0 || bmi > 80.0) {
      out.push_back({Severity::Error, "bmi", bmi, 10.0, 80.0, what + "; expected 10 to 80"});
    } else if (bmi < 15.0 || bmi > 45.0) {
      out.push_back({Severity::Warning, "bmi", bmi, 15.0, 45.0, what + "; typical 15 to 45"});
    }
  }
  return out;
}

bool has_errors(const std::vector<ValidationMessage>& messages) {
  return std::any_of(messages.begin(), messages.end(),
                     [](const ValidationMessage& m) { return m.severity == Severity::Error; });
}

// ---------------------------------------------------------------------------------------------
// The hanging arm (moved from apps/modelgen on 2026-11-30 so that the CLI's survey studies can
// map ANSUR II's arm onto the virtual one; the arithmetic is unchanged, the open models' bytes
// depend on it).

HangingArms hanging_arms(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  return hanging_arms(model, vertices, model.landmarks);
}

HangingArms hanging_arms(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                         const LandmarkTable& lm) {
  const int kShoulder[2] = {16, 17};  // SMPL left_shoulder, right_shoulder
  const char* kAcromion[2] = {"left_shoulder", "right_shoulder"};
  const char* kWrist[2] = {"left_wrist", "right_wrist"};
  const char* kRadiale[2] = {"left_radiale", "right_radiale"};
  if (model.parents.size() <= 17 || model.j_regressor.rows() <= 17 ||
      model.weights.cols() != static_cast<Eigen::Index>(model.parents.size()) ||
      model.weights.rows() != vertices.rows() || model.j_regressor.cols() != vertices.rows()) {
    throw ModelMismatchError(
        "hanging arms: the model needs SMPL's joints (left and right shoulder are joints 16 and "
        "17) with a joint regressor and skinning weights for its " +
        std::to_string(vertices.rows()) +
        " vertices; use an SMPL-family model with its skeleton (the open models, SMPL files)");
  }
  // Joints whose motion follows a shoulder rotation: the shoulder and its descendants.
  std::vector<char> follows[2];
  for (int s = 0; s < 2; ++s) {
    follows[s].assign(model.parents.size(), 0);
    follows[s][static_cast<std::size_t>(kShoulder[s])] = 1;
    for (std::size_t j = 0; j < model.parents.size(); ++j) {
      const int p = model.parents[j];
      if (p >= 0 && follows[s][static_cast<std::size_t>(p)]) {
        follows[s][j] = 1;
      }
    }
  }
  auto landmark = [&](const char* name) -> std::vector<int> {
    const auto it = lm.find(name);
    if (it == lm.end() || it->second.empty()) {
      throw LandmarkError(std::string("hanging arms: the model has no landmark '") + name +
                          "'; give it a landmark table that names it (docs/measurements.md)");
    }
    return it->second;
  };
  HangingArms out;
  for (int s = 0; s < 2; ++s) {
    Eigen::Vector3d joint = Eigen::Vector3d::Zero();
    for (smpl::SparseMatrix::InnerIterator it(model.j_regressor, kShoulder[s]); it; ++it) {
      joint += it.value() * vertices.row(it.col()).transpose();
    }
    // T-pose arm along +x (left) or -x (right); hanging: rotated 90 degrees down about z.
    const double sign = s == 0 ? -1.0 : 1.0;
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(sign * 0.5 * smpl::kPi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::Vector3d acromion = Eigen::Vector3d::Zero();
    const std::vector<int> a = landmark(kAcromion[s]);
    for (int v : a) {
      acromion += vertices.row(v).transpose() / static_cast<double>(a.size());
    }
    // Linear blend skinning restricted to the shoulder rotation: the share of a vertex's
    // weight on joints that follow the shoulder moves with it.
    auto hanging = [&](const std::vector<int>& ids) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int v : ids) {
        double moving = 0;
        for (smpl::SparseMatrix::InnerIterator it(model.weights, v); it; ++it) {
          if (follows[s][static_cast<std::size_t>(it.col())]) {
            moving += it.value();
          }
        }
        const Eigen::Vector3d p = vertices.row(v).transpose();
        sum += (p + moving * (r * (p - joint) + joint - p)) / static_cast<double>(ids.size());
      }
      return sum;
    };
    const Eigen::Vector3d wrist = hanging(landmark(kWrist[s]));
    const auto radiale = lm.find(kRadiale[s]);
    out.radiale[s] = radiale == lm.end() || radiale->second.empty()
                         ? Eigen::Vector3d::Constant(std::nan(""))
                         : hanging(radiale->second);
    out.acromion[s] = acromion;
    out.wrist[s] = wrist;
  }
  return out;
}

double hanging_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  return hanging_arm_length(model, vertices, model.landmarks);
}

double hanging_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                          const LandmarkTable& landmarks) {
  const HangingArms h = hanging_arms(model, vertices, landmarks);
  return 0.5 * ((h.wrist[0] - h.acromion[0]).norm() + (h.wrist[1] - h.acromion[1]).norm());
}

double hanging_upper_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  const HangingArms h = hanging_arms(model, vertices);
  return 0.5 * ((h.radiale[0] - h.acromion[0]).norm() + (h.radiale[1] - h.acromion[1]).norm());
}

}  // namespace caliper
