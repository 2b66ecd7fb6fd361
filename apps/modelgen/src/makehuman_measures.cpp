/// \file makehuman_measures.cpp
/// The survey measurements of the open model v2 (makehuman_measures.hpp).
#include "makehuman_measures.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/circumference.hpp"
#include "caliper/volume.hpp"
#include "makehuman_shape.hpp"
#include "validation.hpp"

namespace modelgen::mh {
namespace {

constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

/// SMPL joint indices.
constexpr int kJointLeftHip = 1, kJointRightHip = 2, kJointLeftKnee = 4, kJointLeftAnkle = 7,
              kJointNeck = 12, kJointHead = 15, kJointLeftShoulder = 16, kJointLeftElbow = 18;

/// The ankle girth is taken at least this far above the ankle joint (below, the slice meets the
/// heel and the instep).
constexpr double kAnkleRise = 0.03;

/// Height above the floor, as a fraction of stature, of the top of the iliac crest: the mean
/// iliocristale height / stature of ANSUR II (0.611 women, 0.604 men; both sexes weighted
/// alike). Each subject's own iliac crest height then moves the vertex (fitted on ANSUR II's
/// iliocristaleheight).
constexpr double kIliacCrestFraction = 0.608;

/// Height of the trochanterion (the top of the femur's greater trochanter) above the crotch, as
/// a fraction of stature: ANSUR II's mean (trochanterionheight - crotchheight) / stature of the
/// sex (0.0388 women, 0.0313 men; the neutral rule the mean of the two). Placed at ANSUR II's
/// mean trochanterion height / stature (0.516) instead, the point sat 9 mm too high over the
/// women's crotch: their fits then missed crotch height by -3.0 mm, knee height by +3.0 mm and
/// the upper leg by +3.1 mm on average (the mesh's lateral hip keeps its height over the crotch).
/// Each subject's own upper leg length then moves it (fitted on ANSUR II's trochanterion height
/// minus its lateral femoral epicondyle height, and on NHANES's upper leg length).
double trochanter_above_crotch(const std::string& sex) {
  constexpr double kFemale = 0.0388, kMale = 0.0313;
  if (sex == "female") return kFemale;
  if (sex == "male") return kMale;
  return 0.5 * (kFemale + kMale);
}

/// Step of the scans that place the gluteal fold and the calf's largest girth.
constexpr double kScanStep = 0.002;

/// Loops of a neck slice lie within this distance of the midline (a T-posed arm is far out).
constexpr double kNeckHalfWidth = 0.05;

/// The neck girth is the smallest of the slices from kNeckBelow under to kNeckAbove over the
/// average body's narrowest neck level, every kNeckStep (a tape finds the narrowest neck below the
/// jaw; the level of the narrowest neck moves with the shape, and just below it the girth grows
/// by about 1.5 cm every 5 mm down the slope of the shoulders). The slices cut only the faces of
/// the neck region (within kNeckRegion of that level, inside the shoulders).
constexpr double kNeckRegion = 0.12;
constexpr double kNeckBelow = 0.02, kNeckAbove = 0.03, kNeckStep = 0.0025;

/// The leg slices cut only the faces below kLegRegionTop over the average body's crotch (the
/// gluteal fold lies 5 cm under it), the wrist slices only those beyond kWristRegion inside
/// the average body's wrist landmark: the same loops, a fraction of the time.
constexpr double kLegRegionTop = 0.02, kWristRegion = 0.08;

/// Half-height of the band of vertices a rule picks from around a level.
constexpr double kBand = 0.005;

/// Tape girth of the left leg at height `h` (NaN when the plane meets no leg).
double left_leg_girth(const smpl::Vertices& v, const smpl::Faces& f, double h, double mid) {
  const std::vector<Eigen::Vector2d> p =
      caliper::clip_loops_left(caliper::slice_mesh(v, f, h), mid);
  return p.size() < 3 ? kNoValue : caliper::convex_hull_perimeter(p);
}

/// Tape girth of the one loop of `loops` whose centroid is nearest `near` (NaN for no loop).
double nearest_loop_girth(const std::vector<caliper::SliceLoop>& loops,
                          const Eigen::Vector2d& near) {
  const caliper::SliceLoop* best = nullptr;
  for (const caliper::SliceLoop& l : loops) {
    if (best == nullptr || (l.centroid - near).norm() < (best->centroid - near).norm()) best = &l;
  }
  return best == nullptr ? kNoValue : caliper::convex_hull_perimeter(best->points);
}

/// The loops of the plane x = `x`, points (y, z).
std::vector<caliper::SliceLoop> slice_x(const smpl::Vertices& v, const smpl::Faces& f, double x) {
  smpl::Vertices w(v.rows(), 3);
  w.col(0) = v.col(1);
  w.col(1) = v.col(0);
  w.col(2) = v.col(2);
  return caliper::slice_mesh(w, f, x);
}

/// The vertex nearest `p` among those `keep(i)` accepts; throws naming `rule` when none does.
template <typename Keep>
int nearest_vertex(const smpl::Vertices& v, const Eigen::Vector3d& p, const char* rule, Keep keep) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const double d = (v.row(i).transpose() - p).squaredNorm();
    if (keep(static_cast<int>(i)) && d < best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  if (best < 0) {
    throw std::runtime_error(
        std::string("MakeHuman survey measurements: no vertex of the average body fits "
                    "the rule of ") +
        rule);
  }
  return best;
}

/// The rearmost point (least z) of the left leg's slice at `h`, or NaN z when none.
Eigen::Vector3d left_leg_back(const smpl::Vertices& v, const smpl::Faces& f, double h, double mid) {
  Eigen::Vector3d back(0.0, h, kNoValue);
  for (const Eigen::Vector2d& p : caliper::clip_loops_left(caliper::slice_mesh(v, f, h), mid)) {
    if (p.x() > mid && !(p.y() >= back.z())) back = Eigen::Vector3d(p.x(), h, p.y());
  }
  return back;
}

/// The buttock fold: scanning the back of the left leg from 12 cm below the crotch to 6 cm
/// above it, the level where the profile bends forward most sharply (a crease: the rearmost
/// point lies furthest in front of the mean of its neighbours 1 cm above and below).
int gluteal_fold(const smpl::Vertices& v, const smpl::Faces& f, double crotch_y, double mid) {
  const int n = static_cast<int>(std::lround(0.18 / kScanStep));
  const int h = static_cast<int>(std::lround(0.01 / kScanStep));
  std::vector<Eigen::Vector3d> back;
  for (int i = 0; i <= n; ++i)
    back.push_back(left_leg_back(v, f, crotch_y - 0.12 + i * kScanStep, mid));
  int best = -1;
  double best_bend = 0.0;
  for (int i = h; i + h <= n; ++i) {
    const double bend = back[i].z() - 0.5 * (back[i - h].z() + back[i + h].z());
    if (std::isfinite(bend) && bend > best_bend) {
      best_bend = bend;
      best = i;
    }
  }
  if (best < 0) throw std::runtime_error("MakeHuman survey measurements: no gluteal fold found");
  return nearest_vertex(v, back[best], "gluteal_fold", [&](int i) { return v(i, 0) > mid; });
}

/// The back of the left leg at its largest (`largest`) or smallest girth between heights `y0`
/// and `y1`; `rule` names it in errors.
int leg_level(const smpl::Vertices& v, const smpl::Faces& f, double y0, double y1, double mid,
              bool largest, const char* rule) {
  double best_girth = largest ? 0.0 : std::numeric_limits<double>::infinity(), best_y = kNoValue;
  for (double y = y0; y <= y1; y += kScanStep) {
    const double g = left_leg_girth(v, f, y, mid);
    if (std::isfinite(g) && (largest ? g > best_girth : g < best_girth)) {
      best_girth = g;
      best_y = y;
    }
  }
  if (!std::isfinite(best_y)) {
    throw std::runtime_error(std::string("MakeHuman survey measurements: no leg slice for ") +
                             rule);
  }
  return nearest_vertex(v, left_leg_back(v, f, best_y, mid), rule,
                        [&](int i) { return v(i, 0) > mid; });
}

/// Tape girth of the neck at height `h`: the largest loop near the midline (the skin also
/// dips into the mouth, whose loops are smaller and inside).
double neck_girth(const smpl::Vertices& v, const smpl::Faces& f, double h, double mid) {
  double best = kNoValue;
  for (const caliper::SliceLoop& l : caliper::slice_mesh(v, f, h)) {
    if (std::abs(l.centroid.x() - mid) > kNeckHalfWidth) continue;
    const double g = caliper::convex_hull_perimeter(l.points);
    if (!(g <= best)) best = g;
  }
  return best;
}

/// SMPL joint `k` of the body `t` (row `k` of the joint regressor `jr` applied to it).
Eigen::Vector3d joint(const smpl::Vertices& t, const smpl::SparseMatrix& jr, int k) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (smpl::SparseMatrix::InnerIterator it(jr, k); it; ++it) {
    p += it.value() * t.row(it.col()).transpose();
  }
  return p;
}

}  // namespace

