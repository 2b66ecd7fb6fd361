/// \file test_mesh_checks.cpp
/// The geometry checker (apps/modelgen/src/mesh_checks.hpp) on synthetic meshes whose answers
/// are known: a clean cube, a cube with a hole or a flipped face, two cubes, a bowtie of two
/// tetrahedra, intersecting and separate tetrahedra, triangles crossing at a shared vertex, and
/// flipped triangles made by hand on a committed model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mesh_checks.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"

namespace {

struct Mesh {
  smpl::Vertices v;
  smpl::Faces f;
};

/// Unit cube [0,1]^3, 12 triangles wound counter-clockwise seen from outside.
Mesh cube(const Eigen::RowVector3d& offset = Eigen::RowVector3d::Zero()) {
  Mesh m;
  m.v.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    m.v.row(i) = Eigen::RowVector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1) + offset;
  }
  m.f.resize(12, 3);
  m.f << 0, 2, 1, 1, 2, 3,  // z = 0
      4, 5, 6, 5, 7, 6,     // z = 1
      0, 1, 4, 1, 5, 4,     // y = 0
      2, 6, 3, 3, 6, 7,     // y = 1
      0, 4, 2, 2, 4, 6,     // x = 0
      1, 3, 5, 3, 7, 5;     // x = 1
  return m;
}

/// A tetrahedron with outward winding, vertices `a` plus the unit axes scaled by `s`.
Mesh tetrahedron(const Eigen::RowVector3d& a, double s) {
  Mesh m;
  m.v.resize(4, 3);
  m.v << 0, 0, 0, s, 0, 0, 0, s, 0, 0, 0, s;
  m.v.rowwise() += a;
  m.f.resize(4, 3);
  m.f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return m;
}

/// Both meshes in one (faces of the second re-indexed; `weld` merges its vertex 0 into the first
/// mesh's vertex `weld_to`).
Mesh join(const Mesh& a, const Mesh& b, int weld_to = -1) {
  Mesh m;
  const auto na = static_cast<int>(a.v.rows());
  m.v.resize(a.v.rows() + b.v.rows(), 3);
  m.v << a.v, b.v;
  m.f.resize(a.f.rows() + b.f.rows(), 3);
  smpl::Faces fb = b.f.array() + na;
  if (weld_to >= 0) {
    for (Eigen::Index i = 0; i < fb.size(); ++i) {
      if (fb(i) == na) {
        fb(i) = weld_to;
      }
    }
  }
  m.f << a.f, fb;
  return m;
}

TEST(MeshChecks, CleanCubeIsAClosedOrientedSphereWithoutIntersections) {
  const Mesh c = cube();
  const modelgen::TopologyReport r = modelgen::topology_report(8, c.f);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.oriented);
  EXPECT_TRUE(r.vertex_manifold);
  EXPECT_EQ(r.components, 1);
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.unused_vertices, 0);
  EXPECT_EQ(r.boundary_edges, 0);
  EXPECT_EQ(r.nonmanifold_edges, 0);
  // every cell size, from one cell per triangle to one cell for the whole cube
  for (const double cell : {0.1, 0.3, 1.0, 10.0}) {
    EXPECT_TRUE(modelgen::self_intersections(c.v, c.f, cell).empty()) << cell;
  }
}

TEST(MeshChecks, HolesFlippedFacesExtraComponentsAndBowtiesAreFound) {
  Mesh c = cube();
  // a hole: one triangle removed leaves three boundary edges
  const smpl::Faces holed = c.f.topRows(11);
  modelgen::TopologyReport r = modelgen::topology_report(8, holed);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.boundary_edges, 3);
  EXPECT_TRUE(r.oriented);
  // one face wound the other way: closed, but not oriented
  smpl::Faces flipped = c.f;
  std::swap(flipped(3, 1), flipped(3, 2));
  r = modelgen::topology_report(8, flipped);
  EXPECT_TRUE(r.closed);
  EXPECT_FALSE(r.oriented);
  // two separate cubes: two components, V - E + F = 4
  const Mesh two = join(cube(), cube({3, 0, 0}));
  r = modelgen::topology_report(16, two.f);
  EXPECT_TRUE(r.closed && r.oriented && r.vertex_manifold);
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.euler, 4);
  // two tetrahedra sharing one vertex: closed and oriented, but not vertex-manifold
  const Mesh bowtie = join(tetrahedron({0, 0, 0}, 1), tetrahedron({0, 0, 0}, -1), 0);
  r = modelgen::topology_report(8, bowtie.f);
  EXPECT_TRUE(r.closed);
  EXPECT_FALSE(r.vertex_manifold);
  EXPECT_EQ(r.components, 1);
  EXPECT_EQ(r.unused_vertices, 1);  // the welded vertex of the second tetrahedron
  // a third face on an edge
  smpl::Faces fin(13, 3);
  fin << c.f, 0, 1, 7;
  r = modelgen::topology_report(8, fin);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.nonmanifold_edges, 1);
}

