// Text rendering with stb_easy_font (public domain, Debian libstb-dev).
#include "render/text.hpp"

#include <algorithm>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wcast-align"
#endif
#include <stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace caliper::render {

namespace {
std::string printable(const std::string& text) {
  std::string s = text;
  for (char& c : s) {
    if (c != '\n' && (c < 32 || c > 126)) c = '?';
  }
  return s;
}
}  // namespace

void text_triangles(const std::string& text, float x, float y, float scale,
                    std::vector<float>& out_xy) {
  std::string s = printable(text);
  // stb_easy_font writes 4 vertices of 16 bytes per quad; ~270 bytes per character is enough.
  std::vector<char> buffer(std::max<size_t>(1024, s.size() * 300));
  const int quads =
      stb_easy_font_print(0, 0, s.data(), nullptr, buffer.data(), static_cast<int>(buffer.size()));
  auto vx = [&](int q, int k) {
    const float* v =
        reinterpret_cast<const float*>(buffer.data() + static_cast<size_t>(4 * q + k) * 16);
    return std::pair<float, float>(x + v[0] * scale, y + v[1] * scale);
  };
  out_xy.reserve(out_xy.size() + static_cast<size_t>(quads) * 12);
  for (int q = 0; q < quads; ++q) {
    const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int k : order) {
      auto p = vx(q, k);
      out_xy.push_back(p.first);
      out_xy.push_back(p.second);
    }
  }
}

float text_width(const std::string& text, float scale) {
  std::string s = printable(text);
  return static_cast<float>(stb_easy_font_width(s.data())) * scale;
}

float text_height(const std::string& text, float scale) {
  std::string s = printable(text);
  return static_cast<float>(stb_easy_font_height(s.data())) * scale;
}

void separate_boxes(std::vector<TextBox>& boxes, float gap) {
  std::vector<size_t> placed;
  for (size_t i = 0; i < boxes.size(); ++i) {
    if (boxes[i].fixed) placed.push_back(i);
  }
  auto too_close = [gap](const TextBox& a, const TextBox& b) {
    return a.x0 < b.x1 + gap && b.x0 < a.x1 + gap && a.y0 < b.y1 + gap && b.y0 < a.y1 + gap;
  };
  for (size_t i = 0; i < boxes.size(); ++i) {
    if (boxes[i].fixed) continue;
    TextBox& b = boxes[i];
    // Each move puts b below the box it met, which it then never meets again: this ends after
    // at most placed.size() moves.
    for (bool moved = true; moved;) {
      moved = false;
      for (size_t j : placed) {
        if (!too_close(b, boxes[j])) continue;
        const float height = b.y1 - b.y0;
        b.y0 = boxes[j].y1 + gap;  // exactly the bound too_close() tests against
        b.y1 = b.y0 + height;
        moved = true;
      }
    }
    placed.push_back(i);
  }
}

}  // namespace caliper::render
