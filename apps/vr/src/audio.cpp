// Confirmation tones through OpenAL Soft (Debian libopenal-dev).
#include "audio.hpp"
#include "smpl/constants.hpp"

#include <AL/al.h>
#include <AL/alc.h>

#include <chrono>
#include <cmath>
#include <thread>

namespace caliper::vr {
namespace {

using smpl::kPi;

void check_al(const char* what) {
  const ALenum e = alGetError();
  if (e != AL_NO_ERROR)
    throw AudioError(std::string("OpenAL: ") + what + " failed (error 0x" + std::to_string(e) +
                     ")");
}

class OpenAlAudio final : public Audio {
 public:
  explicit OpenAlAudio(const ToneSpec& spec)
      : samples_(tone_samples(spec)), rate_(spec.sample_rate) {
    device_ = alcOpenDevice(nullptr);
    if (!device_) throw AudioError("no audio device could be opened (OpenAL)");
    context_ = alcCreateContext(device_, nullptr);
    if (!context_ || !alcMakeContextCurrent(context_)) {
      if (context_) alcDestroyContext(context_);
      alcCloseDevice(device_);
      throw AudioError("no OpenAL context could be created");
    }
    alGetError();
    alGenSources(1, &source_);
    check_al("alGenSources");
    const ALCchar* name = alcGetString(device_, ALC_DEVICE_SPECIFIER);
    name_ = name ? name : "OpenAL";
  }
  ~OpenAlAudio() override {
    alSourceStop(source_);
    reclaim();
    alDeleteSources(1, &source_);
    for (ALuint b : free_) alDeleteBuffers(1, &b);
    alcMakeContextCurrent(nullptr);
    alcDestroyContext(context_);
    alcCloseDevice(device_);
  }
  void confirm() override {
    reclaim();
    ALuint buffer = 0;
    if (!free_.empty()) {
      buffer = free_.back();
      free_.pop_back();
    } else {
      alGenBuffers(1, &buffer);
      check_al("alGenBuffers");
    }
    alBufferData(buffer, AL_FORMAT_MONO16, samples_.data(),
                 static_cast<ALsizei>(samples_.size() * sizeof(short)), rate_);
    check_al("alBufferData");
    alSourceQueueBuffers(source_, 1, &buffer);
    check_al("alSourceQueueBuffers");
    ALint state = 0;
    alGetSourcei(source_, AL_SOURCE_STATE, &state);
    if (state != AL_PLAYING) alSourcePlay(source_);
    check_al("alSourcePlay");
  }
  void drain(double timeout_s) override {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      ALint state = 0;
      alGetSourcei(source_, AL_SOURCE_STATE, &state);
      if (state != AL_PLAYING) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    // Let the backend mix out its last period before the device closes.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::string description() const override { return "OpenAL (" + name_ + ")"; }

 private:
  void reclaim() {
    ALint done = 0;
    alGetSourcei(source_, AL_BUFFERS_PROCESSED, &done);
    while (done-- > 0) {
      ALuint b = 0;
      alSourceUnqueueBuffers(source_, 1, &b);
      free_.push_back(b);
    }
  }
  std::vector<short> samples_;
  int rate_;
  ALCdevice* device_ = nullptr;
  ALCcontext* context_ = nullptr;
  ALuint source_ = 0;
  std::vector<ALuint> free_;
  std::string name_;
};

}  // namespace

std::vector<short> tone_samples(const ToneSpec& spec) {
  const size_t n_tone = static_cast<size_t>(std::lround(spec.duration * spec.sample_rate));
  const size_t n_gap = static_cast<size_t>(std::lround(spec.gap * spec.sample_rate));
  const size_t ramp = std::max<size_t>(1, n_tone / 8);
  std::vector<short> s(n_tone + n_gap, 0);
  for (size_t i = 0; i < n_tone; ++i) {
    double env = 1.0;
    if (i < ramp)
      env = 0.5 - 0.5 * std::cos(kPi * static_cast<double>(i) / static_cast<double>(ramp));
    else if (i >= n_tone - ramp)
      env = 0.5 -
            0.5 * std::cos(kPi * static_cast<double>(n_tone - 1 - i) / static_cast<double>(ramp));
    const double v =
        spec.amplitude * env *
        std::sin(2.0 * kPi * spec.frequency * static_cast<double>(i) / spec.sample_rate);
    s[i] = static_cast<short>(std::lround(v * 32767.0));
  }
  return s;
}

std::unique_ptr<Audio> make_openal_audio(const ToneSpec& spec) {
  return std::make_unique<OpenAlAudio>(spec);
}

}  // namespace caliper::vr
