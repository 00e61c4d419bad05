/* prru_bench's parts and what they share:
 *   bench_kernels.c  one call of each kernel, generated and reference side,
 *                    the batch loops around them and the kernel table;
 *   bench_states.c   the input states and the agreement of both sides;
 *   bench_harness.c  calibrated, interleaved batch timing;
 *   bench_paths.c    the simulated second and the w_R map throughput;
 *   bench_regen.c    the time to regenerate the kernels;
 *   bench_report.c   the table and the JSON object;
 *   bench_main.c     options and the order of the run. */
#ifndef PRRU_BENCH_H
#define PRRU_BENCH_H

#include <stdio.h>

#include "bench_timer.h"
#include "prru.h"
#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_param_kernels.h"
#include "prru_regressor.h"

#include "params_derive.h" /* prru_params_derive (runtime/src) */
#include "prru_ref.h"

#define PRRU_BENCH_PI 3.14159265358979323846

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
  /* prru_params_model derived (prru_param_derive) for the parameter
   * kernels, as a loaded model holds it: once, not timed. */
  prru_param_derived pd;
  long failures; /* calls that returned an error while being timed */
} bench_ctx;

/* Everything every timed call produced ends here, so no call is dead code. */
extern volatile double bench_sink;

typedef void (*batch_fn)(bench_ctx *c, long n);
typedef int (*eval_fn)(bench_ctx *c, const bench_state *s, double *out);

typedef struct {
  const char *name; /* the JSON key (issue 5) */
  int nout;
  eval_fn gen_eval, ref_eval;
  batch_fn gen_batch, ref_batch;
  const char *ops; /* what the generated side executes */
  /* A runtime-parameter kernel: the constant kernel it is compared with
   * (a row of the table), and the arithmetic of both; NULL, 0, 0 else. */
  const char *constant;
  int arith, constant_arith;
  /* results */
  bench_stats gen, ref;
  double max_rel_diff;
  /* A runtime-parameter kernel's cost (bench_time_cost): its and the
   * constant kernel's per-call ns, and their ratio per repetition. */
  bench_stats cost_param, cost_constant, cost;
} bench_kernel;

/* bench_kernels.c: the table, in report order. */
extern bench_kernel bench_kernels[];
extern const int bench_nkernels;
/* The row named name, or NULL. */
const bench_kernel *bench_kernel_named(const char *name);
/* Calls of the generated fused dynamics kernel, to busy the core. */
void bench_warm_up(bench_ctx *c, long n);

/* bench_states.c */
int bench_make_states(bench_ctx *c);
int bench_agreement(bench_ctx *c, bench_kernel *k, int *bad_state);

/* bench_harness.c */
void bench_time_kernel(bench_ctx *c, bench_kernel *k, int reps, double target_ns);
void bench_time_cost(bench_ctx *c, bench_kernel *p, const bench_kernel *k, int reps,
                     double target_ns);

/* bench_paths.c */
typedef struct {
  int ok;
  bench_stats gen_s, ref_s; /* wall seconds */
  /* The same run on the model file loaded onto the parameter kernels
   * (prru_model_use_parameter_kernels): wall seconds, and per repetition
   * parameter / specialised; param_ok 0 when the file did not load. */
  int param_ok;
  bench_stats param_s, param_ratio;
  double q[3], qd[3];       /* generated path's final state */
  double dq, dqd;           /* max |generated - reference| at t_end */
  unsigned long ref_steps;
  double tol, h0;
} sim_result;

typedef struct {
  int ok, n, n_ref;
  bench_stats gen2_s, gen1_s, ref_s; /* wall seconds: 2 threads, 1 thread, reference */
  double max_rel_diff;               /* generated vs reference w_R on the reference grid */
} map_result;

void bench_simulated_second(const prru_model *m, int reps, sim_result *res);
#ifdef PRRU_BENCH_HAVE_DME
void bench_map_throughput(const prru_model *m, int quick, map_result *res);
#endif

/* bench_modes.c: latency next to throughput, batched against scalar, and
 * thread scaling only with a second core free. */
typedef struct {
  bench_stats latency_ns, throughput_ns, ratio; /* ratio: latency / throughput */
} bench_mode_row;
typedef struct {
  bench_stats batched_ns, scalar_ns, speedup; /* per state; speedup: scalar / batched */
} bench_batch_row;
/* The same model's numbers through the runtime on the specialised kernels
 * and loaded from its file onto the parameter kernels
 * (prru_model_use_parameter_kernels: the simple structural variant where
 * the numbers allow it) and onto the general ones
 * (prru_model_use_general_kernels): ns per call, and per repetition
 * parameter / specialised and general / specialised. */
