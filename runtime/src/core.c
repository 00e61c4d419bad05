/* Model constants, status strings, reachability and the dynamics calls. */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru.h"
#include "internal.h"

const char *prru_strerror(int status)
{
  switch (status) {
  case PRRU_OK: return "success";
  case PRRU_EINPUT: return "invalid input (NaN, infinite or out of range)";
  case PRRU_EUNREACHABLE: return "configuration not reachable (no inverse kinematics)";
  case PRRU_ESINGULAR:
    return "singular configuration (J_d rank-deficient, or too near the workspace boundary to "
           "trust the dynamics)";
  case PRRU_ENOCONV: return "iteration did not converge";
  case PRRU_EINTERRUPTED: return "interrupted";
  case PRRU_EIO: return "input/output error";
  case PRRU_ENOMEM: return "out of memory";
  case PRRU_EPARSE: return "malformed input";
  case PRRU_ESTROKE: return "out_of_stroke: a slider outside its stroke (actuators.stroke)";
  default: return "unknown status";
  }
}

static pthread_once_t gsl_once = PTHREAD_ONCE_INIT;

static void gsl_handler_off(void) { gsl_set_error_handler_off(); }

void prru_gsl_init(void) { pthread_once(&gsl_once, gsl_handler_off); }

static int finite3(const double v[3]) { return prru_finite_n(v, 3); }

int prru_stroke_actuator(const prru_model *m, const double d[])
{
  const prru_mechanism *me = m->mech;
  for (int i = 0; i < me->nact; i++)
    if (d[i] < me->d_min[i] || d[i] > me->d_max[i]) return i;
  return -1;
}

int prru_stroke_why(const prru_model *m, const double d[], char *msg, int msglen)
{
  const int i = prru_stroke_actuator(m, d);
  if (i < 0) return prru_fail(msg, msglen, PRRU_OK, "%s", "");
  return prru_fail(msg, msglen, PRRU_ESTROKE, "slider %d at d = %.9g m is outside its stroke [%.9g, %.9g] m",
                   i + 1, d[i], m->mech->d_min[i], m->mech->d_max[i]);
}

/* Whether the model limits any slider's travel (else the stroke test is
 * skipped where it would cost a kernel call). */
static int has_stroke(const prru_model *m)
{
  for (int i = 0; i < m->mech->nact; i++)
    if (m->mech->d_min[i] > -INFINITY || m->mech->d_max[i] < INFINITY) return 1;
  return 0;
}

int prru_check_reachable(const prru_model *m, prru_data *d, const double q[3])
{
  if (!finite3(q)) return PRRU_EINPUT;
  KERNEL(m, ik)(m->kernel_params, q, d->d);
  /* The kernels answer NaN exactly when an acos argument leaves [-1, 1]. */
  if (!prru_finite_n(d->d, m->mech->nact)) return PRRU_EUNREACHABLE;
  return prru_stroke_actuator(m, d->d) < 0 ? PRRU_OK : PRRU_ESTROKE;
}

double prru_rcond3(const double a[9], double inv[9])
{
  double c[9];
  c[0] = a[4] * a[8] - a[5] * a[7];
  c[1] = a[2] * a[7] - a[1] * a[8];
  c[2] = a[1] * a[5] - a[2] * a[4];
  c[3] = a[5] * a[6] - a[3] * a[8];
  c[4] = a[0] * a[8] - a[2] * a[6];
  c[5] = a[2] * a[3] - a[0] * a[5];
  c[6] = a[3] * a[7] - a[4] * a[6];
  c[7] = a[1] * a[6] - a[0] * a[7];
  c[8] = a[0] * a[4] - a[1] * a[3];
  double det = a[0] * c[0] + a[1] * c[3] + a[2] * c[6];
  if (!(det != 0.0) || !isfinite(det)) return 0.0;
  double na = 0, ni = 0;
  for (int j = 0; j < 3; j++) {
    double sa = fabs(a[j]) + fabs(a[3 + j]) + fabs(a[6 + j]);
    double si = fabs(c[j]) + fabs(c[3 + j]) + fabs(c[6 + j]);
    if (sa > na) na = sa;
    if (si > ni) ni = si;
  }
  if (inv)
    for (int i = 0; i < 9; i++) inv[i] = c[i] / det;
  return fabs(det) / (na * ni);
}

