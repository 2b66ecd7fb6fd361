// libFuzzer target: the PLY reader (smpl::parse_ply, ascii and binary little-endian) on
// arbitrary bytes. Anything but a mesh or a smpl::ModelError is a bug.
#include <cstddef>
#include <cstdint>

#include "smpl/mesh_read.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const smpl::MeshData m = smpl::parse_ply(data, size, "fuzz.ply");
    (void)m.vertices.sum();
  } catch (const smpl::ModelError&) {
  }
  return 0;
}