typedef struct {
  bench_stats specialised_ns, parameter_ns, ratio, general_ns, general_ratio;
} bench_path_row;
/* Single against double precision (--precision float): ns per state of
 * each, and per repetition double / float. */
typedef struct {
  bench_stats double_ns, float_ns, ratio;
} bench_precision_row;
typedef struct {
  bench_mode_row dynamics, forward, inverse;
  int paths_measured;             /* the model file loaded */
  int paths_simple;               /* its parameter path is the simple variant */
  bench_path_row path_dynamics, path_forward, path_inverse, path_reactions;
  bench_batch_row batch_dynamics, batch_eom_solve, batch_dme_terms, batch_w_r;
  bench_precision_row float_dme_terms, float_w_r;
  int ncpu, scaling_measured;
  double idle_second_core; /* of the second most idle CPU, just before */
  bench_stats scaling;     /* map: 1-thread time / 2-thread time */
} bench_modes;
extern bench_modes bench_modes_result;
extern int bench_modes_done; /* bench_modes_result is filled: report it */
void bench_modes_run(bench_ctx *c, int reps, int quick, bench_modes *m);
void bench_modes_print_table(const bench_modes *m);
void bench_modes_print_json(const bench_modes *m);

/* bench_peer.c: prru_dynamics against its SymPy peer (bench/sympy_peer.py). */
typedef struct {
  int available;            /* built, agreeing and timed */
  const char *reason;       /* why not, otherwise */
  double derive_s, cse_s;   /* the peer's SymPy derivation and cse, when built */
  double max_rel_diff;      /* against prru_dynamics at the bench states */
  bench_stats ours_ns, peer_ns, ratio; /* ratio: peer / generated, per repetition */
} bench_peer;
extern bench_peer bench_peer_result;
void bench_peer_run(const bench_ctx *c, int reps, int quick, bench_peer *r);
void bench_peer_print_table(const bench_peer *r);
void bench_peer_print_json(const bench_peer *r);

/* bench_bound.c: each kernel against a scalar lower bound (its multiplies
 * two a cycle at the measured clock plus its sin, cos and sqrt alone). */
#define BENCH_MAX_BOUND 16
typedef struct {
  const char *name;
  int muls;
  double bound_ns, measured_ns;
} bench_bound_row;
typedef struct {
  double clock_ghz, calls_ns; /* calls_ns: sin, cos of q1 and q2 and nsqrt sqrt */
  int clock_measured;         /* else clock_ghz is /proc/cpuinfo's */
  int nsqrt, n;
  bench_bound_row row[BENCH_MAX_BOUND];
} bench_bound;
extern bench_bound bench_bound_result;
void bench_bound_run(const bench_ctx *c, int reps, int quick, bench_bound *b);
void bench_bound_print_table(const bench_bound *b);
void bench_bound_print_json(const bench_bound *b);

/* bench_derivs.c: the closed-form derivatives against the forward step,
 * its central differences and inverse dynamics. */
typedef struct {
  int available, inverse_available; /* specialised kernels; three actuators */
  bench_stats forward_ns, fused_kernel_ns, linearize_ns, central_ns;
  bench_stats inverse_ns, inverse_kernel_ns, inverse_derivs_ns;
  bench_stats fused_over_forward, linearize_over_forward, central_over_linearize;
  bench_stats inverse_derivs_over_inverse;
  /* Batched (issue 29): prru_batch_eom_solve_derivs against the scalar
   * kernel's loop, prru_linearize_batch against prru_linearize's, per state. */
  bench_stats batch_kernel_ns, batch_linearize_ns;
  bench_stats batch_kernel_speedup, batch_linearize_speedup;
} bench_derivs;
extern bench_derivs bench_derivs_result;
void bench_derivs_run(bench_ctx *c, int reps, double target_ns, bench_derivs *r);
void bench_derivs_print_table(const bench_derivs *r);
void bench_derivs_print_json(const bench_derivs *r);

/* bench_regen.c */
enum { BENCH_REGEN_NSETS = 5 };
typedef struct {
  const char *name, *options; /* options: the generator's, after the model */
} bench_regen_set;
extern const bench_regen_set bench_regen_sets[BENCH_REGEN_NSETS];
int bench_time_regeneration(int reps, bench_stats out[BENCH_REGEN_NSETS]);

/* bench_report.c */
typedef struct {
  int json, reps, quick;
  double batch_ms;
} bench_options;

void bench_cpu_model(char *buf, size_t len);
void bench_print_json(const bench_options *op, const char *cpu, const sim_result *sim,
                      const map_result *map, int regen_ok, const bench_stats *regen);
void bench_print_table(const bench_options *op, const char *cpu, const sim_result *sim,
                       const map_result *map, int regen_ok, const bench_stats *regen);

#endif
