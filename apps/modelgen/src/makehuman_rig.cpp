/// \file makehuman_rig.cpp
/// MakeHuman's rig mapped onto SMPL's 24 joints, the baked T-pose and the joint regressor
/// (makehuman_rig.hpp).
///
/// Sections: asset folder; joint and segment tables; rigid transforms; T-pose; merged weights;
/// joint regressor; template model.
#include "makehuman_rig.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "caliper/measurements.hpp"
#include "makehuman_landmarks.hpp"
#include "validation.hpp"

namespace modelgen::mh {

// ------------------------------------------------------------------------------------------------
// Asset folder
// ------------------------------------------------------------------------------------------------

Assets read_assets(const std::string& dir) {
  Assets a;
  a.dir = dir;
  a.base = read_base_mesh(dir + "/3dobjs/base.obj");
  const int n = static_cast<int>(a.base.vertices.rows());
  a.skin = skin_mesh(a.base);
  a.skeleton = read_skeleton(dir + "/rigs/default.mhskel", n);
  a.weights = read_weights(dir + "/rigs/default_weights.mhw", n);
  for (const auto& [bone, list] : a.weights) {
    (void)list;
    a.skeleton.bone(bone);  // throws for a weighted bone the skeleton lacks
  }
  for (const std::string& b : smpl_joint_bones()) {
    a.skeleton.bone(b);
  }
  return a;
}

Target read_asset_target(const Assets& assets, const std::string& relative) {
  return read_target(assets.dir + "/targets/" + relative,
                     static_cast<int>(assets.base.vertices.rows()));
}

// ------------------------------------------------------------------------------------------------
// Joint and segment tables
// ------------------------------------------------------------------------------------------------

const std::vector<std::string>& smpl_joint_bones() {
  // The MakeHuman bone at each SMPL joint, by name; the order comes from smpl_joint_names().
  // MakeHuman's ".L" is the subject's left (+X). The spine joints are spaced as SMPL's: spine1
  // about 11 cm above the pelvis joint, spine3 at mid-chest, 16 cm below the neck.
  static const std::vector<std::string> bones = [] {
    static const std::map<std::string, std::string> bone_of_joint = {
        {"pelvis", "spine05"},
        {"left_hip", "upperleg01.L"},
        {"right_hip", "upperleg01.R"},
        {"spine1", "spine03"},
        {"left_knee", "lowerleg01.L"},
        {"right_knee", "lowerleg01.R"},
        {"spine2", "spine02"},
        {"left_ankle", "foot.L"},
        {"right_ankle", "foot.R"},
        {"spine3", "spine01"},
        {"left_foot", "toe3-1.L"},
        {"right_foot", "toe3-1.R"},
        {"neck", "neck01"},
        {"left_collar", "clavicle.L"},
        {"right_collar", "clavicle.R"},
        {"head", "head"},
        {"left_shoulder", "upperarm01.L"},
        {"right_shoulder", "upperarm01.R"},
        {"left_elbow", "lowerarm01.L"},
        {"right_elbow", "lowerarm01.R"},
        {"left_wrist", "wrist.L"},
        {"right_wrist", "wrist.R"},
        {"left_hand", "finger3-1.L"},
        {"right_hand", "finger3-1.R"}};
    std::vector<std::string> b;
    for (const std::string& joint : smpl::smpl_joint_names()) b.push_back(bone_of_joint.at(joint));
    return b;
  }();
  return bones;
}

int smpl_segment(const Skeleton& skeleton, const std::string& bone) {
  // Segments start at a listed bone; fingers (all five, from their first phalanx) are the hand,
  // toes the foot; the root, pelvis and the two lower spine bones the pelvis.
  static const std::map<std::string, int> starts = [] {
    std::map<std::string, int> m;
    const auto& b = smpl_joint_bones();
    for (std::size_t k = 0; k < b.size(); ++k) {
      m[b[k]] = static_cast<int>(k);
    }
    m["root"] = 0;
    for (const char* side : {".L", ".R"}) {
      const int hand = side[1] == 'L' ? 22 : 23;
      const int foot = side[1] == 'L' ? 10 : 11;
      for (int f = 1; f <= 5; ++f) {
        m["finger" + std::to_string(f) + "-1" + side] = hand;
        m["toe" + std::to_string(f) + "-1" + side] = foot;
      }
    }
    return m;
  }();
  int b = skeleton.bone(bone);
  for (;;) {
    const auto it = starts.find(skeleton.bones[static_cast<std::size_t>(b)].name);
    if (it != starts.end()) {
      return it->second;
    }
    const std::string& parent = skeleton.bones[static_cast<std::size_t>(b)].parent;
    if (parent.empty()) {
      return 0;
    }
    b = skeleton.bone(parent);
  }
}

Eigen::Matrix<double, 24, 3, Eigen::RowMajor> smpl_joints(const Assets& assets,
                                                          const Positions& positions) {
  Eigen::Matrix<double, 24, 3, Eigen::RowMajor> j;
  const auto& names = smpl_joint_bones();
  for (int k = 0; k < 24; ++k) {
    const Bone& b = assets.skeleton.bones[static_cast<std::size_t>(
        assets.skeleton.bone(names[static_cast<std::size_t>(k)]))];
    j.row(k) = joint_position(assets.skeleton, b.head, positions).transpose();
  }
  return j;
}

// ------------------------------------------------------------------------------------------------
// Rigid transforms (x' = r x + t), rotations without trigonometry
// ------------------------------------------------------------------------------------------------

namespace {

struct Rigid {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return r * x + t; }
};

/// a then b: (b o a)(x) = b(a(x)).
Rigid then(const Rigid& a, const Rigid& b) {
  return Rigid{b.r * a.r, b.r * a.t + b.t};
}

/// Rotation r about the point p.
Rigid about(const Eigen::Vector3d& p, const Eigen::Matrix3d& r) {
  return Rigid{r, p - r * p};
}

Eigen::Vector3d unit(const Eigen::Vector3d& v, const char* what) {
  const double n = v.norm();
  if (!(n > 1e-12)) {
    throw AssetError(std::string("degenerate MakeHuman rig: zero-length ") + what);
  }
  return v / n;
}

/// The smallest rotation taking unit vector a onto unit vector b (Rodrigues with the cross and
/// dot products: no trigonometric function). a and b must not be opposite.
Eigen::Matrix3d rotation_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d v = a.cross(b);
  const double c = a.dot(b);
  if (c < -0.999) {
    throw AssetError(
        "MakeHuman rig: a bone would have to turn by nearly 180 degrees to reach "
        "the T-pose; is the base mesh in its A-pose?");
  }
  Eigen::Matrix3d k;
  k << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return Eigen::Matrix3d::Identity() + k + (k * k) / (1.0 + c);
}

