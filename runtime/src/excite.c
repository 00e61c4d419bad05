/* Periodic (Fourier) excitation trajectories for identification
 * (prru_ident.h): coefficients chosen for a well-conditioned stacked base
 * regressor inside the workspace and the actuator force limits. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multimin.h>

#include "ident_internal.h"
#include "internal.h"
#include "prru_ident.h"

void prru_excite_options_default(prru_excite_options *o)
{
  memset(o, 0, sizeof *o);
  /* Every entry: o does not know the model it will be used with. */
  for (int i = 0; i < PRRU_MAX_ACT; i++)
    o->fd_max[i] = 500.0, o->d_min[i] = -HUGE_VAL, o->d_max[i] = HUGE_VAL, o->speed_max[i] = HUGE_VAL;
  o->rcond_min = 1e-2;
  o->amplitude_max[0] = o->amplitude_max[1] = 0.25;
  o->amplitude_max[2] = -0.1; /* negative: that many length scales L */
  o->samples = 100;
  o->check_samples = 0;
  o->max_evals = 3000;
  o->seed = 1;
  o->dt = 0.01;
  o->periods = 1;
}

/* The dense check's points per period: 0 follows samples, so that a
 * caller raising samples gets a check as much finer. */
static int check_points(const prru_excite_options *o)
{
  if (o->check_samples != 0) return o->check_samples;
  return o->samples > 0 && o->samples <= INT_MAX / 20 ? 20 * o->samples : -1;
}

void prru_fourier_default(prru_fourier *f)
{
  memset(f, 0, sizeof *f);
  f->period = 10.0;
  f->harmonics = 5;
}

long prru_excite_rows(const prru_fourier *f, const prru_excite_options *o)
{
  const double run = f->period * o->periods;
  if (!(f->period > 0 && isfinite(f->period)) || o->periods < 1 || !(o->dt > 0 && isfinite(o->dt)) ||
      !(o->dt <= run && isfinite(run)))
    return 0;
  const double n = floor(run / o->dt * (1 + 1e-12));
  return n <= 1e15 ? (long)n + 1 : 0;
}

void prru_excite_options_limits(prru_excite_options *o, const prru_limits *lim)
{
  /* Every entry, as for the defaults: those past the model's actuators
   * are read by no one. */
  for (int i = 0; i < PRRU_MAX_ACT; i++) {
    if (isfinite(lim->force_max[i])) o->fd_max[i] = lim->force_max[i];
    o->speed_max[i] = lim->speed_max[i];
    o->d_min[i] = lim->d_min[i], o->d_max[i] = lim->d_max[i];
  }
}

void prru_fourier_eval(const prru_fourier *f, double t, double q[3], double qd[3], double qdd[3])
{
  const double w = 2 * PRRU_PI / f->period;
  for (int k = 0; k < 3; k++) {
    double x = f->centre[k], v = 0, a = 0;
    for (int l = 1; l <= f->harmonics; l++) {
      const double wl = w * l, s = sin(wl * t), c = cos(wl * t);
      const double A = f->a[k][l - 1], B = f->b[k][l - 1];
      x += A * s + B * c;
      v += wl * (A * c - B * s);
      a -= wl * wl * (A * s + B * c);
    }
    q[k] = x;
    if (qd) qd[k] = v;
    if (qdd) qdd[k] = a;
  }
}

static double amplitude_bound(const prru_model *m, const prru_excite_options *o, int k)
{
  const double v = o->amplitude_max[k];
  return v < 0 ? -v * prru_length_scale(m->mech) : v;
}

/* The assembly mode: det J_d's sign (three actuators; four have no second
 * mode in reach). d holds J_d of the pose. */
static int pose_mode(const prru_model *m, const prru_data *d)
{
  if (m->mech->nact != 3) return 1;
  const double *a = d->Jd;
  const double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                     a[2] * (a[3] * a[7] - a[4] * a[6]);
  return det > 0 ? 1 : -1;
}

/* One point: 0 when usable (reachable, regular, in mode, within the
 * limits), with fd and rcond; else the status and *excess, a continuous
 * measure of how far the point is outside (for the penalty). */
