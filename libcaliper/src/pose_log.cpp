// Pose log reader and writer (JSON Lines). Format: docs/pose-log-format.md.
#include "caliper/pose_log.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "smpl/atomic_file.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/text.hpp"

namespace caliper {
namespace {

constexpr const char* kFormatName = "caliper-pose-log";
constexpr int kFormatVersion = 1;

[[noreturn]] void fail(const std::string& name, int line, const std::string& what) {
  std::ostringstream s;
  s << name << ":" << line << ": " << what;
  throw PoseLogError(s.str(), line);
}

bool is_word_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

/// True when the line holds a bare NaN / Infinity token outside strings (what printf("%f") of a
/// NaN or an inf produces), so that the error can say so instead of "unexpected character".
bool has_non_finite_token(const std::string& line) {
  bool in_string = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
      continue;
    }
    if (i > 0 && is_word_char(line[i - 1])) continue;
    for (const char* token : {"nan", "inf"}) {
      bool match = line.size() - i >= 3;
      for (size_t k = 0; match && k < 3; ++k)
        match = std::tolower(static_cast<unsigned char>(line[i + k])) == token[k];
      if (match) return true;
    }
  }
  return false;
}

double finite_number(const Json& v, const std::string& name, int line, const std::string& key) {
  if (!v.is_number()) fail(name, line, "\"" + key + "\" must be a number");
  const double d = v.as_number();
  if (!std::isfinite(d))
    fail(name, line, "\"" + key + "\" is not a finite number (NaN or infinity)");
  return d;
}

DevicePose parse_device(const Json& j, Device device, const std::string& name, int line,
                        const PoseLogLimits& limits) {
  const std::string dev = device_name(device);
  if (!j.is_object()) fail(name, line, "\"" + dev + "\" must be an object");
  DevicePose d;
  const Json* valid = j.find("valid");
  if (!valid || !valid->is_bool())
    fail(name, line, "\"" + dev + ".valid\" (true/false) is missing");
  d.valid = valid->as_bool();
  const Json* p = j.find("p");
  const Json* q = j.find("q");
  if (d.valid && (!p || !q))
    fail(name, line, "\"" + dev + "\" is valid but has no \"p\" and \"q\"");
  if (p) {
    if (!p->is_array() || p->size() != 3)
      fail(name, line, "\"" + dev + ".p\" must be [x, y, z] (3 numbers, metres)");
    for (int i = 0; i < 3; ++i) {
      d.position[i] = finite_number((*p)[i], name, line, dev + ".p");
      if (std::abs(d.position[i]) > limits.max_abs_position)
        fail(name, line,
             "\"" + dev + ".p\" is " + std::to_string(d.position[i]) +
                 " m from the origin, outside any tracking space");
    }
  }
  if (q) {
    if (!q->is_array() || q->size() != 4)
      fail(name, line, "\"" + dev + ".q\" must be [x, y, z, w] (4 numbers, a unit quaternion)");
    double c[4];
    for (int i = 0; i < 4; ++i) c[i] = finite_number((*q)[i], name, line, dev + ".q");
    Eigen::Quaterniond qq(c[3], c[0], c[1], c[2]);
    const double n = qq.norm();
    if (std::abs(n - 1.0) > limits.quaternion_norm_tolerance)
      fail(name, line,
           "\"" + dev + ".q\" is not a unit quaternion (norm " + std::to_string(n) + ")");
    d.orientation = qq.normalized();
  }
  if (device != Device::Head) {
    if (const Json* t = j.find("trigger")) {
      d.trigger = finite_number(*t, name, line, dev + ".trigger");
      if (d.trigger < 0.0 || d.trigger > 1.0)
        fail(name, line, "\"" + dev + ".trigger\" must be in [0, 1]");
    }
    if (const Json* b = j.find("buttons")) {
      if (!b->is_array()) fail(name, line, "\"" + dev + ".buttons\" must be an array of names");
      for (const Json& n : b->as_array()) {
        if (!n.is_string()) fail(name, line, "\"" + dev + ".buttons\" must hold strings");
        if (n.as_string() == "menu")
          d.menu = true;
        else if (n.as_string() == "squeeze")
          d.squeeze = true;
        else
          fail(name, line, "unknown button \"" + n.as_string() + "\" (known: menu, squeeze)");
      }
    }
  }
  return d;
}

