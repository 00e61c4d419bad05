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
PRRU_API void prru_diff_options_default(prru_diff_options *o);

/* The weights of sample i of n (times t, strictly increasing, finite):
 * *first is the window's first sample, w[k][j] the weight of sample
 * first + j in the k-th derivative at t_i (k = 0: the smoothed value),
 * j < 2m + 1. PRRU_EINPUT for bad options, n < 2m + 1 or i out of range,
 * PRRU_ESINGULAR when the window's times are too close to fit (never for
 * distinct times in double precision). */
PRRU_API int prru_diff_weights(const double *t, int n, int i, const prru_diff_options *o, int *first,
                               double w[3][PRRU_DIFF_MAX_WINDOW]);

/* The smoothed values ys, first derivatives yd and second derivatives ydd
 * of dim signals y sampled at t (n rows, row-major n x dim, any of the
 * outputs NULL if not wanted), and per sample and derivative order k =
 * 0, 1, 2 the truncation factor trunc[3 i + k] and the noise gain
 * gain[3 i + k] (see above; NULL if not wanted). PRRU_EINPUT with msg
 * (naming the row, 1-based) for non-finite data, times not strictly
 * increasing, too few rows or bad options. */
PRRU_API int prru_diff_signal(const double *t, int n, const double *y, int dim,
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
PRRU_API int prru_quintic_waypoints(prru_quintic *tr, int n, const double *q, const double *durations,
                                    double t0, char *msg, int msglen);
/* From n samples of t, q, qd, qdd (each n x 3 row-major, t strictly
 * increasing): the C2 interpolation described above. */
PRRU_API int prru_quintic_samples(prru_quintic *tr, int n, const double *t, const double *q,
                                  const double *qd, const double *qdd, char *msg, int msglen);
/* q, qd, qdd at time t in [t_0, t_{n-1}] (any output may be NULL);
 * PRRU_EINPUT outside that interval or for a non-finite t. */
PRRU_API int prru_quintic_eval(const prru_quintic *tr, double t, double q[3], double qd[3],
                               double qdd[3]);
PRRU_API double prru_quintic_t_begin(const prru_quintic *tr);
PRRU_API double prru_quintic_t_end(const prru_quintic *tr);
PRRU_API void prru_quintic_free(prru_quintic *tr);

/* The rows of a motion sampled every dt over [t0, t1]: t0 + k dt for k =
 * 0 .. n - 1, then t1 itself (a remainder below 1e-9 dt merged into that
 * last row), at least those two however short the span. prru_row_count:
 * the number of rows, n + 1 = max(1, ceil((t1 - t0) / dt - 1e-9)) + 1; 0
 * where dt is not > 0 or (t1 - t0) / dt exceeds 1e8 (or either is not a
 * number). prru_row_time: row k's time (k = rows - 1: t1). What prru traj
 * and the Python binding write. */
PRRU_API long prru_row_count(double t0, double t1, double dt);
PRRU_API double prru_row_time(double t0, double t1, double dt, long k, long rows);

/* A pose on a trajectory is usable when it is reachable and J_d regular:
 * prru_check_regular's status (PRRU_OK, PRRU_EINPUT, PRRU_EUNREACHABLE,
 * PRRU_ESINGULAR), with *rcond as there. */
PRRU_API int prru_traj_pose_ok(const prru_model *m, prru_data *d, const double q[3], double *rcond);
/* Samples of a path are regular one by one even where the path crosses
 * the singular set between two of them; two regular samples with opposite
 * signs of det J_d (prru_jd_det_sign, prru.h) show that crossing whatever
 * the sampling (prru traj, track, id and the time-optimal planner refuse
 * such a path). prru_path_side follows the sign along the samples, in
 * order; with four actuators J_d has no determinant and nothing is
 * crossed. */
typedef struct {
  int sign; /* det J_d's sign at the regular samples so far, 0 before */
} prru_path_side;
/* Before the first sample. */
PRRU_API void prru_path_side_init(prru_path_side *s);
/* 1 when the regular sample's J_d (nact x 3) has the opposite sign to the samples
 * before (the path crossed the singular set since the last one; the sign
 * kept), else 0 (the sign recorded). */
PRRU_API int prru_path_side_crossed(prru_path_side *s, const double Jd[], int nact);
/* The next sample q of a path: prru_traj_pose_ok's status (d filled as
 * there), or PRRU_ESINGULAR with *crossed = 1 when the pose is regular but
 * on the other side of the singular set (crossed may be NULL). */
PRRU_API int prru_path_sample(prru_path_side *s, const prru_model *m, prru_data *d, const double q[3], double *rcond,
                              int *crossed);

/* ---- Time-optimal path parameterisation (TOPP-RA) ----
 * The path of prru_quintic_waypoints (straight lines in q from waypoint to
 * waypoint, at rest at every waypoint) traversed as fast as the drives'
 * limits (prru_limits: rail force, slider speed, stroke) allow. Segment k
 * is q(s) = q_k + s (q_{k+1} - q_k), s in [0, 1], and each segment is a
 * rest-to-rest problem of its own. Along it qd = q' s', qdd = q' s'' and
 * the actuator forces of inverse dynamics (prru_inverse_dynamics, no
 * platform loads; with four actuators the minimum-norm forces, no preload)
 * are
 *     f(s) = a(s) s'' + b(s) s'^2 + c(s) + h(s, s'),
 * a, b, c taken from the inverse dynamics itself (affine in qdd, even part
 * quadratic in qd; the armature is in a and b) and h the odd part, the
 * drives' damping and smoothed Coulomb friction (nonlinear in s').
 *
 * Method (Pham & Pham, IEEE T-RO 2018). On a grid of N intervals per
 * segment with x = s'^2 and a constant u = s'' on each interval (so x is
 * linear in s and x_{j+1} = x_j + 2 (s_{j+1} - s_j) u_j), every
 * interval's (u_j, x_j) is confined by linear inequalities: the force
 * limits at both ends of the interval (at s_j with x_j and at s_{j+1}
 * with x_j + 2 Delta u_j, the "interpolation" discretisation, so that the
 * forces are within the limits where the acceleration jumps), the speed
 * limits |dd_i/ds| s' <= speed_max_i as bounds on x at both ends, x >= 0.
 * The backward pass computes the controllable sets K_j = [lo_j, hi_j]
 * (the x from which rest at the segment's end can still be reached; a
 * two-variable linear programme per grid point), the forward pass picks
 * the largest u_j keeping x_{j+1} in K_{j+1} from x_0 = 0. The drive term
 * h, not linear in x, enters linearised at x0, the previous pass's x (the
 * first pass leaves h out): as its secant through x = 0, h(x0)/x0 x, until
 * x moves by less than 5 % between passes, then as its tangent (Newton's
 * method; back to secants, switching ten times later, should a pass on
 * tangents find the path infeasible), repeated until x moves by less
 * than 1e-6 of its largest value. The linearisation is exact at x0, and
 * whatever it leaves is caught by the check: the result is
 * then checked with the exact inverse dynamics at 9 points of every
 * interval (more where a slider's speed passes through its smoothed
 * Coulomb force's ramp: the points where it crosses +-2^k
 * coulomb_velocity, k = -4..4), each force near its limit maximised
 * between the samples by golden sections, and where a force or speed exceeds its limit by more than
 * PRRU_TOPP_CHECK_TOL (relative), that limit is tightened at the
 * interval's ends by the excess and the passes run again (at most
 * PRRU_TOPP_MAX_ITER times, else PRRU_ENOCONV). */
#define PRRU_TOPP_GRID_DEFAULT 400
#define PRRU_TOPP_CHECK_TOL 1e-9
#define PRRU_TOPP_MAX_ITER 200

typedef struct {
  int nseg;     /* segments (waypoints - 1) */
  int grid;     /* intervals per segment, N */
  double *q;    /* the waypoints, (nseg + 1) x 3 */
  /* Per grid point, nseg x (N + 1), segment-major: s'^2, the constant s''
   * of the interval that starts there (0 at a segment's last point) and
   * the time (s, from 0; a segment's last point and the next one's first
   * share theirs). */
  double *x, *u, *t;
  double duration;        /* s */
  /* The share of intervals on which some limit is within 1e-3 (relative)
   * of its bound at one of the interval's ends (the exact inverse
   * dynamics), and the passes run. */
  double active_fraction;
  int iterations;
} prru_topp;

/* The time-optimal parameterisation of the path through the n waypoints
 * q (n x 3) under lim, on grid intervals per segment (0: the default
 * PRRU_TOPP_GRID_DEFAULT; 2 .. 100000). Needs a finite force_max on at
 * least one actuator (the speed limits alone leave the accelerations
 * unbounded). PRRU_EINPUT with msg for bad arguments and for an
 * infeasible path, naming the first infeasible grid point (segment, s,
 * grid point) and the limit: a pose outside the workspace, singular, or
 * (three actuators) across a sign change of det J_d; a slider outside
 * its stroke; no acceleration that holds the forces within force_max
 * there (at rest, or on the way from rest to rest). PRRU_ESINGULAR where
 * inverse dynamics refuses a pose (too near the workspace boundary),
 * PRRU_ENOCONV when the check does not pass after PRRU_TOPP_MAX_ITER
 * tightenings, PRRU_ENOMEM. Allocates: prru_topp_free (also after a
 * failure, which leaves tp empty). */
PRRU_API int prru_topp_solve(prru_topp *tp, const prru_model *m, int n, const double *q,
                             const prru_limits *lim, int grid, char *msg, int msglen);
/* q, qd, qdd at time t in [0, duration] (any output NULL if not wanted):
 * s(t) integrated exactly with the constant s'' of t's interval (the
 * interval that starts at or before t; the last one at t = duration).
 * PRRU_EINPUT outside [0, duration]. */
PRRU_API int prru_topp_eval(const prru_topp *tp, double t, double q[3], double qd[3], double qdd[3]);
/* A row of the profile at t, checked again with the exact inverse
 * dynamics (what traj --time-optimal writes and the Python binding
 * returns): q, qd, qdd, the forces fd and slider speeds dd; d->d holds the
 * sliders. PRRU_OK; inverse dynamics' status where it refuses the pose;
 * PRRU_ENOCONV when a force or speed exceeds its limit by more than
 * PRRU_TOPP_ROW_TOL of it or a slider leaves its stroke (between grid
 * points: the profile cannot be trusted); msg says which, at t. */
#define PRRU_TOPP_ROW_TOL 1e-6
PRRU_API int prru_topp_row(const prru_model *m, prru_data *d, const prru_limits *lim, const prru_topp *tp, double t,
                           double q[3], double qd[3], double qdd[3], double fd[], double dd[],
                           char *msg, int msglen);
PRRU_API void prru_topp_free(prru_topp *tp);

/* The exact check of one state against lim (no platform loads): fd the
 * inverse dynamics' forces (minimum norm with four actuators), dd the
 * slider speeds (either may be NULL), *ratio the largest of |fd_i| /
 * force_max_i and |dd_i| / speed_max_i (0 with no finite limit), *which
 * its actuator (0-based) and *kind 0 force, 1 speed (NULL if not wanted).
 * The stroke is not part of it (prru_topp_solve checks it at the grid);
 * d->d and d->Jd hold the pose's sliders and J_d afterwards. The statuses
 * of prru_inverse_dynamics. */
PRRU_API int prru_limits_ratio(const prru_model *m, prru_data *d, const prru_limits *lim,
                               const double q[3], const double qd[3], const double qdd[3],
                               double fd[], double dd[], double *ratio, int *which,
                               int *kind);

/* The fastest point-to-point quintic (prru_quintic_waypoints' time law)
 * through the same waypoints whose every segment is uniformly time-scaled
 * to meet lim: per segment the shortest duration T for which the largest
 * prru_limits_ratio over samples + 1 evenly spaced points in the
 * segment's time is <= 1, by bisection on T to 1e-9 relative (doubling
 * from 1 s to bracket it). durations: n - 1. PRRU_EINPUT with msg when
 * no duration up to 2^60 s meets the limits (the static loads exceed
 * them), and with inverse dynamics' status where it refuses a pose. The
 * stroke is not checked here (the path's poses are prru_topp_solve's). */
PRRU_API int prru_quintic_fastest(const prru_model *m, int n, const double *q, const prru_limits *lim,
                                  int samples, double *durations, char *msg, int msglen);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_TRAJ_H */
