/* Computed-torque (or LQR, below) tracking of a joint trajectory,
 * simulated in closed loop.
 *
 * Controller: the model's own inverse dynamics (the generated kernels) at
 * the measured state with the commanded acceleration
 *     qdd_c = qdd_ref + Kd (qd_ref - qd) + Kp (q_ref - q),
 * i.e. fd = J_d^-T (M(q) qdd_c + h(q, qd) - G(q) - passive(q, qd))
 * (J_d^+T, the least-norm forces, with four actuators), each force then
 * clipped to its limit |fd_i| <= f_max_i (counted as saturated). With the
 * model exact and no saturation the error obeys e'' + Kd e' + Kp e = 0
 * per coordinate (critically damped for Kd = 2 sqrt(Kp)), so a run that
 * starts on the reference stays on it.
 *
 * Plant: the same equations of motion with its own parameters, evaluated
 * by the parameter kernels of the tracked model's topology (a robot of
 * its limbs): a plant with heavier links, other drive friction, ... than
 * the controller's model (model mismatch). The model's own numbers
 * (prru_model_params) are the exact plant.
 *
 * Timing: control_period = 0 evaluates the controller inside every
 * right-hand-side evaluation of the integrator (continuous control, the
 * ideal case; no sensor noise). control_period > 0 is a digital
 * controller: at t_k = t_0 + k Tc it reads the state (plus Gaussian noise
 * of standard deviations noise_q, noise_qd from a seeded generator: the
 * same seed gives the same run), computes fd and holds it until t_{k+1}
 * (zero-order hold), while the integrator solves the plant between the
 * ticks with fd constant.
 *
 * Strokes: slider i must stay in [d_min_i, d_max_i] (the plant's slider
 * positions): a run that leaves it stops, as at an end stop. Integration:
 * gsl_odeiv2 rk8pd with abs_tol, rel_tol (at least PRRU_TOL_MIN) over
 * each output interval. The integrator workspace and the noise generator
 * are allocated once per run; the per-step work allocates nothing. */
#ifndef PRRU_CONTROL_H
#define PRRU_CONTROL_H

#include <signal.h>

#include "prru.h"
#include "prru_traj.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A model's numbers in the layout the parameter kernels read (the plant of
 * prru_track, a design's starting point): prru_params_model for the built
 * model; coulomb_velocity 1 m/s where the model has no Coulomb force. */
PRRU_API void prru_model_params(const prru_model *m, prru_params *p);

/* The model file (format 2, spec 11-13) of m's structure, body names and
 * drive keys (lead, gear, stroke, limits: m's own; a changed armature
 * goes back into rotor_inertia where m's file gave that) with the numbers
 * p, named name ([a-z][a-z0-9_]{0,15}) and described by description (any
 * bytes: made valid by prru_description and JSON-escaped): *text, a
 * NUL-terminated string to free(). Magnitudes below 1e-9 are written as
 * 0 (model files hold none). The text is read back by the loader first:
 * PRRU_EINPUT with its message when p does not make a valid model (a
 * mass not positive, ...), PRRU_ENOMEM; *text NULL then. What identify
 * and optimize write. */
PRRU_API int prru_model_file_text(const prru_model *m, const prru_params *p, const char *name, const char *description,
                                  char **text, char *msg, int msglen);
/* Whether name is a model name (spec 11): a lower-case C identifier,
 * [a-z][a-z0-9_]*, of at most PRRU_MODEL_NAME_MAX (16) characters. */
PRRU_API int prru_model_name_valid(const char *name);
/* The name of a model made from one named base, into out (17 bytes,
 * PRRU_MODEL_NAME_MAX + 1 of prru_model_file.h): base cut so that base +
 * suffix fits 16 characters, then suffix (identify's "_id", optimize's
 * "_opt"): a valid name whenever base is and suffix is [a-z0-9_]*. */
PRRU_API void prru_model_name_derive(const char *base, const char *suffix, char *out);

typedef struct {
  double t;                   /* s */
  double q_ref[3], qd_ref[3], qdd_ref[3];
  double q[3], qd[3];         /* the plant's true state */
  double e[3];                /* q_ref - q */
  double fd[PRRU_MAX_ACT];       /* applied (after clipping) actuator forces, N */
  double fd_cmd[PRRU_MAX_ACT];   /* the controller's forces before clipping */
  double d[PRRU_MAX_ACT];        /* the plant's slider positions, m */
  /* The slider speeds J_d(q) qd, m/s, of the controller's model at the
   * plant's state (the plant's own where it has the model's geometry):
   * what a speed limit is compared with. */
  double dd[PRRU_MAX_ACT];
  /* The plant's acceleration at t under fd (the force it sees from t on):
   * (q, qd, qdd, fd) satisfy the plant's equations of motion exactly, as
   * identification data with exact rates. */
  double qdd[3];
  int saturated[PRRU_MAX_ACT];   /* 1 where |fd_cmd_i| > f_max_i */
} prru_track_sample;