double prru_length_scale(const prru_mechanism *me)
{
  double s = 0;
  for (int i = 0; i < me->nlimb; i++) s += me->l1[i];
  return s / me->nlimb;
}

/* For a symmetric M and s = 1 / L: the 1-norms of M_s = D^-1 M D^-1
 * (D = diag(L, L, 1)) and of its adjugate, *det = det M_s, and whether M
 * is positive definite (Sylvester; false for NaN). rcond_1(M_s) =
 * det / (na ni), with no division: the forward-dynamics step tests
 * na ni rcond_min <= det directly. */
static int mass_norms(const double M[9], double s, double *na, double *ni, double *det)
{
  const double s2 = s * s;
  const double a00 = M[0] * s2, a01 = M[1] * s2, a02 = M[2] * s, a11 = M[4] * s2,
               a12 = M[5] * s, a22 = M[8];
  const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22,
               c02 = a01 * a12 - a02 * a11, c11 = a00 * a22 - a02 * a02,
               c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
  *det = a00 * c00 + a01 * c01 + a02 * c02;
  const double n0 = fabs(a00) + fabs(a01) + fabs(a02), n1 = fabs(a01) + fabs(a11) + fabs(a12),
               n2 = fabs(a02) + fabs(a12) + fabs(a22);
  const double i0 = fabs(c00) + fabs(c01) + fabs(c02), i1 = fabs(c01) + fabs(c11) + fabs(c12),
               i2 = fabs(c02) + fabs(c12) + fabs(c22);
  *na = n0 > n1 ? (n0 > n2 ? n0 : n2) : (n1 > n2 ? n1 : n2);
  *ni = i0 > i1 ? (i0 > i2 ? i0 : i2) : (i1 > i2 ? i1 : i2);
  return a00 > 0 && c22 > 0 && *det > 0;
}

double prru_mass_rcond(const prru_model *m, const double M[9])
{
  double na, ni, det;
  if (!mass_norms(M, 1.0 / prru_length_scale(m->mech), &na, &ni, &det)) return 0.0;
  const double rc = det / (na * ni);
  return isfinite(rc) ? rc : 0.0;
}

double prru_stretch(const prru_model *m, const double Jd[])
{
  const double s = 1.0 / prru_length_scale(m->mech);
  double big = 0;
  for (int i = 0; i < m->mech->nact; i++) {
    const double r = (fabs(Jd[3 * i]) + fabs(Jd[3 * i + 1])) * s + fabs(Jd[3 * i + 2]);
    if (!(r <= big)) big = r; /* NaN propagates */
  }
  return big;
}

/* 1 / (|A|_1 |A^+|_1) of a full-column-rank 4 x 3 matrix A (the
 * four-actuator topology's J_d, the only redundant one), with
 * X = A^+ = (A^T A)^-1 A^T = R^-1 Q1^T from a Householder QR A = Q R
 * (never the normal equations, which would square the condition number);
 * 0 when A is rank deficient or not finite (X is then unusable). For a
 * square A this is prru_rcond3's quantity, the 1-norm being the operator
 * norm of R^4 -> R^3 for X: 1 = |X A|_1 <= |X|_1 |A|_1, so it lies in
 * (0, 1] and is unchanged by scaling A. */
