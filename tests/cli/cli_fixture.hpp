/// \file cli_fixture.hpp
/// Test models for the command-line tests: a small SMPL-shaped random model (tests/support) whose
/// random shape blend shapes are replaced by smooth, body-like deformation fields (stature, girth,
/// arm length, leg length, hip, chest, waist, ...), so that measurements depend on the betas
/// (almost) linearly, as with SMPL, and the regressors behave as in the paper. Saved in the
/// project's .npz format; no licensed model is needed. The template is an ellipsoid, so its
/// proportions are not human (arm span 0.6 m): commands on it need --force.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "caliper_test/random_model.hpp"
#include "smpl/body_model.hpp"

namespace caliper::test {

/// Height above the floor (min y) of landmark `name` of `m`'s template.
inline double cli_landmark_height(const smpl::BodyModel& m, const std::string& name, double floor) {
  double y = 0.0;
  const auto& ids = m.landmarks.at(name);
  for (int i : ids) y += m.v_template(i, 1);
  return y / static_cast<double>(ids.size()) - floor;
}

/// A small model (1,298 vertices, 10 betas, 24 joints, no pose blend shapes) with smooth shape
/// fields; its metadata names `gender`. Small so that training and studies run in milliseconds.
/// `full_size`: SMPL's 6,890 vertices and 13,776 faces instead.
inline smpl::BodyModel cli_test_model(const std::string& gender, std::uint64_t seed = 7,
                                      bool full_size = false) {
  RandomModelOptions o;
  o.num_betas = 10;
  o.pose_blend_shapes = false;
  o.seed = seed;
  if (!full_size) {
    o.rings = 36;
    o.segments = 36;
  }
  smpl::BodyModel m = make_random_model(o);
  m.meta.gender = gender;
  m.meta.name = "caliper-test-" + gender;
  const double floor = m.v_template.col(1).minCoeff();
  const double height = m.v_template.col(1).maxCoeff() - floor;
  const double crotch = cli_landmark_height(m, "crotch", floor);
  const double hip = cli_landmark_height(m, "left_hip", floor);
  const double chest = cli_landmark_height(m, "left_nipple", floor);
  const double waist = cli_landmark_height(m, "navel", floor);
  // Small seed-dependent variation so that models of different seeds differ.
  const double s = 1.0 + 0.1 * static_cast<double>(seed % 7) / 7.0;
  auto bump = [](double y, double c, double w) { return std::exp(-((y - c) / w) * ((y - c) / w)); };
  m.shapedirs.setZero(3 * static_cast<Eigen::Index>(m.num_vertices()), 10);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double x = m.v_template(v, 0), z = m.v_template(v, 2);
    const double y = m.v_template(v, 1) - floor;  // >= 0; the floor vertex never moves up or down
    const double arm = std::clamp((std::abs(x) - 0.12) / 0.2, 0.0, 1.0);
    auto set = [&](int b, double dx, double dy, double dz) {
      m.shapedirs(3 * v + 0, b) = dx;
      m.shapedirs(3 * v + 1, b) = dy;
      m.shapedirs(3 * v + 2, b) = dz;
    };
    set(0, 0.0, 0.04 * s * y, 0.0);                                  // stature
    set(1, 0.035 * x, 0.0, 0.035 * s * z);                           // girth
    set(2, 0.08 * x * arm, 0.0, 0.0);                                // arm length
    set(3, 0.0, 0.03 * std::min(y, crotch), 0.0);                    // leg length
    set(4, 0.05 * x * bump(y, hip, 0.12) * (1.0 - arm), 0.0, 0.0);   // hips
    set(5, 0.0, 0.0, 0.05 * z * bump(y, chest, 0.15));               // chest depth
    set(6, 0.03 * x * bump(y, waist, 0.1) * (1.0 - arm), 0.0, 0.0);  // waist
    set(7, 0.0, 0.0, 0.04 * z * y / height);                         // posture
    set(8, 0.02 * x * (y / height) * (y / height), 0.0, 0.0);        // upper body breadth
    set(9, 0.0, 0.0, 0.03 * z * bump(y, 0.3, 0.1));                  // calves
  }
  return m;
}

}  // namespace caliper::test
