/// \file journal.hpp
/// The session journal: every state change of a measuring session that cannot be recomputed
/// (an accepted sample, a skip, a redo, a typed value) is appended to a JSON Lines file and
/// flushed at once, so that nothing is lost when the app or the machine crashes. `caliper-vr
/// --resume FILE` reads the journal back, replays its records into a fresh MeasuringSession and
/// continues at the step where it stopped (format: docs/vr.md).
///
/// Crash safety: a record only counts when its line is complete (ends with a newline and parses).
/// A journal cut at any byte therefore reads as the records whose lines were complete; the torn
/// tail is reported and cut off before new records are appended.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/json.hpp"
#include "caliper/line_file.hpp"

namespace caliper {

/// Thrown when a journal cannot be opened or written, or its header is not a journal header.
class JournalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One journal record. `type` is one of:
/// - "start": the session started (operator pressed start, or self role).
/// - "floor_sample": `index` = target, `points[0]` = tip on the floor (m, tracking space).
/// - "floor_retry": the floor fit was off (tilt or residual); the floor samples are discarded.
/// - "sample": `step` id, `points` = tip positions (1 or 2), `value` = measured value (m).
/// - "redo": `step` whose takes are discarded (operator redo).
/// - "skip": `step` skipped.
/// - "typed": `step` id, `value` (number) or `text` (choice).
struct JournalRecord {
  std::string type;
  std::string step;
  int index = -1;
  std::vector<Eigen::Vector3d> points;
  double value = 0.0;
  std::string text;
  double time = 0.0;  ///< session time of the event, s (informative)
};

/// Serialises a record as one JSON object.
Json journal_record_json(const JournalRecord& record);
/// Parses a record; throws JsonError for a malformed one.
JournalRecord journal_record_from_json(const Json& json);

/// What read_journal() recovered.
struct JournalContents {
  bool has_header = false;             ///< false: the file is empty or its header line was torn
  Json header;                         ///< the header object (format, version, protocol, role, ...)
  std::vector<JournalRecord> records;  ///< the complete records, in order
  size_t valid_bytes = 0;              ///< length of the prefix made of complete lines
  bool torn_tail = false;              ///< bytes after valid_bytes were ignored (a cut last line)
};

/// Parses journal text. Never throws for a cut file: an incomplete or unparseable LAST line is
/// ignored (torn_tail). Throws JournalError (naming `name` and the line) when a complete line in
/// the middle is corrupt, when a complete first line is not a journal header, or when the
/// header's "version" is not 1 (another format version: never guessed).
JournalContents parse_journal(const std::string& text, const std::string& name);

/// Reads a journal file (see parse_journal). A missing file throws JournalError.
JournalContents read_journal(const std::string& path);

/// Checks that a journal read for `--resume` belongs to a session with protocol `protocol_name`:
/// throws JournalError naming `path`, the journal's protocol and this one when they differ (a
/// header without "protocol" is accepted: older journals of the self role).
void check_journal_protocol(const JournalContents& contents, const std::string& protocol_name,
                            const std::string& path);

/// Appends records to a journal, one flushed line each.
class JournalWriter {
 public:
  /// Starts a new journal at `path` (truncating it) with `header` (an object; "format" and
  /// "version" are added).
  static JournalWriter create(const std::string& path, const Json& header);
  /// Continues an existing journal: cuts the torn tail (contents.valid_bytes) off, writes a
  /// header first if the file had none, then appends.
  static JournalWriter resume(const std::string& path, const JournalContents& contents,
                              const Json& header);

  JournalWriter(JournalWriter&&) noexcept = default;
  JournalWriter& operator=(JournalWriter&&) noexcept = default;

  /// Appends one record and flushes it (fflush + fsync where available). Throws JournalError.
  void append(const JournalRecord& record);
  const std::string& path() const { return path_; }

 private:
  JournalWriter(std::string path, LineFile file) : path_(std::move(path)), file_(std::move(file)) {}
  void write_line(const std::string& line);
  std::string path_;
  LineFile file_;
};

}  // namespace caliper