/// Half of rotation_between(a, b): onto the bisector of a and b.
Eigen::Matrix3d half_rotation_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return rotation_between(a, unit(a + b, "bisector"));
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// T-pose
// ------------------------------------------------------------------------------------------------

TPoseBody t_pose(const Assets& assets, const Positions& a_pose) {
  const Skeleton& sk = assets.skeleton;
  auto head = [&](const std::string& bone) {
    return joint_position(sk, sk.bones[static_cast<std::size_t>(sk.bone(bone))].head, a_pose);
  };
  // Transforms of the bones that move; every other bone inherits its nearest listed ancestor's.
  std::map<std::string, Rigid> moved;
  for (const std::string side : {".L", ".R"}) {
    const Eigen::Vector3d axis(side == ".L" ? 1.0 : -1.0, 0.0, 0.0);
    const Eigen::Vector3d s = head("upperarm01" + side);
    const Eigen::Vector3d e = head("lowerarm01" + side);
    const Eigen::Vector3d w = head("wrist" + side);
    const Eigen::Vector3d k = head("finger3-1" + side);
    const Eigen::Vector3d i2 = head("finger2-1" + side);
    const Eigen::Vector3d i5 = head("finger5-1" + side);

    const Eigen::Vector3d upper = unit(e - s, "upper arm");
    const Rigid shoulder = about(s, rotation_between(upper, axis));
    const Rigid deltoid = about(s, half_rotation_between(upper, axis));
    const Eigen::Vector3d e1 = shoulder(e);
    const Rigid elbow =
        then(shoulder, about(e1, rotation_between(unit(shoulder(w) - e1, "forearm"), axis)));
    const Eigen::Vector3d w1 = elbow(w);
    const Rigid wrist = then(elbow, about(w1, rotation_between(unit(elbow(k) - w1, "hand"), axis)));
    // Palm down: the index knuckle straight in front of the little-finger knuckle.
    Eigen::Vector3d across = wrist(i2) - wrist(i5);
    across.x() = 0.0;
    across = unit(across, "knuckle line");
    const Eigen::Vector3d forward(0.0, 0.0, 1.0);
    const Rigid twist = about(w1, rotation_between(across, forward));
    const Rigid half_twist = about(w1, half_rotation_between(across, forward));

    moved["shoulder01" + side] = deltoid;
    moved["upperarm01" + side] = shoulder;
    moved["upperarm02" + side] = shoulder;
    moved["lowerarm01" + side] = elbow;
    moved["lowerarm02" + side] = then(elbow, half_twist);
    moved["wrist" + side] = then(wrist, twist);
  }
  std::vector<Rigid> bone_rigid(sk.bones.size());
  for (std::size_t b = 0; b < sk.bones.size(); ++b) {
    const auto it = moved.find(sk.bones[b].name);
    if (it != moved.end()) {
      bone_rigid[b] = it->second;
    } else if (!sk.bones[b].parent.empty()) {
      // Parents precede children (read_skeleton), so the parent's transform is final.
      bone_rigid[b] = bone_rigid[static_cast<std::size_t>(sk.bone(sk.bones[b].parent))];
    }
  }

  TPoseBody out;
  const Eigen::Index n = a_pose.rows();
  Positions acc = Positions::Zero(n, 3);
  Eigen::VectorXd wsum = Eigen::VectorXd::Zero(n);
  for (const auto& [bone, list] : assets.weights) {  // bone-name order: fixed summation order
    const Rigid& g = bone_rigid[static_cast<std::size_t>(sk.bone(bone))];
    for (const auto& [i, x] : list) {
      acc.row(i) += x * g(a_pose.row(i).transpose()).transpose();
      wsum(i) += x;
    }
  }
  out.positions = a_pose;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (wsum(i) > 0.0) {
      out.positions.row(i) = acc.row(i) / wsum(i);
    }
  }
  const auto rest = smpl_joints(assets, a_pose);
  const auto& names = smpl_joint_bones();
  for (int j = 0; j < 24; ++j) {
    const Rigid& g =
        bone_rigid[static_cast<std::size_t>(sk.bone(names[static_cast<std::size_t>(j)]))];
    out.joints.row(j) = g(rest.row(j).transpose()).transpose();
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// Merged weights
// ------------------------------------------------------------------------------------------------

std::vector<std::vector<int>> vertex_neighbours(Eigen::Index n, const smpl::Faces& faces) {
  std::vector<std::vector<int>> ring(static_cast<std::size_t>(n));
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = faces(f, c);
      const int b = faces(f, (c + 1) % 3);
      ring[static_cast<std::size_t>(a)].push_back(b);
      ring[static_cast<std::size_t>(b)].push_back(a);
    }
  }
  for (auto& r : ring) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
  }
  return ring;
}

