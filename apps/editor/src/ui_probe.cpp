// UiProbe: the last item's rectangle, window and enabled state (ImGui internals, read only).
#include "ui_probe.hpp"

#include <imgui_internal.h>

namespace caliper::editor {

void UiProbe::track(const char* label) {
  const ImGuiContext& g = *ImGui::GetCurrentContext();
  const ImGuiWindow* w = g.CurrentWindow;
  UiItem item;
  item.label = label;
  item.window = w != nullptr && w->Name != nullptr ? w->Name : "";
  item.min = g.LastItemData.Rect.Min;
  item.max = g.LastItemData.Rect.Max;
  item.enabled = (g.LastItemData.InFlags & ImGuiItemFlags_Disabled) == 0;
  if (w != nullptr) {
    const ImVec2 c((item.min.x + item.max.x) / 2, (item.min.y + item.max.y) / 2);
    item.visible = w->ClipRect.Contains(c);
  }
  items_.push_back(item);
}

}  // namespace caliper::editor
