/* Rotational DME, translational segment and w_R at one configuration; the
 * derivation and the definitions are in prru_dme.h. */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "prru_dme.h"

const char *prru_dme_status_name(int status)
{
  switch (status) {
  case PRRU_OK: return "ok";
  case PRRU_ESINGULAR: return "singular";
  case PRRU_EUNREACHABLE: return "unreachable";
  case PRRU_ESTROKE: return "out_of_stroke";
  case PRRU_DME_OTHER_MODE: return "other_mode";
  default: return "invalid";
  }
}

int prru_assembly_mode(const double d[], const double Jd[], int nact)
{
  for (int i = 0; i < nact; i++)
    if (!isfinite(d[i])) return 0;
  return prru_jd_det_sign(Jd, nact);
}

int prru_jd_other_mode(const double Jd[], int nact, int home)
{
  return home != 0 && prru_jd_det_sign(Jd, nact) != home;
}

int prru_mode_status(int regular_status, const double Jd[], int nact, int home)
{
  return regular_status == PRRU_OK && prru_jd_other_mode(Jd, nact, home) ? PRRU_DME_OTHER_MODE
                                                                         : regular_status;
}

/* With N actuators J_d^+ is 3 x N, Mt N x N, JtR and JtT 3 x N. Every
 * sum below runs left to right from its first term, as the three-term
 * expressions it generalizes did, so three actuators give the same bits. */

static double dot3(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double dotn(int N, const double *a, const double *b)
{
  double s = a[0] * b[0];
  for (int i = 1; i < N; i++) s += a[i] * b[i];
  return s;
}

/* c = a b, a 3x3, b 3xN, row-major. */
static void mul3n(int N, const double a[9], const double *b, double *c)
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < N; j++)
      c[N * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[N + j] + a[3 * i + 2] * b[2 * N + j];
}

/* Sign convention for directions: largest-magnitude component positive, so
 * that a direction is reported the same way however it was computed. */
static void canonical_sign(double v[3])
{
  int k = 0;
  for (int i = 1; i < 3; i++)
    if (fabs(v[i]) > fabs(v[k])) k = i;
  if (v[k] < 0)
    for (int i = 0; i < 3; i++) v[i] = -v[i];
}

static void set_undefined(prru_dme *out)
{
  const double nan = NAN;
  out->w_R = out->sigma_T = out->half_length_T = nan;
  for (int i = 0; i < 2; i++) {
    out->sigma[i] = out->semi_axis[i] = nan;
    out->axis_dir[i][0] = out->axis_dir[i][1] = out->axis_dir[i][2] = nan;
  }
  for (int i = 0; i < 3; i++) out->dir_T[i] = nan;
  for (int i = 0; i < PRRU_MAX_ACT * PRRU_MAX_ACT; i++) out->Mt[i] = nan;
  for (int i = 0; i < 3 * PRRU_MAX_ACT; i++) out->JtR[i] = out->JtT[i] = nan;
}

static int fail(prru_dme *out, int status)
{
  out->status = status;
  set_undefined(out);
  return status;
}

int prru_dme_eval(const prru_model *m, prru_data *d, const double q[3], prru_dme *out)
{
  out->jd_rcond = 0.0;
  int st = prru_check_regular(m, d, q, &out->jd_rcond);
  if (st != PRRU_OK) return fail(out, st);

  /* regular: prru_check_regular left J_d^+ (J_d^-1 for three actuators) */
  double jp[18];
  KERNEL(m, mass)(m->kernel_params, q, d->M);
  KERNEL(m, platform_jacobian)(m->kernel_params, q, jp);
  return prru_dme_from(d->M, d->Jdpinv, m->mech->nact, jp, out);
}

