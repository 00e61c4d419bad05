/* Simulation with the gsl_odeiv2 driver: state y = (q, qd), samples at
 * fixed times, every sample handed out as soon as it exists so that a run
 * that stops (workspace left, J_d singular, step failure, step budget
 * spent, SIGINT, also in the middle of a step) keeps all it computed.
 * Tolerances below PRRU_TOL_MIN are refused up front: they cannot be met
 * and used to make the step size collapse for ever. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "prru.h"
#include "internal.h"
#include "prru_linearize.h"

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
  volatile sig_atomic_t *interrupt;
  int status; /* why the right-hand side last failed */
  double t_fail, y_fail[6]; /* where it did */
} sim_ctx;

/* When the right-hand side cannot evaluate (a state outside the
 * workspace, J_d singular, not finite; or an interrupt) it returns
 * GSL_EBADFUNC, on which every stepper, GSL's evolve and the driver return
 * at once, even in the middle of a long step; c->status says why. (Any
 * other status would make evolve retry with half the step: a run would
 * then skirt the singular set between accepted states and crawl towards
 * the boundary in steps of a few ulp instead of stopping.) */
#define RHS_STOP GSL_EBADFUNC

static int rhs(double t, const double y[], double f[], void *p)
{
  sim_ctx *c = p;
  if (c->interrupt && *c->interrupt) {
    c->status = PRRU_EINTERRUPTED;
    return RHS_STOP;
  }
  prru_loads l;
  prru_schedule_eval(c->loads, t, &l);
  memcpy(f, y + 3, 3 * sizeof y[0]);
  int st = prru_forward_dynamics(c->m, c->d, y, y + 3, &l, f + 3);
  if (st != PRRU_OK) {
    c->status = st;
    c->t_fail = t;
    memcpy(c->y_fail, y, sizeof c->y_fail);
    return RHS_STOP;
  }
  return GSL_SUCCESS;
}

/* msbdf needs df/dy and df/dt, by finite differences of the right-hand
 * side, accurate enough for a Newton matrix. msbdf asks for them at its
 * predicted point, which may lie within a difference step of the
 * workspace's boundary (an acos argument near +-1, J_d nearly singular),
 * so a probe that fails must not end the run: column j takes central
 * differences where both probes y +- h e_j evaluate, else second-order
 * one-sided differences on the side that does (y + 2h e_j there, else
 * first order), else the same with h / 16, three times. The Jacobian fails
 * only when y itself, or every probe of a column, does; probes that fail
 * leave c->status as it was. */
static int jac_differences(double t, const double y[], double *dfdy, double dfdt[], void *p)
{
  sim_ctx *c = p;
  const int status0 = c->status;
  double yp[6], f0[6], fp[6], fm[6], f2[6];
  if (rhs(t, y, f0, p) != GSL_SUCCESS) return RHS_STOP;
  for (int j = 0; j < 6; j++) {
    double h = 1e-7 * fmax(1.0, fabs(y[j]));
    int done = 0;
    for (int shrink = 0; shrink < 4 && !done; shrink++, h /= 16) {
      memcpy(yp, y, sizeof yp);
      yp[j] = y[j] + h;
      int okp = rhs(t, yp, fp, p) == GSL_SUCCESS;
      yp[j] = y[j] - h;
      int okm = rhs(t, yp, fm, p) == GSL_SUCCESS;
      if (c->status == PRRU_EINTERRUPTED) return RHS_STOP;
      if (okp && okm) {
        for (int i = 0; i < 6; i++) dfdy[6 * i + j] = (fp[i] - fm[i]) / (2 * h);
        done = 1;
      } else if (okp || okm) { /* one-sided, sh the step towards the inside */
        const double sh = okp ? h : -h, *f1 = okp ? fp : fm;
        yp[j] = y[j] + 2 * sh;
        int ok2 = rhs(t, yp, f2, p) == GSL_SUCCESS;
        if (c->status == PRRU_EINTERRUPTED) return RHS_STOP;
        for (int i = 0; i < 6; i++)
          dfdy[6 * i + j] = ok2 ? (-3 * f0[i] + 4 * f1[i] - f2[i]) / (2 * sh) : (f1[i] - f0[i]) / sh;
        done = 1;
      }
    }
    if (!done) return RHS_STOP; /* c->status: the last probe's reason */
  }
  /* t enters through the loads only, which are defined for every t. */
  double ht = 1e-7 * fmax(1.0, fabs(t));
  if (rhs(t + ht, y, fp, p) != GSL_SUCCESS || rhs(t - ht, y, fm, p) != GSL_SUCCESS)
    return RHS_STOP;
  for (int i = 0; i < 6; i++) dfdt[i] = (fp[i] - fm[i]) / (2 * ht);
  c->status = status0;
  return GSL_SUCCESS;
}

