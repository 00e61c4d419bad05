/* The reference library against evidence that does not come from its own
 * formulas, for whatever model the build uses: finite differences of its
 * closed-form poses and actuator displacements (J_d, Jd' qd, J_R, J_T,
 * delta, mu, G), the kinetic energy summed body by body (M as its Hessian,
 * h as its Christoffel form), the drives' terms against their definitions
 * (spec section 11), the virtual-power identity H^T Q = 0, every body's
 * Newton-Euler equation with the reactions (eq. 28) and the platform's
 * written out from the spec's geometry, and the inverse of the forward
 * dynamics. With four limbs (spec section 12) also the mirror symmetry of
 * limbs 3 and 4, the minimum-norm inverse dynamics, the redundant reaction
 * direction z (Q z = 0) and lambda . z = 0; w_R against section 8 (three
 * limbs) and section 12 (J_d^+) written out here. And the committed model
 * of the other topology, evaluated by this build's reference (its
 * topology is its parameters'). The paper's numbers are in
 * paper_reference.c. */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_mechanism.h"
#include "prru_model_file.h"
#include "prru_ref.h"
#include "testref.h"
#include "testutil.h"

#define PI 3.14159265358979323846
#define NB PRRU_NBODY
#define NW (6 * PRRU_NBODY)
#define NL PRRU_NLAMBDA
#define NA PRRU_NACT

static prru_ref_params P;
static prru_ref_ws *W;

/* ---- finite differences: 4th-order central with step fd_h (truncation
 * ~h^4 f^(5), rounding ~1e-16 |f| / h). fd_h is FD_H = 1e-3 scaled by the
 * state's squared margin (see margin()): near a singular boundary the
 * functions vary on a length that shrinks like the margin squared, and
 * scaling the step with it keeps both errors at their size far from the
 * boundary (truncation ~1e-12, rounding ~1e-13). ---- */
#define FD_H 1e-3
static double fd_h = FD_H;

typedef int (*vfun)(const double q[3], const double qd[3], double *out);

/* Directional derivative of f along dir at q; non-zero if any evaluation fails. */
static int fd_dir(vfun f, const double q[3], const double qd[3], const double dir[3], int n,
                  double *deriv)
{
  static const double step[4] = {2, 1, -1, -2}, wgt[4] = {-1, 8, -8, 1};
  double out[3 * NW]; /* the largest output: H */
  for (int i = 0; i < n; i++) deriv[i] = 0;
  for (int s = 0; s < 4; s++) {
    double qs[3];
    for (int i = 0; i < 3; i++) qs[i] = q[i] + step[s] * fd_h * dir[i];
    if (f(qs, qd, out) != GSL_SUCCESS) return 1;
    for (int i = 0; i < n; i++) deriv[i] += wgt[s] * out[i] / (12 * fd_h);
  }
  return 0;
}

/* Derivative along qd (the motion q(t) = q + t qd): along the unit
 * direction, so that the step is fd_h whatever |qd|, then scaled. */
static int fd_along(vfun f, const double q[3], const double qd[3], int n, double *deriv)
{
  const double nq = sqrt(qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]);
  const double dir[3] = {qd[0] / nq, qd[1] / nq, qd[2] / nq};
  int bad = fd_dir(f, q, qd, dir, n, deriv);
  for (int i = 0; i < n; i++) deriv[i] *= nq;
  return bad;
}

static int f_ik(const double q[3], const double qd[3], double *out)
{
  (void)qd;
  return prru_ref_ik(&P, q, out);
}

static int f_pos(const double q[3], const double qd[3], double *out)
{
  double R[9 * NB];
  (void)qd;
  return prru_ref_poses(&P, q, R, out);
}

static int f_rot(const double q[3], const double qd[3], double *out)
{
  double p[3 * NB];
  (void)qd;
  return prru_ref_poses(&P, q, out, p);
}

static int f_H(const double q[3], const double qd[3], double *out)
{
  (void)qd;
  return prru_ref_jacobians(&P, W, q, out);
}

static int f_Jd(const double q[3], const double qd[3], double *out)
{
  (void)qd;
  return prru_ref_jd(&P, q, out);
}

/* The qd-quadratic part of d/dt (A(q) qd) is sum_jk (dA_rj/dq_k) qd_j qd_k,
 * from the FD partials dA/dq_k of an n x 3 matrix A (at dA + 3 NW k); out
 * gets it. Its terms can cancel, so the return value, the largest sum of
 * their magnitudes, is the scale an error in it is measured against. */
static double quad_form(const double *dA, const double qd[3], int n, double *out)
{
  double scale = 0;
  for (int r = 0; r < n; r++) {
    double s = 0, a = 0;
    for (int k = 0; k < 3; k++)
      for (int j = 0; j < 3; j++) {
        const double t = dA[3 * NW * k + 3 * r + j] * qd[j] * qd[k];
        s += t;
        a += fabs(t);
      }
    out[r] = s;
    scale = fmax(scale, a);
  }
  return scale;
}

static int f_V(const double q[3], const double qd[3], double *out)
{
  double E[2];
  int st = prru_ref_energy(&P, W, q, qd, E);
  out[0] = E[1];
  return st;
}

static int f_M(const double q[3], const double qd[3], double *out)
{
  (void)qd;
  return prru_ref_mass(&P, W, q, out);
}

static const double EJ[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

static double norm(const double *x, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += x[i] * x[i];
  return sqrt(s);
}

/* ---- sampling ----
 * Any q1, q2 of a half turn and any height; what the model cannot reach
 * is rejected. So are states too close to a singular boundary for finite
 * differences with a fixed step: where an upper link nears full stretch
 * or fold (acos argument r near +-1) d(q) has a square-root branch point,
 * its derivatives grow like (1 - r^2)^(-k + 1/2) and the step's truncation
 * error with them; sqrt(1 - r^2) is |sin| of the upper link's angle,
 * read off its rotation (Rx(alpha): R[7], Ry(alpha): R[2]). Likewise the
 * U joint of limb 3 locks where cos(phi) = 0, phi = asin(-sin q1 cos q2),
 * and gamma's gradient grows like 1/cos^2(phi). When J_d must be inverted
 * (inverse dynamics) its condition number is bounded too: near the
 * actuation singularity fd = J_d^-T (...) loses digits in proportion. */
#define MARGIN 0.3
#define COND_JD 1e3

static double margin(const double q[3]) { return ref_margin(&P, q); }

/* A^-1 of a 3x3 matrix by cofactors; returns det A. */
static double inv3(const double A[9], double Ai[9])
{
  double C[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      const int r0 = (i + 1) % 3, r1 = (i + 2) % 3, c0 = (j + 1) % 3, c1 = (j + 2) % 3;
      C[3 * j + i] = A[3 * r0 + c0] * A[3 * r1 + c1] - A[3 * r0 + c1] * A[3 * r1 + c0];
    }
  const double det = A[0] * C[0] + A[1] * C[3] + A[2] * C[6];
  for (int i = 0; i < 9; i++) Ai[i] = C[i] / det;
  return det;
}

/* J^T J of an NA x 3 row-major J. */
static void gram(const double *J, double N[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      N[3 * i + j] = 0;
      for (int l = 0; l < NA; l++) N[3 * i + j] += J[3 * l + i] * J[3 * l + j];
    }
}

/* 1-norm condition number of a 3x3 matrix (cofactor inverse). */
static double cond3(const double A[9])
{
  double Ai[9];
  inv3(A, Ai);
  double na = 0, ni = 0;
  for (int j = 0; j < 3; j++) {
    double a = 0, b = 0;
    for (int i = 0; i < 3; i++) {
      a += fabs(A[3 * i + j]);
      b += fabs(Ai[3 * i + j]);
    }
    na = fmax(na, a);
    ni = fmax(ni, b);
  }
  return na * ni;
}

/* Condition number of J_d at q: the 1-norm one for three limbs; for four
 * (J_d is 4x3) sqrt(cond_1(J_d^T J_d)), the same measure (cond_2(J_d)^2 =
 * cond_2(J_d^T J_d)) of what the minimum-norm inverse dynamics inverts. */
static double cond_jd(const double q[3])
{
  double J[3 * NA], N[9];
  if (prru_ref_jd(&P, q, J) != GSL_SUCCESS) return INFINITY;
  if (NA == 3) return cond3(J);
  gram(J, N);
  return sqrt(cond3(N));
}

static double machine_size(void)
{
  double s = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) s = fmax(s, P.l1[i] + P.l2[i]);
  return s;
}

static void random_state(double q[3], double qd[3], int regular_jd)
{
  const double L = machine_size();
  double m;
  do {
    q[0] = tu_uniform(-PI / 2, PI / 2);
    q[1] = tu_uniform(-PI / 2, PI / 2);
    q[2] = tu_uniform(-2 * L, 2 * L);
  } while ((m = margin(q)) < MARGIN || (regular_jd && cond_jd(q) > COND_JD));
  fd_h = FD_H * m * m;
  for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
}

static void random_loads(double fd[NA], double fp[3], double mp[3])
{
  for (int i = 0; i < 3; i++) {
    fd[i] = tu_uniform(-60, 60);
    fp[i] = tu_uniform(-30, 30);
    mp[i] = tu_uniform(-3, 3);
  }
  for (int i = 3; i < NA; i++) fd[i] = tu_uniform(-60, 60); /* limb 4 */
}

/* The drive forces of spec section 11 written out here:
 * phi_i = -c_i dd_i - f_i tanh(dd_i / v_s). */
