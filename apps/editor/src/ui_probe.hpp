/// \file ui_probe.hpp
/// A record of the interactive items of the last frame (label, screen rectangle, enabled), so
/// that tests can press every button through ImGui's own input (mouse position and buttons,
/// keys) without knowing the layout. Debian's Dear ImGui 1.86 has no test engine hooks.
#pragma once

#include <imgui.h>

#include <string>
#include <vector>

namespace caliper::editor {

/// One interactive item as drawn in the last frame.
struct UiItem {
  std::string label;   ///< the visible label (or "##id" for unlabelled fields)
  std::string window;  ///< the ImGui window it belongs to
  ImVec2 min, max;     ///< screen rectangle (pixels from the top-left)
  bool enabled = true;
  bool visible = true;  ///< inside its window's visible (scrolled) area
};

class UiProbe {
 public:
  /// Records the last item (call right after the widget).
  void track(const char* label);
  /// Called by the frame start: forgets the previous frame's items.
  void clear() { items_.clear(); }
  const std::vector<UiItem>& items() const { return items_; }

 private:
  std::vector<UiItem> items_;
};

}  // namespace caliper::editor
