/// \file pose_log.hpp
/// The pose log: a JSON Lines recording of every frame's headset and controller poses, tracking
/// flags, trigger values, buttons and operator commands (format: docs/pose-log-format.md).
/// `caliper-vr --record FILE` writes it, `caliper-vr --replay FILE` and the tests read it, and the
/// session simulator (simulator.hpp) generates it for a virtual person of known body shape.
///
/// Line 1 is a header object, every later line one frame. Units: metres, seconds; orientation
/// quaternions are [x, y, z, w]; frame +Y up. Positions are grip poses (the app adds the tip
/// offset of the interaction profile, see session.hpp).
#pragma once

#include <array>
#include <cstdio>
#include <istream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "caliper/json.hpp"
#include "caliper/line_file.hpp"

namespace caliper {

/// Thrown for every pose log problem. `line` is the 1-based line of the file (0 when the problem
/// is not about one line, e.g. the file cannot be opened). The message names the file and line.
class PoseLogError : public std::runtime_error {
 public:
  PoseLogError(const std::string& what, int line_number)
      : std::runtime_error(what), line(line_number) {}
  int line;
};

/// The three tracked devices, in the order they are stored.
enum class Device { Head = 0, Left = 1, Right = 2 };
constexpr int kNumDevices = 3;
/// "head", "left", "right".
const char* device_name(Device device);

/// One device's state in one frame.
struct DevicePose {
  bool valid = false;  ///< position and orientation tracked this frame
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               ///< grip (or head) position, m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< unit quaternion
  double trigger = 0.0;  ///< trigger value in [0, 1] (controllers only)
  bool menu = false;     ///< menu button pressed
  bool squeeze = false;  ///< squeeze / grip button pressed
};

/// An operator command typed or clicked in the desktop window (or scripted in a log):
/// "start", "redo", "skip" (no value), "weight" (number, kg), "sex" (string "female"/"male").
struct OperatorCommand {
  std::string command;
  Json value;  ///< null for start/redo/skip
};

/// One frame.
struct PoseFrame {
  double time = 0.0;                            ///< seconds since the start of the recording
  std::array<DevicePose, kNumDevices> devices;  ///< indexed by Device
  std::vector<OperatorCommand> commands;        ///< commands issued during this frame
  /// The interaction profile the runtime reported on this frame, when it differs from the one
  /// in force before (live runtimes report it some frames after the start); "" = no change.
  std::string interaction_profile;
  int line = 0;  ///< 1-based line in the file it was read from (0 if none)

  const DevicePose& device(Device d) const { return devices[static_cast<int>(d)]; }
  DevicePose& device(Device d) { return devices[static_cast<int>(d)]; }
};

/// The header line.
struct PoseLogHeader {
  int version = 1;                        ///< format version (this reader knows 1)
  std::string reference_space = "stage";  ///< OpenXR reference space the poses are in
  /// Profile in force at the first frame; "" when the runtime had not reported one yet (frames
  /// name it when it becomes known, PoseFrame::interaction_profile).
  std::string interaction_profile = "/interaction_profiles/htc/vive_controller";
  std::string role = "self";  ///< "self" or "operator"
  double frame_rate = 90.0;   ///< the source's frames per second (live: the runtime's display rate)
  std::string source;         ///< "openxr", "simulator seed=...", ...
  std::optional<double> weight;  ///< kg typed on the command line (--weight) of the recording
  std::string sex;               ///< --sex of the recording ("" = not given)
};

/// A whole log in memory.
struct PoseLog {
  PoseLogHeader header;
  std::vector<PoseFrame> frames;
  /// Why the source ended early, when the recording says so (a `{"lost": "..."}` line after the
  /// last frame: the runtime lost the session); "" = the log simply ends.
  std::string lost;
};

/// Checks applied while reading, with the reason for each default.
struct PoseLogLimits {
  /// A tracked device moving faster than this between two consecutive valid frames is a
  /// tracking glitch, not a person: hands peak near 10 m/s in fast throws.
  double max_speed = 20.0;  ///< m/s
  /// Quaternions are written with 6 decimals; a norm further than this from 1 is corrupt data.
  double quaternion_norm_tolerance = 1e-3;
  /// Positions beyond this distance from the origin are not inside any tracking space.
  double max_abs_position = 100.0;  ///< m
};

/// Parses a log held in memory. `name` is used in messages (usually the path). Throws
/// PoseLogError with the 1-based line for: an empty text, a header that is not a pose log header
/// or has an unknown version, a malformed line (with the JSON error's column), a missing or
/// mistyped key, NaN or infinity (written as NaN/Infinity tokens), a non-unit quaternion, time that
/// does not increase, an impossible jump (speed above limits.max_speed) and a truncated last line
/// (no newline at the end and not a complete JSON object).
PoseLog parse_pose_log(const std::string& text, const std::string& name,
                       const PoseLogLimits& limits = {});

/// Reads and parses a file (see parse_pose_log). Throws PoseLogError (line 0) when the file cannot
/// be read.
PoseLog read_pose_log(const std::string& path, const PoseLogLimits& limits = {});

/// Serialises the header line (without newline).
std::string pose_log_header_line(const PoseLogHeader& header);
/// Serialises one frame line (without newline). Positions, quaternions and time are rounded to
/// 6 decimals (micrometres), trigger values to 3, each written as the shortest number that reads
/// back to the rounded value. Throws PoseLogError for NaN or infinite values.
std::string pose_log_frame_line(const PoseFrame& frame);

/// Writes a log line by line, flushing after every frame so that a crash loses at most one
/// frame. Move-only; the file is closed by the destructor.
class PoseLogWriter {
 public:
  /// Creates (truncates) `path` and writes the header. Throws PoseLogError when it cannot.
  PoseLogWriter(const std::string& path, const PoseLogHeader& header);
  PoseLogWriter(PoseLogWriter&&) noexcept = default;
  PoseLogWriter& operator=(PoseLogWriter&&) noexcept = default;

  /// Appends one frame. Throws PoseLogError on I/O failure.
  void write(const PoseFrame& frame);
  /// Appends the `{"lost": reason}` line: the source was lost here (see PoseLog::lost).
  void write_lost(const std::string& reason);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  LineFile file_;
};

/// Writes a whole log to `path` (header and frames) atomically (smpl::write_file_atomic); throws
/// smpl::WriteError when writing fails (the previous file is then unchanged).
void write_pose_log(const std::string& path, const PoseLog& log);

}  // namespace caliper
