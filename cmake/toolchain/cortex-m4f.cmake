# SPDX-License-Identifier: Apache-2.0
# Cortex-M4 with single-precision FPU, hard-float ABI (e.g. STM32F4, nRF52, QEMU mps2-an386).
set(ICOAC_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(ICOAC_TARGET_CORE cortex-m4f)
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi.cmake)
