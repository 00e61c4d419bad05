/* Paper eqs. 1-13 by hand: poses, J_R, J_T, delta, mu of every body, for
 * the per-limb geometry and centres of mass of spec section 11, and the
 * fourth limb of spec section 12.
 *
 * Every limb is a function of one scalar xi of q plus the height q3 (which
 * enters every position as + q3 e3): xi = q1 for limbs 1, 2 (everything
 * lives in the plane x = 0 and turns about e1), xi = gamma(q1, q2) for
 * limb 3 and its mirror image limb 4 (plane y = 0, axes e2; limb3() below
 * derives both). A body quantity f(xi) then has
 *   df/dq_j = f_x dxi/dq_j,   quadratic part of f'' = f_xx xi'^2 + f_x xi'',
 * where xi'' here is only the qd-quadratic part qd^T (d2xi/dq2) qd. Each
 * closed-form scalar is carried with its first two xi-derivatives.
 *
 * A limb body turns by an angle ang(xi) about a fixed axis e (e1 or e2), so
 * its centre of mass origin(xi) + Rot(e, ang) com moves, beyond its frame
 * origin, by the offset r = Rot(e, ang) com whose xi-derivatives follow
 * from dRot/dang = [e]x Rot: r_x = ang_x e x r and
 * r_xx = ang_xx e x r + ang_x^2 e x (e x r). The platform turns about two
 * axes and is done with partial derivatives in q1, q2 instead (platform()).
 * Sliders do not turn (R = I): their com is a constant offset from A_i. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "ref_internal.h"

/* A scalar of the limb and its first two derivatives in xi. */
typedef struct { double v, x, xx; } scal;

/* The limb's scalar xi: gradient in q, rate xi' = g.qd, and the
 * qd-quadratic part of xi''. */
typedef struct { double g[3], rate, quad; } chain;

