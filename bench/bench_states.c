/* The inputs prru_bench times the kernels on, and the agreement of the
 * generated and the reference side on every one of them. */
#include <math.h>

#include "bench.h"

/* Deterministic xorshift64*, so every run times the same inputs. */
static unsigned long long rng_state = 0x2545F4914F6CDD1DULL;
static double uniform(double lo, double hi)
{
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  unsigned long long r = rng_state * 2685821657736338717ULL;
  return lo + (hi - lo) * ((double)(r >> 11) / 9007199254740992.0);
}

/* |det| of rows a, b, c of J (NACT x 3) over the product of their norms:
 * 1 for orthogonal rows, 0 for dependent ones. */
static double rows_det(const double *J, int a, int b, int c)
{
  const double *x = J + 3 * a, *y = J + 3 * b, *z = J + 3 * c;
  double det = x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) +
               x[2] * (y[0] * z[1] - y[1] * z[0]);
  double rows = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) *
                sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]) *
                sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
  return fabs(det) / rows;
}

/* Reachable states well away from singular J_d (row-scaled |det| > 0.05,
 * far above the runtime's rcond 1e-8; with more than three actuators, of
 * the best three of J_d's rows, which bounds J_d's rank-3 conditioning
 * alike), spread over the region the paper's scenario and workspace map
 * visit, so that no kernel is timed on an error path and the solves are
 * not near-singular. The draws for the first three actuators come first,
 * so a 3-limb model gets the same states whatever PRRU_NACT allows. */
int bench_make_states(bench_ctx *c)
{
  prru_params_derive(&prru_params_model, &c->pd);
  int n = 0;
  for (long attempt = 0; attempt < 100000 && n < NSTATES; attempt++) {
    bench_state *s = &c->st[n];
    s->q[0] = uniform(-0.35, 0.35);
    s->q[1] = uniform(-0.5, 0.6);
    s->q[2] = uniform(-1.0, 0.2);
    double d[PRRU_NACT], J[3 * PRRU_NACT];
    prru_ik_jd(s->q, d, J);
    int reachable = 1;
    for (int i = 0; i < PRRU_NACT; i++) reachable &= isfinite(d[i]) != 0;
    if (!reachable)
      continue;
    double best = 0.0;
    for (int a = 0; a < PRRU_NACT; a++)
      for (int b = a + 1; b < PRRU_NACT; b++)
        for (int e = b + 1; e < PRRU_NACT; e++) best = fmax(best, rows_det(J, a, b, e));
    if (!(best > 0.05))
      continue;
    for (int i = 0; i < 3; i++) {
      s->qd[i] = uniform(-1.0, 1.0);
      s->qdd[i] = uniform(-5.0, 5.0);
      s->l.fd[i] = uniform(-100.0, 100.0);
      s->l.fp[i] = uniform(-50.0, 50.0);
      s->l.mp[i] = uniform(-5.0, 5.0);
    }
    for (int i = 3; i < PRRU_NACT; i++) s->l.fd[i] = uniform(-100.0, 100.0);
    n++;
  }
  return n == NSTATES ? 0 : -1;
}

/* ---- Agreement: both sides on every state ---- */

/* max over states of max_i |gen_i - ref_i| / max_i |ref_i|: relative to the
 * output's scale, so structurally-zero entries do not demand exact zeros.
 * Returns the failing side's status (and the state) if a call fails. */
int bench_agreement(bench_ctx *c, bench_kernel *k, int *bad_state)
{
  double g[MAXOUT], r[MAXOUT];
  k->max_rel_diff = 0.0;
  for (int i = 0; i < NSTATES; i++) {
    int st = k->gen_eval(c, &c->st[i], g);
    if (st == 0) st = k->ref_eval(c, &c->st[i], r);
    if (st != 0) {
      *bad_state = i;
      return st;
    }
    double err = 0.0, scale = 1e-300;
    for (int j = 0; j < k->nout; j++) {
      double e = fabs(g[j] - r[j]);
      if (!(e <= err)) err = e; /* NaN propagates */
      if (fabs(r[j]) > scale) scale = fabs(r[j]);
    }
    if (!(err / scale <= k->max_rel_diff)) k->max_rel_diff = err / scale;
  }
  return 0;
}

