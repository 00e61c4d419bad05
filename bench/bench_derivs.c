/* The closed-form derivatives (prru_linearize.h) against what they
 * replace, batches interleaved and the ratios taken per repetition (the
 * machine is shared: a load that comes and goes scales both sides):
 *   - the fused kernel prru_eom_solve_derivs (qdd and every block) and
 *     prru_linearize (the kernel, the forward step's trust test, A and B)
 *     against the forward step prru_forward_dynamics (target <= 3x);
 *   - central differences of the forward step for the same A and B
 *     (2 (6 + NACT) forward steps) against prru_linearize (target: the
 *     closed form >= 4x faster);
 *   - prru_inverse_derivs / prru_inverse_dynamics_derivs (three
 *     actuators) against prru_inverse_dynamics (target <= 3x);
 *   - the batched forms over the same NSTATES states (issue 29, target
 *     >= 3.5x): prru_batch_eom_solve_derivs against the loop of
 *     prru_eom_solve_derivs, prru_linearize_batch (dt = 0) against the
 *     loop of prru_linearize. */
#include <math.h>
#include <string.h>

#include "bench.h"
#include "prru_derivs.h"
#include "prru_kernels.h"
#include "prru_linearize.h"

bench_derivs bench_derivs_result;

enum { FWD, KERNEL_FUSED, LINEARIZE, CENTRAL, KERNEL_BATCH, LINEARIZE_BATCH, INV, INV_KERNEL, INV_DERIVS,
       NSIDES };

/* The states in the batched kernels' layout (rows of NSTATES), 64-byte
 * aligned as the generated header asks, and their outputs. */
enum { NDER = 9 + 9 + 3 * PRRU_NACT + 9 + 9 };
static struct {
  double q[3 * NSTATES], qd[3 * NSTATES], fd[PRRU_NACT * NSTATES], fp[3 * NSTATES], mp[3 * NSTATES];
  double M[9 * NSTATES], b[3 * NSTATES], qdd[3 * NSTATES], mn[3 * NSTATES], D[NDER * NSTATES];
  double aq[3 * NSTATES], aqd[3 * NSTATES];
  prru_loads l[NSTATES];
  int st[NSTATES];
} soa __attribute__((aligned(64)));
static prru_linearization lin[NSTATES];

static void soa_fill(const bench_ctx *c)
{
  for (int k = 0; k < NSTATES; k++) {
    const bench_state *s = &c->st[k];
    for (int i = 0; i < 3; i++) {
      soa.q[i * NSTATES + k] = soa.aq[3 * k + i] = s->q[i];
      soa.qd[i * NSTATES + k] = soa.aqd[3 * k + i] = s->qd[i];
      soa.fp[i * NSTATES + k] = s->l.fp[i];
      soa.mp[i * NSTATES + k] = s->l.mp[i];
    }
    for (int i = 0; i < PRRU_NACT; i++) soa.fd[i * NSTATES + k] = s->l.fd[i];
    soa.l[k] = s->l;
  }
}