static void drive_friction(const prru_ref_params *p, const double dd[NA], double phi[NA])
{
  for (int i = 0; i < NA; i++) {
    phi[i] = -p->damping[i] * dd[i];
    if (p->coulomb[i] != 0) phi[i] -= p->coulomb[i] * tanh(dd[i] / p->coulomb_velocity);
  }
}

static int has_drives(void)
{
  int any = 0;
  for (int i = 0; i < NA; i++) any |= P.armature[i] != 0 || P.damping[i] != 0 || P.coulomb[i] != 0;
  return any;
}

/* ---- the parameters are the descriptor's ---- */
static void test_params(void)
{
  int same = P.nlimb == prru_mech.nlimb;
  for (int i = 0; i < 3; i++) same &= P.g[i] == prru_mech.gravity[i];
  for (int b = 0; b < NB; b++) {
    same &= P.mass[b] == prru_mech.mass[b];
    for (int i = 0; i < 3; i++) same &= P.com[b][i] == prru_mech.com[b][i];
    for (int i = 0; i < 9; i++) same &= P.inertia[b][i] == prru_mech.inertia[b][i];
  }
  for (int i = 0; i < PRRU_NLIMB; i++)
    same &= P.b[i] == prru_mech.b[i] && P.l1[i] == prru_mech.l1[i] && P.l2[i] == prru_mech.l2[i] &&
            P.a[i] == prru_mech.a[i];
  for (int i = 0; i < NA; i++)
    same &= P.armature[i] == prru_mech.armature[i] && P.damping[i] == prru_mech.damping[i] &&
            P.coulomb[i] == prru_mech.coulomb[i];
  same &= P.coulomb_velocity == prru_mech.coulomb_velocity;
  TU_TRUE(same, "prru_ref_params_default copies prru_mech");
  /* The reference puts C_3 (and C_4) at O' whatever a[2] (a[3]) says (spec
   * sections 4, 12). */
  int at_o = 1;
  for (int l = 2; l < PRRU_NLIMB; l++) at_o &= P.a[l] == 0.0;
  TU_TRUE(at_o, "a[2] (a[3]) = 0: the U joints of limbs 3 (and 4) are O'");
  /* The layout the tests below read: C1..C3 (C4) first in lambda, 3 forces
   * then the moment. */
  int layout = 1;
  for (int l = 0; l < PRRU_NLIMB; l++)
    layout &= prru_mech.joint[l].type == 'U' && prru_mech.joint[l].limb == l &&
              prru_mech.joint[l].lambda_count == 4 && prru_mech.joint[l].distal == prru_mech.platform;
  TU_TRUE(layout, "lambda starts with the U joints C1..C3 (C4) (4 each)");
  printf("model %s (format %d): drives %s\n", prru_mech.name, prru_mech.format,
         has_drives() ? "yes" : "none");
}

/* ---- Jacobians, delta, mu, J_d, Jd' qd, G by finite differences ---- */
static void test_finite_differences(void)
{
  double e_jd = 0, e_jt = 0, e_jr = 0, e_dm = 0, e_g = 0, e_skew = 0, e_dd = 0, e_ddb = 0;
  int fails = 0;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], Jd[3 * NA], H[3 * NW], dm[NW], G[3], dd[NA], ddb[NA];
    random_state(q, qd, 0);
    if (prru_ref_jd(&P, q, Jd) || prru_ref_jacobians(&P, W, q, H) ||
        prru_ref_bias_terms(&P, W, q, qd, dm) || prru_ref_gravity(&P, W, q, G) ||
        prru_ref_actuator_rates(&P, q, qd, dd, ddb)) {
      fails++;
      continue;
    }
    double Jd_fd[3 * NA], H_fd[3 * NW], dm_fd[NW], G_fd[3], R[9 * NB], pos[3 * NB], dd_fd[NA], ddb_fd[NA];
    prru_ref_poses(&P, q, R, pos);
    int bad = 0;
    for (int j = 0; j < 3; j++) {
      double dd_j[NA], dp[3 * NB], dR[9 * NB], dV;
      bad |= fd_dir(f_ik, q, qd, EJ[j], NA, dd_j);
      bad |= fd_dir(f_pos, q, qd, EJ[j], 3 * NB, dp);
      bad |= fd_dir(f_rot, q, qd, EJ[j], 9 * NB, dR);
      bad |= fd_dir(f_V, q, qd, EJ[j], 1, &dV);
      for (int i = 0; i < NA; i++) Jd_fd[3 * i + j] = dd_j[i];
      G_fd[j] = -dV;
      for (int b = 0; b < NB; b++) {
        /* skew(omega_j) = (dR/dq_j) R^T: read omega off it, and check it
         * is skew (so R stays a rotation to first order). */
        double S[9];
        for (int r = 0; r < 3; r++)
          for (int c = 0; c < 3; c++) {
            S[3 * r + c] = 0;
            for (int l = 0; l < 3; l++) S[3 * r + c] += dR[9 * b + 3 * r + l] * R[9 * b + 3 * c + l];
          }
        for (int r = 0; r < 3; r++)
          for (int c = 0; c < 3; c++) e_skew = fmax(e_skew, fabs(S[3 * r + c] + S[3 * c + r]));
        H_fd[3 * (3 * b + 0) + j] = S[7];
        H_fd[3 * (3 * b + 1) + j] = S[2];
        H_fd[3 * (3 * b + 2) + j] = S[3];
        for (int i = 0; i < 3; i++) H_fd[3 * (3 * NB + 3 * b + i) + j] = dp[3 * b + i];
      }
    }
    /* Along the motion: d' = d/dt d(q + t qd); the qd-quadratic parts of
     * the accelerations [delta; mu] = d/dt (H qd) and Jd' qd = d/dt (J_d qd)
     * from the partials of H and J_d. */
    static double dH[3][3 * NW], dJ[3][3 * NW];
    for (int k = 0; k < 3; k++) {
      bad |= fd_dir(f_H, q, qd, EJ[k], 3 * NW, dH[k]);
      bad |= fd_dir(f_Jd, q, qd, EJ[k], 3 * NA, dJ[k]);
    }
    bad |= fd_along(f_ik, q, qd, NA, dd_fd);
    if (bad) { fails++; continue; }
    const double s_dm = quad_form(dH[0], qd, NW, dm_fd), s_ddb = quad_form(dJ[0], qd, NA, ddb_fd);
    e_jd = fmax(e_jd, tu_relerr(Jd, Jd_fd, 3 * NA, 1e-300));
    e_jr = fmax(e_jr, tu_relerr(H, H_fd, 3 * 3 * NB, 1e-300));
    e_jt = fmax(e_jt, tu_relerr(H + 9 * NB, H_fd + 9 * NB, 9 * NB, 1e-300));
    e_dm = fmax(e_dm, tu_relerr(dm, dm_fd, NW, s_dm));
    /* G against the finite difference of V: truncation ~1e-12 of |G| (as
     * every check here), plus V's rounding, which the difference divides
     * by the step: four evaluations weighted (1 + 8 + 8 + 1) / 12, each
     * off by a few u of V's terms sum_b m_b |g| |p_b| (positions, not
     * lever arms: large for a robot far below its origin or a big one; a
     * random model's 1.06e-11 of |G| broke the old fixed bound). In units
     * of that allowance: at most 1. */
    double Vt = 0, gn = sqrt(P.g[0] * P.g[0] + P.g[1] * P.g[1] + P.g[2] * P.g[2]);
    for (int b = 0; b < NB; b++)
      Vt += P.mass[b] * gn * sqrt(pos[3 * b] * pos[3 * b] + pos[3 * b + 1] * pos[3 * b + 1] +
                                  pos[3 * b + 2] * pos[3 * b + 2]);
    double gmax = 0, gdiff = 0;
    for (int j = 0; j < 3; j++) {
      gmax = fmax(gmax, fabs(G[j]));
      gdiff = fmax(gdiff, fabs(G[j] - G_fd[j]));
    }
    e_g = fmax(e_g, gdiff / (1e-11 * gmax + 8 * DBL_EPSILON * Vt / fd_h));
    e_dd = fmax(e_dd, tu_relerr(dd, dd_fd, NA, 1e-300));
    e_ddb = fmax(e_ddb, tu_relerr(ddb, ddb_fd, NA, s_ddb));
  }
  tu_check(fails == 0, "finite-difference states evaluate", fails, 0);
  tu_check(e_jd <= 1e-11, "J_d = FD of prru_ref_ik", e_jd, 1e-11);
  tu_check(e_jr <= 1e-11, "J_R of every body = vee((dR/dq) R^T) by FD of the poses", e_jr, 1e-11);
  tu_check(e_skew <= 1e-11, "(dR/dq) R^T is skew", e_skew, 1e-11);
  tu_check(e_jt <= 1e-11, "J_T of every centre of mass = FD of it", e_jt, 1e-11);
  tu_check(e_dm <= 1e-9, "[delta; mu] = qd-quadratic part of d/dt (H qd), FD of H", e_dm, 1e-9);
  tu_check(e_g <= 1, "G = -dV/dq by FD of the potential energy (in 1e-11 |G| + 8 u V / h)", e_g, 1);
  tu_check(e_dd <= 1e-11, "actuator_rates dd = d/dt d by FD along qd", e_dd, 1e-11);
  tu_check(e_ddb <= 1e-9, "actuator_rates Jd' qd = qd-quadratic part of d/dt (J_d qd), FD of J_d", e_ddb, 1e-9);
  printf("finite differences (200 states): Jd %.1e JR %.1e (skew %.1e) JT %.1e delta/mu %.1e G %.1e"
         " dd %.1e Jd'qd %.1e\n", e_jd, e_jr, e_skew, e_jt, e_dm, e_g, e_dd, e_ddb);
}

