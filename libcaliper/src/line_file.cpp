#include "caliper/line_file.hpp"

#include <unistd.h>

namespace caliper {

LineFile::LineFile(const std::string& path, const char* mode)
    : file_(std::fopen(path.c_str(), mode)) {}

bool LineFile::append_line(const std::string& line, bool sync) {
  if (!file_) return false;
  const std::string l = line + "\n";
  if (std::fwrite(l.data(), 1, l.size(), file_.get()) != l.size()) return false;
  if (std::fflush(file_.get()) != 0) return false;
  if (sync) fsync(fileno(file_.get()));  // best effort: not every file system supports it
  return true;
}

}  // namespace caliper