static double rcond_pinv(const double A[4 * 3], double X[3 * 4])
{
  enum { N = 4 };
  double W[N][3], V[3][N], beta[3];
  PRRU_UNROLLED for (int i = 0; i < N; i++)
    PRRU_UNROLLED for (int j = 0; j < 3; j++) W[i][j] = A[3 * i + j];
  if (!prru_finite_n(A, 3 * N)) return 0.0;
  double na = 0;
  PRRU_UNROLLED for (int j = 0; j < 3; j++) {
    double s = 0;
    PRRU_UNROLLED for (int i = 0; i < N; i++) s += fabs(W[i][j]);
    if (s > na) na = s;
  }
  PRRU_UNROLLED for (int k = 0; k < 3; k++) {
    /* H_k = I - beta v v^T maps W[k.., k] to (alpha, 0, ...). Scaled by
     * the column's largest entry so that no square over- or underflows. */
    double sc = 0, nx = 0;
    PRRU_UNROLLED for (int i = k; i < N; i++)
      if (fabs(W[i][k]) > sc) sc = fabs(W[i][k]); /* W is finite: no fmax call */
    if (!(sc > 0)) return 0.0;
    PRRU_UNROLLED for (int i = 0; i < N; i++) V[k][i] = i < k ? 0.0 : W[i][k] / sc;
    PRRU_UNROLLED for (int i = k; i < N; i++) nx += V[k][i] * V[k][i];
    nx = sqrt(nx);
    double alpha = V[k][k] > 0 ? -nx : nx;
    V[k][k] -= alpha;
    double vv = 0;
    PRRU_UNROLLED for (int i = k; i < N; i++) vv += V[k][i] * V[k][i];
    beta[k] = 2.0 / vv;
    PRRU_UNROLLED for (int j = k; j < 3; j++) {
      double s = 0;
      PRRU_UNROLLED for (int i = k; i < N; i++) s += V[k][i] * W[i][j];
      s *= beta[k];
      PRRU_UNROLLED for (int i = k; i < N; i++) W[i][j] -= s * V[k][i];
    }
    W[k][k] = alpha * sc; /* the rest of column k is 0 */
  }
  /* R = W's upper 3x3; rows 0..2 of Q^T = H_2 H_1 H_0 applied to the
   * identity's columns, then X = R^-1 (Q^T)_{0..2}. (Divisions, not
   * reciprocals: the batched maps repeat this arithmetic bit for bit.) */
  PRRU_UNROLLED for (int c = 0; c < N; c++) {
    double e[N];
    PRRU_UNROLLED for (int i = 0; i < N; i++) e[i] = i == c ? 1.0 : 0.0;
    PRRU_UNROLLED for (int k = 0; k < 3; k++) {
      double s = 0;
      PRRU_UNROLLED for (int i = k; i < N; i++) s += V[k][i] * e[i];
      s *= beta[k];
      PRRU_UNROLLED for (int i = k; i < N; i++) e[i] -= s * V[k][i];
    }
    PRRU_UNROLLED for (int i = 2; i >= 0; i--) {
      double s = e[i];
      PRRU_UNROLLED for (int j = i + 1; j < 3; j++) s -= W[i][j] * X[N * j + c];
      X[N * i + c] = s / W[i][i];
    }
  }
  double nx = 0;
  PRRU_UNROLLED for (int c = 0; c < N; c++) {
    double s = fabs(X[c]) + fabs(X[N + c]) + fabs(X[2 * N + c]);
    if (!(s <= nx)) nx = s; /* NaN propagates */
  }
  if (!isfinite(nx) || !(nx > 0)) return 0.0;
  return 1.0 / (na * nx);
}

int prru_jd_regular(const double Jd[], int nact, double L, double rcond_min,
                    double Jdpinv[], double *rcond)
{
  /* J_d's rotation columns are lengths per radian, its height column is
   * dimensionless: conditioned as it stands, a model scaled by 1e-7 would
   * be singular everywhere. So the condition number is that of
   * Js = J_d diag(1/L, 1/L, 1) (rotations measured as arc lengths at the
   * model's own scale), the same for a robot of any size; and
   * J_d^+ = diag(1/L, 1/L, 1) Js^+ (for three actuators, J_d^-1 =
   * diag(1/L, 1/L, 1) Js^-1). */
  if (nact != 3 && nact != 4) {
    if (rcond) *rcond = 0.0;
    return PRRU_EINPUT;
  }
  double Js[3 * PRRU_MAX_ACT];
  for (int i = 0; i < nact; i++) {
    Js[3 * i] = Jd[3 * i] / L;
    Js[3 * i + 1] = Jd[3 * i + 1] / L;
    Js[3 * i + 2] = Jd[3 * i + 2];
  }
  double rc = nact == 3 ? prru_rcond3(Js, Jdpinv) : rcond_pinv(Js, Jdpinv);
  for (int j = 0; j < 2 * nact; j++) Jdpinv[j] /= L;
  if (rcond) *rcond = rc;
  /* rc > 0 also when rcond_min is 0: an exactly singular J_d has no inverse. */
  return rc > 0 && rc >= rcond_min ? PRRU_OK : PRRU_ESINGULAR;
}

