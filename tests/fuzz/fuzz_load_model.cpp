// libFuzzer target: load_model_from_memory (format detection, .npz / .pkl parsing, key mapping,
// validate) on arbitrary bytes. Anything but a BodyModel or a smpl::ModelError is a bug.
#include <cstddef>
#include <cstdint>

#include "smpl/io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const smpl::BodyModel m = smpl::load_model_from_memory(data, size, "fuzz");
    smpl::validate(m, "fuzz");
  } catch (const smpl::ModelError&) {
  }
  return 0;
}
