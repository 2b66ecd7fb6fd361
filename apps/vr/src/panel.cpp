#include "panel.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "render/text.hpp"

namespace caliper::vr {

std::vector<std::string> wrap_text(const std::string& text, float scale, float max_width) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    const std::string candidate = line.empty() ? word : line + " " + word;
    if (!line.empty() && render::text_width(candidate, scale) > max_width) {
      lines.push_back(line);
      line = word;
    } else {
      line = candidate;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

void fill_triangles(render::Image& image, const std::vector<float>& xy,
                    const unsigned char rgba[4]) {
  for (size_t t = 0; t + 6 <= xy.size(); t += 6) {
    const float x0 = xy[t], y0 = xy[t + 1], x1 = xy[t + 2], y1 = xy[t + 3], x2 = xy[t + 4],
                y2 = xy[t + 5];
    const float area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if (std::abs(area) < 1e-6f) continue;
    const int xmin = std::max(0, static_cast<int>(std::floor(std::min({x0, x1, x2}))));
    const int xmax = std::min(image.width - 1, static_cast<int>(std::ceil(std::max({x0, x1, x2}))));
    const int ymin = std::max(0, static_cast<int>(std::floor(std::min({y0, y1, y2}))));
    const int ymax =
        std::min(image.height - 1, static_cast<int>(std::ceil(std::max({y0, y1, y2}))));
    for (int y = ymin; y <= ymax; ++y) {
      for (int x = xmin; x <= xmax; ++x) {
        const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
        const float w0 = ((x1 - px) * (y2 - py) - (x2 - px) * (y1 - py)) / area;
        const float w1 = ((x2 - px) * (y0 - py) - (x0 - px) * (y2 - py)) / area;
        const float w2 = 1.0f - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        std::copy(rgba, rgba + 4, image.pixel(x, y));
      }
    }
  }
}

render::Image panel_image(const PanelContent& c, int width, int height) {
  render::Image img;
  img.width = width;
  img.height = height;
  img.rgba.resize(static_cast<size_t>(4) * width * height);
  const unsigned char bg[4] = {static_cast<unsigned char>(c.highlight ? 214 : 244),
                               static_cast<unsigned char>(c.highlight ? 242 : 244),
                               static_cast<unsigned char>(c.highlight ? 214 : 248), 255};
  for (size_t i = 0; i < img.rgba.size(); i += 4) std::copy(bg, bg + 4, &img.rgba[i]);
  // A frame.
  const unsigned char frame[4] = {60, 90, 140, 255};
  for (int x = 0; x < width; ++x)
    for (int k = 0; k < 4; ++k) {
      std::copy(frame, frame + 4, img.pixel(x, k));
      std::copy(frame, frame + 4, img.pixel(x, height - 1 - k));
    }
  for (int y = 0; y < height; ++y)
    for (int k = 0; k < 4; ++k) {
      std::copy(frame, frame + 4, img.pixel(k, y));
      std::copy(frame, frame + 4, img.pixel(width - 1 - k, y));
    }
  const float margin = 20.0f * static_cast<float>(width) / 512.0f;
  const float text_w = static_cast<float>(width) - 2 * margin;
  // Shrink the text until everything fits (long results lists on the final panel).
  float unit = static_cast<float>(width) / 512.0f;
  const auto layout_height = [&](float u) {
    float h = margin;
    const auto add = [&](const std::string& t, float sc) {
      h += render::text_height(t, sc) + 4.0f * sc;
    };
    if (!c.title.empty()) add(c.title, 4.0f * u);
    h += 12.0f * u;
    for (const std::string& l : wrap_text(c.body, 2.4f * u, text_w)) add(l, 2.4f * u);
    for (const std::string& l : c.lines) add(l, 2.2f * u);
    for (const std::string& l : wrap_text(c.footer, 2.2f * u, text_w)) add(l, 2.2f * u);
    return h + margin;
  };
  while (unit > 0.3f && layout_height(unit) > static_cast<float>(height)) unit *= 0.9f;
  float y = margin;
  std::vector<float> tri;
  const unsigned char dark[4] = {25, 30, 40, 255};
  const unsigned char accent[4] = {30, 70, 150, 255};
  const unsigned char grey[4] = {80, 80, 90, 255};
  const auto draw = [&](const std::string& text, float scale, const unsigned char* colour) {
    tri.clear();
    render::text_triangles(text, margin, y, scale, tri);
    fill_triangles(img, tri, colour);
    y += render::text_height(text, scale) + 4.0f * scale;
  };
  if (!c.title.empty()) draw(c.title, 4.0f * unit, accent);
  y += 6.0f * unit;
  for (const std::string& l : wrap_text(c.body, 2.4f * unit, text_w)) draw(l, 2.4f * unit, dark);
  y += 6.0f * unit;
  for (const std::string& l : c.lines) draw(l, 2.2f * unit, dark);
  if (!c.footer.empty()) {
    const std::vector<std::string> f = wrap_text(c.footer, 2.2f * unit, text_w);
    float fh = 0.0f;
    for (const std::string& l : f) fh += render::text_height(l, 2.2f * unit) + 8.8f * unit;
    y = std::max(y, static_cast<float>(height) - margin - fh);
    for (const std::string& l : f) draw(l, 2.2f * unit, grey);
  }
  return img;
}

}  // namespace caliper::vr
