# Avatar export per format (Google Benchmark; not run by ctest). Figures: docs/performance.md,
# section "Avatar export per format".
add_executable(bench_export ${CMAKE_CURRENT_LIST_DIR}/bench_export.cpp)
target_link_libraries(bench_export PRIVATE smpl smpl_gltf smpl_fbx smpl_export caliper_test_support
  benchmark::benchmark)
target_compile_definitions(bench_export PRIVATE
  CALIPER_ASSETS_DIR="${PROJECT_SOURCE_DIR}/assets")
caliper_project_target(bench_export)
