/* Computed-torque and LQR tracking in closed loop (prru_control.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "prru_control.h"
#include "prru_linearize.h"
#include "internal.h"

/* Computed torque's default bandwidth, rad/s (the LQR's defaults match it). */
#define TRACK_BANDWIDTH 20.0

int prru_track_gains_bandwidth(double w, prru_track_options *o)
{
  if (!(w > 0.0 && isfinite(w * w))) return PRRU_EINPUT;
  for (int i = 0; i < 3; i++) {
    o->kp[i] = w * w;
    o->kd[i] = 2.0 * w;
  }
  return PRRU_OK;
}

void prru_track_options_default(const prru_model *m, prru_track_options *o)
{
  memset(o, 0, sizeof *o);
  prru_track_gains_bandwidth(TRACK_BANDWIDTH, o);
  o->dt_out = 1e-3;
  /* Every entry: unlimited whatever the number of actuators. */
  for (int i = 0; i < PRRU_MAX_ACT; i++) {
    o->f_max[i] = INFINITY;
    o->speed_max[i] = INFINITY;
    o->d_min[i] = -INFINITY;
    o->d_max[i] = INFINITY;
  }
  o->seed = 1;
  prru_model_params(m, &o->plant);
  o->abs_tol = 1e-12;
  o->rel_tol = 1e-12;
}

/* Solves M x = b for symmetric positive definite M (Cholesky, unrolled);
 * 0, or -1 when M is not positive definite (or not finite). */
static int spd3_solve(const double M[9], const double b[3], double x[3])
{
  double l00 = M[0];
  if (!(l00 > 0.0)) return -1;
  l00 = sqrt(l00);
  double l10 = M[3] / l00, l20 = M[6] / l00;
  double l11 = M[4] - l10 * l10;
  if (!(l11 > 0.0)) return -1;
  l11 = sqrt(l11);
  double l21 = (M[7] - l20 * l10) / l11;
  double l22 = M[8] - l20 * l20 - l21 * l21;
  if (!(l22 > 0.0)) return -1;
  l22 = sqrt(l22);
  double y0 = b[0] / l00, y1 = (b[1] - l10 * y0) / l11, y2 = (b[2] - l20 * y0 - l21 * y1) / l22;
  x[2] = y2 / l22;
  x[1] = (y1 - l21 * x[2]) / l11;
  x[0] = (y0 - l10 * x[1] - l20 * x[2]) / l00;
  return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) ? 0 : -1;
}

/* prru_plant_accel with the plant's numbers derived for its topology t
 * (t->derive). */
static int plant_accel(const prru_topology *t, const prru_topo_derived *p, const double q[3],
                       const double qd[3], const double fd[], double qdd[3])
{
  static const double zero[3] = {0.0, 0.0, 0.0};
  double M[9], b[3];
  t->general->eom(p, q, qd, fd, zero, zero, M, b);
  for (int i = 0; i < 9; i++)
    if (!isfinite(M[i])) return PRRU_EUNREACHABLE;
  if (!prru_finite_n(b, 3)) {
    /* M finite: q is reachable. b at rest without forces finite: the
     * velocities or forces overflow b (PRRU_EINPUT); else q lies on the
     * workspace boundary, where the velocity mapping divides by zero. */
    static const double zero_fd[PRRU_MAX_ACT] = {0};
    t->general->eom(p, q, zero, zero_fd, zero, zero, M, b);
    return prru_finite_n(b, 3) ? PRRU_EINPUT : PRRU_ESINGULAR;
  }
  return spd3_solve(M, b, qdd) == 0 ? PRRU_OK : PRRU_ESINGULAR;
}

int prru_plant_accel(const prru_model *m, const prru_params *p, const double q[3], const double qd[3],
                     const double fd[], double qdd[3])
{
  const prru_topology *t = prru_topology_of(m->mech->nlimb);
  if (!t) return PRRU_EINPUT;
  prru_topo_derived dp;
  t->derive(p, &dp);
  return plant_accel(t, &dp, q, qd, fd, qdd);
}

int prru_computed_torque(const prru_model *m, prru_data *d, const prru_track_options *o,
                         const double q_ref[3], const double qd_ref[3], const double qdd_ref[3],
                         const double q[3], const double qd[3], double fd_cmd[],
                         double fd[], int sat[])
{
  double qdd_c[3];
  for (int i = 0; i < 3; i++)
    qdd_c[i] = qdd_ref[i] + o->kd[i] * (qd_ref[i] - qd[i]) + o->kp[i] * (q_ref[i] - q[i]);
  prru_loads l;
  memset(&l, 0, sizeof l);
  if (!prru_finite_n(qdd_c, 3)) return PRRU_EINPUT; /* the gains times the errors overflow */
  int st = prru_inverse_dynamics(m, d, q, qd, qdd_c, &l, fd_cmd);
  if (st != PRRU_OK) return st;
  const int na = m->mech->nact;
  if (!prru_finite_n(fd_cmd, na)) return PRRU_EINPUT;
  for (int i = 0; i < na; i++) {
    double lim = o->f_max[i];
    sat[i] = fabs(fd_cmd[i]) > lim;
    fd[i] = sat[i] ? copysign(lim, fd_cmd[i]) : fd_cmd[i];
  }
  return PRRU_OK;
}

/* ---- time-varying discrete LQR ---- */

/* The integrator may probe a few ulps past the reference's end. */
static double clamp_time(const prru_quintic *ref, double t)
{
  return fmin(fmax(t, prru_quintic_t_begin(ref)), prru_quintic_t_end(ref));
}

/* The bandwidth the default weights aim at: computed torque's default. */
#define LQR_BANDWIDTH TRACK_BANDWIDTH

/* Tick k's time: t_0 + k step, the last one exactly the reference's end. */
static double tick_time(const prru_quintic *ref, double step, long k, long nticks)
{
  return k == nticks ? prru_quintic_t_end(ref) : prru_quintic_t_begin(ref) + (double)k * step;
}

