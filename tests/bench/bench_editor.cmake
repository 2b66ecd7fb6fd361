# Editor idle CPU (not run by ctest): caliper-editor in a real window under Xvfb with no input,
# CPU time read from /proc over a window of seconds, against the same editor redrawing every
# frame (--no-idle-wait) in the same run. Figures: docs/performance.md, "Renderer and editor".
if(TARGET caliper-editor)
  add_executable(bench_editor_idle ${CMAKE_CURRENT_LIST_DIR}/bench_editor_idle.cpp)
  caliper_project_target(bench_editor_idle)
endif()
