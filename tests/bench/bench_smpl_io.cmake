# libsmpl file I/O benchmarks (Google Benchmark; not run by ctest). Figures: docs/performance.md,
# section "libsmpl file I/O". The full-size fixture files are generated on first run by
# tests/smpl/fixtures/make_io_fixtures.py (Debian's python3 with numpy and scipy).
add_executable(bench_smpl_io ${CMAKE_CURRENT_LIST_DIR}/bench_smpl_io.cpp)
target_link_libraries(bench_smpl_io PRIVATE smpl benchmark::benchmark)
target_compile_definitions(bench_smpl_io PRIVATE
  CALIPER_BENCH_DATA_DIR="${CMAKE_CURRENT_BINARY_DIR}/data/smpl_io"
  CALIPER_SYSTEM_PYTHON="${CALIPER_SYSTEM_PYTHON}"
  CALIPER_IO_FIXTURE_SCRIPT="${PROJECT_SOURCE_DIR}/tests/smpl/fixtures/make_io_fixtures.py")
caliper_project_target(bench_smpl_io)
