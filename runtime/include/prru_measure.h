/* Simulated measurements: what a prototype's sensors would report of a
 * simulated run (prru measure), so that identification can be tried on
 * data as imperfect as a real robot's before the robot exists.
 *
 * Sensors. The sliders' positions d come from encoders of finite
 * resolution r: d_meas = r round(d / r), an error uniform in +-r/2
 * (standard deviation r / sqrt(12)), the same at every sample (not noise
 * that averages away within a window, and not independent between
 * neighbouring samples when d moves slowly). The actuator forces carry
 * white Gaussian noise of standard deviation sigma (N), from GSL's
 * mt19937 seeded by the caller: a seed gives the same data on every
 * machine. Samples are taken at a rate below the run's: every row whose
 * time is t_0 + k / rate.
 *
 * Differentiation. Identification needs qd and qdd, which a real robot
 * does not measure: identify differentiates q (from the encoders by
 * forward kinematics) with a local polynomial fit (prru_traj.h) of 2m + 1
 * samples and degree p. A wider window averages quantisation away but
 * bends the signal (truncation); the best choice depends on the
 * resolution, the rate and the motion. A simulated run knows the exact
 * qdd, so prru_measure_best_diff tries every setting and reports the one
 * whose qdd is nearest the truth: the setting to give identify. */
#ifndef PRRU_MEASURE_H
#define PRRU_MEASURE_H

#include "prru.h"
#include "prru_traj.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double rate;         /* samples per second; 0 keeps every row of the run */
  double d_resolution; /* encoder resolution on d (m); 0: exact positions */
  double force_sigma;  /* standard deviation of the force noise (N); 0: exact */
  unsigned long seed;  /* of the force noise */
} prru_measure_options;

/* Every row, exact sensors, seed 1. */
PRRU_API void prru_measure_options_default(prru_measure_options *o);

/* The rows of a run (times t, n rows, strictly increasing) a sensor
 * sampling at o->rate sees: idx[0..*nout) with t[idx[k]] = t[0] + k / rate
 * to 1e-6 of a period, up to the last row. PRRU_EINPUT with msg for a bad
 * option (negative, not finite) or when a sample time has no row (msg
 * names the time: the run's rows must fall on the sensor's clock). idx
 * holds n entries. */
PRRU_API int prru_measure_rows(const double *t, int n, const prru_measure_options *o, int *idx, int *nout,
                               char *msg, int msglen);

/* The sensors' readings in place: d (n x nact, row-major) quantised,
 * fd (n x nact) with noise, drawn row by row. PRRU_EINPUT for bad options
 * (msg names the option), PRRU_ENOMEM. */
PRRU_API int prru_measure_apply(const prru_measure_options *o, int n, int nact, double *d, double *fd, char *msg,
                                int msglen);

/* q (n x 3) of n rows of slider positions d (n x nact) by least-squares
 * forward kinematics (prru_forward_kinematics_lsq), each row seeded from the
 * previous row's pose and the first from prru_fk_default_seed's level
 * pose: a motion sampled densely
 * enough stays in its assembly mode. A converged pose is the sliders' when
 * its residual is within dres (m, the encoders' resolution: four sliders
 * quantised to dres leave the least-squares pose within dres in the
 * 2-norm) plus the solver's tolerance 1e-9 (1 + |d_1|); dres = INFINITY
 * accepts every converged pose (exact or three sliders). On failure *row is
 * the first row refused (0-based; -1 on success) and *residual its residual
 * where the solver converged (NaN where it did not): PRRU_EINPUT for a
 * residual beyond dres, prru_forward_kinematics_lsq's statuses otherwise,
 * PRRU_ENOMEM; msg names the row and the reason. */
PRRU_API int prru_measure_poses(const prru_model *m, int n, const double *d, double dres, double *q, int *row,
                                double *residual, char *msg, int msglen);

/* How well a differentiation setting recovers qdd from measured sliders:
 * the poses by forward kinematics (least squares from the previous row's
 * pose, as identify does), their second derivative as prru_diff_signal
 * computes it, and the error against the exact qdd (n x 3) as the largest
 * over the three coordinates of RMS(error) / RMS(exact qdd), the RMS taken
 * over every ceil(n / 1000)-th row (48 settings on every row of a long run
 * would take seconds; the sample keeps the ends' windows in their share). */
typedef struct {
  prru_diff_options best;
  double best_error;    /* of best */
  double default_error; /* of prru_diff_options_default's */
  int tried;            /* settings tried */
} prru_diff_choice;

/* Tries m = 1 .. PRRU_DIFF_MAX_HALF with p = 2 and 4 (p <= 2m, 2m + 1 <=
 * n) on the measured d (n x nact, times t) and keeps the smallest
 * error; ties keep the narrower window. PRRU_EINPUT with msg for fewer
 * than 3 rows or exact qdd of zero RMS in every coordinate, the statuses of
 * prru_forward_kinematics_lsq for a row no pose reproduces (msg names the
 * row), PRRU_ENOMEM. */
PRRU_API int prru_measure_best_diff(const prru_model *m, int n, const double *t, const double *d, const double *qdd,
                                    prru_diff_choice *c, char *msg, int msglen);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_MEASURE_H */