/* ---- M, h, energy ---- */
static void test_mass_energy(void)
{
  double e_sym = 0, e_T = 0, e_hess = 0, e_m33 = 0, e_g3 = 0;
  double e_arm_M = 0, e_arm_h = 0, e_arm_T = 0;
  int not_pd = 0;
  prru_ref_params P0 = P; /* the same machine without armature */
  memset(P0.armature, 0, sizeof P0.armature);
  double mtot = 0, ktot = 0, gz = 0;
  for (int b = 0; b < NB; b++) mtot += P.mass[b];
  for (int i = 0; i < NA; i++) ktot += P.armature[i];
  for (int b = 0; b < NB; b++) gz += P.mass[b] * P.g[2];
  for (int n = 0; n < 300; n++) {
    double q[3], qd[3], M[9], E[2], G[3];
    random_state(q, qd, 0);
    prru_ref_mass(&P, W, q, M);
    prru_ref_energy(&P, W, q, qd, E);
    prru_ref_gravity(&P, W, q, G);
    double mmax = 0;
    for (int i = 0; i < 9; i++) mmax = fmax(mmax, fabs(M[i]));
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) e_sym = fmax(e_sym, fabs(M[3 * i + j] - M[3 * j + i]) / mmax);
    /* Sylvester: leading minors positive. */
    double m1 = M[0], m2 = M[0] * M[4] - M[1] * M[3];
    double m3 = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                M[2] * (M[3] * M[7] - M[4] * M[6]);
    if (!(m1 > 0 && m2 > 0 && m3 > 0)) not_pd++;
    double T = 0;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) T += 0.5 * qd[i] * M[3 * i + j] * qd[j];
    e_T = fmax(e_T, fabs(E[0] - T) / T);

    /* M = d2T/dqd2: T (body velocities and drive rates, not M) is exactly
     * quadratic in qd, so polarization gives its Hessian without
     * truncation: M_ii = 2 T(e_i), M_ij = T(e_i + e_j) - T(e_i) - T(e_j). */
    double Ti[3], Mh[9];
    for (int i = 0; i < 3; i++) {
      double Ei[2];
      prru_ref_energy(&P, W, q, EJ[i], Ei);
      Ti[i] = Ei[0];
      Mh[4 * i] = 2 * Ti[i];
    }
    for (int i = 0; i < 3; i++)
      for (int j = i + 1; j < 3; j++) {
        double v[3] = {EJ[i][0] + EJ[j][0], EJ[i][1] + EJ[j][1], EJ[i][2] + EJ[j][2]}, Eij[2];
        prru_ref_energy(&P, W, q, v, Eij);
        Mh[3 * i + j] = Mh[3 * j + i] = Eij[0] - Ti[i] - Ti[j];
      }
    e_hess = fmax(e_hess, tu_relerr(Mh, M, 9, 1e-300));

    /* q3 lifts every body rigidly along e3 (no pose depends on q3 other
     * than through + q3 e3, and d_i = z_Ai gains q3 too): J_T,b e3 = e3,
     * J_R,b e3 = 0 and J_d e3 = (1, 1, 1) for any geometry, so
     * M33 = sum m_b + sum k_i and G3 = sum m_b g_z exactly. */
    e_m33 = fmax(e_m33, fabs(M[8] - (mtot + ktot)) / (mtot + ktot));
    e_g3 = fmax(e_g3, fabs(G[2] - gz) / fabs(gz));

    /* The armature's share: against the same machine without it,
     * M - M0 = J_d^T K J_d, h - h0 = J_d^T K (Jd' qd), T - T0 = sum k dd^2/2. */
    double M0[9], h[3], h0[3], E0[2], Jd[3 * NA], dd[NA], ddb[NA], JKJ[9], JKb[3], dM[9], dh[3];
    prru_ref_mass(&P0, W, q, M0);
    prru_ref_bias(&P, W, q, qd, h);
    prru_ref_bias(&P0, W, q, qd, h0);
    prru_ref_energy(&P0, W, q, qd, E0);
    prru_ref_jd(&P, q, Jd);
    prru_ref_actuator_rates(&P, q, qd, dd, ddb);
    double Tk = 0, hmax = 1e-300;
    for (int i = 0; i < NA; i++) Tk += 0.5 * P.armature[i] * dd[i] * dd[i];
    for (int i = 0; i < 3; i++) {
      JKb[i] = 0;
      for (int l = 0; l < NA; l++) JKb[i] += Jd[3 * l + i] * P.armature[l] * ddb[l];
      for (int j = 0; j < 3; j++) {
        JKJ[3 * i + j] = 0;
        for (int l = 0; l < NA; l++) JKJ[3 * i + j] += Jd[3 * l + i] * P.armature[l] * Jd[3 * l + j];
        dM[3 * i + j] = M[3 * i + j] - M0[3 * i + j];
      }
      dh[i] = h[i] - h0[i];
      hmax = fmax(hmax, fabs(h[i]));
    }
    double em = 0, eh = 0;
    for (int i = 0; i < 9; i++) em = fmax(em, fabs(dM[i] - JKJ[i]) / mmax);
    for (int i = 0; i < 3; i++) eh = fmax(eh, fabs(dh[i] - JKb[i]) / hmax);
    e_arm_M = fmax(e_arm_M, em);
    e_arm_h = fmax(e_arm_h, eh);
    e_arm_T = fmax(e_arm_T, fabs(E[0] - E0[0] - Tk) / E[0]);
  }
  tu_check(e_sym <= 1e-15, "M symmetric", e_sym, 1e-15);
  tu_check(not_pd == 0, "M positive definite", not_pd, 0);
  tu_check(e_T <= 1e-13, "T body by body (+ armature) = qd^T M qd / 2", e_T, 1e-13);
  tu_check(e_hess <= 1e-13, "M = d2T/dqd2 (polarization of T)", e_hess, 1e-13);
  tu_check(e_m33 <= 1e-14, "M33 = total mass + total armature", e_m33, 1e-14);
  tu_check(e_g3 <= 1e-14, "G3 = sum m_b g_z", e_g3, 1e-14);
  tu_check(e_arm_M <= 1e-14, "M - M(no armature) = J_d^T K J_d", e_arm_M, 1e-14);
  tu_check(e_arm_h <= 1e-13, "h - h(no armature) = J_d^T K Jd' qd", e_arm_h, 1e-13);
  tu_check(e_arm_T <= 1e-14, "T - T(no armature) = sum k dd^2 / 2", e_arm_T, 1e-14);
  printf("mass (300 states): asymmetry %.1e, T %.1e, d2T/dqd2 %.1e, M33 %.1e (M33 = %.6g kg), G3 %.1e;"
         " armature M %.1e h %.1e T %.1e\n", e_sym, e_T, e_hess, e_m33, mtot + ktot, e_g3, e_arm_M,
         e_arm_h, e_arm_T);
}

/* h_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k: Lagrange's
 * equations with the kinetic energy qd^T M qd / 2 (the armature included),
 * by 4th-order central FD of the reference's own M. */
static void test_christoffel(void)
{
  double worst = 0;
  int fails = 0;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], dM[3][9], h[3], hc[3] = {0, 0, 0};
    random_state(q, qd, 0);
    int bad = prru_ref_bias(&P, W, q, qd, h) != GSL_SUCCESS;
    for (int k = 0; k < 3; k++) bad |= fd_dir(f_M, q, qd, EJ[k], 9, dM[k]);
    if (bad) { fails++; continue; }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++) hc[i] += (dM[k][3 * i + j] - 0.5 * dM[i][3 * j + k]) * qd[j] * qd[k];
    worst = fmax(worst, tu_relerr(h, hc, 3, 1e-300));
  }
  tu_check(fails == 0, "Christoffel states evaluate", fails, 0);
  tu_check(worst <= 1e-8, "h = Christoffel form of dM/dq (FD)", worst, 1e-8);
  printf("Christoffel (200 states): %.1e\n", worst);
}

