/* The runtime's paths end to end: one simulated second of the paper's
 * scenario, generated and reference, and the throughput of a w_R map. */
#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_errno.h>

#include "bench.h"
#include "bench_refsim.h"
#ifdef PRRU_BENCH_HAVE_DME
#include "prru_dme.h"
#endif

typedef struct {
  prru_sample last;
  int n;
} sim_capture;

static int capture_sample(const prru_sample *s, void *ctx)
{
  sim_capture *cap = ctx;
  cap->last = *s;
  cap->n++;
  return 0;
}

/* One simulated second of the paper's section 4.3 scenario (spec section
 * 9), generated and reference path (a redundant fourth actuator driven
 * like the third, as prru_schedule_paper does). */
void bench_simulated_second(const prru_model *m, int reps, sim_result *res)
{
  double g[MAXREPS], r[MAXREPS];
  prru_load_schedule sched;
  prru_sim_options o;
  prru_schedule_paper(&sched);
  prru_sim_options_default(&o);
  o.stepper = PRRU_RK8PD;
  o.t_end = 1.0;
  /* One output interval: the steps are the integrator's own, not cut at
   * sample times, on both paths alike. */
  o.dt_out = 1.0;
  o.abs_tol = o.rel_tol = 1e-10;
  o.reactions = 0;
  o.loads = &sched;
  o.on_sample = capture_sample;
  o.interrupt = NULL;
  bench_refsim_options ro = {o.h0, o.abs_tol, o.rel_tol, o.t_end};
  double q0[3], qd0[3], y[6], pg[MAXREPS], pr[MAXREPS];
  bench_refsim_initial(q0, qd0);
  prru_model param;
  char lmsg[512] = "";
  prru_model_default(&param);
  res->param_ok = prru_model_load(&param, PRRU_BENCH_MODEL, lmsg, sizeof lmsg) == PRRU_OK &&
                  prru_model_use_parameter_kernels(&param) == PRRU_OK;
  if (!res->param_ok) fprintf(stderr, "prru_bench: the simulated second on the parameter path not timed: %s\n", lmsg);
  res->ok = 0;
  res->tol = o.rel_tol;
  res->h0 = o.h0;
  for (int i = 0; i < reps; i++) {
    sim_capture cap = {{0}, 0};
    double t_stop = 0.0;
    char msg[256] = "";
    o.ctx = &cap;
    double t0 = bench_now_ns();
    int st = prru_simulate(m, q0, qd0, &o, &t_stop, msg, (int)sizeof msg);
    g[i] = (bench_now_ns() - t0) * 1e-9;
    if (st != PRRU_OK || cap.n == 0 || !(fabs(cap.last.t - o.t_end) <= 1e-12)) {
      fprintf(stderr, "prru_bench: prru_simulate stopped at t = %g s: %s (%s)\n", t_stop,
              prru_strerror(st), msg);
      prru_schedule_free(&sched);
      prru_model_free(&param);
      return;
    }
    if (res->param_ok) { /* right after, so that load hits both alike */
      sim_capture pcap = {{0}, 0};
      o.ctx = &pcap;
      t0 = bench_now_ns();
      st = prru_simulate(&param, q0, qd0, &o, &t_stop, msg, (int)sizeof msg);
      pg[i] = (bench_now_ns() - t0) * 1e-9;
      pr[i] = pg[i] / g[i];
      res->param_ok = st == PRRU_OK && pcap.n > 0;
    }
    t0 = bench_now_ns();
    st = bench_refsim_paper(&ro, y, &res->ref_steps);
    r[i] = (bench_now_ns() - t0) * 1e-9;
    if (st != 0) {
      prru_schedule_free(&sched);
      prru_model_free(&param);
      return;
    }
    res->dq = res->dqd = 0.0;
    for (int j = 0; j < 3; j++) {
      res->q[j] = cap.last.q[j];
      res->qd[j] = cap.last.qd[j];
      res->dq = fmax(res->dq, fabs(cap.last.q[j] - y[j]));
      res->dqd = fmax(res->dqd, fabs(cap.last.qd[j] - y[3 + j]));
    }
  }
  prru_schedule_free(&sched);
  prru_model_free(&param);
  res->gen_s = bench_stats_of(g, reps);
  res->ref_s = bench_stats_of(r, reps);
  if (res->param_ok) {
    res->param_s = bench_stats_of(pg, reps);
    res->param_ratio = bench_stats_of(pr, reps);
  }
  res->ok = 1;
}