/* Non-zero stops the run after this sample (as prru_sample_fn). */
typedef int (*prru_track_fn)(const prru_track_sample *s, void *ctx);

typedef struct {
  double kp[3], kd[3];        /* gains, 1/s^2 and 1/s, >= 0 */
  double control_period;      /* s; 0: continuous */
  double dt_out;              /* s, output sampling when continuous
                                 (ignored otherwise: one sample per tick) */
  double f_max[PRRU_MAX_ACT];    /* N, > 0; INFINITY: unlimited */
  /* m/s, > 0; INFINITY: unlimited. Computed torque cannot hold a speed,
   * so this limit is reported (prru_track_summary's over_speed), never
   * enforced. */
  double speed_max[PRRU_MAX_ACT];
  double d_min[PRRU_MAX_ACT], d_max[PRRU_MAX_ACT]; /* m; -/+INFINITY: unlimited */
  double noise_q, noise_qd;   /* sensor noise std (rad or m, per s), >= 0 */
  unsigned long seed;
  double q0_offset[3];        /* initial error: q(t_0) = q_ref(t_0) - offset */
  prru_params plant;          /* the plant's parameters */
  double abs_tol, rel_tol;
  prru_track_fn on_sample; void *ctx;
  volatile sig_atomic_t *interrupt;
  /* The controller: PRRU_TRACK_CT, computed torque with kp, kd (the
   * default), or PRRU_TRACK_LQR, the time-varying discrete LQR below
   * (needs control_period > 0; kp, kd unused) with the diagonal weights
   * lqr_q (q1..3 then qd1..3, >= 0, finite) and lqr_r (per actuator,
   * > 0, finite). All of lqr_q zero, or all of lqr_r zero (the default):
   * that group is prru_lqr_default_weights'. */
  int controller;
  double lqr_q[6], lqr_r[PRRU_MAX_ACT];
} prru_track_options;

enum { PRRU_TRACK_CT = 0, PRRU_TRACK_LQR = 1 };

/* Gains kp = w^2, kd = 2 w with w = 20 rad/s, continuous, dt_out 1 ms, no
 * limits (every entry, for any number of actuators), no noise, seed 1,
 * the exact plant of m (prru_model_params: m's numbers, the plant a robot
 * of m's limbs), rk8pd at 1e-12; computed torque, the LQR weights 0
 * (prru_lqr_default_weights). m: the model to be tracked. */
PRRU_API void prru_track_options_default(const prru_model *m, prru_track_options *o);

/* Critically damped computed-torque gains of bandwidth w (rad/s): kp_i =
 * w^2, kd_i = 2 w for every coordinate (e'' + kd e' + kp e = 0 has the
 * double pole -w). PRRU_EINPUT, o unchanged, unless w is finite, > 0 and
 * w^2 finite. */
PRRU_API int prru_track_gains_bandwidth(double w, prru_track_options *o);

/* The checks prru_track makes of o before it runs (prru_lqr_schedule_build
 * makes the LQR's part), for tracking m (the per-actuator entries of its
 * m->mech->nact actuators are checked; those past them are not read):
 * gains finite and >= 0; control_period finite and
 * >= 0, dt_out finite and > 0 when continuous; force and speed limits > 0
 * (INFINITY allowed), strokes d_min < d_max; sensor noise finite, >= 0
 * and only with control_period > 0; q0_offset finite; tolerances finite
 * and >= PRRU_TOL_MIN; a known controller; for PRRU_TRACK_LQR
 * control_period > 0, lqr_q finite and >= 0 (all 0: the default
 * weights), lqr_r all 0 (the default weights) or each finite and > 0.
 * PRRU_OK, or PRRU_EINPUT with msg naming the option by its member's
 * name (kp, kd, dt_out, q0_offset, abs_tol, rel_tol, lqr_q, lqr_r), or
 * as "control period", "sensor noise", "controller PRRU_TRACK_LQR", so
 * that a front end can put its own option names in their place. */
PRRU_API int prru_track_options_check(const prru_model *m, const prru_track_options *o, char *msg,
                                      int msglen);

