# Project options and the interface targets that carry warnings and sanitizers.
# Flags live on interface targets, never in global CMAKE_CXX_FLAGS.
option(CALIPER_BUILD_APPS "Build the command line, editor, VR app and model generator" ON)
option(CALIPER_BUILD_TESTS "Build the unit, integration and golden tests" ON)
option(CALIPER_BUILD_BENCHMARKS "Build the Google Benchmark programs" ON)
option(CALIPER_BUILD_FUZZERS "Build libFuzzer targets (needs clang)" OFF)
option(CALIPER_WERROR "Treat compiler warnings as errors" OFF)
set(CALIPER_SANITIZE "" CACHE STRING "Sanitizers to enable, e.g. address,undefined")

add_library(caliper_warnings INTERFACE)
add_library(caliper::warnings ALIAS caliper_warnings)
target_compile_options(caliper_warnings INTERFACE
  $<$<COMPILE_LANG_AND_ID:CXX,GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
    -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wformat=2 -Wimplicit-fallthrough>)
# Floating point: no contraction of a*b+c into fused multiply-adds, so a result does not depend
# on whether the compiler or a runtime-selected kernel variant had FMA (the open models must be
# byte-identical on every CPU; docs/models.md). Never -ffast-math (design.md).
target_compile_options(caliper_warnings INTERFACE
  $<$<COMPILE_LANG_AND_ID:CXX,GNU,Clang>:-ffp-contract=off>
  $<$<COMPILE_LANG_AND_ID:C,GNU,Clang>:-ffp-contract=off>)
if(CALIPER_WERROR)
  target_compile_options(caliper_warnings INTERFACE $<$<COMPILE_LANG_AND_ID:CXX,GNU,Clang>:-Werror>)
endif()

add_library(caliper_sanitizers INTERFACE)
add_library(caliper::sanitizers ALIAS caliper_sanitizers)
if(CALIPER_SANITIZE)
  target_compile_options(caliper_sanitizers INTERFACE
    -fsanitize=${CALIPER_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(caliper_sanitizers INTERFACE -fsanitize=${CALIPER_SANITIZE})
endif()

# One helper that applies the project's interface targets to one of its own targets.
function(caliper_project_target target)
  target_link_libraries(${target} PRIVATE caliper_warnings caliper_sanitizers)
endfunction()
