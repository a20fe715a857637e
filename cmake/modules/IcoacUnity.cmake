# SPDX-License-Identifier: Apache-2.0
# Unity (ThrowTheSwitch), the C unit-test framework, as CMake users take it: fetched at its
# release v2.6.1, never copied into this repository. Without internet, point CMake at a local
# copy of that release with the standard cache variable FETCHCONTENT_SOURCE_DIR_UNITY (the
# Makefile's UNITY_DIR).
#
# Gives the target `unity`, built for whatever compiler the including project uses (host or
# arm-none-eabi), with doubles and 64-bit integers in its assertions and TEST_PRINTF (a printf of
# its own, through UNITY_OUTPUT_CHAR, for failure context on cores without stdio).
include_guard(GLOBAL)
include(FetchContent)
FetchContent_Declare(unity
  GIT_REPOSITORY https://github.com/ThrowTheSwitch/Unity.git
  GIT_TAG cbcd08fa7de711053a3deec6339ee89cad5d2697 # v2.6.1
  GIT_SHALLOW FALSE)
FetchContent_MakeAvailable(unity)
target_compile_definitions(unity PUBLIC UNITY_INCLUDE_DOUBLE UNITY_SUPPORT_64 UNITY_INCLUDE_PRINT_FORMATTED)
