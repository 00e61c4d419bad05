/* Minimal bare-metal start for the MPS2 boards QEMU emulates (AN386:
 * Cortex-M4, AN500: Cortex-M7): the vector table, a reset handler that
 * enables the FPU, copies .data and zeroes .bss, and ARM semihosting for
 * output and the exit status (QEMU's -semihosting). No C library start-up:
 * the firmware links only what it calls. */
#include <stdint.h>

#include "semihost.h"

extern uint32_t __stack_top, __data_load, __data_start, __data_end, __bss_start, __bss_end;
int main(void);

static int semihost(int op, const void *arg)
{
  register int r0 __asm__("r0") = op;
  register const void *r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

void sh_puts(const char *s)
{
  semihost(0x04, s); /* SYS_WRITE0 */
}

void sh_exit(int status)
{
  /* SYS_EXIT, 32-bit form: the reason itself; QEMU exits 0 for
   * ADP_Stopped_ApplicationExit, 1 for any other reason. */
  semihost(0x18, (const void *)(uintptr_t)(status == 0 ? 0x20026 : 0x20023));
  for (;;) {
  }
}

void sh_hex(uint32_t w)
{
  static const char digit[] = "0123456789abcdef";
  char s[10];
  for (int i = 0; i < 8; i++) s[i] = digit[(w >> (28 - 4 * i)) & 0xfu];
  s[8] = ' ';
  s[9] = 0;
  sh_puts(s);
}

void reset_handler(void);
void reset_handler(void)
{
  /* CP10 and CP11 full access (CPACR), then the pipeline sees it. */
  volatile uint32_t *cpacr = (volatile uint32_t *)0xE000ED88u;
  *cpacr |= 0xFu << 20;
  __asm__ volatile("dsb\n\tisb" ::: "memory");
  const uint32_t *src = &__data_load;
  for (uint32_t *dst = &__data_start; dst < &__data_end;) *dst++ = *src++;
  for (uint32_t *dst = &__bss_start; dst < &__bss_end;) *dst++ = 0;
  sh_exit(main());
}

static void fault_handler(void)
{
  sh_puts("FAIL: fault\n");
  sh_exit(1);
}

__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
  (void (*)(void))(uintptr_t)&__stack_top, reset_handler, fault_handler, fault_handler,
  fault_handler, fault_handler, fault_handler, 0, 0, 0, 0, fault_handler, fault_handler, 0,
  fault_handler, fault_handler,
};
