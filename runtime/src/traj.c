/* Local polynomial differentiation and piecewise-quintic trajectories
 * (prru_traj.h). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "prru_traj.h"
#include "internal.h"

void prru_diff_options_default(prru_diff_options *o)
{
  o->half_width = 4;
  o->degree = 4;
}

static int diff_options_ok(const prru_diff_options *o)
{
  return o && o->half_width >= 1 && o->half_width <= PRRU_DIFF_MAX_HALF && o->degree >= 2 &&
         o->degree <= PRRU_DIFF_MAX_DEGREE && o->degree <= 2 * o->half_width;
}

/* The window of 2m + 1 samples centred on i where possible, shifted
 * inwards at the ends so that it always has its full length. */
static int window_first(int n, int i, int m)
{
  int first = i - m;
  if (first < 0) first = 0;
  if (first > n - (2 * m + 1)) first = n - (2 * m + 1);
  return first;
}

int prru_diff_weights(const double *t, int n, int i, const prru_diff_options *o, int *first,
                      double w[3][PRRU_DIFF_MAX_WINDOW])
{
  if (!diff_options_ok(o) || n < 2 * o->half_width + 1 || i < 0 || i >= n) return PRRU_EINPUT;
  prru_gsl_init();
  const int len = 2 * o->half_width + 1, ncoef = o->degree + 1;
  const int f = window_first(n, i, o->half_width);
  double scale = 0.0;
  for (int j = 0; j < len; j++) scale = fmax(scale, fabs(t[f + j] - t[i]));
  if (!(scale > 0.0) || !isfinite(scale)) return PRRU_EINPUT;
  /* Vandermonde matrix in the scaled time: its columns are O(1), so the
   * QR keeps the fit's accuracy for every time step. */
  double V[PRRU_DIFF_MAX_WINDOW * (PRRU_DIFF_MAX_DEGREE + 1)], tau[PRRU_DIFF_MAX_DEGREE + 1];
  for (int j = 0; j < len; j++) {
    double s = (t[f + j] - t[i]) / scale, p = 1.0;
    for (int k = 0; k < ncoef; k++, p *= s) V[j * ncoef + k] = p;
  }
  gsl_matrix_view A = gsl_matrix_view_array(V, (size_t)len, (size_t)ncoef);
  gsl_vector_view tv = gsl_vector_view_array(tau, (size_t)ncoef);
  if (gsl_linalg_QR_decomp(&A.matrix, &tv.vector) != GSL_SUCCESS) return PRRU_ESINGULAR;
  for (int k = 0; k < ncoef; k++)
    if (!(fabs(V[k * ncoef + k]) > 1e-10)) return PRRU_ESINGULAR;
  /* Column j of the pseudo-inverse is the fit to the unit vector e_j; its
   * coefficients 0, 1, 2 give the value and, scaled by k! / scale^k, the
   * derivatives at t_i. */
  double e[PRRU_DIFF_MAX_WINDOW], c[PRRU_DIFF_MAX_DEGREE + 1], r[PRRU_DIFF_MAX_WINDOW];
  gsl_vector_view ev = gsl_vector_view_array(e, (size_t)len);
  gsl_vector_view cv = gsl_vector_view_array(c, (size_t)ncoef);
  gsl_vector_view rv = gsl_vector_view_array(r, (size_t)len);
  for (int j = 0; j < len; j++) {
    memset(e, 0, sizeof e);
    e[j] = 1.0;
    if (gsl_linalg_QR_lssolve(&A.matrix, &tv.vector, &ev.vector, &cv.vector, &rv.vector) !=
        GSL_SUCCESS)
      return PRRU_ESINGULAR;
    w[0][j] = c[0];
    w[1][j] = c[1] / scale;
    w[2][j] = 2.0 * c[2] / (scale * scale);
  }
  *first = f;
  return PRRU_OK;
}

/* trunc_k and gain_k of sample i from its weights (see prru_traj.h). */
static void diff_bounds(const double *t, int i, int f, int len, int degree,
                        double w[3][PRRU_DIFF_MAX_WINDOW], double trunc[3], double gain[3])
{
  double fact = 1.0;
  for (int k = 2; k <= degree + 1; k++) fact *= k;
  for (int k = 0; k < 3; k++) {
    double tr = 0.0, g = 0.0;
    for (int j = 0; j < len; j++) {
      tr += fabs(w[k][j]) * pow(fabs(t[f + j] - t[i]), degree + 1);
      g += w[k][j] * w[k][j];
    }
    if (trunc) trunc[k] = tr / fact;
    if (gain) gain[k] = sqrt(g);
  }
}

