/* Paper eqs. 1-13 by hand: poses, J_R, J_T, delta, mu of every body.
 *
 * Every limb is a function of one scalar xi of q plus the height q3 (which
 * enters every position as + q3 e3): xi = q1 for limbs 1, 2 (everything
 * lives in the plane x = 0 and turns about e1), xi = gamma(q1, q2) for
 * limb 3 (plane y = 0, axes e2). A body quantity f(xi) then has
 *   df/dq_j = f_x dxi/dq_j,   quadratic part of f'' = f_xx xi'^2 + f_x xi'',
 * where xi'' here is only the qd-quadratic part qd^T (d2xi/dq2) qd. Each
 * closed-form scalar is carried with its first two xi-derivatives. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_mechanism.h"
#include "ref_internal.h"

void prru_ref_params_default(prru_ref_params *p)
{
  const prru_mechanism *me = &prru_mech;
  p->g = -me->gravity[2];
  p->b12 = me->b[0];
  p->b3 = me->b[2];
  p->l1 = me->l1[0];
  p->l2 = me->l2[0];
  p->a = me->a[0];
  for (int b = 0; b < PRRU_REF_NBODY; b++) {
    p->mass[b] = me->mass[b];
    for (int i = 0; i < 3; i++) p->inertia[b][i] = me->inertia[b][4 * i];
  }
}

/* A scalar of the limb and its first two derivatives in xi. */
typedef struct { double v, x, xx; } scal;

/* The limb's scalar xi: gradient in q, rate xi' = g.qd, and the
 * qd-quadratic part of xi''. */
typedef struct { double g[3], rate, quad; } chain;

static const double E1[3] = {1, 0, 0}, E2[3] = {0, 1, 0};

static void rot_x(double t, double R[9])
{
  double c = cos(t), s = sin(t);
  double M[9] = {1, 0, 0, 0, c, -s, 0, s, c};
  memcpy(R, M, sizeof M);
}

