/* prru_linearize.h: the closed-form derivatives of the dynamics. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>

#include "prru_linearize.h"
#include "internal.h"

int prru_linearize_available(const prru_model *m)
{
  return m->kernels->eom_solve_derivs != NULL;
}

/* A = [0 I; Dq Dqd], B = [0; Dfd] (N actuators). */
static void state_space(int N, prru_linearization *o)
{
  memset(o->A, 0, sizeof o->A);
  memset(o->B, 0, sizeof o->B);
  for (int i = 0; i < 3; i++) {
    o->A[6 * i + 3 + i] = 1.0;
    for (int k = 0; k < 3; k++) {
      o->A[6 * (3 + i) + k] = o->dqdd_dq[3 * i + k];
      o->A[6 * (3 + i) + 3 + k] = o->dqdd_dqd[3 * i + k];
    }
    for (int k = 0; k < N; k++) o->B[N * (3 + i) + k] = o->dqdd_dfd[N * i + k];
  }
}

/* Ad, Bd from exp([A B; 0 0] dt): PRRU_OK, or PRRU_EINPUT where GSL fails
 * or the exponential is not finite. */
static int zero_order_hold(int N, prru_linearization *o, double dt)
{
  enum { SMAX = 6 + PRRU_MAX_ACT };
  const int S = 6 + N;
  double aug[SMAX * SMAX] = {0}, ex[SMAX * SMAX];
  for (int i = 0; i < 6; i++) {
    for (int k = 0; k < 6; k++) aug[S * i + k] = o->A[6 * i + k] * dt;
    for (int k = 0; k < N; k++) aug[S * i + 6 + k] = o->B[N * i + k] * dt;
  }
  gsl_matrix_view a = gsl_matrix_view_array(aug, (size_t)S, (size_t)S),
                  e = gsl_matrix_view_array(ex, (size_t)S, (size_t)S);
  prru_gsl_init();
  if (gsl_linalg_exponential_ss(&a.matrix, &e.matrix, GSL_PREC_DOUBLE) != GSL_SUCCESS ||
      !prru_finite_n(ex, S * S))
    return PRRU_EINPUT;
  for (int i = 0; i < 6; i++) {
    for (int k = 0; k < 6; k++) o->Ad[6 * i + k] = ex[S * i + k];
    for (int k = 0; k < N; k++) o->Bd[N * i + k] = ex[S * i + 6 + k];
  }
  return PRRU_OK;
}

/* The trust test and the rest of the linearisation once the derivative
 * kernel has left M, b, qdd in d, minors, and the derivative blocks in o
 * (prru_linearize and prru_linearize_batch: one test for both). */
static int linearization_from(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                              const prru_loads *l, const double minors[3], double dt,
                              prru_linearization *o)
{
  int st = prru_forward_verdict(m, d, q, qd, l, minors,
                                KERNEL(m, unseen_finite_eom_solve_derivs)(q, qd, l->fd, l->fp, l->mp));
  /* Trusted qdd from finite inputs: the derivatives are products of the
   * same finite terms and one division by det M, which the test bounds;
   * they overflow only where qdd nearly does. */
  if (st == PRRU_OK &&
      !(prru_finite_n(o->dqdd_dq, 9) && prru_finite_n(o->dqdd_dqd, 9) &&
        prru_finite_n(o->dqdd_dfd, 3 * m->mech->nact) && prru_finite_n(o->dqdd_dfp, 9) &&
        prru_finite_n(o->dqdd_dmp, 9)))
    st = PRRU_EINPUT;
  if (st == PRRU_OK) {
    memcpy(o->qdd, d->qdd, sizeof o->qdd);
    state_space(m->mech->nact, o);
    o->dt = dt;
    memset(o->Ad, 0, sizeof o->Ad), memset(o->Bd, 0, sizeof o->Bd);
    if (dt > 0) st = zero_order_hold(m->mech->nact, o, dt);
  }
  if (st != PRRU_OK) memset(o, 0, sizeof *o);
  return st;
}

int prru_linearize(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                   const prru_loads *l, double dt, prru_linearization *out)
{
  if (!prru_linearize_available(m) || !(dt >= 0) || !isfinite(dt)) return PRRU_EINPUT;
  /* Straight into out (a copy of its 1.4 kB costs a tenth of the call);
   * the entries past the model's actuators stay 0. */
  prru_linearization *o = out;
  memset(o->dqdd_dfd, 0, sizeof o->dqdd_dfd);
  double minors[3];
  KERNEL(m, eom_solve_derivs)(m->kernel_params, q, qd, l->fd, l->fp, l->mp, d->M, d->b, d->qdd,
                               minors, o->dqdd_dq, o->dqdd_dqd, o->dqdd_dfd, o->dqdd_dfp,
                               o->dqdd_dmp);
  return linearization_from(m, d, q, qd, l, minors, dt, o);
}