PoseLogHeader parse_header(const Json& j, const std::string& name) {
  if (!has_format(j, kFormatName))
    fail(name, 1,
         std::string("the first line is not a pose log header (expected {\"format\": \"") +
             kFormatName + "\", ...})");
  PoseLogHeader h;
  const Json* v = j.find("version");
  if (!v || !v->is_number()) fail(name, 1, "the header has no \"version\"");
  // Compared as a number before any cast: a version of 1e300 must not be cast to int (UB).
  if (v->as_number() != static_cast<double>(kFormatVersion))
    fail(name, 1,
         "pose log version " + v->dump() + " is not supported (this build reads version 1)");
  h.version = kFormatVersion;
  if (const Json* u = j.find("units"); u && (!u->is_string() || u->as_string() != "metres"))
    fail(name, 1, "\"units\" must be \"metres\"");
  if (const Json* s = j.find("reference_space"); s && s->is_string())
    h.reference_space = s->as_string();
  if (const Json* s = j.find("interaction_profile"); s && s->is_string())
    h.interaction_profile = s->as_string();
  if (const Json* s = j.find("role"); s) {
    if (!s->is_string() || (s->as_string() != "self" && s->as_string() != "operator"))
      fail(name, 1, "\"role\" must be \"self\" or \"operator\"");
    h.role = s->as_string();
  }
  if (const Json* s = j.find("frame_rate"); s && s->is_number()) h.frame_rate = s->as_number();
  if (const Json* s = j.find("source"); s && s->is_string()) h.source = s->as_string();
  if (const Json* w = j.find("weight"); w && !w->is_null()) {
    if (!w->is_number() || !std::isfinite(w->as_number()) || w->as_number() <= 0.0)
      fail(name, 1, "\"weight\" must be a positive number (kg)");
    h.weight = w->as_number();
  }
  if (const Json* s = j.find("sex"); s && !s->is_null()) {
    if (!s->is_string() || (s->as_string() != "female" && s->as_string() != "male"))
      fail(name, 1, "\"sex\" must be \"female\" or \"male\"");
    h.sex = s->as_string();
  }
  return h;
}

/// `v` rounded to `decimals` decimals: the value a reader gets back from its fixed-point text
/// (the log stays as compact as that precision), with -0 written as 0 so that logs stay stable.
double rounded(double v, int decimals) {
  if (!std::isfinite(v))
    throw PoseLogError("pose log writer: refusing to write a NaN or infinite value", 0);
  const double r = std::strtod(smpl::format_fixed(v, decimals).c_str(), nullptr);
  return r == 0.0 ? 0.0 : r;
}

}  // namespace

namespace {
constexpr std::array<const char*, kNumDevices> kDeviceNames = {"head", "left", "right"};
}  // namespace

const char* device_name(Device device) {
  return smpl::enum_name(device, kDeviceNames);
}

