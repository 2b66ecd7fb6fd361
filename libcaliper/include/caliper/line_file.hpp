/// \file line_file.hpp
/// A file written one line at a time and flushed after each line, for the records that must
/// survive a crash (the session journal, pose logs). Owns its FILE*, closes it once, move-only.
#pragma once

#include <cstdio>
#include <memory>
#include <string>

namespace caliper {

class LineFile {
 public:
  LineFile() = default;
  /// Opens `path` with fopen `mode` ("wb" truncates, "ab" appends); test with is_open().
  LineFile(const std::string& path, const char* mode);

  bool is_open() const { return file_ != nullptr; }
  /// Writes `line` and a newline, then fflush; with `sync` also fsync, so the line reaches the
  /// disk and not only the OS. False when the file is not open or a write fails.
  bool append_line(const std::string& line, bool sync = false);

 private:
  struct Closer {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace caliper