static int point(const prru_model *m, prru_data *d, const prru_excite_options *o, int mode,
                 const double q[3], const double qd[3], const double qdd[3], double fd[],
                 double *rcond, double *excess)
{
  const int na = m->mech->nact;
  prru_loads l;
  memset(&l, 0, sizeof l);
  *excess = 0;
  int st = prru_check_regular(m, d, q, rcond);
  if (st == PRRU_ESTROKE) {
    /* Beyond the model's own stroke: measured like the options' stroke
     * below (check_regular left d), so the penalty stays continuous. */
    for (int i = 0; i < na; i++) {
      const double range = m->mech->d_max[i] - m->mech->d_min[i];
      if (d->d[i] < m->mech->d_min[i]) *excess += (m->mech->d_min[i] - d->d[i]) / range;
      if (d->d[i] > m->mech->d_max[i]) *excess += (d->d[i] - m->mech->d_max[i]) / range;
    }
    if (!(*excess > 0)) *excess = 10; /* an infinite end: no distance to measure */
    return st;
  }
  if (st == PRRU_ESINGULAR || (st == PRRU_OK && (*rcond < o->rcond_min || pose_mode(m, d) != mode))) {
    /* Continuous through the mode change: the other mode counts as
     * negative rcond. */
    const double s = st == PRRU_OK && pose_mode(m, d) != mode ? -*rcond : st == PRRU_OK ? *rcond : 0;
    *excess = 1 + (o->rcond_min - s) / o->rcond_min;
    return PRRU_ESINGULAR;
  }
  if (st != PRRU_OK) {
    *excess = 10;
    return st;
  }
  /* Stroke violations relative to the stroke (d holds the sliders), and
   * slider speeds d' = J_d qd beyond speed_max (J_d from check_regular). */
  for (int i = 0; i < na; i++) {
    const double range = o->d_max[i] - o->d_min[i];
    if (d->d[i] < o->d_min[i]) *excess += (o->d_min[i] - d->d[i]) / range;
    if (d->d[i] > o->d_max[i]) *excess += (d->d[i] - o->d_max[i]) / range;
    const double v = d->Jd[3 * i] * qd[0] + d->Jd[3 * i + 1] * qd[1] + d->Jd[3 * i + 2] * qd[2];
    if (fabs(v) > o->speed_max[i]) *excess += fabs(v) / o->speed_max[i] - 1;
  }
  st = prru_inverse_dynamics(m, d, q, qd, qdd, &l, fd);
  if (st != PRRU_OK) {
    *excess = 10;
    return st;
  }
  for (int i = 0; i < na; i++)
    if (fabs(fd[i]) > o->fd_max[i]) *excess += fabs(fd[i]) / o->fd_max[i] - 1;
  return *excess > 0 ? PRRU_EINPUT : PRRU_OK;
}

int prru_excite_check(const prru_model *m, const prru_fourier *f, const prru_excite_options *o,
                      int n, double fd_peak[], double *rcond_worst, double *t_bad)
{
  prru_data *d = malloc(sizeof *d);
  if (!d) return PRRU_ENOMEM;
  const int na = m->mech->nact;
  int st = prru_check_regular(m, d, f->centre, NULL);
  const int mode = st == PRRU_OK ? pose_mode(m, d) : 1;
  for (int i = 0; i < na; i++) fd_peak[i] = 0;
  *rcond_worst = INFINITY;
  for (int s = 0; s < n && st == PRRU_OK; s++) {
    double t = f->period * s / n, q[3], qd[3], qdd[3], fd[PRRU_MAX_ACT], rc, ex;
    prru_fourier_eval(f, t, q, qd, qdd);
    st = point(m, d, o, mode, q, qd, qdd, fd, &rc, &ex);
    if (st != PRRU_OK) {
      *t_bad = t;
      break;
    }
    if (rc < *rcond_worst) *rcond_worst = rc;
    for (int i = 0; i < na; i++)
      if (fabs(fd[i]) > fd_peak[i]) fd_peak[i] = fabs(fd[i]);
  }
  free(d);
  return st;
}

#define MERIT_RANK 50.0
#define MERIT_INFEASIBLE 100.0

typedef struct {
  const prru_model *m;
  const prru_base *b;
  const prru_excite_options *o;
  prru_fourier f;
  prru_data *d;
  gsl_matrix *W, *V;
  gsl_vector *sv, *work;
  int mode, evals;
  double bound[3];
  volatile sig_atomic_t *stop;
} excite_ctx;

