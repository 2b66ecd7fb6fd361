# caliper-vr benchmark (Google Benchmark; not run by ctest). Figures: docs/performance.md,
# section "VR app": CPU time per frame of the app in replay at the headset's resolution.
if(TARGET caliper_vr_app)
  add_executable(bench_vr ${CMAKE_CURRENT_LIST_DIR}/bench_vr.cpp)
  target_link_libraries(bench_vr PRIVATE caliper_vr_app caliper caliper_render benchmark::benchmark)
  target_compile_definitions(bench_vr PRIVATE CALIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  caliper_project_target(bench_vr)
endif()