int prru_jd_det_sign(const double Jd[], int nact)
{
  if (nact != 3) return 0;
  const double *a = Jd;
  double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
               a[2] * (a[3] * a[7] - a[4] * a[6]);
  return det > 0 ? 1 : det < 0 ? -1 : 0;
}

int prru_check_regular(const prru_model *m, prru_data *d, const double q[3], double *rcond)
{
  if (rcond) *rcond = 0.0;
  if (!finite3(q)) return PRRU_EINPUT;
  KERNEL(m, ik_jd)(m->kernel_params, q, d->d, d->Jd);
  if (!prru_finite_n(d->d, m->mech->nact)) return PRRU_EUNREACHABLE;
  if (prru_stroke_actuator(m, d->d) >= 0) return PRRU_ESTROKE;
  return prru_jd_regular(d->Jd, m->mech->nact, prru_length_scale(m->mech), m->jd_rcond_min, d->Jdpinv, rcond);
}

int prru_actuators(const prru_model *m, prru_data *d, const double q[3], double act[])
{
  int st = prru_check_reachable(m, d, q);
  if (st == PRRU_OK) memcpy(act, d->d, (size_t)m->mech->nact * sizeof(double));
  return st;
}

static int loads_finite(const prru_model *m, const prru_loads *l)
{
  return prru_finite_n(l->fd, m->mech->nact) && finite3(l->fp) && finite3(l->mp);
}

/* Why prru_eom produced non-finite output from finite inputs: q out of
 * reach; exactly on the workspace boundary (an acos argument of +-1, where
 * the velocity mapping divides by zero); or velocities and loads so large
 * that the arithmetic overflows at a regular q. */
static int classify_failure(const prru_model *m, prru_data *d, const double q[3])
{
  static const double zero[3] = {0, 0, 0}, zero_fd[PRRU_MAX_ACT] = {0};
  int st = prru_check_reachable(m, d, q);
  if (st != PRRU_OK) return st;
  double M[9], b[3];
  KERNEL(m, eom)(m->kernel_params, q, zero, zero_fd, zero, zero, M, b);
  return finite3(b) ? PRRU_EINPUT : PRRU_ESINGULAR;
}

/* Why prru_eom_solve's outputs failed the test of prru_forward_dynamics. */
PRRU_COLD static int forward_failure(const prru_model *m, prru_data *d, const double q[3],
                                     const double qd[3], const prru_loads *l,
                                     const double minors[3])
{
  if (!finite3(q) || !finite3(qd) || !loads_finite(m, l)) return PRRU_EINPUT;
  if (!finite3(d->b)) return classify_failure(m, d, q);
  if (!(minors[0] > 0) || !(minors[1] > 0) || !(minors[2] > 0)) return PRRU_ESINGULAR;
  return PRRU_EINPUT; /* b finite, M^-1 b overflowed */
}

int prru_forward_dynamics(const prru_model *m, prru_data *d, const double q[3],
                          const double qd[3], const prru_loads *l, double qdd[3])
{
  /* M qdd = b solved inside the kernel (a constant diagonal entry of M
   * eliminated first where the model has one, else M's adjugate; one
   * division, scheduled with the rest of the kernel: a separate Cholesky
   * chained three square roots and six divisions after it). Whether M is
   * positive definite is Sylvester's criterion on the nested principal
   * minors the kernel returns: otherwise qdd is not used. */
  double minors[3];
  KERNEL(m, eom_solve)(m->kernel_params, q, qd, l->fd, l->fp, l->mp, d->M, d->b, d->qdd, minors);
  const int st = prru_forward_verdict(m, d, q, qd, l, minors,
                                      KERNEL(m, unseen_finite_eom_solve)(q, qd, l->fd, l->fp, l->mp));
  if (st == PRRU_OK) memcpy(qdd, d->qdd, sizeof d->qdd);
  return st;
}

