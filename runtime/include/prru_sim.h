/* prru runtime, simulation: actuator and platform loads as functions of
 * time, the integration of the forward dynamics (GSL odeiv2) and scenario
 * files. */
#ifndef PRRU_SIM_H
#define PRRU_SIM_H

#include "prru_dynamics.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Loads as functions of time ---- */
typedef enum { PRRU_LOAD_CONSTANT, PRRU_LOAD_HARMONIC, PRRU_LOAD_TABLE } prru_load_kind;
typedef struct {
  prru_load_kind kind;
  prru_loads base;         /* constant part */
  /* harmonic: fp += amp * (sin(w t), -cos(w t), 0) (the paper's load) */
  double amp, omega;
  /* table: rows of t, fd1..fdN, fp1..3, mp1..3 (N = nact, the actuators
   * of the model it was read for), linear interpolation, held constant
   * outside [t_0, t_n] */
  int nact, nrows;
  double *rows;            /* (nact + 7) * nrows, owned by the schedule */
} prru_load_schedule;

PRRU_API void prru_schedule_constant(prru_load_schedule *s, const prru_loads *l);
/* The paper's section 4.3 loads: fd = (50, 40, 25) N, fp = 50 (sin 4pi t,
 * -cos 4pi t, 0) N, mp = 0; a fourth actuator (the redundant limb, which
 * mirrors limb 3) gets limb 3's 25 N. */
PRRU_API void prru_schedule_paper(prru_load_schedule *s);
/* Reads a CSV with header t,fd1..fdN[,fp1,fp2,fp3[,mp1,mp2,mp3]] (N =
 * m's actuators); times strictly increasing. On error fills msg
 * (file:line: reason). */
PRRU_API int prru_schedule_read_csv(const prru_model *m, prru_load_schedule *s, const char *path, char *msg,
                                    int msglen);
PRRU_API void prru_schedule_eval(const prru_load_schedule *s, double t, prru_loads *out);
PRRU_API void prru_schedule_free(prru_load_schedule *s);

/* ---- Simulation ---- */
typedef enum { PRRU_RK8PD, PRRU_RKF45, PRRU_RKCK, PRRU_MSBDF } prru_stepper;
/* PRRU_OK and sets *s from "rk8pd", "rkf45", "rkck", "msbdf". */
PRRU_API int prru_stepper_parse(const char *name, prru_stepper *s);
PRRU_API const char *prru_stepper_name(prru_stepper s);

typedef struct {
  double t, q[3], qd[3], qdd[3], d[PRRU_MAX_ACT];
  double lambda[PRRU_MAX_LAMBDA]; /* when options.reactions */
  double T, V;
} prru_sample;

/* The sample consumer: PRRU_OK (0) to go on; non-zero stops the run after
 * this sample, and prru_simulate returns PRRU_EINTERRUPTED with msg
 * "stopped at t = ... by the sample consumer". The status says only that
 * the consumer stopped the run: a consumer that stops for a reason of its
 * own (a write error) keeps the reason in ctx and reports it (the CLI
 * returns PRRU_EIO and keeps errno; it then exits 1 with the reason, not
 * as an interrupt). */
typedef int (*prru_sample_fn)(const prru_sample *s, void *ctx);

/* The smallest non-zero tolerance prru_simulate accepts, for abs_tol and
 * rel_tol alike: 100 DBL_EPSILON (about 2.2e-14). A step's error estimate
 * is a difference of two solutions that each carry rounding of a few
 * DBL_EPSILON |y| per stage; the state's components (rad, m and their
 * rates) are of order 1 or larger, so a smaller tolerance is either
 * dominated by the other one or cannot be met at all (the step size then
 * collapses and the run never ends). 0 switches that part of the error
 * control off; both 0 is refused. */
#define PRRU_TOL_MIN (100 * DBL_EPSILON)
/* Default step budget: accepted integrator steps per output interval. */
#define PRRU_MAX_STEPS_DEFAULT 100000L

