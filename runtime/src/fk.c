/* Forward kinematics: q with d(q) = act by Newton's method on the closed
 * inverse kinematics, GSL's hybridsj with the exact Jacobian J_d (three
 * actuators); Gauss-Newton on |d(q) - act|^2 with J_d^+ (four, and the
 * least-squares variant for any number). */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multiroots.h>

#include "prru.h"
#include "internal.h"

/* The residual tolerances are relative to the larger of the model's
 * length and the slider heights, whatever the robot's size. */
static double fk_scale(const prru_model *m, const double act[])
{
  double scale = prru_length_scale(m->mech);
  for (int i = 0; i < m->mech->nact; i++) scale = fmax(scale, fabs(act[i]));
  return scale;
}

/* What the iterations aim at: 100 ulps of the scale. */
static double fk_tol(const prru_model *m, const double act[])
{
  return 100 * DBL_EPSILON * fk_scale(m, act);
}

/* Ten times fk_tol: hybridsj may stall a few ulps short of it. */
double prru_fk_tolerance(const prru_model *m, const double act[])
{
  return 1000 * DBL_EPSILON * fk_scale(m, act);
}

void prru_fk_default_seed(const prru_model *m, const double act[], double q0[3])
{
  /* ik_jd, the kernel prru_check_regular evaluates: d(0) as the solvers
   * see it, to the bit. */
  const double zero[3] = {0, 0, 0};
  const int na = m->mech->nact;
  double d0[PRRU_MAX_ACT], Jd0[PRRU_MAX_ACT * 3], sum = 0.0;
  KERNEL(m, ik_jd)(m->kernel_params, zero, d0, Jd0);
  for (int i = 0; i < na; i++) sum += act[i] - d0[i];
  q0[0] = q0[1] = 0.0;
  q0[2] = sum / na;
}

double prru_fk_residual(const prru_model *m, const double q[3], const double act[])
{
  /* The kernel prru_check_regular fills d->d with: the same residual as
   * prru_forward_kinematics_lsq's at its answer, to the bit. */
  double d[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3], res = 0;
  KERNEL(m, ik_jd)(m->kernel_params, q, d, Jd);
  for (int i = 0; i < m->mech->nact; i++) {
    const double r = fabs(d[i] - act[i]);
    if (isnan(r)) return NAN; /* fmax would drop it */
    res = fmax(res, r);
  }
  return res;
}

static int act_finite(int na, const double act[])
{
  for (int i = 0; i < na; i++)
    if (!isfinite(act[i])) return 0;
  return 1;
}

/* Residual r = d - act at the pose prru_check_regular last evaluated
 * (d->d); returns |r|^2, *rmax = max |r_i|. */
static double fk_residual(int na, const prru_data *d, const double act[], double r[], double *rmax)
{
  double f = 0, mx = 0;
  for (int i = 0; i < na; i++) {
    r[i] = d->d[i] - act[i];
    f += r[i] * r[i];
    mx = fmax(mx, fabs(r[i]));
  }
  *rmax = mx;
  return f;
}

int prru_forward_kinematics_lsq(const prru_model *m, prru_data *d, const double act[],
                                const double seed[3], double q[3], double *residual)
{
  if (residual) *residual = NAN;
  const int na = m->mech->nact;
  if (!act_finite(na, act)) return PRRU_EINPUT;
  int st = prru_check_regular(m, d, seed, NULL);
  if (st != PRRU_OK) return st;
  /* Steps need J_d^+ only to exist; the model's tolerance is applied to
   * the answer. */
  prru_model m0 = *m;
  m0.jd_rcond_min = 0.0;
  const double tol = fk_tol(m, act), L = prru_length_scale(m->mech);
  double x[3] = {seed[0], seed[1], seed[2]}, r[PRRU_MAX_ACT], rmax;
  double f = fk_residual(na, d, act, r, &rmax);
  /* Slider positions so far out that |r|^2 overflows: no step could ever
   * be accepted, and the seed would come back as a "fit". */
  if (!isfinite(f)) return PRRU_EINPUT;
  int iter, settled = 0;
  for (iter = 0; iter < 200 && !settled; iter++) {
    if (rmax <= tol) { settled = 1; break; }
    /* Gauss-Newton step -J_d^+ r, halved until |r|^2 decreases. */
    double step[3], xt[3], rt[PRRU_MAX_ACT], rmt = 0, ft = f;
    for (int j = 0; j < 3; j++) {
      step[j] = 0;
      for (int i = 0; i < na; i++) step[j] -= d->Jdpinv[na * j + i] * r[i];
    }
    /* Stationary: the step is below rounding of x (angles in rad, the
     * height in units of L). */
    if (fabs(step[0]) <= 4 * DBL_EPSILON * (1 + fabs(x[0])) &&
        fabs(step[1]) <= 4 * DBL_EPSILON * (1 + fabs(x[1])) &&
        fabs(step[2]) <= 4 * DBL_EPSILON * (L + fabs(x[2]))) {
      settled = 1;
      break;
    }
    int accepted = 0;
    for (double t = 1.0; t > 1e-12 && !accepted; t *= 0.5) {
      for (int j = 0; j < 3; j++) xt[j] = x[j] + t * step[j];
      if (prru_check_regular(&m0, d, xt, NULL) != PRRU_OK) continue;
      ft = fk_residual(na, d, act, rt, &rmt);
      accepted = ft < f;
    }
    if (!accepted) {
      /* No decrease along the Gauss-Newton direction: |r|^2 is at a
       * stationary point to rounding. Back to x (d must describe it). */
      settled = 1;
      if (prru_check_regular(&m0, d, x, NULL) != PRRU_OK) return PRRU_ENOCONV;
      break;
    }
    memcpy(x, xt, sizeof x);
    memcpy(r, rt, sizeof r);
    f = ft, rmax = rmt;
  }
  if (!settled) return PRRU_ENOCONV;
  st = prru_check_regular(m, d, x, NULL);
  if (st != PRRU_OK) return st == PRRU_EUNREACHABLE ? PRRU_ENOCONV : st;
  fk_residual(na, d, act, r, &rmax);
  if (residual) *residual = rmax;
  memcpy(q, x, sizeof x);
  return PRRU_OK;
}

