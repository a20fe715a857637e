# SPDX-License-Identifier: Apache-2.0
# The firmware unit tests (tests/c/<name>.c) that also run on the Cortex-M cores under QEMU: add
# a test's name here and it is cross-built (tests/unit_target) and run by the host's ctest
# (tests/target) on both cores.
set(ICOAC_TARGET_UNIT_TESTS test_rng test_fast_exp)

# Of those, the ones too big for the Cortex-M0+ board (QEMU microbit, 16 KiB RAM): Cortex-M4F
# only. Each such test says why at its top.
set(ICOAC_TARGET_UNIT_TESTS_M4F_ONLY)
