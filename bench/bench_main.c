/* prru_bench: per-call cost of the generated kernels and the runtime's paths
 * against the straightforward reference (prru_reference) in the same run,
 * the wall time of one simulated second of the paper's scenario on both
 * paths, and the time to regenerate the kernels from the model file.
 *
 * usage: prru_bench [--json] [--reps N] [--quick] [--batch-ms MS]
 *
 * Method, per kernel: the generated and the reference side are each timed
 * in batches of n calls (n calibrated so that a batch lasts --batch-ms, so
 * the clock's cost and resolution vanish); the calibration runs double as
 * warm-up; then the repetitions alternate generated and reference batches,
 * so that load from other processes hits both sides alike. Reported: per-call
 * ns, median and [min-max] over the repetitions.
 * Inputs cycle through NSTATES precomputed reachable states with varied
 * q, qd, qdd and loads, so no input is a compile-time constant and the branch
 * predictor does not see one state; every call's output feeds a sink. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <gsl/gsl_errno.h>

#include "bench_refsim.h"
#include "bench_timer.h"
#include "prru.h"
#include "prru_ref.h"

#define PRRU_BENCH_PI 3.14159265358979323846
#ifdef PRRU_BENCH_HAVE_DME
#include "prru_dme.h"
#endif

/* Set by bench/CMakeLists.txt; the fallbacks keep a hand build honest. */
#ifndef PRRU_BENCH_FLAGS
#define PRRU_BENCH_FLAGS "unknown (built outside CMake)"
#endif
#ifndef PRRU_BENCH_BUILD_TYPE
#define PRRU_BENCH_BUILD_TYPE "unknown"
#endif
#ifndef PRRU_BENCH_SOURCE_DIR
#define PRRU_BENCH_SOURCE_DIR "."
#endif
#ifndef PRRU_BENCH_MODEL
#define PRRU_BENCH_MODEL PRRU_BENCH_SOURCE_DIR "/models/3prru_paper.json"
#endif
#ifndef PRRU_BENCH_PYTHON
#define PRRU_BENCH_PYTHON "python3"
#endif

#if defined(__clang__)
#define BENCH_COMPILER "clang " __clang_version__
#elif defined(__GNUC__)
#define BENCH_COMPILER "gcc " __VERSION__
#else
#define BENCH_COMPILER "unknown C compiler"
#endif

/* A power of two, so the state index is a mask, not a division. */
#define NSTATES 64
#define MAXOUT (3 * PRRU_NH) /* largest output of one call: H, 6 NBODY x 3 */
#define MAXREPS 1000

/* What the generated side of the runtime's paths executes (runtime/src/core.c,
 * reactions.c): the generated kernels named, plus the listed numerics. */
#define PRRU_BENCH_OPS_FORWARD_DYNAMICS "eom: " PRRU_OPS_EOM "; + unrolled 3x3 Cholesky"
#if PRRU_NACT == 3
#define PRRU_BENCH_OPS_JD_INVERSE "3x3 adjugate solve"
#define PRRU_BENCH_OPS_JD_ALGEBRA "3x3 algebra"
#else /* the redundant 4-PRRU: J_d^+ (spec section 12) */
#define PRRU_BENCH_OPS_JD_INVERSE "J_d^+ by Householder QR of the 4x3 J_d"
#define PRRU_BENCH_OPS_JD_ALGEBRA "J_d^+ by Householder QR, 4x4 and 3x4 algebra"
#endif
#define PRRU_BENCH_OPS_INVERSE_DYNAMICS "ik_jd + eom (" \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_IK_JD) " + " PRRU_OPS_ARITH_STR(PRRU_ARITH_EOM) \
  " arithmetic) + " PRRU_BENCH_OPS_JD_INVERSE
#define PRRU_BENCH_OPS_REACTIONS "forward_dynamics + poses + reaction_basis + wrench_bias (" \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_EOM) " + " PRRU_OPS_ARITH_STR(PRRU_ARITH_POSES) " + " \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_REACTION_BASIS) " + " PRRU_OPS_ARITH_STR(PRRU_ARITH_WRENCH_BIAS) \
  " arithmetic) + per-body Q^T Phi^-1 Q + arrowhead block Cholesky (GSL)"
