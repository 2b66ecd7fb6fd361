/// \file mesh_checks.cpp
#include "mesh_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace modelgen {

namespace {

int find_root(std::vector<int>& parent, int x) {
  while (parent[static_cast<std::size_t>(x)] != x) {
    parent[static_cast<std::size_t>(x)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    x = parent[static_cast<std::size_t>(x)];
  }
  return x;
}

}  // namespace

TopologyReport topology_report(int num_vertices, const smpl::Faces& faces) {
  TopologyReport r;
  std::vector<std::array<int, 3>> directed;  // a, b, face
  const int nf = static_cast<int>(faces.rows());
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      directed.push_back({faces(f, k), faces(f, (k + 1) % 3), f});
    }
  }
  std::vector<std::array<int, 3>> sorted = directed;
  std::sort(sorted.begin(), sorted.end());
  r.oriented = true;
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    if (sorted[i][0] == sorted[i - 1][0] && sorted[i][1] == sorted[i - 1][1]) {
      r.oriented = false;
    }
  }
  std::map<std::pair<int, int>, int> undirected;
  for (const auto& d : directed) {
    ++undirected[{std::min(d[0], d[1]), std::max(d[0], d[1])}];
  }
  for (const auto& [e, n] : undirected) {
    r.boundary_edges += n == 1;
    r.nonmanifold_edges += n >= 3;
  }
  r.closed = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
  // vertex fans: walk the triangles around each vertex through shared edges
  std::vector<std::vector<int>> vf(static_cast<std::size_t>(num_vertices));
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      vf[static_cast<std::size_t>(faces(f, k))].push_back(f);
    }
  }
  r.vertex_manifold = true;
  for (int v = 0; v < num_vertices; ++v) {
    const auto& fs = vf[static_cast<std::size_t>(v)];
    if (fs.empty()) {
      ++r.unused_vertices;
      continue;
    }
    // union-find over faces of the fan connected through an edge (v, w)
    std::vector<int> parent(fs.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::map<int, std::vector<int>> by_other;
    for (std::size_t i = 0; i < fs.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const int w = faces(fs[i], k);
        if (w != v) {
          by_other[w].push_back(static_cast<int>(i));
        }
      }
    }
    for (const auto& [w, list] : by_other) {
      for (std::size_t i = 1; i < list.size(); ++i) {
        parent[static_cast<std::size_t>(find_root(parent, list[i]))] = find_root(parent, list[0]);
      }
    }
    const int root = find_root(parent, 0);
    for (std::size_t i = 1; i < fs.size(); ++i) {
      if (find_root(parent, static_cast<int>(i)) != root) {
        r.vertex_manifold = false;
      }
    }
  }
  // connected components: vertices joined by the faces' edges, counted over used vertices
  std::vector<int> parent(static_cast<std::size_t>(num_vertices));
  std::iota(parent.begin(), parent.end(), 0);
  for (int f = 0; f < nf; ++f) {
    for (int k = 1; k < 3; ++k) {
      parent[static_cast<std::size_t>(find_root(parent, faces(f, k)))] =
          find_root(parent, faces(f, 0));
    }
  }
  for (int v = 0; v < num_vertices; ++v) {
    r.components += !vf[static_cast<std::size_t>(v)].empty() && find_root(parent, v) == v;
  }
  r.euler = num_vertices - static_cast<int>(undirected.size()) + nf;
  return r;
}

namespace {

/// Whether segment p-q crosses triangle (a, b, c) (Moller-Trumbore with the segment's
/// parameter in [0, 1]); a segment parallel to the triangle's plane never does.
bool segment_hits_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                           const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = q - p;
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-18) {
    return false;  // parallel (coplanar cases are not reported)
  }
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0.0 || u > 1.0) {
    return false;
  }
  const Eigen::Vector3d qq = s.cross(e1);
  const double w = inv * d.dot(qq);
  if (w < 0.0 || u + w > 1.0) {
    return false;
  }
  const double t = inv * e2.dot(qq);
  return t >= 0.0 && t <= 1.0;
}

