/// \file test_contact.cpp
/// Separation of touching skin (apps/modelgen/src/contact.hpp) on a model whose answer is known:
/// two balls, mirror images of each other, 2 cm apart at the mean, that the first component
/// moves towards each other (1 cm each per SD: at +2 SD they overlap by 2 cm, so that vertices
/// lie wholly inside the other ball, their triangles crossing nothing) and the second grows (5 mm
/// per SD: at +2 SD they overlap, at -2 SD not).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

#include "contact.hpp"
#include "mesh_checks.hpp"

namespace {

/// A ball of radius `r` around `c`: an octahedron subdivided `levels` times, projected onto the
/// sphere, wound outward. `mirror_x` reflects it through x = 0 (winding kept outward).
void add_ball(const Eigen::Vector3d& c, double r, int levels, bool mirror_x,
              std::vector<Eigen::Vector3d>& verts, std::vector<std::array<int, 3>>& faces) {
  std::vector<Eigen::Vector3d> v = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                    {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::vector<std::array<int, 3>> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto middle = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[static_cast<size_t>(a)] + v[static_cast<size_t>(b)]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : f) {
      const int ab = middle(t[0], t[1]), bc = middle(t[1], t[2]), ca = middle(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
    }
    f = next;
  }
  const int base = static_cast<int>(verts.size());
  for (const Eigen::Vector3d& p : v) {
    Eigen::Vector3d q = c + r * p;
    if (mirror_x) q.x() = -q.x();
    verts.push_back(q);
  }
  for (const auto& t : f) {
    faces.push_back(mirror_x ? std::array<int, 3>{base + t[0], base + t[2], base + t[1]}
                             : std::array<int, 3>{base + t[0], base + t[1], base + t[2]});
  }
}

/// The two-ball model: left ball at x > 0, right ball its mirror image; component 0 moves both
/// towards x = 0 by 10 mm per SD, component 1 scales the radius by 5 mm per SD.
smpl::BodyModel two_balls() {
  std::vector<Eigen::Vector3d> verts;
  std::vector<std::array<int, 3>> faces;
  const Eigen::Vector3d centre(0.06, 0.0, 0.0);
  add_ball(centre, 0.05, 3, false, verts, faces);
  const auto half = static_cast<Eigen::Index>(verts.size());
  add_ball(centre, 0.05, 3, true, verts, faces);
  smpl::BodyModel m;
  const auto nv = static_cast<Eigen::Index>(verts.size());
  m.v_template.resize(nv, 3);
  for (Eigen::Index i = 0; i < nv; ++i) m.v_template.row(i) = verts[static_cast<size_t>(i)];
  m.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (Eigen::Index t = 0; t < m.faces.rows(); ++t) {
    for (int k = 0; k < 3; ++k) m.faces(t, k) = faces[static_cast<size_t>(t)][k];
  }
  m.mirror.resize(static_cast<size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) m.mirror[static_cast<size_t>(i)] = (i + half) % nv;
  m.shapedirs = Eigen::MatrixXd::Zero(3 * nv, 3);
  for (Eigen::Index i = 0; i < nv; ++i) {
    const double side = i < half ? 1.0 : -1.0;
    m.shapedirs(3 * i, 0) = -side * 0.010;
    const Eigen::Vector3d out =
        (Eigen::Vector3d(m.v_template.row(i)) - Eigen::Vector3d(side * centre.x(), 0, 0)) / 0.05;
    for (int d = 0; d < 3; ++d) m.shapedirs(3 * i + d, 1) = 0.005 * out[d];
  }
  return m;
}

smpl::Vertices body(const smpl::BodyModel& m, int component, double beta) {
  smpl::Vertices v = m.v_template;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    for (int d = 0; d < 3; ++d) v(i, d) += beta * m.shapedirs(3 * i + d, component);
  }
  return v;
}