/* The last tick's index: t_0 is always a tick, and t_1 (a remainder
 * below 1e-9 step merged into the last tick): at least two, however
 * short the span. */
static long last_tick(const prru_quintic *ref, double step)
{
  const double t0 = prru_quintic_t_begin(ref), t1 = prru_quintic_t_end(ref);
  return (long)fmax(1.0, ceil((t1 - t0) / step - 1e-9));
}

static int all_zero(const double *v, int n)
{
  for (int i = 0; i < n; i++)
    if (v[i] != 0.0) return 0;
  return 1;
}

/* The reference at tick k of a run with period step: x = (q, qd), the
 * feed-forward u (inverse dynamics without loads). */
static int lqr_reference_tick(const prru_model *m, prru_data *d, const prru_quintic *ref, double step,
                              long k, long last, double x[6], double u[], char *msg, int msglen)
{
  static const prru_loads none;
  double t = tick_time(ref, step, k, last), qdd[3];
  prru_quintic_eval(ref, clamp_time(ref, t), x, x + 3, qdd);
  int st = prru_inverse_dynamics(m, d, x, x + 3, qdd, &none, u);
  if (st == PRRU_OK && !prru_finite_n(u, m->mech->nact)) st = PRRU_EINPUT;
  if (st != PRRU_OK)
    return prru_fail(msg, msglen, st, "LQR schedule: tick %ld (t = %.9g s): the reference's inverse "
                     "dynamics at q = (%.9g, %.9g, %.9g) failed: %s", k, t, x[0], x[1], x[2],
                     prru_strerror(st));
  return PRRU_OK;
}

/* The zero-order-hold linearisation at tick k's reference (x, u). */
static int lqr_linearize_tick(const prru_model *m, prru_data *d, const double x[6],
                              const double u[], double step, double t, long k,
                              prru_linearization *lin, char *msg, int msglen)
{
  prru_loads l;
  memset(&l, 0, sizeof l);
  memcpy(l.fd, u, (size_t)m->mech->nact * sizeof(double));
  char why[300];
  int st = prru_linearize_why(m, d, x, x + 3, &l, step, lin, why, sizeof why);
  if (st != PRRU_OK)
    return prru_fail(msg, msglen, st, "LQR schedule: tick %ld (t = %.9g s): the linearisation at q = "
                     "(%.9g, %.9g, %.9g) failed: %s%s%s", k, t, x[0], x[1], x[2], prru_strerror(st),
                     why[0] ? ": " : "", why);
  return PRRU_OK;
}

/* a_j: the acceleration coordinate j alone gets from forces of size F,
 * F / |G^+ e_j| with G = dqdd/dfd (3 x na) and G^+ = G^T (G
 * G^T)^-1 (the least-norm forces for an acceleration): the scale of a
 * decoupled double integrator, where the largest acceleration of j
 * (F |row j of G|) would count the other coordinates' motion too. 0, or
 * -1 when G G^T is singular. */
static int decoupled_accel(const double G[], int na, double F, double a[3])
{
  double H[9], Hi[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double h = 0.0;
      for (int k = 0; k < na; k++) h += G[i * na + k] * G[j * na + k];
      H[3 * i + j] = h;
    }
  if (!(prru_rcond3(H, Hi) > 1e-14)) return -1;
  for (int j = 0; j < 3; j++) {
    double n = 0.0;
    for (int k = 0; k < na; k++) {
      double c = 0.0; /* (G^T H^-1)_kj */
      for (int i = 0; i < 3; i++) c += G[i * na + k] * Hi[3 * i + j];
      n = hypot(n, c);
    }
    a[j] = F / n;
    if (!(a[j] > 0.0 && isfinite(a[j]))) return -1;
  }
  return 0;
}

