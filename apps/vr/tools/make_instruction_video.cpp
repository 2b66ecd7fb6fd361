// Writes the small instruction video of the arm-span step (assets/media/arm-span.mp4): a figure
// raising both arms to the sides while two controllers move to the fingertips, drawn on the CPU
// and encoded with libavcodec's MPEG-4 part 2 encoder (bit-exact, single thread, so the file is
// the same on every run).   Usage: caliper-vr-make-video OUT.mp4
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

#include "panel.hpp"
#include "render/text.hpp"
#include "smpl/constants.hpp"

namespace {

constexpr int kWidth = 192, kHeight = 128, kFps = 12, kFrames = 36;
using smpl::kPi;

void quad(caliper::render::Image& img, double ax, double ay, double bx, double by,
          double half_width, const unsigned char rgba[4]) {
  const double dx = bx - ax, dy = by - ay, len = std::max(1e-9, std::hypot(dx, dy));
  const double nx = -dy / len * half_width, ny = dx / len * half_width;
  const std::vector<float> t = {float(ax + nx), float(ay + ny), float(bx + nx), float(by + ny),
                                float(bx - nx), float(by - ny), float(ax + nx), float(ay + ny),
                                float(bx - nx), float(by - ny), float(ax - nx), float(ay - ny)};
  caliper::vr::fill_triangles(img, t, rgba);
}

void disc(caliper::render::Image& img, double cx, double cy, double r,
          const unsigned char rgba[4]) {
  std::vector<float> t;
  for (int i = 0; i < 24; ++i) {
    const double a0 = 2 * kPi * i / 24, a1 = 2 * kPi * (i + 1) / 24;
    t.insert(t.end(),
             {float(cx), float(cy), float(cx + r * std::cos(a0)), float(cy + r * std::sin(a0)),
              float(cx + r * std::cos(a1)), float(cy + r * std::sin(a1))});
  }
  caliper::vr::fill_triangles(img, t, rgba);
}

caliper::render::Image frame_image(int i) {
  caliper::render::Image img;
  img.width = kWidth;
  img.height = kHeight;
  img.rgba.assign(static_cast<size_t>(4) * kWidth * kHeight, 255);
  for (size_t p = 0; p < img.rgba.size(); p += 4) {
    img.rgba[p] = 236;
    img.rgba[p + 1] = 240;
    img.rgba[p + 2] = 246;
  }
  const unsigned char body[4] = {120, 124, 140, 255}, ctl[4] = {40, 40, 50, 255},
                      target[4] = {220, 30, 120, 255}, text[4] = {30, 70, 150, 255};
  std::vector<float> tri;
  caliper::render::text_triangles("Arm span", 6, 4, 1.6f, tri);
  caliper::vr::fill_triangles(img, tri, text);
  const double t = static_cast<double>(i) / (kFrames - 1);
  const double lift = std::min(1.0, t / 0.6);
  const double s = lift * lift * (3 - 2 * lift);
  const double cx = kWidth / 2.0, shoulder_y = 52.0, arm = 46.0;
  disc(img, cx, 32, 9, body);                   // head
  quad(img, cx, 44, cx, 88, 10, body);          // torso
  quad(img, cx - 5, 88, cx - 9, 122, 4, body);  // legs
  quad(img, cx + 5, 88, cx + 9, 122, 4, body);
  for (int side : {-1, 1}) {
    const double angle = (1.0 - s) * 1.35;  // radians below the horizontal
    const double hx = cx + side * (10 + arm * std::cos(angle)),
                 hy = shoulder_y + arm * std::sin(angle);
    quad(img, cx + side * 10, shoulder_y, hx, hy, 3, body);
    disc(img, cx + side * (10 + arm), shoulder_y, 3.5, target);  // where the tips go
    quad(img, hx, hy, hx, hy + 12, 3, ctl);                      // the controller in the hand
  }
  return img;
}

void check(int r, const char* what) {
  if (r < 0) throw std::runtime_error(std::string("FFmpeg: ") + what + " failed");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: caliper-vr-make-video OUT.mp4\n");
    return 2;
  }
  try {
    const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
    if (!codec) throw std::runtime_error("no MPEG-4 encoder in this FFmpeg");
    AVFormatContext* fmt = nullptr;
    check(avformat_alloc_output_context2(&fmt, nullptr, nullptr, argv[1]), "output context");
    AVStream* st = avformat_new_stream(fmt, nullptr);
    AVCodecContext* c = avcodec_alloc_context3(codec);
    c->width = kWidth;
    c->height = kHeight;
    c->time_base = {1, kFps};
    c->framerate = {kFps, 1};
    c->pix_fmt = AV_PIX_FMT_YUV420P;
    c->gop_size = kFps;
    c->bit_rate = 150000;
    c->thread_count = 1;
    c->flags |= AV_CODEC_FLAG_BITEXACT;
    if (fmt->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    check(avcodec_open2(c, codec, nullptr), "opening the encoder");
    check(avcodec_parameters_from_context(st->codecpar, c), "stream parameters");
    st->time_base = c->time_base;
    fmt->flags |= AVFMT_FLAG_BITEXACT;
    check(avio_open(&fmt->pb, argv[1], AVIO_FLAG_WRITE), "opening the output file");
    check(avformat_write_header(fmt, nullptr), "writing the header");
    SwsContext* sws =
        sws_getContext(kWidth, kHeight, AV_PIX_FMT_RGBA, kWidth, kHeight, AV_PIX_FMT_YUV420P,
                       SWS_BILINEAR | SWS_BITEXACT, nullptr, nullptr, nullptr);
    AVFrame* frame = av_frame_alloc();
    frame->format = AV_PIX_FMT_YUV420P;
    frame->width = kWidth;
    frame->height = kHeight;
    check(av_frame_get_buffer(frame, 0), "frame buffer");
    AVPacket* pkt = av_packet_alloc();
    const auto drain = [&]() {
      while (avcodec_receive_packet(c, pkt) == 0) {
        av_packet_rescale_ts(pkt, c->time_base, st->time_base);
        pkt->stream_index = st->index;
        check(av_interleaved_write_frame(fmt, pkt), "writing a packet");
      }
    };
    for (int i = 0; i < kFrames; ++i) {
      const caliper::render::Image img = frame_image(i);
      check(av_frame_make_writable(frame), "frame");
      const uint8_t* src[1] = {img.rgba.data()};
      const int stride[1] = {4 * kWidth};
      sws_scale(sws, src, stride, 0, kHeight, frame->data, frame->linesize);
      frame->pts = i;
      check(avcodec_send_frame(c, frame), "encoding a frame");
      drain();
    }
    check(avcodec_send_frame(c, nullptr), "flushing the encoder");
    drain();
    check(av_write_trailer(fmt), "writing the trailer");
    avio_closep(&fmt->pb);
    av_packet_free(&pkt);
    av_frame_free(&frame);
    sws_freeContext(sws);
    avcodec_free_context(&c);
    avformat_free_context(fmt);
    std::printf("wrote %s (%dx%d, %d frames at %d fps)\n", argv[1], kWidth, kHeight, kFrames, kFps);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "caliper-vr-make-video: %s\n", e.what());
    return 1;
  }
}