/* The batched kernel's chunk of states: its inputs and outputs in rows
 * of CHUNK (component i of state k at [i * CHUNK + k]); the derivative
 * blocks in prru_linearization's order, one row per entry. */
enum { CHUNK = 32, NDERIV = 9 + 9 + 3 * PRRU_MAX_ACT + 9 + 9 };
typedef struct {
  double q[3 * CHUNK], qd[3 * CHUNK], fd[PRRU_MAX_ACT * CHUNK], fp[3 * CHUNK], mp[3 * CHUNK];
  double M[9 * CHUNK], b[3 * CHUNK], qdd[3 * CHUNK], minors[3 * CHUNK], D[NDERIV * CHUNK];
} linearize_chunk;

static void to_rows(double *rows, const double *v, int dim, int k, int n)
{
  for (int i = 0; i < dim; i++) rows[i * n + k] = v[i];
}

static void from_rows(double *v, const double *rows, int dim, int k, int n)
{
  for (int i = 0; i < dim; i++) v[i] = rows[i * n + k];
}

/* States o .. o + n - 1 of prru_linearize_batch (n <= CHUNK); the first
 * status that is not PRRU_OK, else PRRU_OK. */
static int linearize_chunk_at(const prru_model *m, int o, int n, const double *q, const double *qd,
                              const prru_loads *l, double dt, prru_linearization *out, int *status,
                              linearize_chunk *c)
{
  const int N = m->mech->nact;
  for (int k = 0; k < n; k++) {
    to_rows(c->q, q + 3 * (o + k), 3, k, n), to_rows(c->qd, qd + 3 * (o + k), 3, k, n);
    to_rows(c->fd, l[o + k].fd, N, k, n), to_rows(c->fp, l[o + k].fp, 3, k, n);
    to_rows(c->mp, l[o + k].mp, 3, k, n);
  }
  double *D = c->D;
  KERNEL(m, batch_eom_solve_derivs)(m->kernel_params, n, c->q, c->qd, c->fd, c->fp, c->mp, c->M, c->b,
                                    c->qdd, c->minors, D, D + 9 * n, D + 18 * n, D + (18 + 3 * N) * n,
                                    D + (27 + 3 * N) * n);
  int first = PRRU_OK;
  for (int k = 0; k < n; k++) {
    prru_data d;
    double minors[3];
    prru_linearization *x = out + o + k;
    from_rows(d.M, c->M, 9, k, n), from_rows(d.b, c->b, 3, k, n), from_rows(d.qdd, c->qdd, 3, k, n);
    from_rows(minors, c->minors, 3, k, n);
    memset(x->dqdd_dfd, 0, sizeof x->dqdd_dfd);
    from_rows(x->dqdd_dq, D, 9, k, n), from_rows(x->dqdd_dqd, D + 9 * n, 9, k, n);
    from_rows(x->dqdd_dfd, D + 18 * n, 3 * N, k, n);
    from_rows(x->dqdd_dfp, D + (18 + 3 * N) * n, 9, k, n);
    from_rows(x->dqdd_dmp, D + (27 + 3 * N) * n, 9, k, n);
    int st = linearization_from(m, &d, q + 3 * (o + k), qd + 3 * (o + k), l + o + k, minors, dt, x);
    /* A failure is judged again the scalar way: the batch's vector sin and
     * cos may move a state within a few ulp of a threshold across it, and
     * a failure's status is prru_linearize's (failures are rare: the cost
     * of a second evaluation does not matter). */
    if (st != PRRU_OK) st = prru_linearize(m, &d, q + 3 * (o + k), qd + 3 * (o + k), l + o + k, dt, x);
    if (status) status[o + k] = st;
    if (first == PRRU_OK) first = st;
  }
  return first;
}