#define PRRU_BENCH_OPS_W_R "ik_jd + mass + platform_jacobian (" \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_IK_JD) " + " PRRU_OPS_ARITH_STR(PRRU_ARITH_MASS) " + " \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_PLATFORM_JACOBIAN) " arithmetic) + " PRRU_BENCH_OPS_JD_ALGEBRA \
  ", one Jacobi rotation"
#define PRRU_OPS_ARITH_STR(x) PRRU_OPS_STR_(x)
#define PRRU_OPS_STR_(x) #x

typedef struct {
  double q[3], qd[3], qdd[3];
  prru_loads l;
} bench_state;

typedef struct {
  bench_state st[NSTATES];
  prru_model m;
  prru_data *d;
  prru_ref_params p;
  prru_ref_ws *w;
  long failures; /* calls that returned an error while being timed */
} bench_ctx;

/* Everything every timed call produced ends here, so no call is dead code. */
volatile double bench_sink;

/* ---- One evaluation of each kernel, generated (g_) and reference (r_) ----
 * Each writes its outputs contiguously into out and returns non-zero on
 * failure. They are static inline in this file so the batch loops below call
 * the library function directly, with no extra indirection per call. */

static inline int g_jd(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_jd(s->q, out);
  return 0;
}
static inline int r_jd(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_jd(&c->p, s->q, out);
}
static inline int g_jacobians(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_jacobians(s->q, out);
  return 0;
}
static inline int r_jacobians(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_jacobians(&c->p, c->w, s->q, out);
}
static inline int g_bias_terms(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_bias_terms(s->q, s->qd, out);
  return 0;
}
static inline int r_bias_terms(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_bias_terms(&c->p, c->w, s->q, s->qd, out);
}
static inline int g_mass(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_mass(s->q, out);
  return 0;
}
static inline int r_mass(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_mass(&c->p, c->w, s->q, out);
}
static inline int g_bias(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_bias(s->q, s->qd, out);
  return 0;
}
static inline int r_bias(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_bias(&c->p, c->w, s->q, s->qd, out);
}
static inline int g_gravity(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_gravity(s->q, out);
  return 0;
}
static inline int r_gravity(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_gravity(&c->p, c->w, s->q, out);
}
static inline int g_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_dynamics(s->q, s->qd, out, out + 9, out + 12);
  return 0;
}
static inline int r_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_dynamics(&c->p, c->w, s->q, s->qd, out, out + 9, out + 12);
}
static inline int g_forward_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_forward_dynamics(&c->m, c->d, s->q, s->qd, &s->l, out);
}
static inline int r_forward_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_forward_dynamics(&c->p, c->w, s->q, s->qd, s->l.fd, s->l.fp, s->l.mp, out);
}
static inline int g_inverse_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_inverse_dynamics(&c->m, c->d, s->q, s->qd, s->qdd, &s->l, out);
}
static inline int r_inverse_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_inverse_dynamics(&c->p, c->w, s->q, s->qd, s->qdd, s->l.fp, s->l.mp, out);
}
static inline int g_reactions(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_reactions(&c->m, c->d, s->q, s->qd, &s->l, out);
}
static inline int r_reactions(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_reactions(&c->p, c->w, s->q, s->qd, s->l.fd, s->l.fp, s->l.mp, out);
}
#ifdef PRRU_BENCH_HAVE_DME
/* prru_dme_eval computes the whole ellipse (w_R, axes, the translational
 * segment): that is what the runtime offers for w_R, so that is timed. */
static inline int g_w_r(bench_ctx *c, const bench_state *s, double *out)
{
  prru_dme e;
  int st = prru_dme_eval(&c->m, c->d, s->q, &e);
  out[0] = e.w_R;
  return st;
}
static inline int r_w_r(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_w_r(&c->p, c->w, s->q, out);
}
#endif

typedef void (*batch_fn)(bench_ctx *c, long n);
typedef int (*eval_fn)(bench_ctx *c, const bench_state *s, double *out);

/* n calls of one side of one kernel. Only the first and last output feed the
 * sink: the kernels live in another library (no LTO), so the compiler cannot
 * drop any of their work, and summing all outputs of H would add more
 * than a cheap kernel costs. */
#define BENCH_BATCH(fn, eval, nout)                          \
  static void fn(bench_ctx *c, long n)                       \
  {                                                          \
    double out[MAXOUT], acc = 0.0;                           \
    long bad = 0;                                            \
    for (long k = 0; k < n; k++) {                           \
      bad += eval(c, &c->st[k & (NSTATES - 1)], out) != 0;   \
      acc += out[0] + out[(nout) - 1];                       \
    }                                                        \
    bench_sink += acc;                                       \
    c->failures += bad;                                      \
  }
