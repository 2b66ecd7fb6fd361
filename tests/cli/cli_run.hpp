/// \file cli_run.hpp
/// What one in-process run of the `caliper` program gave (exit code, standard output and
/// error), for the command-line tests.
#pragma once

#include <string>

namespace caliper::test {

struct CliRun {
  int code = 0;
  std::string out, err;
};

/// True when `s` contains `part`.
inline bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace caliper::test
