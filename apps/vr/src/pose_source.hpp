/// \file pose_source.hpp
/// Where the app's tracking comes from, behind one small interface: OpenXR (openxr_system.hpp),
/// a recorded pose log (ReplayPoseSource), or either of them wrapped by a recorder
/// (RecordingPoseSource, `--record FILE`).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "caliper/pose_log.hpp"
#include "caliper/protocol_file.hpp"

namespace caliper::vr {

class PoseSource {
 public:
  virtual ~PoseSource() = default;
  PoseSource() = default;
  PoseSource(const PoseSource&) = delete;
  PoseSource& operator=(const PoseSource&) = delete;

  /// The next frame's poses, or std::nullopt when the source has ended (end of the log, or the
  /// runtime asked the app to quit).
  virtual std::optional<PoseFrame> next_frame() = 0;
  /// The active interaction profile (for the tip offsets), e.g.
  /// "/interaction_profiles/htc/vive_controller".
  virtual std::string interaction_profile() const = 0;
  /// Vibrates a controller (no-op without hardware).
  virtual void haptic_pulse(Tip /*hand*/, double /*amplitude*/, double /*seconds*/) {}
  /// The session role recorded in the source ("self" or "operator"; "" when unknown).
  virtual std::string role() const { return ""; }
};

/// Replays a pose log frame by frame (deterministic; no clock involved).
class ReplayPoseSource final : public PoseSource {
 public:
  explicit ReplayPoseSource(PoseLog log) : log_(std::move(log)) {}
  std::optional<PoseFrame> next_frame() override {
    if (next_ >= log_.frames.size()) return std::nullopt;
    return log_.frames[next_++];
  }
  std::string interaction_profile() const override { return log_.header.interaction_profile; }
  std::string role() const override { return log_.header.role; }
  const PoseLog& log() const { return log_; }
  size_t position() const { return next_; }

 private:
  PoseLog log_;
  size_t next_ = 0;
};

/// Wraps another source and appends every frame it returns to a pose log (flushed per frame).
class RecordingPoseSource final : public PoseSource {
 public:
  RecordingPoseSource(std::unique_ptr<PoseSource> inner, const std::string& path,
                      PoseLogHeader header)
      : inner_(std::move(inner)), writer_(path, header) {}
  std::optional<PoseFrame> next_frame() override {
    std::optional<PoseFrame> f = inner_->next_frame();
    if (f) {
      for (const OperatorCommand& c : pending_) f->commands.push_back(c);
      pending_.clear();
      writer_.write(*f);
    }
    return f;
  }
  std::string interaction_profile() const override { return inner_->interaction_profile(); }
  void haptic_pulse(Tip hand, double amplitude, double seconds) override {
    inner_->haptic_pulse(hand, amplitude, seconds);
  }
  std::string role() const override { return inner_->role(); }
  /// Commands issued outside the pose stream (operator window) are recorded with the next frame.
  void record_command(const OperatorCommand& c) { pending_.push_back(c); }
  PoseSource& inner() { return *inner_; }

 private:
  std::unique_ptr<PoseSource> inner_;
  PoseLogWriter writer_;
  std::vector<OperatorCommand> pending_;
};

}  // namespace caliper::vr
