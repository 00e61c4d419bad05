/* Side-by-side cost, ours vs MuJoCo 2.2.2 on the same mechanism, same run.
 *
 * usage: bench_mujoco PRRU_MJCF.xml [repetitions]
 *
 * 1. One forward-dynamics call at the same state and loads (the spec's
 *    reference state q = (0.1, 0.2, -0.8), qd = (0.3, -0.4, 0.5), paper
 *    loads at t = 0): prru_forward_dynamics vs mj_forward on the tree of
 *    5 DOF per limb with 6 weld rows per platform copy after the first
 *    (15 DOF, 12 rows for three limbs), on the model the kernels and the
 *    MJCF were made from (the drives' Coulomb force, which MuJoCo does not
 *    model, goes in through qfrc_applied, see prru_mujoco.h).
 * 2. A simulated second of the paper's scenario, 1001 samples, at the same
 *    accuracy. Accuracy is max |q - q_ref| over the samples, q_ref being
 *    prru_simulate at tolerance 1e-13. MuJoCo's soft welds put a floor of
 *    ~1e-7 under its error however small its step, so: MuJoCo RK4 at the
 *    largest step of a ladder within 1.5x of its best error, and our rk8pd
 *    at the loosest tolerance whose error is no larger than that.
 * Times are medians over the repetitions (bench_timer.h). */
/* clock_gettime under -std=c99 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "bench_timer.h"
#include "prru.h"
#include "prru_mujoco.h"

static double sink; /* keeps the timed calls from being optimised away */

typedef struct {
  int n, cap;
  double *q;
} qtrace;

static int store_q(const prru_sample *s, void *ctx)
{
  qtrace *tr = ctx;
  if (tr->n == tr->cap) return 1;
  memcpy(tr->q + 3 * tr->n++, s->q, sizeof s->q);
  return 0;
}

static double max_dq(const double *a, const double *b, int n)
{
  double e = 0;
  for (int i = 0; i < 3 * n; i++) e = fmax(e, fabs(a[i] - b[i]));
  return e;
}

/* Ours: the paper run at tolerance tol into tr; seconds taken. */
static double run_ours(const prru_model *pm, prru_scenario *sc, double tol, qtrace *tr)
{
  double t_stop;
  char msg[200];
  sc->opt.abs_tol = sc->opt.rel_tol = tol;
  sc->opt.loads = &sc->loads;
  sc->opt.on_sample = store_q;
  sc->opt.ctx = tr;
  tr->n = 0;
  double t0 = bench_now_ns();
  int st = prru_simulate(pm, sc->q0, sc->qd0, &sc->opt, &t_stop, msg, sizeof msg);
  double t1 = bench_now_ns();
  if (st != PRRU_OK || tr->n != tr->cap) {
    fprintf(stderr, "bench_mujoco: prru_simulate at tol %g: %s\n", tol, msg);
    exit(1);
  }
  return (t1 - t0) * 1e-9;
}

/* MuJoCo: the paper run with mj_step RK4 at dt into q (nsamp samples). */
static double run_mj(mjModel *m, mjData *d, const mjmap *mp, const prru_scenario *sc,
                     double dt, int nsamp, double *q)
{
  state_residuals sr;
  int per_sample = (int)floor(sc->opt.dt_out / dt + 0.5);
  mj_resetData(m, d);
  m->opt.timestep = dt;
  m->opt.integrator = mjINT_RK4;
  if (!set_state(m, d, mp, sc->q0, sc->qd0, &sr)) exit(1);
  d->time = 0;
  double t0 = bench_now_ns();
  for (int k = 0; k < nsamp; k++) {
    if (k > 0) {
      for (int s = 0; s < per_sample; s++) mj_step(m, d);
      mj_kinematics(m, d);
    }
    platform_q(d, mp->P[0], q + 3 * k);
  }
  double t1 = bench_now_ns();
  return (t1 - t0) * 1e-9;
}