typedef struct {
  prru_stepper stepper;
  double t_end, dt_out;          /* s; samples at 0, dt_out, ..., t_end */
  double abs_tol, rel_tol, h0;   /* gsl_odeiv2_driver tolerances (0 or at
                                    least PRRU_TOL_MIN), first step */
  int reactions;                 /* compute lambda for each sample */
  const prru_load_schedule *loads;
  /* Every sample, as it is reached: the caller's output and progress
   * report (the library draws nothing). */
  prru_sample_fn on_sample; void *ctx;
  /* Non-zero stops the run: polled between samples and inside every
   * evaluation of the right-hand side, so a long integrator step stops too. */
  volatile sig_atomic_t *interrupt;
  /* Step budget: the run stops (PRRU_ENOCONV) once the integrator needs
   * more than this many accepted steps between two samples (GSL's driver
   * takes nmax + 2 before it gives up; gsl_odeiv2_driver_set_nmax), so no
   * run can spin forever; 0 means PRRU_MAX_STEPS_DEFAULT, negative is
   * refused. */
  long max_steps;
} prru_sim_options;

PRRU_API void prru_sim_options_default(prru_sim_options *o);
/* Checks o as prru_simulate does before it starts: PRRU_OK, or
 * PRRU_EINPUT with msg (may be NULL) naming the member of
 * prru_sim_options at fault and why ("abs_tol = 1e-20 is below ..."), and
 * *field (when field is non-NULL) that member's name, so that a front end
 * can name its own option. */
PRRU_API int prru_sim_options_check(const prru_sim_options *o, const char **field, char *msg, int msglen);
/* Integrates from (q0, qd0); calls on_sample for every sample it reached.
 * Stops with PRRU_EUNREACHABLE / PRRU_ESINGULAR (state left the workspace),
 * PRRU_ENOCONV (step failure, or the step budget max_steps exhausted:
 * "step budget of N steps exhausted at t = ..."), PRRU_EINTERRUPTED
 * (*interrupt, also in the middle of a step, or the sample consumer);
 * PRRU_EINPUT for bad options, among them a tolerance below PRRU_TOL_MIN,
 * abs_tol = 0 with msbdf and a loads table read for another number of
 * actuators than m's. *t_stop is the time of the last sample
 * delivered; every sample delivered stays delivered. msg (may be NULL)
 * says why it stopped, naming the option for PRRU_EINPUT. */
PRRU_API int prru_simulate(const prru_model *m, const double q0[3], const double qd0[3],
                           const prru_sim_options *o, double *t_stop, char *msg, int msglen);

/* ---- Scenarios: initial state, loads and integrator settings ----
 * opt.loads points at the scenario's own loads once it is set up; a copy of
 * the struct must re-point it (opt.loads = &copy.loads). */
typedef struct {
  double q0[3], qd0[3];
  prru_load_schedule loads;
  prru_sim_options opt;
} prru_scenario;

/* The paper's section 4.3 study: q0 = (0, pi/6, -0.8), qd0 = 0, paper loads,
 * 1 s, samples every 1 ms, rk8pd at 1e-10. */
PRRU_API void prru_scenario_paper(prru_scenario *s);
/* A scenario file for model m: one `key = value` per line, '#' comments;
 * keys q0, qd0, fp, mp (3 numbers each), fd (one per actuator of m),
 * harmonic (amplitude N, angular frequency
 * rad/s), loads (a CSV file for prru_schedule_read_csv, relative to the
 * scenario's directory), t_end, dt, stepper, atol, rtol, h0, max_steps
 * (opt.max_steps). Unset keys keep their defaults (zero state and loads,
 * 1 s, 1 ms, rk8pd, 1e-10, PRRU_MAX_STEPS_DEFAULT).
 * On error msg says `name:line: reason`. */
PRRU_API int prru_scenario_read(const prru_model *m, prru_scenario *s, const char *path, char *msg, int msglen);
/* The same from memory; name is used in messages, base_dir for `loads`
 * (NULL: loads not allowed). */
PRRU_API int prru_scenario_parse(const prru_model *m, prru_scenario *s, const char *text, size_t len,
                                 const char *name, const char *base_dir, char *msg, int msglen);
PRRU_API void prru_scenario_free(prru_scenario *s);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_SIM_H */
