/// \file pose_source.hpp
/// Where the app's tracking comes from, behind one small interface: OpenXR (openxr_system.hpp),
/// a recorded pose log (ReplayPoseSource), or either of them wrapped by a recorder
/// (RecordingPoseSource, `--record FILE`).
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "caliper/pose_log.hpp"
#include "caliper/protocol_file.hpp"
#include "smpl/non_copyable.hpp"

namespace caliper::vr {

/// The pose source was lost in the middle of a session (the OpenXR runtime lost the instance or
/// the session, or a recording says it was): treated like its end (summary, exit 3, the
/// `--resume` command). The message says what happened in plain words.
class PoseSourceLost : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PoseSource : smpl::NonCopyable {
 public:
  virtual ~PoseSource() = default;

  /// The next frame's poses, or std::nullopt when the source has ended (end of the log, or the
  /// runtime asked the app to quit). Throws PoseSourceLost when the source was lost.
  virtual std::optional<PoseFrame> next_frame() = 0;
  /// The active interaction profile (for the tip offsets), e.g.
  /// "/interaction_profiles/htc/vive_controller"; "" while the runtime has not reported one.
  /// May change between frames (the runtime binds the controllers some frames after the start).
  virtual std::string interaction_profile() const = 0;
  /// Frames per second of the source (live: the runtime's display rate; 0 = unknown).
  virtual double frame_rate() const { return 0.0; }
  /// Vibrates a controller (no-op without hardware).
  virtual void haptic_pulse(Tip /*hand*/, double /*amplitude*/, double /*seconds*/) {}
  /// The session role recorded in the source ("self" or "operator"; "" when unknown).
  virtual std::string role() const { return ""; }
};

/// Replays a pose log frame by frame (deterministic; no clock involved).
class ReplayPoseSource final : public PoseSource {
 public:
  explicit ReplayPoseSource(PoseLog log)
      : log_(std::move(log)), profile_(log_.header.interaction_profile) {}
  /// Frames in order; a frame naming a new interaction profile changes interaction_profile()
  /// from that frame on. At the end of a log whose recording was lost: throws PoseSourceLost.
  std::optional<PoseFrame> next_frame() override {
    if (next_ >= log_.frames.size()) {
      if (!log_.lost.empty()) throw PoseSourceLost(log_.lost);
      return std::nullopt;
    }
    const PoseFrame& f = log_.frames[next_++];
    if (!f.interaction_profile.empty()) profile_ = f.interaction_profile;
    return f;
  }
  std::string interaction_profile() const override { return profile_; }
  double frame_rate() const override { return log_.header.frame_rate; }
  std::string role() const override { return log_.header.role; }
  const PoseLog& log() const { return log_; }
  size_t position() const { return next_; }

 private:
  PoseLog log_;
  std::string profile_;
  size_t next_ = 0;
};

/// Wraps another source and appends every frame it returns to a pose log (flushed per frame).
/// The header is written with the first frame, when the source knows its frame rate (and, if
/// the runtime has reported it by then, the interaction profile); later profile changes are
/// recorded on the frame where they happen, and a lost source as the log's `lost` line, so that
/// the replay of a live recording sees what the live session saw.
class RecordingPoseSource final : public PoseSource {
 public:
  /// `header`: role, source, typed values; profile and frame rate are taken from `inner` when
  /// the first frame arrives. Nothing is written before it.
  RecordingPoseSource(std::unique_ptr<PoseSource> inner, std::string path, PoseLogHeader header)
      : inner_(std::move(inner)), path_(std::move(path)), header_(std::move(header)) {}
  std::optional<PoseFrame> next_frame() override {
    std::optional<PoseFrame> f;
    try {
      f = inner_->next_frame();
    } catch (const PoseSourceLost& e) {
      mark_lost(e.what());
      throw;
    }
    if (f) {
      const std::string profile = inner_->interaction_profile();
      if (!writer_) {
        header_.interaction_profile = profile;
        if (inner_->frame_rate() > 0.0) header_.frame_rate = inner_->frame_rate();
        writer_.emplace(path_, header_);
      } else if (profile != header_.interaction_profile) {
        f->interaction_profile = profile;
      }
      header_.interaction_profile = profile;  // the profile in force from here on
      for (const OperatorCommand& c : pending_) f->commands.push_back(c);
      pending_.clear();
      writer_->write(*f);
    }
    return f;
  }
  std::string interaction_profile() const override { return inner_->interaction_profile(); }
  double frame_rate() const override { return inner_->frame_rate(); }
  void haptic_pulse(Tip hand, double amplitude, double seconds) override {
    inner_->haptic_pulse(hand, amplitude, seconds);
  }
  std::string role() const override { return inner_->role(); }
  /// Records that the source was lost outside next_frame() (e.g. while submitting a frame);
  /// no-op when it is already recorded or nothing was recorded yet.
  void mark_lost(const std::string& reason) {
    if (writer_ && !lost_) writer_->write_lost(reason);
    lost_ = true;
  }
  /// Commands issued outside the pose stream (operator window) are recorded with the next frame.
  void record_command(const OperatorCommand& c) { pending_.push_back(c); }
  PoseSource& inner() { return *inner_; }

 private:
  std::unique_ptr<PoseSource> inner_;
  std::string path_;
  PoseLogHeader header_;
  std::optional<PoseLogWriter> writer_;
  std::vector<OperatorCommand> pending_;
  bool lost_ = false;
};

}  // namespace caliper::vr
