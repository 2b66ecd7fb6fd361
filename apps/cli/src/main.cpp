// `caliper`: the command line of The Virtual Caliper (docs/cli.md).
#include <iostream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  const std::vector<std::string> args(argv + 1, argv + argc);
  caliper::cli::Io io{std::cout, std::cerr, caliper::cli::stderr_is_terminal()};
  const int code = caliper::cli::main_guarded(args, io);
  std::cout.flush();
  return code;
}
