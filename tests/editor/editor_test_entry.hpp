// Fitted small random test models shared by the editor's unit tests (fitting the regressors
// takes a moment, so each is made once per test program, when a test first asks for it).
#pragma once

#include <memory>

#include "app/recompute.hpp"
#include "caliper_test/random_model.hpp"

namespace caliper::test {

inline const app::ModelEntry& editor_test_entry() {
  static const app::ModelEntry e = [] {
    RandomModelOptions o;
    o.rings = 30;
    o.segments = 28;
    auto m = std::make_shared<smpl::BodyModel>(make_random_model(o));
    m->meta.gender = "female";
    m->meta.name = "random-test";
    return app::make_model_entry(m, "random-test");
  }();
  return e;
}

/// The same small model with 16 joints (MANO's): no shoulder joints to swing the arms down,
/// so no hanging-arm map (app::hanging_arm_unavailable()); its regressors are fitted as for
/// any model.
inline const app::ModelEntry& editor_test_entry_without_hanging_arm() {
  static const app::ModelEntry e = [] {
    RandomModelOptions o;
    o.rings = 30;
    o.segments = 28;
    o.num_joints = 16;
    auto m = std::make_shared<smpl::BodyModel>(make_random_model(o));
    m->meta.gender = "female";
    m->meta.name = "sixteen-joints";
    return app::make_model_entry(m, "sixteen-joints");
  }();
  return e;
}

}  // namespace caliper::test
