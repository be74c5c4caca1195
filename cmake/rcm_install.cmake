# Install rules: the public headers, the libraries (shared, versioned
# SONAME), the rcm executable and the CMake package, so that
#
#   cmake --install build --prefix P
#   find_package(rcm 0.2 REQUIRED)      # with CMAKE_PREFIX_PATH=P
#   target_link_libraries(app PRIVATE rcm::rcm rcm::calib)
#
# works (examples/consumer/ is such a project; scripts/test_install.sh
# builds it against a fresh install).
include(CMakePackageConfigHelpers)

set(rcm_install_targets rcm rcm_calib rcm_sim rcm_viz)
if(TARGET rcm_rosbag)
  list(APPEND rcm_install_targets rcm_rosbag)
endif()
install(TARGETS ${rcm_install_targets}
  EXPORT rcmTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET rcm_cli)
  install(TARGETS rcm_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

# Public headers. The bag headers belong to rcm::rosbag and are installed
# with it only.
set(rcm_header_excludes "")
if(NOT TARGET rcm_rosbag)
  set(rcm_header_excludes PATTERN "rosbag" EXCLUDE)
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/rcm/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h" ${rcm_header_excludes})
install(FILES ${PROJECT_BINARY_DIR}/rcm/include/rcm/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rcm)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/calib/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")

if(TARGET rcm_rosbag)
  set(rcm_with_rosbag ON)
else()
  set(rcm_with_rosbag OFF)
endif()
string(REPLACE ";" " " RCM_OPENCV_COMPONENTS "${RCM_OPENCV_COMPONENTS}")
set(rcm_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/rcm)
install(EXPORT rcmTargets NAMESPACE rcm:: DESTINATION ${rcm_cmake_dir})
configure_package_config_file(
  ${PROJECT_SOURCE_DIR}/cmake/rcmConfig.cmake.in
  ${PROJECT_BINARY_DIR}/rcmConfig.cmake
  INSTALL_DESTINATION ${rcm_cmake_dir})
# 0.2.x satisfies find_package(rcm 0.2); 0.3 does not (the ABI before 1.0
# changes with the minor version, as the SONAME says).
write_basic_package_version_file(
  ${PROJECT_BINARY_DIR}/rcmConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/rcmConfig.cmake
              ${PROJECT_BINARY_DIR}/rcmConfigVersion.cmake
        DESTINATION ${rcm_cmake_dir})