void grow_marks(std::vector<char>& mark, const std::vector<std::vector<int>>& ring, int rings) {
  for (int r = 0; r < rings; ++r) {
    const std::vector<char> before = mark;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      if (before[i] == 0) continue;
      for (const int n : ring[i]) mark[static_cast<std::size_t>(n)] = 1;
    }
  }
}

void smooth_marked(Eigen::Ref<smpl::Vertices> v, const std::vector<std::vector<int>>& ring,
                   const std::vector<char>& mark, int passes) {
  for (int pass = 0; pass < passes; ++pass) {
    const smpl::Vertices before = v;
    for (Eigen::Index x = 0; x < v.rows(); ++x) {
      const auto& n = ring[static_cast<std::size_t>(x)];
      if (mark[static_cast<std::size_t>(x)] == 0 || n.empty()) continue;
      Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
      for (const int y : n) mean += before.row(y);
      v.row(x) = 0.5 * before.row(x) + (0.5 / static_cast<double>(n.size())) * mean;
    }
  }
}

namespace {

using WeightRows = Eigen::Matrix<double, Eigen::Dynamic, 24, Eigen::RowMajor>;

// Diffuses the V x 24 weights `w` over the 1-ring, `passes` times (see merged_weights): each pass
// w'(i) = (w(i) + mean of w over the 1-ring of i) / 2, kept to the joints `allowed` for i, then
// renormalised to sum 1. Plain loops in a fixed order (neighbours increasing, joints 0..23), so
// the result is the same bit for bit on every CPU (no FMA: the build uses -ffp-contract=off).
void diffuse_weights(const std::vector<std::vector<int>>& ring,
                     const std::vector<std::array<bool, 24>>& allowed, int passes, WeightRows& w) {
  const auto v = w.rows();
  WeightRows next(v, 24);
  for (int pass = 0; pass < passes; ++pass) {
    for (Eigen::Index i = 0; i < v; ++i) {
      const auto& r = ring[static_cast<std::size_t>(i)];
      const auto& ok = allowed[static_cast<std::size_t>(i)];
      double sum = 0.0;
      for (int k = 0; k < 24; ++k) {
        double x = 0.0;
        if (ok[static_cast<std::size_t>(k)]) {
          double mean = 0.0;
          for (const int n : r) {
            mean += w(n, k);
          }
          mean = r.empty() ? w(i, k) : mean / static_cast<double>(r.size());
          x = 0.5 * w(i, k) + 0.5 * mean;
        }
        next(i, k) = x;
        sum += x;
      }
      for (int k = 0; k < 24; ++k) {
        next(i, k) = next(i, k) / sum;  // sum > 0: w(i, k) > 0 for an allowed k, its own
      }
    }
    w.swap(next);
  }
}

// Keeps the 4 largest weights of each row of `w` (ties to the lower joint index), the others set
// to 0, divided by their sum. Throws AssetError if a row has no positive weight.
void keep_four_largest(const Assets& assets, WeightRows& w) {
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    std::array<int, 24> order{};
    for (int k = 0; k < 24; ++k) {
      order[static_cast<std::size_t>(k)] = k;
    }
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return w(i, a) > w(i, b); });
    double sum = 0.0;
    for (int r = 0; r < 4; ++r) {
      sum += w(i, order[static_cast<std::size_t>(r)]);
    }
    if (!(sum > 0.0)) {
      throw AssetError("MakeHuman weights: skin vertex " + std::to_string(i) + " (base vertex " +
                       std::to_string(assets.skin.source_vertex[static_cast<std::size_t>(i)]) +
                       ") has no bone weight");
    }
    for (int r = 0; r < 24; ++r) {
      const auto k = order[static_cast<std::size_t>(r)];
      w(i, k) = r < 4 && w(i, k) > 0.0 ? w(i, k) / sum : 0.0;
    }
  }
}

}  // namespace