SurveyVertices survey_vertices(const smpl::Vertices& t, const smpl::Faces& f,
                               const smpl::SparseMatrix& j_regressor,
                               const caliper::LandmarkTable& landmarks, const std::string& sex) {
  SurveyVertices s;
  s.midline_x =
      0.5 * (joint(t, j_regressor, kJointLeftHip).x() + joint(t, j_regressor, kJointRightHip).x());
  const double mid = s.midline_x;
  const double floor = t.col(1).minCoeff();
  const double crest_y = floor + kIliacCrestFraction * (t.col(1).maxCoeff() - floor);
  const double half = caliper::landmark_point(t, landmarks.at("left_shoulder")).x();
  // Iliac crest: the most lateral torso vertex (inside the shoulders) at that height.
  double best = -1.0;
  for (Eigen::Index i = 0; i < t.rows(); ++i) {
    if (std::abs(t(i, 1) - crest_y) < 0.01 && t(i, 0) > 0.0 && t(i, 0) < half && t(i, 0) > best) {
      best = t(i, 0);
      s.iliac_crest = static_cast<int>(i);
    }
  }
  if (s.iliac_crest < 0) throw std::runtime_error("MakeHuman shape: no iliac crest vertex");
  // Trochanterion: where the edges of the mesh cross its level, the most lateral crossing.
  const double trochanter_y = caliper::landmark_point(t, landmarks.at("crotch")).y() +
                              trochanter_above_crotch(sex) * (t.col(1).maxCoeff() - floor);
  double lateral = -1.0;
  int edge_a = -1, edge_b = -1;
  double share = 0.0;
  for (Eigen::Index r = 0; r < f.rows(); ++r) {
    for (int e = 0; e < 3; ++e) {
      const int a = f(r, e), b = f(r, (e + 1) % 3);
      const double ya = t(a, 1), yb = t(b, 1);
      if ((ya - trochanter_y) * (yb - trochanter_y) >= 0.0) continue;
      const double u = (trochanter_y - ya) / (yb - ya);
      const double x = t(a, 0) + u * (t(b, 0) - t(a, 0));
      if (x > 0.0 && x < half && x > lateral) {
        lateral = x;
        edge_a = a;
        edge_b = b;
        share = u;
      }
    }
  }
  if (edge_a < 0) {
    throw std::runtime_error(
        "MakeHuman shape: no mesh edge crosses the trochanterion's level on the left hip; the base "
        "mesh is not MakeHuman's: give its CC0 assets as published with --makehuman DIR");
  }
  const auto of_b = static_cast<int>(std::lround(share * kTrochanterShares));
  s.trochanterion.assign(kTrochanterShares - of_b, edge_a);
  s.trochanterion.insert(s.trochanterion.end(), of_b, edge_b);
  // Neck: the narrowest neck slice between the neck and head joints (below the jaw); the
  // front midline vertex at that level.
  const Eigen::Vector3d neck_joint = joint(t, j_regressor, kJointNeck);
  double neck_y = kNoValue, neck_best = std::numeric_limits<double>::infinity();
  for (double y = neck_joint.y(); y <= joint(t, j_regressor, kJointHead).y(); y += kScanStep) {
    const double g = neck_girth(t, f, y, mid);
    if (g < neck_best) {
      neck_best = g;
      neck_y = y;
    }
  }
  if (!std::isfinite(neck_y)) throw std::runtime_error("MakeHuman survey measurements: no neck");
  s.neck_front = nearest_vertex(t, Eigen::Vector3d(mid, neck_y, 1.0), "neck_front", [&](int i) {
    return std::abs(t(i, 0) - mid) < 0.002 && std::abs(t(i, 1) - neck_y) < kBand;
  });
  const double crotch_y = caliper::landmark_point(t, landmarks.at("crotch")).y();
  s.gluteal_fold = gluteal_fold(t, f, crotch_y, mid);
  const Eigen::Vector3d knee = joint(t, j_regressor, kJointLeftKnee);
  const double ankle_y = joint(t, j_regressor, kJointLeftAnkle).y();
  s.calf_back = leg_level(t, f, ankle_y, knee.y(), mid, true, "calf_back");
  s.ankle_back = leg_level(t, f, ankle_y + kAnkleRise, t(s.calf_back, 1), mid, false, "ankle_back");
  // Lateral femoral epicondyle: the most lateral vertex of the left knee at the joint.
  s.knee_lateral =
      nearest_vertex(t, Eigen::Vector3d(1.0, knee.y(), knee.z()), "knee_lateral", [&](int i) {
        return std::abs(t(i, 1) - knee.y()) < kBand && t(i, 0) > mid &&
               std::abs(t(i, 2) - knee.z()) < 0.03;
      });
  return s;
}

