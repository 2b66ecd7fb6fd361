/// \file mesh_checks.hpp
/// Geometry checks for closed triangle meshes: closedness, manifoldness, orientation,
/// self-intersection (uniform grid + triangle-triangle tests) and flipped triangles after posing.
#pragma once

#include <utility>
#include <vector>

#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"

namespace modelgen_test {

/// Topology of a triangle mesh.
struct TopologyReport {
  bool closed = false;           ///< every undirected edge has exactly two faces
  bool oriented = false;         ///< every directed edge occurs once (consistent winding)
  bool vertex_manifold = false;  ///< the faces around every vertex form one fan
  int euler = 0;                 ///< V - E + F
  int unused_vertices = 0;
};

TopologyReport topology_report(int num_vertices, const smpl::Faces& faces);

/// Pairs (i < j) of triangles sharing no vertex whose interiors intersect. Uses a uniform grid
/// of cell size `cell` metres over the triangles' bounding boxes; each candidate pair is tested
/// with edge-triangle crossings (Moller-Trumbore), which finds every non-coplanar intersection.
std::vector<std::pair<int, int>> self_intersections(const smpl::Vertices& v, const smpl::Faces& f,
                                                    double cell = 0.02);

/// Triangles flipped by posing. For triangle t with skinning weights w (summed over its three
/// vertices), the local rotation R_t is the rotation nearest (polar decomposition) to
/// sum_j w_j R_j, R_j the rotation of joint j's posed world transform: the rotation linear blend
/// skinning applies around t. t is flipped when its posed normal n' satisfies n' . (R_t n) < 0,
/// i.e. it turned by more than 90 degrees against its own local rotation (a fold). Degenerate
/// triangles (area below 1e-12 m^2 in either state) count as flipped.
std::vector<int> flipped_triangles(const smpl::BodyModel& model, const smpl::Vertices& rest,
                                   const smpl::Body& posed);

}  // namespace modelgen_test