smpl::SparseMatrix merged_weights(const Assets& assets) {
  return merged_weights(assets, kWeightSmoothingPasses);
}

smpl::SparseMatrix merged_weights(const Assets& assets, int smoothing_passes) {
  if (smoothing_passes < 0) {
    throw std::invalid_argument("merged_weights: smoothing_passes is " +
                                std::to_string(smoothing_passes) + "; give 0 or more");
  }
  const auto v = static_cast<Eigen::Index>(assets.skin.source_vertex.size());
  WeightRows acc = WeightRows::Zero(v, 24);
  for (const auto& [bone, list] : assets.weights) {
    const int seg = smpl_segment(assets.skeleton, bone);
    for (const auto& [i, x] : list) {
      const int s = assets.skin.skin_vertex[static_cast<std::size_t>(i)];
      if (s >= 0) {
        acc(s, seg) += x;
      }
    }
  }
  // Stray weights on the other side's limbs: SMPL's left joints are 1, 4, 7, ..., 22 (hips to
  // hands, collars 13 and shoulders 16 included) and each right joint follows its left one.
  const std::array<int, 9> left_joints{{1, 4, 7, 10, 13, 16, 18, 20, 22}};
  std::vector<std::array<bool, 24>> other_side(static_cast<std::size_t>(v));
  for (Eigen::Index i = 0; i < v; ++i) {
    const double x =
        assets.base.vertices(assets.skin.source_vertex[static_cast<std::size_t>(i)], 0);
    auto& o = other_side[static_cast<std::size_t>(i)];
    o.fill(false);
    for (const int l : left_joints) {
      if (x < -kMidlineBand) {
        o[static_cast<std::size_t>(l)] = true;
      } else if (x > kMidlineBand) {
        o[static_cast<std::size_t>(l) + 1] = true;
      }
    }
    for (int k = 0; k < 24; ++k) {
      if (o[static_cast<std::size_t>(k)]) {
        acc(i, k) = 0.0;
      }
    }
  }
  keep_four_largest(assets, acc);  // the merge as MakeHuman gives it: 0 passes
  if (smoothing_passes > 0) {
    // Each vertex may take the joints that influence it or a 1-ring neighbour in the 4-kept
    // merge, never one of the other side's limbs.
    const auto ring = vertex_neighbours(v, assets.skin.faces);
    std::vector<std::array<bool, 24>> allowed(static_cast<std::size_t>(v));
    for (Eigen::Index i = 0; i < v; ++i) {
      auto& a = allowed[static_cast<std::size_t>(i)];
      for (int k = 0; k < 24; ++k) {
        bool near = acc(i, k) > 0.0;
        for (const int n : ring[static_cast<std::size_t>(i)]) {
          near = near || acc(n, k) > 0.0;
        }
        a[static_cast<std::size_t>(k)] =
            near && !other_side[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
      }
    }
    diffuse_weights(ring, allowed, smoothing_passes, acc);
    keep_four_largest(assets, acc);
  }
  std::vector<Eigen::Triplet<double>> trip;
  for (Eigen::Index i = 0; i < v; ++i) {
    for (int k = 0; k < 24; ++k) {
      if (acc(i, k) > 0.0) {
        trip.emplace_back(static_cast<int>(i), k, acc(i, k));
      }
    }
  }
  smpl::SparseMatrix w(v, 24);
  w.setFromTriplets(trip.begin(), trip.end());
  w.makeCompressed();
  return w;
}

// ------------------------------------------------------------------------------------------------
// Joint regressor
// ------------------------------------------------------------------------------------------------

namespace {

// The skin vertices (indices into src) around joint j of `body`: where 36 rays from the joint
// first meet the skin (per ray, the nearest vertex within 20 degrees of it): 12 in the plane
// across the limb (the YZ plane for the arm joints, which lie along X in the T-pose; the
// horizontal plane for the others) and 12 tilted 30 degrees to either side.
std::vector<int> vertices_around_joint(const TPoseBody& body, const std::vector<int>& src, int j) {
  const auto nv = static_cast<int>(src.size());
  const Eigen::Vector3d c = body.joints.row(j).transpose();
  const bool arm = j >= 16;
  std::vector<int> chosen;
  const double h = 0.5 * std::sqrt(3.0);  // cos 30 degrees
  const double ca[12] = {1.0, h, 0.5, 0.0, -0.5, -h, -1.0, -h, -0.5, 0.0, 0.5, h};
  const double sa[12] = {0.0, 0.5, h, 1.0, h, 0.5, 0.0, -0.5, -h, -1.0, -h, -0.5};
  for (int ring = 0; ring < 3; ++ring) {
    for (int r = 0; r < 12; ++r) {
      // Three rings of 12 rays: in the plane and tilted 30 degrees to either side of it.
      const double along = ring == 0 ? 0.0 : (ring == 1 ? 0.5 : -0.5);
      const double across = ring == 0 ? 1.0 : h;
      const Eigen::Vector3d d = arm ? Eigen::Vector3d(along, across * ca[r], across * sa[r])
                                    : Eigen::Vector3d(across * ca[r], along, across * sa[r]);
      constexpr double kCone = 0.9397;  // cos 20 degrees
      double best = 1e300;
      int arg = -1;
      for (int s = 0; s < nv; ++s) {
        const Eigen::Vector3d e =
            body.positions.row(src[static_cast<std::size_t>(s)]).transpose() - c;
        const double n2 = e.squaredNorm();
        const double dot = e.dot(d);
        if (dot > 0.0 && dot * dot >= kCone * kCone * n2 && n2 < best) {
          best = n2;
          arg = s;
        }
      }
      if (arg >= 0 && std::find(chosen.begin(), chosen.end(), arg) == chosen.end()) {
        chosen.push_back(arg);
      }
    }
  }
  return chosen;
}

// Weights (summing to 1) of the chosen vertices whose weighted mean best gives joint j over all
// bodies, with a ridge towards equal weights.
Eigen::VectorXd joint_weights(const std::vector<TPoseBody>& bodies, const std::vector<int>& src,
                              const std::vector<int>& chosen, int j) {
  const int k = static_cast<int>(chosen.size());
  // Normal matrix of sum_b |sum_i w_i (v_i^b - J^b)|^2, summed in body, coordinate order.
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k, k);
  for (const TPoseBody& b : bodies) {
    for (int c3 = 0; c3 < 3; ++c3) {
      for (int p = 0; p < k; ++p) {
        const double dp =
            b.positions(src[static_cast<std::size_t>(chosen[static_cast<std::size_t>(p)])], c3) -
            b.joints(j, c3);
        for (int q = 0; q < k; ++q) {
          const double dq =
              b.positions(src[static_cast<std::size_t>(chosen[static_cast<std::size_t>(q)])], c3) -
              b.joints(j, c3);
          m(p, q) += dp * dq;
        }
      }
    }
  }
  // Ridge towards equal weights, 1e-3 of the mean diagonal: without it the 36 weights cancel
  // (entries to -1.3 with 1e-4); with it they stay within [-0.4, 0.5] for 0.5 mm more RMS
  // error on the training bodies.
  double tr = 0.0;
  for (int p = 0; p < k; ++p) {
    tr += m(p, p);
  }
  const double lambda = 1e-3 * tr / k;
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(k + 1, k + 1);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(k + 1);
  for (int p = 0; p < k; ++p) {
    for (int q = 0; q < k; ++q) {
      kkt(p, q) = 2.0 * m(p, q);
    }
    kkt(p, p) += 2.0 * lambda;
    kkt(p, k) = 1.0;
    kkt(k, p) = 1.0;
    rhs(p) = 2.0 * lambda / k;
  }
  rhs(k) = 1.0;
  const Eigen::VectorXd sol = kkt.fullPivLu().solve(rhs);
  double sum = 0.0;
  for (int p = 0; p < k; ++p) {
    sum += sol(p);
  }
  Eigen::VectorXd w(k);
  for (int p = 0; p < k; ++p) {
    w(p) = sol(p) / sum;
  }
  return w;
}

/// The SMPL joint on the other side (left_* <-> right_*), or `j` itself on the midline.
int mirror_joint(int j) {
  const std::vector<std::string>& names = smpl::smpl_joint_names();
  const std::string& n = names[static_cast<std::size_t>(j)];
  std::string other;
  if (n.rfind("left_", 0) == 0) other = "right_" + n.substr(5);
  if (n.rfind("right_", 0) == 0) other = "left_" + n.substr(6);
  if (other.empty()) return j;
  return static_cast<int>(std::find(names.begin(), names.end(), other) - names.begin());
}

}  // namespace

