/// \file mesh_checks.hpp
/// Geometry checks of the open body models (issue 11, "Must show" 2): closedness, manifoldness,
/// orientation and connectivity of a triangle mesh; self-intersection (uniform-grid broad phase,
/// then edge-triangle crossings, Moller and Trumbore, J. Graphics Tools 2(1), 1997); triangles
/// flipped by posing with linear blend skinning; and the 10 test poses the models are checked in.
/// Used by the model tests (tests/modelgen) and by caliper-modelgen-check (check_main.cpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"

namespace modelgen {

/// Topology of a triangle mesh.
struct TopologyReport {
  bool closed = false;           ///< every undirected edge has exactly two faces
  bool oriented = false;         ///< every directed edge occurs once (consistent winding)
  bool vertex_manifold = false;  ///< the faces around every vertex form one fan
  int euler = 0;                 ///< V - E + F (V = num_vertices)
  int unused_vertices = 0;       ///< vertices no face uses
  int components = 0;            ///< connected components (faces joined at shared vertices)
  int boundary_edges = 0;        ///< undirected edges with one face
  int nonmanifold_edges = 0;     ///< undirected edges with three or more faces
};

/// Topology of `faces` (F x 3 indices into [0, num_vertices)). A closed, oriented,
/// vertex-manifold mesh of one component with euler 2 is a sphere (genus 0). Faces with a
/// repeated index count their edges as given (a degenerate face makes the mesh non-closed).
/// Precondition: every index in [0, num_vertices).
TopologyReport topology_report(int num_vertices, const smpl::Faces& faces);

/// Pairs (i < j), sorted, of triangles whose interiors intersect, among pairs that share no
/// vertex and pairs that share exactly one vertex (for those, only a crossing away from the
/// shared vertex counts: one triangle's opposite edge through the other triangle). Triangles
/// sharing an edge are not tested (they meet along it). Coplanar overlaps are not reported
/// (edge-triangle crossings need a transversal edge). Broad phase: a uniform grid of cell size
/// `cell` metres (> 0) over the triangles' bounding boxes, each pair tested once.
/// `v`: V x 3 positions, metres; `f`: F x 3 indices into v.
std::vector<std::pair<int, int>> self_intersections(const smpl::Vertices& v, const smpl::Faces& f,
                                                    double cell = 0.02);

/// How far the surfaces cross at an intersecting pair (i, j) of self_intersections(), metres: for
/// each triangle, the largest distance of its vertices behind the other's plane (against the
/// other's normal, so the winding must be outward); the smaller of the two. An upper bound of the
/// penetration depth there (exact for a corner poking through a face). 0 when no vertex of either
/// triangle is behind the other's plane; a degenerate triangle's plane gives 0.
double crossing_depth(const smpl::Vertices& v, const smpl::Faces& f, int i, int j);

/// Area (m^2) below which a triangle counts as degenerate in flipped_triangles() (1 um^2: the
/// skin's smallest triangles are about 1 mm^2).
constexpr double kDegenerateArea = 1e-12;

/// Triangles flipped by posing. For triangle t with skinning weights w (summed over its three
/// vertices), the local rotation R_t is the rotation nearest (polar decomposition) to
/// sum_j w_j R_j, R_j the rotation of joint j's posed world transform: the rotation linear blend
/// skinning applies around t. t is flipped when its posed normal n' satisfies n' . (R_t n) < 0,
/// n its normal in `rest`, i.e. it turned by more than 90 degrees against its own local rotation
/// (a fold). Degenerate triangles (area below kDegenerateArea in either state) count as flipped.
/// `rest`: the model's V x 3 vertices before posing (same shape as `posed`); `posed`:
/// smpl::evaluate() of the same betas. Returns the sorted triangle indices.
std::vector<int> flipped_triangles(const smpl::BodyModel& model, const smpl::Vertices& rest,
                                   const smpl::Body& posed);

/// One test pose: a name and an SMPL pose vector (3 * 24 axis-angle values, radians).
struct TestPose {
  std::string name;
  Eigen::VectorXd theta;
};

/// The 10 test poses the open models are checked in (docs/models.md, "Geometry checks"): elbows
/// flexed 90 degrees (each), knees flexed 90 degrees (each), shoulders lowered 90 degrees (arms
/// down, each), the left shoulder 90 degrees forward, hips flexed 90 degrees (each) and the left
/// hip abducted 45 degrees. For SMPL's 24 joints, left at +X, rest pose a T-pose facing +Z.
const std::vector<TestPose>& test_poses();

/// The SMPL joint (0..23) with the largest summed skinning weight over triangle `t`'s three
/// vertices: where on the body a triangle is, for reports.
int dominant_joint(const smpl::BodyModel& model, int t);

}  // namespace modelgen
