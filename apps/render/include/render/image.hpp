/// \file image.hpp
/// RGBA8 images, PNG input/output (stb_image / stb_image_write from Debian's libstb) and the
/// image comparison used by the golden-image tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace caliper::render {

/// width x height RGBA8 pixels, row-major, top row first.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  ///< 4 * width * height bytes

  std::uint8_t* pixel(int x, int y) { return &rgba[4 * (static_cast<size_t>(y) * width + x)]; }
  const std::uint8_t* pixel(int x, int y) const {
    return &rgba[4 * (static_cast<size_t>(y) * width + x)];
  }
};

/// Writes a PNG (RGB when every alpha is 255, otherwise RGBA) atomically
/// (smpl::write_file_atomic). Throws RenderError for an inconsistent image and smpl::WriteError
/// naming the path when it cannot be written (the previous file is then unchanged).
void write_png(const Image& image, const std::string& path);

/// Reads a PNG as RGBA. Throws RenderError naming the path when it is missing or not a PNG.
Image read_png(const std::string& path);

/// Per-channel absolute differences of two images of the same size (0..255).
struct ImageDifference {
  bool same_size = false;
  int max_abs = 0;           ///< largest channel difference over all pixels (RGB only)
  double mean_abs = 0.0;     ///< mean channel difference over all pixels (RGB only)
  double fraction_over = 0;  ///< fraction of pixels whose largest channel difference is > 16
};

/// Compares RGB channels of `a` and `b`.
ImageDifference compare_images(const Image& a, const Image& b);

}  // namespace caliper::render
