# Install and export the libraries so that other projects can use them:
#   find_package(VirtualCaliper) + target_link_libraries(app PRIVATE vc::caliper)   (CMake)
#   pkg-config --cflags --libs virtual-caliper                                     (anything else)
# Exported targets: vc::smpl (alias smpl::smpl), vc::smpl_gltf (alias smpl::gltf), vc::caliper
# (alias caliper::caliper). They are static libraries, so their private link dependencies (zlib,
# tinygltf, nlohmann_json, libcsv) travel in the exported interface as $<LINK_ONLY:...> and the package
# config finds every one of them (find_dependency); tests/consumer/run.sh checks it from outside.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
set(CALIPER_CMAKE_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/VirtualCaliper)

install(DIRECTORY libsmpl/include/smpl DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY libcaliper/include/caliper DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(CALIPER_EXPORTED_TARGETS smpl caliper caliper_warnings caliper_sanitizers)
set(CALIPER_HAVE_GLTF OFF)
if(TARGET smpl_gltf)
  list(APPEND CALIPER_EXPORTED_TARGETS smpl_gltf)
  set(CALIPER_HAVE_GLTF ON)
endif()
install(TARGETS ${CALIPER_EXPORTED_TARGETS} EXPORT VirtualCaliperTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The programs' data: open default models, protocols, media. caliper::find_assets_dir() looks
# for it at <prefix>/bin/../share/virtual-caliper/assets.
install(DIRECTORY assets/ DESTINATION ${CMAKE_INSTALL_DATADIR}/virtual-caliper/assets)
install(EXPORT VirtualCaliperTargets NAMESPACE vc:: DESTINATION ${CALIPER_CMAKE_INSTALL_DIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/VirtualCaliperConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfig.cmake
  INSTALL_DESTINATION ${CALIPER_CMAKE_INSTALL_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfigVersion.cmake
  ${CMAKE_CURRENT_LIST_DIR}/FindLibCSV.cmake
  DESTINATION ${CALIPER_CMAKE_INSTALL_DIR})

# pkg-config: one file for the three libraries, relocatable (prefix from the file's own folder,
# so `cmake --install build --prefix P` works for any P). The libraries are static, so their link
# dependencies are in Requires (not Requires.private): plain `pkg-config --libs` links.
set(CALIPER_PC_REQUIRES "eigen3 zlib nlohmann_json")
# minizip goes in Libs, not Requires: its Cflags would put /usr/include/minizip (whose zip.h
# shadows libzip's) on every consumer's include path, and no installed header includes it.
# libcsv (CSV parsing in libcaliper) has no .pc file: it goes in Libs too.
set(CALIPER_PC_LIBS "-lcaliper -lsmpl -lminizip -lcsv")
if(CALIPER_HAVE_GLTF)
  set(CALIPER_PC_REQUIRES "${CALIPER_PC_REQUIRES} tinygltf")
  set(CALIPER_PC_LIBS "-lcaliper -lsmpl_gltf -lsmpl -lminizip -lcsv")
endif()
file(RELATIVE_PATH CALIPER_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" CALIPER_PC_TO_PREFIX "${CALIPER_PC_TO_PREFIX}")
configure_file(${CMAKE_CURRENT_LIST_DIR}/virtual-caliper.pc.in
  ${CMAKE_CURRENT_BINARY_DIR}/virtual-caliper.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/virtual-caliper.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
