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
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "bench.h"

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
  if (bench_make_states(&c) != 0) {
    fprintf(stderr, "prru_bench: found fewer than %d regular reachable states\n", NSTATES);
    return 1;
  }
  for (int i = 0; i < bench_nkernels; i++) {
    int bad = -1, st = bench_agreement(&c, &bench_kernels[i], &bad);
    if (st != 0) {
      const bench_state *s = &c.st[bad];
      fprintf(stderr, "prru_bench: %s failed (status %d) at q = (%g, %g, %g): not timing an "
              "error path\n", bench_kernels[i].name, st, s->q[0], s->q[1], s->q[2]);
      return 1;
    }
  }
  /* Busy the core for a while first: on this VM the first ~100 ms of work
   * run visibly slower (clock ramp-up), which would bias whichever kernel
   * came first. */
  if (!op.quick)
    for (double t0 = bench_now_ns(); bench_now_ns() - t0 < 3e8;) bench_warm_up(&c, 64 * NSTATES);
  for (int i = 0; i < bench_nkernels; i++) {
    if (!op.json) fprintf(stderr, "timing %s...\n", bench_kernels[i].name);
    bench_time_kernel(&c, &bench_kernels[i], op.reps, op.batch_ms * 1e6);
    if (c.failures) {
      fprintf(stderr, "prru_bench: %ld calls of %s failed while timed\n", c.failures,
              bench_kernels[i].name);
      return 1;
    }
  }
  for (int i = 0; i < bench_nkernels; i++) {
    bench_kernel *k = &bench_kernels[i];
    if (!k->constant) continue;
    if (!op.json) fprintf(stderr, "timing %s against %s...\n", k->name, k->constant);
    bench_time_cost(&c, k, bench_kernel_named(k->constant), op.reps, op.batch_ms * 1e6);
  }
  if (!op.json) fprintf(stderr, "simulating...\n");
  sim_result sim;
  memset(&sim, 0, sizeof sim);
  bench_simulated_second(&c.m, op.quick ? 1 : (op.reps > 7 ? op.reps : 7), &sim);
  map_result map;
  memset(&map, 0, sizeof map);
#ifdef PRRU_BENCH_HAVE_DME
  if (!op.json) fprintf(stderr, "mapping...\n");
  bench_map_throughput(&c.m, op.quick, &map);
#endif
  if (!op.json) fprintf(stderr, "latency, throughput and batched kernels...\n");
  bench_modes_run(&c, op.reps, op.quick, &bench_modes_result);
  if (c.failures) {
    fprintf(stderr, "prru_bench: %ld calls failed in the latency and batched runs\n", c.failures);
    return 1;
  }
  if (!op.json) fprintf(stderr, "dynamics against the SymPy peer...\n");
  bench_peer_run(&c, op.reps, op.quick, &bench_peer_result);
  bench_bound_run(&c, op.reps, op.quick, &bench_bound_result);
  if (!op.json) fprintf(stderr, "derivatives...\n");
  bench_derivs_run(&c, op.reps, op.batch_ms * 1e6, &bench_derivs_result);
  if (c.failures) {
    fprintf(stderr, "prru_bench: %ld calls failed in the derivative runs\n", c.failures);
    return 1;
  }
  bench_modes_done = 1;
  if (!op.json) fprintf(stderr, "regenerating...\n");
  bench_stats regen[BENCH_REGEN_NSETS];
  int regen_ok = bench_time_regeneration(op.quick ? 1 : 3, regen) == 0;

  char cpu[256];
  bench_cpu_model(cpu, sizeof cpu);
  /* Without --json the table comes first and the same numbers follow as the
   * last line, so `make bench` shows both from one run. */
  if (!op.json) {
    bench_print_table(&op, cpu, &sim, &map, regen_ok, regen);
    printf("\n");
  }
  bench_print_json(&op, cpu, &sim, &map, regen_ok, regen);
  free(c.d);
  prru_ref_free(c.w);
  /* A failed simulation or regeneration is a broken project, not a slow one. */
  return sim.ok && regen_ok ? 0 : 1;
}
