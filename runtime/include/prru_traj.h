/* Trajectories: derivatives of sampled signals (local polynomial fits) and
 * piecewise-quintic joint trajectories (point-to-point segments, or a
 * C2 interpolation of sampled q, qd, qdd).
 *
 * Differentiation. Measured or planned positions q(t_i) alone do not give
 * the velocities and accelerations that inverse dynamics needs. Each
 * sample's derivatives here come from a least-squares polynomial of degree
 * p fitted to the 2m + 1 samples around it (a Savitzky-Golay filter that
 * also accepts unevenly spaced times; near the ends the window is the
 * 2m + 1 samples nearest to the end, not shortened). Every estimate is a
 * fixed linear combination sum_j w_j y(t_j), and the fit reproduces any
 * polynomial of degree <= p exactly, so for a signal with a bounded
 * derivative of order p + 1 the error of the k-th derivative is at most
 *     trunc_k * max |y^(p+1)|,   trunc_k = sum_j |w_kj| |t_j - t_i|^(p+1) / (p+1)!
 * over the window (Taylor's theorem with the remainder at each t_j), plus
 * rounding, and white noise of standard deviation s on y becomes noise of
 * standard deviation gain_k s on the estimate, gain_k = |w_k|_2. Both are
 * returned per sample, so a caller can state the bound it relies on. On
 * evenly spaced samples h apart, trunc_k is of order h^(p+1-k) and gain_k
 * of order h^-k m^-(k+1/2): a wider window averages noise away at the
 * price of a larger truncation factor. Default m = 4, p = 4 (9 samples):
 * at h = 1 ms, trunc_2 = 2.2e-9 s^3 in the middle of a run (the qdd error
 * is below 2.2e-9 s^3 times the largest 5th derivative) and 2.7e-7 s^3 at
 * the first and last samples (one-sided windows); gain_2 = 4.4e5 s^-2 in
 * the middle (1 urad of white noise on q becomes 0.44 rad/s^2 on qdd).
 *
 * The fit is a Householder QR of the window's Vandermonde matrix in the
 * scaled time (t_j - t_i) / max_j |t_j - t_i| (GSL), on the stack: no
 * allocation, so these calls can run per sample in a loop. */
#ifndef PRRU_TRAJ_H
#define PRRU_TRAJ_H

#include "prru.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Limits of the window half-width m and the degree p. */
#define PRRU_DIFF_MAX_HALF 25
#define PRRU_DIFF_MAX_DEGREE 8
#define PRRU_DIFF_MAX_WINDOW (2 * PRRU_DIFF_MAX_HALF + 1)

typedef struct {
  int half_width; /* m >= 1: the window is 2m + 1 samples */
  int degree;     /* p, 2 <= p <= 2m (p = 2m interpolates) */
} prru_diff_options;

/* m = 4, p = 4. */
void prru_diff_options_default(prru_diff_options *o);

/* The weights of sample i of n (times t, strictly increasing, finite):
 * *first is the window's first sample, w[k][j] the weight of sample
 * first + j in the k-th derivative at t_i (k = 0: the smoothed value),
 * j < 2m + 1. PRRU_EINPUT for bad options, n < 2m + 1 or i out of range,
 * PRRU_ESINGULAR when the window's times are too close to fit (never for
 * distinct times in double precision). */
int prru_diff_weights(const double *t, int n, int i, const prru_diff_options *o, int *first,
                      double w[3][PRRU_DIFF_MAX_WINDOW]);

/* The smoothed values ys, first derivatives yd and second derivatives ydd
 * of dim signals y sampled at t (n rows, row-major n x dim, any of the
 * outputs NULL if not wanted), and per sample and derivative order k =
 * 0, 1, 2 the truncation factor trunc[3 i + k] and the noise gain
 * gain[3 i + k] (see above; NULL if not wanted). PRRU_EINPUT with msg
 * (naming the row, 1-based) for non-finite data, times not strictly
 * increasing, too few rows or bad options. */
int prru_diff_signal(const double *t, int n, const double *y, int dim,
                     const prru_diff_options *o, double *ys, double *yd, double *ydd,
                     double *trunc, double *gain, char *msg, int msglen);

/* ---- Piecewise-quintic trajectories of q ----
 * Knots t_0 < ... < t_{n-1} with q, qd, qdd at each; between two knots
 * each coordinate is the quintic polynomial that matches both knots'
 * position, velocity and acceleration, so q is twice continuously
 * differentiable. Point-to-point segments between waypoints are the case
 * qd = qdd = 0 at every knot: q moves along the straight line between the
 * waypoints with the time law s = 10 u^3 - 15 u^4 + 6 u^5, u = (t - t_k) /
 * T_k, whose peak speed is 1.875 and peak acceleration 10 / sqrt(3) =
 * 5.7735 times |Delta q| / T_k and |Delta q| / T_k^2. A table of samples
 * (t, q, qd, qdd) consistent with a quintic reproduces it exactly. */
typedef struct {
  int n;          /* knots (>= 2) */
  double *t;      /* n */
  double *coef;   /* (n - 1) segments x 3 coordinates x 6 coefficients in u,
                     then the last knot's q, qd, qdd (9, returned exactly) */
} prru_quintic;

/* From waypoints q_0..q_{n-1} (n x 3 row-major) and the n - 1 segment
 * durations (s, > 0), starting at t0. Allocates (a set-up call);
 * PRRU_EINPUT with msg naming the bad waypoint or duration, PRRU_ENOMEM.
 * A duration that rounding loses is refused, the first one as any other:
 * one that leaves its knot time unchanged, shorter than sqrt(DBL_MIN) =
 * 1.5e-154 s (its square underflows), or whose peak acceleration
 * overflows. */
int prru_quintic_waypoints(prru_quintic *tr, int n, const double *q, const double *durations,
                           double t0, char *msg, int msglen);
/* From n samples of t, q, qd, qdd (each n x 3 row-major, t strictly
 * increasing): the C2 interpolation described above. */
int prru_quintic_samples(prru_quintic *tr, int n, const double *t, const double *q,
                         const double *qd, const double *qdd, char *msg, int msglen);
/* q, qd, qdd at time t in [t_0, t_{n-1}] (any output may be NULL);
 * PRRU_EINPUT outside that interval or for a non-finite t. */
int prru_quintic_eval(const prru_quintic *tr, double t, double q[3], double qd[3],
                      double qdd[3]);
double prru_quintic_t_begin(const prru_quintic *tr);
double prru_quintic_t_end(const prru_quintic *tr);
void prru_quintic_free(prru_quintic *tr);

/* A pose on a trajectory is usable when it is reachable and J_d regular:
 * prru_check_regular's status (PRRU_OK, PRRU_EINPUT, PRRU_EUNREACHABLE,
 * PRRU_ESINGULAR), with *rcond as there. */
int prru_traj_pose_ok(const prru_model *m, prru_data *d, const double q[3], double *rcond);
/* Samples of a path are regular one by one even where the path crosses
 * the singular set between two of them; two regular samples with opposite
 * signs of det J_d (prru_jd_det_sign, prru.h) show that crossing whatever
 * the sampling (prru traj and prru track refuse such a path). */

#ifdef __cplusplus
}
#endif
#endif /* PRRU_TRAJ_H */