int prru_forward_verdict(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                         const prru_loads *l, const double minors[3], int unseen_finite)
{
  /* The inputs are tested through the outputs, not one by one before the
   * call: the generator proves that a NaN or an infinity in any input but
   * the few PRRU_UNSEEN_FINITE_EOM_SOLVE tests makes b or qdd non-finite
   * (with q unreachable, everything is NaN). Only on failure are all of
   * them examined, to name the cause: the statuses are those of testing
   * every input first. */
  if (!finite3(d->b) || !(minors[0] > 0) || !(minors[1] > 0) || !(minors[2] > 0) ||
      !finite3(d->qdd) || !unseen_finite)
    return forward_failure(m, d, q, qd, l, minors);
  /* The trust criterion (prru_model.mass_rcond_min): prru_mass_rcond's
   * test without its division. */
  double na, ni, det;
  if (!mass_norms(d->M, 1.0 / prru_length_scale(m->mech), &na, &ni, &det) ||
      !(na * ni * m->mass_rcond_min <= det))
    return PRRU_ESINGULAR;
  if (has_stroke(m)) { /* the kernel leaves no d: one more for the stroke */
    double act[PRRU_MAX_ACT];
    KERNEL(m, ik)(m->kernel_params, q, act);
    if (prru_stroke_actuator(m, act) >= 0) return PRRU_ESTROKE;
  }
  return PRRU_OK;
}

int prru_forward_dynamics_why(const prru_model *m, prru_data *d, const double q[3],
                              const double qd[3], const prru_loads *l, char *msg, int msglen)
{
  double qdd[3];
  const int st = prru_forward_dynamics(m, d, q, qd, l, qdd);
  const char *const f = "(%.9g, %.9g, %.9g)";
  char qs[96];
  snprintf(qs, sizeof qs, f, q[0], q[1], q[2]);
  switch (st) {
  case PRRU_OK:
    return prru_fail(msg, msglen, st, "%s", "");
  case PRRU_EUNREACHABLE:
    return prru_fail(msg, msglen, st, "q = %s is outside the workspace (no inverse kinematics)", qs);
  case PRRU_ESTROKE: {
    char why[160];
    double act[PRRU_MAX_ACT];
    KERNEL(m, ik)(m->kernel_params, q, act);
    prru_stroke_why(m, act, why, sizeof why);
    return prru_fail(msg, msglen, st, "q = %s is out_of_stroke: %s", qs, why);
  }
  case PRRU_ESINGULAR: {
    if (!finite3(d->b))
      return prru_fail(msg, msglen, st,
                       "q = %s is on the workspace boundary (an upper link horizontal)", qs);
    const double rc = prru_mass_rcond(m, d->M);
    if (rc > 0)
      return prru_fail(msg, msglen, st,
                       "q = %s is too near the workspace boundary to trust the dynamics: the "
                       "mass matrix's rcond %.3g is below mass_rcond_min %.3g (an upper link "
                       "nearly horizontal, its slider moving without bound)",
                       qs, rc, m->mass_rcond_min);
    return prru_fail(msg, msglen, st, "the mass matrix is not positive definite at q = %s", qs);
  }
  default: /* PRRU_EINPUT */
    if (!finite3(q)) return prru_fail(msg, msglen, st, "q is not finite");
    if (!finite3(qd) || !loads_finite(m, l))
      return prru_fail(msg, msglen, st, "the velocities or the loads are not finite");
    return prru_fail(msg, msglen, st,
                     "the dynamics overflow at q = %s: the velocities qd = (%.3g, %.3g, %.3g) or "
                     "the loads are too large",
                     qs, qd[0], qd[1], qd[2]);
  }
}

/* prru_jd_regular's test rc >= rcond_min, rc = 1 / (|Js|_1 |Js^-1|_1) with
 * Js = J_d diag(1/L, 1/L, 1), from J_d and J_d^-1 (Js^-1 = diag(L, L, 1)
 * J_d^-1) and without a division on the kernel's outputs: with
 * p = L |Js|_1 |Js^-1|_1 = L / rc, the test is p rcond_min <= L. False
 * where J_d^-1 is not finite (J_d singular). */
static int regular_from_inverse(const double J[9], const double inv[9], double L,
                                double rcond_min)
{
  double na = 0, ni = 0; /* na = L |Js|_1, ni = |Js^-1|_1 */
  for (int j = 0; j < 3; j++) {
    const double sa = fabs(J[j]) + fabs(J[3 + j]) + fabs(J[6 + j]);
    const double si = L * (fabs(inv[j]) + fabs(inv[3 + j])) + fabs(inv[6 + j]);
    const double ca = j < 2 ? sa : L * sa;
    if (ca > na) na = ca; /* fmax's result (NaN ignored), without its libm call */
    if (!(si <= ni)) ni = si; /* NaN propagates */
  }
  const double p = na * ni;
  return p > 0 && isfinite(p) && p * rcond_min <= L;
}

