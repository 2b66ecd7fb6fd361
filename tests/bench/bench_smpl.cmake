# libsmpl benchmarks (Google Benchmark; not run by ctest). Figures: docs/performance.md,
# section "libsmpl evaluation and export".
add_executable(bench_smpl ${CMAKE_CURRENT_LIST_DIR}/bench_smpl.cpp)
target_link_libraries(bench_smpl PRIVATE smpl smpl_gltf caliper_test_support benchmark::benchmark)
caliper_project_target(bench_smpl)
