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

# One of the project's libraries, set up the one way they all are:
#   caliper_add_library(<name> [STATIC] [PIC] [ALIAS <alias>] [INCLUDE <dir> [INSTALL_INCLUDE]]
#                       SOURCES <files...> [LINK <target_link_libraries arguments...>])
# PIC makes it position-independent (so that shared objects can link the static library); INCLUDE is the public include folder (INSTALL_INCLUDE: <prefix>/include once installed); LINK
# goes to target_link_libraries as written (with its PUBLIC / PRIVATE keywords); the project's
# warnings and sanitizers are applied (caliper_project_target).
function(caliper_add_library name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "STATIC;PIC;INSTALL_INCLUDE" "ALIAS;INCLUDE" "SOURCES;LINK")
  set(kind "")
  if(arg_STATIC)
    set(kind STATIC)
  endif()
  add_library(${name} ${kind} ${arg_SOURCES})
  if(arg_ALIAS)
    add_library(${arg_ALIAS} ALIAS ${name})
  endif()
  if(arg_INCLUDE AND arg_INSTALL_INCLUDE)
    target_include_directories(${name} PUBLIC
      $<BUILD_INTERFACE:${arg_INCLUDE}> $<INSTALL_INTERFACE:include>)
  elseif(arg_INCLUDE)
    target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${arg_INCLUDE}>)
  endif()
  if(arg_LINK)
    target_link_libraries(${name} ${arg_LINK})
  endif()
  if(arg_PIC)
    set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()
  caliper_project_target(${name})
endfunction()

# One of the project's programs:
#   caliper_add_program(<name> [INSTALL] [OUTPUT_NAME <file name>] SOURCES <files...>
#                       [LINK <libraries...>])
# LINK is private; INSTALL puts the program in <prefix>/bin.
function(caliper_add_program name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "INSTALL" "OUTPUT_NAME" "SOURCES;LINK")
  add_executable(${name} ${arg_SOURCES})
  if(arg_OUTPUT_NAME)
    set_target_properties(${name} PROPERTIES OUTPUT_NAME ${arg_OUTPUT_NAME})
  endif()
  target_link_libraries(${name} PRIVATE ${arg_LINK})
  caliper_project_target(${name})
  if(arg_INSTALL)
    install(TARGETS ${name} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endfunction()

# Text files embedded in the program as C++ string constants, regenerated when they change:
#   caliper_embed_files(<output.cpp> NAMESPACE <ns> FILES <files...> NAMES <identifiers...>
#                       COMMENT <text>)
# File i becomes `extern const char* const <ns>::<NAMES[i]>` (its text byte for byte); add
# <output.cpp> to a target's sources and declare the constants where they are used.
set(CALIPER_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_files.cmake)
function(caliper_embed_files output)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "NAMESPACE;COMMENT" "FILES;NAMES")
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output} -DNAMESPACE=${arg_NAMESPACE}
            "-DINPUTS=${arg_FILES}" "-DNAMES=${arg_NAMES}" -P ${CALIPER_EMBED_SCRIPT}
    DEPENDS ${arg_FILES} ${CALIPER_EMBED_SCRIPT}
    COMMENT "${arg_COMMENT}"
    VERBATIM)
  # Compiled on its own in a unity build: generated code stays out of the batches that
  # clang-tidy reads as the project's sources (.ci/clang-tidy.py).
  set_source_files_properties(${output} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
endfunction()
