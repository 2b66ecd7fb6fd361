// libFuzzer target: the measuring protocol file reader (caliper::parse_protocol) on arbitrary
// text. Anything but a Protocol or a caliper::ProtocolError is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "caliper/protocol_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const caliper::Protocol p = caliper::parse_protocol(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
    (void)p.steps.size();
  } catch (const caliper::ProtocolError&) {
  }
  return 0;
}
