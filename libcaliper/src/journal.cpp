// Session journal: append-only JSON Lines that survives being cut at any byte.
#include "caliper/journal.hpp"
#include "smpl/text.hpp"

#include <cmath>

#include <unistd.h>

namespace caliper {
namespace {

constexpr const char* kJournalFormat = "caliper-session-journal";

}  // namespace

Json journal_record_json(const JournalRecord& r) {
  Json j = Json::object();
  j.set("type", r.type);
  if (!r.step.empty()) j.set("step", r.step);
  if (r.index >= 0) j.set("index", r.index);
  if (!r.points.empty()) {
    Json pts = Json::array();
    for (const Eigen::Vector3d& p : r.points)
      pts.push_back(Json(std::vector<double>{p.x(), p.y(), p.z()}));
    j.set("points", pts);
  }
  if (r.type == "sample" || (r.type == "typed" && r.text.empty())) j.set("value", r.value);
  if (!r.text.empty()) j.set("text", r.text);
  j.set("time", r.time);
  return j;
}

JournalRecord journal_record_from_json(const Json& j) {
  JournalRecord r;
  r.type = j.at("type").as_string();
  if (const Json* s = j.find("step")) r.step = s->as_string();
  if (const Json* s = j.find("index")) r.index = s->as_int();
  if (const Json* s = j.find("points")) {
    for (const Json& p : s->as_array()) {
      const std::vector<double> v = p.as_numbers();
      if (v.size() != 3) throw JsonError("a journal point must have 3 coordinates");
      r.points.emplace_back(v[0], v[1], v[2]);
    }
  }
  if (const Json* s = j.find("value")) r.value = s->as_number();
  if (const Json* s = j.find("text")) r.text = s->as_string();
  if (const Json* s = j.find("time")) r.time = s->as_number();
  static const char* kTypes[] = {"start", "floor_sample", "floor_retry", "sample",
                                 "redo",  "skip",         "typed"};
  bool known = false;
  for (const char* t : kTypes) known = known || r.type == t;
  if (!known) throw JsonError("unknown journal record type \"" + r.type + "\"");
  return r;
}

JournalContents parse_journal(const std::string& text, const std::string& name) {
  JournalContents c;
  size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    const size_t end = text.find('\n', pos);
    if (end == std::string::npos) {  // a cut last line: ignored
      c.torn_tail = true;
      break;
    }
    ++line_no;
    const std::string line = text.substr(pos, end - pos);
    const bool last_line = end + 1 == text.size();
    Json j;
    bool ok = true;
    std::string why;
    try {
      j = parse_json(line);
      if (!c.has_header) {
        if (!has_format(j, kJournalFormat))
          throw JournalError(name + ":1: not a session journal (expected {\"format\": \"" +
                             std::string(kJournalFormat) + "\", ...})");
        const Json* version = j.find("version");
        if (!version || !version->is_number() || version->as_number() != 1.0)
          throw JournalError(name + ":1: session journal version " +
                             (version ? version->dump() : std::string("(none)")) +
                             " is not supported (this build reads version 1)");
        c.header = j;
        c.has_header = true;
      } else {
        c.records.push_back(journal_record_from_json(j));
      }
    } catch (const JsonError& e) {
      ok = false;
      why = e.what();
    }
    if (!ok) {
      // A line that ends with a newline but does not parse can only be the last one if the cut
      // happened inside a multi-byte write; anywhere else the journal is corrupt.
      if (last_line) {
        c.torn_tail = true;
        break;
      }
      throw JournalError(name + ":" + std::to_string(line_no) + ": corrupt journal record (" + why +
                         "); the records before this line are intact");
    }
    pos = end + 1;
    c.valid_bytes = pos;
  }
  return c;
}

JournalContents read_journal(const std::string& path) {
  const std::optional<std::string> text = smpl::read_file(path);
  if (!text) throw JournalError(path + ": cannot open the session journal (does the file exist?)");
  return parse_journal(*text, path);
}

void check_journal_protocol(const JournalContents& contents, const std::string& protocol_name,
                            const std::string& path) {
  if (!contents.has_header) return;
  const Json* p = contents.header.find("protocol");
  if (!p) return;
  if (!p->is_string() || p->as_string() != protocol_name)
    throw JournalError(path + ": the journal was written with the protocol " + p->dump() +
                       ", this session uses \"" + protocol_name +
                       "\"; resume with the same --protocol, or start a new session");
}

JournalWriter JournalWriter::create(const std::string& path, const Json& header) {
  LineFile f(path, "wb");
  if (!f.is_open())
    throw JournalError(path + ": cannot create the session journal (is the folder writable?)");
  JournalWriter w(path, std::move(f));
  Json h = format_header(kJournalFormat);
  if (header.is_object())
    for (const auto& kv : header.as_object()) h.set(kv.first, kv.second);
  w.write_line(h.dump());
  return w;
}

JournalWriter JournalWriter::resume(const std::string& path, const JournalContents& contents,
                                    const Json& header) {
  if (!contents.has_header) return create(path, header);
  if (truncate(path.c_str(), static_cast<off_t>(contents.valid_bytes)) != 0)
    throw JournalError(path + ": cannot cut the torn last line off the session journal");
  LineFile f(path, "ab");
  if (!f.is_open()) throw JournalError(path + ": cannot open the session journal for appending");
  return JournalWriter(path, std::move(f));
}

void JournalWriter::write_line(const std::string& line) {
  if (!file_.append_line(line, /*sync=*/true))
    throw JournalError(path_ + ": cannot append to the session journal (disk full?)");
}

void JournalWriter::append(const JournalRecord& record) {
  write_line(journal_record_json(record).dump());
}

}  // namespace caliper
