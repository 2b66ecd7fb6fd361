// The project's one CSV reader, on libcsv (Debian libcsv-dev, 3.0.3).
//
// Why libcsv and not fast-cpp-csv-parser (libfccp-dev): libcsv is a small C library, maintained
// in Debian, that implements RFC 4180 in full (quoted cells with commas, doubled quotes and line
// breaks; LF, CRLF or CR row ends), passes bytes through unchanged (the male ANSUR II file is
// Latin-1), and streams: it calls back once per cell and once per row, so this module keeps the
// line numbers, the row limits and the per-row recovery itself, and never holds more than one
// row. Its strict mode reports the byte of a misplaced quote, which becomes the column of the
// error. fast-cpp-csv-parser fixes the number of columns at compile time (CSVReader<N>), the
// survey files have 108 of which the callers pick a few by name at run time, it has no Debian
// release since 2016, and it reports errors by its own exception types with a fixed line length.
//
// The text is fed to libcsv one line at a time, so that every row knows the line it starts on,
// a row is measured before libcsv buffers it (kCsvMaxRowBytes), comment lines can be skipped, and
// with per-row errors a bad line is dropped and the parser restarted at the next one.
// CSV_REPALL_NL makes libcsv report every line break outside a quoted cell: a line whose break
// was not reported ends inside a quoted cell.
#include "caliper/csv.hpp"

#include <csv.h>

#include <new>
#include <optional>
#include <utility>

#include "smpl/text.hpp"

namespace caliper {

int CsvTable::column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  const std::string ln = smpl::to_lower(name);
  for (size_t i = 0; i < header.size(); ++i)
    if (smpl::to_lower(header[i]) == ln) return static_cast<int>(i);
  return -1;
}

namespace {

/// libcsv trims spaces and tabs around unquoted cells by default; the tables keep their bytes.
int no_space(unsigned char /*c*/) {
  return 0;
}

/// What the callbacks build (they are C callbacks: they record problems, never throw).
struct TableBuilder {
  CsvTable table;
  std::string source;
  bool per_row_errors = false;
  std::vector<std::string> row;
  int row_line = 1;              ///< line where the current row starts
  bool line_break_seen = false;  ///< libcsv reported the fed line's break (outside quotes)
  std::string error;             ///< first problem that ends reading (thrown after csv_parse)

  std::string where(int line) const { return source + ":" + std::to_string(line); }

  void end_row() {
    if (row.empty()) return;  // a line break outside any row (blank line, LF of a CRLF)
    if (table.header.empty()) {
      table.header = std::move(row);
      for (auto& h : table.header) {
        h.erase(0, h.find_first_not_of(" \t"));
        h.erase(h.find_last_not_of(" \t") + 1);
      }
    } else {
      std::string problem;
      if (row.size() != table.header.size()) {
        problem = where(row_line) + ": " + std::to_string(row.size()) +
                  " cells, but the header has " + std::to_string(table.header.size()) +
                  "; check for a missing comma";
        if (!per_row_errors && error.empty()) error = problem;
        row.resize(table.header.size());
      }
      table.rows.push_back(std::move(row));
      table.line_numbers.push_back(row_line);
      table.row_errors.push_back(std::move(problem));
    }
    row.clear();
  }

