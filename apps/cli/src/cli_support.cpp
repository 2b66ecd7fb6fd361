#include "cli_support.hpp"

#include "caliper/assets.hpp"
#include "caliper/errors.hpp"
#include "caliper/inputs.hpp"
#include "smpl/text.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace caliper::cli {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Argument parsing
// ---------------------------------------------------------------------------------------------

std::optional<std::string> ParsedArgs::get(const std::string& name) const {
  auto it = values.find(name);
  if (it == values.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::string ParsedArgs::get_or(const std::string& name, const std::string& fallback) const {
  auto v = get(name);
  return v ? *v : fallback;
}

namespace {

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string closest_option(const std::string& name, const std::vector<OptionSpec>& specs) {
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  return closest_name(name, names);
}

}  // namespace

std::string closest_name(const std::string& name, const std::vector<std::string>& names) {
  std::string best;
  size_t best_d = 4;  // suggest only near misses
  for (const std::string& n : names) {
    const size_t d = edit_distance(name, n);
    if (d < best_d) {
      best_d = d;
      best = n;
    }
  }
  return best;
}

std::string count_noun(long long n, const std::string& singular, const std::string& plural) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural);
}

ParsedArgs parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs) {
  ParsedArgs out;
  auto find_long = [&](const std::string& n) -> const OptionSpec* {
    for (const auto& s : specs)
      if (s.name == n) return &s;
    return nullptr;
  };
  auto find_short = [&](const std::string& n) -> const OptionSpec* {
    for (const auto& s : specs)
      if (!s.short_name.empty() && s.short_name == n) return &s;
    return nullptr;
  };
  bool options_done = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (options_done || a.size() < 2 || a[0] != '-' ||
        (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.')) {
      out.positional.push_back(a);
      continue;
    }
    if (a == "--") {
      options_done = true;
      continue;
    }
    std::string name;
    std::optional<std::string> inline_value;
    const OptionSpec* spec = nullptr;
    std::string shown;
    if (a.rfind("--", 0) == 0) {
      name = a.substr(2);
      const size_t eq = name.find('=');
      if (eq != std::string::npos) {
        inline_value = name.substr(eq + 1);
        name = name.substr(0, eq);
      }
      shown = "--" + name;
      if (name == "help") {
        out.flags.insert("help");
        continue;
      }
      spec = find_long(name);
    } else {
      name = a.substr(1, 1);
      if (a.size() > 2) inline_value = a.substr(2);
      shown = "-" + name;
      if (name == "h" && !inline_value) {
        out.flags.insert("help");
        continue;
      }
      spec = find_short(name);
    }
    if (!spec) {
      std::string msg = "unknown option " + shown;
      const std::string near = closest_option(name, specs);
      if (!near.empty()) msg += " (did you mean --" + near + "?)";
      throw UsageError(msg);
    }
    if (spec->value_name.empty()) {
      if (inline_value) throw UsageError("option --" + spec->name + " takes no value");
      out.flags.insert(spec->name);
      continue;
    }
    std::string value;
    if (inline_value) {
      value = *inline_value;
    } else {
      if (i + 1 >= args.size())
        throw UsageError("option " + shown + " needs a value (" + spec->value_name + ")");
      value = args[++i];
    }
    auto& slot = out.values[spec->name];
    if (!slot.empty() && !spec->repeatable)
      throw UsageError("option --" + spec->name + " given more than once");
    slot.push_back(value);
  }
  return out;
}

std::string format_options(const std::vector<OptionSpec>& specs) {
  std::ostringstream s;
  std::vector<std::pair<std::string, std::string>> rows;
  size_t width = 0;
  for (const auto& o : specs) {
    std::string left = "  ";
    left += o.short_name.empty() ? "    " : "-" + o.short_name + ", ";
    left += "--" + o.name;
    if (!o.value_name.empty()) left += " " + o.value_name;
    width = std::max(width, left.size());
    rows.emplace_back(left, o.help);
  }
  rows.emplace_back("  -h, --help", "show this help and exit");
  width = std::max<size_t>(width, 12);
  for (const auto& [left, help] : rows)
    s << std::left << std::setw(static_cast<int>(width + 2)) << left << help << "\n";
  return s.str();
}