static void rot_y(double t, double R[9])
{
  double c = cos(t), s = sin(t);
  double M[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  memcpy(R, M, sizeof M);
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

/* Platform (eqs. 1-2): R_P = Rx(q1) Ry(q2), omega = q1' e1 + q2' Rx(q1) e2,
 * whose derivative along the motion is q1' q2' e1 x Rx(q1) e2. */
static void platform(const double q[3], const double *qd, ref_kin *k)
{
  double c1 = cos(q[0]), s1 = sin(q[0]), Rx[9], Ry[9];
  rot_x(q[0], Rx);
  rot_y(q[1], Ry);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      k->R[REF_P][3 * i + j] = Rx[3 * i] * Ry[j] + Rx[3 * i + 1] * Ry[3 + j] + Rx[3 * i + 2] * Ry[6 + j];
  k->p[REF_P][2] = q[2];
  double JR[9] = {1, 0, 0, 0, c1, 0, 0, s1, 0};
  memcpy(k->JR[REF_P], JR, sizeof JR);
  k->JT[REF_P][8] = 1.0;
  if (qd) {
    k->delta[REF_P][1] = -s1 * qd[0] * qd[1];
    k->delta[REF_P][2] = c1 * qd[0] * qd[1];
  }
}

/* Limbs 1 and 2 (eqs. 3-4, 6-11), s = -1, +1; xi = q1. With e = a + l2,
 * B_i = (0, s e cos q1, q3 + s e sin q1) and alpha_i = s beta with
 * beta = acos((b12 - e cos q1)/l1), so d_i = z_Bi + l1 sin(beta). */
static int limb12(const prru_ref_params *p, const double q[3], int limb, const chain *c, ref_kin *k)
{
  const double s = limb == 0 ? -1.0 : 1.0;
  const double c1 = cos(q[0]), s1 = sin(q[0]), q3 = q[2];
  const double e = p->a + p->l2, kl = p->a + 0.5 * p->l2;
  const int L = REF_L1 + limb, U = REF_U1 + limb, S = REF_S1 + limb;

  double C[3] = {0, s * p->a * c1, q3 + s * p->a * s1};
  double B[3] = {0, s * e * c1, q3 + s * e * s1};
  memcpy(k->C[limb], C, sizeof C);
  memcpy(k->B[limb], B, sizeof B);

  /* Lower link: R = Rx(q1), centre halfway along s l2 from C_i. */
  double PL[3] = {0, s * kl * c1, q3 + s * kl * s1};
  double PLx[3] = {0, -s * kl * s1, s * kl * c1};
  double PLxx[3] = {0, -s * kl * c1, -s * kl * s1};
  rot_x(q[0], k->R[L]);
  set_translation(k, L, PL, PLx, PLxx, c);
  set_rotation(k, L, (scal){q[0], 1.0, 0.0}, E1, c);

  scal r = {(p->b12 - e * c1) / p->l1, e * s1 / p->l1, e * c1 / p->l1}, beta, sb;
  if (acos_chain(r, &beta, &sb) != GSL_SUCCESS) return GSL_EDOM;
  scal alpha = {s * beta.v, s * beta.x, s * beta.xx};
  scal zB = {B[2], s * e * c1, -s * e * s1};
  scal d = {zB.v + p->l1 * sb.v, zB.x + p->l1 * sb.x, zB.xx + p->l1 * sb.xx};

  /* Upper link: R = Rx(alpha_i), centre (A_i + B_i)/2. */
  double PU[3] = {0, 0.5 * s * (p->b12 + e * c1), zB.v + 0.5 * p->l1 * sb.v};
  double PUx[3] = {0, -0.5 * s * e * s1, zB.x + 0.5 * p->l1 * sb.x};
  double PUxx[3] = {0, -0.5 * s * e * c1, zB.xx + 0.5 * p->l1 * sb.xx};
  rot_x(alpha.v, k->R[U]);
  set_translation(k, U, PU, PUx, PUxx, c);
  set_rotation(k, U, alpha, E1, c);

  /* Slider: translates along e3 only, centre A_i. */
  double PS[3] = {0, s * p->b12, d.v}, PSx[3] = {0, 0, d.x}, PSxx[3] = {0, 0, d.xx};
  rot_x(0.0, k->R[S]); /* R_S = I */
  set_translation(k, S, PS, PSx, PSxx, c);
  memcpy(k->A[limb], PS, sizeof PS);
  k->d[limb] = d.v;
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

/* Limb 3 (eqs. 5, 12-13); xi = gamma. x3 = (cos gamma, 0, -sin gamma). */
static int limb3(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k)
{
  chain c;
  const double gam = gamma_chain(q, qd, &c), cg = cos(gam), sg = sin(gam), q3 = q[2];
  const double kl = 0.5 * p->l2;
  k->gamma = gam;

  double C[3] = {0, 0, q3}, B[3] = {p->l2 * cg, 0, q3 - p->l2 * sg};
  memcpy(k->C[2], C, sizeof C);
  memcpy(k->B[2], B, sizeof B);

  double PL[3] = {kl * cg, 0, q3 - kl * sg};
  double PLx[3] = {-kl * sg, 0, -kl * cg};
  double PLxx[3] = {-kl * cg, 0, kl * sg};
  rot_y(gam, k->R[REF_L3]);
  set_translation(k, REF_L3, PL, PLx, PLxx, &c);
  set_rotation(k, REF_L3, (scal){gam, 1.0, 0.0}, E2, &c);

  scal r = {(p->l2 * cg - p->b3) / p->l1, -p->l2 * sg / p->l1, -p->l2 * cg / p->l1}, alpha, sa;
  if (acos_chain(r, &alpha, &sa) != GSL_SUCCESS) return GSL_EDOM;
  scal zB = {B[2], -p->l2 * cg, p->l2 * sg};
  scal d = {zB.v + p->l1 * sa.v, zB.x + p->l1 * sa.x, zB.xx + p->l1 * sa.xx};

  double PU[3] = {0.5 * (p->b3 + p->l2 * cg), 0, zB.v + 0.5 * p->l1 * sa.v};
  double PUx[3] = {-0.5 * p->l2 * sg, 0, zB.x + 0.5 * p->l1 * sa.x};
  double PUxx[3] = {-0.5 * p->l2 * cg, 0, zB.xx + 0.5 * p->l1 * sa.xx};
  rot_y(alpha.v, k->R[REF_U3]);
  set_translation(k, REF_U3, PU, PUx, PUxx, &c);
  set_rotation(k, REF_U3, alpha, E2, &c);

  double PS[3] = {p->b3, 0, d.v}, PSx[3] = {0, 0, d.x}, PSxx[3] = {0, 0, d.xx};
  rot_y(0.0, k->R[REF_S3]); /* R_S = I */
  set_translation(k, REF_S3, PS, PSx, PSxx, &c);
  memcpy(k->A[2], PS, sizeof PS);
  k->d[2] = d.v;
  return GSL_SUCCESS;
}

int ref_kinematics(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k)
{
  memset(k, 0, sizeof *k);
  if (!(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]))) return GSL_EDOM;
  chain c12 = {{1.0, 0.0, 0.0}, qd ? qd[0] : 0.0, 0.0}; /* xi = q1 exactly */
  platform(q, qd, k);
  if (limb12(p, q, 0, &c12, k) || limb12(p, q, 1, &c12, k) || limb3(p, q, qd, k)) return GSL_EDOM;
  /* J_d is the slider's vertical velocity row: d_i = z_Si. */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) k->Jd[3 * i + j] = k->JT[REF_S1 + i][6 + j];
  if (qd)
    for (int b = 0; b < PRRU_REF_NBODY; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
          k->omega[b][i] += k->JR[b][3 * i + j] * qd[j];
          k->v[b][i] += k->JT[b][3 * i + j] * qd[j];
        }
  return GSL_SUCCESS;
}

static void fill_nan(double *x, int n)
{
  for (int i = 0; i < n; i++) x[i] = NAN;
}

int prru_ref_ik(const prru_ref_params *p, const double q[3], double d[3])
{
  ref_kin k;
  int st = ref_kinematics(p, q, NULL, &k);
  if (st) { fill_nan(d, 3); return st; }
  memcpy(d, k.d, sizeof k.d);
  return GSL_SUCCESS;
}

int prru_ref_jd(const prru_ref_params *p, const double q[3], double Jd[9])
{
  ref_kin k;
  int st = ref_kinematics(p, q, NULL, &k);
  if (st) { fill_nan(Jd, 9); return st; }
  memcpy(Jd, k.Jd, sizeof k.Jd);
  return GSL_SUCCESS;
}

int prru_ref_poses(const prru_ref_params *p, const double q[3], double R[90], double pos[30])
{
  ref_kin k;
  int st = ref_kinematics(p, q, NULL, &k);
  if (st) { fill_nan(R, 90); fill_nan(pos, 30); return st; }
  memcpy(R, k.R, sizeof k.R);
  memcpy(pos, k.p, sizeof k.p);
  return GSL_SUCCESS;
}
