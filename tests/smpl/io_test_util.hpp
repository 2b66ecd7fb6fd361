/// \file io_test_util.hpp
/// Helpers of the libsmpl file I/O tests: the fixture directory built once per test run by
/// tests/smpl/fixtures/make_io_fixtures.py (Debian's python3 with numpy and scipy), running
/// Python snippets, reading and writing bytes.
#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "smpl/npz.hpp"

namespace caliper::test {

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `command` through the shell; returns its exit status.
inline int run_command(const std::string& command) {
  const int rc = std::system(command.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/// Runs a Python program (text) with Debian's python3; returns its exit status. Its output goes
/// to the test log.
inline int run_python(const std::string& program, const std::string& args = "") {
  const std::string dir = std::string(CALIPER_TEST_DATA_DIR) + "/smpl_io_py";
  run_command("mkdir -p '" + dir + "'");
  const std::string path = dir + "/snippet_" + std::to_string(::getpid()) + ".py";
  {
    std::ofstream out(path);
    out << program;
  }
  return run_command(std::string("'") + CALIPER_SYSTEM_PYTHON + "' '" + path + "' " + args);
}

/// The fixture directory, generated once per test run (and again when the generator changes):
/// a file lock serialises the test processes ctest runs in parallel, a stamp named after a hash
/// of the generator marks a complete generation.
inline const std::string& io_fixture_dir() {
  static const std::string dir = [] {
    std::string out = std::string(CALIPER_TEST_DATA_DIR) + "/smpl_io";
    const std::string script =
        std::string(CALIPER_TESTS_SOURCE_DIR) + "/fixtures/make_io_fixtures.py";
    const std::string stamp =
        out + "/STAMP_" + std::to_string(std::hash<std::string>{}(read_text(script)));
    run_command("mkdir -p '" + out + "'");
    const int lock = ::open((out + "/.lock").c_str(), O_CREAT | O_RDWR, 0644);
    if (lock < 0) throw std::runtime_error("cannot create the fixture lock in " + out);
    ::flock(lock, LOCK_EX);
    if (!std::ifstream(stamp)) {
      const int rc = run_command(std::string("'") + CALIPER_SYSTEM_PYTHON + "' '" + script + "' '" +
                                 out + "'");
      if (rc != 0) {
        ::close(lock);
        throw std::runtime_error("the fixture generator failed: " + script);
      }
      std::ofstream(stamp) << "ok\n";
    }
    ::flock(lock, LOCK_UN);
    ::close(lock);
    return out;
  }();
  return dir;
}

inline void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  smpl::write_file_bytes(path, bytes);
}

}  // namespace caliper::test
