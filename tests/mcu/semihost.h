/* ARM semihosting output and exit (tests/mcu/startup.c). */
#ifndef SEMIHOST_H
#define SEMIHOST_H
#include <stdint.h>
void sh_puts(const char *s);
void sh_hex(uint32_t w); /* 8 hex digits and a space */
void sh_exit(int status);
#endif
