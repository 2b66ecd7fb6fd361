// libFuzzer target: the CSV reader of the `caliper` command (caliper::cli::parse_csv, RFC 4180
// quoting) on arbitrary text, and the column look-up. Anything but a table or a
// caliper::cli::RuntimeError is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "cli_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const caliper::cli::CsvTable t =
        caliper::cli::parse_csv(std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv");
    if (!t.header.empty()) (void)t.column(t.header.back());
  } catch (const caliper::cli::RuntimeError&) {
  }
  return 0;
}