#define BENCH_PAIR(name, nout)             \
  BENCH_BATCH(gb_##name, g_##name, nout)   \
  BENCH_BATCH(rb_##name, r_##name, nout)

BENCH_PAIR(jd, 3 * PRRU_NACT)
BENCH_PAIR(jacobians, 3 * PRRU_NH)
BENCH_PAIR(bias_terms, PRRU_NH)
BENCH_PAIR(mass, 9)
BENCH_PAIR(bias, 3)
BENCH_PAIR(gravity, 3)
BENCH_PAIR(dynamics, 15)
BENCH_PAIR(forward_dynamics, 3)
BENCH_PAIR(inverse_dynamics, PRRU_NACT)
BENCH_PAIR(reactions, PRRU_NLAMBDA)
#ifdef PRRU_BENCH_HAVE_DME
BENCH_PAIR(w_r, 1)
#endif

typedef struct {
  const char *name; /* the JSON key (issue 5) */
  int nout;
  eval_fn gen_eval, ref_eval;
  batch_fn gen_batch, ref_batch;
  const char *ops; /* what the generated side executes */
  /* results */
  bench_stats gen, ref;
  double max_rel_diff;
} bench_kernel;

#define KERNEL(name, nout, ops) {#name, nout, g_##name, r_##name, gb_##name, rb_##name, ops, \
                                 {0, 0, 0}, {0, 0, 0}, 0}

static bench_kernel kernels[] = {
  KERNEL(jd, 3 * PRRU_NACT, PRRU_OPS_JD),
  KERNEL(jacobians, 3 * PRRU_NH, PRRU_OPS_JACOBIANS),
  KERNEL(bias_terms, PRRU_NH, PRRU_OPS_BIAS_TERMS),
  KERNEL(mass, 9, PRRU_OPS_MASS),
  KERNEL(bias, 3, PRRU_OPS_BIAS),
  KERNEL(gravity, 3, PRRU_OPS_GRAVITY),
  KERNEL(dynamics, 15, PRRU_OPS_DYNAMICS),
  KERNEL(forward_dynamics, 3, PRRU_BENCH_OPS_FORWARD_DYNAMICS),
  KERNEL(inverse_dynamics, PRRU_NACT, PRRU_BENCH_OPS_INVERSE_DYNAMICS),
  KERNEL(reactions, PRRU_NLAMBDA, PRRU_BENCH_OPS_REACTIONS),
#ifdef PRRU_BENCH_HAVE_DME
  KERNEL(w_r, 1, PRRU_BENCH_OPS_W_R),
#endif
};
#define NKERNELS ((int)(sizeof kernels / sizeof kernels[0]))

/* ---- Input states ---- */

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
static int make_states(bench_ctx *c)
{
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
static int agreement(bench_ctx *c, bench_kernel *k, int *bad_state)
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

/* ---- Timing ---- */

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

static void time_kernel(bench_ctx *c, bench_kernel *k, int reps, double target_ns)
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

/* ---- The simulated second ---- */

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

typedef struct {
  int ok;
  bench_stats gen_s, ref_s; /* wall seconds */
  double q[3], qd[3];       /* generated path's final state */
  double dq, dqd;           /* max |generated - reference| at t_end */
  unsigned long ref_steps;
  double tol, h0;
} sim_result;

/* One simulated second of the paper's section 4.3 scenario (spec section
 * 9), generated and reference path (a redundant fourth actuator driven
 * like the third, as prru_schedule_paper does). */
static void simulated_second(const prru_model *m, int reps, sim_result *res)
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
  o.progress = 0;
  bench_refsim_options ro = {o.h0, o.abs_tol, o.rel_tol, o.t_end};
  double q0[3], qd0[3], y[6];
  bench_refsim_initial(q0, qd0);
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
      return;
    }
    t0 = bench_now_ns();
    st = bench_refsim_paper(&ro, y, &res->ref_steps);
    r[i] = (bench_now_ns() - t0) * 1e-9;
    if (st != 0) {
      prru_schedule_free(&sched);
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
  res->gen_s = bench_stats_of(g, reps);
  res->ref_s = bench_stats_of(r, reps);
  res->ok = 1;
}

/* ---- Map throughput (w_R over the fig. 7 rectangle) ---- */

typedef struct {
  int ok, n, n_ref;
  bench_stats gen2_s, gen1_s, ref_s; /* wall seconds: 2 threads, 1 thread, reference */
  double max_rel_diff;               /* generated vs reference w_R on the reference grid */
} map_result;

#ifdef PRRU_BENCH_HAVE_DME
static void map_throughput(const prru_model *m, int quick, map_result *res)
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

/* ---- Regeneration of the kernels from the model file ---- */

static void remove_tree_flat(const char *dir)
{
  DIR *dp = opendir(dir);
  if (dp) {
    struct dirent *e;
    char path[4096];
    while ((e = readdir(dp)) != NULL) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
      if (remove(path) != 0)
        fprintf(stderr, "prru_bench: cannot remove %s: %s\n", path, strerror(errno));
    }
    closedir(dp);
  }
  if (rmdir(dir) != 0)
    fprintf(stderr, "prru_bench: cannot remove %s: %s\n", dir, strerror(errno));
}

