/// \file protocol_file.hpp
/// The measuring protocol file (assets/protocol/virtual-caliper.json, docs/vr.md): the floor
/// calibration targets and limits, then the measurement steps in order, each with its
/// instruction text, the landmarks where the controller tips go, which tips, and what is computed.
/// Implements the procedure of Pujades et al., "The Virtual Caliper", TVCG 2019, sec. 3.1.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace caliper {

/// Thrown for every protocol file problem; the message names the file, the key and the value.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a step computes.
enum class StepKind {
  Height,       ///< one tip; value = tip height above the calibrated floor, m
  Distance,     ///< two tips; value = distance between the tips, m
  TypedNumber,  ///< typed by the operator or on the command line (e.g. weight, kg)
  TypedChoice,  ///< one of `choices`, typed (e.g. sex)
};
/// "height", "distance", "typed_number", "typed_choice".
const char* step_kind_name(StepKind kind);

/// Which controller's tip is used.
enum class Tip { Left, Right };

/// One measurement step.
struct ProtocolStep {
  std::string id;           ///< unique step id (usually the measurement id)
  std::string measurement;  ///< measurement id it produces (shared vocabulary: "height", ...)
  StepKind kind = StepKind::Distance;
  std::string title;        ///< short title for the panel
  std::string instruction;  ///< instruction text shown on the panel
  std::vector<Tip> tips;    ///< 1 (height) or 2 (distance) tips, in the order of `landmarks`
  std::vector<std::string> landmarks;  ///< landmark where each tip goes (same size as tips)
  std::string
      demo_pose;  ///< reference avatar pose of the demonstration: "t_pose", "a_pose", "arms_down"
  std::string video;  ///< optional video file, relative to the protocol file ("" = none)
  std::string unit;   ///< typed steps: "kg"; measured steps: "m"
  std::vector<std::string> choices;  ///< typed_choice: allowed values
  bool optional = false;             ///< may be skipped without warning
};

/// Floor calibration settings.
struct FloorProtocol {
  std::string instruction;
  /// Target positions on the floor, metres, (x, z) relative to the centre of the space.
  std::vector<Eigen::Vector2d> targets;
  double max_tilt_deg = 3.0;     ///< plane tilt above this asks for a retry
  double max_residual_m = 0.01;  ///< plane fit RMS residual above this asks for a retry
};

/// The whole protocol.
struct Protocol {
  std::string name;
  std::string path;               ///< file it was read from ("" when built in code)
  double hold_seconds = 1.0;      ///< trigger hold before a sample is taken (paper: 1 s)
  double max_jitter_m = 0.004;    ///< RMS tip motion during the hold above this rejects the sample
  double isak_threshold = 0.015;  ///< relative difference of two takes that asks for a third
  FloorProtocol floor;
  std::vector<ProtocolStep> steps;

  /// Index of the step with this id, or -1.
  int find_step(const std::string& id) const;
};

/// Reads and validates a protocol file. Throws ProtocolError naming the file, the step and the
/// key for: unknown kinds, a tips/landmarks count that does not fit the kind, duplicate ids, fewer
/// than 3 floor targets, non-positive hold time or thresholds. Landmark names are checked against
/// the shared vocabulary (caliper::landmark_names()).
Protocol read_protocol(const std::string& path);

/// Parses protocol JSON text (`name` is used in messages).
Protocol parse_protocol(const std::string& text, const std::string& name);

/// The paper's protocol: assets/protocol/virtual-caliper.json as embedded at build time (floor
/// with 5 targets, height, arm_span_fingertips, inseam_height, hip_width, arm_length, weight,
/// sex); `path` is "".
Protocol default_protocol();

/// The text of assets/protocol/virtual-caliper.json, byte for byte, embedded at build time
/// (caliper_embed_files in cmake/CaliperOptions.cmake): the one source of default_protocol().
const char* default_protocol_json();

}  // namespace caliper
