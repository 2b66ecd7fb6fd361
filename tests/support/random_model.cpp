// Random, valid, full-size SMPL-shaped body models for tests (no licensed data involved).
#include "caliper_test/random_model.hpp"
#include "smpl/constants.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

// GCC 12 reports false "potential null pointer dereference" inside Eigen's inlined assignments
// to freshly resized dynamic matrices; the sizes here are checked above each use.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wnull-dereference"
#endif

namespace caliper::test {
namespace {

using smpl::kPi;
// The ellipsoid that stands in for a body: centre and semi-axes, metres.
const Eigen::Vector3d kCentre(0.0, -0.26, 0.0);
const Eigen::Vector3d kRadii(0.18, 0.86, 0.12);

// Normal and uniform numbers that do not depend on the standard library's distributions.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform() {  // [0, 1)
    return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double normal() {
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  int index(int n) { return static_cast<int>(uniform() * n) % n; }
  /// Three normal draws in a fixed order, z then y then x: C++ leaves the order of a call's
  /// arguments unspecified (GCC 12 evaluated Vector3d(normal(), normal(), normal()) last argument
  /// first, clang first argument first, so the random models differed between the compilers);
  /// GCC's order, which the expected values of the tests were taken with.
  Eigen::Vector3d normal3() {
    const double z = normal();
    const double y = normal();
    const double x = normal();
    return {x, y, z};
  }

 private:
  std::mt19937_64 engine_;
};

const std::vector<std::string>& smplx_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = smpl::smpl_joint_names();
    n.resize(22);
    n.insert(n.end(), {"jaw", "left_eye_smplhf", "right_eye_smplhf"});
    for (const char* side : {"left", "right"}) {
      for (const char* finger : {"index", "middle", "pinky", "ring", "thumb"}) {
        for (int i = 1; i <= 3; ++i)
          n.push_back(std::string(side) + "_" + finger + std::to_string(i));
      }
    }
    return n;
  }();
  return names;
}

std::vector<std::string> mano_names() {
  std::vector<std::string> n = {"wrist"};
  for (const char* finger : {"index", "middle", "pinky", "ring", "thumb"}) {
    for (int i = 1; i <= 3; ++i) n.push_back(std::string(finger) + std::to_string(i));
  }
  return n;
}

// Indices of the `n` rows of `points` nearest to `p`.
std::vector<int> nearest(const smpl::Vertices& points, const Eigen::Vector3d& p, int n) {
  std::vector<int> ids(static_cast<size_t>(points.rows()));
  std::iota(ids.begin(), ids.end(), 0);
  std::vector<double> d(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    d[i] = (points.row(static_cast<Eigen::Index>(i)).transpose() - p).squaredNorm();
  }
  n = std::min<int>(n, static_cast<int>(ids.size()));
  std::partial_sort(ids.begin(), ids.begin() + n, ids.end(), [&](int a, int b) {
    return d[static_cast<size_t>(a)] < d[static_cast<size_t>(b)] ||
           (d[static_cast<size_t>(a)] == d[static_cast<size_t>(b)] && a < b);
  });
  ids.resize(static_cast<size_t>(n));
  return ids;
}

// Clamp a point to lie inside the ellipsoid scaled by `fraction`.
Eigen::Vector3d inside(const Eigen::Vector3d& p, double fraction) {
  const Eigen::Vector3d u = (p - kCentre).cwiseQuotient(kRadii);
  const double r = u.norm();
  if (r <= fraction) return p;
  return kCentre + (u * (fraction / r)).cwiseProduct(kRadii);
}

}  // namespace

const std::vector<int>& smplx_parents() {
  static const std::vector<int> parents = {-1, 0,  0,  0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  9,
                                           9,  12, 13, 14, 16, 17, 18, 19, 15, 15, 15, 20, 25, 26,
                                           20, 28, 29, 20, 31, 32, 20, 34, 35, 20, 37, 38, 21, 40,
                                           41, 21, 43, 44, 21, 46, 47, 21, 49, 50, 21, 52, 53};
  return parents;
}

const std::vector<std::string>& smplx_joint_names() {
  return smplx_names();
}

const std::vector<int>& mano_parents() {
  static const std::vector<int> parents = {-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14};
  return parents;
}

Eigen::VectorXd random_pose(int num_joints, double max_angle, std::uint64_t seed) {
  Rng rng(seed);
  Eigen::VectorXd pose(3 * num_joints);
  for (int k = 0; k < num_joints; ++k) {
    Eigen::Vector3d axis = rng.normal3();
    axis.normalize();
    pose.segment<3>(3 * static_cast<Eigen::Index>(k)) = axis * rng.uniform(0.0, max_angle);
  }
  return pose;
}

Eigen::VectorXd random_betas(int num_betas, double scale, std::uint64_t seed) {
  Rng rng(seed);
  Eigen::VectorXd b(num_betas);
  for (int i = 0; i < num_betas; ++i) b[i] = scale * rng.normal();
  return b;
}

