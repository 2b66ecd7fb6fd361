/// \file contact.cpp
#include "contact.hpp"

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <thread>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "makehuman.hpp"
#include "makehuman_rig.hpp"
#include "mesh_checks.hpp"
#include "smpl/export.hpp"
#include "validation.hpp"

namespace modelgen {

namespace {

/// Check body `b`'s vertices: 0 the mean, then -sd and +sd along each component (a plain loop:
/// the same bits on every CPU).
smpl::Vertices check_body(const smpl::BodyModel& model, int b, double sd) {
  smpl::Vertices v = model.v_template;
  if (b == 0) return v;
  const Eigen::Index c = (b - 1) / 2;
  const double beta = (b % 2 == 1) ? -sd : sd;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    for (int d = 0; d < 3; ++d) v(i, d) += beta * model.shapedirs(3 * i + d, c);
  }
  return v;
}

/// A plane through `p` with unit normal `n`: the other sheet where a vertex went through it.
struct Plane {
  Eigen::Vector3d p, n;
  double behind(const Eigen::Vector3d& x) const { return -(x - p).dot(n); }
};

/// How far each vertex of body `v` must move back along its inward normal this round (capped),
/// into `need`; returns the number of intersecting triangle pairs. Seeds: for every intersecting
/// pair, the vertices of each triangle behind the other's plane. From the seeds the region that
/// went through is flooded over the mesh's edges (breadth first, seeds in pair order) while the
/// vertices stay behind the plane that their seed went through and within `kReach` of it: the
/// vertices wholly inside the other sheet, whose triangles cross nothing. Each vertex moves half
/// its depth behind that plane plus the gap (the other sheet moves too). `away` sums per vertex
/// the way out of the other sheet (its plane's normal) weighted by the depth.
int vertex_needs(const smpl::Vertices& v, const smpl::Faces& f,
                 const std::vector<std::vector<int>>& ring, const smpl::Vertices& inward,
                 const Eigen::VectorXd& cap, const ContactOptions& o, Eigen::VectorXd& need,
                 smpl::Vertices& away) {
  constexpr double kReach = 0.02;  // metres from the seed: a flood stays local
  // A vertex faces the other sheet when its outward normal is more than 120 degrees from the
  // other sheet's (inward . n > cos 60): skin that only grazes it (the top of a toe beside its
  // neighbour's side) is not moved.
  constexpr double kFacing = 0.5;
  auto facing = [&](int x, const Eigen::Vector3d& n) {
    return inward.row(x).dot(n.transpose()) > kFacing;
  };
  need.setZero(v.rows());
  away.setZero(v.rows(), 3);
  const auto pairs = self_intersections(v, f);
  std::vector<int> plane_of(static_cast<std::size_t>(v.rows()), -1);
  std::vector<Plane> planes;
  std::vector<int> queue;
  auto seed = [&](int a, int b) {  // a's vertices behind b's plane
    const Eigen::Vector3d p = v.row(f(b, 0)), q = v.row(f(b, 1)), r = v.row(f(b, 2));
    const Eigen::Vector3d n = (q - p).cross(r - p);
    if (n.norm() == 0.0) return;
    const Plane plane{p, n / n.norm()};
    for (int k = 0; k < 3; ++k) {
      const int x = f(a, k);
      if (x == f(b, 0) || x == f(b, 1) || x == f(b, 2)) continue;  // shared corner
      if (plane_of[static_cast<std::size_t>(x)] >= 0) continue;
      if (plane.behind(v.row(x)) > 0.0 && facing(x, plane.n)) {
        planes.push_back(plane);
        plane_of[static_cast<std::size_t>(x)] = static_cast<int>(planes.size()) - 1;
        queue.push_back(x);
      }
    }
  };
  for (const auto& [i, j] : pairs) {
    seed(i, j);
    seed(j, i);
  }
  std::vector<Eigen::Vector3d> origin;  // each queued vertex's seed position
  origin.reserve(queue.size());
  for (const int x : queue) origin.emplace_back(v.row(x));
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int x = queue[head];
    const Plane& plane = planes[static_cast<std::size_t>(plane_of[static_cast<std::size_t>(x)])];
    const double d = plane.behind(v.row(x));
    need[x] = std::max(need[x], std::min(0.5 * d + o.gap, cap[x]));
    away.row(x) += d * plane.n.transpose();
    for (const int y : ring[static_cast<std::size_t>(x)]) {
      if (plane_of[static_cast<std::size_t>(y)] >= 0) continue;
      const Eigen::Vector3d py = v.row(y);
      const Eigen::Vector3d from = origin[head];
      if (plane.behind(py) <= 0.0 || !facing(y, plane.n) || (py - from).norm() > kReach) continue;
      plane_of[static_cast<std::size_t>(y)] = plane_of[static_cast<std::size_t>(x)];
      queue.push_back(y);
      origin.push_back(from);
    }
  }
  return static_cast<int>(pairs.size());
}

