// The editor's logic without a window: commands in, state out.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "app/editor_core.hpp"
#include "app/units.hpp"
#include "caliper_test/random_model.hpp"

namespace ca = caliper::app;

TEST(Probe, RandomModel) {
  auto m = std::make_shared<smpl::BodyModel>(caliper::test::make_random_model(10));
  m->meta.gender = "female";
  ca::EditorCore core;
  core.add_model(ca::make_model_entry(m, "random"));
  for (auto& msg : core.messages()) std::printf("msg %s\n", msg.text.c_str());
  for (auto& [id, v] : core.avatar().achieved) std::printf("%s %g\n", id.c_str(), v);
  for (auto& [id, v] : core.state().values) std::printf("in %s %g\n", id.c_str(), v);
}
