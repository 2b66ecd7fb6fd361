# libcaliper and `caliper` command benchmarks (Google Benchmark; not run by ctest). Figures and
# commands: docs/performance.md, section "libcaliper and the caliper command".
add_executable(bench_caliper ${CMAKE_CURRENT_LIST_DIR}/bench_caliper.cpp)
target_include_directories(bench_caliper PRIVATE ${PROJECT_SOURCE_DIR}/tests/cli)
target_link_libraries(bench_caliper PRIVATE caliper_cli_core caliper_test_support benchmark::benchmark)
target_compile_definitions(bench_caliper PRIVATE CALIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
caliper_project_target(bench_caliper)