/// Spreads `need` to the 1-ring at half strength, twice, so that a moved vertex takes its
/// neighbours along (a dent one vertex wide would fold).
void spread(const smpl::Faces& f, Eigen::VectorXd& need) {
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::VectorXd out = need;
    for (Eigen::Index t = 0; t < f.rows(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const int a = f(t, k), b = f(t, (k + 1) % 3);
        out[a] = std::max(out[a], 0.5 * need[b]);
        out[b] = std::max(out[b], 0.5 * need[a]);
      }
    }
    need = out;
  }
}

}  // namespace

namespace {

/// Each vertex's largest move per round: `max_step`, or half its shortest edge on `v` if less
/// (a move longer than the edges folds the skin: the lips' edges are 1-2 mm, the thighs' 10).
Eigen::VectorXd step_caps(const smpl::Vertices& v, const smpl::Faces& f, double max_step) {
  Eigen::VectorXd cap = Eigen::VectorXd::Constant(v.rows(), max_step);
  for (Eigen::Index t = 0; t < f.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = f(t, k), b = f(t, (k + 1) % 3);
      const double half = 0.5 * (v.row(a) - v.row(b)).norm();
      cap[a] = std::min(cap[a], half);
      cap[b] = std::min(cap[b], half);
    }
  }
  return cap;
}

/// One round's moves: the linear offset a + beta_c b_c per vertex that gives each check body
/// its need (see the header), along the inward normals; scaled down where the vertex's moves
/// so far (`moved`, on its worst check body, summed over the rounds) would pass `limit`.
void apply_needs(const std::vector<Eigen::VectorXd>& need, const smpl::Vertices& inward, int k,
                 double sd, double limit, Eigen::VectorXd& moved, smpl::BodyModel& model) {
  Eigen::VectorXd b(k);
  for (Eigen::Index i = 0; i < model.v_template.rows(); ++i) {
    double a = need[0][i];
    for (int c = 0; c < k; ++c) {
      const std::size_t lo = 1 + 2 * static_cast<std::size_t>(c);
      a = std::max(a, 0.5 * (need[lo][i] + need[lo + 1][i]));
    }
    double worst = a;
    for (int c = 0; c < k; ++c) {
      const std::size_t lo = 1 + 2 * static_cast<std::size_t>(c);
      b[c] = (need[lo + 1][i] - need[lo][i]) / (2.0 * sd);
      worst = std::max(worst, a + sd * std::abs(b[c]));
    }
    if (worst == 0.0) continue;
    const double scale = std::clamp((limit - moved[i]) / worst, 0.0, 1.0);
    moved[i] += scale * worst;
    for (int c = 0; c < k; ++c) {
      for (int d = 0; d < 3; ++d) model.shapedirs(3 * i + d, c) += scale * b[c] * inward(i, d);
    }
    for (int d = 0; d < 3; ++d) model.v_template(i, d) += scale * a * inward(i, d);
  }
}

}  // namespace

namespace {

/// The per-round state of separate_contacts().
struct Rounds {
  std::vector<Eigen::VectorXd> need;  ///< per check body
  std::vector<smpl::Vertices> away;   ///< per check body (vertex_needs)
  std::vector<int> pairs;             ///< per check body
};

/// Checks every body of `model` into `r` (independent: threads take every threads-th body).
void check_bodies(const smpl::BodyModel& model, const std::vector<std::vector<int>>& ring,
                  const smpl::Vertices& inward, const Eigen::VectorXd& cap, const ContactOptions& o,
                  int threads, Rounds& r) {
  const int bodies = static_cast<int>(r.pairs.size());
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(threads));
  for (int w = 0; w < threads; ++w) {
    pool.emplace_back([&, w] {
      for (int b = w; b < bodies; b += threads) {
        const auto i = static_cast<std::size_t>(b);
        r.pairs[i] = vertex_needs(check_body(model, b, o.sd), model.faces, ring, inward, cap, o,
                                  r.need[i], r.away[i]);
      }
    });
  }
  for (std::thread& t : pool) t.join();
}