/* Coefficients from the optimiser's variables: a coordinate's variables
 * times its amplitude bound, scaled down together when the sum of their
 * magnitudes exceeds 1, so that |q_k - c_k| <= sum |a| + |b| never exceeds
 * the bound whatever the simplex tries (no constraint to violate). */
static void unpack(excite_ctx *c, const gsl_vector *x)
{
  const int L = c->f.harmonics;
  for (int k = 0; k < 3; k++) {
    double sum = 0;
    for (int l = 0; l < L; l++) sum += fabs(gsl_vector_get(x, (size_t)(2 * L * k + l))) +
                                      fabs(gsl_vector_get(x, (size_t)(2 * L * k + L + l)));
    const double scale = sum > 1 ? c->bound[k] / sum : c->bound[k];
    for (int l = 0; l < L; l++) {
      c->f.a[k][l] = scale * gsl_vector_get(x, (size_t)(2 * L * k + l));
      c->f.b[k][l] = scale * gsl_vector_get(x, (size_t)(2 * L * k + L + l));
    }
  }
}

/* The inverse of unpack for coefficients within their bounds. */
static void pack(excite_ctx *c, const prru_fourier *f, gsl_vector *x)
{
  const int L = c->f.harmonics;
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < L; l++) {
      gsl_vector_set(x, (size_t)(2 * L * k + l), f->a[k][l] / c->bound[k]);
      gsl_vector_set(x, (size_t)(2 * L * k + L + l), f->b[k][l] / c->bound[k]);
    }
}

/* log10 of the 2-norm condition number of the column-scaled stacked base
 * regressor at the optimisation samples (below 17), MERIT_RANK when it is
 * rank deficient, or a penalty above MERIT_INFEASIBLE growing with how far
 * the trajectory leaves the feasible set. */
static double merit(const gsl_vector *x, void *ctx)
{
  excite_ctx *c = ctx;
  c->evals++;
  unpack(c, x);
  const int n = c->o->samples, p = c->b->nbase;
  double excess = 0;
  for (int s = 0; s < n; s++) {
    double q[3], qd[3], qdd[3], fd[PRRU_MAX_ACT], rc, ex, Y[3 * PRRU_MAX_REG], Yb[3 * PRRU_MAX_REG];
    prru_fourier_eval(&c->f, c->f.period * s / n, q, qd, qdd);
    if (point(c->m, c->d, c->o, c->mode, q, qd, qdd, fd, &rc, &ex) != PRRU_OK) {
      excess += ex;
      continue;
    }
    prru_model_regressor(c->m, q, qd, qdd, c->b->vs, Y);
    prru_base_regressor(c->b, Y, 3, Yb);
    for (int r = 0; r < 3; r++)
      for (int j = 0; j < p; j++) gsl_matrix_set(c->W, 3 * (size_t)s + (size_t)r, (size_t)j, Yb[r * p + j]);
  }
  if (excess > 0) return MERIT_INFEASIBLE * (1 + excess);
  for (int j = 0; j < p; j++) {
    gsl_vector_view col = gsl_matrix_column(c->W, (size_t)j);
    double nrm = gsl_blas_dnrm2(&col.vector);
    if (!(nrm > 0)) return MERIT_RANK;
    gsl_vector_scale(&col.vector, 1.0 / nrm);
  }
  gsl_linalg_SV_decomp(c->W, c->V, c->sv, c->work);
  const double smin = gsl_vector_get(c->sv, (size_t)p - 1);
  return smin > 0 ? fmin(log10(gsl_vector_get(c->sv, 0) / smin), MERIT_RANK) : MERIT_RANK;
}

