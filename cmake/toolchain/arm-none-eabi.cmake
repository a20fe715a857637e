# SPDX-License-Identifier: Apache-2.0
# Generic bare-metal arm-none-eabi layer. Include it from a per-core file that sets
# ICOAC_CPU_FLAGS first (cortex-m4f.cmake, cortex-m0plus.cmake).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

find_program(ICOAC_ARM_GCC arm-none-eabi-gcc REQUIRED)
find_program(ICOAC_ARM_AR arm-none-eabi-ar REQUIRED)
find_program(ICOAC_ARM_OBJCOPY arm-none-eabi-objcopy REQUIRED)
find_program(ICOAC_ARM_SIZE arm-none-eabi-size REQUIRED)
find_program(ICOAC_ARM_NM arm-none-eabi-nm REQUIRED)
set(CMAKE_C_COMPILER ${ICOAC_ARM_GCC})
set(CMAKE_ASM_COMPILER ${ICOAC_ARM_GCC})
set(CMAKE_AR ${ICOAC_ARM_AR})

# No host executables can run: try_compile builds a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# The CPU flags select the instruction set, the float ABI and the matching multilib (libc, libm):
# they are compile and link options of every target (directory properties of the project that
# loads this file, try_compile's too), so that a CMAKE_C_FLAGS given on the command line cannot
# drop them, as it would drop CMAKE_C_FLAGS_INIT, which only seeds the cache. (project() reads
# this file twice; CMake de-duplicates the options.) The section flags are ordinary defaults.
separate_arguments(ICOAC_CPU_OPTIONS UNIX_COMMAND "${ICOAC_CPU_FLAGS}")
add_compile_options(${ICOAC_CPU_OPTIONS})
add_link_options(${ICOAC_CPU_OPTIONS})
set(CMAKE_C_FLAGS_INIT "-ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,--gc-sections")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