int main(int argc, char **argv)
{
  if (argc < 2 || argc > 3) {
    fprintf(stderr, "usage: bench_mujoco PRRU_MJCF.xml [repetitions]\n");
    return 2;
  }
  int reps = argc == 3 ? atoi(argv[2]) : 7;
  if (reps < 1 || reps > 1000) {
    fprintf(stderr, "bench_mujoco: repetitions must be 1..1000 (got '%s')\n", argv[2]);
    return 2;
  }
  char err[1000] = "";
  mjModel *m = mj_loadXML(argv[1], NULL, err, sizeof err);
  if (!m) {
    fprintf(stderr, "bench_mujoco: %s: cannot load: %s\n", argv[1], err);
    return 2;
  }
  mjmap mp;
  if (!build_map(m, &mp)) return 2;
  mjData *d = mj_makeData(m);
  prru_model pm;
  prru_model_default(&pm);
  prru_data *pd = malloc(sizeof *pd);
  prru_scenario sc;
  prru_scenario_paper(&sc);
  int v = mj_version();
  printf("MuJoCo %d.%d.%d, %s; medians of %d repetitions\n", v / 100, v / 10 % 10, v % 10,
         argv[1], reps);

  /* ---- 1. one call ---- */
  const double q[3] = {0.1, 0.2, -0.8}, qd[3] = {0.3, -0.4, 0.5};
  prru_loads l;
  prru_schedule_eval(&sc.loads, 0.0, &l);
  state_residuals sr;
  if (!set_state(m, d, &mp, q, qd, &sr)) return 1;
  mj_load_forces(m, d, &mp, &l, d->qfrc_applied);
  enum { BATCH = 20000 };
  double *ours = malloc(sizeof(double) * (size_t)reps), *mj = malloc(sizeof(double) * (size_t)reps);
  for (int r = 0; r < reps; r++) {
    double qdd[3], t0 = bench_now_ns();
    for (int k = 0; k < BATCH; k++) {
      prru_forward_dynamics(&pm, pd, q, qd, &l, qdd);
      sink += qdd[0];
    }
    ours[r] = (bench_now_ns() - t0) / BATCH;
    t0 = bench_now_ns();
    for (int k = 0; k < BATCH / 10; k++) {
      mj_forward(m, d);
      sink += d->qacc[0];
    }
    mj[r] = (bench_now_ns() - t0) / (BATCH / 10);
  }
  bench_stats so = bench_stats_of(ours, reps), sm = bench_stats_of(mj, reps);
  printf("one forward-dynamics call, same state and loads:\n"
         "  prru_forward_dynamics %8.3f us (min %.3f)\n"
         "  mj_forward            %8.3f us (min %.3f)   ratio %.0fx\n",
         so.median * 1e-3, so.min * 1e-3, sm.median * 1e-3, sm.min * 1e-3, sm.median / so.median);

  /* ---- 2. a simulated second at the same accuracy ---- */
  int nsamp = (int)floor(sc.opt.t_end / sc.opt.dt_out + 0.5) + 1;
  qtrace ref = {0, nsamp, malloc(sizeof(double) * 3 * (size_t)nsamp)};
  qtrace tr = {0, nsamp, malloc(sizeof(double) * 3 * (size_t)nsamp)};
  double *qm = malloc(sizeof(double) * 3 * (size_t)nsamp);
  run_ours(&pm, &sc, 1e-13, &ref);

  static const double dts[] = {1e-3, 5e-4, 2e-4, 1e-4, 5e-5};
  enum { NDT = sizeof dts / sizeof dts[0] };
  double mj_err[NDT], best = INFINITY;
  g_schedule = &sc.loads;
  g_map = &mp;
  mjcb_control = apply_loads;
  printf("a simulated second of the paper scenario (error = max |q - q_ref|, q_ref at tol 1e-13):\n");
  for (int i = 0; i < NDT; i++) {
    double secs = run_mj(m, d, &mp, &sc, dts[i], nsamp, qm);
    mj_err[i] = isfinite(qm[3 * nsamp - 1]) ? max_dq(qm, ref.q, nsamp) : INFINITY;
    best = fmin(best, mj_err[i]);
    printf("  mj_step RK4 dt = %-6g error %.2e  (one run %.3f s)\n", dts[i], mj_err[i], secs);
  }
  int pick = NDT - 1;
  for (int i = 0; i < NDT; i++)
    if (mj_err[i] <= 1.5 * best) { pick = i; break; }
  for (int r = 0; r < reps; r++) mj[r] = run_mj(m, d, &mp, &sc, dts[pick], nsamp, qm);
  mjcb_control = NULL;
  sm = bench_stats_of(mj, reps);

  static const double tols[] = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  int tpick = -1;
  double our_err = 0;
  for (int i = 0; i < (int)(sizeof tols / sizeof tols[0]); i++) {
    double secs = run_ours(&pm, &sc, tols[i], &tr);
    double e = max_dq(tr.q, ref.q, nsamp);
    printf("  prru_simulate rk8pd tol %-6g error %.2e  (one run %.3f s)\n", tols[i], e, secs);
    if (tpick < 0 && e <= mj_err[pick]) {
      tpick = i;
      our_err = e;
    }
  }
  if (tpick < 0) tpick = 6;
  for (int r = 0; r < reps; r++) ours[r] = run_ours(&pm, &sc, tols[tpick], &tr);
  so = bench_stats_of(ours, reps);
  printf("same accuracy: mj_step RK4 dt = %g (error %.1e): %.1f ms;"
         " prru_simulate rk8pd tol %g (error %.1e): %.2f ms; ratio %.0fx\n",
         dts[pick], mj_err[pick], sm.median * 1e3, tols[tpick], our_err, so.median * 1e3,
         sm.median / so.median);
  if (sink == 12345.678) printf(" ");
  free(ref.q);
  free(tr.q);
  free(qm);
  free(ours);
  free(mj);
  free(pd);
  prru_scenario_free(&sc);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