int prru_lqr_default_weights(const prru_model *m, const prru_quintic *ref, double period, double q[6],
                             double r[], char *msg, int msglen)
{
  if (!ref || ref->n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "no reference trajectory");
  if (!(period > 0.0 && isfinite(period)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "control period: LQR needs a finite period > 0, got %g",
                     period);
  prru_gsl_init();
  prru_data *d = malloc(sizeof *d);
  prru_linearization *lin = malloc(sizeof *lin);
  int st = d && lin ? PRRU_OK : prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  const long last = last_tick(ref, period);
  const int na = m->mech->nact;
  double x[6], u[PRRU_MAX_ACT], x0[6], u0[PRRU_MAX_ACT], F = 0.0;
  for (long k = 0; k <= last && st == PRRU_OK; k++) {
    st = lqr_reference_tick(m, d, ref, period, k, last, x, u, msg, msglen);
    for (int i = 0; i < na && st == PRRU_OK; i++) F = fmax(F, fabs(u[i]));
    if (k == 0) memcpy(x0, x, sizeof x0), memcpy(u0, u, (size_t)na * sizeof *u0);
  }
  if (F == 0.0) F = 1.0;
  if (st == PRRU_OK)
    st = lqr_linearize_tick(m, d, x0, u0, 0.0, prru_quintic_t_begin(ref), 0, lin, msg, msglen);
  double a[3];
  if (st == PRRU_OK && decoupled_accel(lin->dqdd_dfd, na, F, a) != 0)
    st = prru_fail(msg, msglen, PRRU_ESINGULAR, "LQR default weights: the actuators do not move "
                   "every coordinate at the reference's start (dqdd/dfd rank-deficient)");
  for (int j = 0; j < 3 && st == PRRU_OK && q; j++) {
    const double w = LQR_BANDWIDTH;
    q[j] = (w * w / a[j]) * (w * w / a[j]);
    q[3 + j] = 2.0 * (w / a[j]) * (w / a[j]);
  }
  for (int i = 0; i < na && r && st == PRRU_OK; i++) r[i] = 1.0 / (F * F);
  free(d);
  free(lin);
  if (st == PRRU_OK && msg && msglen > 0) msg[0] = '\0';
  return st;
}

/* The option names as prru_track_options_check promises them: front ends
 * replace them by their own. na: the model's actuators (lqr_r's entries
 * past them are not read). */
static int lqr_weights_check(const prru_track_options *o, int na, char *msg, int msglen)
{
  if (!(o->control_period > 0.0))
    return prru_fail(msg, msglen, PRRU_EINPUT, "controller PRRU_TRACK_LQR needs control period > 0: "
                     "the LQR's gains are those of a sampled controller");
  for (int i = 0; i < 6; i++)
    if (!(o->lqr_q[i] >= 0.0 && isfinite(o->lqr_q[i])))
      return prru_fail(msg, msglen, PRRU_EINPUT, "lqr_q: weight %d is %g, not >= 0 and finite", i + 1,
                       o->lqr_q[i]);
  if (all_zero(o->lqr_r, na)) return PRRU_OK;
  for (int i = 0; i < na; i++)
    if (!(o->lqr_r[i] > 0.0 && isfinite(o->lqr_r[i])))
      return prru_fail(msg, msglen, PRRU_EINPUT, "lqr_r: weight %d is %g, not > 0 and finite", i + 1,
                       o->lqr_r[i]);
  return PRRU_OK;
}

/* One backward Riccati step with N inputs: K = (R + B^T P B)^-1 B^T P A
 * (Cholesky), P <- Q + A^T P (A - B K), symmetrised. Works on the
 * caller's arrays: no allocation. GSL_EDOM where R + B^T P B is not
 * positive definite. */
static int riccati_step(const double A[36], const double B[], const double Q[6], const double R[], int N,
                        double P[36], double K[])
{
  enum { NMAX = PRRU_MAX_ACT };
  double PA[36], PB[6 * NMAX], S[NMAX * NMAX], BtPA[NMAX * 6], AmBK[36], PAmBK[36];
  const size_t n = (size_t)N;
  gsl_matrix_const_view a = gsl_matrix_const_view_array(A, 6, 6), b = gsl_matrix_const_view_array(B, 6, n);
  gsl_matrix_view p = gsl_matrix_view_array(P, 6, 6), pa = gsl_matrix_view_array(PA, 6, 6),
                  pb = gsl_matrix_view_array(PB, 6, n), s = gsl_matrix_view_array(S, n, n),
                  btpa = gsl_matrix_view_array(BtPA, n, 6), k = gsl_matrix_view_array(K, n, 6),
                  ambk = gsl_matrix_view_array(AmBK, 6, 6), pambk = gsl_matrix_view_array(PAmBK, 6, 6);
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &p.matrix, &a.matrix, 0.0, &pa.matrix);
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &p.matrix, &b.matrix, 0.0, &pb.matrix);
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, &b.matrix, &pb.matrix, 0.0, &s.matrix);
  for (int i = 0; i < N; i++) S[i * N + i] += R[i];
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, &b.matrix, &pa.matrix, 0.0, &btpa.matrix);
  if (!prru_finite_n(S, N * N) || gsl_linalg_cholesky_decomp1(&s.matrix) != GSL_SUCCESS) return GSL_EDOM;
  gsl_linalg_cholesky_solve_mat(&s.matrix, &btpa.matrix, &k.matrix);
  memcpy(AmBK, A, sizeof AmBK);
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, -1.0, &b.matrix, &k.matrix, 1.0, &ambk.matrix);
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &p.matrix, &ambk.matrix, 0.0, &pambk.matrix);
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, &a.matrix, &pambk.matrix, 0.0, &p.matrix);
  for (int i = 0; i < 6; i++) {
    P[i * 6 + i] += Q[i];
    for (int j = 0; j < i; j++) P[i * 6 + j] = P[j * 6 + i] = 0.5 * (P[i * 6 + j] + P[j * 6 + i]);
  }
  return prru_finite_n(K, N * 6) && prru_finite_n(P, 36) ? GSL_SUCCESS : GSL_EDOM;
}

/* The weights of the run: o's, or Bryson's for a group left all zero. */
static int lqr_weights(const prru_model *m, const prru_quintic *ref, const prru_track_options *o,
                       prru_lqr_schedule *s, char *msg, int msglen)
{
  memcpy(s->q, o->lqr_q, sizeof s->q);
  memcpy(s->r, o->lqr_r, sizeof s->r);
  int dq = all_zero(o->lqr_q, 6), dr = all_zero(o->lqr_r, s->nact);
  if (!dq && !dr) return PRRU_OK;
  return prru_lqr_default_weights(m, ref, o->control_period, dq ? s->q : NULL, dr ? s->r : NULL, msg,
                                  msglen);
}

/* The reference, feed-forward and the (A_k, B_k) of every tick; then the
 * gains backwards from P_n = Q (the A_k, B_k kept in the K and a scratch
 * array: one linearisation per tick). */
static int lqr_schedule_fill(const prru_model *m, const prru_quintic *ref, prru_lqr_schedule *s,
                             double *AB, prru_data *d, prru_linearization *lin, char *msg, int msglen)
{
  const long last = s->n - 1;
  const int na = s->nact;
  const long NAB = 36 + 6 * na;
  for (long k = 0; k < s->n; k++) {
    double *x = s->x_ref + 6 * k, *u = s->u_ff + na * k;
    int st = lqr_reference_tick(m, d, ref, s->period, k, last, x, u, msg, msglen);
    if (st == PRRU_OK)
      st = lqr_linearize_tick(m, d, x, u, s->period, tick_time(ref, s->period, k, last), k, lin, msg,
                              msglen);
    if (st != PRRU_OK) return st;
    memcpy(AB + NAB * k, lin->Ad, sizeof lin->Ad);
    memcpy(AB + NAB * k + 36, lin->Bd, 6 * (size_t)na * sizeof(double));
  }
  double P[36];
  memset(P, 0, sizeof P);
  for (int i = 0; i < 6; i++) P[i * 6 + i] = s->q[i];
  for (long k = last; k >= 0; k--) {
    if (riccati_step(AB + NAB * k, AB + NAB * k + 36, s->q, s->r, na, P, s->K + 6 * na * k) != GSL_SUCCESS)
      return prru_fail(msg, msglen, PRRU_ENOCONV, "LQR schedule: tick %ld (t = %.9g s): R + B^T P B is "
                       "not positive definite (weights or dynamics out of scale)", k,
                       tick_time(ref, s->period, k, last));
  }
  memcpy(s->P0, P, sizeof P);
  return PRRU_OK;
}