/* Wall seconds of `python3 gen/prru_gen.py MODEL --out TMP --quiet`, the
 * whole process including the interpreter's start, as a user pays it.
 * Returns 0 or -1 (with the reason on stderr). */
static int time_regeneration(int reps, bench_stats *out)
{
  const char *paths[] = {PRRU_BENCH_PYTHON, PRRU_BENCH_SOURCE_DIR, PRRU_BENCH_MODEL};
  for (int i = 0; i < 3; i++)
    if (strchr(paths[i], '\'')) {
      fprintf(stderr, "prru_bench: regeneration: path %s contains a quote\n", paths[i]);
      return -1;
    }
  const char *tmp = getenv("TMPDIR");
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/prru_bench_gen_XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(dir)) {
    fprintf(stderr, "prru_bench: regeneration: cannot create %s: %s\n", dir, strerror(errno));
    return -1;
  }
  char cmd[8192];
  /* The generator's stdout goes to stderr so it cannot corrupt --json. */
  snprintf(cmd, sizeof cmd, "'%s' '%s/gen/prru_gen.py' '%s' --out '%s' --quiet 1>&2",
           PRRU_BENCH_PYTHON, PRRU_BENCH_SOURCE_DIR, PRRU_BENCH_MODEL, dir);
  double s[MAXREPS];
  int rc = 0;
  for (int i = 0; i < reps && rc == 0; i++) {
    double t0 = bench_now_ns();
    rc = system(cmd);
    s[i] = (bench_now_ns() - t0) * 1e-9;
  }
  remove_tree_flat(dir);
  if (rc != 0) {
    fprintf(stderr, "prru_bench: regeneration failed (status %d): %s\n", rc, cmd);
    return -1;
  }
  *out = bench_stats_of(s, reps);
  return 0;
}

/* ---- Reporting ---- */

static void cpu_model(char *buf, size_t len)
{
  snprintf(buf, len, "unknown");
  FILE *f = fopen("/proc/cpuinfo", "r");
  if (!f) return;
  char line[512];
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, "model name", 10) != 0) continue;
    char *v = strchr(line, ':');
    if (!v) continue;
    v++;
    while (*v == ' ' || *v == '\t') v++;
    v[strcspn(v, "\n")] = '\0';
    snprintf(buf, len, "%s", v);
    break;
  }
  fclose(f);
}

static void json_string(const char *s)
{
  putchar('"');
  for (; *s; s++) {
    unsigned char ch = (unsigned char)*s;
    if (ch == '"' || ch == '\\') printf("\\%c", ch);
    else if (ch < 0x20) printf("\\u%04x", ch);
    else putchar(ch);
  }
  putchar('"');
}

typedef struct {
  int json, reps, quick;
  double batch_ms;
} bench_options;

