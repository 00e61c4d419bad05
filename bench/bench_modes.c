/* Latency next to throughput, the batched kernels against the scalar loop,
 * and the thread-scaling figure only where a second core is really free.
 *
 * Latency: each call's input depends on the previous call's output
 * (q + 0.0 * out: IEEE arithmetic may not drop the product, since out could
 * be infinite or NaN, so the next call waits for the last one), as an
 * integrator's steps do. Throughput: the same calls on independent states,
 * so the core overlaps consecutive calls. Batched: one call of the
 * prru_batch_* kernel for NB states against NB calls of the scalar kernel
 * on the same states; w_R: prru_map_eval (one thread, batched kernels)
 * against a loop of prru_dme_eval over the same grid. Every pair is timed
 * interleaved and reported as the median [min-max] of the per-repetition
 * ratios, so load that comes and goes hits both sides alike. Thread
 * scaling: prru_map_eval on one and on two threads over a SCALE_N^2 grid,
 * large enough (about 20 ms a map on one thread) that starting the threads
 * and handing out rows cost nothing next to the work. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "prru_dme.h"
#include "prru_f_batch.h"

#define NB 1024   /* states per batched call */
#define MAP_N 64  /* w_R grid: MAP_N x MAP_N */
#define SCALE_N 512 /* thread-scaling grid: SCALE_N x SCALE_N */

bench_modes bench_modes_result;
int bench_modes_done;

/* ---- latency and throughput of one runtime path ---- */

