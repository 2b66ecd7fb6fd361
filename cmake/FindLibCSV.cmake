# FindLibCSV: libcsv (Debian libcsv-dev), the CSV parser under libcaliper's reader
# (libcaliper/src/csv.cpp). libcsv ships neither a CMake package nor a pkg-config file, so this
# module finds its header and library and defines the imported target LibCSV::LibCSV.
# It is installed beside VirtualCaliperConfig.cmake, which uses it to give consumers of the
# static vc::caliper the same target.
#   LibCSV_FOUND, LibCSV_INCLUDE_DIR, LibCSV_LIBRARY; target LibCSV::LibCSV
find_path(LibCSV_INCLUDE_DIR NAMES csv.h DOC "libcsv header (libcsv-dev)")
find_library(LibCSV_LIBRARY NAMES csv DOC "libcsv library (libcsv-dev)")
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LibCSV
  REQUIRED_VARS LibCSV_LIBRARY LibCSV_INCLUDE_DIR
  REASON_FAILURE_MESSAGE "install libcsv-dev (.ci/install-deps.sh)")
if(LibCSV_FOUND AND NOT TARGET LibCSV::LibCSV)
  add_library(LibCSV::LibCSV UNKNOWN IMPORTED)
  set_target_properties(LibCSV::LibCSV PROPERTIES
    IMPORTED_LOCATION "${LibCSV_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LibCSV_INCLUDE_DIR}")
endif()
mark_as_advanced(LibCSV_INCLUDE_DIR LibCSV_LIBRARY)
