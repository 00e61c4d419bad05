/* Forward kinematics: q with d(q) = act by Newton's method on the closed
 * inverse kinematics, GSL's hybridsj with the exact Jacobian J_d. */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multiroots.h>

#include "prru.h"
#include "internal.h"

typedef struct {
  const double *act;
} fk_ctx;

static int fk_f(const gsl_vector *x, void *p, gsl_vector *f)
{
  const fk_ctx *c = p;
  double q[3] = {gsl_vector_get(x, 0), gsl_vector_get(x, 1), gsl_vector_get(x, 2)}, d[3];
  prru_ik(q, d);
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
  prru_ik_jd(q, d, Jd);
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

int prru_forward_kinematics(const prru_model *m, prru_data *d, const double act[PRRU_NACT],
                            const double seed[3], double q[3])
{
  if (!isfinite(act[0]) || !isfinite(act[1]) || !isfinite(act[2])) return PRRU_EINPUT;
  int st = prru_check_regular(m, d, seed, NULL);
  if (st != PRRU_OK) return st;
  fk_ctx c = {act};
  gsl_multiroot_function_fdf fn = {fk_f, fk_df, fk_fdf, 3, &c};
  double x0[3] = {seed[0], seed[1], seed[2]};
  gsl_vector_view xv = gsl_vector_view_array(x0, 3);
  /* The solver allocates; FK is a set-up call, not a hot path. */
  prru_gsl_init();
  gsl_multiroot_fdfsolver *s = gsl_multiroot_fdfsolver_alloc(gsl_multiroot_fdfsolver_hybridsj, 3);
  if (!s) return PRRU_ENOMEM;
  /* The residual tolerance is relative: 100 ulps of the larger of the
   * model's length and the slider heights, whatever the robot's size. */
  double scale = prru_length_scale(m->mech);
  for (int i = 0; i < PRRU_NACT; i++) scale = fmax(scale, fabs(act[i]));
  const double tol = 100 * DBL_EPSILON * scale;
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
  /* hybridsj may stall a few ulps short of tol; accept ten times it. */
  if (!converged && !(res <= 10 * tol)) return PRRU_ENOCONV;
  st = prru_check_regular(m, d, sol, NULL);
  if (st != PRRU_OK) return st == PRRU_EUNREACHABLE ? PRRU_ENOCONV : st;
  memcpy(q, sol, sizeof sol);
  return PRRU_OK;
}