static int diff_check_data(const double *t, int n, const double *y, int dim, char *msg,
                           int msglen)
{
  for (int i = 0; i < n; i++) {
    if (!isfinite(t[i]))
      return prru_fail(msg, msglen, PRRU_EINPUT, "row %d: time is not finite", i + 1);
    if (i > 0 && !(t[i] > t[i - 1]))
      return prru_fail(msg, msglen, PRRU_EINPUT,
                       "row %d: time %.17g does not increase (previous %.17g)", i + 1, t[i],
                       t[i - 1]);
    for (int k = 0; k < dim; k++)
      if (!isfinite(y[(size_t)i * (size_t)dim + (size_t)k]))
        return prru_fail(msg, msglen, PRRU_EINPUT, "row %d: value %d is not finite", i + 1,
                         k + 1);
  }
  return PRRU_OK;
}

int prru_diff_signal(const double *t, int n, const double *y, int dim,
                     const prru_diff_options *o, double *ys, double *yd, double *ydd,
                     double *trunc, double *gain, char *msg, int msglen)
{
  if (!diff_options_ok(o))
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "window half-width must be 1..%d and degree 2..min(%d, 2 half-width)",
                     PRRU_DIFF_MAX_HALF, PRRU_DIFF_MAX_DEGREE);
  if (dim < 1) return prru_fail(msg, msglen, PRRU_EINPUT, "no signal to differentiate");
  const int len = 2 * o->half_width + 1;
  if (n < len)
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "%d rows, but a window of %d samples (half-width %d) needs at least %d", n,
                     len, o->half_width, len);
  int st = diff_check_data(t, n, y, dim, msg, msglen);
  if (st != PRRU_OK) return st;
  double w[3][PRRU_DIFF_MAX_WINDOW];
  for (int i = 0; i < n; i++) {
    int f;
    st = prru_diff_weights(t, n, i, o, &f, w);
    if (st != PRRU_OK)
      return prru_fail(msg, msglen, st, "row %d: the window's times are too close to fit", i + 1);
    double *out[3] = {ys, yd, ydd};
    for (int k = 0; k < 3; k++) {
      if (!out[k]) continue;
      for (int c = 0; c < dim; c++) {
        double s = 0.0;
        for (int j = 0; j < len; j++) s += w[k][j] * y[(size_t)(f + j) * (size_t)dim + (size_t)c];
        out[k][(size_t)i * (size_t)dim + (size_t)c] = s;
      }
    }
    if (trunc || gain)
      diff_bounds(t, i, f, len, o->degree, w, trunc ? trunc + 3 * i : NULL,
                  gain ? gain + 3 * i : NULL);
  }
  return PRRU_OK;
}

/* ---- Piecewise quintics ---- */

/* Coefficients in u = (t - t_a) / T of the quintic with value, derivative
 * and second derivative (per unit time) y0, v0, a0 at u = 0 and y1, v1,
 * a1 at u = 1 (the quintic Hermite basis, expanded). */
static void hermite5(double T, double y0, double v0, double a0, double y1, double v1, double a1,
                     double c[6])
{
  double dy = y1 - y0, V0 = T * v0, V1 = T * v1, A0 = T * T * a0, A1 = T * T * a1;
  c[0] = y0;
  c[1] = V0;
  c[2] = 0.5 * A0;
  c[3] = 10.0 * dy - 6.0 * V0 - 4.0 * V1 - 1.5 * A0 + 0.5 * A1;
  c[4] = -15.0 * dy + 8.0 * V0 + 7.0 * V1 + 1.5 * A0 - A1;
  c[5] = 6.0 * dy - 3.0 * V0 - 3.0 * V1 - 0.5 * A0 + 0.5 * A1;
}

static int quintic_alloc(prru_quintic *tr, int n, char *msg, int msglen)
{
  tr->n = 0;
  tr->t = NULL;
  tr->coef = NULL;
  if (n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "a trajectory needs at least 2 points, got %d", n);
  tr->t = malloc((size_t)n * sizeof *tr->t);
  /* The segments' coefficients, then the last knot's q, qd, qdd. */
  tr->coef = malloc(((size_t)(n - 1) * 18 + 9) * sizeof *tr->coef);
  if (!tr->t || !tr->coef) {
    prru_quintic_free(tr);
    return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  }
  tr->n = n;
  return PRRU_OK;
}


