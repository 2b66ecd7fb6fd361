// Fitted small random test models shared by the editor's unit tests (fitting the regressors
// takes a moment, so each is made once per test program, when a test first asks for it).
#pragma once

#include <memory>
#include <string>

#include "app/recompute.hpp"
#include "caliper_test/random_model.hpp"

namespace caliper::test {

/// A small random model with `joints` joints, fitted once per test program and name.
inline app::ModelEntry make_editor_test_entry(int joints, const std::string& name) {
  RandomModelOptions o;
  o.rings = 30;
  o.segments = 28;
  o.num_joints = joints;
  auto m = std::make_shared<smpl::BodyModel>(make_random_model(o));
  m->meta.gender = "female";
  m->meta.name = name;
  return app::make_model_entry(m, name);
}

inline const app::ModelEntry& editor_test_entry() {
  static const app::ModelEntry e = make_editor_test_entry(24, "random-test");
  return e;
}

/// The same small model with 16 joints (MANO's): no shoulder joints to swing the arms down,
/// so no hanging-arm map (app::hanging_arm_unavailable()); its regressors are fitted as for
/// any model.
inline const app::ModelEntry& editor_test_entry_without_hanging_arm() {
  static const app::ModelEntry e = make_editor_test_entry(16, "sixteen-joints");
  return e;
}

}  // namespace caliper::test
