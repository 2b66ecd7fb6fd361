/// \file subdivision.cpp
/// Catmull-Clark subdivision as a sparse operator.
#include "subdivision.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <utility>

namespace modelgen {
namespace {

struct Level {
  SubdivisionMatrix s;
  std::vector<std::array<int, 4>> quads;
  int num_in = 0;
  int num_edges = 0;
};

Level one_level(int nv, const std::vector<std::array<int, 4>>& quads) {
  const int nf = static_cast<int>(quads.size());
  // Edges: sorted (min, max, face) records; deterministic, no hashing.
  std::vector<std::array<int, 3>> rec;
  rec.reserve(static_cast<std::size_t>(nf) * 4);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 4; ++k) {
      const int a = quads[f][k], b = quads[f][(k + 1) % 4];
      rec.push_back({std::min(a, b), std::max(a, b), f});
    }
  }
  std::sort(rec.begin(), rec.end());
  std::vector<std::array<int, 4>> edges;  // a, b, f0, f1
  for (std::size_t i = 0; i < rec.size();) {
    if (i + 1 >= rec.size() || rec[i + 1][0] != rec[i][0] || rec[i + 1][1] != rec[i][1] ||
        (i + 2 < rec.size() && rec[i + 2][0] == rec[i][0] && rec[i + 2][1] == rec[i][1])) {
      throw std::logic_error("catmull_clark: mesh is not closed 2-manifold at edge " +
                             std::to_string(rec[i][0]) + "-" + std::to_string(rec[i][1]));
    }
    edges.push_back({rec[i][0], rec[i][1], rec[i][2], rec[i + 1][2]});
    i += 2;
  }
  const int ne = static_cast<int>(edges.size());
  auto edge_id = [&](int a, int b) {
    const std::array<int, 4> key = {std::min(a, b), std::max(a, b), -1, -1};
    const auto it = std::lower_bound(edges.begin(), edges.end(), key,
                                     [](const std::array<int, 4>& x, const std::array<int, 4>& y) {
                                       return x[0] != y[0] ? x[0] < y[0] : x[1] < y[1];
                                     });
    return static_cast<int>(it - edges.begin());
  };
  std::vector<Eigen::Triplet<double>> t;
  // vertex points: (F + 2R + (n - 3) P) / n
  std::vector<std::vector<int>> vfaces(nv), vedges(nv);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 4; ++k) {
      vfaces[quads[f][k]].push_back(f);
    }
  }
  for (int e = 0; e < ne; ++e) {
    vedges[edges[e][0]].push_back(e);
    vedges[edges[e][1]].push_back(e);
  }
  for (int v = 0; v < nv; ++v) {
    const double n = static_cast<double>(vedges[v].size());
    if (vedges[v].empty()) {
      throw std::logic_error("catmull_clark: unused vertex");
    }
    t.emplace_back(v, v, (n - 3) / n);
    for (int f : vfaces[v]) {
      for (int k = 0; k < 4; ++k) {
        t.emplace_back(v, quads[f][k], 1.0 / (4 * n * n));
      }
    }
    for (int e : vedges[v]) {
      t.emplace_back(v, edges[e][0], 2.0 / (2 * n * n));
      t.emplace_back(v, edges[e][1], 2.0 / (2 * n * n));
    }
  }
  // edge points: (a + b + fp0 + fp1) / 4
  for (int e = 0; e < ne; ++e) {
    const int row = nv + e;
    t.emplace_back(row, edges[e][0], 0.25);
    t.emplace_back(row, edges[e][1], 0.25);
    for (int f : {edges[e][2], edges[e][3]}) {
      for (int k = 0; k < 4; ++k) {
        t.emplace_back(row, quads[f][k], 1.0 / 16);
      }
    }
  }
  // face points
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 4; ++k) {
      t.emplace_back(nv + ne + f, quads[f][k], 0.25);
    }
  }
  Level out;
  out.num_in = nv;
  out.num_edges = ne;
  out.s.resize(nv + ne + nf, nv);
  out.s.setFromTriplets(t.begin(), t.end());  // duplicates are summed in a fixed order
  out.quads.reserve(static_cast<std::size_t>(nf) * 4);
  for (int f = 0; f < nf; ++f) {
    const int fp = nv + ne + f;
    for (int k = 0; k < 4; ++k) {
      const int v = quads[f][k];
      const int e_next = nv + edge_id(v, quads[f][(k + 1) % 4]);
      const int e_prev = nv + edge_id(quads[f][(k + 3) % 4], v);
      out.quads.push_back({v, e_next, fp, e_prev});
    }
  }
  return out;
}

}  // namespace

Subdivision catmull_clark(int num_vertices, const std::vector<std::array<int, 4>>& quads,
                          int levels) {
  Subdivision out;
  out.s.resize(num_vertices, num_vertices);
  out.s.setIdentity();
  out.quads = quads;
  int nv = num_vertices;
  for (int l = 0; l < levels; ++l) {
    Level lv = one_level(nv, out.quads);
    if (l == 0) {
      out.face_point.resize(quads.size());
      for (std::size_t f = 0; f < quads.size(); ++f) {
        out.face_point[f] = nv + lv.num_edges + static_cast<int>(f);
      }
    }
    SubdivisionMatrix next = lv.s * out.s;
    out.s = next;
    out.quads = std::move(lv.quads);
    nv = static_cast<int>(out.s.rows());
  }
  out.s.prune(0.0);
  return out;
}

}  // namespace modelgen