enum { AX_X, AX_Y };
static const double E[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

static void cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static void matvec(const double R[9], const double x[3], double y[3])
{
  for (int i = 0; i < 3; i++) y[i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}

/* Rx(t) or Ry(t), the exponential of t [e]x. */
static void rot(int axis, double t, double R[9])
{
  const double c = cos(t), s = sin(t);
  const double Rx[9] = {1, 0, 0, 0, c, -s, 0, s, c}, Ry[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  memcpy(R, axis == AX_X ? Rx : Ry, sizeof Rx);
}

/* theta = acos(r) and sin(theta) = sqrt(1 - r^2) with their xi-derivatives:
 * from sin(theta) theta_x = -r_x and (sin theta)_x = cos(theta) theta_x. */
static int acos_chain(scal r, scal *theta, scal *sn)
{
  if (!(fabs(r.v) <= 1.0)) return GSL_EDOM;
  sn->v = sqrt(1.0 - r.v * r.v);
  theta->v = acos(r.v);
  theta->x = -r.x / sn->v;
  theta->xx = -(r.xx + r.v * theta->x * theta->x) / sn->v;
  sn->x = r.v * theta->x;
  sn->xx = r.x * theta->x + r.v * theta->xx;
  return GSL_SUCCESS;
}

/* Body centre P(xi) (+ q3 e3, already in P): J_T and mu by the chain rule. */
static void set_translation(ref_kin *k, int b, const double P[3], const double Px[3],
                            const double Pxx[3], const chain *c)
{
  for (int i = 0; i < 3; i++) {
    k->p[b][i] = P[i];
    for (int j = 0; j < 3; j++) k->JT[b][3 * i + j] = Px[i] * c->g[j] + (i == 2 && j == 2 ? 1.0 : 0.0);
    k->mu[b][i] = Pxx[i] * c->rate * c->rate + Px[i] * c->quad;
  }
}

/* Body turning by the angle ang(xi) about a fixed axis: omega = ang' axis. */
static void set_rotation(ref_kin *k, int b, scal ang, const double axis[3], const chain *c)
{
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) k->JR[b][3 * i + j] = ang.x * c->g[j] * axis[i];
    k->delta[b][i] = (ang.xx * c->rate * c->rate + ang.x * c->quad) * axis[i];
  }
}

/* A limb body: frame origin O(xi) with its xi-derivatives, rotation
 * Rot(axis, ang(xi)), centre of mass O + Rot com (see the top comment). */
static void set_body(ref_kin *k, const prru_ref_params *p, int b, const double O[3],
                     const double Ox[3], const double Oxx[3], scal ang, int axis, const chain *c)
{
  const double *e = E[axis];
  double r[3], t[3], tt[3], P[3], Px[3], Pxx[3];
  rot(axis, ang.v, k->R[b]);
  matvec(k->R[b], p->com[b], r);
  cross(e, r, t);
  cross(e, t, tt);
  for (int i = 0; i < 3; i++) {
    P[i] = O[i] + r[i];
    Px[i] = Ox[i] + ang.x * t[i];
    Pxx[i] = Oxx[i] + ang.xx * t[i] + ang.x * ang.x * tt[i];
  }
  set_translation(k, b, P, Px, Pxx, c);
  set_rotation(k, b, ang, e, c);
}

/* The actuator of limb i from d(xi) (d_i depends on q3 as + q3): row i of
 * J_d, and Jd' qd = the qd-quadratic part of d_i''. */
static void set_actuator(ref_kin *k, int i, scal d, const chain *c)
{
  k->d[i] = d.v;
  for (int j = 0; j < 3; j++) k->Jd[3 * i + j] = d.x * c->g[j] + (j == 2 ? 1.0 : 0.0);
  k->ddb[i] = d.xx * c->rate * c->rate + d.x * c->quad;
}

/* Platform (eqs. 1-2): R_P = Rx(q1) Ry(q2), omega = q1' e1 + q2' u with
 * u = Rx(q1) e2, whose derivative along the motion is q1' q2' e1 x u.
 * Its centre of mass is O' + r, r = R_P com: dRx/dq1 = [e1]x Rx gives
 * r_1 = e1 x r, and Rx [e2]x Ry com = [u]x Rx Ry com gives r_2 = u x r; once
 * more, r_11 = e1 x r_1, r_12 = e1 x r_2 (= d/dq2 of e1 x r) and
 * r_22 = u x r_2 (u does not depend on q2); mu = sum_jk r_jk qd_j qd_k. */
static void platform(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k)
{
  const double c1 = cos(q[0]), s1 = sin(q[0]);
  const double u[3] = {0, c1, s1};
  double Rx[9], Ry[9], r[3], r1[3], r2[3], r11[3], r12[3], r22[3];
  rot(AX_X, q[0], Rx);
  rot(AX_Y, q[1], Ry);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      k->R[REF_P][3 * i + j] = Rx[3 * i] * Ry[j] + Rx[3 * i + 1] * Ry[3 + j] + Rx[3 * i + 2] * Ry[6 + j];
  matvec(k->R[REF_P], p->com[REF_P], r);
  cross(E[0], r, r1);
  cross(u, r, r2);
  cross(E[0], r1, r11);
  cross(E[0], r2, r12);
  cross(u, r2, r22);
  for (int i = 0; i < 3; i++) {
    k->p[REF_P][i] = r[i] + (i == 2 ? q[2] : 0.0);
    k->JT[REF_P][3 * i] = r1[i];
    k->JT[REF_P][3 * i + 1] = r2[i];
    k->JT[REF_P][3 * i + 2] = i == 2 ? 1.0 : 0.0;
    k->JR[REF_P][3 * i] = E[0][i];
    k->JR[REF_P][3 * i + 1] = u[i];
  }
  /* The tool point O' = (0, 0, q3), where the platform load acts. */
  k->JTO[8] = 1.0;
  if (qd) {
    k->delta[REF_P][1] = -s1 * qd[0] * qd[1];
    k->delta[REF_P][2] = c1 * qd[0] * qd[1];
    for (int i = 0; i < 3; i++)
      k->mu[REF_P][i] = r11[i] * qd[0] * qd[0] + 2.0 * r12[i] * qd[0] * qd[1] + r22[i] * qd[1] * qd[1];
  }
}

/* Limbs 1 and 2 (eqs. 3-4, 6-11), s = -1, +1, with the limb's own b, l1,
 * l2, a; xi = q1. With e = a + l2, B_i = (0, s e cos q1, q3 + s e sin q1)
 * and alpha_i = s beta with beta = acos((b - e cos q1)/l1) (the spec's
 * s (y_A - y_B)/l1 with y_A = s b), so d_i = z_Bi + l1 sin(beta). */
static int limb12(const prru_ref_params *p, const double q[3], int limb, const chain *c, ref_kin *k)
{
  const double s = limb == 0 ? -1.0 : 1.0;
  const double b = p->b[limb], l1 = p->l1[limb], l2 = p->l2[limb], a = p->a[limb];
  const double c1 = cos(q[0]), s1 = sin(q[0]), q3 = q[2];
  const double e = a + l2, kl = a + 0.5 * l2;
  const int n = k->n.nlimb, L = REF_L(n, limb), U = REF_U(n, limb), S = REF_S(n, limb);

  double C[3] = {0, s * a * c1, q3 + s * a * s1};
  double B[3] = {0, s * e * c1, q3 + s * e * s1};
  memcpy(k->C[limb], C, sizeof C);
  memcpy(k->B[limb], B, sizeof B);

  /* Lower link: R = Rx(q1), frame origin halfway along s l2 from C_i. */
  double OL[3] = {0, s * kl * c1, q3 + s * kl * s1};
  double OLx[3] = {0, -s * kl * s1, s * kl * c1};
  double OLxx[3] = {0, -s * kl * c1, -s * kl * s1};
  set_body(k, p, L, OL, OLx, OLxx, (scal){q[0], 1.0, 0.0}, AX_X, c);

  scal r = {(b - e * c1) / l1, e * s1 / l1, e * c1 / l1}, beta, sb;
  if (acos_chain(r, &beta, &sb) != GSL_SUCCESS) return GSL_EDOM;
  scal alpha = {s * beta.v, s * beta.x, s * beta.xx};
  scal zB = {B[2], s * e * c1, -s * e * s1};
  scal d = {zB.v + l1 * sb.v, zB.x + l1 * sb.x, zB.xx + l1 * sb.xx};

  /* Upper link: R = Rx(alpha_i), frame origin (A_i + B_i)/2. */
  double OU[3] = {0, 0.5 * s * (b + e * c1), zB.v + 0.5 * l1 * sb.v};
  double OUx[3] = {0, -0.5 * s * e * s1, zB.x + 0.5 * l1 * sb.x};
  double OUxx[3] = {0, -0.5 * s * e * c1, zB.xx + 0.5 * l1 * sb.xx};
  set_body(k, p, U, OU, OUx, OUxx, alpha, AX_X, c);

  /* Slider: translates along e3 only (R = I), frame origin A_i. */
  double OS[3] = {0, s * b, d.v}, OSx[3] = {0, 0, d.x}, OSxx[3] = {0, 0, d.xx};
  set_body(k, p, S, OS, OSx, OSxx, (scal){0.0, 0.0, 0.0}, AX_X, c);
  memcpy(k->A[limb], OS, sizeof OS);
  set_actuator(k, limb, d, c);
  return GSL_SUCCESS;
}

/* gamma = atan2(sin q2, cos q1 cos q2) with gradient and Hessian in (q1, q2);
 * W = sin^2 q2 + cos^2 q1 cos^2 q2 is the squared norm of atan2's argument. */
static double gamma_chain(const double q[3], const double *qd, chain *c)
{
  const double c1 = cos(q[0]), s1 = sin(q[0]), c2 = cos(q[1]), s2 = sin(q[1]);
  const double W = s2 * s2 + c1 * c1 * c2 * c2, W2 = W * W;
  c->g[0] = s1 * s2 * c2 / W;
  c->g[1] = c1 / W;
  c->g[2] = 0.0;
  const double g11 = s2 * c2 * c1 * (W + 2.0 * s1 * s1 * c2 * c2) / W2;
  const double g12 = s1 * (2.0 * c1 * c1 * c2 * c2 - W) / W2;
  const double g22 = -2.0 * c1 * s1 * s1 * s2 * c2 / W2;
  if (qd) {
    c->rate = c->g[0] * qd[0] + c->g[1] * qd[1];
    c->quad = g11 * qd[0] * qd[0] + 2.0 * g12 * qd[0] * qd[1] + g22 * qd[1] * qd[1];
  } else {
    c->rate = c->quad = 0.0;
  }
  return atan2(s2, c1 * c2);
}

/* Limb 3 (eqs. 5, 12-13) and limb 4 (spec section 12), each with its own
 * b, l1, l2; xi = gamma for both. Both lower links turn with R_L = Ry(gamma)
 * and x3 = R_L e1 = (cos gamma, 0, -sin gamma), limb 3's reaching out along
 * +x3 to its rail at x = +b, limb 4's along x4 = -x3 to its rail at x = -b.
 * With s = +1 (limb 3) or -1 (limb 4) limb 4 is limb 3 reflected in the
 * plane x = 0 (x -> -x, q2 -> -q2, gamma -> -gamma):
 *   B = O' + s l2 x3 = (s l2 cos gamma, 0, q3 - s l2 sin gamma),
 *   r = (x_B - s b) / l1 = s (l2 cos gamma - b) / l1,  alpha = acos(r),
 *   d = z_B + l1 sin(alpha),  A = (s b, 0, d).
 * alpha carries no sign: B - A = l1 (r, 0, -sin alpha) = l1 Ry(alpha) e1 in
 * both limbs, so R_U = Ry(alpha) and the upper link's local x runs from A
 * to B in both. Every x-coordinate and every xi-derivative of a point in
 * the limb (its scalar factors cos and sin of gamma and their derivatives)
 * takes the factor s; the bodies' angles gamma and alpha do not. Their U
 * joint centre is O' itself (spec sections 4, 12): a[2], a[3] play no part. */
static int limb3(const prru_ref_params *p, const double q[3], int limb, double s, const chain *c,
                 ref_kin *k)
{
  const double gam = k->gamma, cg = cos(gam), sg = sin(gam), q3 = q[2];
  const double b = p->b[limb], l1 = p->l1[limb], l2 = p->l2[limb], kl = 0.5 * l2;
  const int n = k->n.nlimb, L = REF_L(n, limb), U = REF_U(n, limb), S = REF_S(n, limb);

  double C[3] = {0, 0, q3}, B[3] = {s * l2 * cg, 0, q3 - s * l2 * sg};
  memcpy(k->C[limb], C, sizeof C);
  memcpy(k->B[limb], B, sizeof B);

  /* Lower link: R = Ry(gamma), frame origin O' + s (l2/2) x3. */
  double OL[3] = {s * kl * cg, 0, q3 - s * kl * sg};
  double OLx[3] = {-s * kl * sg, 0, -s * kl * cg};
  double OLxx[3] = {-s * kl * cg, 0, s * kl * sg};
  set_body(k, p, L, OL, OLx, OLxx, (scal){gam, 1.0, 0.0}, AX_Y, c);

  scal r = {s * (l2 * cg - b) / l1, -s * l2 * sg / l1, -s * l2 * cg / l1}, alpha, sa;
  if (acos_chain(r, &alpha, &sa) != GSL_SUCCESS) return GSL_EDOM;
  scal zB = {B[2], -s * l2 * cg, s * l2 * sg};
  scal d = {zB.v + l1 * sa.v, zB.x + l1 * sa.x, zB.xx + l1 * sa.xx};

  /* Upper link: R = Ry(alpha), frame origin (A + B)/2. */
  double OU[3] = {0.5 * s * (b + l2 * cg), 0, zB.v + 0.5 * l1 * sa.v};
  double OUx[3] = {-0.5 * s * l2 * sg, 0, zB.x + 0.5 * l1 * sa.x};
  double OUxx[3] = {-0.5 * s * l2 * cg, 0, zB.xx + 0.5 * l1 * sa.xx};
  set_body(k, p, U, OU, OUx, OUxx, alpha, AX_Y, c);

  /* Slider: translates along e3 only (R = I), frame origin A. */
  double OS[3] = {s * b, 0, d.v}, OSx[3] = {0, 0, d.x}, OSxx[3] = {0, 0, d.xx};
  set_body(k, p, S, OS, OSx, OSxx, (scal){0.0, 0.0, 0.0}, AX_Y, c);
  memcpy(k->A[limb], OS, sizeof OS);
  set_actuator(k, limb, d, c);
  return GSL_SUCCESS;
}

int ref_kinematics(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k)
{
  memset(k, 0, sizeof *k);
  k->n = ref_size_of(p);
  if (!k->n.nlimb) return GSL_EINVAL;
  if (!(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]))) return GSL_EDOM;
  chain c12 = {{1.0, 0.0, 0.0}, qd ? qd[0] : 0.0, 0.0}, c34; /* xi = q1 exactly; xi = gamma */
  k->gamma = gamma_chain(q, qd, &c34);
  platform(p, q, qd, k);
  if (limb12(p, q, 0, &c12, k) || limb12(p, q, 1, &c12, k) || limb3(p, q, 2, +1.0, &c34, k))
    return GSL_EDOM;
  for (int l = 3; l < k->n.nlimb; l++)
    if (limb3(p, q, l, -1.0, &c34, k)) return GSL_EDOM;
  if (qd) {
    for (int b = 0; b < k->n.nb; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
          k->omega[b][i] += k->JR[b][3 * i + j] * qd[j];
          k->v[b][i] += k->JT[b][3 * i + j] * qd[j];
        }
    for (int i = 0; i < k->n.na; i++)
      for (int j = 0; j < 3; j++) k->dd[i] += k->Jd[3 * i + j] * qd[j];
  }
  return GSL_SUCCESS;
}

