/// \file cage.cpp
/// The parametric control cage (see cage.hpp for the layout).
///
/// Sections: helpers; torso sections; the Builder (adds vertices and quads, mirrors the right
/// side); the stages of build_cage, in the order in which they add vertices and quads (that order
/// gives the vertex and face ids, so it is part of the model files): body_levels, torso_sections
/// and arm_root (numbers only); build_torso; build_shoulder_cap; build_neck_and_head; build_arm
/// for the left and the right arm (tube rings, palm rings, build_thumb, build_fingers); the crotch
/// vertex; build_leg for the left and the right leg (leg_tube, foot_rings, toe cap); set_joints;
/// set_landmarks. The stages keep the arithmetic and its order of the single function they were
/// split from, so the open models regenerate byte for byte (docs/ci.md, docs/models.md).
#include "cage.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>

#include <Eigen/Geometry>

#include "ansur_stats.hpp"
#include "caliper/portable_math.hpp"
#include "smpl/constants.hpp"

namespace modelgen {

// libm's transcendental functions differ in the last bit between CPUs (portable_math.hpp).
namespace pm = caliper::portable;
namespace {

using smpl::kPi;

// SMPL joint ids.
enum Joint : int {
  kPelvis = 0,
  kLHip = 1,
  kSpine1 = 3,
  kLKnee = 4,
  kSpine2 = 6,
  kLAnkle = 7,
  kSpine3 = 9,
  kLFoot = 10,
  kNeck = 12,
  kLCollar = 13,
  kHead = 15,
  kLShoulder = 16,
  kLElbow = 18,
  kLWrist = 20,
  kLHand = 22,
};

double sgnpow(double v, double e) {
  return v < 0 ? -pm::pow(-v, e) : pm::pow(v, e);
}

// Perimeter of an ellipse (Ramanujan's second approximation).
double ellipse_perimeter(double a, double b) {
  const double h = (a - b) * (a - b) / ((a + b) * (a + b));
  return kPi * (a + b) * (1 + 3 * h / (10 + std::sqrt(4 - 3 * h)));
}

// Semi-axis b such that the ellipse (a, b) has perimeter p (b >= 0.3 a).
double ellipse_b_for_perimeter(double a, double p) {
  double lo = 0.3 * a, hi = 6 * a;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ellipse_perimeter(a, mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

VertexBlend skin1(int j) {
  return {{j, 1.0}};
}
VertexBlend skin2(int a, int b, double wb) {
  if (wb <= 0) {
    return skin1(a);
  }
  if (wb >= 1) {
    return skin1(b);
  }
  return {{a, 1 - wb}, {b, wb}};
}

// A torso cross-section: superellipse with separate front and back depths.
struct TorsoSection {
  double y = 0;          // height
  double a = 0;          // half width
  double df = 0;         // front depth from the centre line
  double db = 0;         // back depth
  double cz = 0;         // centre z
  double p = 2;          // superellipse exponent
  double bust = 0;       // forward bulge of the breast vertices (i = 1..3, 13..15)
  double glute = 0;      // backward bulge of the buttock vertices (i = 6, 7, 9, 10)
  double front_dip = 0;  // cleavage: front centre pulled back
};

Eigen::Vector3d torso_point(const TorsoSection& s, int i) {
  if (i > 8) {  // exact mirror of the left half
    Eigen::Vector3d q = torso_point(s, 16 - i);
    q.x() = -q.x();
    return q;
  }
  const double th = 2 * kPi * i / 16.0;
  const double sn = pm::sin(th), cs = pm::cos(th);
  const double e = 2.0 / s.p;
  Eigen::Vector3d q(s.a * sgnpow(sn, e), s.y, s.cz + (cs >= 0 ? s.df : s.db) * sgnpow(cs, e));
  if (i == 0 || i == 8) {
    q.x() = 0.0;  // on the midline exactly
  }
  const int k = i <= 8 ? i : 16 - i;  // mirror index on the left half
  if (s.bust > 0) {
    const double w = k == 2 ? 1.0 : (k == 1 || k == 3) ? 0.65 : 0.0;
    q.z() += w * s.bust;
    if (k == 0) {
      q.z() -= s.front_dip;
    }
  }
  if (s.glute > 0) {
    const double w = (k == 6 || k == 7) ? 1.0 : k == 5 || k == 8 ? 0.45 : 0.0;
    q.z() -= w * s.glute;
  }
  return q;
}

double torso_perimeter(const TorsoSection& s) {
  double per = 0;
  for (int i = 0; i < 16; ++i) {
    const Eigen::Vector3d a = torso_point(s, i), b = torso_point(s, (i + 1) % 16);
    per += pm::hypot(a.x() - b.x(), a.z() - b.z());
  }
  return per;
}

// Chooses the exponent so that the polygon perimeter matches `target`; when the exponent range
// [1.7, 3.2] cannot reach it, the depths are scaled instead (the width is kept: it is a
// measured breadth).
void fit_exponent(TorsoSection& s, double target) {
  constexpr double kMinP = 1.7, kMaxP = 3.2;
  s.p = kMaxP;
  const double at_max = torso_perimeter(s);
  s.p = kMinP;
  const double at_min = torso_perimeter(s);
  if (target > at_max || target < at_min) {
    s.p = target > at_max ? kMaxP : kMinP;
    const TorsoSection base = s;
    double lo = 0.4, hi = 2.5;
    for (int it = 0; it < 50; ++it) {
      const double f = 0.5 * (lo + hi);
      s.df = base.df * f;
      s.db = base.db * f;
      s.bust = base.bust * f;
      s.glute = base.glute * f;
      s.front_dip = base.front_dip * f;
      (torso_perimeter(s) < target ? lo : hi) = f;
    }
    return;
  }
  double lo = kMinP, hi = kMaxP;
  for (int it = 0; it < 50; ++it) {
    s.p = 0.5 * (lo + hi);
    (torso_perimeter(s) < target ? lo : hi) = s.p;
  }
  s.p = 0.5 * (lo + hi);
}

class Builder {
 public:
  explicit Builder(Cage& c) : c_(c) {}

  bool mirrored = false;

  int vert(Eigen::Vector3d p, VertexBlend skin) {
    if (mirrored) {
      p.x() = -p.x();
      for (auto& s : skin) {
        s.first = mirror_joint(s.first);
      }
    }
    c_.positions.push_back(p);
    c_.skin.push_back(std::move(skin));
    c_.mirror.push_back(static_cast<int>(c_.positions.size()) - 1);
    return static_cast<int>(c_.positions.size()) - 1;
  }
  int quad(int a, int b, int c, int d) {
    if (mirrored) {
      c_.quads.push_back({a, d, c, b});
    } else {
      c_.quads.push_back({a, b, c, d});
    }
    return static_cast<int>(c_.quads.size()) - 1;
  }
  // Quads between two rings of equal size (ring order counter-clockwise around the growth
  // direction, on the left side; mirrored sides reverse the winding automatically).
  void connect(const std::vector<int>& a, const std::vector<int>& b) {
    const int n = static_cast<int>(a.size());
    for (int j = 0; j < n; ++j) {
      quad(a[j], a[(j + 1) % n], b[(j + 1) % n], b[j]);
    }
  }
  // connect() along a chain of rings, in order: the first to the second, the second to the
  // third, ...
  void connect_chain(std::initializer_list<std::reference_wrapper<const std::vector<int>>> rings) {
    const std::vector<int>* previous = nullptr;
    for (const std::vector<int>& ring : rings) {
      if (previous != nullptr) connect(*previous, ring);
      previous = &ring;
    }
  }
  static int mirror_joint(int j) {
    // Left joints have odd ids 1, 4, 7, 10, 13, 16, 18, 20, 22 -> right = left + 1.
    switch (j) {
      case 1:
      case 4:
      case 7:
      case 10:
      case 13:
      case 16:
      case 18:
      case 20:
      case 22:
        return j + 1;
      default:
        return j;
    }
  }

  /// The cage being built.
  Cage& cage() { return c_; }

 private:
  Cage& c_;
};

/// The heights (metres above the floor) and breadths (metres) that place the cage's stages,
/// derived from the survey dimensions; the clamps keep the levels in order for any sampled body.
struct BodyLevels {
  double stature = 0;     ///< stature: top of the head
  double crotch = 0;      ///< crotch height
  double acromion = 0;    ///< acromial (shoulder) height
  double axilla = 0;      ///< axilla height, at least 6 cm under the acromion
  double chest = 0;       ///< chest (nipple) height, at least 3 cm under the axilla
  double waist = 0;       ///< waist (omphalion) height, at least 8 cm under the chest
  double buttock = 0;     ///< buttock height, 4 cm over the crotch to 8 cm under the waist
  double cervicale = 0;   ///< cervicale height, at least 3 cm over the acromion
  double knee = 0;        ///< knee height
  double malleolus = 0;   ///< malleolus (ankle) height
  double biacromial = 0;  ///< biacromial breadth, metres
  double hand_scale = 0;  ///< hand length / 0.19 m (the reference hand), dimensionless
};

/// The levels of body `d` (kNumDims values, metres and kg, see Dim).
BodyLevels body_levels(const Eigen::VectorXd& d) {
  BodyLevels lv;
  lv.stature = d[kStature];
  lv.crotch = d[kCrotchHeight];
  lv.acromion = d[kAcromialHeight];
  lv.axilla = std::min(d[kAxillaHeight], lv.acromion - 0.06);
  lv.chest = std::min(d[kChestHeight], lv.axilla - 0.03);
  lv.waist = std::min(d[kWaistHeight], lv.chest - 0.08);
  lv.buttock = std::clamp(d[kButtockHeight], lv.crotch + 0.04, lv.waist - 0.08);
  lv.cervicale = std::max(d[kCervicaleHeight], lv.acromion + 0.03);
  lv.knee = d[kKneeHeight];
  lv.malleolus = d[kMalleolusHeight];
  lv.biacromial = d[kBiacromial];
  lv.hand_scale = d[kHandLength] / 0.19;
  return lv;
}

/// The ten torso cross-sections r0..r9 from the crotch to the shoulder line.
using TorsoSections = std::array<TorsoSection, 10>;

/// Fills the lower torso sections of `sec`: r0 (just above the crotch), r1 (buttocks, widest
/// hips), r2 (iliac crest), r3 (waist). Fits r1 to the buttock and r3 to the waist girth; `glute`
/// is the backward bulge of the buttocks (metres), `bulk` scales the unmeasured depths of r0, r2.
void lower_torso_sections(TorsoSections& sec, const Eigen::VectorXd& d, const BodyLevels& lv,
                          bool female, double glute, double bulk) {
  const double Hcr = lv.crotch, HW = lv.waist, HBt = lv.buttock;
  TorsoSection& s1 = sec[1];  // buttocks, widest hips
  s1.y = HBt;
  s1.a = d[kHipBreadth] / 2;
  s1.df = d[kButtockDepth] * 0.44;
  s1.db = d[kButtockDepth] * 0.56 - glute;
  s1.cz = -0.005;
  s1.glute = glute;
  fit_exponent(s1, d[kButtockCirc]);
  TorsoSection& s0 = sec[0];  // just above the crotch
  s0 = s1;
  s0.y = Hcr + 0.3 * (HBt - Hcr);
  s0.a = s1.a * 0.97;
  s0.df = s1.df * 0.85;
  s0.db = s1.db * 0.92;
  s0.df *= bulk;
  s0.db *= bulk;
  s0.glute = glute * 0.6;
  TorsoSection& s3 = sec[3];  // waist (omphalion)
  s3.y = HW;
  s3.a = d[kWaistBreadth] / 2;
  s3.df = d[kWaistDepth] * 0.52;
  s3.db = d[kWaistDepth] * 0.48;
  s3.cz = 0.0;
  fit_exponent(s3, d[kWaistCirc]);
  TorsoSection& s2 = sec[2];  // iliac crest
  s2.y = 0.5 * (HBt + HW);
  s2.a = 0.5 * (s1.a + s3.a) * (female ? 1.0 : 0.98);
  s2.df = 0.5 * (s1.df + s3.df);
  s2.db = 0.5 * (s1.db + s3.db);
  s2.df *= bulk;
  s2.db *= bulk;
  s2.cz = 0.5 * (s1.cz + s3.cz);
  s2.p = 0.5 * (s1.p + s3.p);
  s2.glute = glute * 0.3;
}

/// Fills the upper torso sections of `sec` from the waist r3 (already filled): r4 (lower chest),
/// r5 (chest at nipple height, fitted to the chest girth), r6 (armpits), r7 and r8 (between the
/// armpits and the shoulders), r9 (shoulder line). `bust` is the forward bulge of the breasts
/// (metres, 0 for men), `bulk` scales the unmeasured depths of r4 and r6.
void upper_torso_sections(TorsoSections& sec, const Eigen::VectorXd& d, const BodyLevels& lv,
                          bool female, double bust, double bulk) {
  const double HA = lv.acromion, HX = lv.axilla, HN = lv.chest, HW = lv.waist, bia = lv.biacromial;
  const TorsoSection& s3 = sec[3];
  TorsoSection& s5 = sec[5];  // chest at nipple height
  s5.y = HN;
  s5.a = d[kChestBreadth] / 2;
  s5.df = d[kChestDepth] * 0.5 - bust;
  s5.db = d[kChestDepth] * 0.5;
  s5.cz = 0.0;
  s5.bust = bust;
  s5.front_dip = female ? 0.25 * bust : 0.0;
  fit_exponent(s5, d[kChestCirc]);
  TorsoSection& s4 = sec[4];  // lower chest
  s4.y = HW + 0.55 * (HN - HW);
  s4.a = 0.35 * s3.a + 0.65 * s5.a;
  s4.df = 0.4 * s3.df + 0.6 * s5.df;
  s4.db = 0.4 * s3.db + 0.6 * s5.db;
  s4.df *= bulk;
  s4.db *= bulk;
  s4.p = 0.5 * (s3.p + s5.p);
  s4.bust = 0.5 * bust;
  TorsoSection& s6 = sec[6];  // armpits
  s6 = s5;
  s6.y = HX;
  s6.a = s5.a * 0.98;
  s6.df = d[kChestDepth] * 0.47 - 0.3 * bust;
  s6.db = d[kChestDepth] * 0.5 * bulk;
  s6.df *= bulk;
  s6.bust = 0.2 * bust;
  s6.front_dip = 0;
  s6.p = std::min(s5.p, 3.0);
  TorsoSection& s9 = sec[9];  // shoulder line
  s9.y = HA;
  s9.a = bia / 2 * 0.86;
  s9.df = d[kChestDepth] * 0.33;
  s9.db = d[kChestDepth] * 0.42;
  s9.cz = -0.01;
  s9.p = 2.6;
  for (int r = 7; r <= 8; ++r) {
    const double t = (r - 6) / 3.0;
    TorsoSection& s = sec[r];
    s.y = HX + t * (HA - HX);
    s.a = (1 - t) * s6.a + t * s9.a;
    s.df = (1 - t) * s6.df + t * s9.df;
    s.db = (1 - t) * s6.db + t * s9.db;
    s.cz = (1 - t) * s6.cz + t * s9.cz;
    s.p = (1 - t) * s6.p + t * s9.p;
  }
}

/// The torso cross-sections r0..r9 of body `d` (kNumDims values, metres): heights from `lv`,
/// breadths, depths and girths from the survey; `female` adds the bust and a rounder pelvis.
/// `bulk` (dimensionless, 1 = as surveyed) scales the depths between the measured levels.
TorsoSections torso_sections(const Eigen::VectorXd& d, const BodyLevels& lv, bool female,
                             double bulk) {
  TorsoSections sec;
  const double bust = female ? std::max(0.015, 0.28 * d[kChestDepth] - 0.015) : 0.0;
  const double glute = (female ? 0.022 : 0.016) + 0.1 * (d[kButtockDepth] - 0.23);
  lower_torso_sections(sec, d, lv, female, glute, bulk);
  upper_torso_sections(sec, d, lv, female, bust, bulk);
  return sec;
}

/// The ellipse where the left arm leaves the torso, in the plane x ~ acromion: ten points
/// (j = 0 top, counter-clockwise seen from the left) that replace torso vertices of r6..r9.
struct ArmRoot {
  double xa = 0;        ///< acromion x (half the biacromial breadth), metres
  double arm_ry = 0;    ///< vertical semi-axis, metres
  double arm_y = 0;     ///< centre height, metres
  double r_bic = 0;     ///< biceps radius (girth / 2 pi, scaled by bulk), metres
  double arm_rz = 0;    ///< front-back semi-axis, metres
  double arm_tilt = 0;  ///< x offset of the top and bottom against the sides, metres
  double arm_xc = 0;    ///< centre x, metres

  /// Point j (0..9) of the ring, metres.
  Eigen::Vector3d point(int j) const {
    const double ph = 2 * kPi * j / 10.0;
    return Eigen::Vector3d(arm_xc + arm_tilt * pm::cos(ph), arm_y + arm_ry * pm::cos(ph),
                           -0.012 + arm_rz * pm::sin(ph));
  }
};

/// The left arm root of body `d` between the axilla and the acromion of `lv`; `bulk` scales the
/// biceps girth.
ArmRoot arm_root(const Eigen::VectorXd& d, const BodyLevels& lv, double bulk) {
  const double HA = lv.acromion, HX = lv.axilla;
  ArmRoot ar;
  ar.xa = lv.biacromial / 2;  // acromion
  ar.arm_ry = (HA - HX) / 2;
  ar.arm_y = (HA + HX) / 2;
  ar.r_bic = d[kBicepsCirc] / (2 * kPi) * 0.92 * bulk;
  ar.arm_rz = std::max(ar.r_bic * 1.25, ar.arm_ry * 0.95);
  ar.arm_tilt = 0.018;
  ar.arm_xc = ar.xa - ar.arm_tilt;
  return ar;
}

/// The arm root point (0..9) that torso vertex (ring `r`, index `i` on the left half, 0..8)
/// becomes, or -1 if it stays a torso point.
int arm_root_index(int r, int i) {
  // Arm root point k sits at torso ring kArmRoot[k][0], left-half index kArmRoot[k][1].
  static constexpr int kArmRoot[10][2] = {{9, 4}, {9, 3}, {8, 3}, {7, 3}, {6, 3},
                                          {6, 4}, {6, 5}, {7, 5}, {8, 5}, {9, 5}};
  for (int k = 0; k < 10; ++k)
    if (kArmRoot[k][0] == r && kArmRoot[k][1] == i) return k;
  return -1;
}

/// The skinning weights of torso vertex (ring `r` 0..9, index `i` 0..15, 0 = front midline,
/// counter-clockwise seen from above, 1..7 on the left).
VertexBlend torso_skin(int r, int i) {
  const int k = i <= 8 ? i : 16 - i;  // distance from the front midline in steps
  const bool left = i > 0 && i < 8;
  const int hip = left ? kLHip : kLHip + 1;
  const int collar = left ? kLCollar : kLCollar + 1;
  const int shoulder = left ? kLShoulder : kLShoulder + 1;
  switch (r) {
    case 0:  // the hip blend spans r1 .. G1 so that 90-degree flexion does not fold the groin
      if (k == 0 || k == 8) {
        return {{kPelvis, 0.6}, {kLHip, 0.2}, {kLHip + 1, 0.2}};
      }
      return skin2(kPelvis, hip, 0.42);
    case 1:
      if (k == 0 || k == 8) {
        return {{kPelvis, 0.8}, {kLHip, 0.1}, {kLHip + 1, 0.1}};
      }
      return skin2(kPelvis, hip, 0.2);
    case 2:
      return skin2(kPelvis, kSpine1, 0.5);
    case 3:
      return skin1(kSpine1);
    case 4:
      return skin2(kSpine1, kSpine2, 0.5);
    case 5:
      return skin2(kSpine2, kSpine3, 0.5);
    case 6:
      if (k >= 3 && k <= 5) {
        return skin2(kSpine3, shoulder, 0.35);
      }
      return skin1(kSpine3);
    case 7:
    case 8:
      if (k >= 3 && k <= 5) {
        return {{kSpine3, 0.35}, {collar, 0.3}, {shoulder, 0.35}};
      }
      if (k == 2 || k == 6) {
        return skin2(kSpine3, collar, 0.3);
      }
      return skin1(kSpine3);
    default:  // 9
      if (k == 4) {
        return skin2(collar, shoulder, 0.5);
      }
      if (k == 3 || k == 5) {
        return {{collar, 0.5}, {shoulder, 0.3}, {kSpine3, 0.2}};
      }
      if (k == 2 || k == 6) {
        return skin2(kSpine3, collar, 0.55);
      }
      return skin2(kSpine3, collar, 0.2);
  }
}

/// Cage vertex ids of the torso: [ring r 0..9][index i 0..15]; -1 inside the arm holes (r7, r8
/// at i = 4 and 12).
using TorsoGrid = std::array<std::array<int, 16>, 10>;

/// Adds the torso tube to the cage: the vertices of the ten rings (`sec`, with the arm root
/// ellipse `root` and its mirror replacing the points around the arm holes; metres), the quads
/// between consecutive rings except in the 3 x 2 arm holes, and the vertices' mirror pairs.
/// Returns the vertex ids.
TorsoGrid build_torso(Builder& b, const TorsoSections& sec, const ArmRoot& root) {
  TorsoGrid T{};
  for (int r = 0; r < 10; ++r) {
    for (int i = 0; i < 16; ++i) {
      T[r][i] = -1;
      const bool hole_interior = (r == 7 || r == 8) && (i == 4 || i == 12);
      if (hole_interior) {
        continue;
      }
      Eigen::Vector3d p;
      const int li = i <= 8 ? i : 16 - i;
      const int j = arm_root_index(r, li);
      if (j >= 0) {
        p = root.point(j);
        if (i > 8) {
          p.x() = -p.x();
        }
      } else {
        p = torso_point(sec[r], i);
        if (r == 9) {  // front of the shoulder line lower, back higher
          const double cs = pm::cos(2 * kPi * i / 16.0);
          p.y() += cs > 0 ? -0.02 * cs : 0.0;
        }
      }
      T[r][i] = b.vert(p, torso_skin(r, i));
    }
  }
  for (int r = 0; r < 10; ++r) {
    for (int i = 0; i < 16; ++i) {
      if (r == 9) {
        continue;  // above the top ring: the cap
      }
      const int i1 = (i + 1) % 16;
      const bool hole = (r >= 6 && r <= 8) && (i == 3 || i == 4 || i == 11 || i == 12);
      if (hole) {
        continue;
      }
      b.quad(T[r][i], T[r][i1], T[r + 1][i1], T[r + 1][i]);
    }
  }
  for (int i = 0; i < 16; ++i) {
    const int m = (16 - i) % 16;
    for (int r = 0; r < 10; ++r) {
      if (T[r][i] >= 0) {
        b.cage().mirror[T[r][i]] = T[r][m];
      }
    }
  }
  return T;
}

/// The shoulder cap: a 4 x 4 grid over the torso's top ring with the neck hole in its middle.
struct ShoulderCap {
  /// Vertex ids by (u, v): u = 0 right .. 4 left, v = 0 back .. 4 front; -1 inside the hole.
  std::array<std::array<int, 5>, 5> grid{};
  std::vector<int> neck;  ///< the neck hole ring, 8 vertex ids counter-clockwise from the front
  double r_neck = 0;      ///< neck radius (neck girth / 2 pi, scaled by bulk), metres
};

/// Adds the shoulder cap to the cage: the grid's boundary is the top torso ring T[9], its
/// interior the neck hole ring of body `d` (neck girth scaled by `bulk`, at the cervicale height
/// `HC7`, metres) with its quads and mirror pairs.
ShoulderCap build_shoulder_cap(Builder& b, const TorsoGrid& T, const Eigen::VectorXd& d, double HC7,
                               double bulk) {
  ShoulderCap cap;
  // Grid (u, v): u = 0 right .. 4 left, v = 0 back .. 4 front. Boundary = top ring T[9].
  std::array<std::array<int, 5>, 5>& G = cap.grid;
  {
    const int bu[16] = {2, 3, 4, 4, 4, 4, 4, 3, 2, 1, 0, 0, 0, 0, 0, 1};
    const int bv[16] = {4, 4, 4, 3, 2, 1, 0, 0, 0, 0, 0, 1, 2, 3, 4, 4};
    for (auto& row : G) {
      row.fill(-1);
    }
    for (int i = 0; i < 16; ++i) {
      G[bu[i]][bv[i]] = T[9][i];
    }
  }
  // Neck hole ring (8, counter-clockwise around +y from the front).
  const int nu[8] = {2, 3, 3, 3, 2, 1, 1, 1};
  const int nv[8] = {3, 3, 2, 1, 1, 1, 2, 3};
  cap.r_neck = d[kNeckCirc] / (2 * kPi) * bulk;
  const double r_neck = cap.r_neck;
  std::vector<int>& N0 = cap.neck;
  N0.resize(8);
  for (int k = 0; k < 8; ++k) {
    const int kl = k <= 4 ? k : 8 - k;  // compute the left half, mirror exactly
    const double th = 2 * kPi * kl / 8.0;
    const double cs = pm::cos(th);
    Eigen::Vector3d p(r_neck * 1.12 * pm::sin(th), HC7 - 0.03 - 0.028 * cs,
                      -0.025 + r_neck * 1.1 * cs);
    if (k > 4) {
      p.x() = -p.x();
    }
    if (kl == 0 || kl == 4) {
      p.x() = 0.0;
    }
    const int kk = k <= 4 ? k : 8 - k;
    VertexBlend sk =
        kk == 2 ? VertexBlend{{kSpine3, 0.4}, {kNeck, 0.4}, {k < 4 ? kLCollar : kLCollar + 1, 0.2}}
                : skin2(kSpine3, kNeck, 0.5);
    N0[k] = b.vert(p, sk);
    G[nu[k]][nv[k]] = N0[k];
  }
  for (int k = 0; k < 8; ++k) {
    b.cage().mirror[N0[k]] = N0[(8 - k) % 8];
  }
  for (int u = 0; u < 4; ++u) {
    for (int v = 0; v < 4; ++v) {
      if (u >= 1 && u <= 2 && v >= 1 && v <= 2) {
        continue;  // neck hole
      }
      b.quad(G[u][v], G[u][v + 1], G[u + 1][v + 1], G[u + 1][v]);
    }
  }
  return cap;
}

/// Adds an 8-vertex ring of the neck or head at height `y` (metres): a superellipse (exponent
/// 2 / 0.85) centred at z = `cz` with half width `a`, front depth `df`, back depth `dbk` and the
/// front vertex pushed forward by `nose` (metres); all vertices skinned with `sk`. Sets the
/// mirror pairs; returns the ids counter-clockwise from the front.
std::vector<int> head_ring(Builder& b, double y, double cz, double a, double df, double dbk,
                           double nose, const VertexBlend& sk) {
  std::vector<int> ring(8);
  for (int k = 0; k < 8; ++k) {
    const int kl = k <= 4 ? k : 8 - k;  // compute the left half, mirror exactly
    const double th = 2 * kPi * kl / 8.0;
    const double sn = pm::sin(th), cs = pm::cos(th);
    Eigen::Vector3d p(a * sgnpow(sn, 0.85), y, cz + (cs >= 0 ? df : dbk) * sgnpow(cs, 0.85));
    if (k > 4) {
      p.x() = -p.x();
    }
    if (kl == 0 || kl == 4) {
      p.x() = 0.0;
    }
    if (k == 0) {
      p.z() += nose;
    }
    ring[k] = b.vert(p, sk);
  }
  for (int k = 0; k < 8; ++k) {
    b.cage().mirror[ring[k]] = ring[(8 - k) % 8];
  }
  return ring;
}

/// The rings of the neck and the head that the joints use, and the top of the head.
struct NeckAndHead {
  std::vector<int> n1, n2;  ///< neck rings over the cap and under the chin, 8 ids each
  std::vector<int> h0;      ///< the lowest head ring (at the chin), 8 ids
  int top = -1;             ///< the vertex at the top of the head
};

/// Adds the neck and the head of body `d` over the cap's neck ring `N0`: neck rings of radius
/// about `r_neck` from the cervicale (`lv`) up to the chin, head rings sized by the head breadth
/// and length up to the stature (all metres), their quads, and a 2 x 2 grid around the top
/// vertex closing the head.
NeckAndHead build_neck_and_head(Builder& b, const std::vector<int>& N0, const Eigen::VectorXd& d,
                                const BodyLevels& lv, double r_neck) {
  const double H = lv.stature, HC7 = lv.cervicale;
  const double hh = 1.72 * d[kTragionTop];  // vertex to menton
  const double chin = H - hh;
  const double hb2 = d[kHeadBreadth] / 2, hl2 = d[kHeadLength] / 2;
  NeckAndHead nh;
  const std::vector<int> N1 =
      head_ring(b, HC7 + 0.02, -0.02, r_neck * 0.98, r_neck * 0.98, r_neck, 0, skin1(kNeck));
  const std::vector<int> N2 = head_ring(b, chin + 0.01, -0.012, r_neck * 1.02, r_neck * 1.05,
                                        r_neck * 1.0, 0, skin2(kNeck, kHead, 0.5));
  const std::vector<int> H0 =
      head_ring(b, chin + 0.03, -0.003, hb2 * 0.78, hl2 * 0.92, hl2 * 0.55, 0, skin1(kHead));
  const std::vector<int> H1 = head_ring(b, chin + 0.36 * hh, -0.015, hb2 * 0.93, hl2 * 0.98,
                                        hl2 * 0.9, 0.016, skin1(kHead));
  const std::vector<int> H2 =
      head_ring(b, chin + 0.58 * hh, -0.019, hb2 * 1.0, hl2 * 0.93, hl2 * 1.0, 0.004, skin1(kHead));
  const std::vector<int> H3 =
      head_ring(b, chin + 0.82 * hh, -0.021, hb2 * 0.9, hl2 * 0.85, hl2 * 0.92, 0, skin1(kHead));
  b.connect_chain({N0, N1, N2, H0, H1, H2, H3});
  const int head_top = b.vert(Eigen::Vector3d(0, H + 0.028, -0.023), skin1(kHead));
  {
    // 3 x 3 grid: boundary H3, centre head_top. (u: 0 right..2 left, v: 0 back..2 front)
    std::array<std::array<int, 3>, 3> g{};
    const int cu[8] = {1, 2, 2, 2, 1, 0, 0, 0};
    const int cv[8] = {2, 2, 1, 0, 0, 0, 1, 2};
    for (int k = 0; k < 8; ++k) {
      g[cu[k]][cv[k]] = H3[k];
    }
    g[1][1] = head_top;
    for (int u = 0; u < 2; ++u) {
      for (int v = 0; v < 2; ++v) {
        b.quad(g[u][v], g[u][v + 1], g[u + 1][v + 1], g[u + 1][v]);
      }
    }
  }
  nh.n1 = N1;
  nh.n2 = N2;
  nh.h0 = H0;
  nh.top = head_top;
  return nh;
}

/// The quantities that place the left arm and hand along +x (T-pose), metres unless noted.
struct ArmDims {
  double xa = 0;          ///< acromion x
  double r_bic = 0;       ///< biceps radius (girth / 2 pi, scaled by bulk)
  double hand_len = 0;    ///< hand length
  double x_w = 0;         ///< wrist x: half the span less the hand
  double x_e = 0;         ///< elbow x: splits acromion-wrist as upper arm : forearm
  double y_axis = 0;      ///< height of the arm's axis
  double r_fa = 0;        ///< forearm radius
  double r_wr = 0;        ///< wrist radius
  double palm = 0;        ///< palm length (along x)
  double hand_w = 0;      ///< hand breadth (along z)
  double hand_t = 0;      ///< hand thickness (along y)
  double hand_scale = 0;  ///< hand length / 0.19 m, dimensionless
};

/// The arm of body `d` (kNumDims values, metres) from its arm root `root` and levels `lv`;
/// `bulk` scales the forearm girth (and the wrist's by its square root).
ArmDims arm_dims(const Eigen::VectorXd& d, const BodyLevels& lv, const ArmRoot& root, double bulk) {
  const double HA = lv.acromion, hand_scale = lv.hand_scale;
  const double xa = root.xa, r_bic = root.r_bic;
  ArmDims a;
  a.xa = xa;
  a.r_bic = r_bic;
  a.hand_scale = hand_scale;
  const double span2 = d[kSpan] / 2;
  const double hand_len = d[kHandLength];
  const double x_w = span2 - hand_len * 0.97;
  const double ua = d[kAcromionRadiale], fa = d[kRadialeStylion];
  a.hand_len = hand_len;
  a.x_w = x_w;
  a.x_e = xa + (x_w - xa) * ua / (ua + fa);
  a.y_axis = HA - r_bic - 0.012;
  a.r_fa = d[kForearmCirc] / (2 * kPi) * 0.9 * bulk;
  a.r_wr = d[kWristCirc] / (2 * kPi) * std::sqrt(bulk);
  a.palm = 0.56 * hand_len;
  a.hand_w = d[kHandBreadth] * 0.95;
  a.hand_t = 0.026 * hand_scale;
  return a;
}

/// The cage vertices and faces of one arm that the joints and landmarks use.
struct ArmIds {
  std::vector<int> all;                    ///< every vertex the arm added, in order of creation
  std::vector<int> root, a1, a4, a7, p2;   ///< the root ring (torso vertices), A1, elbow A4,
                                           ///< wrist A7 and the palm's end ring P2 (10 ids each)
  int tip_face[5] = {-1, -1, -1, -1, -1};  ///< fingertip faces: 0..3 index to little, 4 thumb
};

/// Adds an elliptic arm ring of 10 vertices in the plane x = `x` (metres), centred at (`yc`,
/// `zc`) with semi-axes `ry`, `rz` (metres), j = 0 on top; all skinned with `sk`. Appends the
/// ids to `ids.all` and returns them.
std::vector<int> arm_ring(Builder& b, ArmIds& ids, double x, double yc, double zc, double ry,
                          double rz, const VertexBlend& sk) {
  std::vector<int> r(10);
  for (int j = 0; j < 10; ++j) {
    const double ph = 2 * kPi * j / 10.0;
    r[j] = b.vert(Eigen::Vector3d(x, yc + ry * pm::cos(ph), zc + rz * pm::sin(ph)), sk);
    ids.all.push_back(r[j]);
  }
  return r;
}

/// Adds a palm ring of 10 vertices: a rounded rectangle in the plane x = `x` (metres; its back
/// column 6% of the palm length `palm` nearer the wrist), centred at height `yc`, `w` wide (z)
/// and `t` thick (y); top row j = 2,1,0,9,8 and bottom row j = 3..7, front to back. All skinned
/// with `sk`. Appends the ids to `ids.all` and returns them.
std::vector<int> palm_ring(Builder& b, ArmIds& ids, double palm, double x, double yc, double w,
                           double t, const VertexBlend& sk) {
  std::vector<int> r(10);
  const int top[5] = {2, 1, 0, 9, 8};
  const int bot[5] = {3, 4, 5, 6, 7};
  const double zs[5] = {0.5, 0.25, 0.0, -0.25, -0.5};
  for (int j = 0; j < 10; ++j) {
    int c = 0;
    bool is_top = false;
    for (int k = 0; k < 5; ++k) {
      if (top[k] == j) {
        c = k;
        is_top = true;
      }
      if (bot[k] == j) {
        c = k;
      }
    }
    const double edge = (c == 0 || c == 4) ? 0.75 : 1.0;  // rounded sides
    const double xx = x - ((c == 4) ? 0.06 * palm : 0.0);
    r[j] = b.vert(Eigen::Vector3d(xx, yc + (is_top ? 0.5 : -0.5) * t * edge, zs[c] * w), sk);
    ids.all.push_back(r[j]);
  }
  return r;
}

/// Adds the thumb: three 4-vertex rings extruded from the quad hole (A7[2], A7[3], P1[3], P1[2])
/// between the wrist ring `A7` and the palm ring `P1`, forward, down and outward, sized by
/// `hand_scale` (hand length / 0.19 m), and the tip quad. Appends the vertex ids to `ids.all`;
/// returns the tip face id.
int build_thumb(Builder& b, ArmIds& ids, const std::vector<int>& A7, const std::vector<int>& P1,
                double hand_scale) {
  const std::vector<int> R = {A7[2], A7[3], P1[3], P1[2]};
  Eigen::Vector3d base = Eigen::Vector3d::Zero();
  for (int v : R) {
    base += b.cage().positions[v];
  }
  base /= 4;
  if (b.mirrored) {
    base.x() = -base.x();  // work in left coordinates
  }
  const Eigen::Vector3d dir = Eigen::Vector3d(0.55, -0.3, 0.78).normalized();
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitY().cross(dir).normalized();
  const Eigen::Vector3d ey = dir.cross(ex).normalized();
  const double sx[4] = {-1, -1, 1, 1};
  const double sy[4] = {1, -1, -1, 1};
  std::vector<int> prev = R;
  const double dist[3] = {0.024, 0.046, 0.064};
  const double rad[3] = {0.0115, 0.0105, 0.0095};
  const VertexBlend tsk[3] = {skin2(kLWrist, kLHand, 0.5), skin1(kLHand), skin1(kLHand)};
  for (int t = 0; t < 3; ++t) {
    std::vector<int> cur(4);
    for (int m = 0; m < 4; ++m) {
      const Eigen::Vector3d p = base + dist[t] * hand_scale * dir +
                                rad[t] * hand_scale * (sx[m] * ex * 1.05 + sy[m] * ey * 0.9);
      cur[m] = b.vert(p, tsk[t]);
      ids.all.push_back(cur[m]);
    }
    b.connect(prev, cur);
    prev = cur;
  }
  return b.quad(prev[0], prev[1], prev[2], prev[3]);
}

/// Adds the four fingers (index to little, k = 0..3) on the palm's end grid `P2`: from the
/// columns T_c = P2[2,1,0,9,8][c], B_c = P2[3,4,5,6,7][c], three tapering 4-vertex rings each
/// out to the finger's length (a share of the hand length less the palm, `a`, metres) and a tip
/// quad. Appends the vertex ids to `ids.all` and sets `ids.tip_face[0..3]`.
void build_fingers(Builder& b, ArmIds& ids, const std::vector<int>& P2, const ArmDims& a) {
  const double hand_len = a.hand_len, palm = a.palm, x_w = a.x_w, hand_w = a.hand_w;
  const double hand_scale = a.hand_scale, y_axis = a.y_axis;
  const int top[5] = {2, 1, 0, 9, 8};
  const int bot[5] = {3, 4, 5, 6, 7};
  const double flen = hand_len - palm;
  const double rel_len[4] = {0.93, 1.0, 0.95, 0.78};
  const double x0 = x_w + palm;
  for (int k = 0; k < 4; ++k) {
    std::vector<int> prev = {P2[top[k]], P2[bot[k]], P2[bot[k + 1]], P2[top[k + 1]]};
    const double zc = (0.375 - 0.25 * k) * hand_w * 1.02;
    const double hw = hand_w / 8 * 0.78;
    const double ht = 0.0088 * hand_scale;
    const double L = flen * rel_len[k];
    const double frac[3] = {0.3, 0.64, 0.98};
    const double taper[3] = {1.0, 0.92, 0.82};
    const VertexBlend fsk[3] = {skin1(kLHand), skin1(kLHand), skin1(kLHand)};
    const double dy_off = -0.004;
    for (int t = 0; t < 3; ++t) {
      const double x = x0 + frac[t] * L - (k == 3 ? 0.05 * palm : 0.0);
      const double oy[4] = {ht, -ht, -ht, ht};
      const double oz[4] = {hw, hw, -hw, -hw};
      std::vector<int> cur(4);
      for (int m = 0; m < 4; ++m) {
        cur[m] = b.vert(
            Eigen::Vector3d(x, y_axis + dy_off + oy[m] * taper[t], zc + oz[m] * taper[t]), fsk[t]);
        ids.all.push_back(cur[m]);
      }
      b.connect(prev, cur);
      prev = cur;
    }
    ids.tip_face[k] = b.quad(prev[0], prev[1], prev[2], prev[3]);
  }
}

/// Adds one arm (the left one, or with `mirrored` its mirror image, right joints and reversed
/// winding) on the torso's arm hole (vertices of `T`): seven tube rings from the shoulder to the
/// wrist, two palm rings, the thumb and the fingers, placed by `a` (metres). Returns its ids.
ArmIds build_arm(Builder& b, const TorsoGrid& T, const ArmDims& a, bool mirrored) {
  const double xa = a.xa, x_e = a.x_e, x_w = a.x_w, y_axis = a.y_axis, r_bic = a.r_bic;
  const double r_fa = a.r_fa, r_wr = a.r_wr, palm = a.palm, hand_w = a.hand_w, hand_t = a.hand_t;
  b.mirrored = mirrored;
  ArmIds ids;
  // root ring from the torso
  std::vector<int> root(10);
  {
    const int ri[10] = {9, 9, 8, 7, 6, 6, 6, 7, 8, 9};
    const int ii[10] = {4, 3, 3, 3, 3, 4, 5, 5, 5, 5};
    for (int j = 0; j < 10; ++j) {
      const int i = mirrored ? (16 - ii[j]) % 16 : ii[j];
      root[j] = T[ri[j]][i];
    }
  }
  ids.root = root;
  const auto A1 = arm_ring(b, ids, xa + 0.028, y_axis + 0.004, -0.01, r_bic * 1.12, r_bic * 1.12,
                           skin2(kLCollar, kLShoulder, 0.8));
  const auto A2 = arm_ring(b, ids, xa + 0.45 * (x_e - xa), y_axis, -0.004, r_bic * 0.98,
                           r_bic * 1.0, skin1(kLShoulder));
  const auto A3 = arm_ring(b, ids, x_e - 0.045, y_axis, 0, r_bic * 0.84, r_bic * 0.9,
                           skin2(kLShoulder, kLElbow, 0.15));
  const double r_el = 0.45 * r_bic + 0.55 * r_fa;
  const auto A4 =
      arm_ring(b, ids, x_e, y_axis, 0, r_el * 0.8, r_el * 0.95, skin2(kLShoulder, kLElbow, 0.5));
  const auto A5 = arm_ring(b, ids, x_e + 0.3 * (x_w - x_e), y_axis, 0.002, r_fa * 0.82, r_fa * 1.05,
                           skin2(kLShoulder, kLElbow, 0.88));
  const double r_lf = 0.5 * (r_fa + r_wr);
  const auto A6 = arm_ring(b, ids, x_e + 0.68 * (x_w - x_e), y_axis, 0.003, r_lf * 0.75,
                           r_lf * 1.15, skin1(kLElbow));
  const auto A7 =
      arm_ring(b, ids, x_w, y_axis, 0.004, r_wr * 0.68, r_wr * 1.22, skin2(kLElbow, kLWrist, 0.5));
  const auto P1 = palm_ring(b, ids, palm, x_w + 0.45 * palm, y_axis - 0.002, hand_w * 0.92, hand_t,
                            skin1(kLWrist));
  const auto P2 = palm_ring(b, ids, palm, x_w + palm, y_axis - 0.004, hand_w, hand_t * 0.85,
                            skin2(kLWrist, kLHand, 0.4));
  ids.a1 = A1;
  ids.a4 = A4;
  ids.a7 = A7;
  ids.p2 = P2;
  b.connect_chain({root, A1, A2, A3, A4, A5, A6, A7});
  // A7 -> P1 with the thumb quad (j = 2) left open
  for (int j = 0; j < 10; ++j) {
    if (j == 2) {
      continue;
    }
    b.quad(A7[j], A7[(j + 1) % 10], P1[(j + 1) % 10], P1[j]);
  }
  b.connect(P1, P2);
  ids.tip_face[4] = build_thumb(b, ids, A7, P1, a.hand_scale);
  build_fingers(b, ids, P2, a);
  b.mirrored = false;
  return ids;
}

/// Pairs the vertices `left` and `right` (one limb and its mirror, created in the same order)
/// as mirror images in `cage.mirror`.
void pair_mirrors(Cage& cage, const std::vector<int>& left, const std::vector<int>& right) {
  for (std::size_t k = 0; k < left.size(); ++k) {
    cage.mirror[left[k]] = right[k];
    cage.mirror[right[k]] = left[k];
  }
}
/// The cage vertices of one leg that the joints and landmarks use.
struct LegIds {
  std::vector<int> all;                   ///< every vertex the leg added, in order of creation
  std::vector<int> root, g4, g8, f1, f3;  ///< the root ring (torso r0 and the crotch), knee G4,
                                          ///< ankle G8, heel F1, ball of the foot F3 (10 ids each)
  int heel = -1, sole = -1;               ///< the heel and sole landmark vertices
};

/// Adds a leg ring of 10 vertices centred at `c` in the plane of the unit vectors `u` (outward)
/// and `v` (the leg's front): semi-axes `a` along u and `bb` along v, the back bulged out by
/// `back_bulge` sin^2 and the front by `front_bulge` sin^3 (metres); vertex j at 225 + 36 j
/// degrees from u. All skinned with `sk`. Appends the ids to `ids.all` and returns them.
std::vector<int> leg_ring(Builder& b, LegIds& ids, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& u, const Eigen::Vector3d& v, double a, double bb,
                          double back_bulge, double front_bulge, const VertexBlend& sk) {
  std::vector<int> r(10);
  for (int j = 0; j < 10; ++j) {
    const double ph = (225.0 + 36.0 * j) * kPi / 180.0;
    const double cs = pm::cos(ph), sn = pm::sin(ph);
    double bv = bb * sn;
    if (sn < 0) {
      bv -= back_bulge * sn * sn;
    }
    if (sn > 0) {
      bv += front_bulge * sn * sn * sn;
    }
    r[j] = b.vert(c + a * cs * u + bv * v, sk);
    ids.all.push_back(r[j]);
  }
  return r;
}

/// Adds the eight horizontal rings G1..G8 of the left leg of body `d` (kNumDims values, metres)
/// from under the crotch over the knee to over the malleolus (heights `lv`): thigh, knee, calf and
/// ankle girths (scaled by `bulk`) around the axis x ~ `x_t`; the ankle ring G8 at (`x_a`, `z_a`)
/// (metres). Returns the rings' ids.
std::array<std::vector<int>, 8> leg_tube(Builder& b, LegIds& ids, const Eigen::VectorXd& d,
                                         const BodyLevels& lv, double x_t, double x_a, double z_a,
                                         double bulk) {
  const double Hcr = lv.crotch, HK = lv.knee, HM = lv.malleolus;
  const Eigen::Vector3d ux = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d vz = Eigen::Vector3d::UnitZ();
  std::array<std::vector<int>, 8> G;
  const double r_th = d[kThighCirc] / (2 * kPi) * 0.97 * bulk;
  const double ax1 = std::min(x_t - 0.006, r_th * 0.97);
  const double bz1 = ellipse_b_for_perimeter(ax1, 2 * kPi * r_th);
  G[0] = leg_ring(b, ids, {x_t, Hcr - 0.03, -0.004}, ux, vz, ax1, bz1, 0.0, 0.0,
                  skin2(kPelvis, kLHip, 0.62));
  const double r_lt = d[kLowerThighCirc] / (2 * kPi) * bulk;
  const double r_mid = 0.5 * (r_th + r_lt) * 0.98;
  const double ax2 = std::min(x_t - 0.008, r_mid);
  G[1] = leg_ring(b, ids, {x_t - 0.004, Hcr - 0.4 * (Hcr - HK), 0.004}, ux, vz, ax2,
                  ellipse_b_for_perimeter(ax2, 2 * kPi * r_mid), 0.0, 0.0,
                  skin2(kPelvis, kLHip, 0.88));
  G[2] = leg_ring(b, ids, {x_t - 0.008, HK + 0.085, 0.006}, ux, vz, r_lt * 0.95, r_lt * 0.98, 0.0,
                  0.0, skin2(kLHip, kLKnee, 0.2));
  const double r_kn = r_lt * 0.88;
  G[3] = leg_ring(b, ids, {x_t - 0.01, HK, 0.008}, ux, vz, r_kn, r_kn * 0.98, 0.0, 0.008,
                  skin2(kLHip, kLKnee, 0.5));
  const double r_cf = d[kCalfCirc] / (2 * kPi) * bulk;
  G[4] = leg_ring(b, ids, {x_t - 0.011, HK - 0.055, 0.002}, ux, vz, r_kn * 0.9, r_kn * 0.88, 0.004,
                  0.0, skin2(kLHip, kLKnee, 0.85));
  const double y_calf = HK - 0.3 * (HK - HM);
  G[5] = leg_ring(b, ids, {x_t - 0.011, y_calf, -0.012}, ux, vz, r_cf * 0.9, r_cf * 0.96, 0.012,
                  0.0, skin1(kLKnee));
  const double r_an = d[kAnkleCirc] / (2 * kPi) * 0.96 * bulk;
  G[6] =
      leg_ring(b, ids, {x_t - 0.01, HM + 0.42 * (y_calf - HM), -0.012}, ux, vz,
               0.5 * (r_cf + r_an) * 0.82, 0.5 * (r_cf + r_an) * 0.84, 0.004, 0.0, skin1(kLKnee));
  G[7] = leg_ring(b, ids, {x_a, HM + 0.028, z_a}, ux, vz, r_an * 0.85, r_an * 0.9, 0.0, 0.0,
                  skin2(kLKnee, kLAnkle, 0.55));
  return G;
}

/// Adds the five rings F1..F5 of the left foot, bending forward from the ankle (x = `x_a`,
/// z = `z_a`, metres) to the toes: F1 tilted 45 degrees at the heel, F2..F5 vertical along the
/// foot of length `foot_len` and breadth `foot_w` (metres). Returns the rings' ids.
std::array<std::vector<int>, 5> foot_rings(Builder& b, LegIds& ids, double x_a, double z_a,
                                           double foot_len, double foot_w) {
  const Eigen::Vector3d ux = Eigen::Vector3d::UnitX();
  const double z_heel = z_a - 0.24 * foot_len;
  const Eigen::Vector3d e1 = Eigen::Vector3d(0, -1, 1).normalized();
  const Eigen::Vector3d v1 = e1.cross(ux);  // (0, 1, 1)/sqrt2 -> leg "front" goes up-front
  const Eigen::Vector3d vy = Eigen::Vector3d::UnitY();
  std::array<std::vector<int>, 5> F;
  F[0] = leg_ring(b, ids, {x_a, 0.052, z_heel + 0.062}, ux, v1, foot_w * 0.36, 0.062, 0.0, 0.0,
                  skin1(kLAnkle));
  F[1] = leg_ring(b, ids, {x_a + 0.004, 0.038, z_heel + 0.45 * foot_len}, ux, vy, foot_w * 0.44,
                  0.036, 0.0, 0.0, skin1(kLAnkle));
  F[2] = leg_ring(b, ids, {x_a + 0.006, 0.024, z_heel + 0.72 * foot_len}, ux, vy, foot_w * 0.52,
                  0.024, 0.0, 0.0, skin2(kLAnkle, kLFoot, 0.4));
  F[3] = leg_ring(b, ids, {x_a + 0.003, 0.019, z_heel + 0.88 * foot_len}, ux, vy, foot_w * 0.46,
                  0.018, 0.0, 0.0, skin1(kLFoot));
  F[4] = leg_ring(b, ids, {x_a, 0.016, z_heel + 0.985 * foot_len}, ux, vy, foot_w * 0.34, 0.012,
                  0.0, 0.0, skin1(kLFoot));
  return F;
}

/// Adds one leg of body `d` (the left one, or with `mirrored` its mirror image, right joints and
/// reversed winding): its root ring is the left (right) half of the torso's bottom ring T[0] and
/// the `crotch` vertex; then the leg tube, the foot, their quads and the toe cap (1 x 4 grid).
/// Hip breadth, foot length and breadth in metres; `bulk` scales the girths. Returns its ids.
LegIds build_leg(Builder& b, const TorsoGrid& T, int crotch, const Eigen::VectorXd& d,
                 const BodyLevels& lv, double bulk, bool mirrored) {
  const double x_t = d[kHipBreadth] / 4 + 0.004;
  const double foot_len = d[kFootLength];
  const double foot_w = d[kFootBreadth];
  const double x_a = x_t - 0.008;
  const double z_a = -0.01;
  b.mirrored = mirrored;
  LegIds ids;
  // The left ring's order in mirrored coordinates: the mirrored builder reverses the quads.
  std::vector<int> root(10);
  for (int j = 0; j < 9; ++j) {
    const int i = 8 - j;
    root[j] = T[0][mirrored ? (16 - i) % 16 : i];
  }
  root[9] = crotch;
  ids.root = root;
  const std::array<std::vector<int>, 8> G = leg_tube(b, ids, d, lv, x_t, x_a, z_a, bulk);
  const std::array<std::vector<int>, 5> F = foot_rings(b, ids, x_a, z_a, foot_len, foot_w);
  ids.g4 = G[3];
  ids.g8 = G[7];
  ids.f1 = F[0];
  ids.f3 = F[2];
  ids.heel = F[0][1];  // phi = 261 deg: back-bottom of the bend
  ids.sole = F[2][1];  // phi = 261 deg: bottom of the ball
  b.connect(root, G[0]);
  for (int k = 0; k + 1 < 8; ++k) {
    b.connect(G[k], G[k + 1]);
  }
  b.connect(G[7], F[0]);
  for (int k = 0; k + 1 < 5; ++k) {
    b.connect(F[k], F[k + 1]);
  }
  const std::vector<int>& F5 = F[4];
  for (int c = 0; c < 4; ++c) {
    b.quad(F5[c], F5[c + 1], F5[8 - c], F5[9 - c]);
  }
  b.mirrored = false;
  return ids;
}

/// The ids of every stage of one cage, which the joints and landmarks are made of.
struct CageParts {
  TorsoGrid torso{};  ///< the torso rings
  ShoulderCap cap;    ///< the shoulder cap and the neck's bottom ring
  NeckAndHead head;   ///< the neck and head rings and the top of the head
  ArmIds arm[2];      ///< left, right arm
  int crotch = -1;    ///< the crotch vertex
  LegIds leg[2];      ///< left, right leg
};

/// A blend giving each vertex of `ids` the weight w / ids.size() (a mean scaled by `w`).
VertexBlend mean_of(const std::vector<int>& ids, double w) {
  VertexBlend bl;
  for (int v : ids) {
    bl.emplace_back(v, w / static_cast<double>(ids.size()));
  }
  return bl;
}

/// The blend `a` followed by `bb` (their weights add).
VertexBlend add(VertexBlend a, const VertexBlend& bb) {
  a.insert(a.end(), bb.begin(), bb.end());
  return a;
}

/// The vertices of torso ring `r` (all 16, less the arm hole interiors).
std::vector<int> torso_ring(const TorsoGrid& T, int r) {
  std::vector<int> ids;
  for (int i = 0; i < 16; ++i) {
    if (T[r][i] >= 0) {
      ids.push_back(T[r][i]);
    }
  }
  return ids;
}

/// The 7 vertices of torso ring `r` strictly on the `left` (else right) side of the midline.
std::vector<int> half_ring(const TorsoGrid& T, int r, bool left) {
  std::vector<int> ids;
  for (int i = 1; i < 8; ++i) {
    ids.push_back(T[r][left ? i : 16 - i]);
  }
  return ids;
}

/// Sets `cage.joints`: SMPL's 24 joints as blends (weights sum to 1) of the vertices of `p`.
void set_joints(Cage& cage, const CageParts& p) {
  const TorsoGrid& T = p.torso;
  const auto& G = p.cap.grid;
  const std::vector<int>& N0 = p.cap.neck;
  cage.joints.assign(24, {});
  cage.joints[kPelvis] = add(mean_of(torso_ring(T, 0), 0.5), mean_of(torso_ring(T, 1), 0.5));
  for (int s = 0; s < 2; ++s) {
    const LegIds& leg = p.leg[s];
    const ArmIds& arm = p.arm[s];
    // hip joint: between the leg root and the hip ring, pulled forward towards the groin (the
    // femoral head lies in front of the buttock's mid-plane; this also keeps the groin crease
    // from folding in 90-degree flexion)
    const std::vector<int> groin = {T[0][s == 0 ? 1 : 15], T[0][s == 0 ? 2 : 14],
                                    T[0][s == 0 ? 3 : 13]};
    cage.joints[kLHip + s] = add(add(mean_of(leg.root, 0.4), mean_of(half_ring(T, 1, s == 0), 0.2)),
                                 mean_of(groin, 0.4));
    cage.joints[kLKnee + s] = mean_of(leg.g4, 1.0);
    cage.joints[kLAnkle + s] = add(mean_of(leg.g8, 0.75), mean_of(leg.f1, 0.25));
    cage.joints[kLFoot + s] = mean_of(leg.f3, 1.0);
    const std::vector<int> collar_ids = {G[s == 0 ? 3 : 1][1], G[s == 0 ? 3 : 1][3],
                                         G[s == 0 ? 3 : 1][2], N0[s == 0 ? 2 : 6]};
    cage.joints[kLCollar + s] = add(mean_of(collar_ids, 0.7), mean_of(arm.root, 0.3));
    // Shoulder (glenohumeral) joint: inside the shoulder, medial of and below the acromion
    // (the humeral head's centre lies under the acromion, about 2.5 cm medial of its lateral
    // edge and 5 cm under the skin point). The arm root ring alone puts it 7 mm medial; the
    // torso points in front of and behind the armpit pull it the rest of the way. With the
    // acromion fixed, the hanging arm is then longer than the T-posed arm by the joint's
    // depth, which is how ANSUR's span, biacromial breadth and hanging-arm lengths agree
    // (docs/models.md).
    std::vector<int> armpit;
    for (int r = 6; r <= 9; ++r) {
      armpit.push_back(T[r][s == 0 ? 2 : 14]);
      armpit.push_back(T[r][s == 0 ? 6 : 10]);
    }
    cage.joints[kLShoulder + s] = add(mean_of(arm.root, 0.65), mean_of(armpit, 0.35));
    cage.joints[kLElbow + s] = mean_of(arm.a4, 1.0);
    cage.joints[kLWrist + s] = mean_of(arm.a7, 1.0);
    cage.joints[kLHand + s] = mean_of(arm.p2, 1.0);
  }
  cage.joints[kSpine1] = mean_of(torso_ring(T, 2), 1.0);
  cage.joints[kSpine2] = mean_of(torso_ring(T, 4), 1.0);
  cage.joints[kSpine3] = add(mean_of(torso_ring(T, 5), 0.5), mean_of(torso_ring(T, 6), 0.5));
  cage.joints[kNeck] = add(mean_of(N0, 0.6), mean_of(p.head.n1, 0.4));
  cage.joints[kHead] = add(mean_of(p.head.n2, 0.5), mean_of(p.head.h0, 0.5));
}

/// Sets `cage.landmarks` (named cage vertices) and `cage.face_landmarks` (the fingertips, as
/// face centres) from the vertices of `p`.
void set_landmarks(Cage& cage, const CageParts& p) {
  const TorsoGrid& T = p.torso;
  auto& L = cage.landmarks;
  L["head_top"] = {p.head.top};
  L["crotch"] = {p.crotch};
  L["navel"] = {T[3][0]};
  L["torso_back"] = {T[3][8]};
  for (int s = 0; s < 2; ++s) {
    const std::string side = s == 0 ? "left_" : "right_";
    const ArmIds& arm = p.arm[s];
    // Torso vertex of ring r: index i on the left half, its mirror image 16 - i on the right.
    auto torso = [&](int r, int i) { return std::vector<int>{T[r][s == 0 ? i : 16 - i]}; };
    L[side + "shoulder"] = torso(9, 4);
    L[side + "hip"] = torso(1, 4);
    L[side + "nipple"] = torso(5, 2);
    L[side + "waist"] = torso(3, 4);
    L[side + "chest"] = torso(5, 4);
    L[side + "wrist"] = {arm.a7[2], arm.a7[3]};
    L[side + "elbow"] = {arm.a4[2], arm.a4[3]};
    L[side + "heel"] = {p.leg[s].heel};
    L[side + "sole"] = {p.leg[s].sole};
    cage.face_landmarks[side + "fingertip"] = {arm.tip_face[1]};
  }
}
}  // namespace

Cage build_cage(const Eigen::VectorXd& d, bool female, double bulk) {
  Cage cage;
  Builder b(cage);
  CageParts p;
  const BodyLevels lv = body_levels(d);
  const ArmRoot arm_base = arm_root(d, lv, bulk);
  p.torso = build_torso(b, torso_sections(d, lv, female, bulk), arm_base);
  p.cap = build_shoulder_cap(b, p.torso, d, lv.cervicale, bulk);
  p.head = build_neck_and_head(b, p.cap.neck, d, lv, p.cap.r_neck);
  const ArmDims arms = arm_dims(d, lv, arm_base, bulk);
  p.arm[0] = build_arm(b, p.torso, arms, false);
  p.arm[1] = build_arm(b, p.torso, arms, true);
  pair_mirrors(cage, p.arm[0].all, p.arm[1].all);
  p.crotch = b.vert(Eigen::Vector3d(0, lv.crotch, -0.012),
                    {{kPelvis, 0.4}, {kLHip, 0.3}, {kLHip + 1, 0.3}});
  p.leg[0] = build_leg(b, p.torso, p.crotch, d, lv, bulk, false);
  p.leg[1] = build_leg(b, p.torso, p.crotch, d, lv, bulk, true);
  pair_mirrors(cage, p.leg[0].all, p.leg[1].all);
  set_joints(cage, p);
  set_landmarks(cage, p);
  return cage;
}

}  // namespace modelgen
