/// \file video.hpp
/// Instruction videos on the panel: FFmpeg (libavformat, libavcodec, libswscale) decodes a file
/// into RGBA frames for the renderer's textured quad. Playback follows the session clock and
/// loops, so that a replay shows the same frame at the same time on every run.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "render/image.hpp"

namespace caliper::vr {

class VideoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class VideoPlayer {
 public:
  /// Opens `path` (any container and codec FFmpeg knows). Throws VideoError naming the file.
  explicit VideoPlayer(const std::string& path, int max_width = 512);
  ~VideoPlayer();
  VideoPlayer(const VideoPlayer&) = delete;
  VideoPlayer& operator=(const VideoPlayer&) = delete;

  /// Advances to the frame shown at `seconds` since the start (looping). Returns true when the
  /// image changed.
  bool seek_to(double seconds);
  /// The current frame, RGBA (empty before the first frame).
  const render::Image& image() const { return image_; }
  double duration() const;  ///< seconds (0 when unknown)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  render::Image image_;
};

}  // namespace caliper::vr
