/// \file help_text.hpp
/// What a program's --help says besides its options (the layout: app/cli_style.hpp). A plain
/// struct without CLI11, so that headers can name it cheaply.
#pragma once

#include <string>
#include <vector>

namespace caliper::app {

/// What --help says besides the options.
struct HelpText {
  /// Ways of calling, without "usage: ", e.g. "caliper-vr [options]".
  std::vector<std::string> usage;
  std::string description;  ///< what the program does (may span lines)
  std::string footer;       ///< examples, exit codes, environment (may span lines)
};

}  // namespace caliper::app
