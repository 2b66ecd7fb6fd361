// libFuzzer target: the JSON reader (caliper::parse_json) on arbitrary text, and writing back
// what it read. Anything but a value or a caliper::JsonError is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "caliper/json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const caliper::Json v =
        caliper::parse_json(std::string(reinterpret_cast<const char*>(data), size));
    (void)v.dump(-1);
  } catch (const caliper::JsonError&) {
  }
  return 0;
}
