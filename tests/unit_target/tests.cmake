# SPDX-License-Identifier: Apache-2.0
# The firmware unit tests (tests/c/<name>.c) that also run on the Cortex-M cores under QEMU: add
# a test's name here and it is cross-built (tests/unit_target) and run by the host's ctest
# (tests/target) on both cores. Each must fit the Cortex-M0+ board's 16 KiB of RAM.
set(ICOAC_TARGET_UNIT_TESTS test_config test_ico test_properties test_rng test_critic test_actor test_contract
                            test_control test_misuse test_readings test_search test_fast_exp)