static void print_json(const bench_options *op, const char *cpu, const sim_result *sim,
                       const map_result *map, int regen_ok, const bench_stats *regen)
{
  printf("{\"kernels\": {");
  for (int i = 0; i < NKERNELS; i++) {
    const bench_kernel *k = &kernels[i];
    printf("%s\"%s\": {\"generated_ns\": %.4g, \"reference_ns\": %.4g, \"ratio\": %.4g}",
           i ? ", " : "", k->name, k->gen.median, k->ref.median, k->ref.median / k->gen.median);
  }
  printf("}, \"model\": {\"name\": ");
  json_string(prru_mech.name);
  printf(", \"file\": ");
  json_string(prru_mech.model_file);
  printf(", \"sha256\": ");
  json_string(prru_mech.sha256);
  printf("}, \"cpu\": ");
  json_string(cpu);
  printf(", \"compiler\": ");
  json_string(BENCH_COMPILER);
  printf(", \"flags\": ");
  json_string(PRRU_BENCH_FLAGS);
  printf(", \"build_type\": ");
  json_string(PRRU_BENCH_BUILD_TYPE);
  printf(", \"reps\": %d, \"states\": %d, \"quick\": %s", op->reps, NSTATES,
         op->quick ? "true" : "false");
  printf(", \"spread_ns\": {");
  for (int i = 0; i < NKERNELS; i++) {
    const bench_kernel *k = &kernels[i];
    printf("%s\"%s\": {\"generated\": [%.4g, %.4g], \"reference\": [%.4g, %.4g]}", i ? ", " : "",
           k->name, k->gen.min, k->gen.max, k->ref.min, k->ref.max);
  }
  printf("}, \"max_rel_diff\": {");
  for (int i = 0; i < NKERNELS; i++)
    printf("%s\"%s\": %.3g", i ? ", " : "", kernels[i].name, kernels[i].max_rel_diff);
  printf("}, \"ops\": {");
  for (int i = 0; i < NKERNELS; i++) {
    printf("%s\"%s\": ", i ? ", " : "", kernels[i].name);
    json_string(kernels[i].ops);
  }
  printf("}");
#ifndef PRRU_BENCH_HAVE_DME
  printf(", \"missing\": {\"w_r\": \"runtime/include/prru_dme.h not present at build time\"}");
#endif
  if (sim->ok) {
    printf(", \"simulated_second\": {\"scenario\": \"paper section 4.3\"");
    printf(", \"generated_s\": %.4g, \"reference_s\": %.4g, "
           "\"ratio\": %.4g, \"stepper\": \"rk8pd\", \"rel_tol\": %g, \"abs_tol\": %g, "
           "\"reference_steps\": %lu, \"final_q\": [%.15g, %.15g, %.15g], "
           "\"max_abs_diff_q\": %.3g, \"max_abs_diff_qd\": %.3g}",
           sim->gen_s.median, sim->ref_s.median, sim->ref_s.median / sim->gen_s.median, sim->tol,
           sim->tol, sim->ref_steps, sim->q[0], sim->q[1], sim->q[2], sim->dq, sim->dqd);
  } else
    printf(", \"simulated_second\": null");
  if (map->ok) {
    double pts = (double)map->n * map->n, rpts = (double)map->n_ref * map->n_ref;
    printf(", \"map\": {\"grid\": %d, \"seconds_2_threads\": %.4g, \"seconds_1_thread\": %.4g, "
           "\"generated_points_per_s\": %.4g, \"generated_points_per_s_1_thread\": %.4g, "
           "\"reference_points_per_s\": %.4g, \"ratio_1_thread\": %.4g, \"max_rel_diff\": %.3g}",
           map->n, map->gen2_s.median, map->gen1_s.median, pts / map->gen2_s.median,
           pts / map->gen1_s.median, rpts / map->ref_s.median,
           (pts / map->gen1_s.median) / (rpts / map->ref_s.median), map->max_rel_diff);
  } else {
    printf(", \"map\": null");
  }
  if (regen_ok)
    printf(", \"regeneration_s\": %.4g", regen->median);
  else
    printf(", \"regeneration_s\": null");
  printf("}\n");
}