/* Inverse dynamics' half of the trust criterion (prru_model.mass_rcond_min):
 * stretch^2 mass_rcond_min <= 1, false for a NaN stretch. */
static int near_boundary_ok(const prru_model *m, const double Jd[])
{
  const double r = prru_stretch(m, Jd);
  return r * r * m->mass_rcond_min <= 1.0;
}

/* PRRU_EINPUT where an input is not finite, else st: the status of testing
 * every input first. */
PRRU_COLD static int inverse_failure(int st, const double q[3], const double qd[3],
                                     const double qdd[3], const prru_loads *l)
{
  if (!(finite3(q) && finite3(qd) && finite3(qdd) && finite3(l->fp) && finite3(l->mp)))
    return PRRU_EINPUT;
  return st;
}

int prru_inverse3_status(const prru_model *m, const prru_data *d, const double fd[3])
{
  if (!prru_finite_n(d->d, 3)) return PRRU_EUNREACHABLE;
  if (prru_stroke_actuator(m, d->d) >= 0) return PRRU_ESTROKE;
  if (!regular_from_inverse(d->Jd, d->Jdpinv, prru_length_scale(m->mech), m->jd_rcond_min))
    return PRRU_ESINGULAR;
  if (!near_boundary_ok(m, d->Jd)) return PRRU_ESINGULAR;
  return prru_finite_n(fd, 3) ? PRRU_OK : PRRU_EINPUT;
}

int prru_inverse4_status(const prru_model *m, prru_data *d, const double tau[3], double f[4])
{
  int st;
  if (!prru_finite_n(d->d, 4)) st = PRRU_EUNREACHABLE;
  else if (prru_stroke_actuator(m, d->d) >= 0) st = PRRU_ESTROKE;
  else st = prru_jd_regular(d->Jd, 4, prru_length_scale(m->mech), m->jd_rcond_min, d->Jdpinv, NULL);
  if (st == PRRU_OK && !near_boundary_ok(m, d->Jd)) st = PRRU_ESINGULAR;
  if (st != PRRU_OK) return st;
  const double *inv = d->Jdpinv;
  enum { N = 4 };
  /* fd = J_d^+T tau: row i of J_d^+T is column i of J_d^+ (3 x 4), the
   * solution of J_d^T fd = tau of least norm; non-finite where tau is. */
  for (int i = 0; i < N; i++) f[i] = inv[i] * tau[0] + inv[N + i] * tau[1] + inv[2 * N + i] * tau[2];
  return prru_finite_n(f, N) ? PRRU_OK : PRRU_EINPUT;
}

int prru_inverse_failure(int st, const double q[3], const double qd[3], const double qdd[3],
                         const prru_loads *l)
{
  return inverse_failure(st, q, qd, qdd, l);
}

int prru_inverse_dynamics(const prru_model *m, prru_data *d, const double q[3],
                          const double qd[3], const double qdd[3], const prru_loads *l,
                          double fd[])
{
  int st;
  const int na = m->mech->nact;
  double f[PRRU_MAX_ACT];
  if (na == 3) {
    /* One kernel gives d, J_d, J_d^-1 and fd = J_d^-T (M qdd - b); here
     * only prru_check_regular's test, on that J_d and J_d^-1. */
    KERNEL(m, inverse_terms)(m->kernel_params, q, qd, qdd, l->fp, l->mp, d->d, d->Jd, d->Jdpinv, f);
    st = prru_inverse3_status(m, d, f);
  } else {
    /* One kernel gives d, J_d and J_d^T fd = tau = M qdd - (G + J_T,P^T
     * fp + J_R,P^T mp - h): prru_check_regular's test on that J_d. */
    double tau[3];
    KERNEL(m, inverse_terms)(m->kernel_params, q, qd, qdd, l->fp, l->mp, d->d, d->Jd, NULL, tau);
    st = prru_inverse4_status(m, d, tau, f);
  }
  /* Inputs tested through the outputs, as in prru_forward_dynamics. */
  if (st != PRRU_OK || !KERNEL(m, unseen_finite_inverse_terms)(q, qd, qdd, l->fp, l->mp))
    return inverse_failure(st, q, qd, qdd, l);
  memcpy(fd, f, (size_t)na * sizeof *f);
  return PRRU_OK;
}

