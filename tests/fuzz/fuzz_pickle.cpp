// libFuzzer target: the restricted unpickler on arbitrary bytes. Any outcome other than a
// PickleDict or a smpl::ModelError (crash, other exception, sanitizer report, timeout) is a bug.
#include <cstddef>
#include <cstdint>

#include "smpl/pickle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const smpl::PickleDict d = smpl::parse_pickle(data, size, "fuzz.pkl");
    for (const auto& [key, value] : d) {
      // Touch what the model loader touches.
      if (value.kind == smpl::PickleValue::Kind::kArray && value.array.is_numeric()) {
        (void)value.array.to_double();
      }
    }
  } catch (const smpl::ModelError&) {
  }
  return 0;
}
