#include "pose_correctives.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "caliper/portable_math.hpp"
#include "makehuman_rig.hpp"
#include "mesh_checks.hpp"
#include "validation.hpp"

namespace modelgen {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Vector4d;  // w, x, y, z

// The unit quaternion that turns by s of q's rotation: the identity and q blended and
// normalised (q's w >= 0: bends up to 180 degrees).
Quat blended(const Quat& q, double s) {
  Quat b = s * q;
  b[0] += 1.0 - s;
  return b / std::sqrt(b.squaredNorm());
}

Mat3 matrix(const Quat& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  Mat3 r;
  r << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return r;
}

// Weight of every vertex on joint k and its descendants (parents precede children).
Eigen::VectorXd subtree_weight(const smpl::BodyModel& model, int k) {
  std::vector<char> below(static_cast<std::size_t>(model.num_joints()), 0);
  below[static_cast<std::size_t>(k)] = 1;
  for (int j = k + 1; j < model.num_joints(); ++j) {
    const int p = model.parents[static_cast<std::size_t>(j)];
    below[static_cast<std::size_t>(j)] = p >= 0 ? below[static_cast<std::size_t>(p)] : 0;
  }
  Eigen::VectorXd s = Eigen::VectorXd::Zero(model.num_vertices());
  for (Eigen::Index i = 0; i < model.weights.outerSize(); ++i) {
    for (smpl::SparseMatrix::InnerIterator it(model.weights, i); it; ++it) {
      if (below[static_cast<std::size_t>(it.col())] != 0) {
        s[it.row()] += it.value();
      }
    }
  }
  return s;
}

// One bend: about an axis by an angle; the quaternion, its matrix and its 9 pose features.
struct Bend {
  Quat q;
  Mat3 r;
  Eigen::Matrix<double, 9, 1> feature;
};

std::vector<Bend> bends(const std::vector<double>& angles_deg) {
  constexpr double kPi = 3.14159265358979323846;
  std::vector<Bend> out;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double deg : angles_deg) {
      for (const double sign : {1.0, -1.0}) {
        const double half = sign * deg * kPi / 360.0;
        Bend b;
        b.q = Quat::Zero();
        b.q[0] = caliper::portable::cos(half);
        b.q[1 + axis] = caliper::portable::sin(half);
        b.r = matrix(b.q);
        for (int i = 0; i < 9; ++i) {
          b.feature[i] = b.r(i / 3, i % 3) - (i / 3 == i % 3 ? 1.0 : 0.0);
        }
        out.push_back(b);
      }
    }
  }
  return out;
}

// The band of one joint: the vertices solved for, their index, and the factored Laplacian
// (uniform weights) of the band with the rest held.
struct Band {
  std::vector<int> vertices;
  std::vector<int> index;      // V, -1 outside the band
  std::vector<int> rings_out;  // V, rings from the mixing skin (0 on it, and everywhere when
                               // the band does not reach the end of the limb)
  bool open_end = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
};

// Weight of the pull of a band vertex towards where skinning puts it: none where the weights
// mix, growing with the square of the vertex's distance in rings from the mixing skin to
// o.anchor at the band's edge. It fixes where a hand, a foot or the head ends up when the band
// reaches its far end (the solve sees only edges), and leaves the skin near the joint free.
double anchor(int rings_out, const PoseCorrectiveOptions& o) {
  const double f = static_cast<double>(rings_out) / static_cast<double>(std::max(1, o.rings));
  return o.anchor * f * f;
}