/* msbdf's df/dy in closed form: A of prru_linearize at y under the loads
 * at t (the generated derivative kernels, one call instead of the 13
 * right-hand sides of the differences above), and df/dt through the loads
 * alone, [0; dqdd/dfd fd' + dqdd/dfp fp' + dqdd/dmp mp'], their rates by
 * central differences of the schedule (exact on a table's linear pieces,
 * as the differences of the right-hand side were). Where y is not trusted
 * it fails as the right-hand side does; where only the derivatives
 * overflow, the differences above. */
static int jac(double t, const double y[], double *dfdy, double dfdt[], void *p)
{
  sim_ctx *c = p;
  if (c->interrupt && *c->interrupt) {
    c->status = PRRU_EINTERRUPTED;
    return RHS_STOP;
  }
  prru_loads l, lp, lm;
  prru_schedule_eval(c->loads, t, &l);
  prru_linearization lin;
  const int st = prru_linearize(c->m, c->d, y, y + 3, &l, 0.0, &lin);
  if (st != PRRU_OK) return jac_differences(t, y, dfdy, dfdt, p);
  memcpy(dfdy, lin.A, sizeof lin.A);
  const double ht = 1e-7 * fmax(1.0, fabs(t));
  prru_schedule_eval(c->loads, t + ht, &lp);
  prru_schedule_eval(c->loads, t - ht, &lm);
  for (int i = 0; i < 3; i++) {
    double r = 0;
    const int na = c->m->mech->nact;
    for (int k = 0; k < na; k++)
      r += lin.dqdd_dfd[na * i + k] * (lp.fd[k] - lm.fd[k]);
    for (int k = 0; k < 3; k++)
      r += lin.dqdd_dfp[3 * i + k] * (lp.fp[k] - lm.fp[k]) + lin.dqdd_dmp[3 * i + k] * (lp.mp[k] - lm.mp[k]);
    dfdt[i] = 0;
    dfdt[3 + i] = r / (2 * ht);
  }
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
    for (int i = 0; i < m->mech->nlambda; i++) s->lambda[i] = NAN;
  }
  return prru_energies(m, s->q, s->qd, &s->T, &s->V);
}

/* PRRU_EINPUT with msg, naming member F in *field (when asked for). */
#define bad_option(F, field, msg, msglen, ...) \
  ((field) ? (void)(*(field) = (F)) : (void)0, prru_fail(msg, msglen, PRRU_EINPUT, __VA_ARGS__))