static void fill_nan(double *x, int n)
{
  for (int i = 0; i < n; i++) x[i] = NAN;
}

int prru_ref_ik(const prru_ref_params *p, const double q[3], double d[])
{
  ref_kin k;
  int st = ref_kinematics(p, q, NULL, &k);
  if (st) { fill_nan(d, k.n.na); return st; }
  memcpy(d, k.d, k.n.na * sizeof *d);
  return GSL_SUCCESS;
}

int prru_ref_jd(const prru_ref_params *p, const double q[3], double Jd[])
{
  ref_kin k;
  int st = ref_kinematics(p, q, NULL, &k);
  if (st) { fill_nan(Jd, 3 * k.n.na); return st; }
  memcpy(Jd, k.Jd, 3 * k.n.na * sizeof *Jd);
  return GSL_SUCCESS;
}

int prru_ref_poses(const prru_ref_params *p, const double q[3], double R[], double pos[])
{
  ref_kin k;
  int st = ref_kinematics(p, q, NULL, &k);
  if (st) { fill_nan(R, 9 * k.n.nb); fill_nan(pos, 3 * k.n.nb); return st; }
  memcpy(R, k.R, k.n.nb * sizeof k.R[0]);
  memcpy(pos, k.p, k.n.nb * sizeof k.p[0]);
  return GSL_SUCCESS;
}

/* d' = J_d qd, and d'' = J_d qdd + Jd' qd from the chain rule on d_i(xi)
 * (set_actuator): d_i'' = d_xx xi'^2 + d_x xi'' with xi'' = g.qdd + quad. */
int prru_ref_actuator_rates(const prru_ref_params *p, const double q[3], const double qd[3],
                            double dd[], double ddb[])
{
  ref_kin k;
  int st = ref_kinematics(p, q, qd, &k);
  if (st) { fill_nan(dd, k.n.na); fill_nan(ddb, k.n.na); return st; }
  memcpy(dd, k.dd, k.n.na * sizeof *dd);
  memcpy(ddb, k.ddb, k.n.na * sizeof *ddb);
  return GSL_SUCCESS;
}