static void run_side(bench_ctx *c, int side, long n)
{
  double acc = 0;
  long bad = 0;
  for (long k = 0; k < n; k++) {
    const bench_state *s = &c->st[k & (NSTATES - 1)];
    double out[PRRU_NACT], M[9], b[3], qdd[3], mn[3], D[5][9 + 3 * PRRU_NACT];
    prru_linearization o;
    switch (side) {
    case FWD:
      bad += prru_forward_dynamics(&c->m, c->d, s->q, s->qd, &s->l, out) != 0;
      acc += out[k % 3];
      break;
    case KERNEL_FUSED:
      prru_eom_solve_derivs(s->q, s->qd, s->l.fd, s->l.fp, s->l.mp, M, b, qdd, mn, D[0], D[1], D[2],
                            D[3], D[4]);
      acc += D[k % 5][k % 9] + qdd[0];
      break;
    case LINEARIZE:
      bad += prru_linearize(&c->m, c->d, s->q, s->qd, &s->l, 0.0, &o) != 0;
      acc += o.A[18 + k % 18] + o.B[9 + k % 3];
      break;
    case CENTRAL: {
      /* The columns of A's lower half and of B: d qdd / d (q, qd, fd). */
      double x[6 + PRRU_NACT], col[3];
      prru_loads l = s->l;
      memcpy(x, s->q, sizeof s->q), memcpy(x + 3, s->qd, sizeof s->qd);
      memcpy(x + 6, s->l.fd, PRRU_NACT * sizeof(double));
      for (int j = 0; j < 6 + PRRU_NACT; j++) {
        const double h = 1e-6 * (1 + fabs(x[j]));
        double up[3], dn[3], y[6 + PRRU_NACT];
        memcpy(y, x, sizeof y);
        y[j] = x[j] + h;
        memcpy(l.fd, y + 6, PRRU_NACT * sizeof(double));
        bad += prru_forward_dynamics(&c->m, c->d, y, y + 3, &l, up) != 0;
        y[j] = x[j] - h;
        memcpy(l.fd, y + 6, PRRU_NACT * sizeof(double));
        bad += prru_forward_dynamics(&c->m, c->d, y, y + 3, &l, dn) != 0;
        for (int i = 0; i < 3; i++) col[i] = (up[i] - dn[i]) / (2 * h);
        acc += col[j % 3];
      }
      break;
    }
    case KERNEL_BATCH: /* one call in NSTATES does the next NSTATES states */
      if ((k & (NSTATES - 1)) == 0) {
        double *Dv = soa.D;
        prru_batch_eom_solve_derivs(NSTATES, soa.q, soa.qd, soa.fd, soa.fp, soa.mp, soa.M, soa.b, soa.qdd,
                                    soa.mn, Dv, Dv + 9 * NSTATES, Dv + 18 * NSTATES,
                                    Dv + (18 + 3 * PRRU_NACT) * NSTATES, Dv + (27 + 3 * PRRU_NACT) * NSTATES);
        acc += soa.D[k % (NDER * NSTATES)] + soa.qdd[k % 3];
      }
      break;
    case LINEARIZE_BATCH:
      if ((k & (NSTATES - 1)) == 0) {
        bad += prru_linearize_batch(&c->m, NSTATES, soa.aq, soa.aqd, soa.l, 0.0, lin, soa.st) != 0;
        acc += lin[k % NSTATES].A[18 + k % 18] + lin[(k + 7) % NSTATES].B[9 + k % 3];
      }
      break;
    case INV:
      bad += prru_inverse_dynamics(&c->m, c->d, s->q, s->qd, s->qdd, &s->l, out) != 0;
      acc += out[k % 3];
      break;
#if PRRU_NACT == 3
    case INV_KERNEL: {
      double d[3], Jd[9], Ji[9], fd[3];
      prru_inverse_derivs(s->q, s->qd, s->qdd, s->l.fp, s->l.mp, d, Jd, Ji, fd, D[0], D[1], D[2]);
      acc += D[k % 3][k % 9] + fd[0];
      break;
    }
    case INV_DERIVS: {
      double fd[3];
      bad += prru_inverse_dynamics_derivs(&c->m, c->d, s->q, s->qd, s->qdd, &s->l, fd, D[0], D[1],
                                          D[2]) != 0;
      acc += D[k % 3][k % 9] + fd[0];
      break;
    }
#endif
    default:
      break;
    }
  }
  bench_sink += acc;
  c->failures += bad;
}

static double batch_ns(bench_ctx *c, int side, long n)
{
  const double t0 = bench_now_ns();
  run_side(c, side, n);
  return (bench_now_ns() - t0) / (double)n;
}

static long calls_for(bench_ctx *c, int side, double target_ns)
{
  long n = NSTATES;
  while (n < (1L << 26) && batch_ns(c, side, n) * (double)n < target_ns) n *= 2;
  return n;
}

void bench_derivs_run(bench_ctx *c, int reps, double target_ns, bench_derivs *r)
{
  const int nsides = PRRU_NACT == 3 ? NSIDES : INV;
  long n[NSIDES];
  double t[NSIDES][MAXREPS], ratio[6][MAXREPS];
  memset(r, 0, sizeof *r);
  r->available = prru_linearize_available(&c->m);
  if (!r->available) return;
  soa_fill(c);
  for (int s = 0; s < nsides; s++) n[s] = (calls_for(c, s, target_ns) + NSTATES - 1) & ~(long)(NSTATES - 1);
  for (int i = 0; i < reps; i++) {
    for (int s = 0; s < nsides; s++) t[s][i] = batch_ns(c, s, n[s]);
    ratio[0][i] = t[KERNEL_FUSED][i] / t[FWD][i];
    ratio[1][i] = t[LINEARIZE][i] / t[FWD][i];
    ratio[2][i] = t[CENTRAL][i] / t[LINEARIZE][i];
    ratio[3][i] = PRRU_NACT == 3 ? t[INV_DERIVS][i] / t[INV][i] : 0;
    ratio[4][i] = t[KERNEL_FUSED][i] / t[KERNEL_BATCH][i];
    ratio[5][i] = t[LINEARIZE][i] / t[LINEARIZE_BATCH][i];
  }
  bench_stats *ns[NSIDES] = {&r->forward_ns,         &r->fused_kernel_ns,    &r->linearize_ns,
                             &r->central_ns,         &r->batch_kernel_ns,    &r->batch_linearize_ns,
                             &r->inverse_ns,         &r->inverse_kernel_ns,  &r->inverse_derivs_ns};
  for (int s = 0; s < nsides; s++) *ns[s] = bench_stats_of(t[s], reps);
  r->fused_over_forward = bench_stats_of(ratio[0], reps);
  r->linearize_over_forward = bench_stats_of(ratio[1], reps);
  r->central_over_linearize = bench_stats_of(ratio[2], reps);
  if (PRRU_NACT == 3) r->inverse_derivs_over_inverse = bench_stats_of(ratio[3], reps);
  r->batch_kernel_speedup = bench_stats_of(ratio[4], reps);
  r->batch_linearize_speedup = bench_stats_of(ratio[5], reps);
  r->inverse_available = PRRU_NACT == 3;
}

