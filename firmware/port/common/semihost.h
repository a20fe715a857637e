/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal ARM semihosting (bkpt 0xab): no newlib rdimon, hence no heap. */
#ifndef ICOAC_PORT_SEMIHOST_H
#define ICOAC_PORT_SEMIHOST_H

void semihost_write0(const char *s);
void semihost_exit(int code) __attribute__((noreturn));

#endif