/* ---- the drives' damping and friction ---- */
static void test_passive(void)
{
  double e_def = 0, e_pow = 0, e_fd = 0;
  int fails = 0, positive = 0, nonzero_without = 0;
  prru_ref_params Pnd = P; /* no damping, no friction */
  memset(Pnd.damping, 0, sizeof Pnd.damping);
  memset(Pnd.coulomb, 0, sizeof Pnd.coulomb);
  for (int n = 0; n < 300; n++) {
    double q[3], qd[3], fd[NA], fp[3], mp[3];
    random_state(q, qd, 0);
    random_loads(fd, fp, mp);
    /* Low slider speeds too, where tanh(dd / v_s) is not saturated. */
    if (n % 3 == 0)
      for (int i = 0; i < 3; i++) qd[i] *= 1e-3;
    double Qp[3], Qp0[3], Jd[3 * NA], dd[NA], ddb[NA], phi[NA], Qdef[3];
    if (prru_ref_passive(&P, W, q, qd, Qp) || prru_ref_jd(&P, q, Jd) ||
        prru_ref_actuator_rates(&P, q, qd, dd, ddb) || prru_ref_passive(&Pnd, W, q, qd, Qp0)) {
      fails++;
      continue;
    }
    for (int i = 0; i < 3; i++) nonzero_without |= Qp0[i] != 0.0;
    /* Definition: Qp = J_d^T phi, phi from the slider rates. */
    drive_friction(&P, dd, phi);
    double pscale = 1e-300, power = 0, qdQp = 0;
    for (int j = 0; j < 3; j++) {
      Qdef[j] = 0;
      for (int i = 0; i < NA; i++) Qdef[j] += Jd[3 * i + j] * phi[i];
      qdQp += qd[j] * Qp[j];
    }
    for (int i = 0; i < NA; i++) {
      power += phi[i] * dd[i];
      pscale += fabs(phi[i] * dd[i]);
    }
    e_def = fmax(e_def, tu_relerr(Qp, Qdef, 3, 1e-300));
    /* Virtual power: qd . Qp = phi . dd, and it only dissipates. */
    e_pow = fmax(e_pow, fabs(qdQp - power) / pscale);
    if (qdQp > 0) positive++;

    /* Forward dynamics: M qdd = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp
     * + Qp - h, from the reference's separate pieces; O' = (0, 0, q3)
     * (spec section 1) so J_T,O'^T fp = (0, 0, fp3). */
    double qdd[3], M[9], h[3], G[3], H[3 * NW];
    if (prru_ref_forward_dynamics(&P, W, q, qd, fd, fp, mp, qdd) ||
        prru_ref_dynamics(&P, W, q, qd, M, h, G) || prru_ref_jacobians(&P, W, q, H)) {
      fails++;
      continue;
    }
    double lhs[3], rhs[3], scale = 1e-300;
    for (int j = 0; j < 3; j++) {
      lhs[j] = M[3 * j] * qdd[0] + M[3 * j + 1] * qdd[1] + M[3 * j + 2] * qdd[2];
      double t[6] = {G[j], 0, j == 2 ? fp[2] : 0.0, 0, Qp[j], -h[j]};
      for (int i = 0; i < 3; i++) {
        t[1] += Jd[3 * i + j] * fd[i];
        t[3] += H[3 * i + j] * mp[i];
      }
      for (int i = 3; i < NA; i++) t[1] += Jd[3 * i + j] * fd[i]; /* limb 4 */
      rhs[j] = 0;
      for (int k = 0; k < 6; k++) {
        rhs[j] += t[k];
        scale = fmax(scale, fabs(t[k]));
      }
    }
    for (int j = 0; j < 3; j++) e_fd = fmax(e_fd, fabs(lhs[j] - rhs[j]) / scale);
  }
  tu_check(fails == 0, "passive states evaluate", fails, 0);
  tu_check(e_def <= 1e-15, "Qp = J_d^T (-c dd - f tanh(dd / v_s))", e_def, 1e-15);
  tu_check(e_pow <= 1e-14, "qd . Qp = phi . dd (virtual power)", e_pow, 1e-14);
  tu_check(positive == 0, "qd . Qp <= 0 (the drives only dissipate)", positive, 0);
  TU_TRUE(!nonzero_without, "Qp = 0 exactly without damping and friction");
  tu_check(e_fd <= 1e-14, "forward dynamics: M qdd = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp + Qp - h",
           e_fd, 1e-14);
  printf("passive (300 states): definition %.1e, power %.1e, forward dynamics %.1e\n", e_def, e_pow,
         e_fd);
}

/* ---- reactions ---- */

/* The unit null vector of J_d^T for four limbs (NA = 4): n_i = (-1)^i det
 * of J_d without row i (J_d^T n = 0 is the Laplace expansion of a 4x4
 * determinant with a repeated column); fd along n moves no coordinate. */
static void jdt_null(const double *J, double n[NA])
{
  double nn = 0;
  for (int i = 0; i < NA; i++) {
    double A[9] = {0}, Ai[9];
    for (int r = 0, k = 0; r < NA; r++) {
      if (r == i) continue;
      for (int c = 0; c < 3; c++) A[3 * k + c] = J[3 * r + c];
      k++;
    }
    n[i] = (i % 2 ? -1.0 : 1.0) * inv3(A, Ai);
    nn += n[i] * n[i];
  }
  for (int i = 0; i < NA; i++) n[i] /= sqrt(nn);
}

