/// \file atomic_file.hpp
/// The one way the project writes a whole file: atomically, so that a reader (or the user after
/// a crash or a full disk) sees either the previous file or the complete new one, never a file
/// cut short. Used by every exporter and writer of libsmpl, libcaliper and the programs
/// (docs/reliability.md, "Writes").
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "smpl/body_model.hpp"

namespace smpl {

/// A file could not be written: the folder is missing or not writable, the disk is full, the
/// rename was refused. The message names the file, the system's reason and what to do. A
/// ModelError, as every file problem of libsmpl.
class WriteError : public ModelError {
 public:
  using ModelError::ModelError;
};

/// Writes `bytes` to `path` atomically: a new temporary file in the same folder
/// (".NAME.tmp-PID-N"), every byte written, flushed and fsync'ed, then renamed over `path` (and the
/// folder fsync'ed, best effort). An existing regular file keeps its permission bits; a symbolic
/// link is followed and the file it points to is replaced. On any failure it throws WriteError;
/// the previous file at `path` is untouched and the temporary file is removed.
/// `path` naming an existing non-regular file (a character device such as /dev/stdout or
/// /dev/full, a FIFO) is written in place, since it cannot be replaced; every error is still
/// reported. Thread-safe (distinct temporary names per call).
void write_file_atomic(const std::string& path, std::string_view bytes);

/// write_file_atomic() of the concatenation of `pieces`, without concatenating them (a GLB's
/// header, JSON and binary chunk are written from where they are).
void write_file_atomic(const std::string& path, const std::vector<std::string_view>& pieces);

}  // namespace smpl