static void print_table(const bench_options *op, const char *cpu, const sim_result *sim,
                        const map_result *map, int regen_ok, const bench_stats *regen)
{
  printf("prru_bench: ns per call, median [min-max] of %d repetitions, %d input states\n",
         op->reps, NSTATES);
  printf("model: %s (%s, sha256 %s)\n", prru_mech.name, prru_mech.model_file, prru_mech.sha256);
  printf("cpu: %s | compiler: %s | flags: %s (%s)\n\n", cpu, BENCH_COMPILER, PRRU_BENCH_FLAGS,
         PRRU_BENCH_BUILD_TYPE);
  printf("%-17s %-26s %-32s %8s %9s  %s\n", "kernel", "generated ns", "reference ns", "ratio",
         "rel diff", "generated: operations");
  for (int i = 0; i < NKERNELS; i++) {
    const bench_kernel *k = &kernels[i];
    char gs[64], rs[64];
    snprintf(gs, sizeof gs, "%.1f [%.1f-%.1f]", k->gen.median, k->gen.min, k->gen.max);
    snprintf(rs, sizeof rs, "%.1f [%.1f-%.1f]", k->ref.median, k->ref.min, k->ref.max);
    printf("%-17s %-26s %-32s %7.1fx %9.1e  %s\n", k->name, gs, rs, k->ref.median / k->gen.median,
           k->max_rel_diff, k->ops);
  }
#ifndef PRRU_BENCH_HAVE_DME
  printf("%-17s not timed: runtime/include/prru_dme.h was not present at build time\n", "w_r");
#endif
  printf("\n");
  if (sim->ok) {
    printf("simulated second (paper scenario, rk8pd, rel = abs tol %g, h0 %g):\n", sim->tol,
           sim->h0);
    printf("  generated  %.3f ms [%.3f-%.3f]  (prru_simulate)\n", 1e3 * sim->gen_s.median,
           1e3 * sim->gen_s.min, 1e3 * sim->gen_s.max);
    printf("  reference  %.3f ms [%.3f-%.3f]  (gsl_odeiv2 + prru_ref_forward_dynamics, %lu steps)"
           "\n", 1e3 * sim->ref_s.median, 1e3 * sim->ref_s.min, 1e3 * sim->ref_s.max,
           sim->ref_steps);
    printf("  ratio %.1fx; final q = (%.12f, %.12f, %.12f); max |diff| q %.2e, qd %.2e\n",
           sim->ref_s.median / sim->gen_s.median, sim->q[0], sim->q[1], sim->q[2], sim->dq,
           sim->dqd);
  } else {
    printf("simulated second: failed (see above)\n");
  }
  if (map->ok) {
    double pts = (double)map->n * map->n, rpts = (double)map->n_ref * map->n_ref;
    printf("w_R map over the fig. 7 rectangle (q3 = 0):\n");
    printf("  generated  %dx%d in %.3f s [%.3f-%.3f] with 2 threads (%.3g points/s), %.3f s with 1"
           "\n", map->n, map->n, map->gen2_s.median, map->gen2_s.min, map->gen2_s.max,
           pts / map->gen2_s.median, map->gen1_s.median);
    printf("  reference  %dx%d in %.3f s, 1 thread (%.3g points/s); per-thread ratio %.1fx; "
           "max rel diff %.1e\n", map->n_ref, map->n_ref, map->ref_s.median,
           rpts / map->ref_s.median, (pts / map->gen1_s.median) / (rpts / map->ref_s.median),
           map->max_rel_diff);
  } else {
    printf("w_R map: not measured\n");
  }
  if (regen_ok)
    printf("regeneration of every kernel from %s: %.3f s [%.3f-%.3f] (target < 2 s)\n",
           PRRU_BENCH_MODEL, regen->median, regen->min, regen->max);
  else
    printf("regeneration: failed (see above)\n");
  if (strcmp(PRRU_BENCH_BUILD_TYPE, "Release") != 0)
    printf("note: build type %s, not Release: these are not the documented numbers\n",
           PRRU_BENCH_BUILD_TYPE);
}

static void usage(FILE *f)
{
  fprintf(f,
          "usage: prru_bench [--json] [--reps N] [--quick] [--batch-ms MS]\n"
          "  --json        only the JSON object on stdout (default: the table, then\n"
          "                the JSON object as the last line)\n"
          "  --reps N      timed repetitions per kernel and side (default 11, 1..%d)\n"
          "  --quick       smoke run: 3 repetitions of 0.2 ms batches, one simulated\n"
          "                second and one regeneration; timings are not meaningful\n"
          "  --batch-ms MS length of one timed batch (default 10)\n",
          MAXREPS);
}

