# SPDX-License-Identifier: Apache-2.0
# Cortex-M0+ (ARMv6-M), no FPU: soft float (e.g. RP2040, STM32G0, SAMD21). Runs on QEMU's
# Cortex-M0 (-M microbit), which implements the same ARMv6-M instruction set.
set(ICOAC_CPU_FLAGS "-mcpu=cortex-m0plus -mthumb -mfloat-abi=soft")
set(ICOAC_TARGET_CORE cortex-m0plus)
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi.cmake)