static void test_reactions(void)
{
  double e_HQ = 0, e_trip = 0, e_ne_f = 0, e_ne_m = 0, e_all = 0, e_Qz = 0, e_lz = 0, e_zs = 0;
  int fails = 0, bad_nullity = 0;
  const int redundant = NL - (6 * NB - 3); /* 0 for three limbs, 1 for four */
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], fd[NA], fp[3], mp[3], qdd[3], fd2[NA], lam[NL];
    static double Q[NW * NL];
    random_state(q, qd, 1);
    random_loads(fd, fp, mp);

    double H[3 * NW];
    if (prru_ref_jacobians(&P, W, q, H) || prru_ref_reaction_basis(&P, W, q, Q)) { fails++; continue; }
    double HQ[3 * NL];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < NL; j++) {
        HQ[NL * i + j] = 0;
        for (int r = 0; r < NW; r++) HQ[NL * i + j] += H[3 * r + i] * Q[NL * r + j];
      }
    e_HQ = fmax(e_HQ, norm(HQ, 3 * NL) / (norm(H, 3 * NW) * norm(Q, NW * NL)));

    double Jd[3 * NA], dd[NA], ddb[NA], phi[NA], fs[NA];
    if (prru_ref_jd(&P, q, Jd) || prru_ref_actuator_rates(&P, q, qd, dd, ddb)) { fails++; continue; }
    if (prru_ref_forward_dynamics(&P, W, q, qd, fd, fp, mp, qdd) ||
        prru_ref_inverse_dynamics(&P, W, q, qd, qdd, fp, mp, fd2)) { fails++; continue; }
    /* The inverse dynamics returns the least-norm fd that gives qdd: fd
     * itself for three limbs; for four, fd less its part along the null
     * vector of J_d^T (spec section 12's f = J_d (J_d^T J_d)^-1 tau). */
    double fexp[NA];
    memcpy(fexp, fd, sizeof fexp);
    if (NA == 4) {
      double nv[NA], t = 0;
      jdt_null(Jd, nv);
      for (int i = 0; i < NA; i++) t += nv[i] * fd[i];
      for (int i = 0; i < NA; i++) fexp[i] -= t * nv[i];
    }
    e_trip = fmax(e_trip, tu_relerr(fd2, fexp, NA, 1.0));

    /* What slider i receives from its drive (spec section 11), from the
     * qdd above: fd_i - k_i dd_i'' + phi_i, dd'' = J_d qdd + Jd' qd. */
    drive_friction(&P, dd, phi);
    for (int i = 0; i < NA; i++) {
      double acc = ddb[i] + Jd[3 * i] * qdd[0] + Jd[3 * i + 1] * qdd[1] + Jd[3 * i + 2] * qdd[2];
      fs[i] = fd[i] - P.armature[i] * acc + phi[i];
    }

    if (prru_ref_reactions(&P, W, q, qd, fd, fp, mp, lam)) { fails++; continue; }
    /* The public members now hold H, Phi, K, Q, dm of this state: the whole
     * eq. 28 residual Phi H qdd + K - Fbar - Q lambda, body by body, with
     * Fbar written out here. */
    double R[9 * NB], pos[3 * NB];
    prru_ref_poses(&P, q, R, pos);
    const double *pP = pos + 3 * prru_mech.platform;
    const double arm[3] = {-pP[0], -pP[1], q[2] - pP[2]}; /* O' - p_P */
    double fpm[3];
    tu_cross(arm, fp, fpm);
    double Fbar[NW];
    memset(Fbar, 0, sizeof Fbar);
    for (int b = 0; b < NB; b++)
      for (int i = 0; i < 3; i++) Fbar[3 * NB + 3 * b + i] = P.mass[b] * P.g[i];
    for (int i = 0; i < 3; i++) {
      Fbar[3 * prru_mech.platform + i] += mp[i] + fpm[i];
      Fbar[3 * NB + 3 * prru_mech.platform + i] += fp[i];
    }
    for (int i = 0; i < NA; i++) Fbar[3 * NB + 3 * prru_mech.slider[i] + 2] += fs[i];
    double res[NW], scale = 0;
    for (int r = 0; r < NW; r++) {
      double Ql = 0, PhiHq = 0;
      for (int c = 0; c < NW; c++) {
        double Hc = 0;
        for (int j = 0; j < 3; j++) Hc += gsl_matrix_get(W->H, c, j) * qdd[j];
        PhiHq += gsl_matrix_get(W->Phi, r, c) * Hc;
      }
      for (int j = 0; j < NL; j++) Ql += gsl_matrix_get(W->Q, r, j) * lam[j];
      res[r] = PhiHq + gsl_vector_get(W->K, r) - Fbar[r] - Ql;
      scale = fmax(scale, fmax(fabs(Fbar[r]), fabs(Ql)));
    }
    double rmax = 0;
    for (int r = 0; r < NW; r++) rmax = fmax(rmax, fabs(res[r]));
    e_all = fmax(e_all, rmax / scale);

    /* Platform Newton-Euler from the spec's geometry and the lambda labels
     * alone (R_P, C_i, u, n3, n4, p_P = O' + R_P com recomputed here, the
     * accelerations by the rigid-body formulas), not from Q or mu. */
    const double c1 = cos(q[0]), s1 = sin(q[0]), c2 = cos(q[1]), s2 = sin(q[1]);
    const double RP[9] = {c2, 0, s2, s1 * s2, c1, -s1 * c2, -c1 * s2, s1, c1 * c2};
    const double u[3] = {RP[0], RP[3], RP[6]}, wv[3] = {RP[2], RP[5], RP[8]};
    const double gam = atan2(s2, c1 * c2), x3[3] = {cos(gam), 0, -sin(gam)};
    const double x4[3] = {-x3[0], -x3[1], -x3[2]}; /* limb 4's lower link (spec section 12) */
    double n3[3], n4[3];
    tu_cross(wv, x3, n3);
    tu_cross(wv, x4, n4);
    const double nn3 = norm(n3, 3), nn4 = norm(n4, 3);
    for (int i = 0; i < 3; i++) {
      n3[i] /= nn3;
      n4[i] /= nn4;
    }
    const int ip = prru_mech.platform;
    const double mP = P.mass[ip];
    double rc[3], F[3], Mo[3];
    tu_matvec3(RP, P.com[ip], rc); /* p_P - O' */
    for (int i = 0; i < 3; i++) {
      F[i] = fp[i] + mP * P.g[i];
      Mo[i] = mp[i] + fpm[i];
    }
    for (int l = 0; l < PRRU_NLIMB; l++) {
      const double *f = lam + prru_mech.joint[l].lambda_offset;
      /* C_i - O' = R_P (0, s a_i, 0) for limbs 1, 2; C_3 = C_4 = O'. */
      const double loc[3] = {0, l == 0 ? -P.a[0] : l == 1 ? P.a[1] : 0.0, 0};
      double c[3], r[3], rxf[3];
      tu_matvec3(RP, loc, c);
      for (int i = 0; i < 3; i++) r[i] = c[i] - rc[i];
      tu_cross(r, f, rxf);
      const double *ax = l < 2 ? u : l == 2 ? n3 : n4;
      for (int i = 0; i < 3; i++) {
        F[i] += f[i];
        Mo[i] += rxf[i] + f[3] * ax[i];
      }
    }
    /* omega = q1' e1 + q2' e1', e1' = Rx(q1) e2; alpha = J_R qdd + q1' q2'
     * e1 x e1'; a_P = q3'' e3 + alpha x rc + omega x (omega x rc). */
    const double e1p[3] = {0, c1, s1};
    double om[3], al[3], e1xe1p[3], IP[9], Iom[3], Ial[3], gyro[3], t1[3], t2[3], aP[3];
    tu_cross(EJ[0], e1p, e1xe1p);
    for (int i = 0; i < 3; i++) {
      om[i] = EJ[0][i] * qd[0] + e1p[i] * qd[1];
      al[i] = EJ[0][i] * qdd[0] + e1p[i] * qdd[1] + qd[0] * qd[1] * e1xe1p[i];
    }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        IP[3 * i + j] = 0;
        for (int l = 0; l < 3; l++)
          for (int m = 0; m < 3; m++) IP[3 * i + j] += RP[3 * i + l] * P.inertia[ip][3 * l + m] * RP[3 * j + m];
      }
    tu_matvec3(IP, om, Iom);
    tu_matvec3(IP, al, Ial);
    tu_cross(om, Iom, gyro);
    tu_cross(al, rc, t1);
    tu_cross(om, rc, t2);
    tu_cross(om, t2, aP);
    for (int i = 0; i < 3; i++) aP[i] += t1[i] + (i == 2 ? qdd[2] : 0.0);
    double lhsF[3], lhsM[3];
    for (int i = 0; i < 3; i++) {
      lhsF[i] = mP * aP[i];
      lhsM[i] = Ial[i] + gyro[i];
    }
    /* Scales: the largest U-joint force and its largest lever. */
    double fmax_c = 0;
    const double lever = fmax(P.a[0], P.a[1]) + norm(rc, 3);
    for (int l = 0; l < PRRU_NLIMB; l++)
      fmax_c = fmax(fmax_c, norm(lam + prru_mech.joint[l].lambda_offset, 3));
    e_ne_f = fmax(e_ne_f, tu_relerr(lhsF, F, 3, fmax_c));
    e_ne_m = fmax(e_ne_m, tu_relerr(lhsM, Mo, 3, fmax_c * lever));

    /* The redundant reaction direction (four limbs): the reference's z,
     * Q z = 0 with the Q of prru_ref_reaction_basis above, lambda . z = 0
     * (lambda the least-norm solution), and z the internal force the spec
     * names: limbs 3 and 4 push O' along e2 against each other (the C3 and
     * C4 forces opposite and along e2, no U-joint moment), closed through
     * their rails, with nothing in limbs 1 and 2. */
    double z[NL];
    int nullity;
    if (prru_ref_reaction_null(&P, W, q, z, &nullity)) { fails++; continue; }
    bad_nullity += nullity != redundant;
    if (nullity == 1) {
      double Qz[NW], lz = 0, dev = 0;
      for (int r = 0; r < NW; r++) {
        Qz[r] = 0;
        for (int j = 0; j < NL; j++) Qz[r] += Q[NL * r + j] * z[j];
      }
      for (int j = 0; j < NL; j++) lz += lam[j] * z[j];
      e_Qz = fmax(e_Qz, norm(Qz, NW) / norm(Q, NW * NL)); /* |z| = 1 */
      e_lz = fmax(e_lz, fabs(lz) / norm(lam, NL));
      for (int jt = 0; jt < PRRU_NJOINT; jt++) {
        const prru_joint_info *J = &prru_mech.joint[jt];
        const double *zj = z + J->lambda_offset;
        if (J->limb < 2)
          for (int c = 0; c < J->lambda_count; c++) dev = fmax(dev, fabs(zj[c]));
        if (J->type == 'U' && J->limb >= 2) {
          const double *z3 = z + prru_mech.joint[2].lambda_offset;
          dev = fmax(dev, fmax(fabs(zj[0]), fabs(zj[2]))); /* force along e2 only */
          dev = fmax(dev, fabs(zj[3]));                     /* no moment */
          dev = fmax(dev, fabs(zj[1] - (J->limb == 2 ? 1 : -1) * z3[1]));
        }
      }
      if (!(fabs(z[prru_mech.joint[2].lambda_offset + 1]) > 0.1)) dev = INFINITY;
      e_zs = fmax(e_zs, dev);
    }
  }
  tu_check(fails == 0, "reaction states evaluate", fails, 0);
  tu_check(e_HQ <= 1e-12, "H^T Q = 0 (relative to |H||Q|)", e_HQ, 1e-12);
  tu_check(e_trip <= 1e-12, NA == 3 ? "inverse dynamics of forward dynamics returns fd"
                                    : "inverse dynamics of forward dynamics returns fd less its J_d^T-null part",
           e_trip, 1e-12);
  tu_check(e_all <= 1e-12, "Phi H qdd + K = Fbar + Q lambda (eq. 28), every body, drive forces net",
           e_all, 1e-12);
  tu_check(e_ne_f <= 1e-12, "platform force balance with the C-joint reactions", e_ne_f, 1e-12);
  tu_check(e_ne_m <= 1e-12, "platform moment balance with the C-joint reactions", e_ne_m, 1e-12);
  tu_check(bad_nullity == 0, "Q's numerical null space has dimension NLAMBDA - (6 NBODY - 3)",
           bad_nullity, 0);
  if (redundant) {
    tu_check(e_Qz <= 1e-14, "Q z = 0 for the reference's null direction z (relative to |Q|)", e_Qz, 1e-14);
    tu_check(e_lz <= 1e-14, "lambda . z = 0: the minimum-norm lambda", e_lz, 1e-14);
    tu_check(e_zs <= 1e-13, "z: limbs 3 and 4 push O' along e2 against each other, nothing in limbs 1, 2",
             e_zs, 1e-13);
  }
  printf("reactions (200 states): H^T Q %.1e, fd round trip %.1e, eq. 28 %.1e, platform N-E %.1e / %.1e",
         e_HQ, e_trip, e_all, e_ne_f, e_ne_m);
  if (redundant) printf("; null direction: Q z %.1e, lambda . z %.1e, structure %.1e", e_Qz, e_lz, e_zs);
  printf("\n");
}

/* ---- dynamic manipulability ----
 * w_R written out here from spec section 8 (J_d^-1, three limbs) and
 * section 12 (J_d^+ = (J_d^T J_d)^-1 J_d^T, any number of limbs), with
 * cofactor inverses and no SVD: JtR = J_R,P J_d^+ has rank 2 with range
 * span{e1, u} = n^perp, n = e1 x u = (0, -sin q1, cos q1), so JtR^+ =
 * JtR^T (JtR JtR^T)^+ = JtR^T ((JtR JtR^T + c n n^T)^-1 - n n^T / c), c > 0
 * (c = tr(JtR JtR^T) / 2 keeps the 3x3 inverse as well conditioned as
 * JtR JtR^T is on its range); and the two
 * non-zero squared singular values of B = Mt JtR^+ are the roots of
 * x^2 - tr(B^T B) x + c2 (c2 the sum of B^T B's principal 2x2 minors; its
 * determinant is 0). */
