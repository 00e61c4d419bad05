/* The Cortex-M7 (double-precision FPU) firmware of tests/test_mcu.sh, for
 * its code sizes: the double controller set on one state. Linked, not run:
 * the float set's run on the M4 covers the emulated arithmetic. */
#include <stdint.h>

#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "semihost.h"

/* volatile: the calls' inputs are unknown to the compiler. */
static volatile double in[3 * 5 + PRRU_NACT];

int main(void)
{
  double q[3], qd[3], qdd[3], fd[PRRU_NACT], fp[3], mp[3];
  double d[PRRU_NACT], Jd[PRRU_NACT * 3], M[9], h[3], G[3], b[3], x[3], minors[3];
#if PRRU_NACT == 3
  double o[9];
#endif
  for (int i = 0; i < 3; i++) {
    q[i] = in[i];
    qd[i] = in[3 + i];
    qdd[i] = in[6 + i];
    fp[i] = in[9 + i];
    mp[i] = in[12 + i];
  }
  for (int i = 0; i < PRRU_NACT; i++) fd[i] = in[15 + i];
  prru_ik_jd(q, d, Jd);
  prru_dynamics(q, qd, M, h, G);
  prru_eom_solve(q, qd, fd, fp, mp, M, b, x, minors);
#if PRRU_NACT == 3
  prru_inverse_terms(q, qd, qdd, fp, mp, d, Jd, o, x);
#else
  prru_inverse_terms(q, qd, qdd, fp, mp, d, Jd, x);
#endif
  double sum = x[0] + M[0] + h[0] + G[0] + minors[0] + b[0];
#if PRRU_NACT == 3
  sum += o[0];
#endif
  sh_puts(prru_mech.name);
  return sum > 0.0;
}