TEST(MeshChecks, IntersectingTetrahedraAreFoundSeparateOnesAreNot) {
  // The corner of the second tetrahedron pokes through the first's slanted face: that face
  // (3: x + y + z = 1) crosses the second's three faces at its corner, and nothing else crosses.
  const Mesh poke = join(tetrahedron({0, 0, 0}, 1), tetrahedron({0.2, 0.2, 0.2}, 1));
  for (const double cell : {0.05, 0.25, 1.0, 10.0}) {
    const auto hits = modelgen::self_intersections(poke.v, poke.f, cell);
    const std::vector<std::pair<int, int>> expected{{3, 4}, {3, 5}, {3, 6}};
    EXPECT_EQ(hits, expected) << "cell " << cell;
  }
  // depth: the second tetrahedron's corner is 0.4 / sqrt(3) behind the slanted face
  constexpr double kRoundoff = 1e-12;
  EXPECT_NEAR(modelgen::crossing_depth(poke.v, poke.f, 3, 4), 0.4 / std::sqrt(3.0), kRoundoff);
  const Mesh apart = join(tetrahedron({0, 0, 0}, 1), tetrahedron({0.6, 0.6, 0.6}, 1));
  EXPECT_TRUE(modelgen::self_intersections(apart.v, apart.f, 0.1).empty());
  // one inside the other: surfaces do not cross
  const Mesh nested = join(tetrahedron({0, 0, 0}, 1), tetrahedron({0.1, 0.1, 0.1}, 0.2));
  EXPECT_TRUE(modelgen::self_intersections(nested.v, nested.f, 0.1).empty());
}

TEST(MeshChecks, TrianglesSharingOneVertexCountOnlyWhenTheyCross) {
  Mesh m;
  m.v.resize(7, 3);
  m.v << 0, 0, 0,                 // shared
      1, 0, 0, 0, 1, 0,           // triangle 0 in z = 0
      0.2, 0.2, 1, 0.2, 0.2, -1,  // triangle 1: its far edge pierces triangle 0
      0.3, 0.1, 1;                // triangle 2: shares the vertex, stays above
  m.f.resize(3, 3);
  m.f << 0, 1, 2, 0, 3, 4, 0, 3, 5;
  const auto hits = modelgen::self_intersections(m.v, m.f, 0.5);
  const std::vector<std::pair<int, int>> expected{{0, 1}};
  EXPECT_EQ(hits, expected);
  // triangles sharing an edge are never reported, even folded onto each other
  Mesh fold;
  fold.v.resize(4, 3);
  fold.v << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, 0.9, 0.01;
  fold.f.resize(2, 3);
  fold.f << 0, 1, 2, 1, 0, 3;
  EXPECT_TRUE(modelgen::self_intersections(fold.v, fold.f, 0.5).empty());
}

TEST(MeshChecks, FlippedTrianglesFollowTheSkinningRotation) {
  const smpl::BodyModel model =
      smpl::load_model(std::string(CALIPER_MODELS_DIR) + "/caliper-female.npz");
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  const smpl::Vertices rest = smpl::shape(model, betas).vertices;
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(model.num_joints()));
  // rest pose, and the whole body turned 180 degrees about +Y: every normal follows its rotation
  EXPECT_TRUE(
      modelgen::flipped_triangles(model, rest, smpl::evaluate(model, betas, theta)).empty());
  theta[1] = 3.141592653589793;
  EXPECT_TRUE(
      modelgen::flipped_triangles(model, rest, smpl::evaluate(model, betas, theta)).empty());
  // one vertex pushed through the opposite edge of a triangle turns that triangle over
  theta.setZero();
  smpl::Body body = smpl::evaluate(model, betas, theta);
  const int t = 100;
  const int a = model.faces(t, 0), b = model.faces(t, 1), c = model.faces(t, 2);
  const Eigen::RowVector3d mid = 0.5 * (body.vertices.row(b) + body.vertices.row(c));
  body.vertices.row(a) = mid + 1.0 * (mid - body.vertices.row(a));
  const std::vector<int> f1 = modelgen::flipped_triangles(model, rest, body);
  EXPECT_NE(std::find(f1.begin(), f1.end(), t), f1.end());
  // a vertex collapsed onto its neighbour leaves degenerate triangles, which count as flipped
  body = smpl::evaluate(model, betas, theta);
  body.vertices.row(a) = body.vertices.row(b);
  const std::vector<int> f2 = modelgen::flipped_triangles(model, rest, body);
  EXPECT_NE(std::find(f2.begin(), f2.end(), t), f2.end());
}

TEST(MeshChecks, TestPosesAreTenPoseVectorsOfSmplsJoints) {
  const auto& poses = modelgen::test_poses();
  ASSERT_EQ(poses.size(), 10u);
  for (const auto& p : poses) {
    EXPECT_EQ(p.theta.size(), 72) << p.name;
    EXPECT_GT(p.theta.norm(), 0.7) << p.name;  // at least 45 degrees somewhere
  }
}

}  // namespace
