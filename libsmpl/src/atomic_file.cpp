// Atomic whole-file writes: temporary file in the same folder, write, fsync, rename.
#include "smpl/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace smpl {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
  std::string hint;
  if (err == ENOSPC || err == EDQUOT || err == EFBIG)
    hint = "; free some space or write elsewhere";
  else if (err == ENOENT)
    hint = "; check that the folder exists";
  else if (err == EACCES || err == EPERM || err == EROFS)
    hint = "; check that the folder is writable";
  throw WriteError(path + ": " + what + " (" + std::strerror(err) + ")" + hint +
                   "; the previous file, if any, is unchanged");
}

/// Writes all of `bytes` to `fd`; returns 0 or the errno of the failing write.
int write_all(int fd, std::string_view bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    done += static_cast<size_t>(n);
  }
  return 0;
}

/// Writes every piece in turn; returns 0 or the errno of the failing write.
int write_all(int fd, const std::vector<std::string_view>& pieces) {
  for (const std::string_view piece : pieces) {
    if (const int err = write_all(fd, piece)) return err;
  }
  return 0;
}

/// Writes in place into an existing device or FIFO (which cannot be renamed over).
void write_in_place(const std::string& path, const std::vector<std::string_view>& pieces) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) fail(path, "cannot open for writing", errno);
  int err = write_all(fd, pieces);
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) fail(path, "writing failed", err);
}

std::atomic<unsigned> g_counter{0};

}  // namespace

void write_file_atomic(const std::string& path, std::string_view bytes) {
  write_file_atomic(path, std::vector<std::string_view>{bytes});
}

void write_file_atomic(const std::string& path_in, const std::vector<std::string_view>& pieces) {
  namespace fs = std::filesystem;
  if (path_in.empty()) throw WriteError("cannot write a file with an empty name");
  std::string path = path_in;
  mode_t mode = 0666;
  bool keep_mode = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {  // follows symbolic links
    if (S_ISDIR(st.st_mode)) fail(path_in, "cannot write the file", EISDIR);
    if (!S_ISREG(st.st_mode)) return write_in_place(path_in, pieces);
    mode = st.st_mode & 07777;
    keep_mode = true;
    struct stat lst {};
    if (::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode)) {
      std::error_code ec;
      const fs::path target = fs::canonical(path, ec);  // replace the file, keep the link
      if (ec) fail(path_in, "cannot follow the symbolic link", ec.value());
      path = target.string();
    }
  }
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  int fd = -1;
  std::string tmp;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = (dir / ("." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                  std::to_string(g_counter.fetch_add(1))))
              .string();
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) fail(path_in, "cannot create a temporary file beside it", errno);
  }
  if (fd < 0) fail(path_in, "cannot create a temporary file beside it", EEXIST);
  int err = write_all(fd, pieces);
  const char* what = "writing failed";
  if (err == 0 && keep_mode && ::fchmod(fd, mode) != 0) {
    err = errno;
    what = "cannot set the file's permissions";
  }
  if (err == 0 && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    err = errno;  // EINVAL: the file system does not support fsync; the data is still written
    what = "flushing to disk failed";
  }
  if (::close(fd) != 0 && err == 0) {
    err = errno;
    what = "closing failed";
  }
  if (err == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) {
    err = errno;
    what = "cannot replace the file";
  }
  if (err != 0) {
    ::unlink(tmp.c_str());
    fail(path_in, what, err);
  }
  // Make the rename itself durable (best effort: not every file system allows it).
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace smpl
