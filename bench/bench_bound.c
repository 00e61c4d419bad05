/* How close each kernel is to a scalar lower bound, in the same run.
 *
 * The bound of a kernel is its multiplies issued two a cycle (the two
 * floating-point multiply pipes of current x86-64 cores; adds, subtracts
 * and moves go to other ports), at the clock the core runs at, plus the
 * time of its library calls alone: sin and cos of q1 and q2 and its square
 * roots, measured here on the bench states. It is a bound for code that
 * keeps every multiply pipe busy and overlaps nothing with the calls; the
 * generator's kernels are one scalar straight line each, so nothing but
 * fewer multiplies brings them under it. The multiplies are the
 * generator's own counts (PRRU_OPS_*).
 *
 * The clock is measured: a chain of dependent integer adds runs one add a
 * cycle on every x86-64 core. /proc/cpuinfo's "cpu MHz" is the nominal
 * clock on a VM (2.6 GHz here, where the core runs at 3.6 GHz with boost)
 * and would put the bound 40 % too high; it is the fallback elsewhere. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"

bench_bound bench_bound_result;

/* "... N mul ..." in an operation summary, or -1. */
static int count_of(const char *ops, const char *what)
{
  const char *p = strstr(ops, what);
  if (!p) return -1;
  while (p > ops && p[-1] == ' ') p--;
  while (p > ops && p[-1] >= '0' && p[-1] <= '9') p--;
  return atoi(p);
}

/* "... sqrt N" (a call count follows its name), or 0. */
static int calls_of(const char *ops, const char *name)
{
  const char *p = strstr(ops, name);
  return p ? atoi(p + strlen(name)) : 0;
}

#if defined(__GNUC__) && defined(__x86_64__)
/* GHz from 4 x 2^26 dependent adds (about 75 ms), median of 5. */
static double measured_clock_ghz(int quick)
{
  double g[5];
  for (int r = 0; r < 5; r++) {
    unsigned long x = 0;
    const long n = quick ? 1L << 18 : 1L << 26;
    double t0 = bench_now_ns();
    for (long i = 0; i < n; i++)
      __asm__ volatile("add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0" : "+r"(x));
    g[r] = 4.0 * (double)n / (bench_now_ns() - t0);
  }
  return bench_stats_of(g, 5).median;
}
#else
static double measured_clock_ghz(int quick) { (void)quick; return 0; }
#endif

static double reported_clock_ghz(void)
{
  FILE *f = fopen("/proc/cpuinfo", "r");
  double mhz = 0;
  if (!f) return 0;
  char line[512];
  while (fgets(line, sizeof line, f))
    if (!strncmp(line, "cpu MHz", 7)) {
      const char *v = strchr(line, ':');
      if (v) mhz = atof(v + 1);
      break;
    }
  fclose(f);
  return mhz / 1000.0;
}

/* ns of sin, cos of q1 and q2 and `nsqrt` square roots, as a kernel has
 * them (independent states, every result to the sink). */
static double time_calls(const bench_ctx *c, int nsqrt, long n)
{
  double acc = 0, t0 = bench_now_ns();
  for (long i = 0; i < n; i++) {
    const bench_state *s = &c->st[i & (NSTATES - 1)];
    double a = sin(s->q[0]) + cos(s->q[0]) + sin(s->q[1]) + cos(s->q[1]);
    for (int k = 0; k < nsqrt; k++) a += sqrt(1.5 + s->q[k % 3] * (double)(k + 1));
    acc += a;
  }
  double t = bench_now_ns() - t0;
  bench_sink = bench_sink + acc;
  return t / (double)n;
}

/* The table's rows and what each executes: kernel summaries and how many
 * chained kernels (each with its own calls) one call runs. */
static const struct {
  const char *row, *ops1, *ops2;
} rows[] = {
  {"jd", PRRU_OPS_JD, NULL},
  {"ik_jd", PRRU_OPS_IK_JD, NULL},
  {"mass", PRRU_OPS_MASS, NULL},
  {"bias", PRRU_OPS_BIAS, NULL},
  {"gravity", PRRU_OPS_GRAVITY, NULL},
  {"dynamics", PRRU_OPS_DYNAMICS, NULL},
  {"forward_dynamics", PRRU_OPS_EOM_SOLVE, NULL},
  {"inverse_dynamics", PRRU_OPS_INVERSE_TERMS, NULL},
  {"reactions", PRRU_OPS_EOM_SOLVE, PRRU_OPS_JOINT_REACTIONS},
};
enum { NROWS = sizeof rows / sizeof rows[0] };

void bench_bound_run(const bench_ctx *c, int reps, int quick, bench_bound *b)
{
  memset(b, 0, sizeof *b);
  b->clock_ghz = measured_clock_ghz(quick);
  b->clock_measured = b->clock_ghz > 0;
  if (!b->clock_measured) b->clock_ghz = reported_clock_ghz();
  const int nsqrt = calls_of(PRRU_OPS_DYNAMICS, "sqrt ");
  const long n = quick ? 4 * NSTATES : 4096 * NSTATES;
  double t[MAXREPS];
  time_calls(c, nsqrt, n);
  for (int i = 0; i < reps; i++) t[i] = time_calls(c, nsqrt, n);
  b->calls_ns = bench_stats_of(t, reps).median;
  b->nsqrt = nsqrt;
  if (!(b->clock_ghz > 0)) return;
  for (int i = 0; i < NROWS && b->n < BENCH_MAX_BOUND; i++) {
    const bench_kernel *k = bench_kernel_named(rows[i].row);
    int mul = count_of(rows[i].ops1, " mul"), ncalls = 1;
    if (!k || mul < 0) continue;
    if (rows[i].ops2) {
      int m2 = count_of(rows[i].ops2, " mul");
      if (m2 < 0) continue;
      mul += m2;
      ncalls = 2;
    }
    bench_bound_row *r = &b->row[b->n++];
    r->name = rows[i].row;
    r->muls = mul;
    r->bound_ns = mul / 2.0 / b->clock_ghz + ncalls * b->calls_ns;
    r->measured_ns = k->gen.median;
  }
}

void bench_bound_print_table(const bench_bound *b)
{
  if (!(b->clock_ghz > 0)) {
    printf("lower bounds: no clock frequency measured or in /proc/cpuinfo\n\n");
    return;
  }
  printf("lower bound (multiplies two a cycle at %.2f GHz %s, plus sin and cos of q1, q2\n"
         "and %d sqrt measured alone: %.1f ns) against the median above:\n",
         b->clock_ghz, b->clock_measured ? "measured" : "from /proc/cpuinfo", b->nsqrt,
         b->calls_ns);
  for (int i = 0; i < b->n; i++) {
    const bench_bound_row *r = &b->row[i];
    printf("  %-17s %4d mul  bound %6.1f ns  measured %6.1f ns  %.2fx the bound\n", r->name,
           r->muls, r->bound_ns, r->measured_ns, r->measured_ns / r->bound_ns);
  }
  printf("\n");
}

void bench_bound_print_json(const bench_bound *b)
{
  printf(", \"bound\": {\"clock_ghz\": %.4g, \"clock_measured\": %s, \"calls_ns\": %.4g, "
         "\"kernels\": {",
         b->clock_ghz, b->clock_measured ? "true" : "false", b->calls_ns);
  for (int i = 0; i < b->n; i++) {
    const bench_bound_row *r = &b->row[i];
    printf("%s\"%s\": {\"muls\": %d, \"bound_ns\": %.4g, \"measured_ns\": %.4g}", i ? ", " : "",
           r->name, r->muls, r->bound_ns, r->measured_ns);
  }
  printf("}}");
}