static double w_r_from(const double *Jp, const double M[9], const double H[3 * NW], const double q[3])
{
  double T[3 * NA], Mt[NA * NA], JtR[3 * NA], G[9], Gi[9], Pi[3 * NA], B[3 * NA], BtB[9];
  const double n[3] = {0, -sin(q[0]), cos(q[0])};
  const double *JRP = H + 9 * prru_mech.platform;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < NA; j++) {
      T[NA * i + j] = JtR[NA * i + j] = 0;
      for (int l = 0; l < 3; l++) {
        T[NA * i + j] += M[3 * i + l] * Jp[NA * l + j];
        JtR[NA * i + j] += JRP[3 * i + l] * Jp[NA * l + j];
      }
    }
  for (int i = 0; i < NA; i++)
    for (int j = 0; j < NA; j++) {
      Mt[NA * i + j] = 0;
      for (int l = 0; l < 3; l++) Mt[NA * i + j] += Jp[NA * l + i] * T[NA * l + j];
    }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      G[3 * i + j] = 0;
      for (int l = 0; l < NA; l++) G[3 * i + j] += JtR[NA * i + l] * JtR[NA * j + l];
    }
  const double c = 0.5 * (G[0] + G[4] + G[8]);
  for (int i = 0; i < 9; i++) G[i] += c * n[i / 3] * n[i % 3];
  inv3(G, Gi);
  for (int i = 0; i < 9; i++) Gi[i] -= n[i / 3] * n[i % 3] / c;
  for (int i = 0; i < NA; i++)
    for (int j = 0; j < 3; j++) {
      Pi[3 * i + j] = 0;
      for (int l = 0; l < 3; l++) Pi[3 * i + j] += JtR[NA * l + i] * Gi[3 * l + j];
    }
  for (int i = 0; i < NA; i++)
    for (int j = 0; j < 3; j++) {
      B[3 * i + j] = 0;
      for (int l = 0; l < NA; l++) B[3 * i + j] += Mt[NA * i + l] * Pi[3 * l + j];
    }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      BtB[3 * i + j] = 0;
      for (int l = 0; l < NA; l++) BtB[3 * i + j] += B[3 * l + i] * B[3 * l + j];
    }
  const double tr = BtB[0] + BtB[4] + BtB[8];
  const double c2 = BtB[0] * BtB[4] - BtB[1] * BtB[3] + BtB[0] * BtB[8] - BtB[2] * BtB[6] +
                    BtB[4] * BtB[8] - BtB[5] * BtB[7];
  const double x1 = 0.5 * (tr + sqrt(fmax(tr * tr - 4 * c2, 0.0))), x2 = c2 / x1;
  return sqrt(x1 / x2);
}

static void test_w_r(void)
{
  double e_pinv = 0, e_inv = 0;
  int fails = 0;
  for (int n = 0; n < 300; n++) {
    double q[3], qd[3], M[9], J[3 * NA], H[3 * NW], wr;
    random_state(q, qd, 1);
    if (prru_ref_w_r(&P, W, q, &wr) || prru_ref_mass(&P, W, q, M) || prru_ref_jd(&P, q, J) ||
        prru_ref_jacobians(&P, W, q, H)) {
      fails++;
      continue;
    }
    /* J_d^+ = (J_d^T J_d)^-1 J_d^T (3 x NA). */
    double N[9], Ni[9], Jp[3 * NA];
    gram(J, N);
    inv3(N, Ni);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < NA; j++) {
        Jp[NA * i + j] = 0;
        for (int l = 0; l < 3; l++) Jp[NA * i + j] += Ni[3 * i + l] * J[3 * j + l];
      }
    e_pinv = fmax(e_pinv, fabs(wr - w_r_from(Jp, M, H, q)) / wr);
    if (NA == 3) {
      double Ji[9];
      inv3(J, Ji);
      e_inv = fmax(e_inv, fabs(wr - w_r_from(Ji, M, H, q)) / wr);
    }
  }
  tu_check(fails == 0, "w_R states evaluate", fails, 0);
  tu_check(e_pinv <= 1e-12, "w_R = section 12's sigma_1/sigma_2 of Mt JtR^+ with J_d^+ = (J_d^T J_d)^-1 J_d^T",
           e_pinv, 1e-12);
  if (NA == 3)
    tu_check(e_inv <= 1e-12, "w_R = section 8's sigma_1/sigma_2 of Mt JtR^+ with J_d^-1", e_inv, 1e-12);
  printf("w_R (300 states): J_d^+ route %.1e", e_pinv);
  if (NA == 3) printf(", J_d^-1 route %.1e", e_inv);
  printf("\n");
}

/* ---- limb 4 mirrors limb 3 (spec section 12) ----
 * Reflecting the machine in the plane x = 0 maps limb 3 onto limb 4 and
 * R_P = Rx(q1) Ry(q2) onto Rx(q1) Ry(-q2): where limbs 3 and 4 have the
 * same b, l1 and l2 (read from the descriptor), d_4(q1, q2, q3) =
 * d_3(q1, -q2, q3), d_3(q) = d_4(q1, -q2, q3), and the rows of J_d follow
 * with the q2 column negated. */
static void test_mirror(void)
{
  if (PRRU_NLIMB != 4) return;
  const int l3 = 2, l4 = PRRU_NLIMB - 1;
  if (!(prru_mech.b[l4] == prru_mech.b[l3] && prru_mech.l1[l4] == prru_mech.l1[l3] &&
        prru_mech.l2[l4] == prru_mech.l2[l3])) {
    printf("mirror: limbs 3 and 4 differ in b, l1 or l2; d_4 = d_3 mirrored not checked\n");
    return;
  }
  double e_d = 0, e_j = 0;
  int fails = 0;
  for (int n = 0; n < 300; n++) {
    double q[3], qd[3], d[NA], dm[NA], J[3 * NA], Jm[3 * NA];
    random_state(q, qd, 0);
    const double qm[3] = {q[0], -q[1], q[2]};
    if (prru_ref_ik(&P, q, d) || prru_ref_ik(&P, qm, dm) || prru_ref_jd(&P, q, J) ||
        prru_ref_jd(&P, qm, Jm)) {
      fails++;
      continue;
    }
    const double a[2] = {d[l4], d[l3]}, b[2] = {dm[l3], dm[l4]};
    e_d = fmax(e_d, tu_relerr(a, b, 2, 1e-300));
    const double ja[6] = {J[3 * l4], J[3 * l4 + 1], J[3 * l4 + 2], J[3 * l3], J[3 * l3 + 1], J[3 * l3 + 2]};
    const double jb[6] = {Jm[3 * l3], -Jm[3 * l3 + 1], Jm[3 * l3 + 2], Jm[3 * l4], -Jm[3 * l4 + 1], Jm[3 * l4 + 2]};
    e_j = fmax(e_j, tu_relerr(ja, jb, 6, 1e-300));
  }
  tu_check(fails == 0, "mirror states evaluate (q and (q1, -q2, q3) both reachable)", fails, 0);
  tu_check(e_d <= 1e-15, "d_4(q1, q2, q3) = d_3(q1, -q2, q3) and d_3 = d_4 mirrored", e_d, 1e-15);
  tu_check(e_j <= 1e-15, "J_d rows 3, 4 mirror each other (q2 column negated)", e_j, 1e-15);
  printf("mirror (300 states): d %.1e, J_d %.1e\n", e_d, e_j);
}

static int all_nan(const double *x, int n)
{
  for (int i = 0; i < n; i++)
    if (!isnan(x[i])) return 0;
  return 1;
}

/* The first q along q = t e_axis, t in (0, pi], that the model cannot
 * reach: q1 turns limbs 1, 2 past their reach (limb 3 keeps gamma = 0 at
 * q2 = 0), q2 turns limb 3 (limbs 1, 2 keep q1 = 0). The generator
 * guarantees q = 0 is reachable; a model that reaches a whole half turn has
 * no such q and returns 0. */
static int unreachable_along(int axis, double q[3])
{
  double d[NA];
  for (int k = 1; k <= 3142; k++) {
    q[0] = q[1] = q[2] = 0;
    q[axis] = 1e-3 * k;
    if (prru_ref_ik(&P, q, d) == GSL_EDOM) return 1;
  }
  return 0;
}