typedef struct {
  long samples;
  double t_end;               /* time of the last sample */
  double rms_e[3], max_e[3];  /* over the samples */
  double max_fd[PRRU_MAX_ACT];   /* largest |fd| applied */
  long saturated[PRRU_MAX_ACT];  /* samples with actuator i saturated */
  long any_saturated;         /* samples with any actuator saturated */
  double max_dd[PRRU_MAX_ACT];   /* largest |dd| (the samples' slider speeds) */
  long over_speed;            /* samples with any |dd_i| > speed_max_i */
} prru_track_summary;

/* Tracks ref over its whole time span from q_ref(t_0) - q0_offset,
 * qd_ref(t_0). Fills *sum with the samples delivered (also after a stop).
 * PRRU_EINPUT for bad options (prru_track_options_check); the plant leaving
 * the workspace or its stroke PRRU_EUNREACHABLE, the controller meeting a
 * singular J_d PRRU_ESINGULAR, integrator failure PRRU_ENOCONV,
 * *interrupt or the consumer PRRU_EINTERRUPTED; msg says when and why.
 * With PRRU_TRACK_LQR the gain schedule is built first (once per run):
 * prru_lqr_schedule_build's statuses, no sample delivered. */
PRRU_API int prru_track(const prru_model *m, const prru_quintic *ref, const prru_track_options *o,
                        prru_track_summary *sum, char *msg, int msglen);

/* The reference of a run with rows every step (s): checked at every row
 * time and at least every millisecond (up to 1e8 checks; a longer
 * reference at its rows), and at its end: every pose usable (reachable,
 * J_d regular), det J_d never changing sign (the path does not cross the
 * singular set), every slider within [o->d_min, o->d_max]. *ff_peak: the
 * largest feed-forward force |fd_i| (inverse dynamics without loads)
 * along it. PRRU_EINPUT with msg naming the first bad sample ("reference
 * at sample K (t = T s): ...") or a step giving more than 1e8 rows;
 * PRRU_ENOMEM. */
PRRU_API int prru_track_check_reference(const prru_model *m, const prru_quintic *ref, const prru_track_options *o,
                                        double step, double *ff_peak, char *msg, int msglen);

/* One controller evaluation: the clipped forces fd and the unclipped
 * fd_cmd at the measured (q, qd) for the reference (q_ref, qd_ref,
 * qdd_ref); sat[i] set where clipped. prru_inverse_dynamics's statuses. */
PRRU_API int prru_computed_torque(const prru_model *m, prru_data *d, const prru_track_options *o,
                                  const double q_ref[3], const double qd_ref[3], const double qdd_ref[3],
                                  const double q[3], const double qd[3], double fd_cmd[],
                                  double fd[], int sat[]);

/* Time-varying discrete LQR tracking (controller PRRU_TRACK_LQR).
 *
 * At each control tick t_k of prru_track's run (t_0 + k control_period,
 * the last one the reference's end) the reference state x_ref,k = (q_ref,
 * qd_ref), the feed-forward u_ff,k = the controller model's inverse
 * dynamics at (q_ref, qd_ref, qdd_ref), and the zero-order-hold pair
 * (A_k, B_k) = prru_linearize at (q_ref, qd_ref) under fd = u_ff,k with
 * dt = control_period: x_{k+1} - x_ref,k+1 ~ A_k (x_k - x_ref,k) + B_k
 * (u_k - u_ff,k). The gains minimise sum_k dx_k^T Q dx_k + du_k^T R du_k
 * (Q = diag lqr_q, R = diag lqr_r) by the backward Riccati recursion
 *     K_k = (R + B_k^T P_k+1 B_k)^-1 B_k^T P_k+1 A_k   (Cholesky),
 *     P_k = Q + A_k^T P_k+1 (A_k - B_k K_k), symmetrised,
 * from the terminal cost P_n = Q: the run ends at the reference's end,
 * where the state is weighed like at every tick; the recursion forgets
 * P_n at the closed loop's rate (|eig(A - B K)|^2 per tick), so the gains
 * are the stationary (infinite-horizon) ones except over the last few
 * closed-loop time constants. The law at tick k:
 *     fd = u_ff,k - K_k (x_measured - x_ref,k), then clipped to f_max. */
typedef struct {
  long n;              /* ticks */
  int nact;            /* the model's actuators: the rows of K_k and u_ff,k */
  double period;       /* s */
  double q[6], r[PRRU_MAX_ACT]; /* the weights used (r: nact of them) */
  double *K;           /* n x nact x 6: K_k at K + 6 nact k, row-major */
  double *u_ff;        /* n x nact: u_ff,k at u_ff + nact k */
  double *x_ref;       /* n x 6 */
  double P0[36];       /* P_0, row-major */
} prru_lqr_schedule;

