# SPDX-License-Identifier: Apache-2.0
# One consumer build of tests/consumer/project in a fresh directory, run by ctest:
#   cmake -DMODE=<fetch|package|subdir|cortex-m4f> -DICOAC_SOURCE_DIR=<checkout> -DICOAC_VERSION=<x.y.z>
#         -DWORK=<fresh dir> -DGENERATOR=<gen> [-DC_COMPILER=<host cc>] [-DREADELF=<arm readelf>]
#         -P check_consumer.cmake
# fetch: FetchContent of the release archive made from the checkout; package: cmake --install of
# icoac into a fresh prefix, then find_package (and pkg-config); subdir: add_subdirectory of the
# checkout; cortex-m4f: add_subdirectory of the checkout cross-compiled with the project's
# toolchain file and -DCMAKE_C_FLAGS=-O2, linked into a bare-metal ELF. Every build must hold the
# library alone (its objects, one archive, no test), and the host programs must run.
set(project_dir ${CMAKE_CURRENT_LIST_DIR}/project)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

# run(<output var> <command...>): echo the command, run it, fail on a non-zero status.
function(run out)
  list(JOIN ARGN " " line)
  message(STATUS "$ ${line}")
  execute_process(COMMAND ${ARGN} OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}):\n${stdout}\n${stderr}")
  endif()
  set(${out} "${stdout}${stderr}" PARENT_SCOPE)
endfunction()

function(expect text regex what)
  if(NOT text MATCHES "${regex}")
    message(FATAL_ERROR "${what}: no match for '${regex}' in:\n${text}")
  endif()
endfunction()