typedef struct {
  const double *act;
  const prru_model *m;
} fk_ctx;

static int fk_f(const gsl_vector *x, void *p, gsl_vector *f)
{
  const fk_ctx *c = p;
  double q[3] = {gsl_vector_get(x, 0), gsl_vector_get(x, 1), gsl_vector_get(x, 2)}, d[3];
  KERNEL(c->m, ik)(c->m->kernel_params, q, d);
  for (int i = 0; i < 3; i++) {
    /* Outside the reachable set the solver must back off, not diverge. */
    if (!isfinite(d[i])) return GSL_EDOM;
    gsl_vector_set(f, (size_t)i, d[i] - c->act[i]);
  }
  return GSL_SUCCESS;
}

static int fk_fdf(const gsl_vector *x, void *p, gsl_vector *f, gsl_matrix *J)
{
  const fk_ctx *c = p;
  double q[3] = {gsl_vector_get(x, 0), gsl_vector_get(x, 1), gsl_vector_get(x, 2)}, d[3], Jd[9];
  KERNEL(c->m, ik_jd)(c->m->kernel_params, q, d, Jd);
  for (int i = 0; i < 3; i++) {
    if (!isfinite(d[i])) return GSL_EDOM;
    gsl_vector_set(f, (size_t)i, d[i] - c->act[i]);
    for (int j = 0; j < 3; j++) gsl_matrix_set(J, (size_t)i, (size_t)j, Jd[3 * i + j]);
  }
  return GSL_SUCCESS;
}

static int fk_df(const gsl_vector *x, void *p, gsl_matrix *J)
{
  double f[3];
  gsl_vector_view fv = gsl_vector_view_array(f, 3);
  return fk_fdf(x, p, &fv.vector, J);
}

/* Three actuators: Newton's method on the square system. */
static int fk_square(const prru_model *m, prru_data *d, const double act[], const double seed[3],
                     double q[3])
{
  if (!isfinite(act[0]) || !isfinite(act[1]) || !isfinite(act[2])) return PRRU_EINPUT;
  int st = prru_check_regular(m, d, seed, NULL);
  if (st != PRRU_OK) return st;
  fk_ctx c = {act, m};
  gsl_multiroot_function_fdf fn = {fk_f, fk_df, fk_fdf, 3, &c};
  double x0[3] = {seed[0], seed[1], seed[2]};
  gsl_vector_view xv = gsl_vector_view_array(x0, 3);
  /* The solver allocates; FK is a set-up call, not a hot path. */
  prru_gsl_init();
  gsl_multiroot_fdfsolver *s = gsl_multiroot_fdfsolver_alloc(gsl_multiroot_fdfsolver_hybridsj, 3);
  if (!s) return PRRU_ENOMEM;
  const double tol = fk_tol(m, act);
  int gs = gsl_multiroot_fdfsolver_set(s, &fn, &xv.vector);
  int iter = 0, converged = 0;
  while (gs == GSL_SUCCESS && iter++ < 200) {
    gs = gsl_multiroot_fdfsolver_iterate(s);
    if (gs != GSL_SUCCESS) break;
    if (gsl_multiroot_test_residual(s->f, tol) == GSL_SUCCESS) { converged = 1; break; }
  }
  double sol[3] = {gsl_vector_get(s->x, 0), gsl_vector_get(s->x, 1), gsl_vector_get(s->x, 2)};
  double res = 0;
  for (int i = 0; i < 3; i++) res = fmax(res, fabs(gsl_vector_get(s->f, (size_t)i)));
  gsl_multiroot_fdfsolver_free(s);
  if (!converged && !(res <= prru_fk_tolerance(m, act))) return PRRU_ENOCONV;
  st = prru_check_regular(m, d, sol, NULL);
  if (st != PRRU_OK) return st == PRRU_EUNREACHABLE ? PRRU_ENOCONV : st;
  memcpy(q, sol, sizeof sol);
  return PRRU_OK;
}
int prru_forward_kinematics(const prru_model *m, prru_data *d, const double act[],
                            const double seed[3], double q[3])
{
  if (m->mech->nact == 3) return fk_square(m, d, act, seed, q);
  /* Four actuators: d(q) = act has a solution only when act is consistent
   * (the fourth slider where the other three put it). Least squares, then
   * the same acceptance as hybridsj's: 10 times the tolerance. */
  double sol[3], res;
  int st = prru_forward_kinematics_lsq(m, d, act, seed, sol, &res);
  if (st != PRRU_OK) return st;
  if (!(res <= prru_fk_tolerance(m, act))) return PRRU_ENOCONV;
  memcpy(q, sol, sizeof sol);
  return PRRU_OK;
}
