# Runs one command and checks its exit code and output (used by tests/cli/CMakeLists.txt).
# -DCMD=<exe;arg;...> -DEXPECT_CODE=<n> [-DSTDOUT_REGEX=...] [-DSTDERR_REGEX=...]
# [-DSTDERR_NOT_REGEX=...] [-DWORKDIR=...]
# Arguments arrive joined by "@@" (a list cannot pass through add_test intact).
string(REPLACE "@@" ";" CMD "${CMD}")
if(NOT DEFINED WORKDIR)
  set(WORKDIR ${CMAKE_CURRENT_BINARY_DIR})
endif()
execute_process(COMMAND ${CMD}
  WORKING_DIRECTORY ${WORKDIR}
  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "exit code: ${code}\n--- stdout ---\n${out}\n--- stderr ---\n${err}")
if(NOT "${code}" STREQUAL "${EXPECT_CODE}")
  message(FATAL_ERROR "expected exit code ${EXPECT_CODE}, got ${code}")
endif()
if(DEFINED STDOUT_REGEX AND NOT out MATCHES "${STDOUT_REGEX}")
  message(FATAL_ERROR "stdout does not match: ${STDOUT_REGEX}")
endif()
if(DEFINED STDERR_REGEX AND NOT err MATCHES "${STDERR_REGEX}")
  message(FATAL_ERROR "stderr does not match: ${STDERR_REGEX}")
endif()
if(DEFINED STDERR_NOT_REGEX AND err MATCHES "${STDERR_NOT_REGEX}")
  message(FATAL_ERROR "stderr matches what it must not: ${STDERR_NOT_REGEX}")
endif()
