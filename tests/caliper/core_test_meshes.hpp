/// \file core_test_meshes.hpp
/// Hand-made meshes for the libcaliper core tests: cube, tetrahedron, UV sphere / ellipsoid,
/// vertical prisms (cylinders and star shapes) and a small body-like model whose measurements
/// are exactly linear in its betas.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"

namespace caliper::test {

struct Mesh {
  smpl::Vertices v;
  smpl::Faces f;
};

/// Unit cube [0,1]^3, 12 outward triangles.
inline Mesh make_cube() {
  Mesh m;
  m.v.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.v.row(i) << (i & 1), (i >> 1) & 1, (i >> 2) & 1;
  m.f.resize(12, 3);
  m.f << 0, 2, 1, 1, 2, 3,  // z = 0 (normal -z)
      4, 5, 6, 5, 7, 6,     // z = 1
      0, 1, 4, 1, 5, 4,     // y = 0
      2, 6, 3, 3, 6, 7,     // y = 1
      0, 4, 2, 2, 4, 6,     // x = 0
      1, 3, 5, 3, 7, 5;     // x = 1
  return m;
}

/// Tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1): volume 1/6.
inline Mesh make_tetrahedron() {
  Mesh m;
  m.v.resize(4, 3);
  m.v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.f.resize(4, 3);
  m.f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return m;
}

/// Closed vertical prism over the polygon `ring` (x, z), counter-clockwise seen from +y, from
/// y0 to y1 with `layers` rings of vertices in between, capped by fans around a centre vertex.
inline Mesh make_prism(const std::vector<Eigen::Vector2d>& ring, double y0, double y1,
                       int layers = 4, double centre_x = 0.0, double centre_z = 0.0) {
  const int n = static_cast<int>(ring.size());
  Mesh m;
  m.v.resize(n * layers + 2, 3);
  for (int l = 0; l < layers; ++l) {
    const double y = y0 + (y1 - y0) * l / (layers - 1);
    for (int i = 0; i < n; ++i) m.v.row(l * n + i) << ring[i].x(), y, ring[i].y();
  }
  const int bottom = n * layers, top = bottom + 1;
  m.v.row(bottom) << centre_x, y0, centre_z;
  m.v.row(top) << centre_x, y1, centre_z;
  std::vector<Eigen::Vector3i> tris;
  // Seen from +y with (x, z) counter-clockwise, the outward side winding is (a, b, a') where the
  // x-z orientation is reversed because the frame (x, y, z) maps (x, z) to a left-handed plane.
  for (int l = 0; l + 1 < layers; ++l) {
    for (int i = 0; i < n; ++i) {
      const int a = l * n + i, b = l * n + (i + 1) % n, c = a + n, d = b + n;
      tris.emplace_back(a, c, b);
      tris.emplace_back(b, c, d);
    }
  }
  for (int i = 0; i < n; ++i) {
    tris.emplace_back(bottom, i, (i + 1) % n);
    tris.emplace_back(top, (layers - 1) * n + (i + 1) % n, (layers - 1) * n + i);
  }
  m.f.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t) m.f.row(static_cast<Eigen::Index>(t)) = tris[t];
  return m;
}

/// Circle of `n` points of radius r about (cx, cz), counter-clockwise in (x, z).
inline std::vector<Eigen::Vector2d> circle(int n, double r, double cx = 0.0, double cz = 0.0) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * M_PI * i / n;
    p.emplace_back(cx + r * std::cos(t), cz + r * std::sin(t));
  }
  return p;
}

/// UV ellipsoid with radii (a, b, c) about `centre`; `rings` latitude rings of `segments`.
inline Mesh make_ellipsoid(double a, double b, double c, int rings, int segments,
                           const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
  Mesh m;
  m.v.resize(rings * segments + 2, 3);
  m.v.row(0) = (centre + Eigen::Vector3d(0, -b, 0)).transpose();
  for (int r = 0; r < rings; ++r) {
    const double phi = M_PI * (r + 1) / (rings + 1);  // from the bottom
    for (int s = 0; s < segments; ++s) {
      const double th = 2.0 * M_PI * s / segments;
      m.v.row(1 + r * segments + s) =
          (centre + Eigen::Vector3d(a * std::sin(phi) * std::cos(th), -b * std::cos(phi),
                                    c * std::sin(phi) * std::sin(th)))
              .transpose();
    }
  }
  const int top = rings * segments + 1;
  m.v.row(top) = (centre + Eigen::Vector3d(0, b, 0)).transpose();
  std::vector<Eigen::Vector3i> tris;
  for (int s = 0; s < segments; ++s) {
    const int s1 = (s + 1) % segments;
    tris.emplace_back(0, 1 + s, 1 + s1);
    tris.emplace_back(top, 1 + (rings - 1) * segments + s1, 1 + (rings - 1) * segments + s);
  }
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int s1 = (s + 1) % segments;
      const int a0 = 1 + r * segments + s, a1 = 1 + r * segments + s1;
      const int b0 = a0 + segments, b1 = a1 + segments;
      tris.emplace_back(a0, b0, a1);
      tris.emplace_back(a1, b0, b1);
    }
  }
  m.f.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t) m.f.row(static_cast<Eigen::Index>(t)) = tris[t];
  return m;
}

/// Appends mesh `b` to `a` (disjoint components).
inline void append(Mesh& a, const Mesh& b) {
  const auto nv = a.v.rows(), nf = a.f.rows();
  a.v.conservativeResize(nv + b.v.rows(), 3);
  a.v.bottomRows(b.v.rows()) = b.v;
  a.f.conservativeResize(nf + b.f.rows(), 3);
  a.f.bottomRows(b.f.rows()) = b.f.array() + static_cast<int>(nv);
}

/// Replaces the shape space of `model` by smooth fields: component k moves vertex v by
/// A_k (v - centroid), A_k a 3 x 3 matrix with diagonal entries ~ N(0, `scale`) (per-axis
/// stretches) and off-diagonal ~ N(0, `scale` / 10) (small shears), deterministic in `seed`.
/// Measurements of such a body are close to linear in the betas, as for SMPL (whose shape
/// directions are smooth), unlike a shape space of independent per-vertex noise.
inline void make_shape_space_smooth(smpl::BodyModel& model, std::uint64_t seed,
                                    double scale = 0.02) {
  const Eigen::RowVector3d centroid = model.v_template.colwise().mean();
  std::uint64_t state = seed * 0x9e3779b97f4a7c15ULL + 1;
  const auto normal = [&]() {  // Box-Muller on a 64-bit LCG: deterministic everywhere
    const auto uniform = [&]() {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      return (static_cast<double>(state >> 11) + 1.0) * 0x1.0p-53;
    };
    const double u1 = uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  };
  for (int k = 0; k < model.num_betas(); ++k) {
    Eigen::Matrix3d A;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) A(i, j) = normal() * (i == j ? scale : scale / 10.0);
    }
    for (int v = 0; v < model.num_vertices(); ++v) {
      const Eigen::Vector3d d = A * (model.v_template.row(v) - centroid).transpose();
      model.shapedirs.block(3 * static_cast<Eigen::Index>(v), k, 3, 1) = d;
    }
  }
}

/// Index of the vertex nearest to p.
inline int nearest_vertex(const smpl::Vertices& v, const Eigen::Vector3d& p) {
  Eigen::Index best = 0;
  (v.rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

}  // namespace caliper::test
