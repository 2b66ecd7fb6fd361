/// \file commands.hpp
/// The `caliper` command's subcommands. Each takes the arguments after its name and returns an
/// exit code (cli_support.hpp); errors are thrown (UsageError, ImplausibleInput, RuntimeError,
/// library exceptions) and turned into messages and exit codes by main_guarded(), the one place
/// that catches. See docs/cli.md.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace caliper::cli {

/// Streams of one invocation (tests pass string streams).
struct Io {
  std::ostream& out;
  std::ostream& err;
  bool err_is_terminal = false;  ///< progress bar vs plain progress lines
};

/// Version string printed by --version.
std::string version_string();

/// Runs `caliper <args...>` (args excludes the program name) and returns the exit code. The one
/// catch: every exception becomes a one-line "caliper: error: ..." on `io.err` and its exit code.
int main_guarded(const std::vector<std::string>& args, Io& io);

/// Subcommands (args exclude the subcommand name). They throw on errors.
int cmd_create(const std::vector<std::string>& args, Io& io);
int cmd_measure(const std::vector<std::string>& args, Io& io);
int cmd_train(const std::vector<std::string>& args, Io& io);
int cmd_batch(const std::vector<std::string>& args, Io& io);
int cmd_models(const std::vector<std::string>& args, Io& io);
int cmd_render(const std::vector<std::string>& args, Io& io);
int cmd_evaluate(const std::vector<std::string>& args, Io& io);

}  // namespace caliper::cli