static void test_unreachable(void)
{
  double bad[4][3] = {{NAN, 0, 0}, {0, 0, INFINITY}, {0, 0, 0}, {0, 0, 0}};
  int nbad = 2;
  for (int axis = 0; axis < 2; axis++)
    if (unreachable_along(axis, bad[nbad])) nbad++;
    else printf("no unreachable q along q%d in (0, pi]\n", axis + 1);
  const double qd[3] = {0.1, 0.2, 0.3}, f3[4] = {1, 2, 3, 4}; /* f3[0..NA-1]: fd */
  static double big[NW * NL], big2[9 * NB];
  for (int k = 0; k < nbad; k++) {
    const double *q = bad[k];
    double x[3 * NA], y[NA], z[NA], wr;
    int ok = 1, nullity;
    ok &= prru_ref_ik(&P, q, x) == GSL_EDOM && all_nan(x, NA);
    ok &= prru_ref_jd(&P, q, x) == GSL_EDOM && all_nan(x, 3 * NA);
    ok &= prru_ref_poses(&P, q, big2, big) == GSL_EDOM && all_nan(big2, 9 * NB) && all_nan(big, 3 * NB);
    ok &= prru_ref_jacobians(&P, W, q, big) == GSL_EDOM && all_nan(big, 3 * NW);
    ok &= prru_ref_bias_terms(&P, W, q, qd, big) == GSL_EDOM && all_nan(big, NW);
    ok &= prru_ref_mass(&P, W, q, x) == GSL_EDOM && all_nan(x, 9);
    ok &= prru_ref_bias(&P, W, q, qd, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_gravity(&P, W, q, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_dynamics(&P, W, q, qd, x, y, z) == GSL_EDOM && all_nan(x, 9) && all_nan(y, 3) && all_nan(z, 3);
    ok &= prru_ref_energy(&P, W, q, qd, y) == GSL_EDOM && all_nan(y, 2);
    ok &= prru_ref_actuator_rates(&P, q, qd, y, z) == GSL_EDOM && all_nan(y, NA) && all_nan(z, NA);
    ok &= prru_ref_passive(&P, W, q, qd, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_forward_dynamics(&P, W, q, qd, f3, f3, f3, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_inverse_dynamics(&P, W, q, qd, f3, f3, f3, y) == GSL_EDOM && all_nan(y, NA);
    ok &= prru_ref_reaction_basis(&P, W, q, big) == GSL_EDOM && all_nan(big, NW * NL);
    ok &= prru_ref_reactions(&P, W, q, qd, f3, f3, f3, big) == GSL_EDOM && all_nan(big, NL);
    ok &= prru_ref_reaction_null(&P, W, q, big, &nullity) == GSL_EDOM && all_nan(big, NL) && nullity == -1;
    ok &= prru_ref_w_r(&P, W, q, &wr) == GSL_EDOM && isnan(wr);
    char what[120];
    snprintf(what, sizeof what, "q = (%g, %g, %g) unreachable or not finite: every function GSL_EDOM and NaN",
             q[0], q[1], q[2]);
    TU_TRUE(ok, what);
  }
}

/* ---- the other topology: the reference computes with its parameters'
 * nlimb, not the build's, so a three-limb build's evaluates a four-limb
 * model and a four-limb build's a three-limb one. The committed model of
 * the other topology (models/4prru.json, models/3prru_paper.json), read
 * with the runtime's model-file reader, against properties that hold for
 * any model, with tolerances from the unit roundoff u = DBL_EPSILON / 2
 * and gamma(n) = n u / (1 - n u), the bound on the relative error of n
 * successive roundings (Higham, Accuracy and Stability, section 3.1). ---- */

#define U_ROUND (DBL_EPSILON / 2)
#define SENTINEL 12345.0

static double gamma_n(int n) { return n * U_ROUND / (1 - n * U_ROUND); }

/* A model file's numbers as the reference's parameters: Ixx Iyy Izz Ixy
 * Ixz Iyz as the symmetric tensor, as the runtime fills a descriptor. */
static void ref_params_of_spec(const prru_model_spec *s, prru_ref_params *p)
{
  memset(p, 0, sizeof *p);
  p->nlimb = s->nlimb;
  for (int i = 0; i < 3; i++) p->g[i] = s->gravity[i];
  for (int l = 0; l < s->nlimb; l++) {
    p->b[l] = s->limb[l].b;
    p->l1[l] = s->limb[l].l1;
    p->l2[l] = s->limb[l].l2;
    p->a[l] = s->limb[l].a;
    p->armature[l] = s->armature[l];
    p->damping[l] = s->damping[l];
    p->coulomb[l] = s->coulomb[l];
  }
  for (int b = 0; b < s->nbody; b++) {
    const double *I = s->inertia[b];
    const double T[9] = {I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2]};
    p->mass[b] = s->mass[b];
    memcpy(p->com[b], s->com[b], sizeof p->com[b]);
    memcpy(p->inertia[b], T, sizeof T);
  }
  p->coulomb_velocity = s->coulomb_velocity;
}

static int read_model(const char *path, prru_ref_params *p)
{
  static prru_model_spec spec;
  char msg[512];
  if (prru_model_file_read(path, &spec, msg, sizeof msg) != PRRU_OK) {
    printf("%s\n", msg);
    return 0;
  }
  ref_params_of_spec(&spec, p);
  return 1;
}

/* Every number, the unused entries included (both sides zero them). */
static int same_params(const prru_ref_params *a, const prru_ref_params *b)
{
  int same = a->nlimb == b->nlimb && a->coulomb_velocity == b->coulomb_velocity;
  for (int i = 0; i < 3; i++) same &= a->g[i] == b->g[i];
  for (int l = 0; l < PRRU_MAX_LIMB; l++)
    same &= a->b[l] == b->b[l] && a->l1[l] == b->l1[l] && a->l2[l] == b->l2[l] && a->a[l] == b->a[l];
  for (int i = 0; i < PRRU_MAX_ACT; i++)
    same &= a->armature[i] == b->armature[i] && a->damping[i] == b->damping[i] &&
            a->coulomb[i] == b->coulomb[i];
  for (int k = 0; k < PRRU_MAX_BODY; k++) {
    same &= a->mass[k] == b->mass[k];
    for (int i = 0; i < 3; i++) same &= a->com[k][i] == b->com[k][i];
    for (int i = 0; i < 9; i++) same &= a->inertia[k][i] == b->inertia[k][i];
  }
  return same;
}

/* J^T J of p's nact x 3 J_d. */
static void gram_of(const prru_ref_params *p, const double *J, double N[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      N[3 * i + j] = 0;
      for (int l = 0; l < p->nlimb; l++) N[3 * i + j] += J[3 * l + i] * J[3 * l + j];
    }
}

/* A reachable q of p at least MARGIN from the singular boundaries with
 * cond(J_d) <= COND_JD (measured as cond_jd does), and a qd. */
static void other_state(const prru_ref_params *p, double q[3], double qd[3])
{
  double L = 0, J[3 * PRRU_MAX_ACT], N[9];
  for (int l = 0; l < p->nlimb; l++) L = fmax(L, p->l1[l] + p->l2[l]);
  for (;;) {
    q[0] = tu_uniform(-PI / 2, PI / 2);
    q[1] = tu_uniform(-PI / 2, PI / 2);
    q[2] = tu_uniform(-2 * L, 2 * L);
    if (ref_margin(p, q) < MARGIN || prru_ref_jd(p, q, J) != GSL_SUCCESS) continue;
    gram_of(p, J, N);
    if ((p->nlimb == 3 ? cond3(J) : sqrt(cond3(N))) <= COND_JD) break;
  }
  for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
}

/* A = |H|^T |Phi| |H| + |J_d|^T K |J_d| after a call that left p's H in
 * W, with Phi's rotational blocks bounded by |R_b| |I_b| |R_b|^T: every
 * product of M's with its magnitude, the scale of any rounding in M. */
static void mass_scale(const prru_ref_params *p, const double *R, const double *Jd, double A[9])
{
  const int nb = 1 + 3 * p->nlimb;
  memset(A, 0, 9 * sizeof *A);
  for (int b = 0; b < nb; b++) {
    const double *Rb = R + 9 * b, *Ib = p->inertia[b];
    double Ia[9];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        Ia[3 * i + j] = 0;
        for (int l = 0; l < 3; l++)
          for (int m = 0; m < 3; m++)
            Ia[3 * i + j] += fabs(Rb[3 * i + l]) * fabs(Ib[3 * l + m]) * fabs(Rb[3 * j + m]);
      }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        for (int r = 0; r < 3; r++) {
          const double JTri = fabs(gsl_matrix_get(W->H, 3 * nb + 3 * b + r, i));
          A[3 * i + j] += p->mass[b] * JTri * fabs(gsl_matrix_get(W->H, 3 * nb + 3 * b + r, j));
          for (int c = 0; c < 3; c++)
            A[3 * i + j] += fabs(gsl_matrix_get(W->H, 3 * b + r, i)) * Ia[3 * r + c] *
                            fabs(gsl_matrix_get(W->H, 3 * b + c, j));
        }
  }
  for (int l = 0; l < p->nlimb; l++)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) A[3 * i + j] += p->armature[l] * fabs(Jd[3 * l + i] * Jd[3 * l + j]);
}

/* The inverse of the forward dynamics, compared as generalized forces:
 * J_d^T fd1 = J_d^T fd (fd1 = fd for three limbs; for four fd1 is the
 * minimum-norm force with the same J_d^T fd). The forward dynamics solves
 * M qdd = b by Cholesky (backward error gamma(10) |R^T| |R| <= 3 gamma(10)
 * ||M|| for a 3x3); the inverse rebuilds tau = M qdd + h - G - ... from
 * the same G, h, Qp, M (bit for bit the same in both calls: their own
 * rounding cancels), so tau - b is the rounding of a few sums of the
 * terms S = |G| + |h| + |Qp| + |J_d|^T |fd| + |fp_3| e3 + |J_R,P|^T |mp| +
 * |M| |qdd| (componentwise). Then it solves J_d^T fd1 = tau: for three
 * limbs by LU with partial pivoting (backward error gamma(9) |L| |U|,
 * |L| |U| <= 12 |J_d^T| in norm for a 3x3 with growth <= 4), for four
 * through the inverse of J_d^T J_d, whose error is kappa = cond_1(J_d^T
 * J_d) times larger. Every constant (gamma(n) / u for the sums' n <= 30,
 * 3 gamma(10) / u, 12 gamma(9) / u = 108) is at most 128:
 *   |J_d^T (fd1 - fd)| <= 128 u (||S|| + ||M|| ||qdd|| + kappa || |J_d|^T |fd1| ||).
 * Returns the error over that bound, -1 where a call fails. */
static double id_fd_ratio(const prru_ref_params *p, const double q[3], const double qd[3], const double *fd,
                          const double fp[3], const double mp[3])
{
  const int na = p->nlimb;
  double qdd[3], fd1[PRRU_MAX_ACT], Jd[3 * PRRU_MAX_ACT], M[9], h[3], G[3], Qp[3], N[9];
  if (prru_ref_forward_dynamics(p, W, q, qd, fd, fp, mp, qdd) != GSL_SUCCESS ||
      prru_ref_inverse_dynamics(p, W, q, qd, qdd, fp, mp, fd1) != GSL_SUCCESS ||
      prru_ref_passive(p, W, q, qd, Qp) != GSL_SUCCESS || prru_ref_jd(p, q, Jd) != GSL_SUCCESS ||
      prru_ref_dynamics(p, W, q, qd, M, h, G) != GSL_SUCCESS)
    return -1;
  double kappa = 1, S = 0, Mn = 0, qn = 0, Jf = 0, err = 0;
  if (na == 4) {
    gram_of(p, Jd, N);
    kappa = cond3(N);
  }
  for (int j = 0; j < 3; j++) {
    double s = fabs(G[j]) + fabs(h[j]) + fabs(Qp[j]) + (j == 2 ? fabs(fp[2]) : 0);
    double jf = 0, t1 = 0, t0 = 0, mrow = 0;
    for (int i = 0; i < na; i++) {
      s += fabs(Jd[3 * i + j] * fd[i]);
      jf += fabs(Jd[3 * i + j] * fd1[i]);
      t1 += Jd[3 * i + j] * fd1[i];
      t0 += Jd[3 * i + j] * fd[i];
    }
    for (int i = 0; i < 3; i++) { /* J_R,P: the first rows of p's H, in W */
      s += fabs(gsl_matrix_get(W->H, i, j) * mp[i]) + fabs(M[3 * j + i] * qdd[i]);
      mrow += fabs(M[3 * j + i]);
    }
    S = fmax(S, s);
    Jf = fmax(Jf, jf);
    Mn = fmax(Mn, mrow);
    qn = fmax(qn, fabs(qdd[j]));
    err = fmax(err, fabs(t1 - t0));
  }
  return err / (128 * U_ROUND * (S + Mn * qn + kappa * Jf));
}

static void test_other_topology(void)
{
  const char *src = getenv("PRRU_SOURCE_DIR"), *own = getenv("PRRU_MODEL");
  if (!TU_TRUE(src && own, "PRRU_SOURCE_DIR and PRRU_MODEL set (ctest sets them)")) return;
  static prru_ref_params Pf, Po;
  /* The reader and the conversion on the build's own file first. */
  TU_TRUE(read_model(own, &Pf) && same_params(&Pf, &P),
          "the build's model file, read and converted, is prru_ref_params_default");
  char path[1024], what[1200];
  snprintf(path, sizeof path, "%s/models/%s", src, PRRU_NLIMB == 3 ? "4prru.json" : "3prru_paper.json");
  snprintf(what, sizeof what, "%s reads: %d limbs", path, 7 - PRRU_NLIMB);
  if (!TU_TRUE(read_model(path, &Po) && Po.nlimb == 7 - PRRU_NLIMB, what)) return;
  const int na = Po.nlimb, nb = 1 + 3 * na, nw = 6 * nb, nl = 19 * na;

  /* The build's model before and after the other one in the same
   * workspace: bit for bit the same (the workspace follows each model). */
  double q0[3], qd0[3], fd0[NA], fp0[3], mp0[3], M0a[9], M0b[9], lam0a[NL], lam0b[NL];
  random_state(q0, qd0, 0);
  random_loads(fd0, fp0, mp0);
  prru_ref_mass(&P, W, q0, M0a);
  prru_ref_reactions(&P, W, q0, qd0, fd0, fp0, mp0, lam0a);

  static double Q[6 * PRRU_MAX_BODY * PRRU_MAX_LAMBDA + 1];
  double e_len = 0, w_sym = 0, w_T = 0, w_id = 0;
  int fails = 0, nullity_ok = 1, not_pd = 0, sized = 1;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], d[PRRU_MAX_ACT + 1], lam[PRRU_MAX_LAMBDA + 1], z[PRRU_MAX_LAMBDA];
    double R[9 * PRRU_MAX_BODY], pos[3 * PRRU_MAX_BODY], Jd[3 * PRRU_MAX_ACT], M[9], E[2], A[9];
    double fd[PRRU_MAX_ACT], fp[3], mp[3];
    int nullity;
    other_state(&Po, q, qd);
    for (int i = 0; i < 3; i++) {
      fp[i] = tu_uniform(-30, 30);
      mp[i] = tu_uniform(-3, 3);
    }
    for (int i = 0; i < na; i++) fd[i] = tu_uniform(-60, 60);

    /* The outputs are the model's length: the entry after them is not
     * written. Q's null space: one redundant reaction direction with four
     * limbs, none with three. */
    for (int i = 0; i <= PRRU_MAX_ACT; i++) d[i] = SENTINEL;
    for (int i = 0; i <= PRRU_MAX_LAMBDA; i++) lam[i] = SENTINEL;
    Q[nw * nl] = SENTINEL;
    int st = prru_ref_ik(&Po, q, d) | prru_ref_reaction_basis(&Po, W, q, Q) |
             prru_ref_reactions(&Po, W, q, qd, fd, fp, mp, lam);
    e_len = fmax(e_len, fabs(d[na] - SENTINEL) + fabs(lam[nl] - SENTINEL) + fabs(Q[nw * nl] - SENTINEL));
    nullity_ok &= prru_ref_reaction_null(&Po, W, q, z, &nullity) == GSL_SUCCESS && nullity == (na == 4);

    st |= prru_ref_poses(&Po, q, R, pos) | prru_ref_jd(&Po, q, Jd) | prru_ref_energy(&Po, W, q, qd, E) |
          prru_ref_mass(&Po, W, q, M);
    if (st != GSL_SUCCESS) {
      fails++;
      continue;
    }
    sized &= W->H->size1 == (size_t)nw && W->Q->size2 == (size_t)nl && W->Jd->size1 == (size_t)na;
    mass_scale(&Po, R, Jd, A);

    /* M symmetric: M_ij and M_ji are the same exact sum, each rounded along
     * R I R^T (9 products of 3), Phi H and H^T (Phi H) (6 nbody terms
     * each), then + J_d^T (K J_d) (nact terms, 2 more roundings): within
     * gamma(2 nw + nact + 13) A_ij of it, so of each other within twice
     * that. Positive definite: its leading minors (Sylvester). */
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        const double bound = 2 * gamma_n(2 * nw + na + 13) * A[3 * i + j];
        w_sym = fmax(w_sym, fabs(M[3 * i + j] - M[3 * j + i]) / bound);
      }
    const double m2 = M[0] * M[4] - M[1] * M[3];
    const double m3 = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                      M[2] * (M[3] * M[7] - M[4] * M[6]);
    not_pd += !(M[0] > 0 && m2 > 0 && m3 > 0);

    /* T body by body = qd^T M qd / 2: two evaluations of the same quadratic
     * form in the same computed H, Phi, J_d. prru_ref_energy rounds the
     * velocities (3 terms) and sums 12 nbody + nact products of at most 4
     * factors; the form in M rounds M (above) and its own 9 products of 3:
     * each within gamma(12 nbody + nact + 16) Tabs, Tabs = |qd|^T A |qd| / 2. */
    double Tm = 0, Tabs = 0;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        Tm += 0.5 * qd[i] * M[3 * i + j] * qd[j];
        Tabs += 0.5 * fabs(qd[i]) * A[3 * i + j] * fabs(qd[j]);
      }
    w_T = fmax(w_T, fabs(E[0] - Tm) / (2 * gamma_n(12 * nb + na + 16) * Tabs));

    const double r = id_fd_ratio(&Po, q, qd, fd, fp, mp);
    if (r < 0) fails++;
    else w_id = fmax(w_id, r);
  }
  prru_ref_mass(&P, W, q0, M0b);
  prru_ref_reactions(&P, W, q0, qd0, fd0, fp0, mp0, lam0b);

  snprintf(what, sizeof what, "the %d-limb model evaluates at every drawn state", na);
  tu_check(fails == 0, what, fails, 0);
  tu_check(e_len == 0, "outputs of the other model's lengths (the entry after them untouched)", e_len, 0);
  TU_TRUE(sized, "the workspace's H, Q, J_d are the other model's size");
  snprintf(what, sizeof what, "Q's null space: %d redundant reaction direction(s) for %d limbs", na == 4, na);
  TU_TRUE(nullity_ok, what);
  tu_check(w_sym <= 1, "other topology: M symmetric (asymmetry / bound)", w_sym, 1);
  tu_check(not_pd == 0, "other topology: M positive definite", not_pd, 0);
  tu_check(w_T <= 1, "other topology: T body by body = qd^T M qd / 2 (error / bound)", w_T, 1);
  tu_check(w_id <= 1, "other topology: J_d^T ID(FD(fd)) = J_d^T fd (error / bound)", w_id, 1);
  TU_TRUE(memcmp(M0a, M0b, sizeof M0a) == 0 && memcmp(lam0a, lam0b, sizeof lam0a) == 0,
          "the build's model after the other in the same workspace: M and lambda bit for bit the same");

  /* An nlimb the reference does not know (a zeroed struct's 0, or 5). */
  for (int bad = 0; bad <= 5; bad += 5) {
    prru_ref_params Pb = Po;
    Pb.nlimb = bad;
    double d[PRRU_MAX_ACT] = {SENTINEL, SENTINEL, SENTINEL, SENTINEL}, M[9];
    const double q[3] = {0, 0, 0};
    const int ik = prru_ref_ik(&Pb, q, d), mass = prru_ref_mass(&Pb, W, q, M);
    snprintf(what, sizeof what, "nlimb = %d: GSL_EINVAL, d untouched, M NaN", bad);
    TU_TRUE(ik == GSL_EINVAL && d[0] == SENTINEL && mass == GSL_EINVAL && all_nan(M, 9), what);
  }
  printf("other topology (%d limbs, %s; 200 states): error / bound: M asymmetry %.1e, T %.1e,"
         " ID(FD) %.1e\n", na, path, w_sym, w_T, w_id);
}

int main(void)
{
  prru_ref_params_default(&P);
  W = prru_ref_alloc();
  if (!W) { fprintf(stderr, "prru_ref_alloc failed\n"); return 1; }
  test_params();
  test_finite_differences();
  test_mass_energy();
  test_christoffel();
  test_passive();
  test_reactions();
  test_w_r();
  test_mirror();
  test_unreachable();
  test_other_topology();
  prru_ref_free(W);
  return tu_finish("test_reference");
}
