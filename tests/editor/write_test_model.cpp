// Writes a full-size random SMPL-shaped test model (tests/support make_random_model) as a
// project .npz, for the editor's program tests and documentation runs without licensed files.
// usage: editor_write_test_model OUT.npz [gender]
#include <cstdio>
#include <string>

#include "caliper_test/random_model.hpp"
#include "smpl/io.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: editor_write_test_model OUT.npz [female|male|neutral]\n");
    return 2;
  }
  try {
    // No pose blend shapes: the editor shows the rest pose, and the file stays small (a few MB).
    smpl::BodyModel m = caliper::test::make_random_model(10, 24, false);
    m.meta.gender = argc > 2 ? argv[2] : "female";
    m.meta.name = "random-test-" + m.meta.gender;
    smpl::save_model(m, argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "editor_write_test_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
