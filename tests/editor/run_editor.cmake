# Runs caliper-editor and checks its exit status and that it wrote the screenshot.
# -DEDITOR=... -DARGS="a;b;c" -DSCREENSHOT=out.png [-DLAUNCHER="xvfb-run;-a;..."]
# [-DEXPECT_STATUS=N]: expect exactly this exit status instead (and no screenshot check).
file(REMOVE ${SCREENSHOT})
if(DEFINED EXPECT_STATUS)
  execute_process(COMMAND ${LAUNCHER} ${EDITOR} ${ARGS}
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
  if(NOT status EQUAL EXPECT_STATUS)
    message(FATAL_ERROR "caliper-editor exited with ${status}, expected ${EXPECT_STATUS}\n${out}\n${err}")
  endif()
  message(STATUS "exit status ${status} as expected\n${err}")
  return()
endif()
execute_process(COMMAND ${LAUNCHER} ${EDITOR} ${ARGS} --screenshot ${SCREENSHOT}
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "caliper-editor exited with ${status}\n${out}\n${err}")
endif()
if(NOT EXISTS ${SCREENSHOT})
  message(FATAL_ERROR "caliper-editor did not write ${SCREENSHOT}\n${out}\n${err}")
endif()
file(SIZE ${SCREENSHOT} size)
if(size LESS 10000)
  message(FATAL_ERROR "${SCREENSHOT} is only ${size} bytes: expected a full editor picture")
endif()
message(STATUS "${SCREENSHOT}: ${size} bytes\n${err}")
