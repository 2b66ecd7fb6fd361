/// \file cli_support.hpp
/// Small pieces of the `caliper` command line that do not depend on libcaliper's algorithms:
/// exit codes and the errors that carry them, option parsing (CLI11, app/cli_style.hpp), lengths
/// and masses with units ("168cm", "1.68m", "66in", "5ft6in", "62kg", "137lb"), libcaliper's
/// CSV reader and writer (caliper/csv.hpp) in this namespace's reach, the asset locator and a
/// progress reporter.
#pragma once

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/help_text.hpp"
#include "caliper/csv.hpp"
#include "commands.hpp"

namespace caliper::cli {

/// Exit codes that scripts can rely on (docs/cli.md).
enum ExitCode : int {
  kExitOk = 0,           ///< success
  kExitRuntime = 1,      ///< runtime error: unreadable or invalid input file, failed write
  kExitUsage = 2,        ///< usage error: unknown option, missing value, value without a unit
  kExitImplausible = 3,  ///< measurements refused as implausible (outside the hard limits)
};

/// A usage error (exit code 2): the message names the option and the value.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Input measurements refused as implausible (exit code 3): the message names the value and the
/// expected range. `forceable`: --force would make the avatar anyway (a value outside the
/// plausible range); false for a value no body has (not a number, zero or negative), which
/// --force does not accept either, so the error does not suggest it.
class ImplausibleInput : public std::runtime_error {
 public:
  explicit ImplausibleInput(const std::string& message, bool forceable = true)
      : std::runtime_error(message), forceable_(forceable) {}
  bool forceable() const { return forceable_; }

 private:
  bool forceable_;
};

/// A runtime or input-file error (exit code 1).
class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---------------------------------------------------------------------------------------------
// Argument parsing
// ---------------------------------------------------------------------------------------------

/// One option of a subcommand.
struct OptionSpec {
  std::string name;         ///< long name without dashes, e.g. "height"
  std::string short_name;   ///< one letter without dash, e.g. "j", or ""
  std::string value_name;   ///< e.g. "LENGTH"; empty for a flag without a value
  std::string help;         ///< one line
  bool repeatable = false;  ///< may be given several times (values are collected in order)
};

/// The result of parsing: option values by long name, flags, positional arguments.
struct ParsedArgs {
  std::map<std::string, std::vector<std::string>> values;
  std::set<std::string> flags;  ///< given flags; "help" for --help/-h
  std::vector<std::string> positional;
  std::string help;  ///< with --help: the command's help text (written by CLI11)

  bool has(const std::string& name) const { return values.count(name) || flags.count(name); }
  /// The last value of `name`, if given.
  std::optional<std::string> get(const std::string& name) const;
  /// The last value of `name` or `fallback`.
  std::string get_or(const std::string& name, const std::string& fallback) const;
};

/// The name in `names` closest to `name` (edit distance < 4), or "" when none is near:
/// the "did you mean" of unknown options and commands (app::closest_name).
std::string closest_name(const std::string& name, const std::vector<std::string>& names);
/// "1 person" / "2 people": a count with the singular or plural noun.
std::string count_noun(long long n, const std::string& singular, const std::string& plural);

/// Parses one subcommand's arguments with CLI11 in the programs' common style
/// (app/cli_style.hpp): `--name value`, `--name=value`, `-x value`, `-xVALUE`, flags; `--` ends
/// the options. Throws UsageError naming an unknown option (with the closest known one), a
/// missing value, a value given twice or a flag given a value. `--help`/`-h` is always accepted:
/// it sets the "help" flag and `help` to the text CLI11 writes from `specs` and `help`.
ParsedArgs parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                      const app::HelpText& help = {});

/// Every command's start: parse_args, and with `--help` the help text written to `out` and
/// nullopt returned (the command then has nothing more to do and exits with kExitOk).
std::optional<ParsedArgs> parse_args_or_help(const std::vector<std::string>& args,
                                             const std::vector<OptionSpec>& specs,
                                             const app::HelpText& help, std::ostream& out);

/// The flow of a command that parses its options, runs a pure step and writes a report:
/// parse_args_or_help (with --help: kExitOk), `options_from(parsed)`, `run(options)`, then the
/// exit code of `report(options, result, io)`.
template <class OptionsFrom, class Run, class Report>
int run_command(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                const app::HelpText& help, Io& io, OptionsFrom options_from, Run run,
                Report report) {
  const std::optional<ParsedArgs> parsed = parse_args_or_help(args, specs, help, io.out);
  if (!parsed) return kExitOk;
  const auto options = options_from(*parsed);
  return report(options, run(options), io);
}

/// Parses an integer option value in [lo, hi]; throws UsageError naming the option.
int parse_int(const std::string& text, const std::string& option, int lo, int hi);
/// Parses a finite floating-point number; throws UsageError naming the option.
double parse_number(const std::string& text, const std::string& option);
/// Parses a comma-separated list of finite numbers ("0.5,-1,2"); throws UsageError.
std::vector<double> parse_number_list(const std::string& text, const std::string& option);

// ---------------------------------------------------------------------------------------------
// Units
// ---------------------------------------------------------------------------------------------

/// A length with its unit stated: mm, cm, m, in, ft, and feet-inches ("5ft6in", "5'6\"").
/// Returns metres (caliper::parse_length). Throws UsageError naming `what` when the unit is
/// missing or unknown, or the number is not a finite number.
double parse_length(const std::string& text, const std::string& what);
/// A mass with its unit stated: kg, g, lb/lbs. Returns kilograms. Throws UsageError.
double parse_mass(const std::string& text, const std::string& what);

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------

// The project's one reader and cell writer are libcaliper's (caliper/csv.hpp): CsvTable,
// read_csv, parse_csv and csv_escape are found from here as caliper::..., and throw CsvError.

// ---------------------------------------------------------------------------------------------
// Assets, terminal, progress
// ---------------------------------------------------------------------------------------------

/// The assets folder (caliper::find_assets_dir(): $CALIPER_ASSETS when set, else
/// <exe dir>/../../assets (build tree) or <exe dir>/../share/virtual-caliper/assets (install
/// tree), whichever exists first). Returns nullopt when none exists.
std::optional<std::string> find_assets_dir();
/// The folders find_assets_dir() tried, comma-separated, for error messages.
std::string tried_assets_dirs();
/// True when the file exists and is a regular file.
bool file_exists(const std::string& path);
/// Lower-case extension including the dot (".glb"), or "".
std::string extension_of(const std::string& path);
/// True when standard error is a terminal.
bool stderr_is_terminal();

/// Reports progress of `total` items on `err`: a redrawn bar when `tty`, otherwise a plain line
/// at most every `plain_interval` seconds and at the end. Not thread-safe: call from one thread.
class Progress {
 public:
  Progress(std::ostream& err, std::int64_t total, bool tty, double plain_interval = 2.0);
  void update(std::int64_t done);
  void finish();

 private:
  std::ostream& err_;
  std::int64_t total_;
  bool tty_;
  double plain_interval_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_;
  std::int64_t last_done_ = -1;
  bool finished_ = false;
};

}  // namespace caliper::cli
