// One fitted small random test model shared by the editor's unit tests (fitting the
// regressors takes a moment, so it is made once per test program).
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

}  // namespace caliper::test