smpl::SparseMatrix fit_joint_regressor(const Assets& assets, const std::vector<TPoseBody>& bodies) {
  if (bodies.empty()) {
    throw std::invalid_argument("fit_joint_regressor: needs at least one body");
  }
  const std::vector<int>& src = assets.skin.source_vertex;
  const auto nv = static_cast<int>(src.size());
  std::vector<Eigen::Triplet<double>> trip;
  for (int j = 0; j < 24; ++j) {
    std::vector<int> chosen = vertices_around_joint(bodies.front(), src, j);
    if (chosen.size() < 3) {
      throw AssetError("MakeHuman rig: too few skin vertices around joint " +
                       smpl::smpl_joint_names()[static_cast<std::size_t>(j)]);
    }
    std::sort(chosen.begin(), chosen.end());
    const int k = static_cast<int>(chosen.size());
    const Eigen::VectorXd w = joint_weights(bodies, src, chosen, j);
    // Left/right symmetric: half the weight on the chosen vertex for this joint, half on its
    // mirror vertex for the mirror joint (the rows stay sums of 1).
    const int jm = mirror_joint(j);
    for (int p = 0; p < k; ++p) {
      const int v = chosen[static_cast<std::size_t>(p)];
      trip.emplace_back(j, v, 0.5 * w(p));
      trip.emplace_back(jm, assets.skin.mirror[static_cast<std::size_t>(v)], 0.5 * w(p));
    }
  }
  smpl::SparseMatrix r(24, nv);
  r.setFromTriplets(trip.begin(), trip.end());
  r.makeCompressed();
  return r;
}

