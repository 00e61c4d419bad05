/* Simulation with the gsl_odeiv2 driver: state y = (q, qd), samples at
 * fixed times, every sample handed out as soon as it exists so that a run
 * that stops (workspace left, J_d singular, step failure, SIGINT) keeps all
 * it computed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "prru.h"
#include "internal.h"

static const char *const stepper_names[] = {"rk8pd", "rkf45", "rkck", "msbdf"};

int prru_stepper_parse(const char *name, prru_stepper *s)
{
  for (int i = 0; i < 4; i++)
    if (name && strcmp(name, stepper_names[i]) == 0) {
      *s = (prru_stepper)i;
      return PRRU_OK;
    }
  return PRRU_EINPUT;
}

const char *prru_stepper_name(prru_stepper s)
{
  return (unsigned)s < 4 ? stepper_names[s] : "?";
}

void prru_sim_options_default(prru_sim_options *o)
{
  memset(o, 0, sizeof *o);
  o->stepper = PRRU_RK8PD;
  o->t_end = 1.0;
  o->dt_out = 1e-3;
  o->abs_tol = 1e-10;
  o->rel_tol = 1e-10;
  o->h0 = 1e-4;
}

typedef struct {
  const prru_model *m;
  const prru_load_schedule *loads;
  prru_data *d;
  int status; /* why the right-hand side failed */
} sim_ctx;

static int rhs(double t, const double y[], double f[], void *p)
{
  sim_ctx *c = p;
  prru_loads l;
  prru_schedule_eval(c->loads, t, &l);
  memcpy(f, y + 3, 3 * sizeof y[0]);
  int st = prru_forward_dynamics(c->m, c->d, y, y + 3, &l, f + 3);
  if (st != PRRU_OK) {
    c->status = st;
    return GSL_EBADFUNC; /* the driver stops and reports */
  }
  return GSL_SUCCESS;
}

/* msbdf needs df/dy and df/dt: central differences of the right-hand
 * side, accurate enough for a Newton matrix. */
static int jac(double t, const double y[], double *dfdy, double dfdt[], void *p)
{
  double yp[6], fp[6], fm[6];
  for (int j = 0; j < 6; j++) {
    double h = 1e-7 * fmax(1.0, fabs(y[j]));
    memcpy(yp, y, sizeof yp);
    yp[j] = y[j] + h;
    if (rhs(t, yp, fp, p) != GSL_SUCCESS) return GSL_EBADFUNC;
    yp[j] = y[j] - h;
    if (rhs(t, yp, fm, p) != GSL_SUCCESS) return GSL_EBADFUNC;
    for (int i = 0; i < 6; i++) dfdy[6 * i + j] = (fp[i] - fm[i]) / (2 * h);
  }
  double ht = 1e-7 * fmax(1.0, fabs(t));
  if (rhs(t + ht, y, fp, p) != GSL_SUCCESS || rhs(t - ht, y, fm, p) != GSL_SUCCESS)
    return GSL_EBADFUNC;
  for (int i = 0; i < 6; i++) dfdt[i] = (fp[i] - fm[i]) / (2 * ht);
  return GSL_SUCCESS;
}

static const gsl_odeiv2_step_type *step_type(prru_stepper s)
{
  switch (s) {
  case PRRU_RKF45: return gsl_odeiv2_step_rkf45;
  case PRRU_RKCK: return gsl_odeiv2_step_rkck;
  case PRRU_MSBDF: return gsl_odeiv2_step_msbdf;
  default: return gsl_odeiv2_step_rk8pd;
  }
}

/* Everything a sample reports; PRRU_ESINGULAR when J_d is singular there. */
static int make_sample(const prru_model *m, prru_data *d, const prru_load_schedule *ls,
                       int reactions, double t, const double y[6], prru_sample *s)
{
  prru_loads l;
  prru_schedule_eval(ls, t, &l);
  s->t = t;
  memcpy(s->q, y, sizeof s->q);
  memcpy(s->qd, y + 3, sizeof s->qd);
  int st = prru_check_regular(m, d, s->q, NULL);
  if (st != PRRU_OK) return st;
  memcpy(s->d, d->d, sizeof s->d);
  if (reactions) { /* solves the forward dynamics too (d->qdd) */
    st = prru_reactions(m, d, s->q, s->qd, &l, s->lambda);
    if (st != PRRU_OK) return st;
    memcpy(s->qdd, d->qdd, sizeof s->qdd);
  } else {
    st = prru_forward_dynamics(m, d, s->q, s->qd, &l, s->qdd);
    if (st != PRRU_OK) return st;
    for (int i = 0; i < PRRU_NLAMBDA; i++) s->lambda[i] = NAN;
  }
  return prru_energies(m, s->q, s->qd, &s->T, &s->V);
}

static void progress(double t, double t_end)
{
  int w = 40, n = (int)(w * t / t_end + 0.5);
  fprintf(stderr, "\rsimulating [%.*s%*s] %5.1f%% t = %.3f s", n,
          "########################################", w - n, "", 100.0 * t / t_end, t);
  fflush(stderr);
}

