/// \file files.hpp
/// Files in tests: a whole file's bytes, and an output folder per test area under the build
/// tree's test data directory.
#pragma once

#include <filesystem>
#include <string>

#include "smpl/text.hpp"

namespace caliper::test {

/// The bytes of the file at `p`; empty when it cannot be read (the comparison that uses them
/// then fails and names the file).
inline std::string slurp(const std::filesystem::path& p) {
  return smpl::read_file(p.string()).value_or(std::string());
}

/// `root`/`name` (root: the test target's CALIPER_TEST_DATA_DIR), created if missing.
inline std::filesystem::path output_dir(const std::string& root, const std::string& name) {
  std::filesystem::path d = std::filesystem::path(root) / name;
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace caliper::test