int prru_quintic_samples(prru_quintic *tr, int n, const double *t, const double *q,
                         const double *qd, const double *qdd, char *msg, int msglen)
{
  int st = quintic_alloc(tr, n, msg, msglen);
  if (st != PRRU_OK) return st;
  for (int i = 0; i < n; i++) {
    if (!isfinite(t[i]) || !prru_finite_n(q + 3 * i, 3) || !prru_finite_n(qd + 3 * i, 3) ||
        !prru_finite_n(qdd + 3 * i, 3)) {
      prru_quintic_free(tr);
      return prru_fail(msg, msglen, PRRU_EINPUT, "point %d: not finite", i + 1);
    }
    if (i > 0 && !(t[i] > t[i - 1])) {
      prru_quintic_free(tr);
      return prru_fail(msg, msglen, PRRU_EINPUT,
                       "point %d: time %.17g does not increase (previous %.17g)", i + 1, t[i],
                       t[i - 1]);
    }
    tr->t[i] = t[i];
  }
  for (int s = 0; s + 1 < n; s++)
    for (int c = 0; c < 3; c++) {
      int a = 3 * s + c, b = 3 * (s + 1) + c;
      hermite5(t[s + 1] - t[s], q[a], qd[a], qdd[a], q[b], qd[b], qdd[b],
               tr->coef + 18 * s + 6 * c);
    }
  /* The quintic at u = 1 sums its coefficients, which rounds; the last
   * knot is given exactly (every other knot is a segment's u = 0, exact). */
  double *end = tr->coef + 18 * (n - 1);
  memcpy(end, q + 3 * (n - 1), 3 * sizeof *end);
  memcpy(end + 3, qd + 3 * (n - 1), 3 * sizeof *end);
  memcpy(end + 6, qdd + 3 * (n - 1), 3 * sizeof *end);
  return PRRU_OK;
}

/* Why rounding loses the segment from knot t0 to knot t1 between the
 * waypoints a and b, or NULL when it keeps it. One rule for every segment,
 * the first one included:
 *  - the knot must move: t0 + T rounds to t0 when T is below half the
 *    rounding unit of t0 (u |t0|, u = DBL_EPSILON / 2);
 *  - the evaluation divides by T and T^2 (qd = p'(u) / T, qdd = p''(u) /
 *    T^2). T^2 carries the relative error u of a double only as a normal
 *    number: below DBL_MIN gradual underflow rounds it with a larger
 *    relative error, down to 0 (T = 1e-300 s gives qdd = inf, NaN). So
 *    T^2 >= DBL_MIN, T >= sqrt(DBL_MIN) = 1.5e-154 s;
 *  - the peak acceleration 5.7735 |dq| / T^2 (prru_traj.h) must be a
 *    finite double, else it rounds to infinity. */
static const char *duration_lost(double t0, double t1, const double a[3], const double b[3])
{
  if (!(t1 > t0)) return "the knot time does not move";
  const double T = t1 - t0;
  if (!(T * T >= DBL_MIN)) return "its square, by which accelerations are divided, underflows";
  double dq = 0.0;
  for (int c = 0; c < 3; c++) dq = fmax(dq, fabs(b[c] - a[c]));
  if (!isfinite(5.7735 * (dq / T) / T)) return "the peak acceleration 5.7735 |dq| / T^2 overflows";
  return NULL;
}

int prru_quintic_waypoints(prru_quintic *tr, int n, const double *q, const double *durations,
                           double t0, char *msg, int msglen)
{
  tr->n = 0;
  tr->t = NULL;
  tr->coef = NULL;
  if (n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "need at least 2 waypoints, got %d", n);
  if (!isfinite(t0)) return prru_fail(msg, msglen, PRRU_EINPUT, "start time is not finite");
  double *t = malloc((size_t)n * sizeof *t), *z = calloc((size_t)n * 3, sizeof *z);
  if (!t || !z) {
    free(t);
    free(z);
    return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  }
  int st = PRRU_OK;
  t[0] = t0;
  for (int i = 0; i < n && st == PRRU_OK; i++) {
    if (!prru_finite_n(q + 3 * i, 3))
      st = prru_fail(msg, msglen, PRRU_EINPUT, "waypoint %d is not finite", i + 1);
    else if (i > 0 && !(durations[i - 1] > 0.0 && isfinite(durations[i - 1])))
      st = prru_fail(msg, msglen, PRRU_EINPUT,
                     "duration %d (waypoint %d to %d) must be a finite number > 0, got %g", i, i,
                     i + 1, durations[i - 1]);
    else if (i > 0) {
      t[i] = t[i - 1] + durations[i - 1];
      const char *why = duration_lost(t[i - 1], t[i], q + 3 * (i - 1), q + 3 * i);
      if (why)
        st = prru_fail(msg, msglen, PRRU_EINPUT,
                       "duration %d (waypoint %d to %d, %g s) is lost to rounding at t = %g s: %s",
                       i, i, i + 1, durations[i - 1], t[i - 1], why);
    }
  }
  if (st == PRRU_OK) st = prru_quintic_samples(tr, n, t, q, z, z, msg, msglen);
  free(t);
  free(z);
  return st;
}