void make_band(const Eigen::VectorXd& s, const std::vector<std::vector<int>>& nb,
               const PoseCorrectiveOptions& o, int joint, Band& band) {
  const auto V = static_cast<std::size_t>(s.size());
  std::vector<char> mark(V, 0);
  for (std::size_t i = 0; i < V; ++i) {
    const double w = s[static_cast<Eigen::Index>(i)];
    mark[i] = w > o.band && w < 1.0 - o.band ? 1 : 0;
  }
  band.rings_out.assign(V, 0);
  for (int r = 1; r <= o.rings; ++r) {
    const std::vector<char> before = mark;
    mh::grow_marks(mark, nb, 1);
    for (std::size_t i = 0; i < V; ++i) {
      band.rings_out[i] = mark[i] != before[i] ? r : band.rings_out[i];
    }
  }
  band.index.assign(V, -1);
  band.vertices.clear();
  // the band reaches the end of the limb when none of the skin wholly beyond the joint is left
  // out of it (a hand, a foot, the head): only then is the anchor needed
  band.open_end = true;
  for (std::size_t i = 0; i < V; ++i) {
    if (mark[i] == 0 && s[static_cast<Eigen::Index>(i)] >= 1.0 - o.band) {
      band.open_end = false;
    }
  }
  if (!band.open_end) {
    std::fill(band.rings_out.begin(), band.rings_out.end(), 0);
  }
  for (std::size_t i = 0; i < V; ++i) {
    if (mark[i] != 0) {
      band.index[i] = static_cast<int>(band.vertices.size());
      band.vertices.push_back(static_cast<int>(i));
    }
  }
  std::vector<Eigen::Triplet<double>> t;
  for (const int a : band.vertices) {
    const int ia = band.index[static_cast<std::size_t>(a)];
    const auto& na = nb[static_cast<std::size_t>(a)];
    t.emplace_back(
        ia, ia,
        static_cast<double>(na.size()) + anchor(band.rings_out[static_cast<std::size_t>(a)], o));
    for (const int b : na) {
      if (band.index[static_cast<std::size_t>(b)] >= 0) {
        t.emplace_back(ia, band.index[static_cast<std::size_t>(b)], -1.0);
      }
    }
  }
  const auto n = static_cast<Eigen::Index>(band.vertices.size());
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(t.begin(), t.end());
  band.solver.compute(L);
  if (band.solver.info() != Eigen::Success) {
    // only a band with a piece not joined to anything beyond it (an island of the skin with no
    // anchored vertex) leaves the system singular
    throw std::runtime_error(
        "pose correctives: the skin band around joint " + std::to_string(joint) + " (" +
        std::to_string(band.vertices.size()) +
        " vertices) gives a singular Laplacian; check that the model's faces join the skin "
        "around that joint into one connected surface (no loose pieces, no unreferenced "
        "vertices inside the band)");
  }
}

// Everything one joint's bends share.
struct Joint {
  const smpl::BodyModel* model = nullptr;
  const std::vector<std::vector<int>>* nb = nullptr;
  const PoseCorrectiveOptions* options = nullptr;
  const smpl::Vertices* rest = nullptr;  // the body being bent (rest pose)
  Eigen::VectorXd s;
  Vec3 centre;
  Band band;
};

smpl::Vertices skinned(const Joint& j, const Bend& b) {
  const smpl::Vertices& r = *j.rest;
  smpl::Vertices x(r.rows(), 3);
  for (Eigen::Index i = 0; i < r.rows(); ++i) {
    const Vec3 p = r.row(i).transpose();
    const Vec3 turned = b.r * (p - j.centre) + j.centre;
    x.row(i) = ((1.0 - j.s[i]) * p + j.s[i] * turned).transpose();
  }
  return x;
}

// The band's positions whose edges best match the rest edges turned by the blended rotation
// of each edge, the rest of the skin where skinning puts it.
smpl::Vertices bent(const Joint& j, const Bend& b, const smpl::Vertices& skin) {
  const smpl::Vertices& r = *j.rest;
  const auto n = static_cast<Eigen::Index>(j.band.vertices.size());
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  for (Eigen::Index ia = 0; ia < n; ++ia) {
    const int a = j.band.vertices[static_cast<std::size_t>(ia)];
    for (const int c : (*j.nb)[static_cast<std::size_t>(a)]) {
      const Mat3 re = matrix(blended(b.q, 0.5 * (j.s[a] + j.s[c])));
      rhs.row(ia) += (re * (r.row(a) - r.row(c)).transpose()).transpose();
      if (j.band.index[static_cast<std::size_t>(c)] < 0) {
        rhs.row(ia) += skin.row(c);
      }
    }
    rhs.row(ia) += anchor(j.band.rings_out[static_cast<std::size_t>(a)], *j.options) * skin.row(a);
  }
  const Eigen::MatrixXd x = j.band.solver.solve(rhs);
  smpl::Vertices out = skin;
  for (Eigen::Index ia = 0; ia < n; ++ia) {
    out.row(j.band.vertices[static_cast<std::size_t>(ia)]) = x.row(ia);
  }
  return out;
}