int parse_int(const std::string& text, const std::string& option, int lo, int hi) {
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
    throw UsageError("--" + option + " " + text + ": expected a whole number from " +
                     std::to_string(lo) + " to " + std::to_string(hi));
  }
  return static_cast<int>(v);
}

double parse_number(const std::string& text, const std::string& option) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw UsageError(option + " '" + text + "': not a finite number");
  }
  return v;
}

std::vector<double> parse_number_list(const std::string& text, const std::string& option) {
  std::vector<double> out;
  std::string cell;
  std::istringstream in(text);
  while (std::getline(in, cell, ',')) {
    cell.erase(0, cell.find_first_not_of(" \t"));
    cell.erase(cell.find_last_not_of(" \t") + 1);
    out.push_back(parse_number(cell, option));
  }
  if (out.empty()) throw UsageError(option + ": expected a comma-separated list of numbers");
  return out;
}

// ---------------------------------------------------------------------------------------------
// Units
// ---------------------------------------------------------------------------------------------

double parse_length(const std::string& text, const std::string& what) {
  try {
    return caliper::parse_length(text, what);
  } catch (const InvalidInputError& e) {
    throw UsageError(e.what());
  }
}

double parse_mass(const std::string& text, const std::string& what) {
  try {
    return caliper::parse_mass(text, what);
  } catch (const InvalidInputError& e) {
    throw UsageError(e.what());
  }
}

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------

int CsvTable::column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  const std::string ln = smpl::to_lower(name);
  for (size_t i = 0; i < header.size(); ++i)
    if (smpl::to_lower(header[i]) == ln) return static_cast<int>(i);
  return -1;
}

CsvTable parse_csv(const std::string& text, const std::string& source, bool per_row_errors) {
  CsvTable t;
  std::vector<std::string> row;
  std::string cell;
  bool in_quotes = false;
  bool row_has_content = false;
  int line = 1;
  int row_line = 1;
  size_t i = 0;
  // Skip a UTF-8 byte order mark.
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;
  size_t row_start = i;  // first byte of the current row's line
  auto end_row = [&]() {
    row.push_back(cell);
    cell.clear();
    if (row_has_content || row.size() > 1 || !row[0].empty()) {
      if (t.header.empty()) {
        t.header = row;
      } else {
        std::string error;
        if (row.size() != t.header.size()) {
          error = source + ":" + std::to_string(row_line) + ": " + std::to_string(row.size()) +
                  " cells, but the header has " + std::to_string(t.header.size()) +
                  "; check for a missing comma";
          if (!per_row_errors) throw RuntimeError(error);
          row.resize(t.header.size());
        }
        t.rows.push_back(row);
        t.line_numbers.push_back(row_line);
        t.row_errors.push_back(error);
      }
    }
    row.clear();
    row_has_content = false;
  };
  // With per-row errors, a data row whose quoted cell is not closed on its own line (a stray ")
  // is an error row of that line alone, its cells split at commas; reading goes on at the next
  // line, so one typo never swallows the rows after it.
  auto unclosed_quote_row = [&](size_t line_end) {
    std::string text_line = text.substr(row_start, line_end - row_start);
    if (!text_line.empty() && text_line.back() == '\r') text_line.pop_back();
    std::vector<std::string> cells(1);
    for (char ch : text_line) {
      if (ch == ',')
        cells.emplace_back();
      else if (ch != '"')
        cells.back() += ch;
    }
    cells.resize(t.header.size());
    t.rows.push_back(std::move(cells));
    t.line_numbers.push_back(row_line);
    t.row_errors.push_back(source + ":" + std::to_string(row_line) +
                           ": a quoted cell is not closed on this line; check for a stray \"");
    row.clear();
    cell.clear();
    in_quotes = false;
    row_has_content = false;
  };
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (in_quotes) {
      if (c == '\n' && per_row_errors && !t.header.empty()) {
        unclosed_quote_row(i);
        ++line;
        row_line = line;
        row_start = i + 1;
        continue;
      }
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          cell += '"';
          ++i;
        } else {
          in_quotes = false;
        }
      } else {
        if (c == '\n') ++line;
        cell += c;
      }
      continue;
    }
    if (c == '"') {
      in_quotes = true;
      row_has_content = true;
    } else if (c == ',') {
      row.push_back(cell);
      cell.clear();
      row_has_content = true;
    } else if (c == '\r') {
      // ignored (CRLF)
    } else if (c == '\n') {
      end_row();
      ++line;
      row_line = line;
      row_start = i + 1;
    } else {
      cell += c;
    }
  }
  if (in_quotes && per_row_errors && !t.header.empty()) unclosed_quote_row(text.size());
  if (in_quotes) throw RuntimeError(source + ":" + std::to_string(row_line) + ": unclosed quote");
  if (!cell.empty() || !row.empty() || row_has_content) end_row();
  if (t.header.empty()) throw RuntimeError(source + ": empty CSV file (no header row)");
  for (auto& h : t.header) {
    h.erase(0, h.find_first_not_of(" \t"));
    h.erase(h.find_last_not_of(" \t") + 1);
  }
  return t;
}