# The consumer build holds icoac's objects, the consumer's main.c and nothing else.
function(check_library_only build)
  file(GLOB icoac_sources RELATIVE ${ICOAC_SOURCE_DIR}/firmware/src ${ICOAC_SOURCE_DIR}/firmware/src/*.c)
  list(REMOVE_ITEM icoac_sources icoac_batch.c) # ICOAC_BATCH: off outside the developer build
  list(LENGTH icoac_sources expected_library_objects)
  file(GLOB_RECURSE objects RELATIVE ${build} ${build}/*.o ${build}/*.obj)
  list(FILTER objects EXCLUDE REGEX "^CMakeFiles/[0-9][^/]*/") # CMake's compiler identification
  file(GLOB_RECURSE archives RELATIVE ${build} ${build}/*.a)
  set(library_objects ${objects})
  list(FILTER library_objects INCLUDE REGEX "/icoac\\.dir/src/icoac_[a-z_]+\\.c\\.o(bj)?$")
  list(LENGTH library_objects n_library)
  list(LENGTH objects n_objects)
  math(EXPR n_other "${n_objects} - ${n_library}")
  message(STATUS "consumer build: ${n_objects} objects (${n_library} of icoac, ${n_other} of the consumer), "
                 "archives: ${archives}")
  if(NOT n_library EQUAL expected_library_objects OR NOT n_other EQUAL 1 OR NOT objects MATCHES "/consumer\\.dir/main\\.c\\.o")
    message(FATAL_ERROR "expected ${expected_library_objects} icoac objects and main.c's, got:\n${objects}")
  endif()
  if(NOT archives MATCHES "^([^;]*/)?libicoac\\.a$")
    message(FATAL_ERROR "expected one archive, libicoac.a, got: ${archives}")
  endif()
  run(tests ${CMAKE_CTEST_COMMAND} -N --test-dir ${build})
  expect("${tests}" "Total Tests: 0" "icoac added tests to the consumer")
endfunction()

# check_host_run(<exe> <maxima>): the ticks ran, icoac_version() is the version, and the
# caller saw the maxima "<inputs> inputs <rules> rules <units> critic units".
function(check_host_run exe maxima)
  run(output ${exe})
  message(STATUS "${output}")
  expect("${output}" "tick 4 force 1\\.000" "the consumer's ticks (the reflex at tick 4)")
  expect("${output}" "icoac ${ICOAC_VERSION} \\(header ${ICOAC_VERSION}, ABI [0-9]+\\)" "icoac_version()")
  expect("${output}" "maxima ${maxima}," "the build maxima")
endfunction()
set(default_maxima "6 inputs 6 rules 216 critic units")

set(host_compiler)
if(C_COMPILER)
  set(host_compiler -DCMAKE_C_COMPILER=${C_COMPILER})
endif()
set(build ${WORK}/build)

if(MODE STREQUAL "fetch")
  run(dist ${CMAKE_COMMAND} -DICOAC_SOURCE_DIR=${ICOAC_SOURCE_DIR} -DICOAC_VERSION=${ICOAC_VERSION}
      -DICOAC_DIST_DIR=${WORK}/dist -P ${ICOAC_SOURCE_DIR}/cmake/IcoacDist.cmake)
  message(STATUS "${dist}")
  set(archive ${WORK}/dist/icoac-${ICOAC_VERSION}.tar.gz)
  file(SHA256 ${archive} sha256)
  # with the cart-pole's maxima (a consumer's cache variables reach the library and its callers)
  run(out ${CMAKE_COMMAND} -S ${project_dir} -B ${build} -G ${GENERATOR} ${host_compiler} -DICOAC_FROM=fetch
      -DICOAC_URL=file://${archive} -DICOAC_SHA256=${sha256}
      -DICOAC_MAX_INPUTS=4 -DICOAC_MAX_RULES=4 -DICOAC_MAX_CRITIC_UNITS=162)
  run(out ${CMAKE_COMMAND} --build ${build})
  check_library_only(${build})
  check_host_run(${build}/consumer "4 inputs 4 rules 162 critic units")

elseif(MODE STREQUAL "package")
  set(prefix ${WORK}/prefix)
  run(out ${CMAKE_COMMAND} -S ${ICOAC_SOURCE_DIR} -B ${WORK}/icoac-build -G ${GENERATOR} ${host_compiler}
      -DCMAKE_BUILD_TYPE=Release -DICOAC_BUILD_HOST=OFF)
  run(out ${CMAKE_COMMAND} --build ${WORK}/icoac-build)
  run(out ${CMAKE_COMMAND} --install ${WORK}/icoac-build --prefix ${prefix})
  message(STATUS "${out}")
  # SameMinorVersion before 1.0: a request for 0.<minor> takes 0.<minor>.x only.
  string(REGEX MATCH "^([0-9]+)\\.([0-9]+)" minor_version ${ICOAC_VERSION})
  math(EXPR next_minor "${CMAKE_MATCH_2} + 1")
  foreach(request_expected IN ITEMS "${minor_version}:TRUE" "${CMAKE_MATCH_1}.${next_minor}:FALSE")
    string(REPLACE ":" ";" request_expected ${request_expected})
    list(GET request_expected 0 PACKAGE_FIND_VERSION)
    list(GET request_expected 1 expected)
    string(REPLACE "." ";" parts ${PACKAGE_FIND_VERSION})
    list(GET parts 0 PACKAGE_FIND_VERSION_MAJOR)
    list(GET parts 1 PACKAGE_FIND_VERSION_MINOR)
    set(CMAKE_SIZEOF_VOID_P "")
    include(${prefix}/lib/cmake/icoac/icoacConfigVersion.cmake)
    if(NOT "${PACKAGE_VERSION_COMPATIBLE}" STREQUAL "${expected}")
      message(FATAL_ERROR "icoac ${PACKAGE_VERSION} for a request of ${PACKAGE_FIND_VERSION}: compatible "
                          "'${PACKAGE_VERSION_COMPATIBLE}', expected ${expected}")
    endif()
    message(STATUS "find_package(icoac ${PACKAGE_FIND_VERSION}) with ${PACKAGE_VERSION} installed: compatible ${expected}")
  endforeach()
  run(out ${CMAKE_COMMAND} -S ${project_dir} -B ${build} -G ${GENERATOR} ${host_compiler} -DICOAC_FROM=package
      -DCMAKE_PREFIX_PATH=${prefix})
  message(STATUS "${out}")
  expect("${out}" "icoac ${ICOAC_VERSION}: maxima 6 inputs, 6 rules, 216 critic units" "icoacConfig.cmake's variables")
  run(out ${CMAKE_COMMAND} --build ${build})
  file(GLOB_RECURSE objects ${build}/*.o)
  list(LENGTH objects n_objects)
  if(NOT n_objects EQUAL 1)
    message(FATAL_ERROR "a find_package consumer compiles its main.c alone, got: ${objects}")
  endif()
  check_host_run(${build}/consumer "${default_maxima}")
  # pkg-config (icoac.pc): the same program from the .pc's flags alone.
  find_program(PKG_CONFIG pkg-config)
  if(PKG_CONFIG AND C_COMPILER)
    set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
    run(pc_flags ${PKG_CONFIG} --cflags --libs icoac)
    message(STATUS "pkg-config --cflags --libs icoac: ${pc_flags}")
    separate_arguments(pc_flags UNIX_COMMAND "${pc_flags}")
    run(out ${C_COMPILER} -std=c99 ${project_dir}/main.c ${pc_flags} -o ${WORK}/consumer_pc)
    check_host_run(${WORK}/consumer_pc "${default_maxima}")
  endif()
  # The installed icoac_build_config.h: the include path alone gives the library's maxima, and
  # another maximum is an error.
  if(C_COMPILER)
    run(out ${C_COMPILER} -std=c99 -c ${project_dir}/main.c -I${prefix}/include -o ${WORK}/plain.o)
    message(STATUS "$ ${C_COMPILER} -std=c99 -c main.c -I${prefix}/include -DICOAC_MAX_INPUTS=4 (must fail)")
    execute_process(COMMAND ${C_COMPILER} -std=c99 -c ${project_dir}/main.c -I${prefix}/include -DICOAC_MAX_INPUTS=4
                    -o ${WORK}/other_maxima.o RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
    if(rc EQUAL 0 OR NOT err MATCHES "ICOAC_MAX_INPUTS differs from the library build's")
      message(FATAL_ERROR "a caller with ICOAC_MAX_INPUTS=4 compiled against a library of 6 (${rc}):\n${err}")
    endif()
    string(REGEX MATCH "[^\n]*#error[^\n]*" err_line "${err}")
    message(STATUS "refused: ${err_line}")
  endif()

elseif(MODE STREQUAL "subdir")
  run(out ${CMAKE_COMMAND} -S ${project_dir} -B ${build} -G ${GENERATOR} ${host_compiler} -DICOAC_FROM=subdir
      -DICOAC_SOURCE_DIR=${ICOAC_SOURCE_DIR})
  run(out ${CMAKE_COMMAND} --build ${build})
  check_library_only(${build})
  check_host_run(${build}/consumer "${default_maxima}")

elseif(MODE STREQUAL "cortex-m4f")
  run(out ${CMAKE_COMMAND} -S ${project_dir} -B ${build} -G ${GENERATOR}
      -DCMAKE_TOOLCHAIN_FILE=${ICOAC_SOURCE_DIR}/cmake/toolchain/cortex-m4f.cmake -DCMAKE_C_FLAGS=-O2
      -DICOAC_FROM=subdir -DICOAC_SOURCE_DIR=${ICOAC_SOURCE_DIR})
  run(out ${CMAKE_COMMAND} --build ${build} --verbose)
  # Every compile and the link get -O2 and the CPU flags.
  string(REGEX MATCHALL "[^\n]*arm-none-eabi-gcc[^\n]*" commands "${out}")
  list(LENGTH commands n_commands)
  set(n_cpu 0)
  foreach(command IN LISTS commands)
    expect("${command}" " -O2( |$)" "CMAKE_C_FLAGS")
    expect("${command}" "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16" "the toolchain's CPU flags")
    math(EXPR n_cpu "${n_cpu} + 1")
  endforeach()
  list(GET commands 0 first_command)
  list(FILTER commands INCLUDE REGEX " -o consumer\\.elf")
  list(LENGTH commands n_links)
  message(STATUS "first compile: ${first_command}\nlink: ${commands}")
  message(STATUS "${n_cpu} of ${n_commands} compiler calls have -O2 and -mcpu=cortex-m4 -mthumb -mfloat-abi=hard "
                 "-mfpu=fpv4-sp-d16, the link (${n_links}) too")
  if(n_commands LESS 2 OR NOT n_links EQUAL 1)
    message(FATAL_ERROR "expected compiles and one link of consumer.elf in:\n${out}")
  endif()
  check_library_only(${build})
  # The library's objects and the linked ELF (with newlib's multilib): ARMv7E-M (Cortex-M4) with
  # FPv4-SP (VFPv4-D16, single precision), floats passed in VFP registers.
  foreach(file icoac/firmware/CMakeFiles/icoac.dir/src/icoac_step.c.obj consumer.elf)
    run(attributes ${READELF} -A ${build}/${file})
    message(STATUS "${file}: ${attributes}")
    foreach(tag "Tag_CPU_arch: v7E-M" "Tag_CPU_arch_profile: Microcontroller" "Tag_FP_arch: VFPv4-D16"
                "Tag_ABI_HardFP_use: SP only" "Tag_ABI_VFP_args: VFP registers")
      expect("${attributes}" "${tag}" "${file}'s attributes")
    endforeach()
  endforeach()
  run(header ${READELF} -h ${build}/consumer.elf)
  expect("${header}" "Machine: +ARM" "ELF header")
  expect("${header}" "hard-float ABI" "ELF header")
else()
  message(FATAL_ERROR "MODE must be fetch, package, subdir or cortex-m4f, not '${MODE}'")
endif()
message(STATUS "consumer ${MODE}: OK")