/// Whether triangles i and j (sharing no vertex) intersect: some edge of one crosses the other.
bool triangles_intersect(const smpl::Vertices& v, const smpl::Faces& f, int i, int j) {
  const Eigen::Vector3d a0 = v.row(f(i, 0)), a1 = v.row(f(i, 1)), a2 = v.row(f(i, 2));
  const Eigen::Vector3d b0 = v.row(f(j, 0)), b1 = v.row(f(j, 1)), b2 = v.row(f(j, 2));
  return segment_hits_triangle(a0, a1, b0, b1, b2) || segment_hits_triangle(a1, a2, b0, b1, b2) ||
         segment_hits_triangle(a2, a0, b0, b1, b2) || segment_hits_triangle(b0, b1, a0, a1, a2) ||
         segment_hits_triangle(b1, b2, a0, a1, a2) || segment_hits_triangle(b2, b0, a0, a1, a2);
}

/// Whether triangles i and j sharing exactly vertex i's corner `ci` and j's corner `cj` cross
/// away from it. Their intersection (if not coplanar) is a segment from the shared vertex to a
/// point on the opposite edge of one of them, so testing both opposite edges finds it.
bool fan_triangles_intersect(const smpl::Vertices& v, const smpl::Faces& f, int i, int ci, int j,
                             int cj) {
  const Eigen::Vector3d a0 = v.row(f(i, 0)), a1 = v.row(f(i, 1)), a2 = v.row(f(i, 2));
  const Eigen::Vector3d b0 = v.row(f(j, 0)), b1 = v.row(f(j, 1)), b2 = v.row(f(j, 2));
  const Eigen::Vector3d ap = v.row(f(i, (ci + 1) % 3)), aq = v.row(f(i, (ci + 2) % 3));
  const Eigen::Vector3d bp = v.row(f(j, (cj + 1) % 3)), bq = v.row(f(j, (cj + 2) % 3));
  return segment_hits_triangle(ap, aq, b0, b1, b2) || segment_hits_triangle(bp, bq, a0, a1, a2);
}

}  // namespace

