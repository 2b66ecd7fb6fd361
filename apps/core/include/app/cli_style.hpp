/// \file cli_style.hpp
/// The one style of every program's command line (caliper, caliper-editor, caliper-vr,
/// caliper-modelgen, caliper-modelgen-render), on CLI11 (libcli11-dev): options are declared on
/// a CLI::App, CLI11 parses them and writes --help; this header gives all the programs the same
/// --help layout and the same usage errors. Header-only (CMake target caliper_cli_style); it
/// prints nothing itself.
///
/// --help layout:
///   usage: PROGRAM ...            (one line per way of calling it)
///
///   what the program does
///
///   options:
///     -x, --name VALUE   what it does, with its unit (default VALUE)
///
///   FOOTER                        (examples, exit codes, environment)
///
/// Usage errors: one line that names the option or argument, what was wrong with it and, for a
/// mistyped option, the closest known one; programs print it as
/// "PROGRAM: error: MESSAGE (see PROGRAM --help)" and exit with code 2 (usage_error_line()).
#pragma once

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/help_text.hpp"

namespace caliper::app {

/// A command line that cannot be run: the message names the option or argument and what was
/// wrong with it. Programs exit with code 2.
class CommandLineError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The name in `names` closest to `name` (edit distance < 4), or "" when none is near: the
/// "did you mean" of unknown options and commands.
inline std::string closest_name(const std::string& name, const std::vector<std::string>& names) {
  const auto distance = [](const std::string& a, const std::string& b) {
    std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      cur[0] = i;
      for (size_t j = 1; j <= b.size(); ++j)
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
      std::swap(prev, cur);
    }
    return prev[b.size()];
  };
  std::string best;
  size_t best_d = 4;  // suggest only near misses
  for (const std::string& n : names) {
    const size_t d = distance(name, n);
    if (d < best_d) {
      best_d = d;
      best = n;
    }
  }
  return best;
}

/// The --help layout above: custom usage lines, value names instead of CLI11's types, the
/// default at the end of the description ("(default X)"), groups in lower case.
class HelpFormatter : public CLI::Formatter {
 public:
  explicit HelpFormatter(std::vector<std::string> usage) : usage_(std::move(usage)) {
    column_width(30);
  }

  std::string make_help(const CLI::App* app, std::string name,
                        CLI::AppFormatMode mode) const override {
    std::ostringstream out;
    out << make_usage(app, name);
    if (!app->get_description().empty()) out << "\n" << app->get_description() << "\n";
    out << "\n" << make_groups(app, mode) << make_subcommands(app, mode);
    if (!app->get_footer().empty()) out << "\n" << app->get_footer() << "\n";
    return out.str();
  }

  /// One group: its name and its options, no blank line before it (make_groups() puts one
  /// between groups).
  std::string make_group(std::string group, bool is_positional,
                         std::vector<const CLI::Option*> opts) const override {
    std::string out = group + ":\n";
    for (const CLI::Option* opt : opts) out += make_option(opt, is_positional);
    return out;
  }

  std::string make_usage(const CLI::App* app, std::string name) const override {
    if (usage_.empty())
      return "usage: " + name + (app->get_options().size() > 1 ? " [options]\n" : "\n");
    std::string out;
    for (size_t i = 0; i < usage_.size(); ++i)
      out += (i ? "       " : "usage: ") + usage_[i] + "\n";
    return out;
  }

  std::string make_option_opts(const CLI::Option* opt) const override {
    if (opt->get_type_size() == 0 || opt->get_type_name().empty()) return "";
    return " " + opt->get_type_name();
  }

  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string d = opt->get_description();
    const std::string& value = opt->get_default_str();
    // Not for an option that collects values (its default is the empty list "[]").
    if (!value.empty() && value != "[]" && d.find("(default") == std::string::npos)
      d += " (default " + value + ")";
    return d;
  }

 private:
  std::vector<std::string> usage_;
};

/// Gives `app` the common style: the help layout, `-h, --help`, one value per option
/// occurrence, defaults shown, unknown arguments collected for parse_command_line().
inline void apply_style(CLI::App& app, const HelpText& text) {
  app.formatter(std::make_shared<HelpFormatter>(text.usage));
  app.description(text.description);
  app.footer(text.footer);
  app.option_defaults()->group("options")->always_capture_default();
  app.set_help_flag("-h,--help", "show this help and exit");
  app.allow_extras();
  app.positionals_at_end(false);
}

