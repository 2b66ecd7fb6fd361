#include "cli_support.hpp"

#include "app/cli_style.hpp"

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

std::string closest_name(const std::string& name, const std::vector<std::string>& names) {
  return app::closest_name(name, names);
}

std::string count_noun(long long n, const std::string& singular, const std::string& plural) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural);
}

ParsedArgs parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                      const app::HelpText& help) {
  ParsedArgs out;
  CLI::App cli("", "caliper");
  app::apply_style(cli, help);
  std::map<std::string, bool> flags;  // node-based: the references CLI11 holds stay valid
  for (const OptionSpec& s : specs) {
    const std::string names =
        (s.short_name.empty() ? "" : "-" + s.short_name + ",") + "--" + s.name;
    if (s.value_name.empty()) {
      app::add_flag(cli, names, flags[s.name], s.help);
    } else {
      app::add_value(cli, names, out.values[s.name], s.value_name, s.help, s.repeatable);
    }
  }
  app::CommandLine line;
  try {
    line = app::parse_command_line(cli, args);
  } catch (const app::CommandLineError& e) {
    throw UsageError(e.what());
  }
  if (line.help) {
    out.flags.insert("help");
    out.help = cli.help();
  }
  for (const auto& [name, given] : flags)
    if (given) out.flags.insert(name);
  for (auto it = out.values.begin(); it != out.values.end();)
    it = it->second.empty() ? out.values.erase(it) : std::next(it);
  out.positional = std::move(line.positional);
  return out;
}

std::optional<ParsedArgs> parse_args_or_help(const std::vector<std::string>& args,
                                             const std::vector<OptionSpec>& specs,
                                             const app::HelpText& help, std::ostream& out) {
  ParsedArgs a = parse_args(args, specs, help);
  if (a.flags.count("help")) {
    out << a.help;
    return std::nullopt;
  }
  return a;
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
    const int filled = static_cast<int>(std::lround(frac * width));
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
