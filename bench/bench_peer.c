/* prru_dynamics against its SymPy peer (bench/sympy_peer.py: the same
 * poses, M, h and G derived and printed by SymPy, sympy.cse, C99 printer),
 * compiled from the build tree with the same flags as the kernels. The peer
 * must agree with prru_dynamics to 1e-12 at every bench state (relative to
 * the largest entry of M, h, G) before it is timed; then batches of the two
 * are interleaved and the median of the per-repetition ratio reported. */
#include <math.h>
#include <stdio.h>

#include "bench.h"

#ifdef PRRU_BENCH_HAVE_SYMPY_PEER
#include "sympy_peer.c"
#endif

#define PEER_TOL 1e-12

bench_peer bench_peer_result;

#ifdef PEER_DERIVE_S
static double rel(const double *a, const double *b, int n)
{
  double e = 0, s = 1e-300;
  for (int i = 0; i < n; i++) {
    if (!(fabs(a[i] - b[i]) <= e)) e = fabs(a[i] - b[i]);
    if (fabs(b[i]) > s) s = fabs(b[i]);
  }
  return e / s;
}

static double run(const bench_ctx *c, long n, int peer)
{
  double M[9], h[3], G[3], acc = 0;
  double t0 = bench_now_ns();
  for (long i = 0; i < n; i++) {
    const bench_state *s = &c->st[i & (NSTATES - 1)];
    if (peer)
      peer_dynamics(s->q, s->qd, M, h, G);
    else
      prru_dynamics(s->q, s->qd, M, h, G);
    /* Every output feeds the sink, or the compiler could drop the inlined
     * side's unused entries. */
    for (int j = 0; j < 9; j++) acc += M[j];
    acc += h[0] + h[1] + h[2] + G[0] + G[1] + G[2];
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc;
  return t / (double)n;
}
#endif

void bench_peer_run(const bench_ctx *c, int reps, int quick, bench_peer *r)
{
  r->available = 0;
  r->reason = "SymPy was not importable when the bench was configured";
#if defined(PEER_UNAVAILABLE)
  r->reason = PEER_UNAVAILABLE;
  (void)c, (void)reps, (void)quick;
#elif defined(PEER_DERIVE_S)
  r->derive_s = PEER_DERIVE_S;
  r->cse_s = PEER_CSE_S;
  r->max_rel_diff = 0;
  for (int k = 0; k < NSTATES; k++) {
    double M[9], h[3], G[3], Mp[9], hp[3], Gp[3];
    prru_dynamics(c->st[k].q, c->st[k].qd, M, h, G);
    peer_dynamics(c->st[k].q, c->st[k].qd, Mp, hp, Gp);
    double e = fmax(rel(Mp, M, 9), fmax(rel(hp, h, 3), rel(Gp, G, 3)));
    if (!(e <= r->max_rel_diff)) r->max_rel_diff = e;
  }
  if (!(r->max_rel_diff <= PEER_TOL)) {
    r->reason = "the peer disagrees with prru_dynamics beyond 1e-12: not timed";
    return;
  }
  const long n = quick ? 4 * NSTATES : 512 * NSTATES;
  double ours[MAXREPS], peer[MAXREPS], ratio[MAXREPS];
  run(c, n, 0);
  run(c, n, 1);
  for (int i = 0; i < reps; i++) {
    ours[i] = run(c, n, 0);
    peer[i] = run(c, n, 1);
    ratio[i] = peer[i] / ours[i];
  }
  r->ours_ns = bench_stats_of(ours, reps);
  r->peer_ns = bench_stats_of(peer, reps);
  r->ratio = bench_stats_of(ratio, reps);
  r->available = 1;
#else
  (void)c, (void)reps, (void)quick;
#endif
}

void bench_peer_print_table(const bench_peer *r)
{
  if (!r->available) {
    printf("SymPy peer of dynamics: not timed (%s)\n\n", r->reason);
    return;
  }
  printf("dynamics (M, h, G) against its SymPy peer (derivation %.1f s + cse %.1f s, cached in the\n"
         "build tree; agreement %.1e), interleaved batches, same flags:\n"
         "  generated %.1f ns, SymPy peer %.1f ns: %.2fx [%.2f-%.2f]\n\n",
         r->derive_s, r->cse_s, r->max_rel_diff, r->ours_ns.median, r->peer_ns.median,
         r->ratio.median, r->ratio.min, r->ratio.max);
}

void bench_peer_print_json(const bench_peer *r)
{
  if (!r->available) {
    printf(", \"sympy_peer\": {\"timed\": false, \"reason\": \"%s\"}", r->reason);
    return;
  }
  printf(", \"sympy_peer\": {\"timed\": true, \"generated_ns\": %.4g, \"peer_ns\": %.4g, "
         "\"ratio\": {\"median\": %.4g, \"min\": %.4g, \"max\": %.4g}, \"max_rel_diff\": %.3g, "
         "\"derive_s\": %.3g, \"cse_s\": %.3g}",
         r->ours_ns.median, r->peer_ns.median, r->ratio.median, r->ratio.min, r->ratio.max,
         r->max_rel_diff, r->derive_s, r->cse_s);
}