/// ContactDirection::OutOfTheOtherSheet: each vertex that needs a move for the first time takes
/// the depth-weighted sum of the ways out over the check bodies (its mirror vertex's, reflected,
/// added: the same direction mirrored on both sides) as its direction from then on.
void fix_directions(const Rounds& r, const std::vector<int>& mirror, smpl::Vertices& dir,
                    std::vector<bool>& fixed) {
  const Eigen::Index nv = dir.rows();
  for (Eigen::Index i = 0; i < nv; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) continue;
    Eigen::RowVector3d t = Eigen::RowVector3d::Zero();
    for (const smpl::Vertices& a : r.away) t += a.row(i);
    if (!mirror.empty()) {
      Eigen::RowVector3d u = Eigen::RowVector3d::Zero();
      for (const smpl::Vertices& a : r.away) u += a.row(mirror[static_cast<std::size_t>(i)]);
      u.x() = -u.x();
      t += u;
    }
    if (t.norm() > 0.0) {
      dir.row(i) = t / t.norm();
      fixed[static_cast<std::size_t>(i)] = true;
    }
  }
}

}  // namespace

ContactReport separate_contacts(smpl::BodyModel& model, const ContactOptions& options) {
  const int k = std::min(options.components, model.num_betas());
  const int bodies = 1 + 2 * k;
  const Eigen::Index nv = model.v_template.rows();
  const smpl::Vertices inward = -smpl::vertex_normals(model.v_template, model.faces);
  const bool mirrored = static_cast<Eigen::Index>(model.mirror.size()) == nv;
  const std::vector<int> no_mirror;
  const std::vector<int>& mirror = mirrored ? model.mirror : no_mirror;
  const std::vector<std::vector<int>> ring = mh::vertex_neighbours(nv, model.faces);
  const ContactOptions& o = options;
  const Eigen::VectorXd cap = step_caps(model.v_template, model.faces, options.max_step);
  const smpl::BodyModel original = model;
  Eigen::VectorXd moved = Eigen::VectorXd::Zero(nv);
  smpl::Vertices dir = inward;  // each vertex's direction of move
  std::vector<bool> fixed(static_cast<std::size_t>(nv), false);

  ContactReport report;
  report.bodies = bodies;
  report.direction = o.direction;
  Rounds r{std::vector<Eigen::VectorXd>(static_cast<std::size_t>(bodies)),
           std::vector<smpl::Vertices>(static_cast<std::size_t>(bodies)),
           std::vector<int>(static_cast<std::size_t>(bodies), 0)};
  // The state with the fewest intersecting pairs over the check bodies is kept: a round can
  // make more than it removes (a crease pushed into a fold), and the rounds after it rarely
  // recover.
  smpl::Vertices best_template;
  Eigen::MatrixXd best_dirs;
  long best_total = -1;
  for (int round = 0;; ++round) {
    check_bodies(model, ring, inward, cap, o, std::max(1, o.threads), r);
    if (round == 0) report.pairs_before = r.pairs;
    const long total = std::accumulate(r.pairs.begin(), r.pairs.end(), 0L);
    if (best_total < 0 || total < best_total) {
      best_total = total;
      best_template = model.v_template;
      best_dirs = model.shapedirs.leftCols(k);
      report.pairs_after = r.pairs;
      report.kept_round = round;
    }
    if (total == 0 || round == o.max_rounds) break;
    report.rounds = round + 1;
    for (Eigen::VectorXd& n : r.need) {
      spread(model.faces, n);
      if (mirrored) {  // the model stays left/right symmetric
        const Eigen::VectorXd copy = n;
        for (Eigen::Index i = 0; i < nv; ++i) {
          n[i] = std::max(copy[i], copy[mirror[static_cast<std::size_t>(i)]]);
        }
      }
    }
    if (o.direction == ContactDirection::OutOfTheOtherSheet) fix_directions(r, mirror, dir, fixed);
    apply_needs(r.need, dir, k, o.sd, o.max_move, moved, model);
  }
  model.v_template = best_template;
  model.shapedirs.leftCols(k) = best_dirs;
  if (mirrored) {
    // Equal moves on mirror vertices along mirrored directions: symmetric to rounding, exact
    // here (as shape_model() leaves them).
    mh::symmetrize(model.v_template, model.mirror);
    for (int c = 0; c < k; ++c) {
      mh::symmetrize(Eigen::Map<smpl::Vertices>(model.shapedirs.col(c).data(), nv, 3),
                     model.mirror);
    }
  }
  for (Eigen::Index i = 0; i < nv; ++i) {
    const Eigen::RowVector3d a = model.v_template.row(i) - original.v_template.row(i);
    double worst = a.norm();
    for (int c = 0; c < k; ++c) {
      for (const double beta : {-o.sd, o.sd}) {
        Eigen::RowVector3d d = a;
        for (int j = 0; j < 3; ++j) {
          d[j] += beta * (model.shapedirs(3 * i + j, c) - original.shapedirs(3 * i + j, c));
        }
        worst = std::max(worst, d.norm());
      }
    }
    if (worst > 0.0) ++report.moved_vertices;
    report.largest_move = std::max(report.largest_move, worst);
  }
  return report;
}

