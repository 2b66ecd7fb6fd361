/// \file text.hpp
/// Text as triangles, from the public-domain stb_easy_font vector font (Debian libstb-dev,
/// header only; no font file is needed at run time).
#pragma once

#include <string>
#include <vector>

namespace caliper::render {

/// 2D triangles of `text` with its top-left corner at (x, y) pixels (y grows downwards),
/// glyph height 7 * scale pixels: appends 2 floats per vertex, 3 vertices per triangle.
void text_triangles(const std::string& text, float x, float y, float scale,
                    std::vector<float>& out_xy);

/// Width and height in pixels of `text` at `scale` (multi-line text uses '\n').
float text_width(const std::string& text, float scale);
float text_height(const std::string& text, float scale);

/// A label's box on the screen in pixels (y grows downwards). `fixed` boxes never move.
struct TextBox {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool fixed = false;
};

/// Moves labels apart so that no two boxes overlap: every box that is not `fixed` is taken in
/// order and moved straight down, below each fixed or earlier box it overlaps, until at least
/// `gap` pixels separate it from all of them. Boxes that overlap nothing stay where they are;
/// fixed boxes may still overlap each other. At most one move per earlier box, so O(n^2).
void separate_boxes(std::vector<TextBox>& boxes, float gap);

}  // namespace caliper::render
