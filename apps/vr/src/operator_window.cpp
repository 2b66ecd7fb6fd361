#include "operator_window.hpp"

#include <imgui.h>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

namespace caliper::vr {

OperatorWindow::OperatorWindow(render::GlfwWindowContext& w) : window_(w) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui_ImplGlfw_InitForOpenGL(w.window(), true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
}

OperatorWindow::~OperatorWindow() {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

std::vector<OperatorCommand> OperatorWindow::frame(VrApp& app, render::Renderer& renderer,
                                                   const render::Scene& scene) {
  std::vector<OperatorCommand> out;
  window_.make_current();
  const int w = window_.width(), h = window_.height();
  if (app.body_ik() && app.embodiment().frames > 0) {
    // The driven avatar from outside, head included.
    render::Scene outside;
    app.build_scene(outside, true);
    renderer.draw(outside, app.operator_view(w, h));
  } else {
    render::View v = app.stereo_views(w, h)[0];
    v.viewport = {0, 0, w, h};
    renderer.draw(scene, v);
  }
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(300, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Operator");
  const SessionView& sv = app.session().view();
  const ProtocolStep* s = app.session().current_step();
  const char* phase = sv.phase == Phase::Floor  ? "Floor calibration"
                      : sv.phase == Phase::Done ? "Done"
                      : s                       ? s->title.c_str()
                                                : "Waiting for Start";
  ImGui::Text("Step: %s", phase);
  if (sv.holding)
    ImGui::ProgressBar(static_cast<float>(sv.hold_progress), ImVec2(-1, 0), "holding");
  ImGui::TextWrapped("%s", sv.message.c_str());
  if (ImGui::Button("Start")) out.push_back({"start", Json()});
  ImGui::SameLine();
  if (ImGui::Button("Redo")) out.push_back({"redo", Json()});
  ImGui::SameLine();
  if (ImGui::Button("Skip")) out.push_back({"skip", Json()});
  ImGui::Separator();
  // The fields show the session's values (--weight/--sex, the log, ...) whenever those change;
  // in between the operator's typing is kept.
  const TypedFields typed = typed_fields(app.session());
  if (!synced_ || synced_->weight != typed.weight || synced_->sex != typed.sex) {
    weight_ = typed.weight;
    sex_ = typed.sex;
    synced_ = typed;
  }
  ImGui::InputDouble("kg", &weight_, 0.5, 5.0, "%.1f");
  ImGui::SameLine();
  if (ImGui::Button("Set weight")) out.push_back({"weight", Json(weight_)});
  if (ImGui::RadioButton("female", sex_ == 0)) {
    sex_ = 0;
    out.push_back({"sex", Json("female")});
  }
  ImGui::SameLine();
  if (ImGui::RadioButton("male", sex_ == 1)) {
    sex_ = 1;
    out.push_back({"sex", Json("male")});
  }
  ImGui::Separator();
  const SessionResult r = app.session().result();
  for (const auto& kv : r.measurements) {
    const auto t = r.takes.find(kv.first);
    ImGui::Text("%-20s %8.1f %s%s", kv.first.c_str(),
                kv.first == "weight" ? kv.second : kv.second * 100.0,
                kv.first == "weight" ? "kg" : "cm",
                t != r.takes.end() && t->second.size() == 3 ? "  (3 takes)" : "");
  }
  ImGui::End();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  return out;
}

}  // namespace caliper::vr
