/// \file subdivision.hpp
/// Catmull-Clark subdivision of a closed quad mesh (Catmull and Clark, "Recursively generated
/// B-spline surfaces on arbitrary topological meshes", CAD 1978) as a sparse linear operator:
/// for a fixed topology the refined positions are S * cage positions, so one operator serves
/// every body of the population.
#pragma once

#include <array>
#include <vector>

#include <Eigen/SparseCore>

namespace modelgen {

/// Row-major sparse matrix, refined vertices x cage vertices; each row sums to 1.
using SubdivisionMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// Result of subdividing a quad mesh.
struct Subdivision {
  SubdivisionMatrix s;                    ///< refined x input vertices
  std::vector<std::array<int, 4>> quads;  ///< refined quads, same orientation as the input
  /// Refined index of each input face's centre (face point), for face landmarks.
  std::vector<int> face_point;
};

/// `levels` rounds of Catmull-Clark subdivision of the closed quad mesh (`num_vertices`, `quads`).
/// Vertex numbering: input vertex i keeps index i; then edge points; then face points.
/// Precondition: the mesh is closed and 2-manifold (every edge has exactly two faces).
Subdivision catmull_clark(int num_vertices, const std::vector<std::array<int, 4>>& quads,
                          int levels);

}  // namespace modelgen
