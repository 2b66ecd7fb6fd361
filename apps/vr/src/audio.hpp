/// \file audio.hpp
/// Confirmation tones through OpenAL Soft. The tone samples are generated here (a short sine
/// burst with raised-cosine edges). Tones are queued on one streaming source, each followed by
/// a gap of silence, so that tones triggered faster than real time (replay) still come out one
/// after the other and can be counted in the output of OpenAL's `wave` backend.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "smpl/non_copyable.hpp"

namespace caliper::vr {

class AudioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Tone parameters.
struct ToneSpec {
  double frequency = 880.0;  ///< Hz
  double duration = 0.08;    ///< s of tone
  double gap = 0.07;         ///< s of silence queued after it
  double amplitude = 0.5;    ///< of full scale
  int sample_rate = 44100;
};

/// The tone as mono 16-bit samples followed by the gap (what is queued per confirmation).
std::vector<short> tone_samples(const ToneSpec& spec);

class Audio : smpl::NonCopyable {
 public:
  virtual ~Audio() = default;
  /// Plays one confirmation tone (queued after any that are still playing).
  virtual void confirm() = 0;
  /// Blocks until every queued tone has played (end of a replay), at most `timeout_s`.
  virtual void drain(double /*timeout_s*/) {}
  virtual std::string description() const = 0;
};

/// No sound (--no-audio, or when no OpenAL device opens).
class SilentAudio final : public Audio {
 public:
  void confirm() override { ++count_; }
  std::string description() const override { return "no audio"; }
  int count() const { return count_; }

 private:
  int count_ = 0;
};

/// Opens the default OpenAL device (ALSOFT_DRIVERS / alsoft.conf choose the backend). Throws
/// AudioError when no device or context can be opened.
std::unique_ptr<Audio> make_openal_audio(const ToneSpec& spec = {});

}  // namespace caliper::vr
