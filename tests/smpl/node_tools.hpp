// Runs the Node tools of the glTF/VRM tests: the Khronos glTF-Validator (tests/gltf) and the
// reference VRM loader @pixiv/three-vrm (tests/vrm), both installed by `npm ci` (CI installs them).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace caliper::test {

/// Runs `node <tools_dir>/<script> files...`; returns its exit status and output (stdout+stderr).
inline int run_node_tool(const std::string& tools_dir, const std::string& script,
                         const std::vector<std::filesystem::path>& files, std::string& output) {
  std::string cmd = std::string("\"") + CALIPER_NODE + "\" \"" + tools_dir + "/" + script + "\"";
  for (const auto& f : files) cmd += " \"" + f.string() + "\"";
  cmd += " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) output.append(buf.data(), n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// True when node and `tools_dir`/node_modules/`package` exist; else `why` says what to do.
inline bool node_tool_installed(const std::string& tools_dir, const std::string& package,
                                std::string& why) {
  if (std::string(CALIPER_NODE).empty() ||
      std::string(CALIPER_NODE).find("NOTFOUND") != std::string::npos) {
    why = "node was not found at configure time (install nodejs: .ci/install-deps.sh)";
    return false;
  }
  if (!std::filesystem::exists(std::filesystem::path(tools_dir) / "node_modules" / package)) {
    why = tools_dir + "/node_modules is missing: run `npm ci` there (.ci/install-deps.sh)";
    return false;
  }
  return true;
}

}  // namespace caliper::test