TEST(Contact, SeparatesTheCheckBodiesAndKeepsTheModelSymmetric) {
  smpl::BodyModel m = two_balls();
  const smpl::BodyModel before = m;
  ASSERT_TRUE(modelgen::self_intersections(m.v_template, m.faces).empty());
  ASSERT_FALSE(modelgen::self_intersections(body(m, 0, 2.0), m.faces).empty());
  ASSERT_FALSE(modelgen::self_intersections(body(m, 0, 1.5), m.faces).empty());
  ASSERT_FALSE(modelgen::self_intersections(body(m, 1, 2.0), m.faces).empty());

  modelgen::ContactOptions o;
  o.components = 2;
  const modelgen::ContactReport r = modelgen::separate_contacts(m, o);
  EXPECT_EQ(r.bodies, 5);
  ASSERT_EQ(r.pairs_before.size(), 5U);
  EXPECT_EQ(r.pairs_before[0], 0);  // the mean
  EXPECT_EQ(r.pairs_before[1], 0);  // -2 SD along the first component: further apart
  EXPECT_GT(r.pairs_before[2], 0);  // +2 SD
  EXPECT_EQ(r.pairs_before[3], 0);  // -2 SD along the second: smaller
  EXPECT_GT(r.pairs_before[4], 0);
  for (const int p : r.pairs_after) EXPECT_EQ(p, 0);
  EXPECT_GT(r.rounds, 1);  // 10 mm per side, at most 4 mm per round
  // Every check body is clean, and so are the bodies between them on each line.
  for (int c = 0; c < 2; ++c) {
    for (const double beta : {-2.0, -1.0, 0.0, 0.5, 1.0, 1.5, 2.0}) {
      EXPECT_TRUE(modelgen::self_intersections(body(m, c, beta), m.faces).empty())
          << "component " << c << " at " << beta;
    }
  }
  // Only the facing sides moved: the outer halves of the balls (x beyond the centres) and the
  // third component are as they were, and no vertex moved outward.
  for (Eigen::Index i = 0; i < m.v_template.rows(); ++i) {
    if (std::abs(before.v_template(i, 0)) > 0.06) {
      EXPECT_EQ(m.v_template.row(i), before.v_template.row(i)) << i;
    }
  }
  EXPECT_TRUE(m.shapedirs.col(2) == before.shapedirs.col(2));
  // The facing poles are 20 mm into the other ball at +2 SD along the first component; each
  // ball moves back half of that, plus the gaps and what the flood's planes overshoot.
  EXPECT_GT(r.largest_move, 0.009);
  EXPECT_LT(r.largest_move, 0.02);
  // Exactly symmetric.
  for (Eigen::Index i = 0; i < m.v_template.rows(); ++i) {
    const auto j = static_cast<Eigen::Index>(m.mirror[static_cast<size_t>(i)]);
    EXPECT_EQ(m.v_template(i, 0), -m.v_template(j, 0));
    EXPECT_EQ(m.v_template(i, 1), m.v_template(j, 1));
    EXPECT_EQ(m.shapedirs(3 * i, 0), -m.shapedirs(3 * j, 0));
  }
}

TEST(Contact, TheSameBytesWithAnyNumberOfThreadsAndNothingToDoOnACleanModel) {
  smpl::BodyModel a = two_balls(), b = two_balls();
  modelgen::ContactOptions o;
  o.components = 2;
  modelgen::separate_contacts(a, o);
  o.threads = 3;
  modelgen::separate_contacts(b, o);
  EXPECT_TRUE(a.v_template == b.v_template);
  EXPECT_TRUE(a.shapedirs == b.shapedirs);
  // Run again on the separated model: nothing left to do, nothing changes.
  const smpl::BodyModel again = a;
  const modelgen::ContactReport r = modelgen::separate_contacts(a, o);
  EXPECT_EQ(r.rounds, 0);
  EXPECT_EQ(r.moved_vertices, 0);
  EXPECT_TRUE(a.v_template == again.v_template);
  EXPECT_TRUE(a.shapedirs == again.shapedirs);
}

TEST(Contact, TheMoveLimitHoldsAndTheStateWithTheFewestPairsIsKept) {
  smpl::BodyModel m = two_balls();
  const smpl::BodyModel before = m;
  modelgen::ContactOptions o;
  o.components = 2;
  o.max_move = 0.003;  // the balls need about 10 mm each: not enough
  const modelgen::ContactReport r = modelgen::separate_contacts(m, o);
  EXPECT_LE(r.largest_move, 0.003 + 1e-12);
  auto total = [](const std::vector<int>& p) { return std::accumulate(p.begin(), p.end(), 0); };
  EXPECT_GT(total(r.pairs_after), 0);
  EXPECT_LT(total(r.pairs_after), total(r.pairs_before));
  EXPECT_LE(r.kept_round, r.rounds);
  // The report is of the state returned.
  int now = 0;
  for (int c = 0; c < 2; ++c) {
    for (const double beta : {-2.0, 2.0}) {
      now += static_cast<int>(modelgen::self_intersections(body(m, c, beta), m.faces).size());
    }
  }
  EXPECT_EQ(now, total(r.pairs_after));
  for (Eigen::Index i = 0; i < m.v_template.rows(); ++i) {
    EXPECT_LE((m.v_template.row(i) - before.v_template.row(i)).norm(), 0.003 + 1e-12);
  }
}