// ------------------------------------------------------------------------------------------------
// Template model
// ------------------------------------------------------------------------------------------------

std::vector<std::string> default_regressor_targets() {
  std::vector<std::string> t;
  for (const char* sex : {"female", "male"}) {
    for (const char* muscle : {"min", "average", "max"}) {
      for (const char* weight : {"min", "average", "max"}) {
        if (std::string(muscle) == "average" && std::string(weight) == "average") {
          continue;  // the empty corner: the base itself
        }
        t.push_back(std::string("macrodetails/universal-") + sex + "-young-" + muscle + "muscle-" +
                    weight + "weight.target");
      }
    }
    for (const char* h : {"min", "max"}) {
      t.push_back(std::string("macrodetails/height/") + sex +
                  "-young-averagemuscle-averageweight-" + h + "height.target");
    }
  }
  for (const std::string& m : measure_targets()) t.push_back(m);
  return t;
}

std::vector<std::string> measure_targets() {
  std::vector<std::string> t;
  for (const char* m : {"ankle-circ",       "bust-circ",      "calf-circ",       "frontchest-dist",
                        "hips-circ",        "knee-circ",      "lowerarm-length", "lowerleg-height",
                        "napetowaist-dist", "neck-circ",      "neck-height",     "shoulder-dist",
                        "thigh-circ",       "underbust-circ", "upperarm-circ",   "upperarm-length",
                        "upperleg-height",  "waist-circ",     "waisttohip-dist", "wrist-circ"}) {
    for (const char* d : {"decr", "incr"}) {
      t.push_back(std::string("measure/measure-") + m + "-" + d + ".target");
    }
  }
  return t;
}

