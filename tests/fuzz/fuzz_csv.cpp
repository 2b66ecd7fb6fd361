// libFuzzer target: the project's CSV reader (caliper::parse_csv on libcsv: RFC 4180 quoting,
// per-row errors, comment lines, row and cell limits) on arbitrary text, and the column look-up.
// The first byte picks the options. Anything but a table or a caliper::CsvError is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "caliper/csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  caliper::CsvOptions options;
  options.per_row_errors = (data[0] & 1) != 0;
  options.comment_lines = (data[0] & 2) != 0;
  try {
    const caliper::CsvTable t = caliper::parse_csv(
        std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1), "fuzz.csv", options);
    if (t.rows.size() != t.line_numbers.size() || t.rows.size() != t.row_errors.size())
      __builtin_trap();
    for (const auto& row : t.rows)
      if (row.size() != t.header.size()) __builtin_trap();
    if (!t.header.empty()) (void)t.column(t.header.back());
  } catch (const caliper::CsvError&) {
  }
  return 0;
}