PoseLog parse_pose_log(const std::string& text, const std::string& name,
                       const PoseLogLimits& limits) {
  PoseLog log;
  if (text.empty()) fail(name, 1, "the file is empty (expected a header line)");
  size_t pos = 0;
  int line_no = 0;
  bool have_header = false;
  const PoseFrame* prev = nullptr;
  while (pos < text.size()) {
    ++line_no;
    const size_t end = text.find('\n', pos);
    const bool terminated = end != std::string::npos;
    std::string line = text.substr(pos, terminated ? end - pos : std::string::npos);
    pos = terminated ? end + 1 : text.size();
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    Json j;
    try {
      j = parse_json(line);
    } catch (const JsonError& e) {
      if (!terminated)
        fail(name, line_no, "the file is truncated: the last line ends in the middle of a record");
      if (has_non_finite_token(line))
        fail(name, line_no, "contains NaN or infinity; pose values must be finite numbers");
      fail(name, line_no,
           std::string("malformed JSON at column ") + std::to_string(e.column) + ": " + e.what());
    }
    if (!have_header) {
      log.header = parse_header(j, name);
      have_header = true;
      continue;
    }
    if (!j.is_object()) fail(name, line_no, "a frame line must be a JSON object");
    if (!log.lost.empty())
      fail(name, line_no, "a line follows the \"lost\" line, which must be the last one");
    if (const Json* lost = j.find("lost")) {
      if (!lost->is_string() || lost->as_string().empty())
        fail(name, line_no, "\"lost\" must be a non-empty string (why the source ended)");
      log.lost = lost->as_string();
      continue;
    }
    PoseFrame f;
    f.line = line_no;
    const Json* t = j.find("t");
    if (!t) fail(name, line_no, "the frame has no time \"t\"");
    f.time = finite_number(*t, name, line_no, "t");
    for (int d = 0; d < kNumDevices; ++d) {
      const Device dev = static_cast<Device>(d);
      const Json* dj = j.find(device_name(dev));
      if (!dj) fail(name, line_no, std::string("the frame has no \"") + device_name(dev) + "\"");
      f.devices[d] = parse_device(*dj, dev, name, line_no, limits);
    }
    if (const Json* ip = j.find("profile")) {
      if (!ip->is_string() || ip->as_string().empty())
        fail(name, line_no, "\"profile\" must be an interaction profile path");
      f.interaction_profile = ip->as_string();
    }
    if (const Json* c = j.find("commands")) {
      if (!c->is_array()) fail(name, line_no, "\"commands\" must be an array");
      for (const Json& cj : c->as_array()) {
        if (!cj.is_object() || !cj.contains("command") || !cj.at("command").is_string())
          fail(name, line_no, "each command must be {\"command\": \"...\", \"value\": ...}");
        OperatorCommand oc;
        oc.command = cj.at("command").as_string();
        if (const Json* v = cj.find("value")) oc.value = *v;
        if (oc.command != "start" && oc.command != "redo" && oc.command != "skip" &&
            oc.command != "weight" && oc.command != "sex")
          fail(name, line_no,
               "unknown command \"" + oc.command + "\" (known: start, redo, skip, weight, sex)");
        f.commands.push_back(std::move(oc));
      }
    }
    if (prev) {
      const double dt = f.time - prev->time;
      if (!(dt > 0.0))
        fail(name, line_no,
             "time " + std::to_string(f.time) + " s does not increase (previous line " +
                 std::to_string(prev->line) + ": " + std::to_string(prev->time) + " s)");
      for (int d = 0; d < kNumDevices; ++d) {
        const DevicePose& a = prev->devices[d];
        const DevicePose& b = f.devices[d];
        if (!a.valid || !b.valid) continue;
        const double speed = (b.position - a.position).norm() / dt;
        if (speed > limits.max_speed) {
          std::ostringstream s;
          s << "impossible jump of the " << device_name(static_cast<Device>(d))
            << " device: " << (b.position - a.position).norm() << " m in " << dt << " s (" << speed
            << " m/s, limit " << limits.max_speed << " m/s) since line " << prev->line;
          fail(name, line_no, s.str());
        }
      }
    }
    log.frames.push_back(std::move(f));
    prev = &log.frames.back();
  }
  if (!have_header) fail(name, 1, "the file has no header line");
  return log;
}

PoseLog read_pose_log(const std::string& path, const PoseLogLimits& limits) {
  const std::optional<std::string> text = smpl::read_file(path);
  if (!text) throw PoseLogError(path + ": cannot open the pose log (does the file exist?)", 0);
  return parse_pose_log(*text, path, limits);
}

