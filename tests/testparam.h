/* The parameter kernels take the numbers derived from a design
 * (prru_param_derived, prru_param_derive: what depends on the numbers
 * alone, computed once). The tests change designs between calls and call
 * the kernels a few thousand times, so they derive at every call:
 * tp_derived(p) fills one of four static buffers in turn (so that up to
 * four can be live at once) and returns it. Single-threaded. */
#ifndef PRRU_TESTPARAM_H
#define PRRU_TESTPARAM_H
#include "testbuild.h"

static const prru_param_derived *tp_derived(const prru_params *p)
{
  static prru_param_derived buf[4];
  static int next;
  prru_param_derived *d = &buf[next++ % 4];
  prru_params_derive(p, d);
  return d;
}

#endif
