// PNG input/output with stb_image / stb_image_write (Debian libstb-dev, linked from libstb).
#include "render/image.hpp"

#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cstdlib>

#include "render/gl_functions.hpp"
#include "smpl/atomic_file.hpp"

namespace caliper::render {

void write_png(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != 4 * static_cast<size_t>(image.width) * image.height) {
    throw RenderError("write_png " + path + ": the image is empty or its size is inconsistent");
  }
  bool opaque = true;
  for (size_t i = 3; i < image.rgba.size(); i += 4) opaque = opaque && image.rgba[i] == 255;
  // Encoded in memory, then written atomically (smpl/atomic_file.hpp).
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<size_t>(size));
  };
  int ok = 0;
  if (opaque) {
    std::vector<std::uint8_t> rgb(3 * static_cast<size_t>(image.width) * image.height);
    for (size_t p = 0, n = rgb.size() / 3; p < n; ++p) {
      rgb[3 * p] = image.rgba[4 * p];
      rgb[3 * p + 1] = image.rgba[4 * p + 1];
      rgb[3 * p + 2] = image.rgba[4 * p + 2];
    }
    ok = stbi_write_png_to_func(append, &png, image.width, image.height, 3, rgb.data(),
                                image.width * 3);
  } else {
    ok = stbi_write_png_to_func(append, &png, image.width, image.height, 4, image.rgba.data(),
                                image.width * 4);
  }
  if (!ok) throw RenderError("could not encode PNG " + path);
  smpl::write_file_atomic(path, png);
}

Image read_png(const std::string& path) {
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 4);
  if (data == nullptr) {
    throw RenderError("could not read PNG " + path + ": " + stbi_failure_reason());
  }
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(data, data + 4 * static_cast<size_t>(w) * h);
  stbi_image_free(data);
  return img;
}

ImageDifference compare_images(const Image& a, const Image& b) {
  ImageDifference d;
  d.same_size = a.width == b.width && a.height == b.height && a.rgba.size() == b.rgba.size();
  if (!d.same_size || a.rgba.empty()) return d;
  double sum = 0;
  size_t over = 0;
  const size_t pixels = a.rgba.size() / 4;
  for (size_t p = 0; p < pixels; ++p) {
    int pixel_max = 0;
    for (int c = 0; c < 3; ++c) {
      const int diff = std::abs(int(a.rgba[4 * p + c]) - int(b.rgba[4 * p + c]));
      pixel_max = std::max(pixel_max, diff);
      sum += diff;
    }
    d.max_abs = std::max(d.max_abs, pixel_max);
    if (pixel_max > 16) ++over;
  }
  d.mean_abs = sum / static_cast<double>(3 * pixels);
  d.fraction_over = static_cast<double>(over) / static_cast<double>(pixels);
  return d;
}

}  // namespace caliper::render
