# Every dependency comes from a Debian 12 package (see .ci/install-deps.sh).
# Nothing is downloaded at configure time.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(ZLIB REQUIRED)
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
find_package(TinyGLTF REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(assimp 5 REQUIRED)
# minizip (libminizip-dev) writes the .npz container (libsmpl/src/zip.cpp says why not libzip).
pkg_check_modules(MINIZIP REQUIRED IMPORTED_TARGET minizip)
# libcsv (libcsv-dev) parses every CSV file (libcaliper/src/csv.cpp says why this library);
# cmake/FindLibCSV.cmake, as it has no CMake package or pkg-config file.
find_package(LibCSV REQUIRED)

# Python: Debian's python3 (python3-numpy, python3-scipy, python3-pytest come from apt), never
# whichever python3 is first on PATH (a pyenv shim on some machines). Set CALIPER_PYTHON to use
# another interpreter.
find_program(CALIPER_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH
  DOC "Python interpreter for the tests and the Python module (default: Debian's /usr/bin/python3)")
if(CALIPER_PYTHON)
  set(Python3_EXECUTABLE ${CALIPER_PYTHON})
endif()

if(CALIPER_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
  find_package(Python3 REQUIRED COMPONENTS Interpreter)
endif()
# The Python module `caliper` (libcaliper/python): pybind11-dev and python3-dev. ON by default when
# both are found, except in sanitizer builds (an ASan-instrumented module cannot be loaded into an
# uninstrumented python3).
find_package(Python3 COMPONENTS Interpreter Development.Module)
find_package(pybind11 2.6 CONFIG QUIET)
if(pybind11_FOUND AND Python3_Development.Module_FOUND AND NOT CALIPER_SANITIZE)
  set(CALIPER_PYTHON_DEFAULT ON)
else()
  set(CALIPER_PYTHON_DEFAULT OFF)
endif()
option(CALIPER_BUILD_PYTHON "Build the Python module caliper (needs pybind11-dev, python3-dev)"
  ${CALIPER_PYTHON_DEFAULT})
if(CALIPER_BUILD_PYTHON AND NOT (pybind11_FOUND AND Python3_Development.Module_FOUND))
  message(FATAL_ERROR "CALIPER_BUILD_PYTHON is ON but pybind11 (pybind11-dev) or the Python "
    "headers (python3-dev) for ${Python3_EXECUTABLE} were not found; install them "
    "(.ci/install-deps.sh) or configure with -DCALIPER_BUILD_PYTHON=OFF")
endif()

if(CALIPER_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
if(CALIPER_BUILD_APPS)
  # Every program's options and --help (apps/core/include/app/cli_style.hpp).
  find_package(CLI11 2 REQUIRED CONFIG)
  find_package(OpenGL REQUIRED)
  find_package(glfw3 3.3 REQUIRED)
  find_package(glm REQUIRED)
  find_package(OpenXR REQUIRED)
  find_package(OpenAL REQUIRED)
  # meshoptimizer (libmeshoptimizer-dev): the body's simplified levels while a slider is dragged
  # (apps/render, docs/rendering.md).
  find_package(meshoptimizer CONFIG QUIET)
  if(NOT meshoptimizer_FOUND)
    message(FATAL_ERROR "meshoptimizer not found: install Debian's libmeshoptimizer-dev "
      "(bash .ci/install-deps.sh installs every dependency of the build)")
  endif()
  pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
  pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
  pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavformat libavcodec libswscale libavutil)
endif()
