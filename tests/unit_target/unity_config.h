/* SPDX-License-Identifier: Apache-2.0 */
/* Unity's configuration on the cores (UNITY_INCLUDE_CONFIG_H): output over semihosting, a line
 * at a time (target_main.c). */
#ifndef ICOAC_UNITY_CONFIG_H
#define ICOAC_UNITY_CONFIG_H

#define UNITY_OUTPUT_CHAR(c) icoac_unit_putchar(c)
#define UNITY_OUTPUT_CHAR_HEADER_DECLARATION icoac_unit_putchar(int c)
#define UNITY_OUTPUT_FLUSH() icoac_unit_flush()
#define UNITY_OUTPUT_FLUSH_HEADER_DECLARATION icoac_unit_flush(void)

#endif