// Folds the solve leaves (few, where the bend squeezes the skin hardest) smoothed out: the band
// vertices of folded triangles and two rings around them averaged with their neighbours, five
// passes a round; the round with the fewest folds is kept.
std::vector<int> smooth_folds(const Joint& j, const Bend& b, int rounds, smpl::Vertices& x) {
  const smpl::Faces& f = j.model->faces;
  std::vector<int> folds = folded_triangles(*j.rest, x, f, j.s, b.q);
  smpl::Vertices best = x;
  std::vector<int> best_folds = folds;
  for (int round = 0; round < rounds && !folds.empty(); ++round) {
    std::vector<char> mark(static_cast<std::size_t>(x.rows()), 0);
    for (const int t : folds) {
      for (int c = 0; c < 3; ++c) {
        mark[static_cast<std::size_t>(f(t, c))] = 1;
      }
    }
    mh::grow_marks(mark, *j.nb, 2);
    for (std::size_t i = 0; i < mark.size(); ++i) {
      mark[i] = j.band.index[i] >= 0 ? mark[i] : 0;  // only the band moves
    }
    mh::smooth_marked(x, *j.nb, mark, 5);
    folds = folded_triangles(*j.rest, x, f, j.s, b.q);
    if (folds.size() < best_folds.size()) {
      best = x;
      best_folds = folds;
    }
  }
  x = std::move(best);
  return best_folds;
}

// Fits joint k's 9 columns of `posedirs` (rows of the band only; the rest stay 0).
void fit_joint(const smpl::BodyModel& model, const std::vector<smpl::Vertices>& bodies,
               const std::vector<std::vector<int>>& nb, const PoseCorrectiveOptions& o, int k,
               Eigen::MatrixXd& posedirs, JointCorrective& rep) {
  Joint j;
  j.model = &model;
  j.nb = &nb;
  j.options = &o;
  j.s = subtree_weight(model, k);
  make_band(j.s, nb, o, k, j.band);
  const std::vector<Bend> bs = bends(o.angles_deg);
  const auto B = static_cast<Eigen::Index>(bs.size());
  const auto S = B * static_cast<Eigen::Index>(bodies.size());
  const auto n = static_cast<Eigen::Index>(j.band.vertices.size());
  Eigen::MatrixXd F(S, 9), D(S, 3 * n);
  rep = JointCorrective{};
  rep.joint = k;
  rep.band_vertices = static_cast<int>(n);
  rep.samples = static_cast<int>(S);
  for (Eigen::Index q = 0; q < S; ++q) {
    const Bend& b = bs[static_cast<std::size_t>(q % B)];
    j.rest = &bodies[static_cast<std::size_t>(q / B)];
    j.centre = (model.j_regressor.row(k) * *j.rest).transpose();
    F.row(q) = b.feature.transpose();
    const smpl::Vertices skin = skinned(j, b);
    rep.folds_skinned +=
        static_cast<int>(folded_triangles(*j.rest, skin, model.faces, j.s, b.q).size());
    smpl::Vertices x = bent(j, b, skin);
    rep.folds_target += static_cast<int>(smooth_folds(j, b, o.cleanup_rounds, x).size());
    for (Eigen::Index ia = 0; ia < n; ++ia) {
      const int a = j.band.vertices[static_cast<std::size_t>(ia)];
      // skinning: x = M (rest + d) + t with M = (1 - s) I + s R, so d = M^-1 (target - skin)
      const Mat3 m = (1.0 - j.s[a]) * Mat3::Identity() + j.s[a] * b.r;
      const Vec3 d = m.inverse() * (x.row(a) - skin.row(a)).transpose();
      D.block<1, 3>(q, 3 * ia) = d.transpose();
      rep.largest_offset = std::max(rep.largest_offset, std::sqrt(d.squaredNorm()));
    }
  }
  // ridge: bends about the three axes excite 6 of the 9 features; the other 3 get no weight
  const Eigen::Matrix<double, 9, 9> a =
      F.transpose() * F + 1e-6 * static_cast<double>(S) * Eigen::Matrix<double, 9, 9>::Identity();
  const Eigen::MatrixXd p = a.ldlt().solve(F.transpose() * D);  // 9 x 3n
  const Eigen::MatrixXd residual = F * p - D;
  rep.fit_rms = S * n > 0 ? std::sqrt(residual.squaredNorm() / static_cast<double>(S * 3 * n)) : 0;
  // a joint whose targets fold more than skinning alone (the head bent 90 degrees squeezes the
  // throat more than any skin can take) keeps plain skinning
  rep.kept = rep.folds_target <= rep.folds_skinned;
  if (!rep.kept) {
    return;
  }
  for (Eigen::Index ia = 0; ia < n; ++ia) {
    const int v = j.band.vertices[static_cast<std::size_t>(ia)];
    for (int c = 0; c < 3; ++c) {
      for (int f = 0; f < 9; ++f) {
        // rounded to 2^-20 m (1 um): far below the fit's error, and the file compresses
        posedirs(3 * Eigen::Index{v} + c, 9 * Eigen::Index{k - 1} + f) =
            std::round(std::ldexp(p(f, 3 * ia + c), 20)) / std::ldexp(1.0, 20);
      }
    }
  }
}

}  // namespace

