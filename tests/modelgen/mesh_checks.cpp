/// \file mesh_checks.cpp
#include "mesh_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace modelgen_test {

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
  r.closed = true;
  for (const auto& [e, n] : undirected) {
    if (n != 2) {
      r.closed = false;
    }
  }
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
    for (std::size_t i = 0; i < fs.size(); ++i) {
      parent[i] = static_cast<int>(i);
    }
    auto find = [&](int x) {
      while (parent[static_cast<std::size_t>(x)] != x) {
        x = parent[static_cast<std::size_t>(x)];
      }
      return x;
    };
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
        parent[static_cast<std::size_t>(find(list[i]))] = find(list[0]);
      }
    }
    const int root = find(0);
    for (std::size_t i = 1; i < fs.size(); ++i) {
      if (find(static_cast<int>(i)) != root) {
        r.vertex_manifold = false;
      }
    }
  }
  r.euler = num_vertices - static_cast<int>(undirected.size()) + nf;
  return r;
}

namespace {

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

bool triangles_intersect(const smpl::Vertices& v, const smpl::Faces& f, int i, int j) {
  const Eigen::Vector3d a0 = v.row(f(i, 0)), a1 = v.row(f(i, 1)), a2 = v.row(f(i, 2));
  const Eigen::Vector3d b0 = v.row(f(j, 0)), b1 = v.row(f(j, 1)), b2 = v.row(f(j, 2));
  return segment_hits_triangle(a0, a1, b0, b1, b2) || segment_hits_triangle(a1, a2, b0, b1, b2) ||
         segment_hits_triangle(a2, a0, b0, b1, b2) || segment_hits_triangle(b0, b1, a0, a1, a2) ||
         segment_hits_triangle(b1, b2, a0, a1, a2) || segment_hits_triangle(b2, b0, a0, a1, a2);
}

}  // namespace

std::vector<std::pair<int, int>> self_intersections(const smpl::Vertices& v, const smpl::Faces& f,
                                                    double cell) {
  const int nf = static_cast<int>(f.rows());
  const Eigen::RowVector3d lo = v.colwise().minCoeff();
  std::map<std::array<int, 3>, std::vector<int>> grid;
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(nf));
  for (int t = 0; t < nf; ++t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) {
      box.extend(Eigen::Vector3d(v.row(f(t, k))));
    }
    boxes[static_cast<std::size_t>(t)] = box;
    const Eigen::Vector3d mn = (box.min() - lo.transpose()) / cell;
    const Eigen::Vector3d mx = (box.max() - lo.transpose()) / cell;
    for (int x = static_cast<int>(mn.x()); x <= static_cast<int>(mx.x()); ++x) {
      for (int y = static_cast<int>(mn.y()); y <= static_cast<int>(mx.y()); ++y) {
        for (int z = static_cast<int>(mn.z()); z <= static_cast<int>(mx.z()); ++z) {
          grid[{x, y, z}].push_back(t);
        }
      }
    }
  }
  std::vector<std::pair<int, int>> hits;
  for (const auto& [key, list] : grid) {
    for (std::size_t a = 0; a < list.size(); ++a) {
      for (std::size_t b = a + 1; b < list.size(); ++b) {
        const int i = std::min(list[a], list[b]), j = std::max(list[a], list[b]);
        bool shared = false;
        for (int p = 0; p < 3; ++p) {
          for (int q = 0; q < 3; ++q) {
            shared = shared || f(i, p) == f(j, q);
          }
        }
        if (shared) {
          continue;
        }
        if (!boxes[static_cast<std::size_t>(i)].intersects(boxes[static_cast<std::size_t>(j)])) {
          continue;
        }
        if (triangles_intersect(v, f, i, j)) {
          hits.emplace_back(i, j);
        }
      }
    }
  }
  std::sort(hits.begin(), hits.end());
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
  return hits;
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
    if (n0.norm() < 2e-12 || n1.norm() < 2e-12) {
      out.push_back(t);
      continue;
    }
    if (n1.dot(r * n0) < 0) {
      out.push_back(t);
    }
  }
  return out;
}

}  // namespace modelgen_test