int prru_linearize_batch(const prru_model *m, int n, const double *q, const double *qd,
                         const prru_loads *l, double dt, prru_linearization *out, int *status)
{
  const int bad = !m->kernels->batch_eom_solve_derivs || !(dt >= 0) || !isfinite(dt);
  int first = PRRU_OK;
  if (n < 0) return PRRU_EINPUT;
  if (bad) {
    for (int k = 0; k < n; k++) {
      memset(out + k, 0, sizeof *out);
      if (status) status[k] = PRRU_EINPUT;
    }
    return PRRU_EINPUT;
  }
  /* About 20 kB of this thread's stack (4 actuators: 21): no allocation. */
  linearize_chunk c PRRU_ALIGN64;
  for (int o = 0; o < n; o += CHUNK) {
    const int st = linearize_chunk_at(m, o, n - o < CHUNK ? n - o : CHUNK, q, qd, l, dt, out, status, &c);
    if (first == PRRU_OK) first = st;
  }
  return first;
}

int prru_linearize_why(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                       const prru_loads *l, double dt, prru_linearization *out, char *msg,
                       int msglen)
{
  const int st = prru_linearize(m, d, q, qd, l, dt, out);
  if (st == PRRU_OK) return prru_fail(msg, msglen, st, "%s", "");
  if (!prru_linearize_available(m))
    return prru_fail(msg, msglen, st, "the %s kernels of this model have no derivatives",
                     m->kernels->path);
  if (!(dt >= 0) || !isfinite(dt))
    return prru_fail(msg, msglen, st, "dt = %g: the hold period must be finite and >= 0", dt);
  /* The forward step's own diagnosis: the same kernel terms and test. */
  if (prru_forward_dynamics_why(m, d, q, qd, l, msg, msglen) != PRRU_OK) return st;
  return prru_fail(msg, msglen, st,
                   "the derivatives of qdd or their exponential over dt = %g overflow at this "
                   "state",
                   dt);
}

static int inverse3_derivs(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                           const double qdd[3], const prru_loads *l, double fd[3], double dfd_dq[9],
                           double dfd_dqd[9], double dfd_dqdd[9])
{
  if (!m->kernels->inverse_derivs) return PRRU_EINPUT;
  /* The three blocks in one array: one finiteness test for the 27. */
  double f[3], D[27];
  KERNEL(m, inverse_derivs)(m->kernel_params, q, qd, qdd, l->fp, l->mp, d->d, d->Jd, d->Jdpinv, f, D,
                            D + 9, D + 18, NULL);
  int st = prru_inverse3_status(m, d, f);
  if (st != PRRU_OK || !KERNEL(m, unseen_finite_inverse_derivs)(q, qd, qdd, l->fp, l->mp))
    return prru_inverse_failure(st, q, qd, qdd, l);
  if (!prru_finite_n(D, 27)) return PRRU_EINPUT;
  memcpy(fd, f, sizeof f);
  if (dfd_dq) memcpy(dfd_dq, D, 9 * sizeof *D);
  if (dfd_dqd) memcpy(dfd_dqd, D + 9, 9 * sizeof *D);
  if (dfd_dqdd) memcpy(dfd_dqdd, D + 18, 9 * sizeof *D);
  return PRRU_OK;
}

/* rhs (3 x 3, row-major) mapped by J_d^+T (4 x 3; its row i is column i
 * of J_d^+, Jp = d->Jdpinv) into out (4 x 3). */
static void map_pinv_t(const double *Jp, const double rhs[9], double out[3 * 4])
{
  enum { N = 4 };
  for (int i = 0; i < N; i++)
    for (int k = 0; k < 3; k++)
      out[3 * i + k] = Jp[i] * rhs[k] + Jp[N + i] * rhs[3 + k] + Jp[2 * N + i] * rhs[6 + k];
}

/* fd = J_d^+T tau + t n (prru_inverse_dynamics_preload: J_d^+ by the
 * runtime's QR, n by prru_null_from_jd) and its derivatives, composed from
 * the kernel's tau, dtau/dx and dJ_d/dq. With y = (J_d^T J_d)^-1 tau
 * (= J_d^+ fd at t = 0), differentiating J_d^T J_d y = tau gives
 *   d(J_d y) = (I - J_d J_d^+) dJ_d y + J_d^+T (dtau - dJ_d^T J_d y),
 * and J_d^T n = 0, |n| = 1 give dn = -J_d^+T dJ_d^T n, so with
 * I - J_d J_d^+ = n n^T:
 *   dfd/dx = n n^T (dJ_d/dx) y + J_d^+T (dtau/dx - (dJ_d/dx)^T fd);
 * dJ_d/dqd = dJ_d/dqdd = 0. Not the symbolic (J_d^T J_d)^-1: the normal
 * equations square J_d's condition number, up to 1e16 at jd_rcond_min. */
