// libFuzzer target: the glTF / GLB reader (read_gltf_from_memory: tinygltf's parser, then the
// accessor, skin and node checks) on arbitrary bytes. No external file is ever read. Anything
// but a GltfAvatar or a smpl::ModelError is a bug.
#include <cstddef>
#include <cstdint>

#include "smpl/gltf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const smpl::GltfAvatar a = smpl::read_gltf_from_memory(data, size, "fuzz.glb");
    (void)a.vertices.sum();
  } catch (const smpl::ModelError&) {
  }
  return 0;
}