  /// With per-row errors: `line` (a data row) is kept as an error row, its cells split at commas
  /// with the quotes dropped, so that the person's id still shows in the results; `message` says
  /// what is wrong with it.
  void bad_line_row(std::string_view line, std::string message) {
    if (!line.empty() && line.back() == '\n') line.remove_suffix(1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    std::vector<std::string> cells(1);
    for (char ch : line) {
      if (ch == ',')
        cells.emplace_back();
      else if (ch != '"')
        cells.back() += ch;
    }
    cells.resize(table.header.size());
    table.rows.push_back(std::move(cells));
    table.line_numbers.push_back(row_line);
    table.row_errors.push_back(std::move(message));
    row.clear();
  }
};

void on_cell(void* data, size_t size, void* user) {
  auto& b = *static_cast<TableBuilder*>(user);
  if (b.row.size() >= kCsvMaxCells) {
    if (b.error.empty())
      b.error = b.where(b.row_line) + ": more than " + std::to_string(kCsvMaxCells) +
                " cells in one row; is this a CSV table?";
    return;
  }
  b.row.emplace_back(static_cast<const char*>(data), size);
}

void on_row_end(int c, void* user) {
  auto& b = *static_cast<TableBuilder*>(user);
  if (c == CSV_LF) b.line_break_seen = true;
  b.end_row();
}

/// A libcsv parser in strict mode (misplaced quotes are errors), freed on every path.
class Parser {
 public:
  Parser() { reset(); }
  ~Parser() { csv_free(&p_); }
  Parser(const Parser&) = delete;
  Parser& operator=(const Parser&) = delete;
  csv_parser* get() { return &p_; }
  /// Drops whatever the parser holds (after an error, or a bad line with per-row errors).
  void reset() {
    if (initialized_) csv_free(&p_);
    if (csv_init(&p_, CSV_STRICT | CSV_STRICT_FINI | CSV_REPALL_NL) != 0) throw std::bad_alloc();
    csv_set_space_func(&p_, no_space);
    initialized_ = true;
  }

 private:
  csv_parser p_{};
  bool initialized_ = false;
};

}  // namespace

CsvTable parse_csv(std::string_view text, const std::string& source, const CsvOptions& options) {
  TableBuilder b;
  b.source = source;
  b.per_row_errors = options.per_row_errors;
  Parser parser;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark

  bool in_quotes = false;  // the previous line ended inside a quoted cell
  size_t row_bytes = 0;
  int line_no = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t nl = text.find('\n', pos);
    const size_t end = nl == std::string_view::npos ? text.size() : nl + 1;
    const std::string_view line = text.substr(pos, end - pos);
    pos = end;
    ++line_no;
    if (!in_quotes) {
      if (options.comment_lines && !line.empty() && line[0] == '#') continue;
      b.row_line = line_no;
      row_bytes = 0;
    }
    row_bytes += line.size();
    if (row_bytes > kCsvMaxRowBytes) {
      throw CsvError(b.where(b.row_line) + ": a row longer than " +
                     std::to_string(kCsvMaxRowBytes >> 20) +
                     " MiB (a quote never closed?); is this a CSV table?");
    }
    b.line_break_seen = false;
    const size_t done = csv_parse(parser.get(), line.data(), line.size(), on_cell, on_row_end, &b);
    if (done == line.size() && line.back() != '\n')  // the last line, without a line break
      csv_parse(parser.get(), "\n", 1, on_cell, on_row_end, &b);
    if (!b.error.empty()) throw CsvError(b.error);
    const bool data_row = !b.table.header.empty();
    if (done < line.size()) {
      if (csv_error(parser.get()) != CSV_EPARSE) throw std::bad_alloc();
      const std::string message =
          b.where(line_no) + ":" + std::to_string(done + 1) +
          ": a quote inside an unquoted cell or after a closing quote; quote the whole cell and "
          "double its inner quotes";
      if (!b.per_row_errors || !data_row || in_quotes) throw CsvError(message);
      b.bad_line_row(line, message);
      parser.reset();
      continue;
    }
    in_quotes = !b.line_break_seen;
    if (in_quotes && b.per_row_errors && data_row) {
      b.bad_line_row(line, b.where(b.row_line) +
                               ": a quoted cell is not closed on this line; check for a stray \"");
      parser.reset();
      in_quotes = false;
    }
  }
  if (in_quotes) throw CsvError(b.where(b.row_line) + ": unclosed quote");
  csv_fini(parser.get(), on_cell, on_row_end, &b);
  if (!b.error.empty()) throw CsvError(b.error);
  if (b.table.header.empty()) throw CsvError(source + ": empty CSV file (no header row)");
  return std::move(b.table);
}

CsvTable read_csv(const std::string& path, const CsvOptions& options) {
  const std::optional<std::string> text = smpl::read_file(path);
  if (!text) throw CsvError(path + ": cannot open the CSV file (does it exist?)");
  return parse_csv(*text, path, options);
}

std::string csv_escape(std::string_view cell) {
  if (cell.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(cell);
  std::string out = "\"";
  for (char c : cell) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace caliper
