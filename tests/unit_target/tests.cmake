# SPDX-License-Identifier: Apache-2.0
# The firmware unit tests (tests/c/<name>.c) that also run on the Cortex-M cores under QEMU: add
# a test's name here and it is cross-built (tests/unit_target) and run by the host's ctest
# (tests/target) on both cores.
set(ICOAC_TARGET_UNIT_TESTS test_config test_ico test_properties test_rng test_critic test_actor test_contract
                            test_control test_misuse test_readings test_search test_fast_exp)

# Of those, the ones too big for the Cortex-M0+ board (QEMU microbit, 16 KiB RAM): Cortex-M4F
# only. test_critic: 15 KB of static scratch arrays (KMAX doubles) and 9.4 KB of stack;
# test_control: 32 KB of recorded trajectories (1000 ticks of doubles).
set(ICOAC_TARGET_UNIT_TESTS_M4F_ONLY test_critic test_control)
