# Install and export smpl::smpl and caliper::caliper so that other projects can find_package them.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(DIRECTORY libsmpl/include/smpl DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY libcaliper/include/caliper DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS smpl caliper caliper_warnings caliper_sanitizers EXPORT VirtualCaliperTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The programs' data: open default models, protocols, media. caliper::find_assets_dir() looks
# for it at <prefix>/bin/../share/virtual-caliper/assets.
install(DIRECTORY assets/ DESTINATION ${CMAKE_INSTALL_DATADIR}/virtual-caliper/assets)
install(EXPORT VirtualCaliperTargets NAMESPACE vc:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/VirtualCaliper)
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfig.cmake
  "include(CMakeFindDependencyMacro)\nfind_dependency(Eigen3)\n"
  "include(\${CMAKE_CURRENT_LIST_DIR}/VirtualCaliperTargets.cmake)\n"
  "if(NOT TARGET smpl::smpl)\n  add_library(smpl::smpl ALIAS vc::smpl)\nendif()\n"
  "if(NOT TARGET caliper::caliper)\n  add_library(caliper::caliper ALIAS vc::caliper)\nendif()\n")
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/VirtualCaliperConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/VirtualCaliper)