int prru_lqr_schedule_build(const prru_model *m, const prru_quintic *ref, const prru_track_options *o,
                            prru_lqr_schedule *s, char *msg, int msglen)
{
  memset(s, 0, sizeof *s);
  if (!ref || ref->n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "no reference trajectory");
  const int na = m->mech->nact;
  int st = lqr_weights_check(o, na, msg, msglen);
  if (st != PRRU_OK) return st;
  prru_gsl_init();
  s->nact = na;
  s->period = o->control_period;
  s->n = last_tick(ref, s->period) + 1;
  if (!((double)s->n <= 1e8))
    return prru_fail(msg, msglen, PRRU_EINPUT, "control period: more than 1e8 ticks");
  size_t n = (size_t)s->n;
  s->K = malloc(n * 6 * (size_t)na * sizeof *s->K);
  s->u_ff = malloc(n * (size_t)na * sizeof *s->u_ff);
  s->x_ref = malloc(n * 6 * sizeof *s->x_ref);
  double *AB = malloc(n * (36 + 6 * (size_t)na) * sizeof *AB);
  prru_data *d = malloc(sizeof *d);
  prru_linearization *lin = malloc(sizeof *lin);
  if (!s->K || !s->u_ff || !s->x_ref || !AB || !d || !lin)
    st = prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  if (st == PRRU_OK) st = lqr_weights(m, ref, o, s, msg, msglen);
  if (st == PRRU_OK) st = lqr_schedule_fill(m, ref, s, AB, d, lin, msg, msglen);
  free(AB);
  free(d);
  free(lin);
  if (st != PRRU_OK) prru_lqr_schedule_free(s);
  if (st == PRRU_OK && msg && msglen > 0) msg[0] = '\0';
  return st;
}

void prru_lqr_schedule_free(prru_lqr_schedule *s)
{
  free(s->K);
  free(s->u_ff);
  free(s->x_ref);
  s->K = s->u_ff = s->x_ref = NULL;
  s->n = 0;
}

int prru_lqr_control(const prru_lqr_schedule *s, long k, const prru_track_options *o, const double x[6],
                     double fd_cmd[], double fd[], int sat[])
{
  if (!(k >= 0 && k < s->n)) return PRRU_EINPUT;
  const int na = s->nact;
  const double *K = s->K + 6 * na * k, *xr = s->x_ref + 6 * k, *u = s->u_ff + na * k;
  double dx[6];
  for (int j = 0; j < 6; j++) dx[j] = x[j] - xr[j];
  for (int i = 0; i < na; i++) {
    double f = u[i];
    for (int j = 0; j < 6; j++) f -= K[6 * i + j] * dx[j];
    fd_cmd[i] = f;
  }
  if (!prru_finite_n(fd_cmd, na)) return PRRU_EINPUT;
  for (int i = 0; i < na; i++) {
    double lim = o->f_max[i];
    sat[i] = fabs(fd_cmd[i]) > lim;
    fd[i] = sat[i] ? copysign(lim, fd_cmd[i]) : fd_cmd[i];
  }
  return PRRU_OK;
}