/* The segment holding t: the last knot <= t (the final knot belongs to
 * the last segment). */
static int quintic_segment(const prru_quintic *tr, double t)
{
  int lo = 0, hi = tr->n - 2;
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (tr->t[mid] <= t)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

int prru_quintic_eval(const prru_quintic *tr, double t, double q[3], double qd[3],
                      double qdd[3])
{
  if (!tr || tr->n < 2 || !isfinite(t) || t < tr->t[0] || t > tr->t[tr->n - 1]) return PRRU_EINPUT;
  if (t == tr->t[tr->n - 1]) {
    const double *end = tr->coef + 18 * (tr->n - 1);
    if (q) memcpy(q, end, 3 * sizeof *q);
    if (qd) memcpy(qd, end + 3, 3 * sizeof *qd);
    if (qdd) memcpy(qdd, end + 6, 3 * sizeof *qdd);
    return PRRU_OK;
  }
  int s = quintic_segment(tr, t);
  double T = tr->t[s + 1] - tr->t[s], u = (t - tr->t[s]) / T;
  for (int c = 0; c < 3; c++) {
    const double *a = tr->coef + 18 * s + 6 * c;
    double p = a[5], dp = 5.0 * a[5], ddp = 20.0 * a[5];
    for (int k = 4; k >= 0; k--) p = p * u + a[k];
    for (int k = 4; k >= 1; k--) dp = dp * u + k * a[k];
    for (int k = 4; k >= 2; k--) ddp = ddp * u + k * (k - 1) * a[k];
    if (q) q[c] = p;
    if (qd) qd[c] = dp / T;
    if (qdd) qdd[c] = ddp / (T * T);
  }
  return PRRU_OK;
}

double prru_quintic_t_begin(const prru_quintic *tr) { return tr->t[0]; }
double prru_quintic_t_end(const prru_quintic *tr) { return tr->t[tr->n - 1]; }

long prru_row_count(double t0, double t1, double dt)
{
  const double span = t1 - t0;
  if (!(dt > 0) || !(span / dt <= 1e8)) return 0;
  /* A remainder of a rounding's size is no row of its own. */
  return (long)fmax(1.0, ceil(span / dt - 1e-9)) + 1;
}

double prru_row_time(double t0, double t1, double dt, long k, long rows)
{
  return k == rows - 1 ? t1 : t0 + (double)k * dt;
}

void prru_quintic_free(prru_quintic *tr)
{
  free(tr->t);
  free(tr->coef);
  tr->t = NULL;
  tr->coef = NULL;
  tr->n = 0;
}

int prru_traj_pose_ok(const prru_model *m, prru_data *d, const double q[3], double *rcond)
{
  return prru_check_regular(m, d, q, rcond);
}

void prru_path_side_init(prru_path_side *s) { s->sign = 0; }

int prru_path_side_crossed(prru_path_side *s, const double Jd[], int nact)
{
  const int sg = prru_jd_det_sign(Jd, nact);
  if (sg * s->sign < 0) return 1;
  if (sg) s->sign = sg;
  return 0;
}

int prru_path_sample(prru_path_side *s, const prru_model *m, prru_data *d, const double q[3], double *rcond,
                     int *crossed)
{
  if (crossed) *crossed = 0;
  const int st = prru_traj_pose_ok(m, d, q, rcond);
  if (st != PRRU_OK) return st;
  if (prru_path_side_crossed(s, d->Jd, m->mech->nact)) {
    if (crossed) *crossed = 1;
    return PRRU_ESINGULAR;
  }
  return PRRU_OK;
}