CsvTable read_csv(const std::string& path, bool per_row_errors) {
  const std::optional<std::string> text = smpl::read_file(path);
  if (!text) throw RuntimeError(path + ": cannot open the CSV file (does it exist?)");
  return parse_csv(*text, path, per_row_errors);
}

std::string csv_escape(const std::string& cell) {
  if (cell.find_first_of(",\"\r\n") == std::string::npos) return cell;
  std::string out = "\"";
  for (char c : cell) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

// ---------------------------------------------------------------------------------------------
// Assets, terminal, progress
// ---------------------------------------------------------------------------------------------

std::optional<std::string> find_assets_dir() {
  return caliper::find_assets_dir();
}

std::string tried_assets_dirs() {
  std::string out;
  for (const std::string& d : caliper::assets_dir_candidates()) {
    out += (out.empty() ? "" : ", ") + d;
  }
  return out.empty() ? "none (the executable's folder is unknown)" : out;
}

bool file_exists(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

std::string extension_of(const std::string& path) {
  return smpl::to_lower(fs::path(path).extension().string());
}

bool stderr_is_terminal() {
  return ::isatty(STDERR_FILENO) == 1;
}

Progress::Progress(std::ostream& err, std::int64_t total, bool tty, double plain_interval)
    : err_(err),
      total_(total),
      tty_(tty),
      plain_interval_(plain_interval),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

void Progress::update(std::int64_t done) {
  if (finished_) return;
  const auto now = std::chrono::steady_clock::now();
  const double since_last = std::chrono::duration<double>(now - last_).count();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const bool end = done >= total_;
  if (done == last_done_) return;
  if (tty_) {
    if (!end && since_last < 0.1) return;
    const int width = 30;
    const double frac = total_ > 0 ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
    const int filled = static_cast<int>(frac * width + 0.5);
    err_ << "\r[" << std::string(static_cast<size_t>(filled), '#')
         << std::string(static_cast<size_t>(width - filled), '.') << "] " << done << "/" << total_;
    if (elapsed > 0) err_ << "  " << static_cast<long>(static_cast<double>(done) / elapsed) << "/s";
    err_ << std::flush;
  } else {
    if (!end && since_last < plain_interval_) return;
    err_ << "progress: " << done << " of " << total_ << " done (" << std::fixed
         << std::setprecision(1) << elapsed << " s)\n"
         << std::defaultfloat;
  }
  last_ = now;
  last_done_ = done;
}

void Progress::finish() {
  if (finished_) return;
  update(total_);
  if (tty_) err_ << "\n";
  finished_ = true;
}

}  // namespace caliper::cli