int prru_track_options_check(const prru_model *m, const prru_track_options *o, char *msg, int msglen)
{
  const int na = m->mech->nact;
  for (int i = 0; i < 3; i++) {
    if (!(o->kp[i] >= 0.0 && isfinite(o->kp[i])))
      return prru_fail(msg, msglen, PRRU_EINPUT, "kp: gain %d is %g, not >= 0 and finite", i + 1, o->kp[i]);
    if (!(o->kd[i] >= 0.0 && isfinite(o->kd[i])))
      return prru_fail(msg, msglen, PRRU_EINPUT, "kd: gain %d is %g, not >= 0 and finite", i + 1, o->kd[i]);
  }
  if (!(o->control_period >= 0.0 && isfinite(o->control_period)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "control period: %g s is not >= 0 and finite",
                     o->control_period);
  if (o->control_period == 0.0 && !(o->dt_out > 0.0 && isfinite(o->dt_out)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "dt_out: %g s is not > 0 and finite", o->dt_out);
  for (int i = 0; i < na; i++) {
    if (!(o->f_max[i] > 0.0))
      return prru_fail(msg, msglen, PRRU_EINPUT,
                       "force limit of actuator %d must be > 0 (or infinite), got %g", i + 1,
                       o->f_max[i]);
    if (!(o->speed_max[i] > 0.0))
      return prru_fail(msg, msglen, PRRU_EINPUT,
                       "speed limit of actuator %d must be > 0 (or infinite), got %g", i + 1,
                       o->speed_max[i]);
    if (!(o->d_min[i] < o->d_max[i]))
      return prru_fail(msg, msglen, PRRU_EINPUT,
                       "stroke of slider %d: minimum %g must be below maximum %g", i + 1,
                       o->d_min[i], o->d_max[i]);
  }
  if (!(o->noise_q >= 0.0 && isfinite(o->noise_q)) || !(o->noise_qd >= 0.0 && isfinite(o->noise_qd)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "sensor noise: standard deviations %g, %g are not >= 0 "
                     "and finite", o->noise_q, o->noise_qd);
  if ((o->noise_q > 0.0 || o->noise_qd > 0.0) && o->control_period == 0.0)
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "sensor noise needs control period > 0: a continuous controller inside the "
                     "integrator cannot read noisy samples");
  if (!prru_finite_n(o->q0_offset, 3))
    return prru_fail(msg, msglen, PRRU_EINPUT, "q0_offset: the initial offset must be finite");
  if (!(o->abs_tol >= PRRU_TOL_MIN && isfinite(o->abs_tol)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "abs_tol: %g is not >= %.2g and finite", o->abs_tol,
                     PRRU_TOL_MIN);
  if (!(o->rel_tol >= PRRU_TOL_MIN && isfinite(o->rel_tol)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "rel_tol: %g is not >= %.2g and finite", o->rel_tol,
                     PRRU_TOL_MIN);
  if (o->controller != PRRU_TRACK_CT && o->controller != PRRU_TRACK_LQR)
    return prru_fail(msg, msglen, PRRU_EINPUT, "controller: %d is neither PRRU_TRACK_CT nor "
                     "PRRU_TRACK_LQR", o->controller);
  if (o->controller == PRRU_TRACK_LQR) {
    int st = lqr_weights_check(o, na, msg, msglen);
    if (st != PRRU_OK) return st;
  }
  if (msg && msglen > 0) msg[0] = '\0';
  return PRRU_OK;
}

typedef struct {
  const prru_model *m;
  const prru_quintic *ref;
  const prru_track_options *o;
  prru_data *d;
  const prru_lqr_schedule *lqr; /* the LQR's gains, NULL for computed torque */
  /* o->plant derived for the topology of m (the plant is a robot of m's
   * limbs), once per run. */
  const prru_topology *topo;
  const prru_topo_derived *plant;
  int continuous;
  double fd_hold[PRRU_MAX_ACT];
  int status; /* why the right-hand side last failed */
  /* Where it failed: an integrator's trial state (abandoned, so y no
   * longer holds it) at time t, in the controller or in the plant, and
   * the largest controller force of the step's evaluations before it. */
  int in_plant;
  double fail_t, fail_y[6], fd_step_peak;
} track_ctx;

/* As in simulate.c: GSL_EBADFUNC makes every stepper return at once. */
static int track_rhs(double t, const double y[], double f[], void *p)
{
  track_ctx *c = p;
  if (c->o->interrupt && *c->o->interrupt) {
    c->status = PRRU_EINTERRUPTED;
    return GSL_EBADFUNC;
  }
  double fd[PRRU_MAX_ACT], fd_cmd[PRRU_MAX_ACT];
  int sat[PRRU_MAX_ACT], st = PRRU_OK;
  if (c->continuous) {
    double qr[3], qdr[3], qddr[3];
    prru_quintic_eval(c->ref, clamp_time(c->ref, t), qr, qdr, qddr);
    st = prru_computed_torque(c->m, c->d, c->o, qr, qdr, qddr, y, y + 3, fd_cmd, fd, sat);
  } else {
    memcpy(fd, c->fd_hold, sizeof fd);
  }
  c->in_plant = st == PRRU_OK;
  if (st == PRRU_OK && c->continuous)
    for (int i = 0; i < c->m->mech->nact; i++) c->fd_step_peak = fmax(c->fd_step_peak, fabs(fd_cmd[i]));
  if (st == PRRU_OK) st = plant_accel(c->topo, c->plant, y, y + 3, fd, f + 3);
  if (st != PRRU_OK) {
    c->status = st;
    c->fail_t = t;
    memcpy(c->fail_y, y, sizeof c->fail_y);
    return GSL_EBADFUNC;
  }
  memcpy(f, y + 3, 3 * sizeof y[0]);
  return GSL_SUCCESS;
}

/* The controller at tick t: fills s (reference, true state, forces) from
 * the measured state (true + noise when rng). */
/* What a failed evaluation at state y means: the pose out of the
 * workspace or singular, or (PRRU_EINPUT, y finite) forces that overflow. */
static const char *failure_text(int st)
{
  return st == PRRU_EUNREACHABLE ? "outside the workspace (not reachable)"
         : st == PRRU_ESINGULAR  ? "singular (J_d singular, or on the workspace boundary)"
         : st == PRRU_EINPUT     ? "regular, but the forces overflow there"
                                 : prru_strerror(st);
}

/* The controller failed at tick t on the measured state meas (y the
 * true one): the message names the state it ran on, and blames the
 * sensor noise when only the noisy measurement is at fault. */
static int tick_failure(track_ctx *c, int st, double t, const double y[6], const double meas[6],
                        int noisy, char *msg, int msglen)
{
  const prru_track_options *o = c->o;
  double rc;
  if (noisy && prru_check_regular(c->m, c->d, y, &rc) == PRRU_OK) {
    char what[200];
    if (st == PRRU_EINPUT)
      snprintf(what, sizeof what, "q = (%.3g, %.3g, %.3g), qd = (%.3g, %.3g, %.3g), makes the "
               "controller's forces overflow", meas[0], meas[1], meas[2], meas[3], meas[4], meas[5]);
    else
      snprintf(what, sizeof what, "q = (%.9g, %.9g, %.9g) is %s: the controller's inverse "
               "dynamics has no forces for it", meas[0], meas[1], meas[2], failure_text(st));
    return prru_fail(msg, msglen, st,
                     "stopped at t = %.9g s: the measured state (true state + sensor noise) %s; "
                     "the true state is regular: the sensor noise (q %g, qd %g) is too large", t,
                     what, o->noise_q, o->noise_qd);
  }
  if (st == PRRU_EINPUT)
    return prru_fail(msg, msglen, st,
                     "stopped at t = %.9g s: the controller's forces overflow at the %s state q = "
                     "(%.9g, %.9g, %.9g), qd = (%.9g, %.9g, %.9g) (gains kp %g, kd %g, or "
                     "velocities too large)", t, noisy ? "measured" : "true", meas[0], meas[1],
                     meas[2], meas[3], meas[4], meas[5], o->kp[0], o->kd[0]);
  return prru_fail(msg, msglen, st, "stopped at t = %.9g s: %s at q = (%.9g, %.9g, %.9g)%s", t,
                   prru_strerror(st), meas[0], meas[1], meas[2],
                   st == PRRU_ESINGULAR ? " (the controller's inverse dynamics)" : "");
}

static int track_tick(track_ctx *c, gsl_rng *rng, long k, double t, const double y[6],
                      prru_track_sample *s, char *msg, int msglen)
{
  const prru_track_options *o = c->o;
  s->t = t;
  prru_quintic_eval(c->ref, clamp_time(c->ref, t), s->q_ref, s->qd_ref, s->qdd_ref);
  double meas[6];
  memcpy(meas, y, sizeof meas);
  if (rng)
    for (int i = 0; i < 6; i++) meas[i] += gsl_ran_gaussian(rng, i < 3 ? o->noise_q : o->noise_qd);
  for (int i = 0; i < 3; i++) {
    s->q[i] = y[i];
    s->qd[i] = y[3 + i];
    s->e[i] = s->q_ref[i] - y[i];
  }
  int st;
  if (c->lqr) {
    st = prru_lqr_control(c->lqr, k, o, meas, s->fd_cmd, s->fd, s->saturated);
    if (st != PRRU_OK)
      return prru_fail(msg, msglen, st, "stopped at t = %.9g s: the LQR's forces overflow at the %s "
                       "state q = (%.9g, %.9g, %.9g), qd = (%.9g, %.9g, %.9g)", t,
                       rng ? "measured" : "true", meas[0], meas[1], meas[2], meas[3], meas[4], meas[5]);
  } else {
    st = prru_computed_torque(c->m, c->d, o, s->q_ref, s->qd_ref, s->qdd_ref, meas, meas + 3,
                              s->fd_cmd, s->fd, s->saturated);
    if (st != PRRU_OK) return tick_failure(c, st, t, y, meas, rng != NULL, msg, msglen);
  }
  memcpy(c->fd_hold, s->fd, sizeof c->fd_hold);
  st = plant_accel(c->topo, c->plant, y, y + 3, s->fd, s->qdd);
  if (st != PRRU_OK)
    return prru_fail(msg, msglen, st, "stopped at t = %.9g s: %s at q = (%.9g, %.9g, %.9g) (the plant's "
                     "equations of motion)", t, prru_strerror(st), y[0], y[1], y[2]);
  c->topo->general->ik(c->plant, y, s->d);
  if (!prru_finite_n(s->d, c->m->mech->nact))
    return prru_fail(msg, msglen, PRRU_EUNREACHABLE,
                     "stopped at t = %.9g s: the plant left the workspace: %s at q = (%.9g, "
                     "%.9g, %.9g)", t, prru_strerror(PRRU_EUNREACHABLE), y[0], y[1], y[2]);
  /* The controller's model's kernels, which prru track and the binding
   * used before this moved here: the plant's parameter kernels agree with
   * them only to rounding, and the reported speeds stay to the bit. */
  double ddb[PRRU_MAX_ACT];
  prru_model_actuator_rates(c->m, s->q, s->qd, s->dd, ddb);
  return PRRU_OK;
}

static void summary_add(prru_track_summary *sum, const prru_track_sample *s, const prru_track_options *o,
                        int na)
{
  sum->samples++;
  sum->t_end = s->t;
  int any = 0, over = 0;
  for (int i = 0; i < 3; i++) {
    sum->rms_e[i] += s->e[i] * s->e[i]; /* a sum of squares until the end */
    sum->max_e[i] = fmax(sum->max_e[i], fabs(s->e[i]));
  }
  for (int i = 0; i < na; i++) {
    sum->max_fd[i] = fmax(sum->max_fd[i], fabs(s->fd[i]));
    sum->saturated[i] += s->saturated[i];
    any |= s->saturated[i];
    sum->max_dd[i] = fmax(sum->max_dd[i], fabs(s->dd[i]));
    over |= fabs(s->dd[i]) > o->speed_max[i];
  }
  sum->any_saturated += any;
  sum->over_speed += over;
}

static void summary_finish(prru_track_summary *sum)
{
  for (int i = 0; i < 3; i++)
    sum->rms_e[i] = sum->samples > 0 ? sqrt(sum->rms_e[i] / (double)sum->samples) : 0.0;
}

/* The first of the na sliders outside its stroke, or -1. */
static int stroke_violation(const prru_track_options *o, const double d[], int na)
{
  for (int i = 0; i < na; i++)
    if (d[i] < o->d_min[i] || d[i] > o->d_max[i]) return i;
  return -1;
}

/* The plant from *t to t1 as gsl_odeiv2_driver_apply runs it (the same
 * evolve calls, step-count and step-size rules), with the sliders checked
 * against their stroke after every accepted step before t1: between two
 * ticks a slider can leave its stroke and come back. GSL_SUCCESS, the evolve's or
 * the driver's error, or GSL_EDOM with *bad the slider out of its stroke
 * (*t, y the state there). */
static int track_advance(gsl_odeiv2_driver *drv, const track_ctx *c, double *t,
                         double t1, double y[6], int *bad)
{
  drv->n = 0;
  while (t1 - *t > 0.0) {
    int gs = gsl_odeiv2_evolve_apply(drv->e, drv->c, drv->s, drv->sys, t, t1, &drv->h, y);
    if (gs != GSL_SUCCESS) return gs;
    if (drv->nmax > 0 && drv->n > drv->nmax) return GSL_EMAXITER;
    if (fabs(drv->h) > drv->hmax) drv->h = drv->hmax;
    if (fabs(drv->h) < drv->hmin) return GSL_ENOPROG;
    drv->n++;
    if (*t >= t1) break; /* the tick itself: track_run checks its sample */
    double d[PRRU_MAX_ACT];
    c->topo->general->ik(c->plant, y, d); /* the plant's sliders, as at the ticks */
    if ((*bad = stroke_violation(c->o, d, c->m->mech->nact)) >= 0) return GSL_EDOM;
  }
  return GSL_SUCCESS;
}

/* The right-hand side failed on one of the integrator's trial states
 * (the step abandoned, the run's state at t regular): the message names
 * the trial, where it failed and the force that drove it there. A trial
 * out of the workspace after a regular state means one step moved the
 * state that far: gains too stiff for the step, or forces that large. */
static int trial_failure(const track_ctx *c, int st, double t, char *msg, int msglen)
{
  const prru_track_options *o = c->o;
  const double *y = c->fail_y;
  double peak = c->fd_step_peak;
  for (int i = 0; i < c->m->mech->nact && !c->continuous; i++) peak = fmax(peak, fabs(c->fd_hold[i]));
  const char *where = c->in_plant ? "the plant's equations of motion" : "the controller's inverse dynamics";
  char what[200];
  if (st == PRRU_EINPUT)
    snprintf(what, sizeof what, "overflow in %s (qd = (%.3g, %.3g, %.3g))", where, y[3], y[4], y[5]);
  else
    snprintf(what, sizeof what, "q = (%.9g, %.9g, %.9g) is %s (%s)", y[0], y[1], y[2],
             failure_text(st), where);
  if (c->lqr)
    return prru_fail(msg, msglen, st,
                     "stopped at t = %.9g s: the integrator's trial state at t = %.9g s left the "
                     "run's regular path: %s; the controller's forces reached %.3g N in this step "
                     "(LQR): raise the input weights lqr_r or limit the forces", t, c->fail_t, what,
                     peak);
  return prru_fail(msg, msglen, st,
                   "stopped at t = %.9g s: the integrator's trial state at t = %.9g s left the "
                   "run's regular path: %s; the controller's forces reached %.3g N in this step "
                   "(gains kp %g %g %g, kd %g %g %g): lower the gains or limit the forces",
                   t, c->fail_t, what, peak, o->kp[0], o->kp[1], o->kp[2], o->kd[0], o->kd[1],
                   o->kd[2]);
}

static int track_step(gsl_odeiv2_driver *drv, track_ctx *c, double *t, double tk, double y[6],
                      char *msg, int msglen)
{
  c->status = PRRU_OK;
  c->fd_step_peak = 0.0;
  gsl_odeiv2_driver_reset(drv);
  int bad = -1, gs = track_advance(drv, c, t, tk, y, &bad);
  if (gs == GSL_SUCCESS) return PRRU_OK;
  if (gs == GSL_EDOM && bad >= 0) {
    double d[PRRU_MAX_ACT];
    c->topo->general->ik(c->plant, y, d);
    return prru_fail(msg, msglen, PRRU_EUNREACHABLE,
                     "stopped at t = %.9g s (between samples): slider %d at d = %.9g m "
                     "left its stroke [%g, %g]", *t, bad + 1, d[bad], c->o->d_min[bad],
                     c->o->d_max[bad]);
  }
  int st = gs == GSL_EBADFUNC && c->status != PRRU_OK ? c->status : PRRU_ENOCONV;
  if (st == PRRU_EINTERRUPTED)
    return prru_fail(msg, msglen, st, "interrupted at t = %.9g s", *t);
  if (st == PRRU_ENOCONV)
    return prru_fail(msg, msglen, st, "integrator failed at t = %.9g s: %s", *t, gsl_strerror(gs));
  return trial_failure(c, st, *t, msg, msglen);
}

static int track_run(track_ctx *c, gsl_odeiv2_driver *drv, gsl_rng *rng, prru_track_sample *s,
                     prru_track_summary *sum, char *msg, int msglen)
{
  const prru_track_options *o = c->o;
  const double t0 = prru_quintic_t_begin(c->ref);
  const double step = c->continuous ? o->dt_out : o->control_period;
  const long nticks = last_tick(c->ref, step);
  double y[6], t = t0, qd0[3];
  prru_quintic_eval(c->ref, t0, y, qd0, NULL);
  for (int i = 0; i < 3; i++) {
    y[i] -= o->q0_offset[i];
    y[3 + i] = qd0[i];
  }
  for (long k = 0; k <= nticks; k++) {
    double tk = tick_time(c->ref, step, k, nticks);
    if (k > 0) {
      int st = track_step(drv, c, &t, tk, y, msg, msglen);
      if (st != PRRU_OK) return st;
    }
    int st = track_tick(c, rng, k, tk, y, s, msg, msglen);
    if (st != PRRU_OK) return st;
    int bad = stroke_violation(o, s->d, c->m->mech->nact);
    if (bad >= 0)
      return prru_fail(msg, msglen, PRRU_EUNREACHABLE,
                       "stopped at t = %.9g s: slider %d at d = %.9g m left its stroke [%g, %g]",
                       tk, bad + 1, s->d[bad], o->d_min[bad], o->d_max[bad]);
    summary_add(sum, s, o, c->m->mech->nact);
    if (o->on_sample && o->on_sample(s, o->ctx) != 0)
      return prru_fail(msg, msglen, PRRU_EINTERRUPTED,
                       "stopped at t = %.9g s by the sample consumer", tk);
    if (o->interrupt && *o->interrupt)
      return prru_fail(msg, msglen, PRRU_EINTERRUPTED, "interrupted at t = %.9g s", tk);
  }
  return PRRU_OK;
}

int prru_track(const prru_model *m, const prru_quintic *ref, const prru_track_options *o,
               prru_track_summary *sum, char *msg, int msglen)
{
  memset(sum, 0, sizeof *sum);
  if (!ref || ref->n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "no reference trajectory");
  int st = prru_track_options_check(m, o, msg, msglen);
  if (st != PRRU_OK) return st;
  const prru_topology *topo = prru_topology_of(m->mech->nlimb);
  if (!topo)
    return prru_fail(msg, msglen, PRRU_EINPUT, "the model has %d limbs: no plant of that topology",
                     m->mech->nlimb);
  prru_gsl_init();
  track_ctx c;
  memset(&c, 0, sizeof c);
  c.m = m;
  c.ref = ref;
  c.o = o;
  c.d = malloc(sizeof(prru_data));
  prru_topo_derived *plant = malloc(sizeof *plant);
  if (plant) topo->derive(&o->plant, plant);
  c.topo = topo;
  c.plant = plant;
  c.continuous = o->control_period == 0.0;
  prru_lqr_schedule lqr;
  memset(&lqr, 0, sizeof lqr);
  if (o->controller == PRRU_TRACK_LQR) {
    st = prru_lqr_schedule_build(m, ref, o, &lqr, msg, msglen);
    if (st != PRRU_OK) {
      free(c.d);
      free(plant);
      return st;
    }
    c.lqr = &lqr;
  }
  prru_track_sample *s = malloc(sizeof *s);
  gsl_odeiv2_system sys = {track_rhs, NULL, 6, &c};
  double h0 = fmin(1e-4, c.continuous ? o->dt_out : o->control_period);
  gsl_odeiv2_driver *drv =
      gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, h0, o->abs_tol, o->rel_tol);
  int noisy = o->noise_q > 0.0 || o->noise_qd > 0.0;
  gsl_rng *rng = noisy ? gsl_rng_alloc(gsl_rng_mt19937) : NULL;
  if (!c.d || !plant || !s || !drv || (noisy && !rng)) {
    st = prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  } else {
    if (rng) gsl_rng_set(rng, o->seed);
    gsl_odeiv2_driver_set_nmax(drv, (unsigned long)PRRU_MAX_STEPS_DEFAULT);
    memset(s, 0, sizeof *s);
    st = track_run(&c, drv, rng, s, sum, msg, msglen);
  }
  summary_finish(sum);
  if (drv) gsl_odeiv2_driver_free(drv);
  if (rng) gsl_rng_free(rng);
  free(c.d);
  free(plant);
  free(s);
  prru_lqr_schedule_free(&lqr);
  if (st == PRRU_OK && msg && msglen > 0) msg[0] = '\0';
  return st;
}

/* Where a pose is not usable, for the reference's messages. */
static const char *pose_problem(int st)
{
  return st == PRRU_EUNREACHABLE ? "outside the workspace (unreachable)"
         : st == PRRU_ESINGULAR  ? "at a singularity (J_d singular)"
                                 : prru_strerror(st);
}

int prru_track_check_reference(const prru_model *m, const prru_quintic *ref, const prru_track_options *o,
                               double step, double *ff_peak, char *msg, int msglen)
{
  *ff_peak = 0;
  if (!ref || ref->n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "no reference trajectory");
  const double t0 = prru_quintic_t_begin(ref), t1 = prru_quintic_t_end(ref), span = t1 - t0;
  if (!(step > 0) || !(span / step <= 1e8))
    return prru_fail(msg, msglen, PRRU_EINPUT, "more than 1e8 samples (span %g s, step %g s)", span, step);
  /* Every millisecond at least, also between coarse rows. */
  if (span / 1e-3 <= 1e8) step = fmin(step, 1e-3);
  prru_data *d = malloc(sizeof *d);
  if (!d) return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  const long n = (long)fmax(1.0, ceil(span / step - 1e-9));
  const int na = m->mech->nact;
  int st = PRRU_OK, crossed;
  prru_path_side side;
  prru_path_side_init(&side);
  static const prru_loads none;
  for (long k = 0; k <= n && st == PRRU_OK; k++) {
    double t = k == n ? t1 : t0 + (double)k * step, q[3], qd[3], qdd[3], fd[PRRU_MAX_ACT], rcond;
    prru_quintic_eval(ref, t, q, qd, qdd);
    int ps = prru_path_sample(&side, m, d, q, &rcond, &crossed);
    if (crossed) {
      st = prru_fail(msg, msglen, PRRU_EINPUT, "reference at sample %ld (t = %.9g s): the path crosses a "
                     "singularity (det J_d changes sign) before q = (%.9g, %.9g, %.9g)", k + 1, t, q[0],
                     q[1], q[2]);
      break;
    }
    if (ps != PRRU_OK) {
      st = prru_fail(msg, msglen, PRRU_EINPUT, "reference at sample %ld (t = %.9g s): q = (%.9g, %.9g, "
                     "%.9g) is %s", k + 1, t, q[0], q[1], q[2], pose_problem(ps));
      break;
    }
    for (int i = 0; i < na && st == PRRU_OK; i++)
      if (d->d[i] < o->d_min[i] || d->d[i] > o->d_max[i])
        st = prru_fail(msg, msglen, PRRU_EINPUT, "reference at sample %ld (t = %.9g s): slider %d at d = "
                       "%.9g m is outside its stroke [%g, %g]", k + 1, t, i + 1, d->d[i], o->d_min[i],
                       o->d_max[i]);
    if (st == PRRU_OK && prru_inverse_dynamics(m, d, q, qd, qdd, &none, fd) == PRRU_OK)
      for (int i = 0; i < na; i++) *ff_peak = fmax(*ff_peak, fabs(fd[i]));
  }
  free(d);
  return st;
}

static void scale_n(double *v, int n, double f)
{
  for (int i = 0; i < n; i++) v[i] *= f;
}

/* Every entry, also those past a model's sizes (which no kernel reads): a
 * model's own are scaled alike for either topology, and p needs no model. */
int prru_params_scale(prru_params *p, const char *key, double factor)
{
  if (!key || !(factor > 0.0) || !isfinite(factor)) return PRRU_EINPUT;
  if (strcmp(key, "mass") == 0) {
    scale_n(p->mass, PRRU_MAX_BODY, factor);
    scale_n(&p->inertia[0][0], PRRU_MAX_BODY * 6, factor);
  } else if (strcmp(key, "inertia") == 0) {
    scale_n(&p->inertia[0][0], PRRU_MAX_BODY * 6, factor);
  } else if (strcmp(key, "armature") == 0) {
    scale_n(p->armature, PRRU_MAX_ACT, factor);
  } else if (strcmp(key, "damping") == 0) {
    scale_n(p->damping, PRRU_MAX_ACT, factor);
  } else if (strcmp(key, "coulomb") == 0) {
    scale_n(p->coulomb, PRRU_MAX_ACT, factor);
  } else if (strcmp(key, "gravity") == 0) {
    scale_n(p->gravity, 3, factor);
  } else {
    return PRRU_EINPUT;
  }
  return PRRU_OK;
}