int prru_sim_options_check(const prru_sim_options *o, const char **field, char *msg, int msglen)
{
  if (field) *field = NULL;
  if (!(isfinite(o->t_end) && o->t_end > 0))
    return bad_option("t_end", field, msg, msglen, "t_end = %g: must be a positive number of seconds", o->t_end);
  if (!(isfinite(o->dt_out) && o->dt_out > 0 && o->dt_out <= o->t_end))
    return bad_option("dt_out", field, msg, msglen, "dt_out = %g: must be positive and at most t_end (%g s)",
                      o->dt_out, o->t_end);
  if (o->t_end / o->dt_out > 1e8)
    return bad_option("dt_out", field, msg, msglen, "dt_out = %g: more than 1e8 samples up to t_end = %g s",
                      o->dt_out, o->t_end);
  if ((unsigned)o->stepper > PRRU_MSBDF)
    return bad_option("stepper", field, msg, msglen, "stepper = %d: not a prru_stepper", (int)o->stepper);
  const struct { const char *name; double v; } tol[2] = {{"rel_tol", o->rel_tol}, {"abs_tol", o->abs_tol}};
  for (int i = 0; i < 2; i++)
    if (!(tol[i].v >= 0 && isfinite(tol[i].v)))
      return bad_option(tol[i].name, field, msg, msglen, "%s = %g: must be a non-negative number", tol[i].name,
                        tol[i].v);
  if (o->abs_tol + o->rel_tol == 0)
    return bad_option("abs_tol", field, msg, msglen, "abs_tol and rel_tol are both 0: give at least one");
  /* Below PRRU_TOL_MIN a tolerance is rounding noise (see prru.h). */
  for (int i = 0; i < 2; i++)
    if (tol[i].v > 0 && tol[i].v < PRRU_TOL_MIN)
      return bad_option(tol[i].name, field, msg, msglen,
                        "%s = %g is below %.2g (100 x DBL_EPSILON), which no double-precision step can "
                        "resolve: use 0 (off) or at least %.2g", tol[i].name, tol[i].v, PRRU_TOL_MIN, PRRU_TOL_MIN);
  if (o->stepper == PRRU_MSBDF && o->abs_tol == 0)
    return bad_option("abs_tol", field, msg, msglen,
                      "abs_tol = 0 (relative control only) does not work with msbdf, which divides by each "
                      "component's error level (0 wherever the component is 0): give abs_tol > 0");
  if (o->max_steps < 0)
    return bad_option("max_steps", field, msg, msglen,
                      "max_steps = %ld: give a positive number of steps per output interval, or 0 for the "
                      "default (%ld)", o->max_steps, PRRU_MAX_STEPS_DEFAULT);
  if (!(isfinite(o->h0) && o->h0 > 0))
    return bad_option("h0", field, msg, msglen, "h0 = %g: the first step must be positive (s)", o->h0);
  return PRRU_OK;
}