smpl::BodyModel make_random_model(const RandomModelOptions& o) {
  if (o.rings < 2 || o.segments < 3 || o.num_joints < 1 || o.num_betas < 0) {
    throw std::invalid_argument("make_random_model: needs rings >= 2, segments >= 3, joints >= 1");
  }
  Rng rng(o.seed);
  smpl::BodyModel m;
  const int R = o.rings, S = o.segments;
  const int V = R * S + 2;
  const int north = 0, south = V - 1;
  auto vid = [S](int r, int s) { return 1 + r * S + ((s % S) + S) % S; };

  // Vertices on the unit sphere first (faces are oriented there), then the ellipsoid.
  smpl::Vertices unit(V, 3);
  unit.row(north) = Eigen::RowVector3d::UnitY();
  unit.row(south) = -Eigen::RowVector3d::UnitY();
  for (int r = 0; r < R; ++r) {
    const double theta = kPi * (r + 1) / (R + 1);
    for (int s = 0; s < S; ++s) {
      const double phi = 2.0 * kPi * s / S;
      unit.row(vid(r, s)) << std::sin(theta) * std::cos(phi), std::cos(theta),
          std::sin(theta) * std::sin(phi);
    }
  }
  std::vector<std::array<int, 3>> tris;
  tris.reserve(2 * static_cast<size_t>(R) * static_cast<size_t>(S));
  for (int s = 0; s < S; ++s) {
    tris.push_back({north, vid(0, s), vid(0, s + 1)});
    tris.push_back({south, vid(R - 1, s), vid(R - 1, s + 1)});
    for (int r = 0; r + 1 < R; ++r) {
      tris.push_back({vid(r, s), vid(r, s + 1), vid(r + 1, s + 1)});
      tris.push_back({vid(r, s), vid(r + 1, s + 1), vid(r + 1, s)});
    }
  }
  m.faces.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t f = 0; f < tris.size(); ++f) {
    auto t = tris[f];
    const Eigen::Vector3d a = unit.row(t[0]), b = unit.row(t[1]), c = unit.row(t[2]);
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(t[1], t[2]);  // outward winding
    m.faces.row(static_cast<Eigen::Index>(f)) << t[0], t[1], t[2];
  }
  m.v_template.resize(V, 3);
  for (int v = 0; v < V; ++v) {
    const double radial = 1.0 + 0.003 * rng.normal();  // keeps the surface star-shaped
    m.v_template.row(v) =
        (kCentre + radial * unit.row(v).transpose().cwiseProduct(kRadii)).transpose();
  }

  // Skeleton.
  const int K = o.num_joints;
  if (K == 24) {
    m.parents = smpl::smpl_parents();
    m.joint_names = smpl::smpl_joint_names();
  } else if (K == 55) {
    m.parents = smplx_parents();
    m.joint_names = smplx_names();
  } else if (K == 16) {
    m.parents = mano_parents();
    m.joint_names = mano_names();
  } else {
    m.parents.assign(static_cast<size_t>(K), -1);
    m.joint_names.resize(static_cast<size_t>(K));
    for (int k = 0; k < K; ++k) {
      if (k > 0) m.parents[static_cast<size_t>(k)] = rng.index(k);
      m.joint_names[static_cast<size_t>(k)] = "joint" + std::to_string(k);
    }
  }
  std::vector<Eigen::Vector3d> target(static_cast<size_t>(K), kCentre);
  for (int k = 1; k < K; ++k) {
    const Eigen::Vector3d dir = rng.normal3();
    const Eigen::Vector3d step = dir.normalized() * rng.uniform(0.08, 0.2);
    target[static_cast<size_t>(k)] =
        inside(target[static_cast<size_t>(m.parents[static_cast<size_t>(k)])] + step, 0.8);
  }
  constexpr int kRegressorSupport = 10;
  m.j_regressor.resize(K, V);
  {
    std::vector<Eigen::Triplet<double>> trip;
    for (int k = 0; k < K; ++k) {
      const auto ids = nearest(m.v_template, target[static_cast<size_t>(k)], kRegressorSupport);
      std::vector<double> w(ids.size());
      for (auto& x : w) x = rng.uniform(0.5, 1.5);
      const double sum = std::accumulate(w.begin(), w.end(), 0.0);
      for (size_t i = 0; i < ids.size(); ++i) trip.emplace_back(k, ids[i], w[i] / sum);
    }
    m.j_regressor.setFromTriplets(trip.begin(), trip.end());
  }
  smpl::Joints joints = m.j_regressor * m.v_template;
  m.weights.resize(V, K);
  {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(4 * static_cast<size_t>(V));
    for (int v = 0; v < V; ++v) {
      const auto ids = nearest(joints, m.v_template.row(v).transpose(), 4);
      std::vector<double> w(ids.size());
      for (size_t i = 0; i < ids.size(); ++i) {
        const double d = (joints.row(ids[i]) - m.v_template.row(v)).norm();
        w[i] = rng.uniform(0.5, 1.5) / (d + 0.05);
      }
      const double sum = std::accumulate(w.begin(), w.end(), 0.0);
      for (size_t i = 0; i < ids.size(); ++i) trip.emplace_back(v, ids[i], w[i] / sum);
    }
    m.weights.setFromTriplets(trip.begin(), trip.end());
  }

  // Shape directions: a smooth affine field per component plus a little per-vertex noise.
  m.shapedirs.resize(3 * static_cast<Eigen::Index>(V), o.num_betas);
  for (int b = 0; b < o.num_betas; ++b) {
    Eigen::Matrix3d A;
    Eigen::Vector3d t;
    for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = rng.normal();
    for (int i = 0; i < 3; ++i) t[i] = rng.normal();
    for (int v = 0; v < V; ++v) {
      const Eigen::Vector3d u = (m.v_template.row(v).transpose() - kCentre).cwiseQuotient(kRadii);
      const Eigen::Vector3d d = A * u + t;
      for (int c = 0; c < 3; ++c) {
        m.shapedirs(3 * v + c, b) = o.shape_scale * (d[c] + 0.1 * rng.normal());
      }
    }
  }
  if (o.pose_blend_shapes && K > 1) {
    m.posedirs.resize(3 * static_cast<Eigen::Index>(V), 9 * static_cast<Eigen::Index>(K - 1));
    for (Eigen::Index j = 0; j < m.posedirs.cols(); ++j) {
      for (Eigen::Index i = 0; i < m.posedirs.rows(); ++i)
        m.posedirs(i, j) = o.pose_scale * rng.normal();
    }
  }

  // Landmarks of the shared vocabulary at plausible places on the ellipsoid.
  const std::vector<std::pair<const char*, Eigen::Vector3d>> landmark_targets = {
      {"head_top", {0.0, 0.7, 0.0}},          {"left_fingertip", {0.3, 0.32, 0.0}},
      {"right_fingertip", {-0.3, 0.32, 0.0}}, {"left_wrist", {0.3, 0.26, 0.04}},
      {"right_wrist", {-0.3, 0.26, 0.04}},    {"left_shoulder", {0.3, 0.42, 0.0}},
      {"right_shoulder", {-0.3, 0.42, 0.0}},  {"left_elbow", {0.3, 0.18, 0.06}},
      {"right_elbow", {-0.3, 0.18, 0.06}},    {"crotch", {0.0, -0.4, 0.3}},
      {"left_hip", {0.3, -0.3, 0.0}},         {"right_hip", {-0.3, -0.3, 0.0}},
      {"left_nipple", {0.08, 0.25, 0.3}},     {"right_nipple", {-0.08, 0.25, 0.3}},
      {"navel", {0.0, -0.05, 0.3}},           {"left_waist", {0.3, -0.05, 0.0}},
      {"right_waist", {-0.3, -0.05, 0.0}},    {"left_chest", {0.3, 0.25, 0.0}},
      {"right_chest", {-0.3, 0.25, 0.0}},     {"torso_back", {0.0, -0.05, -0.3}},
      {"left_heel", {0.05, -1.05, -0.3}},     {"right_heel", {-0.05, -1.05, -0.3}},
      {"left_sole", {0.04, -1.2, 0.05}},      {"right_sole", {-0.04, -1.2, 0.05}}};
  for (const auto& [name, p] : landmark_targets) m.landmarks[name] = nearest(m.v_template, p, 1);
  // Exact extremes where the vocabulary means them: the highest vertex, the lowest on each side.
  Eigen::Index top = 0, left_low = -1, right_low = -1;
  for (Eigen::Index v = 0; v < V; ++v) {
    const double y = m.v_template(v, 1);
    if (y > m.v_template(top, 1)) top = v;
    Eigen::Index& low = m.v_template(v, 0) > 0 ? left_low : right_low;
    if (m.v_template(v, 0) != 0 && (low < 0 || y < m.v_template(low, 1))) low = v;
  }
  m.landmarks["head_top"] = {static_cast<int>(top)};
  if (left_low >= 0) m.landmarks["left_sole"] = {static_cast<int>(left_low)};
  if (right_low >= 0) m.landmarks["right_sole"] = {static_cast<int>(right_low)};

  // Mirror in x: phi -> pi - phi, exact when the number of segments is even.
  if (S % 2 == 0) {
    m.mirror.resize(static_cast<size_t>(V));
    m.mirror[static_cast<size_t>(north)] = north;
    m.mirror[static_cast<size_t>(south)] = south;
    for (int r = 0; r < R; ++r) {
      for (int s = 0; s < S; ++s) m.mirror[static_cast<size_t>(vid(r, s))] = vid(r, S / 2 - s);
    }
  }
  m.meta.name = "caliper-test-random";
  m.meta.gender = "neutral";
  m.meta.source = "caliper::test::make_random_model seed " + std::to_string(o.seed);
  smpl::validate(m, "make_random_model");
  return m;
}

}  // namespace caliper::test