static int check_options(const prru_sim_options *o, char *msg, int msglen)
{
  if (!(isfinite(o->t_end) && o->t_end > 0))
    return prru_fail(msg, msglen, PRRU_EINPUT, "t_end must be a positive number of seconds");
  if (!(isfinite(o->dt_out) && o->dt_out > 0 && o->dt_out <= o->t_end))
    return prru_fail(msg, msglen, PRRU_EINPUT, "dt must be positive and at most t_end");
  if (o->t_end / o->dt_out > 1e8)
    return prru_fail(msg, msglen, PRRU_EINPUT, "t_end/dt above 1e8 samples");
  if (!(o->abs_tol >= 0 && o->rel_tol >= 0 && o->abs_tol + o->rel_tol > 0 &&
        isfinite(o->abs_tol) && isfinite(o->rel_tol)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "tolerances must be non-negative, not both zero");
  if (!(isfinite(o->h0) && o->h0 > 0))
    return prru_fail(msg, msglen, PRRU_EINPUT, "first step h0 must be positive");
  if ((unsigned)o->stepper > PRRU_MSBDF) return prru_fail(msg, msglen, PRRU_EINPUT, "unknown stepper");
  return PRRU_OK;
}

int prru_simulate(const prru_model *m, const double q0[3], const double qd0[3],
                  const prru_sim_options *o, double *t_stop, char *msg, int msglen)
{
  if (t_stop) *t_stop = NAN;
  int st = check_options(o, msg, msglen);
  if (st != PRRU_OK) return st;
  for (int i = 0; i < 3; i++)
    if (!isfinite(q0[i]) || !isfinite(qd0[i]))
      return prru_fail(msg, msglen, PRRU_EINPUT, "initial state is not finite");
  prru_load_schedule none;
  const prru_load_schedule *ls = o->loads;
  if (!ls) {
    prru_loads zero;
    memset(&zero, 0, sizeof zero);
    prru_schedule_constant(&none, &zero);
    ls = &none;
  }
  prru_data *d = malloc(sizeof *d);      /* ~55 kB: not for the stack */
  prru_data *drhs = malloc(sizeof *drhs);
  prru_sample *s = malloc(sizeof *s);
  if (!d || !drhs || !s) {
    free(d); free(drhs); free(s);
    return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  }
  sim_ctx c = {m, ls, drhs, PRRU_OK};
  gsl_odeiv2_system sys = {rhs, jac, 6, &c};
  prru_gsl_init();
  gsl_odeiv2_driver *drv =
      gsl_odeiv2_driver_alloc_y_new(&sys, step_type(o->stepper), o->h0, o->abs_tol, o->rel_tol);
  double y[6] = {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2]}, t = 0.0;
  /* Samples at k dt, the last one at exactly t_end. */
  long nsamp = (long)ceil(o->t_end / o->dt_out - 1e-9);
  st = drv ? PRRU_OK : PRRU_ENOMEM;
  if (st != PRRU_OK) prru_fail(msg, msglen, st, "out of memory");
  for (long k = 0; st == PRRU_OK && k <= nsamp; k++) {
    double tk = k == nsamp ? o->t_end : (double)k * o->dt_out;
    if (k > 0) {
      c.status = PRRU_OK;
      int gs = gsl_odeiv2_driver_apply(drv, &t, tk, y);
      if (gs != GSL_SUCCESS) {
        st = c.status != PRRU_OK ? c.status : PRRU_ENOCONV;
        prru_fail(msg, msglen, st, "stopped at t = %.9g s: %s%s", t,
                  c.status != PRRU_OK ? prru_strerror(c.status) : "integrator failed: ",
                  c.status != PRRU_OK ? "" : gsl_strerror(gs));
        break;
      }
    }
    int ss = make_sample(m, d, ls, o->reactions, tk, y, s);
    if (ss != PRRU_OK) {
      st = ss;
      prru_fail(msg, msglen, st, "stopped at t = %.9g s: %s at q = (%.9g, %.9g, %.9g)", tk,
                prru_strerror(ss), y[0], y[1], y[2]);
      break;
    }
    if (t_stop) *t_stop = tk;
    if (o->on_sample && o->on_sample(s, o->ctx) != 0) {
      st = PRRU_EINTERRUPTED;
      prru_fail(msg, msglen, st, "stopped at t = %.9g s by the sample consumer", tk);
      break;
    }
    if (o->interrupt && *o->interrupt) {
      st = PRRU_EINTERRUPTED;
      prru_fail(msg, msglen, st, "interrupted at t = %.9g s", tk);
      break;
    }
    if (o->progress && (k % 50 == 0 || k == nsamp)) progress(tk, o->t_end);
  }
  if (o->progress) fputc('\n', stderr);
  if (drv) gsl_odeiv2_driver_free(drv);
  free(d); free(drhs); free(s);
  if (st == PRRU_OK && msg && msglen > 0) msg[0] = '\0';
  return st;
}
