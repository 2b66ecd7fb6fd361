/// \file csv.hpp
/// The project's one CSV reader (people and measurement tables, ANSUR II and NHANES survey files,
/// paired mapping values, the model generator's statistics table) and its one cell writer.
/// Parsing is libcsv's (libcsv-dev; src/csv.cpp says why that library); this module adds what
/// the callers need around it: a header row, line numbers in errors, per-row errors for batch
/// inputs, comment lines, a UTF-8 byte order mark, and size limits against hostile files.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "caliper/errors.hpp"

namespace caliper {

/// A CSV file that cannot be read or is malformed. The message names the file, the line (and
/// the column where the fault is at one byte) and says what to fix.
class CsvError : public CaliperError {
 public:
  using CaliperError::CaliperError;
};

/// Limits against hostile files (a reader never holds more than these per row). Real tables are
/// far below them: an ANSUR II row is under 2 KB and 108 cells.
inline constexpr std::size_t kCsvMaxRowBytes = std::size_t{1} << 20;  ///< 1 MiB, quotes included
inline constexpr std::size_t kCsvMaxCells = 10000;                    ///< cells in one row

/// A CSV table read in full: a header row and data rows of text cells (RFC 4180 quoting; rows
/// end at LF, CRLF or CR; bytes are kept as they are, so Latin-1 files are read unchanged, and
/// unquoted cells keep their spaces; header cells are trimmed of spaces and tabs).
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> line_numbers;  ///< 1-based file line where each row starts (for messages)
  /// Per row: "" when fine, else what is wrong with it ("FILE:LINE: ..."; only with
  /// CsvOptions::per_row_errors: a row with another number of cells than the header, padded or
  /// cut to the header's width; a row with a quoted cell not closed on its own line or a
  /// misplaced quote, its cells split at commas, reading going on at the next line).
  std::vector<std::string> row_errors;
  /// Column index of `name` (exact, then case-insensitive), or -1.
  int column(const std::string& name) const;
};

/// How to read a table.
struct CsvOptions {
  /// Keep a malformed data row with its problem in CsvTable::row_errors instead of throwing
  /// (batch inputs: one typo never costs the other rows). A quoted cell may then not span lines.
  bool per_row_errors = false;
  /// Skip lines starting with '#' outside a quoted cell (survey files, mapping pairs, tables).
  bool comment_lines = false;
};

/// Parses CSV text; `source` names it in errors. Blank lines are skipped; a UTF-8 byte order mark
/// is ignored. Throws CsvError ("SOURCE:LINE[:COLUMN]: ...") when there is no header row, a quote
/// is misplaced (inside an unquoted cell, or text after a closing quote) or never closed, a row
/// has another number of cells than the header (these three per row with per_row_errors), or a
/// row passes kCsvMaxRowBytes or kCsvMaxCells.
CsvTable parse_csv(std::string_view text, const std::string& source,
                   const CsvOptions& options = {});

/// Reads and parses a CSV file (errors name `path`). Throws CsvError when it cannot be read too.
CsvTable read_csv(const std::string& path, const CsvOptions& options = {});

/// One cell for writing: quoted (inner quotes doubled) when it contains a comma, quote or line
/// break, else unchanged. Every CSV the project writes goes through this.
std::string csv_escape(std::string_view cell);

}  // namespace caliper
