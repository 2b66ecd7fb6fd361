// A library user's program (tests/consumer): loads a body model, creates an avatar from two
// measurements and exports it as GLB, using only the installed headers and libraries.
//   consumer MODEL.npz OUT.glb
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "caliper/avatar.hpp"
#include "caliper/regressor.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer MODEL.npz OUT.glb\n");
    return 2;
  }
  try {
    const smpl::BodyModel model = smpl::load_model(argv[1]);  // deflated .npz members: zlib
    const caliper::RegressorSet regressors = caliper::train_regressors(model);
    const caliper::MeasurementMap inputs = {{"height", 1.68}, {"weight", 62.0}};
    const caliper::Avatar avatar = caliper::create_avatar(model, *regressors.find("R2"), inputs);
    smpl::write_gltf(argv[2], model, avatar.betas);  // tinygltf
    const smpl::GltfAvatar back = smpl::read_gltf(argv[2]);
    // A model with texture coordinates is split at its seams in the file; joined again, the
    // file's vertices are the model's.
    const smpl::SeamJoin joined = smpl::join_seams(back.vertices, back.faces);
    if (static_cast<int>(joined.kept.size()) != model.num_vertices()) {
      std::fprintf(stderr,
                   "consumer: %s has %d vertices (%d with the seams joined), the model %d\n",
                   argv[2], static_cast<int>(back.vertices.rows()),
                   static_cast<int>(joined.kept.size()), model.num_vertices());
      return 1;
    }
    const double height = avatar.achieved.at("height");
    std::printf(
        "consumer: %s, %d vertices, height %.4f m (asked 1.68), weight %.2f kg (asked 62), "
        "wrote %s\n",
        model.meta.name.c_str(), model.num_vertices(), height, avatar.achieved.at("weight"),
        argv[2]);
    // R2 reproduces its inputs to about a centimetre (docs/regressors.md); a wildly wrong height
    // means the library did not work.
    return std::abs(height - 1.68) < 0.05 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