#ifdef PRRU_BENCH_HAVE_DME
void bench_map_throughput(const prru_model *m, int quick, map_result *res)
{
  prru_map_grid g = {-PRRU_BENCH_PI / 6, PRRU_BENCH_PI / 6, -PRRU_BENCH_PI / 4, PRRU_BENCH_PI / 6,
                     0.0, 0, 0};
  int n = quick ? 101 : 1001, nref = quick ? 21 : 101, reps = quick ? 1 : 3;
  double t2[MAXREPS], t1[MAXREPS], tr[MAXREPS];
  double *w = malloc((size_t)n * (size_t)n * sizeof *w);
  double *wr = malloc((size_t)nref * (size_t)nref * sizeof *wr);
  prru_ref_params p;
  prru_ref_ws *ws = prru_ref_alloc();
  prru_data *d = malloc(sizeof *d);
  res->ok = 0;
  if (!w || !wr || !ws || !d) goto done;
  prru_ref_params_default(&p);
  g.n1 = g.n2 = n;
  for (int r = 0; r < reps; r++) {
    prru_map_options o;
    prru_map_options_default(&o);
    o.nthreads = 2;
    double t0 = bench_now_ns();
    if (prru_map_eval(m, &g, &o, w, NULL, NULL) != PRRU_OK) goto done;
    t2[r] = (bench_now_ns() - t0) * 1e-9;
    o.nthreads = 1;
    t0 = bench_now_ns();
    if (prru_map_eval(m, &g, &o, w, NULL, NULL) != PRRU_OK) goto done;
    t1[r] = (bench_now_ns() - t0) * 1e-9;
    /* The reference path: one prru_ref_w_r (GSL assembly and SVD) per point
     * on a coarser grid of the same rectangle, one thread. */
    t0 = bench_now_ns();
    for (int i = 0; i < nref; i++)
      for (int j = 0; j < nref; j++) {
        double q[3] = {prru_map_axis(g.q1_lo, g.q1_hi, nref, i),
                       prru_map_axis(g.q2_lo, g.q2_hi, nref, j), g.q3};
        if (prru_ref_w_r(&p, ws, q, &wr[i * nref + j]) != GSL_SUCCESS) wr[i * nref + j] = NAN;
      }
    tr[r] = (bench_now_ns() - t0) * 1e-9;
  }
  res->max_rel_diff = 0.0;
  for (int i = 0; i < nref; i++)
    for (int j = 0; j < nref; j++) {
      double q[3] = {prru_map_axis(g.q1_lo, g.q1_hi, nref, i),
                     prru_map_axis(g.q2_lo, g.q2_hi, nref, j), g.q3};
      prru_dme e;
      if (prru_dme_eval(m, d, q, &e) == PRRU_OK && isfinite(wr[i * nref + j]))
        res->max_rel_diff = fmax(res->max_rel_diff, fabs(e.w_R - wr[i * nref + j]) / e.w_R);
    }
  res->n = n;
  res->n_ref = nref;
  res->gen2_s = bench_stats_of(t2, reps);
  res->gen1_s = bench_stats_of(t1, reps);
  res->ref_s = bench_stats_of(tr, reps);
  res->ok = 1;
done:
  free(w);
  free(wr);
  free(d);
  if (ws) prru_ref_free(ws);
}
#endif
