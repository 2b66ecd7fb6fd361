// libFuzzer target: the OBJ reader (smpl::parse_obj) on arbitrary text. Anything but a mesh or
// a smpl::ModelError is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "smpl/mesh_read.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const smpl::MeshData m =
        smpl::parse_obj(std::string(reinterpret_cast<const char*>(data), size), "fuzz.obj");
    (void)m.vertices.sum();
  } catch (const smpl::ModelError&) {
  }
  return 0;
}
