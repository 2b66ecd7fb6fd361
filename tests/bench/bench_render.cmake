# Renderer and editor benchmarks (Google Benchmark; not run by ctest). Figures: docs/performance.md,
# section "Renderer and editor".
if(TARGET caliper_render AND TARGET caliper_app_core)
  add_executable(bench_render ${CMAKE_CURRENT_LIST_DIR}/bench_render.cpp)
  target_link_libraries(bench_render PRIVATE caliper_render caliper_app_core caliper_test_support
    benchmark::benchmark)
  caliper_project_target(bench_render)
endif()
