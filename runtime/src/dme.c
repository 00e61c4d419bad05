/* Rotational DME, translational segment and w_R at one configuration; the
 * derivation and the definitions are in prru_dme.h. */
#include <math.h>
#include <string.h>

#include "prru_dme.h"

const char *prru_dme_status_name(int status)
{
  switch (status) {
  case PRRU_OK: return "ok";
  case PRRU_ESINGULAR: return "singular";
  case PRRU_EUNREACHABLE: return "unreachable";
  default: return "invalid";
  }
}

static double dot3(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* c = a b, 3x3 row-major. */
static void mul3(const double a[9], const double b[9], double c[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
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
  for (int i = 0; i < 9; i++) out->Mt[i] = out->JtR[i] = out->JtT[i] = nan;
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

  const double *jinv = d->Jdinv; /* regular: prru_check_regular inverted J_d */
  double jp[18], tmp[9];
  prru_mass(q, d->M);
  prru_platform_jacobian(q, jp);
  const double *jrp = jp, *jtp = jp + 9;

  /* Mt = Jinv^T M Jinv (symmetrized: it is symmetric in exact arithmetic). */
  mul3(d->M, jinv, tmp);
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      double s = jinv[i] * tmp[j] + jinv[3 + i] * tmp[3 + j] + jinv[6 + i] * tmp[6 + j];
      double s2 = jinv[j] * tmp[i] + jinv[3 + j] * tmp[3 + i] + jinv[6 + j] * tmp[6 + i];
      out->Mt[3 * i + j] = out->Mt[3 * j + i] = 0.5 * (s + s2);
    }
  mul3(jrp, jinv, out->JtR);
  mul3(jtp, jinv, out->JtT);

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

  /* C = Q^T JtR (rows c0, c1), S = C C^T (2x2 SPD), G = Mt C^T S^-1. */
  double c0[3], c1[3];
  for (int j = 0; j < 3; j++) {
    c0[j] = q0[0] * out->JtR[j] + q0[1] * out->JtR[3 + j] + q0[2] * out->JtR[6 + j];
    c1[j] = q1[0] * out->JtR[j] + q1[1] * out->JtR[3 + j] + q1[2] * out->JtR[6 + j];
  }
  double s00 = dot3(c0, c0), s01 = dot3(c0, c1), s11 = dot3(c1, c1);
  double det = s00 * s11 - s01 * s01;
  if (!(det > 0)) return fail(out, PRRU_ESINGULAR);
  double i00 = s11 / det, i01 = -s01 / det, i11 = s00 / det;
  double mc0[3], mc1[3], g0[3], g1[3];
  for (int i = 0; i < 3; i++) {
    mc0[i] = dot3(out->Mt + 3 * i, c0);
    mc1[i] = dot3(out->Mt + 3 * i, c1);
  }
  for (int i = 0; i < 3; i++) {
    g0[i] = mc0[i] * i00 + mc1[i] * i01;
    g1[i] = mc0[i] * i01 + mc1[i] * i11;
  }

  /* One-sided Jacobi: the rotation (c, -s; s, c) that diagonalizes
   * G^T G = [a g; g b] (Golub & Van Loan, sym.schur2) leaves G's columns
   * orthogonal, so their norms are the singular values. */
  double a = dot3(g0, g0), b = dot3(g1, g1), g = dot3(g0, g1), cs = 1.0, sn = 0.0;
  if (g != 0.0) {
    double tau = (b - a) / (2.0 * g);
    double t = (tau >= 0 ? 1.0 : -1.0) / (fabs(tau) + sqrt(1.0 + tau * tau));
    cs = 1.0 / sqrt(1.0 + t * t);
    sn = t * cs;
  }
  double h0[3], h1[3];
  for (int i = 0; i < 3; i++) {
    h0[i] = cs * g0[i] - sn * g1[i];
    h1[i] = sn * g0[i] + cs * g1[i];
  }
  double sa = sqrt(dot3(h0, h0)), sb = sqrt(dot3(h1, h1));
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
  double cn[3] = {0, 0, 0};
  for (int j = 0; j < 3; j++) {
    for (int i = 0; i < 3; i++) {
      double x = out->JtT[3 * i + j];
      cn[j] += x * x;
      /* (Mt JtT^T)_{ij} = sum_l Mt_il JtT_jl */
      double y = out->Mt[3 * i] * out->JtT[3 * j] + out->Mt[3 * i + 1] * out->JtT[3 * j + 1] +
                 out->Mt[3 * i + 2] * out->JtT[3 * j + 2];
      mf2 += y * y;
    }
    f2 += cn[j];
    if (cn[j] > cn[kt]) kt = j;
  }
  if (!(f2 > 0) || !(mf2 > 0)) return fail(out, PRRU_ESINGULAR);
  out->sigma_T = sqrt(mf2) / f2;
  out->half_length_T = 1.0 / out->sigma_T;
  double nk = sqrt(cn[kt]);
  for (int i = 0; i < 3; i++) out->dir_T[i] = out->JtT[3 * i + kt] / nk;
  canonical_sign(out->dir_T);

  if (!isfinite(out->w_R) || !isfinite(out->sigma_T)) return fail(out, PRRU_ESINGULAR);
  out->status = PRRU_OK;
  return PRRU_OK;
}