static int parse_options(int argc, char **argv, bench_options *op)
{
  int reps_given = 0, batch_given = 0;
  op->json = op->quick = 0;
  op->reps = 11;
  op->batch_ms = 10.0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "--json")) {
      op->json = 1;
    } else if (!strcmp(a, "--quick")) {
      op->quick = 1;
    } else if (!strcmp(a, "--reps") || !strcmp(a, "--batch-ms")) {
      if (i + 1 >= argc) {
        fprintf(stderr, "prru_bench: %s needs a value\n", a);
        return 2;
      }
      char *end;
      errno = 0;
      double v = strtod(argv[++i], &end);
      if (!strcmp(a, "--reps")) {
        if (errno || *end || end == argv[i] || v != floor(v) || v < 1 || v > MAXREPS) {
          fprintf(stderr, "prru_bench: --reps '%s': want an integer in 1..%d\n", argv[i],
                  MAXREPS);
          return 2;
        }
        op->reps = (int)v;
        reps_given = 1;
      } else {
        if (errno || *end || end == argv[i] || !(v > 0 && v <= 10000)) {
          fprintf(stderr, "prru_bench: --batch-ms '%s': want a number in (0, 10000]\n",
                  argv[i]);
          return 2;
        }
        op->batch_ms = v;
        batch_given = 1;
      }
    } else if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
      usage(stdout);
      return 1;
    } else {
      fprintf(stderr, "prru_bench: unknown argument '%s'\n", a);
      usage(stderr);
      return 2;
    }
  }
  if (op->quick) {
    if (!reps_given) op->reps = 3;
    if (!batch_given) op->batch_ms = 0.2;
  }
  return 0;
}

int main(int argc, char **argv)
{
  bench_options op;
  int rc = parse_options(argc, argv, &op);
  if (rc) return rc == 1 ? 0 : rc;
  /* Errors are status codes here, not aborts. */
  gsl_set_error_handler_off();

  static bench_ctx c;
  prru_model_default(&c.m);
  prru_ref_params_default(&c.p);
  c.d = malloc(sizeof *c.d);
  c.w = prru_ref_alloc();
  if (!c.d || !c.w) {
    fprintf(stderr, "prru_bench: out of memory\n");
    return 1;
  }
  if (make_states(&c) != 0) {
    fprintf(stderr, "prru_bench: found fewer than %d regular reachable states\n", NSTATES);
    return 1;
  }
  for (int i = 0; i < NKERNELS; i++) {
    int bad = -1, st = agreement(&c, &kernels[i], &bad);
    if (st != 0) {
      const bench_state *s = &c.st[bad];
      fprintf(stderr, "prru_bench: %s failed (status %d) at q = (%g, %g, %g): not timing an "
              "error path\n", kernels[i].name, st, s->q[0], s->q[1], s->q[2]);
      return 1;
    }
  }
  /* Busy the core for a while first: on this VM the first ~100 ms of work
   * run visibly slower (clock ramp-up), which would bias whichever kernel
   * came first. */
  if (!op.quick)
    for (double t0 = bench_now_ns(); bench_now_ns() - t0 < 3e8;) gb_dynamics(&c, 64 * NSTATES);
  for (int i = 0; i < NKERNELS; i++) {
    if (!op.json) fprintf(stderr, "timing %s...\n", kernels[i].name);
    time_kernel(&c, &kernels[i], op.reps, op.batch_ms * 1e6);
    if (c.failures) {
      fprintf(stderr, "prru_bench: %ld calls of %s failed while timed\n", c.failures,
              kernels[i].name);
      return 1;
    }
  }
  if (!op.json) fprintf(stderr, "simulating...\n");
  sim_result sim;
  memset(&sim, 0, sizeof sim);
  simulated_second(&c.m, op.quick ? 1 : (op.reps > 7 ? op.reps : 7), &sim);
  map_result map;
  memset(&map, 0, sizeof map);
#ifdef PRRU_BENCH_HAVE_DME
  if (!op.json) fprintf(stderr, "mapping...\n");
  map_throughput(&c.m, op.quick, &map);
#endif
  if (!op.json) fprintf(stderr, "regenerating...\n");
  bench_stats regen = {0, 0, 0};
  int regen_ok = time_regeneration(op.quick ? 1 : 3, &regen) == 0;

  char cpu[256];
  cpu_model(cpu, sizeof cpu);
  /* Without --json the table comes first and the same numbers follow as the
   * last line, so `make bench` shows both from one run. */
  if (!op.json) {
    print_table(&op, cpu, &sim, &map, regen_ok, &regen);
    printf("\n");
  }
  print_json(&op, cpu, &sim, &map, regen_ok, &regen);
  free(c.d);
  prru_ref_free(c.w);
  /* A failed simulation or regeneration is a broken project, not a slow one. */
  return sim.ok && regen_ok ? 0 : 1;
}
