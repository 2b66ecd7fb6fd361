/// \file makehuman_landmarks.cpp
/// Landmarks on the MakeHuman skin topology by geometric rules on the T-posed template (contract
/// in the header). Each rule is a filter (which vertices may be the landmark) and a score; ties go
/// to the lower vertex index, so the result does not depend on anything but the template.

#include "makehuman_landmarks.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace modelgen::mh {

namespace {

// SMPL joint indices (smpl::smpl_joint_names() order).
constexpr int kPelvis = 0, kLeftHip = 1, kRightHip = 2, kLeftAnkle = 7, kLeftShoulder = 16,
              kLeftElbow = 18, kLeftWrist = 20;

/// Half-width of the slab "on the midline" (the base mesh's midline vertices are at x = mid
/// to well under a millimetre).
constexpr double kMidline = 0.002;
/// Half-width of the slab across a limb at a joint, and the largest distance from the joint's
/// axis a ring vertex may have (excludes the other fingers and the thumb at the wrist).
constexpr double kRingHalfWidth = 0.005;
constexpr double kRingRadius = 0.08;
/// The acromion's ring lies this far lateral of the shoulder joint (the top of the humeral head).
constexpr double kAcromionLateral = 0.015;
constexpr double kAcromionFrontBack = 0.04;
/// Weight of the position in the score among marker vertices moved alike (decimetres of
/// displacement against metres: only breaks ties).
constexpr double kTieBreak = 1e-6;

int best(const smpl::Vertices& v, const char* name, const std::function<bool(int)>& keep,
         const std::function<double(int)>& score) {
  int arg = -1;
  double top = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < static_cast<int>(v.rows()); ++i) {
    if (!keep(i)) continue;
    const double s = score(i);
    if (s > top) {
      top = s;
      arg = i;
    }
  }
  if (arg < 0) {
    throw std::invalid_argument(std::string("MakeHuman landmarks: no vertex fits the rule of '") +
                                name + "' on this template");
  }
  return arg;
}

/// The vertex of the skin ring across the arm at joint `j` (arm along +X) furthest along
/// `axis`: 2 (+Z) the front, 1 (+Y) the top (at the elbow the radiale: the T-pose raises the arm
/// sideways, so the lateral side of the elbow, the head of the radius, faces up).
int ring_extreme(const smpl::Vertices& v, const Joints24& joints, int j, int axis,
                 const char* name) {
  const Eigen::RowVector3d c = joints.row(j);
  return best(
      v, name,
      [&](int i) {
        const double dy = v(i, 1) - c(1), dz = v(i, 2) - c(2);
        return std::abs(v(i, 0) - c(0)) < kRingHalfWidth &&
               dy * dy + dz * dz < kRingRadius * kRingRadius;
      },
      [&](int i) { return v(i, axis); });
}

/// Per skin vertex: how far the target `relative` moves it (decimetres; 0 for vertices it does
/// not move).
std::vector<double> marker(const Assets& assets, const std::string& relative) {
  const Target t = read_asset_target(assets, relative);
  std::vector<double> m(assets.skin.source_vertex.size(), 0.0);
  for (size_t k = 0; k < t.index.size(); ++k) {
    const int s = assets.skin.skin_vertex[t.index[k]];
    if (s >= 0) m[s] = std::max(m[s], t.delta[k].norm());
  }
  return m;
}

}  // namespace

std::map<std::string, std::vector<int>> template_landmarks(const Assets& assets,
                                                           const smpl::Vertices& v,
                                                           const Joints24& joints) {
  if (v.rows() == 0) throw std::invalid_argument("MakeHuman landmarks: the template is empty");
  const double mid = 0.5 * (joints(kLeftHip, 0) + joints(kRightHip, 0));
  const Eigen::RowVector3d pelvis = joints.row(kPelvis);
  auto on_midline = [&](int i) { return std::abs(v(i, 0) - mid) < kMidline; };

  std::map<std::string, std::vector<int>> L;
  L["head_top"] = {best(v, "head_top", on_midline, [&](int i) { return v(i, 1); })};
  L["left_fingertip"] = {best(
      v, "left_fingertip", [&](int i) { return v(i, 0) > mid; }, [&](int i) { return v(i, 0); })};
  L["left_wrist"] = {ring_extreme(v, joints, kLeftWrist, 2, "left_wrist")};
  L["left_elbow"] = {ring_extreme(v, joints, kLeftElbow, 2, "left_elbow")};
  L["left_radiale"] = {ring_extreme(v, joints, kLeftElbow, 1, "left_radiale")};
  const Eigen::RowVector3d sh = joints.row(kLeftShoulder);
  L["left_shoulder"] = {best(
      v, "left_shoulder",
      [&](int i) {
        return std::abs(v(i, 0) - (sh(0) + kAcromionLateral)) < kRingHalfWidth &&
               std::abs(v(i, 2) - sh(2)) < kAcromionFrontBack;
      },
      [&](int i) { return v(i, 1); })};
  const int crotch = best(
      v, "crotch", [&](int i) { return on_midline(i) && v(i, 1) < pelvis(1); },
      [&](int i) { return -v(i, 1); });
  L["crotch"] = {crotch};
  L["left_hip"] = {best(
      v, "left_hip", [&](int i) { return v(i, 1) >= v(crotch, 1) && v(i, 1) <= pelvis(1); },
      [&](int i) { return v(i, 0); })};
  const std::vector<double> breast = marker(assets, "breast/breast-point-incr.target");
  L["left_nipple"] = {best(
      v, "left_nipple", [&](int i) { return v(i, 0) > mid && breast[i] > 0.0; },
      [&](int i) { return breast[i] + kTieBreak * v(i, 2); })};
  const std::vector<double> navel = marker(assets, "stomach/stomach-navel-in.target");
  const double deepest = *std::max_element(navel.begin(), navel.end());
  L["navel"] = {best(
      v, "navel",
      [&](int i) { return on_midline(i) && navel[i] > 0.0 && navel[i] >= deepest - 1e-9; },
      [&](int i) { return -v(i, 2); })};

  const Eigen::RowVector3d ankle = joints.row(kLeftAnkle);
  auto left_foot = [&](int i) { return v(i, 0) > mid && v(i, 1) < ankle(1); };
  L["left_heel"] = {best(v, "left_heel", left_foot, [&](int i) { return -v(i, 2); })};
  L["left_sole"] = {best(
      v, "left_sole", [&](int i) { return left_foot(i) && v(i, 2) > ankle(2); },
      [&](int i) { return -v(i, 1); })};

  for (const char* name :
       {"fingertip", "wrist", "elbow", "radiale", "shoulder", "hip", "nipple", "heel", "sole"}) {
    const std::string left = std::string("left_") + name;
    const int right = assets.skin.mirror[static_cast<std::size_t>(L.at(left).front())];
    L[std::string("right_") + name] = {right};
  }
  return L;
}

}  // namespace modelgen::mh
