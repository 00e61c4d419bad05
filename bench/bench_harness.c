/* Timing one kernel: calibrated batches, generated and reference side
 * interleaved. */
#include "bench.h"

static double batch_ns(batch_fn f, bench_ctx *c, long n)
{
  double t0 = bench_now_ns();
  f(c, n);
  return bench_now_ns() - t0;
}

/* Calls per batch so that one batch lasts about target_ns; a whole number of
 * passes over the state table so every state weighs the same. */
static long calibrate(batch_fn f, bench_ctx *c, double target_ns)
{
  long n = NSTATES;
  for (;;) {
    double t = batch_ns(f, c, n);
    if (t >= target_ns || n >= (1L << 30)) break;
    double grow = t > 0 ? 1.2 * target_ns / t : 16.0;
    if (grow < 2.0) grow = 2.0;
    if (grow > 16.0) grow = 16.0;
    n = ((long)(n * grow) + NSTATES - 1) / NSTATES * NSTATES;
  }
  return n;
}

void bench_time_kernel(bench_ctx *c, bench_kernel *k, int reps, double target_ns)
{
  double g[MAXREPS], r[MAXREPS];
  long ng = calibrate(k->gen_batch, c, target_ns);
  long nr = calibrate(k->ref_batch, c, target_ns);
  batch_ns(k->gen_batch, c, ng); /* warm-up at the final batch size */
  batch_ns(k->ref_batch, c, nr);
  for (int i = 0; i < reps; i++) {
    g[i] = batch_ns(k->gen_batch, c, ng) / (double)ng;
    r[i] = batch_ns(k->ref_batch, c, nr) / (double)nr;
  }
  k->gen = bench_stats_of(g, reps);
  k->ref = bench_stats_of(r, reps);
}


/* The cost of a runtime-parameter kernel p against its constant-folded
 * namesake k: batches of the two interleaved, and per repetition the ratio
 * of their per-call times, so that a load that comes and goes during the
 * run (the machine is shared) scales both sides of each ratio alike. */
void bench_time_cost(bench_ctx *c, bench_kernel *p, const bench_kernel *k, int reps,
                     double target_ns)
{
  double tp[MAXREPS], tk[MAXREPS], ratio[MAXREPS];
  long np = calibrate(p->gen_batch, c, target_ns);
  long nk = calibrate(k->gen_batch, c, target_ns);
  batch_ns(p->gen_batch, c, np);
  batch_ns(k->gen_batch, c, nk);
  for (int i = 0; i < reps; i++) {
    tp[i] = batch_ns(p->gen_batch, c, np) / (double)np;
    tk[i] = batch_ns(k->gen_batch, c, nk) / (double)nk;
    ratio[i] = tp[i] / tk[i];
  }
  p->cost_param = bench_stats_of(tp, reps);
  p->cost_constant = bench_stats_of(tk, reps);
  p->cost = bench_stats_of(ratio, reps);
}