std::string pose_log_header_line(const PoseLogHeader& header) {
  Json j = Json::object();
  j.set("format", kFormatName);
  j.set("version", header.version);
  j.set("units", "metres");
  j.set("reference_space", header.reference_space);
  j.set("interaction_profile", header.interaction_profile);
  j.set("role", header.role);
  j.set("frame_rate", header.frame_rate);
  Json devices = Json::array();
  for (const char* d : kDeviceNames) devices.push_back(d);
  j.set("devices", devices);
  j.set("source", header.source);
  if (header.weight) j.set("weight", *header.weight);
  if (!header.sex.empty()) j.set("sex", header.sex);
  return j.dump();
}

std::string pose_log_frame_line(const PoseFrame& frame) {
  Json j = Json::object();
  j.set("t", rounded(frame.time, 6));
  for (int d = 0; d < kNumDevices; ++d) {
    const DevicePose& p = frame.devices[d];
    Json device = Json::object();
    device.set("valid", p.valid);
    if (p.valid) {
      device.set("p", Json(std::vector<double>{rounded(p.position[0], 6), rounded(p.position[1], 6),
                                               rounded(p.position[2], 6)}));
      device.set("q", Json(std::vector<double>{
                          rounded(p.orientation.x(), 6), rounded(p.orientation.y(), 6),
                          rounded(p.orientation.z(), 6), rounded(p.orientation.w(), 6)}));
    }
    if (d != static_cast<int>(Device::Head)) {
      device.set("trigger", rounded(p.trigger, 3));
      if (p.menu || p.squeeze) {
        Json buttons = Json::array();
        if (p.menu) buttons.push_back("menu");
        if (p.squeeze) buttons.push_back("squeeze");
        device.set("buttons", std::move(buttons));
      }
    }
    j.set(device_name(static_cast<Device>(d)), std::move(device));
  }
  if (!frame.interaction_profile.empty()) j.set("profile", frame.interaction_profile);
  if (!frame.commands.empty()) {
    Json c = Json::array();
    for (const OperatorCommand& oc : frame.commands) {
      Json o = Json::object();
      o.set("command", oc.command);
      if (!oc.value.is_null()) o.set("value", oc.value);
      c.push_back(std::move(o));
    }
    j.set("commands", std::move(c));
  }
  return j.dump();
}

PoseLogWriter::PoseLogWriter(const std::string& path, const PoseLogHeader& header)
    : path_(path), file_(path, "wb") {
  if (!file_.is_open())
    throw PoseLogError(path + ": cannot create the pose log (is the folder writable?)", 0);
  if (!file_.append_line(pose_log_header_line(header)))
    throw PoseLogError(path + ": cannot write the pose log header (disk full?)", 0);
}

void PoseLogWriter::write(const PoseFrame& frame) {
  if (!file_.append_line(pose_log_frame_line(frame)))
    throw PoseLogError(path_ + ": cannot append to the pose log (disk full?)", 0);
}

namespace {

// The record that ends a log whose pose source was lost.
std::string pose_log_lost_line(const std::string& reason) {
  Json j = Json::object();
  j.set("lost", reason.empty() ? std::string("the source was lost") : reason);
  return j.dump();
}

}  // namespace

void PoseLogWriter::write_lost(const std::string& reason) {
  if (!file_.append_line(pose_log_lost_line(reason)))
    throw PoseLogError(path_ + ": cannot append to the pose log (disk full?)", 0);
}

void write_pose_log(const std::string& path, const PoseLog& log) {
  std::string text = pose_log_header_line(log.header) + "\n";
  for (const PoseFrame& f : log.frames) text += pose_log_frame_line(f) + "\n";
  if (!log.lost.empty()) text += pose_log_lost_line(log.lost) + "\n";
  smpl::write_file_atomic(path, text);
}

}  // namespace caliper