static int inverse4_derivs(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                           const double qdd[3], const prru_loads *l, double t, double fd[4],
                           double dfd_dq[3 * 4], double dfd_dqd[3 * 4], double dfd_dqdd[3 * 4])
{
  enum { N = 4 };
  if (!m->kernels->inverse_derivs) return PRRU_EINPUT;
  double tau[3], Tq[9], Tqd[9], Tqdd[9], DJ[9 * N], f[N], n[N], y[3];
  KERNEL(m, inverse_derivs)(m->kernel_params, q, qd, qdd, l->fp, l->mp, d->d, d->Jd, NULL, tau, Tq,
                            Tqd, Tqdd, DJ);
  int st = prru_inverse4_status(m, d, tau, f);
  if (st == PRRU_OK) st = prru_null_from_jd(m, d->Jd, n);
  if (st != PRRU_OK || !KERNEL(m, unseen_finite_inverse_derivs)(q, qd, qdd, l->fp, l->mp))
    return prru_inverse_failure(st, q, qd, qdd, l);
  const double *Jp = d->Jdpinv;
  for (int k = 0; k < 3; k++) {
    y[k] = 0;
    for (int i = 0; i < N; i++) y[k] += Jp[N * k + i] * f[i];
  }
  for (int i = 0; i < N; i++) f[i] += t * n[i];
  double r[9], Dq[3 * N], Dqd[3 * N], Dqdd[3 * N];
  for (int k = 0; k < 3; k++) {
    const double *Jk = DJ + 3 * N * k;
    for (int j = 0; j < 3; j++) {
      double s = Tq[3 * j + k];
      for (int i = 0; i < N; i++) s -= Jk[3 * i + j] * f[i];
      r[3 * j + k] = s;
    }
  }
  map_pinv_t(Jp, r, Dq);
  for (int k = 0; k < 3; k++) {
    const double *Jk = DJ + 3 * N * k;
    double s = 0;
    for (int i = 0; i < N; i++) s += n[i] * (Jk[3 * i] * y[0] + Jk[3 * i + 1] * y[1] + Jk[3 * i + 2] * y[2]);
    for (int i = 0; i < N; i++) Dq[3 * i + k] += n[i] * s;
  }
  map_pinv_t(Jp, Tqd, Dqd);
  map_pinv_t(Jp, Tqdd, Dqdd);
  if (!prru_finite_n(f, N) || !prru_finite_n(Dq, 3 * N) || !prru_finite_n(Dqd, 3 * N) ||
      !prru_finite_n(Dqdd, 3 * N))
    return PRRU_EINPUT;
  memcpy(fd, f, sizeof f);
  if (dfd_dq) memcpy(dfd_dq, Dq, sizeof Dq);
  if (dfd_dqd) memcpy(dfd_dqd, Dqd, sizeof Dqd);
  if (dfd_dqdd) memcpy(dfd_dqdd, Dqdd, sizeof Dqdd);
  return PRRU_OK;
}

int prru_inverse_dynamics_preload_derivs(const prru_model *m, prru_data *d, const double q[3],
                                         const double qd[3], const double qdd[3],
                                         const prru_loads *l, double preload, double fd[],
                                         double dfd_dq[], double dfd_dqd[], double dfd_dqdd[])
{
  if (!isfinite(preload)) return PRRU_EINPUT;
  if (m->mech->nact == 4)
    return inverse4_derivs(m, d, q, qd, qdd, l, preload, fd, dfd_dq, dfd_dqd, dfd_dqdd);
  if (preload != 0.0) return PRRU_EINPUT;
  return inverse3_derivs(m, d, q, qd, qdd, l, fd, dfd_dq, dfd_dqd, dfd_dqdd);
}

int prru_inverse_dynamics_derivs(const prru_model *m, prru_data *d, const double q[3],
                                 const double qd[3], const double qdd[3], const prru_loads *l,
                                 double fd[], double dfd_dq[], double dfd_dqd[], double dfd_dqdd[])
{
  if (m->mech->nact == 4) return inverse4_derivs(m, d, q, qd, qdd, l, 0.0, fd, dfd_dq, dfd_dqd, dfd_dqdd);
  return inverse3_derivs(m, d, q, qd, qdd, l, fd, dfd_dq, dfd_dqd, dfd_dqdd);
}
