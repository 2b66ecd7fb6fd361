/// \file panel.hpp
/// The instruction panel as an RGBA image drawn on the CPU (text from the renderer's vector
/// font, rasterised here), uploaded as a texture and shown on a quad in the headset. Redrawn
/// only when its text changes.
#pragma once

#include <string>
#include <vector>

#include "panel_content.hpp"
#include "render/image.hpp"

namespace caliper::vr {

/// Draws the panel into a width x height image (top row first).
render::Image panel_image(const PanelContent& content, int width, int height);

/// Splits `text` into lines no wider than `max_width` pixels at `scale`.
std::vector<std::string> wrap_text(const std::string& text, float scale, float max_width);

/// Fills the triangles (2 floats per vertex, pixels, y down) into `image` with `rgba`.
void fill_triangles(render::Image& image, const std::vector<float>& xy,
                    const unsigned char rgba[4]);

}  // namespace caliper::vr