/* Every output feeds the sink, one a call in turn (as bench_kernels.c). */
static double run_dynamics(bench_ctx *c, long n, int chained)
{
  double o[15], acc = 0.0, dep = 0.0; /* M, h, G */
  int j = 0;
  double t0 = bench_now_ns();
  for (long i = 0; i < n; i++) {
    const bench_state *s = &c->st[i & (NSTATES - 1)];
    double q[3] = {s->q[0] + dep, s->q[1], s->q[2]};
    prru_dynamics(q, s->qd, o, o + 9, o + 12);
    if (chained) dep = 0.0 * (o[0] + o[9] + o[14]);
    acc += o[j];
    j = j + 1 == 15 ? 0 : j + 1;
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc + dep;
  return t / (double)n;
}

static double run_forward(bench_ctx *c, long n, int chained)
{
  double qdd[3], acc = 0.0, dep = 0.0;
  double t0 = bench_now_ns();
  for (long i = 0; i < n; i++) {
    const bench_state *s = &c->st[i & (NSTATES - 1)];
    double q[3] = {s->q[0] + dep, s->q[1], s->q[2]};
    c->failures += prru_forward_dynamics(&c->m, c->d, q, s->qd, &s->l, qdd) != PRRU_OK;
    if (chained) dep = 0.0 * qdd[0];
    acc += qdd[0] + qdd[1] + qdd[2];
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc + dep;
  return t / (double)n;
}

static double run_inverse(bench_ctx *c, long n, int chained)
{
  double fd[PRRU_NACT], acc = 0.0, dep = 0.0;
  double t0 = bench_now_ns();
  for (long i = 0; i < n; i++) {
    const bench_state *s = &c->st[i & (NSTATES - 1)];
    double q[3] = {s->q[0] + dep, s->q[1], s->q[2]};
    c->failures += prru_inverse_dynamics(&c->m, c->d, q, s->qd, s->qdd, &s->l, fd) != PRRU_OK;
    if (chained) dep = 0.0 * fd[0];
    for (int a = 0; a < PRRU_NACT; a++) acc += fd[a];
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc + dep;
  return t / (double)n;
}

/* ---- the specialised against the parameter path ---- */

/* Throughput on model m of the calls the issue names, ns per call: the
 * fused dynamics kernel (PATH_DYNAMICS, prru_model_dynamics), a forward
 * step, inverse dynamics and the joint reactions; every output feeds the
 * sink. */
enum { PATH_DYNAMICS, PATH_FORWARD, PATH_INVERSE, PATH_REACTIONS };
static double run_path(bench_ctx *c, const prru_model *m, int kind, long n)
{
  double out[PRRU_NLAMBDA > 15 ? PRRU_NLAMBDA : 15], acc = 0.0;
  double t0 = bench_now_ns();
  for (long i = 0; i < n; i++) {
    const bench_state *s = &c->st[i & (NSTATES - 1)];
    int st = PRRU_OK;
    switch (kind) {
    case PATH_DYNAMICS:
      prru_model_dynamics(m, s->q, s->qd, out, out + 9, out + 12);
      break;
    case PATH_FORWARD:
      st = prru_forward_dynamics(m, c->d, s->q, s->qd, &s->l, out);
      break;
    case PATH_INVERSE:
      st = prru_inverse_dynamics(m, c->d, s->q, s->qd, s->qdd, &s->l, out);
      break;
    default:
      st = prru_reactions(m, c->d, s->q, s->qd, &s->l, out);
    }
    c->failures += st != PRRU_OK;
    acc += out[0] + out[1] + out[2];
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc;
  return t / (double)n;
}

static void time_paths(bench_ctx *c, const prru_model *param, const prru_model *general, int kind, long n,
                       int reps, bench_path_row *r)
{
  double a[MAXREPS], b[MAXREPS], ratio[MAXREPS], g[MAXREPS], gratio[MAXREPS];
  for (int i = -2; i < reps; i++) { /* two warm-up rounds */
    const double ts = run_path(c, &c->m, kind, n), tp = run_path(c, param, kind, n);
    const double tg = run_path(c, general, kind, n);
    if (i < 0) continue;
    a[i] = ts;
    b[i] = tp;
    ratio[i] = tp / ts;
    g[i] = tg;
    gratio[i] = tg / ts;
  }
  r->specialised_ns = bench_stats_of(a, reps);
  r->parameter_ns = bench_stats_of(b, reps);
  r->ratio = bench_stats_of(ratio, reps);
  r->general_ns = bench_stats_of(g, reps);
  r->general_ratio = bench_stats_of(gratio, reps);
}

/* The bench's model file loaded at run time and switched to the
 * parameter kernels: what a user's own model costs against a build of it. */
static void time_loaded(bench_ctx *c, long n, int reps, bench_modes *m)
{
  prru_model param, general;
  char msg[512] = "";
  prru_model_default(&param);
  prru_model_default(&general);
  if (prru_model_load(&param, PRRU_BENCH_MODEL, msg, sizeof msg) != PRRU_OK ||
      prru_model_use_parameter_kernels(&param) != PRRU_OK ||
      prru_model_load(&general, PRRU_BENCH_MODEL, msg, sizeof msg) != PRRU_OK ||
      prru_model_use_general_kernels(&general) != PRRU_OK) {
    fprintf(stderr, "prru_bench: the parameter path not timed: %s\n", msg);
    prru_model_free(&param);
    prru_model_free(&general);
    return;
  }
  m->paths_simple = param.kernels->dynamics != general.kernels->dynamics;
  time_paths(c, &param, &general, PATH_DYNAMICS, n, reps, &m->path_dynamics);
  time_paths(c, &param, &general, PATH_FORWARD, n, reps, &m->path_forward);
  time_paths(c, &param, &general, PATH_INVERSE, n, reps, &m->path_inverse);
  time_paths(c, &param, &general, PATH_REACTIONS, n, reps, &m->path_reactions);
  m->paths_measured = 1;
  prru_model_free(&param);
  prru_model_free(&general);
}

typedef double (*mode_fn)(bench_ctx *c, long n, int chained);

static void time_modes(bench_ctx *c, mode_fn f, long n, int reps, bench_mode_row *r)
{
  double lat[MAXREPS], thr[MAXREPS], ratio[MAXREPS];
  f(c, n, 0);
  f(c, n, 1);
  for (int i = 0; i < reps; i++) {
    thr[i] = f(c, n, 0);
    lat[i] = f(c, n, 1);
    ratio[i] = lat[i] / thr[i];
  }
  r->throughput_ns = bench_stats_of(thr, reps);
  r->latency_ns = bench_stats_of(lat, reps);
  r->ratio = bench_stats_of(ratio, reps);
}

/* ---- batched kernels against the scalar loop ---- */

typedef struct {
  double q[3 * NB], qd[3 * NB], fd[PRRU_NACT * NB], fp[3 * NB], mp[3 * NB];
  double out[48 * NB]; /* the largest output set: dme_terms, 4 NACT + 27 rows */
} soa_states;

/* 64-byte aligned: unaligned, every AVX-512 access of the batched kernels
 * splits a cache line, and they ran up to 1.5x slower depending on where
 * the linker happened to place this. */
#if defined(__GNUC__)
static soa_states soa __attribute__((aligned(64)));
#else
static soa_states soa;
#endif

static void fill_soa(const bench_ctx *c)
{
  for (int k = 0; k < NB; k++) {
    const bench_state *s = &c->st[k & (NSTATES - 1)];
    for (int i = 0; i < 3; i++) {
      soa.q[i * NB + k] = s->q[i];
      soa.qd[i * NB + k] = s->qd[i];
      soa.fp[i * NB + k] = s->l.fp[i];
      soa.mp[i * NB + k] = s->l.mp[i];
    }
    for (int i = 0; i < PRRU_NACT; i++) soa.fd[i * NB + k] = s->l.fd[i];
  }
}

static double sum_out(int n)
{
  double acc = 0.0;
  for (int i = 0; i < n; i++) acc += soa.out[i];
  return acc;
}

/* Outputs per state of each kind of run_batch. */
static const int batch_nout[3] = {15, 18, 4 * PRRU_NACT + 27};

/* kind: 0 dynamics, 1 eom_solve, 2 dme_terms; batched or the scalar loop.
 * Returns ns per state. Every output feeds the sink: the batched call's
 * all after the clock stops, the scalar loop's one a call in turn. */
static double run_batch(const bench_ctx *c, int kind, int batched)
{
  double *o = soa.out, acc = 0.0;
  const int nout = batch_nout[kind];
  int j = 0;
  double t0 = bench_now_ns();
  if (batched) {
    if (kind == 0) prru_batch_dynamics(NB, soa.q, soa.qd, o, o + 9 * NB, o + 12 * NB);
    if (kind == 1)
      prru_batch_eom_solve(NB, soa.q, soa.qd, soa.fd, soa.fp, soa.mp, o, o + 9 * NB, o + 12 * NB,
                           o + 15 * NB);
    if (kind == 2) prru_batch_dme_terms(NB, soa.q, o, o + PRRU_NACT * NB, o + 4 * PRRU_NACT * NB,
                                        o + (4 * PRRU_NACT + 9) * NB);
  } else {
    for (int k = 0; k < NB; k++) {
      const bench_state *s = &c->st[k & (NSTATES - 1)];
      double *x = o + 48 * (k & 31); /* AoS, reused: the loop's outputs stay in cache too */
      if (kind == 0) prru_dynamics(s->q, s->qd, x, x + 9, x + 12);
      if (kind == 1) prru_eom_solve(s->q, s->qd, s->l.fd, s->l.fp, s->l.mp, x, x + 9, x + 12, x + 15);
      if (kind == 2) prru_ik_jd(s->q, x, x + PRRU_NACT), prru_mass(s->q, x + 4 * PRRU_NACT),
                     prru_platform_jacobian(s->q, x + 4 * PRRU_NACT + 9);
      acc += x[j];
      j = j + 1 == nout ? 0 : j + 1;
    }
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc + sum_out(batched ? nout * NB : 48 * 32);
  return t / NB;
}

/* w_R over the n x n grid of the fig. 7 rectangle: prru_map_eval with
 * `threads` threads, or (threads 0) a loop of prru_dme_eval. ns per point. */
static double run_map_n(bench_ctx *c, int n, int threads, double *w, unsigned char *st)
{
  const prru_map_grid g = {-PRRU_BENCH_PI / 6, PRRU_BENCH_PI / 6, -PRRU_BENCH_PI / 4,
                           PRRU_BENCH_PI / 4, 0.0, n, n};
  double t0 = bench_now_ns(), acc = 0.0;
  if (threads > 0) {
    prru_map_options o;
    prru_map_options_default(&o);
    o.nthreads = threads;
    c->failures += prru_map_eval(&c->m, &g, &o, w, st, NULL) != PRRU_OK;
    for (long k = 0; k < (long)n * n; k++) acc += st[k] == PRRU_OK ? w[k] : 0.0;
  } else {
    for (int i = 0; i < n; i++)
      for (int j = 0; j < n; j++) {
        double q[3] = {prru_map_axis(g.q1_lo, g.q1_hi, g.n1, i),
                       prru_map_axis(g.q2_lo, g.q2_hi, g.n2, j), g.q3};
        prru_dme r;
        if (prru_dme_eval(&c->m, c->d, q, &r) == PRRU_OK) acc += r.w_R;
      }
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc;
  return t / ((double)n * n);
}

static double run_map(bench_ctx *c, int threads, double *w, unsigned char *st)
{
  return run_map_n(c, MAP_N, threads, w, st);
}

/* ---- single against double precision ---- */

#if defined(__GNUC__)
static float soa_qf[3 * NB] __attribute__((aligned(64))), soa_outf[48 * NB] __attribute__((aligned(64)));
#else
static float soa_qf[3 * NB], soa_outf[48 * NB];
#endif

/* The batched dme_terms over the NB states, in float or double (the same
 * target_clones: AVX2 on an AVX2 machine). ns per state; every output
 * feeds the sink after the clock stops. */
static double run_dme_terms(int single)
{
  const int nout = batch_nout[2];
  double t0 = bench_now_ns();
  if (single)
    prru_f_batch_dme_terms(NB, soa_qf, soa_outf, soa_outf + PRRU_NACT * NB, soa_outf + 4 * PRRU_NACT * NB,
                           soa_outf + (4 * PRRU_NACT + 9) * NB);
  else
    prru_batch_dme_terms(NB, soa.q, soa.out, soa.out + PRRU_NACT * NB, soa.out + 4 * PRRU_NACT * NB,
                         soa.out + (4 * PRRU_NACT + 9) * NB);
  double t = bench_now_ns() - t0;
  double acc = 0.0;
  if (single)
    for (int i = 0; i < nout * NB; i++) acc += soa_outf[i];
  else
    acc = sum_out(nout * NB);
  bench_sink = bench_sink + acc;
  return t / NB;
}

/* w_R over an n x n grid, one thread, in the precision given: repetition
 * `rep` picks one of three grids (fig. 7's rectangle, a wider one reaching
 * the other assembly mode and the singular band, a higher q3), so that the
 * inputs vary; the float run includes its points redone in double. ns per
 * point. */
static double run_map_precision(bench_ctx *c, int rep, int precision, double *w, unsigned char *st)
{
  static const double grids[3][5] = {{-PRRU_BENCH_PI / 6, PRRU_BENCH_PI / 6, -PRRU_BENCH_PI / 4,
                                      PRRU_BENCH_PI / 4, 0.0},
                                     {-0.9, 0.9, -0.9, 0.9, 0.0},
                                     {-0.6, 0.6, -0.7, 0.5, 0.05}};
  const double *r = grids[rep % 3];
  const prru_map_grid g = {r[0], r[1], r[2], r[3], r[4], SCALE_N / 2, SCALE_N / 2};
  prru_map_options o;
  prru_map_options_default(&o);
  o.nthreads = 1;
  o.precision = precision;
  double t0 = bench_now_ns(), acc = 0.0;
  c->failures += prru_map_eval(&c->m, &g, &o, w, st, NULL) != PRRU_OK;
  double t = bench_now_ns() - t0;
  for (long k = 0; k < (long)g.n1 * g.n2; k++) acc += st[k] == PRRU_OK ? w[k] : (double)st[k];
  bench_sink = bench_sink + acc;
  return t / ((double)g.n1 * g.n2);
}

/* kind 0: the dme_terms kernels; 1: the map. Interleaved, medians. */
static void time_precision(bench_ctx *c, int kind, int reps, bench_precision_row *r)
{
  double dn[MAXREPS], fn[MAXREPS], ratio[MAXREPS];
  static double w[(SCALE_N / 2) * (SCALE_N / 2)];
  static unsigned char st[(SCALE_N / 2) * (SCALE_N / 2)];
  for (int i = 0; i < 3 * NB; i++) soa_qf[i] = (float)soa.q[i];
  for (int i = -2; i < reps; i++) { /* two warm-up rounds */
    const int rep = i < 0 ? 0 : i;
    const double td = kind == 0 ? run_dme_terms(0) : run_map_precision(c, rep, PRRU_PRECISION_DOUBLE, w, st);
    const double tf = kind == 0 ? run_dme_terms(1) : run_map_precision(c, rep, PRRU_PRECISION_FLOAT, w, st);
    if (i < 0) continue;
    dn[i] = td;
    fn[i] = tf;
    ratio[i] = td / tf;
  }
  r->double_ns = bench_stats_of(dn, reps);
  r->float_ns = bench_stats_of(fn, reps);
  r->ratio = bench_stats_of(ratio, reps);
}

static void time_batched(bench_ctx *c, int kind, int reps, bench_batch_row *r)
{
  double b[MAXREPS], s[MAXREPS], ratio[MAXREPS];
  static double w[MAP_N * MAP_N];
  static unsigned char st[MAP_N * MAP_N];
  for (int i = -2; i < reps; i++) { /* two warm-up rounds */
    double tb, ts;
    if (kind < 3) {
      ts = run_batch(c, kind, 0);
      tb = run_batch(c, kind, 1);
    } else {
      ts = run_map(c, 0, w, st);
      tb = run_map(c, 1, w, st);
    }
    if (i < 0) continue;
    b[i] = tb;
    s[i] = ts;
    ratio[i] = ts / tb;
  }
  r->batched_ns = bench_stats_of(b, reps);
  r->scalar_ns = bench_stats_of(s, reps);
  r->speedup = bench_stats_of(ratio, reps);
}

/* ---- is a second core free? ---- */

/* Fraction of the time every other CPU was idle over `seconds`, from
 * /proc/stat (this process sleeps meanwhile, so its own CPU counts too):
 * the smallest idle fraction of the two most idle CPUs. -1 if unknown. */
static double second_core_idle(double seconds, int *ncpu)
{
  enum { MAXCPU = 256 };
  static unsigned long long idle0[MAXCPU], total0[MAXCPU];
  double frac[MAXCPU];
  int n = 0;
  for (int pass = 0; pass < 2; pass++) {
    FILE *f = fopen("/proc/stat", "r");
    if (!f) return -1;
    char line[512];
    int cpu = 0;
    while (fgets(line, sizeof line, f) && cpu < MAXCPU) {
      unsigned long long v[8] = {0};
      if (strncmp(line, "cpu", 3) != 0 || line[3] == ' ') continue;
      if (sscanf(line + 3, "%*d %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3],
                 &v[4], &v[5], &v[6], &v[7]) < 4)
        continue;
      unsigned long long idle = v[3] + v[4], total = 0;
      for (int i = 0; i < 8; i++) total += v[i];
      if (pass == 0) {
        idle0[cpu] = idle;
        total0[cpu] = total;
      } else {
        frac[cpu] = total > total0[cpu] ? (double)(idle - idle0[cpu]) / (double)(total - total0[cpu])
                                        : 0.0;
      }
      cpu++;
    }
    fclose(f);
    n = cpu;
    if (pass == 0) {
      struct timespec ts = {(time_t)seconds, (long)((seconds - floor(seconds)) * 1e9)};
      nanosleep(&ts, NULL);
    }
  }
  *ncpu = n;
  if (n < 2) return 0.0;
  double best = -1, second = -1;
  for (int i = 0; i < n; i++) {
    if (frac[i] > best) {
      second = best;
      best = frac[i];
    } else if (frac[i] > second) {
      second = frac[i];
    }
  }
  return second;
}

void bench_modes_run(bench_ctx *c, int reps, int quick, bench_modes *m)
{
  memset(m, 0, sizeof *m);
  const long n = quick ? 4 * NSTATES : 256 * NSTATES;
  time_modes(c, run_dynamics, n, reps, &m->dynamics);
  time_modes(c, run_forward, n, reps, &m->forward);
  time_modes(c, run_inverse, n, reps, &m->inverse);
  time_loaded(c, n, reps, m);
  fill_soa(c);
  time_batched(c, 0, reps, &m->batch_dynamics);
  time_batched(c, 1, reps, &m->batch_eom_solve);
  time_batched(c, 2, reps, &m->batch_dme_terms);
  time_batched(c, 3, reps, &m->batch_w_r);
  time_precision(c, 0, reps, &m->float_dme_terms);
  time_precision(c, 1, reps, &m->float_w_r);
  /* Thread scaling only with a second core idle (>= 90 %) just before. */
  m->idle_second_core = second_core_idle(quick ? 0.05 : 0.5, &m->ncpu);
  m->scaling_measured = m->ncpu > 1 && m->idle_second_core >= 0.9;
  if (m->scaling_measured) {
    static double w[SCALE_N * SCALE_N];
    static unsigned char st[SCALE_N * SCALE_N];
    double r[MAXREPS];
    run_map_n(c, SCALE_N, 2, w, st); /* warm-up: the pages of w and st */
    for (int i = 0; i < reps; i++)
      r[i] = run_map_n(c, SCALE_N, 1, w, st) / run_map_n(c, SCALE_N, 2, w, st);
    m->scaling = bench_stats_of(r, reps);
  }
}

static void row(const char *name, const bench_mode_row *r)
{
  printf("  %-17s latency %7.1f ns  throughput %7.1f ns  latency/throughput %.2f [%.2f-%.2f]\n",
         name, r->latency_ns.median, r->throughput_ns.median, r->ratio.median, r->ratio.min,
         r->ratio.max);
}

static void batch_row(const char *name, const bench_batch_row *r)
{
  printf("  %-17s %7.1f ns/state batched, %7.1f scalar loop: %.2fx [%.2f-%.2f]\n", name,
         r->batched_ns.median, r->scalar_ns.median, r->speedup.median, r->speedup.min,
         r->speedup.max);
}

static void precision_row(const char *name, const bench_precision_row *r)
{
  printf("  %-17s %7.1f ns/state double, %7.1f float: %.2fx [%.2f-%.2f] (%.3g vs %.3g Mposes/s)\n", name,
         r->double_ns.median, r->float_ns.median, r->ratio.median, r->ratio.min, r->ratio.max,
         1e3 / r->double_ns.median, 1e3 / r->float_ns.median);
}

static void path_row(const char *name, const bench_path_row *r)
{
  printf("  %-17s %7.1f ns specialised, %7.1f parameter: %.2fx [%.2f-%.2f]; %7.1f general: %.2fx\n", name,
         r->specialised_ns.median, r->parameter_ns.median, r->ratio.median, r->ratio.min, r->ratio.max,
         r->general_ns.median, r->general_ratio.median);
}

void bench_modes_print_table(const bench_modes *m)
{
  printf("latency (each call's input depends on the last output, as an integrator) and\n"
         "throughput (independent states), per call, median of interleaved repetitions:\n");
  row("dynamics", &m->dynamics);
  row("forward_dynamics", &m->forward);
  row("inverse_dynamics", &m->inverse);
  if (m->paths_measured) {
    printf("the model's numbers on the specialised kernels and loaded onto the parameter kernels\n"
           "(prru_model_load + prru_model_use_parameter_kernels: %s), and onto the general\n"
           "ones, throughput per call:\n",
           m->paths_simple ? "the simple structural variant" : "general, as the numbers need");
    path_row("dynamics", &m->path_dynamics);
    path_row("forward_dynamics", &m->path_forward);
    path_row("inverse_dynamics", &m->path_inverse);
    path_row("reactions", &m->path_reactions);
  }
  printf("batched kernels (%d states a call, one thread) against the scalar loop:\n", NB);
  batch_row("dynamics", &m->batch_dynamics);
  batch_row("eom_solve", &m->batch_eom_solve);
  batch_row("dme_terms", &m->batch_dme_terms);
  batch_row("w_R (64x64 map)", &m->batch_w_r);
  printf("single precision (--precision float) against double, one thread, the same clones:\n");
  precision_row("dme_terms", &m->float_dme_terms);
  precision_row("w_R (256x256 map)", &m->float_w_r);
  if (m->scaling_measured)
    printf("thread scaling (%dx%d map, 2 threads vs 1; a second core was %.0f %% idle): "
           "%.2fx [%.2f-%.2f]\n\n",
           SCALE_N, SCALE_N, 100 * m->idle_second_core, m->scaling.median, m->scaling.min,
           m->scaling.max);
  else
    printf("thread scaling: not measured (%d CPUs; the second most idle was %.0f %% idle, "
           "below 90 %%)\n\n",
           m->ncpu, 100 * m->idle_second_core);
}

static void json_stats(const char *key, const bench_stats *s)
{
  printf("\"%s\": {\"median\": %.4g, \"min\": %.4g, \"max\": %.4g}", key, s->median, s->min, s->max);
}

static void json_mode(const char *name, const bench_mode_row *r, int last)
{
  printf("\"%s\": {\"latency_ns\": %.4g, \"throughput_ns\": %.4g, ", name, r->latency_ns.median,
         r->throughput_ns.median);
  json_stats("latency_over_throughput", &r->ratio);
  printf("}%s", last ? "" : ", ");
}

static void json_batch(const char *name, const bench_batch_row *r, int last)
{
  printf("\"%s\": {\"batched_ns\": %.4g, \"scalar_ns\": %.4g, ", name, r->batched_ns.median,
         r->scalar_ns.median);
  json_stats("speedup", &r->speedup);
  printf("}%s", last ? "" : ", ");
}

static void json_precision(const char *name, const bench_precision_row *r, int last)
{
  printf("\"%s\": {\"double_ns\": %.4g, \"float_ns\": %.4g, ", name, r->double_ns.median,
         r->float_ns.median);
  json_stats("double_over_float", &r->ratio);
  printf("}%s", last ? "" : ", ");
}

static void json_path(const char *name, const bench_path_row *r, int last)
{
  printf("\"%s\": {\"specialised_ns\": %.4g, \"parameter_ns\": %.4g, \"general_ns\": %.4g, ", name,
         r->specialised_ns.median, r->parameter_ns.median, r->general_ns.median);
  json_stats("parameter_over_specialised", &r->ratio);
  printf(", ");
  json_stats("general_over_specialised", &r->general_ratio);
  printf("}%s", last ? "" : ", ");
}

void bench_modes_print_json(const bench_modes *m)
{
  printf(", \"modes\": {");
  json_mode("dynamics", &m->dynamics, 0);
  json_mode("forward_dynamics", &m->forward, 0);
  json_mode("inverse_dynamics", &m->inverse, 1);
  printf("}, \"loaded_paths\": ");
  if (m->paths_measured) {
    printf("{\"structure\": \"%s\", ", m->paths_simple ? "simple" : "general");
    json_path("dynamics", &m->path_dynamics, 0);
    json_path("forward_dynamics", &m->path_forward, 0);
    json_path("inverse_dynamics", &m->path_inverse, 0);
    json_path("reactions", &m->path_reactions, 1);
    printf("}");
  } else {
    printf("null");
  }
  printf(", \"batched\": {\"states_per_call\": %d, ", NB);
  json_batch("dynamics", &m->batch_dynamics, 0);
  json_batch("eom_solve", &m->batch_eom_solve, 0);
  json_batch("dme_terms", &m->batch_dme_terms, 0);
  json_batch("w_r", &m->batch_w_r, 1);
  printf("}, \"single_precision\": {");
  json_precision("dme_terms", &m->float_dme_terms, 0);
  json_precision("w_r", &m->float_w_r, 1);
  printf("}, \"thread_scaling\": ");
  if (m->scaling_measured) {
    printf("{\"second_core_idle\": %.3f, \"map_points\": %d, ", m->idle_second_core,
           SCALE_N * SCALE_N);
    json_stats("map_2_over_1_threads", &m->scaling);
    printf("}");
  } else {
    printf("{\"second_core_idle\": %.3f, \"measured\": false}", m->idle_second_core);
  }
}
