#include "bench_refsim.h"

#include <math.h>
#include <stdio.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "prru_ref.h"

/* M_PI is not C99. */
#define BENCH_PI 3.14159265358979323846

typedef struct {
  prru_ref_params p;
  prru_ref_ws *w;
  double fd[PRRU_MAX_ACT];
} refsim_ctx;

void bench_refsim_initial(double q0[3], double qd0[3])
{
  q0[0] = 0.0;
  q0[1] = BENCH_PI / 6.0;
  q0[2] = -0.8;
  qd0[0] = qd0[1] = qd0[2] = 0.0;
}

/* The section 4.3 loads written out here rather than taken from the
 * runtime's prru_schedule_paper, so that the two paths agree only if both
 * implement the spec. */
static const double paper_fd[3] = {50.0, 40.0, 25.0};

static int refsim_rhs(double t, const double y[], double dydt[], void *params)
{
  refsim_ctx *c = params;
  const double *fd = c->fd;
  const double fp[3] = {50.0 * sin(4.0 * BENCH_PI * t), -50.0 * cos(4.0 * BENCH_PI * t), 0.0};
  const double mp[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < 3; i++) dydt[i] = y[3 + i];
  if (prru_ref_forward_dynamics(&c->p, c->w, y, y + 3, fd, fp, mp, dydt + 3) != GSL_SUCCESS)
    return GSL_EBADFUNC; /* left the workspace: makes the driver stop */
  return GSL_SUCCESS;
}

int bench_refsim_paper(const bench_refsim_options *o, double y[6], unsigned long *steps)
{
  refsim_ctx c;
  prru_ref_params_default(&c.p);
  for (int i = 0; i < c.p.nlimb; i++) /* one actuator per limb */
    c.fd[i] = paper_fd[i < 3 ? i : 2]; /* as prru_schedule_paper */
  c.w = prru_ref_alloc();
  if (!c.w) {
    fprintf(stderr, "prru_bench: reference simulation: out of memory\n");
    return GSL_ENOMEM;
  }
  gsl_odeiv2_system sys = {refsim_rhs, NULL, 6, &c};
  gsl_odeiv2_driver *drv = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, o->h0,
                                                         o->abs_tol, o->rel_tol);
  if (!drv) {
    prru_ref_free(c.w);
    fprintf(stderr, "prru_bench: reference simulation: out of memory\n");
    return GSL_ENOMEM;
  }
  bench_refsim_initial(y, y + 3);
  double t = 0.0;
  int status = gsl_odeiv2_driver_apply(drv, &t, o->t_end, y);
  *steps = drv->n;
  if (status != GSL_SUCCESS)
    fprintf(stderr, "prru_bench: reference simulation stopped at t = %g s: %s\n", t,
            gsl_strerror(status));
  gsl_odeiv2_driver_free(drv);
  prru_ref_free(c.w);
  return status;
}
