# JSON reader benchmark (issue 10: parsing must be linear in the number of keys). Figures and
# commands: docs/performance.md, section "JSON".
add_executable(bench_json ${CMAKE_CURRENT_LIST_DIR}/bench_json.cpp)
target_link_libraries(bench_json PRIVATE caliper benchmark::benchmark)
caliper_project_target(bench_json)
