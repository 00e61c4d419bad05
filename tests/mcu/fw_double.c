/* The Cortex-M7 (double-precision FPU) firmware of tests/test_mcu.sh: the
 * double controller set, for its code sizes, and run under QEMU
 * (mps2-an500) on the first of the host's states (mcu_states.h): exit 0
 * when every output is finite there (a reachable pose with a regular
 * J_d), so the set is shown to run on the M7's FPU. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "mcu_ctl.h"
#include "mcu_states.h"
#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "semihost.h"

static int all_finite(const double *v, int n)
{
  int ok = 1;
  for (int i = 0; i < n; i++) ok = ok && isfinite(v[i]);
  return ok;
}

static void widen(const float *f, double *d, int n)
{
  for (int i = 0; i < n; i++) d[i] = f[i];
}

int main(void)
{
  mcu_in x;
  memcpy(&x, mcu_states[0], sizeof x);
  double q[3], qd[3], qdd[3], fd[PRRU_NACT], fp[3], mp[3];
  widen(x.q, q, 3);
  widen(x.qd, qd, 3);
  widen(x.qdd, qdd, 3);
  widen(x.fd, fd, PRRU_NACT);
  widen(x.fp, fp, 3);
  widen(x.mp, mp, 3);
  double d[PRRU_NACT], Jd[PRRU_NACT * 3], M[9], h[3], G[3], b[3], qdds[3], minors[3];
  prru_ik_jd(q, d, Jd);
  int ok = all_finite(d, PRRU_NACT) && all_finite(Jd, PRRU_NACT * 3);
  prru_dynamics(q, qd, M, h, G);
  ok = ok && all_finite(M, 9) && all_finite(h, 3) && all_finite(G, 3);
  prru_eom_solve(q, qd, fd, fp, mp, M, b, qdds, minors);
  ok = ok && all_finite(b, 3) && all_finite(qdds, 3) && all_finite(minors, 3);
#if PRRU_NACT == 3
  double Jdinv[9], fdo[3];
  prru_inverse_terms(q, qd, qdd, fp, mp, d, Jd, Jdinv, fdo);
  ok = ok && all_finite(Jdinv, 9) && all_finite(fdo, 3);
#else
  double tau[3];
  prru_inverse_terms(q, qd, qdd, fp, mp, d, Jd, tau);
  ok = ok && all_finite(tau, 3);
#endif
  sh_puts(prru_mech.name);
  sh_puts(ok ? ": double set finite on the M7\n" : ": FAIL: a double output is not finite\n");
  return ok ? 0 : 1;
}
