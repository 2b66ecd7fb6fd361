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

}  // namespace caliper::render