static int check_options(const prru_model *m, const prru_base *b, const prru_excite_options *o,
                         const prru_fourier *f, char *msg, int msglen)
{
  if (!(f->period > 0) || !isfinite(f->period)) {
    snprintf(msg, (size_t)msglen, "period must be a positive number of seconds");
    return PRRU_EINPUT;
  }
  if (f->harmonics < 1 || f->harmonics > PRRU_EXCITE_MAX_HARMONICS) {
    snprintf(msg, (size_t)msglen, "harmonics must be 1..%d", PRRU_EXCITE_MAX_HARMONICS);
    return PRRU_EINPUT;
  }
  const int na = m->mech->nact;
  if (!prru_base_fits(m, b)) {
    snprintf(msg, (size_t)msglen, "the base parameters were computed for a model of %d bodies and %d actuators, "
             "not this one's %d and %d", b->nbody, b->nact, m->mech->nbody, na);
    return PRRU_EINPUT;
  }
  for (int i = 0; i < na; i++)
    if (!(o->fd_max[i] > 0) || !isfinite(o->fd_max[i])) {
      snprintf(msg, (size_t)msglen, "force limit of actuator %d must be positive", i + 1);
      return PRRU_EINPUT;
    }
  for (int i = 0; i < na; i++)
    if (!(o->speed_max[i] > 0)) {
      snprintf(msg, (size_t)msglen, "speed limit of actuator %d must be positive", i + 1);
      return PRRU_EINPUT;
    }
  for (int i = 0; i < na; i++)
    if (!(o->d_min[i] < o->d_max[i])) {
      snprintf(msg, (size_t)msglen, "stroke of slider %d is empty", i + 1);
      return PRRU_EINPUT;
    }
  if (!(o->rcond_min > 0 && o->rcond_min < 1)) {
    snprintf(msg, (size_t)msglen, "rcond_min must lie in (0, 1)");
    return PRRU_EINPUT;
  }
  for (int k = 0; k < 3; k++)
    if (!(amplitude_bound(m, o, k) > 0) || !isfinite(amplitude_bound(m, o, k))) {
      snprintf(msg, (size_t)msglen, "amplitude bound of q%d must be positive", k + 1);
      return PRRU_EINPUT;
    }
  if (3 * o->samples < b->nbase + 1 || check_points(o) < o->samples || o->max_evals < 1) {
    snprintf(msg, (size_t)msglen, "need samples >= %d (3 rows each for %d base parameters), "
             "check samples >= samples and at least one evaluation", b->nbase / 3 + 1, b->nbase);
    return PRRU_EINPUT;
  }
  prru_data d;
  double rc;
  int st = prru_check_regular(m, &d, f->centre, &rc);
  if (st == PRRU_ESTROKE) {
    const int i = prru_stroke_actuator(m, d.d);
    snprintf(msg, (size_t)msglen, "centre (%g, %g, %g) puts slider %d at %g m, outside its stroke [%g, %g] m",
             f->centre[0], f->centre[1], f->centre[2], i + 1, d.d[i], m->mech->d_min[i], m->mech->d_max[i]);
    return PRRU_EINPUT;
  }
  if (st != PRRU_OK || rc < o->rcond_min) {
    snprintf(msg, (size_t)msglen, "centre (%g, %g, %g) is %s", f->centre[0], f->centre[1], f->centre[2],
             st == PRRU_OK ? "too close to a singularity (rcond below the limit)" : prru_strerror(st));
    return PRRU_EINPUT;
  }
  for (int i = 0; i < na; i++)
    if (d.d[i] < o->d_min[i] || d.d[i] > o->d_max[i]) {
      snprintf(msg, (size_t)msglen, "centre (%g, %g, %g) puts slider %d at %g m, outside its stroke", f->centre[0],
               f->centre[1], f->centre[2], i + 1, d.d[i]);
      return PRRU_EINPUT;
    }
  return PRRU_OK;
}

