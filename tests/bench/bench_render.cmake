# Renderer and editor benchmarks (Google Benchmark; not run by ctest). Figures: docs/performance.md,
# section "Renderer and editor". The editor's frame code (apps/editor/src/editor_app.cpp,
# imgui_gl.cpp; library caliper_editor_ui) is linked so that a whole editor frame can be timed
# headless.
if(TARGET caliper_render AND TARGET caliper_app_core AND TARGET caliper-editor)
  add_executable(bench_render ${CMAKE_CURRENT_LIST_DIR}/bench_render.cpp)
  target_link_libraries(bench_render PRIVATE caliper_editor_ui caliper_test_support
    benchmark::benchmark)
  target_compile_definitions(bench_render PRIVATE CALIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  caliper_project_target(bench_render)
endif()