std::vector<int> folded_triangles(const smpl::Vertices& rest, const smpl::Vertices& posed,
                                  const smpl::Faces& faces, const Eigen::VectorXd& s,
                                  const Eigen::Vector4d& q) {
  std::vector<int> out;
  for (Eigen::Index t = 0; t < faces.rows(); ++t) {
    const int i = faces(t, 0), j = faces(t, 1), k = faces(t, 2);
    const Vec3 n0 = Vec3(rest.row(j) - rest.row(i)).cross(Vec3(rest.row(k) - rest.row(i)));
    const Vec3 n1 = Vec3(posed.row(j) - posed.row(i)).cross(Vec3(posed.row(k) - posed.row(i)));
    const Mat3 r = matrix(blended(q, (s[i] + s[j] + s[k]) / 3.0));
    // |cross| is twice the area
    if (std::sqrt(n0.squaredNorm()) < 2 * kDegenerateArea ||
        std::sqrt(n1.squaredNorm()) < 2 * kDegenerateArea || n1.dot(r * n0) < 0) {
      out.push_back(static_cast<int>(t));
    }
  }
  return out;
}

Eigen::MatrixXd pose_correctives(const smpl::BodyModel& model, const PoseCorrectiveOptions& o,
                                 PoseCorrectiveReport* report) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  const int K = model.num_joints();
  const Eigen::Index V = model.num_vertices();
  Eigen::MatrixXd posedirs = Eigen::MatrixXd::Zero(3 * V, 9 * Eigen::Index{K - 1});
  const std::vector<std::vector<int>> nb = mh::vertex_neighbours(V, model.faces);
  const std::vector<smpl::Vertices> bodies = {model.v_template};  // the mean body
  std::vector<JointCorrective> reps(static_cast<std::size_t>(std::max(0, K - 1)));
  std::atomic<int> next{1};
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(std::max(1, o.threads)));
  const auto work = [&](std::size_t worker) {
    try {
      for (int k = next++; k < K; k = next++) {
        fit_joint(model, bodies, nb, o, k, posedirs, reps[static_cast<std::size_t>(k - 1)]);
      }
    } catch (...) {
      errors[worker] = std::current_exception();
      next = K;
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < errors.size(); ++t) {
    pool.emplace_back(work, t);
  }
  work(0);
  for (std::thread& t : pool) {
    t.join();
  }
  for (const std::exception_ptr& e : errors) {
    if (e) {
      std::rethrow_exception(e);
    }
  }
  if (report != nullptr) {
    report->joints = std::move(reps);
  }
  return posedirs;
}

}  // namespace modelgen
