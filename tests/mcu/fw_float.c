/* The Cortex-M4 firmware of tests/test_mcu.sh: the single-precision
 * controller set on the states the host drew (mcu_states.h, written by
 * test_float_kernels --states), and newlib's float functions over a sweep;
 * every value printed as its bit pattern, for the host to compare
 * (test_float_kernels --mcu). The descriptor's identity comes first, so the
 * host knows which model the firmware was built from. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "mcu_ctl.h"
#include "mcu_states.h"
#include "prru_mechanism.h"
#include "semihost.h"

static void put_words(const float *v, unsigned n)
{
  for (unsigned i = 0; i < n; i++) {
    uint32_t w;
    memcpy(&w, v + i, sizeof w);
    sh_hex(w);
  }
}

/* volatile: the compiler must neither fold nor hoist the calls. */
static volatile float sink;

static void sweep(const char *name, int fn, float lo, float hi, unsigned n)
{
  for (unsigned k = 0; k < n; k++) {
    float x = lo + (hi - lo) * ((float)k + 0.5f) / (float)n, y;
    switch (fn) {
    case 0: y = sinf(x); break;
    case 1: y = cosf(x); break;
    case 2: y = sqrtf(x); break;
    case 3: y = tanhf(x); break;
    case 4: y = acosf(x); break;
    default: y = atan2f(x, 0.75f); break;
    }
    sink = y;
    sh_puts("F ");
    sh_puts(name);
    sh_puts(" ");
    put_words(&x, 1);
    put_words(&y, 1);
    sh_puts("\n");
  }
}

int main(void)
{
  sh_puts("M ");
  sh_puts(prru_mech.name);
  sh_puts(" ");
  sh_puts(prru_mech.sha256);
  sh_puts("\n");
  for (unsigned s = 0; s < sizeof mcu_states / sizeof mcu_states[0]; s++) {
    mcu_in x;
    mcu_out y;
    memcpy(&x, mcu_states[s], sizeof x);
    mcu_eval(&x, &y);
    sh_puts("S ");
    put_words((const float *)&x, MCU_IN_WORDS);
    sh_puts(": ");
    put_words((const float *)&y, MCU_OUT_WORDS);
    sh_puts("\n");
  }
  const unsigned n = MCU_SWEEP;
  sweep("sinf", 0, -8.0f, 8.0f, n);
  sweep("sinf", 0, -1000.0f, 1000.0f, n);
  sweep("cosf", 1, -8.0f, 8.0f, n);
  sweep("cosf", 1, -1000.0f, 1000.0f, n);
  sweep("sqrtf", 2, 0.0f, 4.0f, n);
  sweep("tanhf", 3, -10.0f, 10.0f, n);
  sweep("acosf", 4, -1.0f, 1.0f, n);
  sweep("atan2f", 5, -4.0f, 4.0f, n);
  sh_puts("E\n");
  return 0;
}
