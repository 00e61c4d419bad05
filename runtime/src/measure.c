/* Simulated measurements (prru_measure.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "internal.h"
#include "prru_measure.h"

void prru_measure_options_default(prru_measure_options *o)
{
  o->rate = 0;
  o->d_resolution = 0;
  o->force_sigma = 0;
  o->seed = 1;
}

static int bad_option(const prru_measure_options *o, char *msg, int msglen)
{
  const char *what = NULL;
  if (!(isfinite(o->rate) && o->rate >= 0)) what = "rate";
  else if (!(isfinite(o->d_resolution) && o->d_resolution >= 0)) what = "d_resolution";
  else if (!(isfinite(o->force_sigma) && o->force_sigma >= 0)) what = "force_sigma";
  if (what && msg && msglen > 0) snprintf(msg, (size_t)msglen, "%s must be finite and >= 0", what);
  return what != NULL;
}

int prru_measure_rows(const double *t, int n, const prru_measure_options *o, int *idx, int *nout, char *msg,
                      int msglen)
{
  *nout = 0;
  if (bad_option(o, msg, msglen) || n < 1) {
    if (n < 1 && msg && msglen > 0) snprintf(msg, (size_t)msglen, "the run has no rows");
    return PRRU_EINPUT;
  }
  if (o->rate == 0) {
    for (int i = 0; i < n; i++) idx[i] = i;
    *nout = n;
    return PRRU_OK;
  }
  /* Sample k at t_0 + k T: the row within 1e-6 T of it. Rows are
   * increasing, so one pass finds them in order. */
  const double T = 1.0 / o->rate, tol = 1e-6 * T;
  int i = 0;
  for (long k = 0;; k++) {
    const double tk = t[0] + (double)k * T;
    if (tk > t[n - 1] + tol) break;
    while (i < n && t[i] < tk - tol) i++;
    if (i >= n || fabs(t[i] - tk) > tol) {
      if (msg && msglen > 0)
        snprintf(msg, (size_t)msglen,
                 "no row at t = %.9g s, sample %ld at %.9g Hz: the run's rows must fall on the sensor's "
                 "clock (a run with rows every 1 / (j x rate) s)",
                 tk, k + 1, o->rate);
      return PRRU_EINPUT;
    }
    idx[(*nout)++] = i++;
  }
  return PRRU_OK;
}

int prru_measure_apply(const prru_measure_options *o, int n, int nact, double *d, double *fd, char *msg,
                       int msglen)
{
  if (bad_option(o, msg, msglen)) return PRRU_EINPUT;
  const double r = o->d_resolution;
  if (r > 0)
    for (long k = 0; k < (long)n * nact; k++) d[k] = r * nearbyint(d[k] / r);
  if (o->force_sigma > 0) {
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) {
      if (msg && msglen > 0) snprintf(msg, (size_t)msglen, "out of memory");
      return PRRU_ENOMEM;
    }
    gsl_rng_set(rng, o->seed);
    for (long k = 0; k < (long)n * nact; k++) fd[k] += gsl_ran_gaussian(rng, o->force_sigma);
    gsl_rng_free(rng);
  }
  return PRRU_OK;
}

/* The error of one setting: max over coordinates of RMS(qdd_est - qdd) /
 * RMS(qdd), over those with motion, at every stride-th row (an unbiased
 * sample of the RMS over all rows, windows at the ends included in their
 * share: trying 48 settings on every row of a long run would take
 * seconds). Negative when the setting does not apply. */
static double setting_error(int n, const double *t, const double *q, const double *qdd, const prru_diff_options *o,
                            int stride)
{
  double e[3] = {0, 0, 0}, s[3] = {0, 0, 0}, w[3][PRRU_DIFF_MAX_WINDOW];
  const int len = 2 * o->half_width + 1;
  for (int i = 0; i < n; i += stride) {
    int f;
    if (prru_diff_weights(t, n, i, o, &f, w) != PRRU_OK) return -1;
    for (int k = 0; k < 3; k++) {
      double est = 0;
      for (int j = 0; j < len; j++) est += w[2][j] * q[3 * (f + j) + k];
      const double x = est - qdd[3 * i + k];
      e[k] += x * x;
      s[k] += qdd[3 * i + k] * qdd[3 * i + k];
    }
  }
  double worst = 0;
  for (int k = 0; k < 3; k++)
    if (s[k] > 0) worst = fmax(worst, sqrt(e[k] / s[k]));
  return worst;
}