/* Bryson's rule from the model's own scales, matched to computed torque's
 * default bandwidth w = 20 rad/s: a force scale F, the largest |u_ff,i|
 * along the reference at the ticks every period (1 N if that is 0), with
 * R_i = 1 / F^2; a_j = F / |G^+ e_j|, the acceleration coordinate j alone
 * gets from forces of that scale (G = dqdd/dfd of the linearisation at the
 * reference's start, G^+ = G^T (G G^T)^-1, the least-norm forces of an
 * acceleration); the acceptable errors e_q,j = a_j / w^2 (the error for
 * which computed torque's Kp = w^2 asks for a_j) and e_qd,j = a_j / (sqrt 2
 * w): Q_j = 1 / e_q,j^2, Q_3+j = 1 / e_qd,j^2. For a decoupled double
 * integrator qdd_j = g_j fd_j this makes the continuous LQR's gains
 * exactly Kp = w^2, Kd = 2 w (critically damped at w), whatever F (F
 * only sets the cost's unit). A coupled robot's LQR spends force where
 * it is cheapest instead: its error is shaped differently from computed
 * torque's (docs/control.md measures both). q, r may be NULL.
 * prru_lqr_schedule_build's statuses for a reference the model cannot
 * follow (PRRU_ESINGULAR where G G^T is singular); PRRU_EINPUT for
 * period <= 0. */
PRRU_API int prru_lqr_default_weights(const prru_model *m, const prru_quintic *ref, double period,
                                      double q[6], double r[], char *msg, int msglen);

/* The schedule of the run prru_track makes with o (o->controller is not
 * read; o->control_period > 0 and the weights are), into *s (allocated
 * once: prru_lqr_schedule_free). PRRU_EINPUT for bad weights or period
 * (msg names the option: lqr_q, lqr_r, control period); where the
 * reference's inverse dynamics or linearisation fails at a tick, that
 * status (PRRU_EUNREACHABLE, PRRU_ESINGULAR, ...) with msg naming the
 * tick's time; PRRU_ENOCONV where R + B^T P B is not positive definite
 * (non-finite numbers); PRRU_ENOMEM. On failure *s holds nothing to
 * free. */
PRRU_API int prru_lqr_schedule_build(const prru_model *m, const prru_quintic *ref,
                                     const prru_track_options *o, prru_lqr_schedule *s, char *msg,
                                     int msglen);
PRRU_API void prru_lqr_schedule_free(prru_lqr_schedule *s);

/* The LQR law at tick k (0 <= k < s->n) on the measured state x (q then
 * qd): fd_cmd = u_ff,k - K_k (x - x_ref,k), fd clipped to o->f_max, sat[i]
 * set where clipped, for the s->nact actuators of the model s was built
 * for. PRRU_EINPUT where fd_cmd is not finite (k out of range, x not
 * finite or overflowing). */
PRRU_API int prru_lqr_control(const prru_lqr_schedule *s, long k, const prru_track_options *o,
                              const double x[6], double fd_cmd[], double fd[],
                              int sat[]);

/* The plant's accelerations under fd (no platform loads): M qdd = b from
 * the equations of motion of m's topology with the numbers p (a plant of
 * m's limbs: o->plant), solved by Cholesky. m: the model whose topology
 * (m->mech->nlimb) p is read in; its own numbers are not used.
 * PRRU_EUNREACHABLE where the plant's q is unreachable (NaN),
 * PRRU_ESINGULAR when M is not positive definite, PRRU_EINPUT for a
 * model of neither topology. Derives p at every call, about as long as
 * the solve: prru_track derives its plant once per run. */
PRRU_API int prru_plant_accel(const prru_model *m, const prru_params *p, const double q[3], const double qd[3],
                              const double fd[], double qdd[3]);

/* Model mismatch: multiplies one group of *p's parameters by factor
 * (finite, > 0), every entry of the group (whatever the model's sizes):
 * "mass" every body's mass and inertia tensor (the same
 * shapes made of a denser material: centres of mass unchanged), "inertia"
 * the inertia tensors alone, "armature", "damping", "coulomb" the drives'
 * numbers, "gravity" the gravity vector. PRRU_EINPUT for another key or
 * factor. */
PRRU_API int prru_params_scale(prru_params *p, const char *key, double factor);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_CONTROL_H */
