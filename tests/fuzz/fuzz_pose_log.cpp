// libFuzzer target: the pose log reader (caliper::parse_pose_log, JSON Lines) on arbitrary text.
// Anything but a PoseLog or a caliper::PoseLogError is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "caliper/pose_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const caliper::PoseLog log = caliper::parse_pose_log(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.jsonl");
    (void)log.frames.size();
  } catch (const caliper::PoseLogError&) {
  }
  return 0;
}
