/* Computed-torque tracking of a joint trajectory, simulated in closed loop.
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
 * by the runtime-parameter kernels (prru_param_kernels.h): a plant with
 * heavier links, other drive friction, ... than the controller's model
 * (model mismatch). prru_params_model is the exact plant.
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
#include "prru_param_kernels.h"
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

typedef struct {
  double t;                   /* s */
  double q_ref[3], qd_ref[3], qdd_ref[3];
  double q[3], qd[3];         /* the plant's true state */
  double e[3];                /* q_ref - q */
  double fd[PRRU_NACT];       /* applied (after clipping) actuator forces, N */
  double fd_cmd[PRRU_NACT];   /* the controller's forces before clipping */
  double d[PRRU_NACT];        /* the plant's slider positions, m */
  /* The plant's acceleration at t under fd (the force it sees from t on):
   * (q, qd, qdd, fd) satisfy the plant's equations of motion exactly, as
   * identification data with exact rates. */
  double qdd[3];
  int saturated[PRRU_NACT];   /* 1 where |fd_cmd_i| > f_max_i */
} prru_track_sample;

/* Non-zero stops the run after this sample (as prru_sample_fn). */
typedef int (*prru_track_fn)(const prru_track_sample *s, void *ctx);

typedef struct {
  double kp[3], kd[3];        /* gains, 1/s^2 and 1/s, >= 0 */
  double control_period;      /* s; 0: continuous */
  double dt_out;              /* s, output sampling when continuous
                                 (ignored otherwise: one sample per tick) */
  double f_max[PRRU_NACT];    /* N, > 0; INFINITY: unlimited */
  double d_min[PRRU_NACT], d_max[PRRU_NACT]; /* m; -/+INFINITY: unlimited */
  double noise_q, noise_qd;   /* sensor noise std (rad or m, per s), >= 0 */
  unsigned long seed;
  double q0_offset[3];        /* initial error: q(t_0) = q_ref(t_0) - offset */
  prru_params plant;          /* the plant's parameters */
  double abs_tol, rel_tol;
  prru_track_fn on_sample; void *ctx;
  volatile sig_atomic_t *interrupt;
} prru_track_options;

/* Gains kp = w^2, kd = 2 w with w = 20 rad/s, continuous, dt_out 1 ms, no
 * limits, no noise, seed 1, the exact plant (prru_params_model), rk8pd at
 * 1e-12. */
PRRU_API void prru_track_options_default(prru_track_options *o);

typedef struct {
  long samples;
  double t_end;               /* time of the last sample */
  double rms_e[3], max_e[3];  /* over the samples */
  double max_fd[PRRU_NACT];   /* largest |fd| applied */
  long saturated[PRRU_NACT];  /* samples with actuator i saturated */
  long any_saturated;         /* samples with any actuator saturated */
} prru_track_summary;

/* Tracks ref over its whole time span from q_ref(t_0) - q0_offset,
 * qd_ref(t_0). Fills *sum with the samples delivered (also after a stop).
 * PRRU_EINPUT for bad options (msg names the option); the plant leaving
 * the workspace or its stroke PRRU_EUNREACHABLE, the controller meeting a
 * singular J_d PRRU_ESINGULAR, integrator failure PRRU_ENOCONV,
 * *interrupt or the consumer PRRU_EINTERRUPTED; msg says when and why. */
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
                                  const double q[3], const double qd[3], double fd_cmd[PRRU_NACT],
                                  double fd[PRRU_NACT], int sat[PRRU_NACT]);

/* The plant's accelerations under fd (no platform loads): M qdd = b from
 * prru_param_eom with o->plant, solved by Cholesky. PRRU_EUNREACHABLE
 * where the plant's q is unreachable (NaN), PRRU_ESINGULAR when M is not
 * positive definite. */
PRRU_API int prru_plant_accel(const prru_params *p, const double q[3], const double qd[3],
                              const double fd[PRRU_NACT], double qdd[3]);

/* Model mismatch: multiplies one group of *p's parameters by factor
 * (finite, > 0): "mass" every body's mass and inertia tensor (the same
 * shapes made of a denser material: centres of mass unchanged), "inertia"
 * the inertia tensors alone, "armature", "damping", "coulomb" the drives'
 * numbers, "gravity" the gravity vector. PRRU_EINPUT for another key or
 * factor. */
PRRU_API int prru_params_scale(prru_params *p, const char *key, double factor);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_CONTROL_H */