/* A small random start: every coefficient uniform in +-bound / (4 L). */
static void start_point(excite_ctx *c, gsl_vector *x, unsigned long seed)
{
  unsigned long long s = 0xD1B54A32D192ED03ULL ^ (unsigned long long)seed;
  if (!s) s = 1;
  for (size_t i = 0; i < x->size; i++) {
    s ^= s >> 12, s ^= s << 25, s ^= s >> 27;
    const double u = (double)((s * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
    gsl_vector_set(x, i, (2 * u - 1) / (2.0 * c->f.harmonics));
  }
}

static int minimise(excite_ctx *c, gsl_vector *x, double *fbest)
{
  gsl_multimin_function fn = {merit, x->size, c};
  gsl_multimin_fminimizer *mz = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2, x->size);
  gsl_vector *step = gsl_vector_alloc(x->size);
  if (!mz || !step) {
    if (mz) gsl_multimin_fminimizer_free(mz);
    gsl_vector_free(step);
    return PRRU_ENOMEM;
  }
  gsl_vector_set_all(step, 0.1);
  gsl_multimin_fminimizer_set(mz, &fn, x, step);
  int st = PRRU_OK;
  while (c->evals < c->o->max_evals) {
    if (c->stop && *c->stop) {
      st = PRRU_EINTERRUPTED;
      break;
    }
    if (gsl_multimin_fminimizer_iterate(mz) != GSL_SUCCESS) break;
    if (gsl_multimin_fminimizer_size(mz) < 1e-6) break;
  }
  gsl_vector_memcpy(x, mz->x);
  *fbest = mz->fval;
  gsl_multimin_fminimizer_free(mz);
  gsl_vector_free(step);
  return st;
}

int prru_excite(const prru_model *m, const prru_base *b, const prru_excite_options *o,
                volatile sig_atomic_t *stop, prru_fourier *f, prru_excite_result *r, char *msg,
                int msglen)
{
  memset(r, 0, sizeof *r);
  prru_gsl_init();
  int st = check_options(m, b, o, f, msg, msglen);
  if (st != PRRU_OK) return st;
  excite_ctx c;
  memset(&c, 0, sizeof c);
  c.m = m, c.b = b, c.o = o, c.f = *f, c.stop = stop;
  for (int k = 0; k < 3; k++) c.bound[k] = amplitude_bound(m, o, k);
  const size_t nx = 6 * (size_t)f->harmonics, p = (size_t)b->nbase;
  c.d = malloc(sizeof *c.d);
  c.W = gsl_matrix_alloc(3 * (size_t)o->samples, p);
  c.V = gsl_matrix_alloc(p, p);
  c.sv = gsl_vector_alloc(p);
  c.work = gsl_vector_alloc(p);
  gsl_vector *x = gsl_vector_alloc(nx);
  st = c.d && c.W && c.V && c.sv && c.work && x ? PRRU_OK : PRRU_ENOMEM;
  if (st == PRRU_OK) {
    prru_check_regular(m, c.d, f->centre, NULL);
    c.mode = pose_mode(m, c.d);
    start_point(&c, x, o->seed);
    const double m0 = merit(x, &c);
    r->cond_start = m0 < MERIT_RANK ? pow(10, m0) : INFINITY;
    double best;
    st = minimise(&c, x, &best);
    unpack(&c, x);
    const double best_merit = merit(x, &c);
    r->cond = pow(10, best_merit);
    r->evals = c.evals;
    *f = c.f;
    if (st == PRRU_OK && best_merit >= MERIT_RANK) {
      snprintf(msg, (size_t)msglen, "no feasible excitation found (every trial left the workspace, "
               "met a singularity or exceeded a force limit); lower the amplitudes or raise the limits");
      st = PRRU_ENOCONV;
    }
  }
  if (st == PRRU_OK) {
    double tb = 0;
    int cs = prru_excite_check(m, f, o, check_points(o), r->fd_peak, &r->rcond_worst, &tb);
    /* Between the optimisation samples a limit can be crossed: shrink the
     * motion about the centre until the dense check passes. */
    for (int shrink = 0; cs != PRRU_OK && cs != PRRU_ENOMEM && shrink < 30; shrink++) {
      for (int k = 0; k < 3; k++)
        for (int l = 0; l < f->harmonics; l++) f->a[k][l] *= 0.95, f->b[k][l] *= 0.95;
      cs = prru_excite_check(m, f, o, check_points(o), r->fd_peak, &r->rcond_worst, &tb);
      r->shrunk = shrink + 1;
    }
    if (cs == PRRU_OK && r->shrunk) {
      gsl_vector *y = gsl_vector_alloc(nx);
      if (y) {
        pack(&c, f, y);
        r->cond = pow(10, merit(y, &c));
        gsl_vector_free(y);
      }
    }
    if (cs != PRRU_OK) {
      snprintf(msg, (size_t)msglen, "the optimised excitation fails the dense check at t = %.6g s (%s); "
               "use more samples", tb, cs == PRRU_EINPUT ? "a force or stroke limit exceeded" : prru_strerror(cs));
      st = PRRU_ENOCONV;
    }
  }
  free(c.d);
  gsl_matrix_free(c.W), gsl_matrix_free(c.V), gsl_vector_free(c.sv), gsl_vector_free(c.work);
  gsl_vector_free(x);
  return st;
}