std::vector<std::pair<int, int>> self_intersections(const smpl::Vertices& v, const smpl::Faces& f,
                                                    double cell) {
  const int nf = static_cast<int>(f.rows());
  std::vector<std::pair<int, int>> hits;
  if (nf == 0 || v.rows() == 0) {
    return hits;
  }
  const Eigen::Vector3d lo = v.colwise().minCoeff().transpose();
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(nf));
  // (cell key, triangle) for every cell a triangle's bounding box touches; sorted, so that the
  // triangles of one cell are adjacent
  std::vector<std::pair<std::uint64_t, int>> entries;
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3i(((p - lo) / cell).array().floor().cast<int>());
  };
  auto key = [](const Eigen::Vector3i& c) {
    return (static_cast<std::uint64_t>(c.x()) << 42) | (static_cast<std::uint64_t>(c.y()) << 21) |
           static_cast<std::uint64_t>(c.z());
  };
  for (int t = 0; t < nf; ++t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) {
      box.extend(Eigen::Vector3d(v.row(f(t, k))));
    }
    boxes[static_cast<std::size_t>(t)] = box;
    const Eigen::Vector3i mn = cell_of(box.min()), mx = cell_of(box.max());
    for (int x = mn.x(); x <= mx.x(); ++x) {
      for (int y = mn.y(); y <= mx.y(); ++y) {
        for (int z = mn.z(); z <= mx.z(); ++z) {
          entries.emplace_back(key({x, y, z}), t);
        }
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  for (std::size_t begin = 0; begin < entries.size();) {
    std::size_t end = begin;
    while (end < entries.size() && entries[end].first == entries[begin].first) {
      ++end;
    }
    for (std::size_t a = begin; a < end; ++a) {
      for (std::size_t b = a + 1; b < end; ++b) {
        const int i = entries[a].second, j = entries[b].second;  // i < j: sorted by triangle
        const Eigen::AlignedBox3d& bi = boxes[static_cast<std::size_t>(i)];
        const Eigen::AlignedBox3d& bj = boxes[static_cast<std::size_t>(j)];
        if (!bi.intersects(bj)) {
          continue;
        }
        // test each pair once: in the cell holding the lower corner of the boxes' overlap
        if (key(cell_of(bi.intersection(bj).min())) != entries[begin].first) {
          continue;
        }
        int shared = 0, ci = -1, cj = -1;
        for (int p = 0; p < 3; ++p) {
          for (int q = 0; q < 3; ++q) {
            if (f(i, p) == f(j, q)) {
              ++shared;
              ci = p;
              cj = q;
            }
          }
        }
        const bool hit = shared == 0   ? triangles_intersect(v, f, i, j)
                         : shared == 1 ? fan_triangles_intersect(v, f, i, ci, j, cj)
                                       : false;
        if (hit) {
          hits.emplace_back(i, j);
        }
      }
    }
    begin = end;
  }
  std::sort(hits.begin(), hits.end());
  return hits;
}

double crossing_depth(const smpl::Vertices& v, const smpl::Faces& f, int i, int j) {
  auto behind = [&](int a, int b) {
    const Eigen::Vector3d p = v.row(f(b, 0)), q = v.row(f(b, 1)), r = v.row(f(b, 2));
    const Eigen::Vector3d n = (q - p).cross(r - p);
    if (n.norm() == 0.0) {
      return 0.0;
    }
    double d = 0.0;
    for (int k = 0; k < 3; ++k) {
      d = std::max(d, -(Eigen::Vector3d(v.row(f(a, k))) - p).dot(n) / n.norm());
    }
    return d;
  };
  return std::min(behind(i, j), behind(j, i));
}

std::vector<int> flipped_triangles(const smpl::BodyModel& model, const smpl::Vertices& rest,
                                   const smpl::Body& posed) {
  std::vector<int> out;
  const Eigen::MatrixXd w(model.weights);
  for (int t = 0; t < model.num_faces(); ++t) {
    const int i = model.faces(t, 0), j = model.faces(t, 1), k = model.faces(t, 2);
    const Eigen::RowVectorXd tw = w.row(i) + w.row(j) + w.row(k);
    Eigen::Matrix3d blend = Eigen::Matrix3d::Zero();
    for (int q = 0; q < tw.size(); ++q) {
      if (tw[q] > 0) {
        blend += tw[q] * posed.transforms[static_cast<std::size_t>(q)].block<3, 3>(0, 0);
      }
    }
    // nearest rotation (polar decomposition through the SVD)
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(blend, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
    if (r.determinant() < 0) {
      Eigen::Matrix3d u = svd.matrixU();
      u.col(2) = -u.col(2);
      r = u * svd.matrixV().transpose();
    }
    const Eigen::Vector3d n0 = (Eigen::Vector3d(rest.row(j) - rest.row(i)))
                                   .cross(Eigen::Vector3d(rest.row(k) - rest.row(i)));
    const Eigen::Vector3d n1 =
        (Eigen::Vector3d(posed.vertices.row(j) - posed.vertices.row(i)))
            .cross(Eigen::Vector3d(posed.vertices.row(k) - posed.vertices.row(i)));
    // |cross| is twice the area
    if (n0.norm() < 2 * kDegenerateArea || n1.norm() < 2 * kDegenerateArea) {
      out.push_back(t);
      continue;
    }
    if (n1.dot(r * n0) < 0) {
      out.push_back(t);
    }
  }
  return out;
}

const std::vector<TestPose>& test_poses() {
  static const std::vector<TestPose> poses = [] {
    constexpr double kRight = 1.5707963267948966;
    struct One {
      const char* name;
      int joint;
      Eigen::Vector3d axis_angle;
    };
    const One ones[] = {
        {"left elbow flexed", 18, {0, -kRight, 0}},
        {"right elbow flexed", 19, {0, kRight, 0}},
        {"left knee flexed", 4, {kRight, 0, 0}},
        {"right knee flexed", 5, {kRight, 0, 0}},
        {"left shoulder down", 16, {0, 0, -kRight}},
        {"right shoulder down", 17, {0, 0, kRight}},
        {"left shoulder forward", 16, {0, -kRight, 0}},
        {"left hip flexed", 1, {-kRight, 0, 0}},
        {"right hip flexed", 2, {-kRight, 0, 0}},
        {"left hip abducted 45", 1, {0, 0, kRight / 2}},
    };
    std::vector<TestPose> out;
    for (const One& o : ones) {
      Eigen::VectorXd theta = Eigen::VectorXd::Zero(3 * Eigen::Index{24});
      theta.segment<3>(3 * Eigen::Index{o.joint}) = o.axis_angle;
      out.push_back({o.name, theta});
    }
    return out;
  }();
  return poses;
}

int dominant_joint(const smpl::BodyModel& model, int t) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(model.num_joints());
  for (int c = 0; c < 3; ++c) {
    for (smpl::SparseMatrix::InnerIterator it(model.weights, model.faces(t, c)); it; ++it) {
      sum[it.col()] += it.value();
    }
  }
  Eigen::Index arg = 0;
  sum.maxCoeff(&arg);
  return static_cast<int>(arg);
}

}  // namespace modelgen
