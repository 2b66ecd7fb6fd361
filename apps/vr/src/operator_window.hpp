/// \file operator_window.hpp
/// The operator's desktop window (ImGui on the GLFW window): it mirrors the headset's left eye and
/// offers Start, Redo, Skip, the weight and the sex. Used live (next to OpenXR) and in replay
/// with `--operator-window` (under Xvfb in CI, which also renders docs/images/vr-operator.png).
#pragma once

#include <optional>
#include <vector>

#include "render/glfw_context.hpp"
#include "render/renderer.hpp"
#include "vr_app.hpp"

namespace caliper::vr {

class OperatorWindow {
 public:
  /// Sets up ImGui for `window` (whose context must be current).
  explicit OperatorWindow(render::GlfwWindowContext& window);
  ~OperatorWindow();
  OperatorWindow(const OperatorWindow&) = delete;
  OperatorWindow& operator=(const OperatorWindow&) = delete;

  /// Draws the mirror of `scene` from the head and the controls into the window's back buffer
  /// (the caller swaps); returns the commands the operator clicked or typed this frame.
  std::vector<OperatorCommand> frame(VrApp& app, render::Renderer& renderer,
                                     const render::Scene& scene);

 private:
  render::GlfwWindowContext& window_;
  double weight_ = 70.0;
  int sex_ = -1;
  std::optional<TypedFields> synced_;  ///< the session's values last copied into the fields
};

}  // namespace caliper::vr
