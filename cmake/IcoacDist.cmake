# SPDX-License-Identifier: Apache-2.0
# The library-only release archive icoac-<version>.tar.gz, for FetchContent or add_subdirectory:
#   cmake -DICOAC_SOURCE_DIR=<checkout> -DICOAC_VERSION=<x.y.z> -DICOAC_DIST_DIR=<out> -P cmake/IcoacDist.cmake
# (the top-level target icoac_dist, `make dist`). It holds the top-level CMakeLists.txt, firmware/,
# cmake/, LICENSE, README.md and the porting guide and changelog: without sim_host/ and tests/,
# it configures as the library alone whatever the caller's options.
foreach(var ICOAC_SOURCE_DIR ICOAC_VERSION ICOAC_DIST_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "IcoacDist.cmake: -D${var}=... is required")
  endif()
endforeach()

set(name icoac-${ICOAC_VERSION})
set(stage ${ICOAC_DIST_DIR}/stage)
file(REMOVE_RECURSE ${stage})
file(MAKE_DIRECTORY ${stage}/${name}/docs)
file(COPY ${ICOAC_SOURCE_DIR}/CMakeLists.txt ${ICOAC_SOURCE_DIR}/LICENSE ${ICOAC_SOURCE_DIR}/README.md
          ${ICOAC_SOURCE_DIR}/cmake ${ICOAC_SOURCE_DIR}/firmware
     DESTINATION ${stage}/${name} PATTERN __pycache__ EXCLUDE
     # the project's own checks: static analysis, and the test framework's fetch
     PATTERN lint EXCLUDE PATTERN .clang-tidy EXCLUDE PATTERN modules EXCLUDE)
file(COPY ${ICOAC_SOURCE_DIR}/docs/porting.md ${ICOAC_SOURCE_DIR}/docs/changelog.md DESTINATION ${stage}/${name}/docs)

set(archive ${ICOAC_DIST_DIR}/${name}.tar.gz)
# Files in sorted order with a fixed time: the same sources give the same tar (the gzip header
# still holds the time of compression, so pin the SHA256 of the archive you publish).
file(GLOB_RECURSE files RELATIVE ${stage} ${stage}/${name}/*)
execute_process(COMMAND ${CMAKE_COMMAND} -E tar cfz ${archive} --format=gnutar "--mtime=1970-01-01 00:00:00 UTC" ${files}
                WORKING_DIRECTORY ${stage} COMMAND_ERROR_IS_FATAL ANY)
file(REMOVE_RECURSE ${stage})
file(SIZE ${archive} size)
file(SHA256 ${archive} sha256)
message(STATUS "${archive}: ${size} bytes, SHA256 ${sha256}")
