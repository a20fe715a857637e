# SPDX-License-Identifier: Apache-2.0
# Included by firmware/CMakeLists.txt (ICOAC_INSTALL) after the library targets.
# `cmake --install`: the library variants of this build (lib/), their public and generated
# headers (include/icoac/), the CMake package icoac (lib/cmake/icoac/: targets icoac::<variant>,
# the build options as icoac_<OPTION> variables) and a pkg-config file per variant
# (lib/pkgconfig/<variant>.pc). Component "icoac"; the Python wheel installs only "harness".
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ICOAC_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/icoac CACHE STRING
    "Where the CMake package of icoac is installed, relative to the prefix")
get_property(icoac_variants GLOBAL PROPERTY ICOAC_LIBRARY_TARGETS)

install(TARGETS ${icoac_variants} EXPORT icoacTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT icoac
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_SOURCE_DIR}/firmware/include/icoac/icoac.h ${PROJECT_SOURCE_DIR}/firmware/include/icoac/icoac_types.h
              ${PROJECT_SOURCE_DIR}/firmware/include/icoac/icoac_rng.h
              ${PROJECT_SOURCE_DIR}/firmware/include/icoac/icoac_params.h
              ${ICOAC_GENERATED_INCLUDE_DIR}/icoac/icoac_version.h
              ${ICOAC_GENERATED_INCLUDE_DIR}/icoac/icoac_build_config.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/icoac COMPONENT icoac)
install(EXPORT icoacTargets NAMESPACE icoac:: DESTINATION ${ICOAC_INSTALL_CMAKEDIR} COMPONENT icoac)

# 0.x: a minor release may change the API and ABI (docs/changelog.md), so find_package(icoac 0.2)
# accepts 0.2.x only; from 1.0 on, SameMajorVersion.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(icoac_compatibility SameMinorVersion)
else()
  set(icoac_compatibility SameMajorVersion)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/icoacConfig.cmake.in ${PROJECT_BINARY_DIR}/icoacConfig.cmake
                              INSTALL_DESTINATION ${ICOAC_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/icoacConfigVersion.cmake
                                 COMPATIBILITY ${icoac_compatibility})
install(FILES ${PROJECT_BINARY_DIR}/icoacConfig.cmake ${PROJECT_BINARY_DIR}/icoacConfigVersion.cmake
        DESTINATION ${ICOAC_INSTALL_CMAKEDIR} COMPONENT icoac)

# pkg-config: one file per variant, its defines in Cflags (as the target's), libm in Libs (static
# archives: a plain `pkg-config --libs` must link it).
file(RELATIVE_PATH ICOAC_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" ICOAC_PC_TO_PREFIX "${ICOAC_PC_TO_PREFIX}")
foreach(variant IN LISTS icoac_variants)
  get_target_property(icoac_pc_defines ${variant} INTERFACE_COMPILE_DEFINITIONS)
  list(TRANSFORM icoac_pc_defines PREPEND -D)
  list(JOIN icoac_pc_defines " " ICOAC_PC_CFLAGS)
  set(ICOAC_PC_NAME ${variant})
  configure_file(${PROJECT_SOURCE_DIR}/cmake/icoac.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/${variant}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/pkgconfig/${variant}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
          COMPONENT icoac)
endforeach()