int prru_dme_from(const double M[9], const double Jdpinv[], int nact, const double JP[18],
                  prru_dme *out)
{
  if (nact != 3 && nact != 4) return fail(out, PRRU_EINPUT);
  const int N = nact == 3 ? 3 : 4; /* (what GCC can tell is at least 1) */
  const double *jinv = Jdpinv;
  double tmp[3 * PRRU_MAX_ACT];
  const double *jrp = JP, *jtp = JP + 9;

  /* Mt = J^+T M J^+ (symmetrized: it is symmetric in exact arithmetic). */
  mul3n(N, M, jinv, tmp);
  for (int i = 0; i < N; i++)
    for (int j = i; j < N; j++) {
      double s = jinv[i] * tmp[j] + jinv[N + i] * tmp[N + j] + jinv[2 * N + i] * tmp[2 * N + j];
      double s2 = jinv[j] * tmp[i] + jinv[N + j] * tmp[N + i] + jinv[2 * N + j] * tmp[2 * N + i];
      out->Mt[N * i + j] = out->Mt[N * j + i] = 0.5 * (s + s2);
    }
  mul3n(N, jrp, jinv, out->JtR);
  mul3n(N, jtp, jinv, out->JtT);

  /* Orthonormal basis Q of range(J_R,P): the column of largest norm, then
   * the largest remainder of the others after removing it. */
  double col[3][3];
  int k0 = 0;
  for (int j = 0; j < 3; j++) {
    col[j][0] = jrp[j];
    col[j][1] = jrp[3 + j];
    col[j][2] = jrp[6 + j];
  }
  for (int j = 1; j < 3; j++)
    if (dot3(col[j], col[j]) > dot3(col[k0], col[k0])) k0 = j;
  double q0[3], q1[3], n0 = sqrt(dot3(col[k0], col[k0]));
  if (!(n0 > 0)) return fail(out, PRRU_ESINGULAR);
  for (int i = 0; i < 3; i++) q0[i] = col[k0][i] / n0;
  double best = -1;
  for (int j = 0; j < 3; j++) {
    if (j == k0) continue;
    double r[3], c = dot3(col[j], q0);
    for (int i = 0; i < 3; i++) r[i] = col[j][i] - c * q0[i];
    double nr = dot3(r, r);
    if (nr > best) {
      best = nr;
      memcpy(q1, r, sizeof r);
    }
  }
  best = sqrt(best);
  if (!(best > 0)) return fail(out, PRRU_ESINGULAR);
  for (int i = 0; i < 3; i++) q1[i] /= best;

  /* C = Q^T JtR (rows c0, c1: 2 x N), S = C C^T (2x2 SPD),
   * G = Mt C^T S^-1 (N x 2, columns g0, g1). */
  double c0[PRRU_MAX_ACT], c1[PRRU_MAX_ACT];
  for (int j = 0; j < N; j++) {
    c0[j] = q0[0] * out->JtR[j] + q0[1] * out->JtR[N + j] + q0[2] * out->JtR[2 * N + j];
    c1[j] = q1[0] * out->JtR[j] + q1[1] * out->JtR[N + j] + q1[2] * out->JtR[2 * N + j];
  }
  double s00 = dotn(N, c0, c0), s01 = dotn(N, c0, c1), s11 = dotn(N, c1, c1);
  double det = s00 * s11 - s01 * s01;
  if (!(det > 0)) return fail(out, PRRU_ESINGULAR);
  double i00 = s11 / det, i01 = -s01 / det, i11 = s00 / det;
  double mc0[PRRU_MAX_ACT], mc1[PRRU_MAX_ACT], g0[PRRU_MAX_ACT], g1[PRRU_MAX_ACT];
  for (int i = 0; i < N; i++) {
    mc0[i] = dotn(N, out->Mt + N * i, c0);
    mc1[i] = dotn(N, out->Mt + N * i, c1);
  }
  for (int i = 0; i < N; i++) {
    g0[i] = mc0[i] * i00 + mc1[i] * i01;
    g1[i] = mc0[i] * i01 + mc1[i] * i11;
  }

  /* One-sided Jacobi: the rotation (c, -s; s, c) that diagonalizes
   * G^T G = [a g; g b] (Golub & Van Loan, sym.schur2) leaves G's columns
   * orthogonal, so their norms are the singular values. */
  double a = dotn(N, g0, g0), b = dotn(N, g1, g1), g = dotn(N, g0, g1), cs = 1.0, sn = 0.0;
  if (g != 0.0) {
    double tau = (b - a) / (2.0 * g);
    double t = (tau >= 0 ? 1.0 : -1.0) / (fabs(tau) + sqrt(1.0 + tau * tau));
    cs = 1.0 / sqrt(1.0 + t * t);
    sn = t * cs;
  }
  double h0[PRRU_MAX_ACT], h1[PRRU_MAX_ACT];
  for (int i = 0; i < N; i++) {
    h0[i] = cs * g0[i] - sn * g1[i];
    h1[i] = sn * g0[i] + cs * g1[i];
  }
  double sa = sqrt(dotn(N, h0, h0)), sb = sqrt(dotn(N, h1, h1));
  /* Right singular vectors in the (q0, q1) coordinates: (cs, -sn), (sn, cs). */
  double va[3], vb[3];
  for (int i = 0; i < 3; i++) {
    va[i] = cs * q0[i] - sn * q1[i];
    vb[i] = sn * q0[i] + cs * q1[i];
  }
  if (sb > sa) {
    double t = sa;
    sa = sb;
    sb = t;
    double tv[3];
    memcpy(tv, va, sizeof tv);
    memcpy(va, vb, sizeof tv);
    memcpy(vb, tv, sizeof tv);
  }
  if (!(sb > 0) || !isfinite(sa)) return fail(out, PRRU_ESINGULAR);
  out->sigma[0] = sa;
  out->sigma[1] = sb;
  out->semi_axis[0] = 1.0 / sa;
  out->semi_axis[1] = 1.0 / sb;
  out->w_R = sa / sb;
  canonical_sign(va);
  canonical_sign(vb);
  memcpy(out->axis_dir[0], va, sizeof va);
  memcpy(out->axis_dir[1], vb, sizeof vb);

  /* Rank-1 JtT = s u r^T: JtT^+ = JtT^T / |JtT|_F^2, so the only non-zero
   * singular value of Mt JtT^+ is |Mt JtT^T|_F / |JtT|_F^2, and the segment
   * runs along u, the direction of JtT's largest column. */
  double f2 = 0, mf2 = 0;
  int kt = 0;
  double cn[PRRU_MAX_ACT];
  for (int j = 0; j < N; j++) { /* cn[j] = |column j of JtT|^2 */
    cn[j] = 0;
    for (int i = 0; i < 3; i++) {
      double x = out->JtT[N * i + j];
      cn[j] += x * x;
    }
    f2 += cn[j];
    if (cn[j] > cn[kt]) kt = j;
  }
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < N; i++) {
      /* (Mt JtT^T)_{ij} = sum_l Mt_il JtT_jl */
      double y = dotn(N, out->Mt + N * i, out->JtT + N * j);
      mf2 += y * y;
    }
  if (!(f2 > 0) || !(mf2 > 0)) return fail(out, PRRU_ESINGULAR);
  out->sigma_T = sqrt(mf2) / f2;
  out->half_length_T = 1.0 / out->sigma_T;
  double nk = sqrt(cn[kt]);
  for (int i = 0; i < 3; i++) out->dir_T[i] = out->JtT[N * i + kt] / nk;
  canonical_sign(out->dir_T);

  if (!isfinite(out->w_R) || !isfinite(out->sigma_T)) return fail(out, PRRU_ESINGULAR);
  out->status = PRRU_OK;
  return PRRU_OK;
}