int prru_simulate(const prru_model *m, const double q0[3], const double qd0[3],
                  const prru_sim_options *o, double *t_stop, char *msg, int msglen)
{
  if (t_stop) *t_stop = NAN;
  int st = prru_sim_options_check(o, NULL, msg, msglen);
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
  /* A table's force columns are those of the model it was read for. */
  if (ls->kind == PRRU_LOAD_TABLE && ls->nact != m->mech->nact)
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "the loads table has %d actuator force columns; model %s has %d actuators", ls->nact,
                     m->mech->name, m->mech->nact);
  prru_data *d = malloc(sizeof *d);      /* ~55 kB: not for the stack */
  prru_data *drhs = malloc(sizeof *drhs);
  prru_sample *s = malloc(sizeof *s);
  if (!d || !drhs || !s) {
    free(d); free(drhs); free(s);
    return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  }
  sim_ctx c = {m, ls, drhs, o->interrupt, PRRU_OK, 0.0, {0}};
  gsl_odeiv2_system sys = {rhs, jac, 6, &c};
  prru_gsl_init();
  gsl_odeiv2_driver *drv =
      gsl_odeiv2_driver_alloc_y_new(&sys, step_type(o->stepper), o->h0, o->abs_tol, o->rel_tol);
  /* GSL's driver returns GSL_EMAXITER once an apply has taken more than
   * nmax accepted steps (rejected ones are bounded per accepted step). */
  const long budget = o->max_steps > 0 ? o->max_steps : PRRU_MAX_STEPS_DEFAULT;
  if (drv) gsl_odeiv2_driver_set_nmax(drv, (unsigned long)budget);
  double t_last = 0.0; /* the last sample delivered */
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
      if (gs == RHS_STOP && c.status == PRRU_EINTERRUPTED) {
        st = PRRU_EINTERRUPTED;
        prru_fail(msg, msglen, st, "interrupted at t = %.9g s (during the step to t = %.9g s)",
                  t_last, tk);
        break;
      }
      if (gs == GSL_EMAXITER) {
        st = PRRU_ENOCONV;
        prru_fail(msg, msglen, st,
                  "stopped at t = %.9g s: step budget of %ld steps exhausted at t = %.9g s on the "
                  "way to the sample at t = %.9g s (raise max_steps, or loosen the tolerances)",
                  t_last, budget, t, tk);
        break;
      }
      if (gs == RHS_STOP && c.status != PRRU_OK) {
        /* A step's trial state whose dynamics failed: every stepper meets
         * the same edge of the trusted workspace (prru_model.mass_rcond_min)
         * within a step of the others, so the report names that state and
         * the library's one diagnosis of it, whichever stepper ran. */
        char why[256];
        prru_loads lf;
        prru_schedule_eval(ls, c.t_fail, &lf);
        st = prru_forward_dynamics_why(m, d, c.y_fail, c.y_fail + 3, &lf, why, sizeof why);
        if (st == PRRU_OK) st = c.status; /* not reproduced: report the status */
        const int edge = st == PRRU_EUNREACHABLE || st == PRRU_ESINGULAR || st == PRRU_ESTROKE;
        prru_fail(msg, msglen, st, "stopped at t = %.9g s: %s at t = %.9g s: %s", t,
                  edge ? "the motion reached the workspace boundary"
                       : "the dynamics failed in the step",
                  c.t_fail, why[0] ? why : prru_strerror(st));
        break;
      }
      if (gs != GSL_SUCCESS) {
        st = PRRU_ENOCONV;
        prru_fail(msg, msglen, st, "stopped at t = %.9g s: integrator failed: %s", t,
                  gsl_strerror(gs));
        break;
      }
    }
    int ss = make_sample(m, d, ls, o->reactions, tk, y, s);
    if (ss != PRRU_OK) {
      /* The sample's own state: the same diagnosis as a failed step's
       * (prru_forward_dynamics_why), or, where the forward dynamics are
       * fine, what make_sample added (J_d singular, the reactions). */
      char why[256];
      prru_loads lk;
      prru_schedule_eval(ls, tk, &lk);
      st = prru_forward_dynamics_why(m, d, y, y + 3, &lk, why, sizeof why);
      if (st == PRRU_OK && ss == PRRU_EINPUT) /* the reactions or the energy overflow */
        snprintf(why, sizeof why,
                 "the dynamics overflow (velocities or loads too large: qd = (%.9g, %.9g, %.9g))",
                 y[3], y[4], y[5]);
      else if (st == PRRU_OK)
        snprintf(why, sizeof why, "%s at q = (%.9g, %.9g, %.9g)", prru_strerror(ss), y[0], y[1],
                 y[2]);
      /* Only a state whose own dynamics fail is the workspace's edge; a
       * singular J_d there (make_sample's test) is a singularity inside. */
      const int edge = st == PRRU_EUNREACHABLE || st == PRRU_ESINGULAR || st == PRRU_ESTROKE;
      if (st == PRRU_OK) st = ss;
      prru_fail(msg, msglen, st, "stopped at t = %.9g s: %s%s", tk,
                edge ? "the motion reached the workspace boundary: " : "", why);
      break;
    }
    t_last = tk;
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
  }
  if (drv) gsl_odeiv2_driver_free(drv);
  free(d); free(drhs); free(s);
  if (st == PRRU_OK && msg && msglen > 0) msg[0] = '\0';
  return st;
}
