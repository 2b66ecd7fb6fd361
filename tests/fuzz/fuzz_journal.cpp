// libFuzzer target: the session journal reader (caliper::parse_journal) on arbitrary text.
// Anything but JournalContents or a caliper::JournalError is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "caliper/journal.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const caliper::JournalContents j = caliper::parse_journal(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.journal");
    (void)j.records.size();
  } catch (const caliper::JournalError&) {
  }
  return 0;
}
