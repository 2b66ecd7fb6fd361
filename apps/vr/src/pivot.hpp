/// \file pivot.hpp
/// The pivot-calibration step of the controller tip (`caliper-vr --calibrate-tip left|right`):
/// the user rests the tip on one fixed point, holds the trigger and rotates the controller for a
/// few seconds; on release the grip poses go to caliper::calibrate_pivot().
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "caliper/pose_log.hpp"
#include "caliper/protocol.hpp"
#include "caliper/protocol_file.hpp"

namespace caliper::vr {

class PivotCollector {
 public:
  explicit PivotCollector(Tip hand) : hand_(hand) {}
  /// Feeds a frame; returns the calibration when the trigger is released after a hold with at
  /// least kMinPoses valid poses. Throws CalibrationError for a degenerate hold (no rotation).
  std::optional<PivotCalibration> feed(const PoseFrame& frame);
  size_t collected() const { return poses_.size(); }

  static constexpr size_t kMinPoses = 30;

 private:
  Tip hand_;
  bool holding_ = false;
  std::vector<Pose> poses_;
};

inline std::optional<PivotCalibration> PivotCollector::feed(const PoseFrame& frame) {
  const DevicePose& d = frame.device(hand_ == Tip::Left ? Device::Left : Device::Right);
  if (d.trigger >= 0.75) {
    if (!holding_) poses_.clear();
    holding_ = true;
    if (d.valid) {
      Pose p;
      p.orientation = d.orientation;
      p.position = d.position;
      poses_.push_back(p);
    }
    return std::nullopt;
  }
  if (holding_ && d.trigger < 0.25) {
    holding_ = false;
    if (poses_.size() >= kMinPoses) return calibrate_pivot(poses_);
  }
  return std::nullopt;
}

}  // namespace caliper::vr