void bench_derivs_print_table(const bench_derivs *r)
{
  if (!r->available) {
    printf("derivatives: not measured (the model does not evaluate with the specialised kernels)\n\n");
    return;
  }
  printf("closed-form derivatives (ns a call, median; ratios per repetition):\n");
  printf("  forward step prru_forward_dynamics    %8.1f\n", r->forward_ns.median);
  printf("  fused kernel prru_eom_solve_derivs    %8.1f  %.2fx the forward step (target <= 3)\n",
         r->fused_kernel_ns.median, r->fused_over_forward.median);
  printf("  prru_linearize (kernel, test, A, B)   %8.1f  %.2fx the forward step\n",
         r->linearize_ns.median, r->linearize_over_forward.median);
  printf("  central differences of the step       %8.1f  %.2fx prru_linearize (target >= 4)\n",
         r->central_ns.median, r->central_over_linearize.median);
  printf("  batched prru_batch_eom_solve_derivs  %8.1f  %.2fx [%.2f-%.2f] the scalar kernel's loop "
         "(target >= 3.5)\n",
         r->batch_kernel_ns.median, r->batch_kernel_speedup.median, r->batch_kernel_speedup.min,
         r->batch_kernel_speedup.max);
  printf("  batched prru_linearize_batch          %8.1f  %.2fx [%.2f-%.2f] prru_linearize's loop\n",
         r->batch_linearize_ns.median, r->batch_linearize_speedup.median, r->batch_linearize_speedup.min,
         r->batch_linearize_speedup.max);
  if (r->inverse_available) {
    printf("  inverse dynamics                      %8.1f\n", r->inverse_ns.median);
    printf("  inverse_derivs kernel                 %8.1f\n", r->inverse_kernel_ns.median);
    printf("  prru_inverse_dynamics_derivs          %8.1f  %.2fx inverse dynamics (target <= 3)\n",
           r->inverse_derivs_ns.median, r->inverse_derivs_over_inverse.median);
  }
  printf("\n");
}

void bench_derivs_print_json(const bench_derivs *r)
{
  if (!r->available) {
    printf(", \"derivs\": null");
    return;
  }
  printf(", \"derivs\": {\"nact\": %d, \"forward_ns\": %.4g, \"fused_kernel_ns\": %.4g, \"linearize_ns\": %.4g, "
         "\"central_differences_ns\": %.4g, \"fused_over_forward\": %.4g, "
         "\"linearize_over_forward\": %.4g, \"central_over_linearize\": %.4g",
         PRRU_NACT, r->forward_ns.median, r->fused_kernel_ns.median, r->linearize_ns.median,
         r->central_ns.median, r->fused_over_forward.median, r->linearize_over_forward.median,
         r->central_over_linearize.median);
  printf(", \"batch_kernel_ns\": %.4g, \"batch_linearize_ns\": %.4g, \"batch_kernel_speedup\": %.4g, "
         "\"batch_linearize_speedup\": %.4g",
         r->batch_kernel_ns.median, r->batch_linearize_ns.median, r->batch_kernel_speedup.median,
         r->batch_linearize_speedup.median);
  if (r->inverse_available)
    printf(", \"inverse_ns\": %.4g, \"inverse_kernel_ns\": %.4g, \"inverse_derivs_ns\": %.4g, "
           "\"inverse_derivs_over_inverse\": %.4g",
           r->inverse_ns.median, r->inverse_kernel_ns.median, r->inverse_derivs_ns.median,
           r->inverse_derivs_over_inverse.median);
  printf("}");
}