int prru_measure_poses(const prru_model *m, int n, const double *d, double dres, double *q, int *row,
                       double *residual, char *msg, int msglen)
{
  *row = -1;
  *residual = NAN;
  prru_data *ws = malloc(sizeof *ws);
  if (!ws) return PRRU_ENOMEM;
  double seed[3] = {0, 0, 0};
  if (n > 0) prru_fk_default_seed(m, d, seed);
  int st = PRRU_OK;
  for (int i = 0; i < n && st == PRRU_OK; i++) {
    const double *act = d + (size_t)m->mech->nact * i;
    double res = NAN;
    st = prru_forward_kinematics_lsq(m, ws, act, seed, q + 3 * i, &res);
    if (st != PRRU_OK) {
      *row = i;
      if (msg && msglen > 0)
        snprintf(msg, (size_t)msglen, "row %d: no pose for the measured sliders (%s)", i + 1, prru_strerror(st));
    } else if (!(res <= dres + 1e-9 * (1 + fabs(act[0])))) {
      /* The solver stops within 1e-9 (1 + |d_1|) of the least-squares
       * pose, which quantisation moves by at most dres. */
      *row = i, *residual = res;
      st = PRRU_EINPUT;
      if (msg && msglen > 0)
        snprintf(msg, (size_t)msglen, "row %d: inconsistent slider positions: residual %.3g m beyond the "
                 "resolution %.3g m", i + 1, res, dres);
    }
    memcpy(seed, q + 3 * i, sizeof seed);
  }
  free(ws);
  return st;
}

int prru_measure_best_diff(const prru_model *m, int n, const double *t, const double *d, const double *qdd,
                           prru_diff_choice *c, char *msg, int msglen)
{
  memset(c, 0, sizeof *c);
  if (n < 3) {
    if (msg && msglen > 0) snprintf(msg, (size_t)msglen, "%d rows: at least 3 are needed to differentiate", n);
    return PRRU_EINPUT;
  }
  int moving = 0;
  for (long k = 0; k < 3L * n && !moving; k++) moving = qdd[k] != 0;
  if (!moving) {
    if (msg && msglen > 0) snprintf(msg, (size_t)msglen, "the exact qdd is zero throughout: nothing to compare");
    return PRRU_EINPUT;
  }
  double *q = malloc(sizeof(double) * 3 * (size_t)n), res;
  int row;
  int st = q ? prru_measure_poses(m, n, d, INFINITY, q, &row, &res, msg, msglen) : PRRU_ENOMEM;
  prru_diff_options def;
  prru_diff_options_default(&def);
  c->best_error = INFINITY;
  c->default_error = NAN;
  const int stride = n > 1000 ? (n + 999) / 1000 : 1;
  for (int h = 1; h <= PRRU_DIFF_MAX_HALF && st == PRRU_OK && 2 * h + 1 <= n; h++)
    for (int p = 2; p <= 4 && p <= 2 * h; p += 2) {
      prru_diff_options o = {h, p};
      const double e = setting_error(n, t, q, qdd, &o, stride);
      if (e < 0) continue;
      c->tried++;
      if (h == def.half_width && p == def.degree) c->default_error = e;
      if (e < c->best_error) c->best_error = e, c->best = o;
    }
  if (st == PRRU_OK && c->tried == 0) {
    if (msg && msglen > 0) snprintf(msg, (size_t)msglen, "no differentiation setting applies to %d rows", n);
    st = PRRU_EINPUT;
  }
  free(q);
  if (st == PRRU_ENOMEM && msg && msglen > 0) snprintf(msg, (size_t)msglen, "out of memory for %d rows", n);
  return st;
}