TEST(Contact, BothDirectionsSeparateAndTheBetterIsKept) {
  smpl::BodyModel a = two_balls(), best = two_balls();
  modelgen::ContactOptions o;
  o.components = 2;
  o.direction = modelgen::ContactDirection::OutOfTheOtherSheet;
  const modelgen::ContactReport r = modelgen::separate_contacts(a, o);
  EXPECT_EQ(r.direction, modelgen::ContactDirection::OutOfTheOtherSheet);
  for (const int p : r.pairs_after) EXPECT_EQ(p, 0);
  for (int c = 0; c < 2; ++c) {
    for (const double beta : {-2.0, 0.0, 2.0}) {
      EXPECT_TRUE(modelgen::self_intersections(body(a, c, beta), a.faces).empty());
    }
  }
  for (Eigen::Index i = 0; i < a.v_template.rows(); ++i) {  // still exactly symmetric
    const auto j = static_cast<Eigen::Index>(a.mirror[static_cast<size_t>(i)]);
    EXPECT_EQ(a.v_template(i, 0), -a.v_template(j, 0));
  }
  // Both clear the balls: the tie goes to the inward normal, whose model is returned.
  smpl::BodyModel inward = two_balls();
  o.direction = modelgen::ContactDirection::InwardNormal;
  modelgen::separate_contacts(inward, o);
  o.direction = modelgen::ContactDirection::OutOfTheOtherSheet;  // ignored
  const modelgen::ContactReport rb = modelgen::separate_contacts_best(best, o);
  EXPECT_EQ(rb.direction, modelgen::ContactDirection::InwardNormal);
  EXPECT_TRUE(best.v_template == inward.v_template);
  EXPECT_TRUE(best.shapedirs == inward.shapedirs);
}

// A crumple: component 2 slides one vertex of each ball (mirror images) 20 mm per SD along the
// surface and 6 mm into it, past its neighbours (edges about 8 mm), so that at +2 SD its fan
// folds under the triangles next to it (12 pairs): pairs within two rings of each other, which
// unfold_creases() smooths out of that component, leaving the mean and the other components
// alone.
TEST(Contact, CrumplesAreSmoothedOutOfTheComponentThatMakesThem) {
  smpl::BodyModel m = two_balls();
  m.shapedirs.conservativeResize(Eigen::NoChange, 3);
  m.shapedirs.col(2).setZero();
  const auto nv = static_cast<Eigen::Index>(m.v_template.rows());
  Eigen::Index top = 0;  // the left ball's vertex highest in y
  for (Eigen::Index i = 0; i < nv / 2; ++i) {
    if (m.v_template(i, 1) > m.v_template(top, 1)) top = i;
  }
  const Eigen::Index mirror = m.mirror[static_cast<std::size_t>(top)];
  for (const Eigen::Index v : {top, mirror}) {
    m.shapedirs(3 * v + 1, 2) = -0.006;  // down into the ball ...
    m.shapedirs(3 * v + 2, 2) = 0.02;    // ... and along +z, under its neighbours
  }
  auto pairs_at = [&](int c, double beta) {
    return modelgen::self_intersections(body(m, c, beta), m.faces).size();
  };
  ASSERT_GT(pairs_at(2, 2.0), 0u);
  ASSERT_EQ(pairs_at(2, 0.0), 0u);
  const smpl::BodyModel before = m;
  modelgen::ContactOptions o;
  o.components = 3;
  const modelgen::UnfoldReport r = modelgen::unfold_creases(m, o);
  EXPECT_EQ(r.bodies, 7);
  EXPECT_GT(r.pairs_before[6], 0);  // +2 SD along component 2
  EXPECT_EQ(std::accumulate(r.pairs_after.begin(), r.pairs_after.end(), 0), 0);
  EXPECT_EQ(pairs_at(2, 2.0), 0u);
  EXPECT_EQ(pairs_at(2, -2.0), 0u);
  EXPECT_GT(r.rounds, 0);
  EXPECT_GT(r.smoothed_vertices, 0);
  // the mean and the components that make no crumple are untouched; the model stays symmetric
  EXPECT_TRUE(m.v_template == before.v_template);
  EXPECT_TRUE(m.shapedirs.leftCols(2) == before.shapedirs.leftCols(2));
  for (Eigen::Index i = 0; i < nv; ++i) {
    const Eigen::Index j = m.mirror[static_cast<std::size_t>(i)];
    EXPECT_EQ(m.shapedirs(3 * i, 2), -m.shapedirs(3 * j, 2));
    EXPECT_EQ(m.shapedirs(3 * i + 1, 2), m.shapedirs(3 * j + 1, 2));
  }
  // two balls pushed into each other (component 0) are not a crumple: left to the contact step
  smpl::BodyModel apart = two_balls();
  const modelgen::UnfoldReport none = modelgen::unfold_creases(apart, o);
  EXPECT_EQ(none.rounds, 0);
  EXPECT_TRUE(apart.shapedirs == two_balls().shapedirs);
}

}  // namespace