namespace {

/// The faces of `faces` whose three vertices `keep` accepts.
template <typename Keep>
smpl::Faces region_faces(const smpl::Faces& faces, Keep keep) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index r = 0; r < faces.rows(); ++r) {
    if (keep(faces(r, 0)) && keep(faces(r, 1)) && keep(faces(r, 2))) rows.push_back(r);
  }
  smpl::Faces out(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t k = 0; k < rows.size(); ++k)
    out.row(static_cast<Eigen::Index>(k)) = faces.row(rows[k]);
  return out;
}

}  // namespace

caliper::WeightFormula open_model_weight_formula(const std::string& sex) {
  caliper::WeightFormula f = caliper::weight_formula_for(sex);
  f.intercept += f.coefficient * kSkinVolumeAllowance;
  f.name = f.name + ": Pujades et al. 2019 on the skin's volume plus 4 L";
  return f;
}

Measurer::Measurer(const smpl::BodyModel& tmpl, const smpl::Vertices& rest, const std::string& sex)
    : model(tmpl),
      faces(tmpl.faces),
      landmarks(caliper::landmarks_for(tmpl)),
      formula(open_model_weight_formula(sex)),
      at(survey_vertices(rest, tmpl.faces, tmpl.j_regressor, landmarks, sex)) {
  const smpl::Vertices& t = rest;
  const double neck_y = t(at.neck_front, 1);
  const double half = caliper::landmark_point(t, landmarks.at("left_shoulder")).x() - at.midline_x;
  neck_faces = region_faces(faces, [&](int i) {
    return std::abs(t(i, 1) - neck_y) < kNeckRegion && std::abs(t(i, 0) - at.midline_x) < half;
  });
  const double crotch_y = caliper::landmark_point(t, landmarks.at("crotch")).y();
  leg_faces = region_faces(faces, [&](int i) { return t(i, 1) < crotch_y + kLegRegionTop; });
  const double wrist_x = caliper::landmark_point(t, landmarks.at("left_wrist")).x();
  wrist_faces = region_faces(faces, [&](int i) { return t(i, 0) > wrist_x - kWristRegion; });
}