ContactReport separate_contacts_best(smpl::BodyModel& model, ContactOptions options) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  smpl::BodyModel other = model;
  options.direction = ContactDirection::InwardNormal;
  ContactReport inward = separate_contacts(model, options);
  options.direction = ContactDirection::OutOfTheOtherSheet;
  ContactReport away = separate_contacts(other, options);
  auto total = [](const std::vector<int>& p) { return std::accumulate(p.begin(), p.end(), 0L); };
  if (total(away.pairs_after) < total(inward.pairs_after)) {
    model = std::move(other);
    return away;
  }
  return inward;
}

namespace {

/// The vertices of the pairs of `v` whose triangles are within two 1-rings of each other (the
/// crumples), grown by two rings; returns the number of such pairs.
int mark_crumples(const smpl::Vertices& v, const smpl::Faces& f,
                  const std::vector<std::vector<int>>& ring, std::vector<char>& mark) {
  constexpr int kNear = 2;  // rings between the two triangles of a crumple
  const auto nv = static_cast<std::size_t>(v.rows());
  mark.assign(nv, 0);
  std::vector<int> dist(nv, -1);
  int count = 0;
  for (const auto& [i, j] : self_intersections(v, f)) {
    // breadth-first from triangle i's corners, at most kNear rings
    std::vector<int> queue;
    for (int c = 0; c < 3; ++c) {
      dist[static_cast<std::size_t>(f(i, c))] = 0;
      queue.push_back(f(i, c));
    }
    for (std::size_t h = 0; h < queue.size(); ++h) {
      const int x = queue[h];
      if (dist[static_cast<std::size_t>(x)] == kNear) continue;
      for (const int y : ring[static_cast<std::size_t>(x)]) {
        if (dist[static_cast<std::size_t>(y)] >= 0) continue;
        dist[static_cast<std::size_t>(y)] = dist[static_cast<std::size_t>(x)] + 1;
        queue.push_back(y);
      }
    }
    bool near = false;
    for (int c = 0; c < 3; ++c) near = near || dist[static_cast<std::size_t>(f(j, c))] >= 0;
    for (const int x : queue) dist[static_cast<std::size_t>(x)] = -1;
    if (!near) continue;
    ++count;
    for (const int t : {i, j}) {
      for (int c = 0; c < 3; ++c) mark[static_cast<std::size_t>(f(t, c))] = 1;
    }
  }
  mh::grow_marks(mark, ring, 2);
  return count;
}

}  // namespace

UnfoldReport unfold_creases(smpl::BodyModel& model, const ContactOptions& options) {
  const DeterministicNumerics pinned;  // the same bytes on every CPU (validation.hpp)
  const int k = std::min(options.components, model.num_betas());
  const Eigen::Index nv = model.v_template.rows();
  const bool mirrored = static_cast<Eigen::Index>(model.mirror.size()) == nv;
  const std::vector<std::vector<int>> ring = mh::vertex_neighbours(nv, model.faces);
  const smpl::BodyModel original = model;
  UnfoldReport report;
  report.bodies = 1 + 2 * k;
  std::vector<char> mark;
  for (int round = 0;; ++round) {
    std::vector<int> pairs(static_cast<std::size_t>(report.bodies), 0);
    std::vector<std::vector<char>> marks(static_cast<std::size_t>(report.bodies));
    for (int b = 0; b < report.bodies; ++b) {
      pairs[static_cast<std::size_t>(b)] = mark_crumples(
          check_body(model, b, options.sd), model.faces, ring, marks[static_cast<std::size_t>(b)]);
    }
    if (round == 0) report.pairs_before = pairs;
    report.pairs_after = pairs;
    if (std::accumulate(pairs.begin(), pairs.end(), 0) == 0 || round == options.max_rounds) break;
    report.rounds = round + 1;
    for (int b = 0; b < report.bodies; ++b) {
      if (pairs[static_cast<std::size_t>(b)] == 0) continue;
      const std::vector<char>& m = marks[static_cast<std::size_t>(b)];
      if (b == 0) {
        mh::smooth_marked(model.v_template, ring, m, 5);
        if (mirrored) mh::symmetrize(model.v_template, model.mirror);
        continue;
      }
      Eigen::Map<smpl::Vertices> column(model.shapedirs.col((b - 1) / 2).data(), nv, 3);
      mh::smooth_marked(column, ring, m, 5);
      if (mirrored) mh::symmetrize(column, model.mirror);
    }
  }
  for (Eigen::Index i = 0; i < nv; ++i) {
    bool changed = model.v_template.row(i) != original.v_template.row(i);
    for (int c = 0; c < k && !changed; ++c) {
      changed = model.shapedirs.block<3, 1>(3 * i, c) != original.shapedirs.block<3, 1>(3 * i, c);
    }
    report.smoothed_vertices += changed ? 1 : 0;
  }
  return report;
}

}  // namespace modelgen