/// Adds an option that takes exactly one value per occurrence (a value starting with '-', such
/// as "-5kg" or "-1", is taken as the value); given twice, it is a usage error unless
/// `repeatable` (then every value is kept, in order).
template <typename T>
CLI::Option* add_value(CLI::App& app, const std::string& names, T& target,
                       const std::string& value_name, const std::string& help,
                       bool repeatable = false) {
  CLI::Option* o = app.add_option(names, target, help);
  o->type_name(value_name)->expected(1)->allow_extra_args(false);
  o->multi_option_policy(repeatable ? CLI::MultiOptionPolicy::TakeAll
                                    : CLI::MultiOptionPolicy::Throw);
  return o;
}

/// Adds a flag (no value; "--flag=value" is a usage error).
inline CLI::Option* add_flag(CLI::App& app, const std::string& names, bool& target,
                             const std::string& help) {
  return app.add_flag(names, target, help)->disable_flag_override();
}

/// A check that an option's value is a number for which `ok` holds; otherwise the message is
/// `need` and the value given ("must be 0 or more, not -3").
inline CLI::Validator number_check(std::function<bool(double)> ok, std::string need) {
  return CLI::Validator(
      [ok = std::move(ok), need = std::move(need)](std::string& text) {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v)) return "'" + text + "' is not a number";
        return ok(v) ? std::string() : need + ", not " + text;
      },
      "");
}

/// A check that a number is 0 or more, with a message that says so.
inline CLI::Validator non_negative() {
  return number_check([](double v) { return v >= 0; }, "must be 0 or more");
}

/// The plain-words message of a CLI11 parse error of `app`.
inline std::string describe(const CLI::ParseError& e, const CLI::App& app) {
  std::string m = e.what();
  const size_t colon = m.find(": ");
  const std::string option = colon == std::string::npos ? "" : m.substr(0, colon);
  const size_t missing = m.find(" missing");
  if (missing != std::string::npos && missing + 8 == m.size() &&
      m.find(" required ") != std::string::npos) {
    const size_t type = m.find(" required ") + 10;
    return "option " + option + " needs a value (" + m.substr(type, missing - type) + ")";
  }
  if (m.find("At Most 1 required but received") != std::string::npos)
    return "option " + option + " given more than once";
  const std::string convert = "Could not convert: ";
  if (m.rfind(convert, 0) == 0 && m.find(" = ") != std::string::npos) {
    const size_t eq = m.find(" = ");
    const std::string name = m.substr(convert.size(), eq - convert.size());
    const CLI::Option* o = app.get_option_no_throw(name);
    return "'" + m.substr(eq + 3) + "' is not a valid value for " + name +
           (o && !o->get_type_name().empty() ? " " + o->get_type_name() : "");
  }
  const size_t flag = m.find(" was given a disallowed flag override");
  if (flag != std::string::npos) return "option --" + m.substr(0, flag) + " takes no value";
  return m;
}

/// What parse_command_line() found besides the declared options.
struct CommandLine {
  bool help = false;                    ///< --help/-h was given (the help was not printed)
  std::vector<std::string> positional;  ///< arguments that are not options, in order
};

/// Parses `args` (without the program name) into the options declared on `app` (styled by
/// apply_style()). Arguments that are no option are returned as positional ("--" ends the
/// options; "-1" or "-.5" are numbers, not options). Throws CommandLineError naming an unknown
/// option (with the closest declared one), a missing value, a value given twice, a flag given a
/// value or a value that a CLI11 check refused.
inline CommandLine parse_command_line(CLI::App& app, std::vector<std::string> args) {
  CommandLine out;
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::CallForHelp&) {
    out.help = true;
    return out;
  } catch (const CLI::ParseError& e) {
    throw CommandLineError(describe(e, app));
  }
  bool options_done = false;
  for (const std::string& a : app.remaining()) {
    const bool number =
        a.size() > 1 && (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.');
    if (options_done || a.size() < 2 || a[0] != '-' || number) {
      out.positional.push_back(a);
    } else if (a == "--") {
      options_done = true;
    } else {
      std::string name = a.substr(0, a.find('='));
      std::vector<std::string> names;
      for (const CLI::Option* o : app.get_options())
        for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
      const std::string near = closest_name(name.rfind("--", 0) == 0 ? name : "-" + name, names);
      throw CommandLineError("unknown option " + name +
                             (near.empty() ? "" : " (did you mean " + near + "?)"));
    }
  }
  return out;
}

/// Throws CommandLineError when `line` has a positional argument (for programs that take none).
inline void no_positional(const CommandLine& line) {
  if (!line.positional.empty())
    throw CommandLineError("unexpected argument '" + line.positional[0] + "'");
}

/// The line a program prints for a usage error: "PROGRAM: error: MESSAGE (see PROGRAM --help)".
inline std::string usage_error_line(const std::string& program, const std::string& message) {
  return program + ": error: " + message + " (see " + program + " --help)\n";
}

}  // namespace caliper::app