Eigen::VectorXd Measurer::operator()(const smpl::Vertices& v) const {
  caliper::MeasurementMap all = caliper::measure(v, landmarks);
  all["weight"] = caliper::weight_from_volume(caliper::mesh_volume(v, faces), formula);
  for (const auto& [id, value] : caliper::circumferences(v, faces, landmarks)) all[id] = value;
  const double floor = v.col(1).minCoeff();
  const Eigen::Vector3d shoulder = caliper::landmark_point(v, landmarks.at("left_shoulder"));
  const Eigen::Vector3d wrist = caliper::landmark_point(v, landmarks.at("left_wrist"));
  const Eigen::Vector3d crotch = caliper::landmark_point(v, landmarks.at("crotch"));
  const double mid = crotch.x();
  all["iliac_crest_height"] = v(at.iliac_crest, 1) - floor;
  std::vector<Eigen::Vector2d> torso;  // the loops between the shoulders, as for the waist
  for (const caliper::SliceLoop& l : caliper::slice_mesh(v, faces, v(at.iliac_crest, 1))) {
    if (l.centroid.x() >= -shoulder.x() && l.centroid.x() <= shoulder.x()) {
      torso.insert(torso.end(), l.points.begin(), l.points.end());
    }
  }
  all["waist_iliac_circumference"] =
      torso.empty() ? kNoValue : caliper::convex_hull_perimeter(torso);
  const Eigen::Vector3d neck = v.row(at.neck_front).transpose();
  double neck_min = kNoValue;
  for (double d = -kNeckBelow; d <= kNeckAbove; d += kNeckStep) {
    const double g = neck_girth(v, neck_faces, neck.y() + d, mid);
    if (!(g >= neck_min)) neck_min = g;
  }
  all["neck_circumference"] = neck_min;
  // At the fold, but never less than caliper::kThighBelowCrotch under the crotch, on the whole
  // mesh, as libcaliper measures a model carrying the fold (caliper::thigh_fold_level()): so close
  // to a man's crotch, the leg region's slice misses faces that the whole mesh's has.
  all["thigh_circumference"] =
      left_leg_girth(v, faces, caliper::thigh_fold_level(v(at.gluteal_fold, 1), crotch.y()), mid);
  all["calf_circumference"] = left_leg_girth(v, leg_faces, v(at.calf_back, 1), mid);
  all["wrist_circumference"] = nearest_loop_girth(slice_x(v, wrist_faces, wrist.x()),
                                                  Eigen::Vector2d(wrist.y(), wrist.z() - 0.025));
  all["ankle_circumference"] = left_leg_girth(v, leg_faces, v(at.ankle_back, 1), mid);
  all["knee_height"] = v(at.knee_lateral, 1) - floor;
  all["upper_leg_length"] =
      caliper::landmark_point(v, at.trochanterion).y() - v(at.knee_lateral, 1);
  all["arm_length"] = hanging_arm_length(model, v);
  all["upper_arm_length"] = hanging_upper_arm_length(model, v);
  // NHANES's mid-upper-arm circumference: the left arm's slice perpendicular to the T-posed
  // arm halfway between the acromion and the radiale, the loop nearest the humerus's midpoint
  // (SMPL's shoulder and elbow joints).
  const Eigen::Vector3d radiale = caliper::landmark_point(v, landmarks.at("left_radiale"));
  const Eigen::Vector3d humerus = 0.5 * (joint(v, model.j_regressor, kJointLeftShoulder) +
                                         joint(v, model.j_regressor, kJointLeftElbow));
  all["upper_arm_circumference"] =
      nearest_loop_girth(slice_x(v, faces, 0.5 * (shoulder.x() + radiale.x())),
                         Eigen::Vector2d(humerus.y(), humerus.z()));
  all["acromial_height"] = shoulder.y() - floor;
  all["hand_length"] = (caliper::landmark_point(v, landmarks.at("left_fingertip")) - wrist).norm();
  Eigen::VectorXd out(static_cast<Eigen::Index>(fit_measures().size()));
  for (size_t i = 0; i < fit_measures().size(); ++i) {
    const auto it = all.find(fit_measures()[i].id);
    out[static_cast<Eigen::Index>(i)] = it == all.end() ? kNoValue : it->second;
  }
  return out;
}

}  // namespace modelgen::mh