/* n from J_d (regular): n_i = (-1)^i det(J_d without row i), the
 * generalized cross product of J_d's three columns, orthogonal to each of
 * them. Column scaling (J_d diag(1/L, 1/L, 1)) scales every minor alike,
 * so the scaled J_d is used: no over- or underflow for any robot size. */
int prru_null_from_jd(const prru_model *m, const double Jd[4 * 3], double n[4])
{
  enum { N = 4 };
  const double L = prru_length_scale(m->mech);
  double Js[N][3], v[N], nn = 0;
  for (int i = 0; i < N; i++) {
    Js[i][0] = Jd[3 * i] / L;
    Js[i][1] = Jd[3 * i + 1] / L;
    Js[i][2] = Jd[3 * i + 2];
  }
  for (int i = 0; i < N; i++) {
    const double *r[3];
    for (int k = 0, j = 0; k < N; k++)
      if (k != i) r[j++] = Js[k];
    double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                 r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                 r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    v[i] = i % 2 ? -det : det;
  }
  double big = 0;
  for (int i = 0; i < N; i++) big = fmax(big, fabs(v[i]));
  if (!(big > 0) || !isfinite(big)) return PRRU_ESINGULAR;
  for (int i = 0; i < N; i++) nn += (v[i] / big) * (v[i] / big);
  nn = big * sqrt(nn);
  /* n_NACT > 0; when it is 0 to rounding, the largest component instead. */
  int k = N - 1;
  if (!(fabs(v[k]) > 64 * DBL_EPSILON * big))
    for (int i = 0; i < N; i++)
      if (fabs(v[i]) > fabs(v[k])) k = i;
  double sg = v[k] < 0 ? -1.0 : 1.0;
  for (int i = 0; i < N; i++) n[i] = sg * v[i] / nn;
  return PRRU_OK;
}

int prru_actuator_null(const prru_model *m, prru_data *d, const double q[3],
                       double n[])
{
  /* Four actuators have a one-dimensional null space; three have none. */
  if (m->mech->nact != 4) return PRRU_EINPUT;
  int st = prru_check_regular(m, d, q, NULL);
  if (st != PRRU_OK) return st;
  return prru_null_from_jd(m, d->Jd, n);
}

int prru_inverse_dynamics_preload(const prru_model *m, prru_data *d, const double q[3],
                                  const double qd[3], const double qdd[3], const prru_loads *l,
                                  double preload, double fd[])
{
  if (!isfinite(preload)) return PRRU_EINPUT;
  if (m->mech->nact != 4) {
    if (preload != 0.0) return PRRU_EINPUT;
    return prru_inverse_dynamics(m, d, q, qd, qdd, l, fd);
  }
  double f[4], n[4];
  int st = prru_inverse_dynamics(m, d, q, qd, qdd, l, f);
  if (st != PRRU_OK) return st;
  if (preload != 0.0) {
    st = prru_null_from_jd(m, d->Jd, n);
    if (st != PRRU_OK) return st;
    for (int i = 0; i < 4; i++) f[i] += preload * n[i];
    if (!prru_finite_n(f, 4)) return PRRU_EINPUT;
  }
  memcpy(fd, f, sizeof f);
  return PRRU_OK;
}

int prru_energies(const prru_model *m, const double q[3], const double qd[3], double *T,
                  double *V)
{
  if (!finite3(q) || !finite3(qd)) return PRRU_EINPUT;
  double E[2];
  KERNEL(m, energy)(m->kernel_params, q, qd, E);
  if (!isfinite(E[0]) || !isfinite(E[1])) {
    /* NaN where q is out of reach; at a reachable q only an overflow of
     * huge velocities (bad input) makes the energy infinite. */
    double act[PRRU_MAX_ACT];
    KERNEL(m, ik)(m->kernel_params, q, act);
    return isfinite(act[0]) ? PRRU_EINPUT : PRRU_EUNREACHABLE;
  }
  *T = E[0];
  *V = E[1];
  return PRRU_OK;
}
