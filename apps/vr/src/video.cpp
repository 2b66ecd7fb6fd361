// Instruction video decoding with FFmpeg 5.1 (Debian 12 packages).
#include "video.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>

namespace caliper::vr {

struct VideoPlayer::Impl {
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  SwsContext* sws = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  int stream = -1;
  double time_base = 0.0;
  double last_pts = -1.0;    ///< seconds of the frame in image_
  bool pending = false;      ///< a decoded frame waits in `frame` (not shown yet)
  double pending_pts = 0.0;  ///< its time, seconds
  int out_w = 0, out_h = 0;
  std::string path;

  ~Impl() {
    if (sws) sws_freeContext(sws);
    if (frame) av_frame_free(&frame);
    if (packet) av_packet_free(&packet);
    if (codec) avcodec_free_context(&codec);
    if (format) avformat_close_input(&format);
  }
  [[noreturn]] void fail(const std::string& what) const { throw VideoError(path + ": " + what); }

  /// Decodes the next frame into `frame`; false at the end of the stream.
  bool decode_next() {
    while (true) {
      const int r = avcodec_receive_frame(codec, frame);
      if (r == 0) return true;
      if (r == AVERROR_EOF) return false;
      if (r != AVERROR(EAGAIN)) fail("cannot decode a video frame");
      const int rd = av_read_frame(format, packet);
      if (rd < 0) {
        avcodec_send_packet(codec, nullptr);  // flush
        continue;
      }
      if (packet->stream_index == stream) avcodec_send_packet(codec, packet);
      av_packet_unref(packet);
    }
  }
  void rewind() {
    av_seek_frame(format, stream, 0, AVSEEK_FLAG_BACKWARD);
    avcodec_flush_buffers(codec);
  }
};

VideoPlayer::VideoPlayer(const std::string& path, int max_width) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  if (avformat_open_input(&m.format, path.c_str(), nullptr, nullptr) < 0)
    m.fail("cannot open the video file (does it exist?)");
  if (avformat_find_stream_info(m.format, nullptr) < 0)
    m.fail("cannot read the video's stream information");
  const AVCodec* decoder = nullptr;
  m.stream = av_find_best_stream(m.format, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (m.stream < 0 || !decoder) m.fail("has no video stream this FFmpeg can decode");
  AVStream* st = m.format->streams[m.stream];
  m.time_base = av_q2d(st->time_base);
  m.codec = avcodec_alloc_context3(decoder);
  if (!m.codec || avcodec_parameters_to_context(m.codec, st->codecpar) < 0)
    m.fail("cannot set up the decoder");
  m.codec->thread_count = 1;  // deterministic, and the renderer already uses the cores
  if (avcodec_open2(m.codec, decoder, nullptr) < 0) m.fail("cannot open the decoder");
  m.frame = av_frame_alloc();
  m.packet = av_packet_alloc();
  if (m.codec->width <= 0 || m.codec->height <= 0) m.fail("has no frame size");
  m.out_w = std::min(max_width, m.codec->width);
  m.out_h = std::max(1, m.codec->height * m.out_w / m.codec->width);
}

VideoPlayer::~VideoPlayer() = default;

double VideoPlayer::duration() const {
  const Impl& m = *impl_;
  if (m.format->duration > 0) return static_cast<double>(m.format->duration) / AV_TIME_BASE;
  return 0.0;
}

bool VideoPlayer::seek_to(double seconds) {
  Impl& m = *impl_;
  const double length = duration();
  if (length > 0.0) seconds = std::fmod(seconds, length);
  if (m.last_pts >= 0.0 && seconds + 1e-9 < m.last_pts) {  // looped: start again
    m.rewind();
    m.last_pts = -1.0;
    m.pending = false;
  }
  bool changed = false;
  // Show the last frame whose time is at or before `seconds` (the first frame before that).
  while (true) {
    if (!m.pending) {
      if (!m.decode_next()) break;
      const int64_t pts = m.frame->best_effort_timestamp;
      m.pending_pts = pts == AV_NOPTS_VALUE ? std::max(0.0, m.last_pts) + 1.0 / 25.0
                                            : static_cast<double>(pts) * m.time_base;
      m.pending = true;
    }
    if (m.last_pts >= 0.0 && m.pending_pts > seconds + 1e-9) break;
    m.sws = sws_getCachedContext(m.sws, m.frame->width, m.frame->height,
                                 static_cast<AVPixelFormat>(m.frame->format), m.out_w, m.out_h,
                                 AV_PIX_FMT_RGBA, SWS_BILINEAR, nullptr, nullptr, nullptr);
    if (!m.sws) m.fail("cannot convert the frames to RGBA");
    image_.width = m.out_w;
    image_.height = m.out_h;
    image_.rgba.resize(static_cast<size_t>(4) * m.out_w * m.out_h);
    uint8_t* dst[4] = {image_.rgba.data(), nullptr, nullptr, nullptr};
    int dst_stride[4] = {4 * m.out_w, 0, 0, 0};
    sws_scale(m.sws, m.frame->data, m.frame->linesize, 0, m.frame->height, dst, dst_stride);
    m.last_pts = m.pending_pts;
    m.pending = false;
    changed = true;
  }
  if (m.last_pts < 0.0) m.fail("has no decodable frames");
  return changed;
}

}  // namespace caliper::vr