smpl::BodyModel template_model(const Assets& assets, const std::vector<std::string>& training) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  std::vector<TPoseBody> bodies;
  bodies.push_back(t_pose(assets, assets.base.vertices));
  for (const std::string& rel : training) {
    Positions p = assets.base.vertices;
    add_target(read_asset_target(assets, rel), 1.0, p);
    bodies.push_back(t_pose(assets, p));
  }
  smpl::BodyModel model;
  model.j_regressor = fit_joint_regressor(assets, bodies);
  smpl::Vertices v = skin_vertices(assets.skin, bodies.front().positions);
  // Origin at the pelvis joint, as SMPL and the cage models.
  const Eigen::RowVector3d pelvis = (model.j_regressor.row(0) * v).eval();
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    v.row(i) -= pelvis;
  }
  symmetrize(v, assets.skin.mirror);
  model.v_template = v;
  model.mirror = assets.skin.mirror;
  Joints24 joints = bodies.front().joints * kMetresPerUnit;
  for (Eigen::Index j = 0; j < joints.rows(); ++j) {
    joints.row(j) -= pelvis;
  }
  model.landmarks = template_landmarks(assets, v, joints);
  caliper::derive_torso_landmarks(v, model.landmarks);  // all 24 names, as the other open models
  model.faces = assets.skin.faces;
  model.uvs = assets.skin.uvs;
  model.uv_faces = assets.skin.uv_faces;
  model.shapedirs = Eigen::MatrixXd::Zero(3 * v.rows(), 0);
  model.posedirs = Eigen::MatrixXd::Zero(3 * v.rows(), 0);
  model.weights = merged_weights(assets);
  model.parents = smpl::smpl_parents();
  model.joint_names = smpl::smpl_joint_names();
  model.meta.name = "caliper-open-makehuman-template";
  model.meta.gender = "neutral";
  model.meta.source = "caliper-modelgen (MakeHuman hm08 CC0 assets)";
  model.meta.extra["licence"] = "MIT; derived from MakeHuman's CC0 1.0 assets";
  smpl::validate(model, "MakeHuman template model");
  return model;
}

}  // namespace modelgen::mh
