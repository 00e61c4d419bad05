/* The reference library against the spec's public reference point and
 * against evidence that does not come from its own formulas: finite
 * differences of its closed-form poses (J_d, J_R, J_T, delta, mu, G), the
 * kinetic energy summed body by body (M), the virtual-power identity
 * H^T Q = 0, the platform's Newton-Euler balance with the reactions, and
 * the inverse of the forward dynamics. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_kernels.h"
#include "prru_ref.h"
#include "testutil.h"

#define NB PRRU_REF_NBODY
#define NL 57

static prru_ref_params P;
static prru_ref_ws *W;

/* ---- finite differences: 4th-order central, step 1e-3 (truncation
 * ~h^4 f^(5) ~ 1e-12, rounding ~1e-16/h ~ 1e-13) ---- */
#define FD_H 1e-3

typedef int (*vfun)(const double q[3], const double qd[3], double *out);

/* Directional derivative of f along dir at q; non-zero if any evaluation fails. */
static int fd_dir(vfun f, const double q[3], const double qd[3], const double dir[3], int n,
                  double *deriv)
{
  static const double step[4] = {2, 1, -1, -2}, wgt[4] = {-1, 8, -8, 1};
  double out[200];
  for (int i = 0; i < n; i++) deriv[i] = 0;
  for (int s = 0; s < 4; s++) {
    double qs[3];
    for (int i = 0; i < 3; i++) qs[i] = q[i] + step[s] * FD_H * dir[i];
    if (f(qs, qd, out) != GSL_SUCCESS) return 1;
    for (int i = 0; i < n; i++) deriv[i] += wgt[s] * out[i] / (12 * FD_H);
  }
  return 0;
}

static int f_ik(const double q[3], const double qd[3], double *out)
{
  (void)qd;
  return prru_ref_ik(&P, q, out);
}

static int f_pos(const double q[3], const double qd[3], double *out)
{
  double R[90];
  (void)qd;
  return prru_ref_poses(&P, q, R, out);
}

static int f_rot(const double q[3], const double qd[3], double *out)
{
  double p[30];
  (void)qd;
  return prru_ref_poses(&P, q, out, p);
}

/* H(q) qd for the fixed qd: its derivative along qd is the qd-quadratic
 * part of the accelerations, [delta; mu]. */
static int f_Hqd(const double q[3], const double qd[3], double *out)
{
  double H[180];
  int st = prru_ref_jacobians(&P, W, q, H);
  for (int i = 0; i < 60; i++) out[i] = H[3 * i] * qd[0] + H[3 * i + 1] * qd[1] + H[3 * i + 2] * qd[2];
  return st;
}

static int f_V(const double q[3], const double qd[3], double *out)
{
  double E[2];
  int st = prru_ref_energy(&P, W, q, qd, E);
  out[0] = E[1];
  return st;
}

static const double EJ[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

static void random_state(double q[3], double qd[3])
{
  double d[3];
  do {
    q[0] = tu_uniform(-0.4, 0.4);
    q[1] = tu_uniform(-0.4, 0.4);
    q[2] = tu_uniform(-1.0, -0.5);
  } while (prru_ref_ik(&P, q, d) != GSL_SUCCESS);
  for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
}

static double norm(const double *x, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += x[i] * x[i];
  return sqrt(s);
}

/* ---- spec section 10 ---- */
static void test_reference_point(void)
{
  static const double M_ref[9] = {
      0.45906598061227876, 0.0034180053946637732, -0.067202143647255787,
      0.0034180053946637732, 0.17775860212149512, -0.75886870659132982,
      -0.067202143647255787, -0.75886870659132982, 12.39};
  static const double h_ref[3] = {-0.0026294266343440007, 0.0043554318154298796, -0.061280218724993618};
  static const double G_ref[3] = {0.6592530291795793, 7.4445020116609459, -121.54590000000001};
  static const double d_ref[3] = {-0.61587356199245987, -0.56196351700317267, -0.63523945236562458};
  static const double Jd_ref[9] = {-0.280316341384197, 0, 1, 0.2569859078659369, 0, 1,
                                   -0.004724475401913745, -0.2418333257655752, 1};
  const double q[3] = {0.1, 0.2, -0.8}, qd[3] = {0.3, -0.4, 0.5};
  double M[9], h[3], G[3], d[3], Jd[9];
  TU_TRUE(prru_ref_dynamics(&P, W, q, qd, M, h, G) == GSL_SUCCESS, "reference point: dynamics status");
  TU_TRUE(prru_ref_ik(&P, q, d) == GSL_SUCCESS, "reference point: ik status");
  TU_TRUE(prru_ref_jd(&P, q, Jd) == GSL_SUCCESS, "reference point: jd status");
  TU_CLOSE(M, M_ref, 9, 1e-12, "reference point M");
  TU_CLOSE(h, h_ref, 3, 1e-12, "reference point h");
  TU_CLOSE(G, G_ref, 3, 1e-12, "reference point G");
  TU_CLOSE(d, d_ref, 3, 1e-12, "reference point d");
  TU_CLOSE(Jd, Jd_ref, 9, 1e-12, "reference point J_d");
  /* M33 is the machine's total mass: q3 moves every body rigidly in z. */
  tu_check(fabs(M[8] - PRRU_TOTAL_MASS) <= 1e-13 * PRRU_TOTAL_MASS, "M33 = total mass 12.39",
           fabs(M[8] - PRRU_TOTAL_MASS), 1e-13 * PRRU_TOTAL_MASS);

  const double q0[3] = {0, 0, 0};
  const double d0[3] = {0.2116601048851672, 0.2116601048851672, 0.2116601048851672};
  double wr;
  prru_ref_ik(&P, q0, d);
  TU_CLOSE(d, d0, 3, 1e-15, "d at q = 0");
  TU_TRUE(prru_ref_w_r(&P, W, q0, &wr) == GSL_SUCCESS, "w_R(0) status");
  tu_check(fabs(wr - 1.80468) <= 5e-6, "w_R(0) = 1.80468 (5 digits)", fabs(wr - 1.80468), 5e-6);
  printf("reference point: w_R(0) = %.10f\n", wr);
}

/* ---- Jacobians, delta, mu, G by finite differences ---- */
static void test_finite_differences(void)
{
  double e_jd = 0, e_jt = 0, e_jr = 0, e_dm = 0, e_g = 0, e_skew = 0;
  int fails = 0;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], Jd[9], H[180], dm[60], G[3];
    random_state(q, qd);
    if (prru_ref_jd(&P, q, Jd) || prru_ref_jacobians(&P, W, q, H) ||
        prru_ref_bias_terms(&P, W, q, qd, dm) || prru_ref_gravity(&P, W, q, G)) {
      fails++;
      continue;
    }
    double Jd_fd[9], H_fd[180], dm_fd[60], G_fd[3], R[90], pos[30];
    prru_ref_poses(&P, q, R, pos);
    int bad = 0;
    for (int j = 0; j < 3; j++) {
      double dd[3], dp[30], dR[90], dV;
      bad |= fd_dir(f_ik, q, qd, EJ[j], 3, dd);
      bad |= fd_dir(f_pos, q, qd, EJ[j], 30, dp);
      bad |= fd_dir(f_rot, q, qd, EJ[j], 90, dR);
      bad |= fd_dir(f_V, q, qd, EJ[j], 1, &dV);
      for (int i = 0; i < 3; i++) Jd_fd[3 * i + j] = dd[i];
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
        for (int i = 0; i < 3; i++) H_fd[3 * (30 + 3 * b + i) + j] = dp[3 * b + i];
      }
    }
    /* Along the unit direction, so that the step is FD_H whatever |qd|. */
    const double nq = norm(qd, 3), dir[3] = {qd[0] / nq, qd[1] / nq, qd[2] / nq};
    bad |= fd_dir(f_Hqd, q, qd, dir, 60, dm_fd);
    for (int i = 0; i < 60; i++) dm_fd[i] *= nq;
    if (bad) { fails++; continue; }
    e_jd = fmax(e_jd, tu_relerr(Jd, Jd_fd, 9, 1e-300));
    e_jr = fmax(e_jr, tu_relerr(H, H_fd, 90, 1e-300));
    e_jt = fmax(e_jt, tu_relerr(H + 90, H_fd + 90, 90, 1e-300));
    e_dm = fmax(e_dm, tu_relerr(dm, dm_fd, 60, 1e-300));
    e_g = fmax(e_g, tu_relerr(G, G_fd, 3, 1e-300));
  }
  tu_check(fails == 0, "finite-difference states evaluate", fails, 0);
  tu_check(e_jd <= 1e-11, "J_d = FD of prru_ref_ik", e_jd, 1e-11);
  tu_check(e_jr <= 1e-11, "J_R of every body = vee((dR/dq) R^T) by FD of the poses", e_jr, 1e-11);
  tu_check(e_skew <= 1e-11, "(dR/dq) R^T is skew", e_skew, 1e-11);
  tu_check(e_jt <= 1e-11, "J_T of every body = FD of its centre", e_jt, 1e-11);
  tu_check(e_dm <= 1e-9, "[delta; mu] = d/dt (H qd) by FD along qd", e_dm, 1e-9);
  tu_check(e_g <= 1e-11, "G = -dV/dq by FD of the potential energy", e_g, 1e-11);
  printf("finite differences (200 states): Jd %.1e JR %.1e (skew %.1e) JT %.1e delta/mu %.1e G %.1e\n",
         e_jd, e_jr, e_skew, e_jt, e_dm, e_g);
}

/* ---- M, energy ---- */
static void test_mass_energy(void)
{
  double e_sym = 0, e_T = 0;
  int not_pd = 0;
  for (int n = 0; n < 300; n++) {
    double q[3], qd[3], M[9], E[2];
    random_state(q, qd);
    prru_ref_mass(&P, W, q, M);
    prru_ref_energy(&P, W, q, qd, E);
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
  }
  tu_check(e_sym <= 1e-15, "M symmetric", e_sym, 1e-15);
  tu_check(not_pd == 0, "M positive definite", not_pd, 0);
  tu_check(e_T <= 1e-13, "T body by body = qd^T M qd / 2", e_T, 1e-13);
  printf("mass: asymmetry %.1e, energy %.1e\n", e_sym, e_T);
}

/* ---- reactions ---- */
static void random_loads(double fd[3], double fp[3], double mp[3])
{
  for (int i = 0; i < 3; i++) {
    fd[i] = tu_uniform(-60, 60);
    fp[i] = tu_uniform(-30, 30);
    mp[i] = tu_uniform(-3, 3);
  }
}

static void test_reactions(void)
{
  double e_HQ = 0, e_trip = 0, e_ne_f = 0, e_ne_m = 0, e_all = 0;
  int fails = 0;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], fd[3], fp[3], mp[3], qdd[3], fd2[3], lam[NL];
    static double Q[60 * NL];
    random_state(q, qd);
    random_loads(fd, fp, mp);

    double H[180];
    if (prru_ref_jacobians(&P, W, q, H) || prru_ref_reaction_basis(&P, W, q, Q)) { fails++; continue; }
    double HQ[3 * NL];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < NL; j++) {
        HQ[NL * i + j] = 0;
        for (int r = 0; r < 60; r++) HQ[NL * i + j] += H[3 * r + i] * Q[NL * r + j];
      }
    e_HQ = fmax(e_HQ, norm(HQ, 3 * NL) / (norm(H, 180) * norm(Q, 60 * NL)));

    if (prru_ref_forward_dynamics(&P, W, q, qd, fd, fp, mp, qdd) ||
        prru_ref_inverse_dynamics(&P, W, q, qd, qdd, fp, mp, fd2)) { fails++; continue; }
    e_trip = fmax(e_trip, tu_relerr(fd2, fd, 3, 1.0));

    if (prru_ref_reactions(&P, W, q, qd, fd, fp, mp, lam)) { fails++; continue; }
    /* The public members now hold H, Phi, K, Q of this state: the whole
     * eq. 28 residual Phi H qdd + K - Fbar - Q lambda, body by body. */
    double res[60], scale = 0;
    for (int r = 0; r < 60; r++) {
      double Ql = 0, Fbar = 0, PhiHq = 0;
      for (int c = 0; c < 60; c++) {
        double Hc = 0;
        for (int j = 0; j < 3; j++) Hc += gsl_matrix_get(W->H, c, j) * qdd[j];
        PhiHq += gsl_matrix_get(W->Phi, r, c) * Hc;
      }
      for (int j = 0; j < NL; j++) Ql += gsl_matrix_get(W->Q, r, j) * lam[j];
      if (r < 3) Fbar = mp[r];
      if (r >= 30 && r < 33) Fbar = fp[r - 30];
      if (r >= 30 && (r - 30) % 3 == 2) Fbar -= P.mass[(r - 30) / 3] * P.g;
      for (int i = 0; i < 3; i++)
        if (r == 30 + 3 * (7 + i) + 2) Fbar += fd[i];
      res[r] = PhiHq + gsl_vector_get(W->K, r) - Fbar - Ql;
      scale = fmax(scale, fmax(fabs(Fbar), fabs(Ql)));
    }
    double rmax = 0;
    for (int r = 0; r < 60; r++) rmax = fmax(rmax, fabs(res[r]));
    e_all = fmax(e_all, rmax / scale);

    /* Platform Newton-Euler from the spec's geometry and the lambda labels
     * alone (C_i, u, n3 recomputed here), not from Q. */
    const double c1 = cos(q[0]), s1 = sin(q[0]), c2 = cos(q[1]), s2 = sin(q[1]);
    const double RP[9] = {c2, 0, s2, s1 * s2, c1, -s1 * c2, -c1 * s2, s1, c1 * c2};
    const double u[3] = {RP[0], RP[3], RP[6]}, wv[3] = {RP[2], RP[5], RP[8]};
    const double gam = atan2(s2, c1 * c2), x3[3] = {cos(gam), 0, -sin(gam)};
    double n3[3] = {wv[1] * x3[2] - wv[2] * x3[1], wv[2] * x3[0] - wv[0] * x3[2], wv[0] * x3[1] - wv[1] * x3[0]};
    double nn = norm(n3, 3);
    for (int i = 0; i < 3; i++) n3[i] /= nn;
    double F[3], Mo[3];
    const double mP = P.mass[0];
    for (int i = 0; i < 3; i++) {
      F[i] = fp[i] + (i == 2 ? -mP * P.g : 0.0);
      Mo[i] = mp[i];
    }
    for (int l = 0; l < 3; l++) {
      const double *f = lam + 4 * l;
      const double sgn = l == 0 ? -1.0 : 1.0;
      /* C_i - O' = R_P (0, s a, 0) for limbs 1, 2; C_3 = O'. */
      double r[3] = {0, 0, 0};
      if (l < 2)
        for (int i = 0; i < 3; i++) r[i] = RP[3 * i + 1] * sgn * P.a;
      const double *ax = l < 2 ? u : n3;
      double rxf[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
      for (int i = 0; i < 3; i++) {
        F[i] += f[i];
        Mo[i] += rxf[i] + f[3] * ax[i];
      }
    }
    /* Platform accelerations: a = J_T,P qdd + mu_P (= qdd3 e3), and
     * I_P omega' + omega x I_P omega with I_P = R_P diag R_P^T. */
    double dm[60];
    prru_ref_bias_terms(&P, W, q, qd, dm);
    double JR[9] = {1, 0, 0, 0, c1, 0, 0, s1, 0};
    double om[3], al[3], IP[9], Iom[3], Ial[3];
    for (int i = 0; i < 3; i++) {
      om[i] = JR[3 * i] * qd[0] + JR[3 * i + 1] * qd[1];
      al[i] = JR[3 * i] * qdd[0] + JR[3 * i + 1] * qdd[1] + dm[i];
    }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        IP[3 * i + j] = 0;
        for (int l = 0; l < 3; l++) IP[3 * i + j] += RP[3 * i + l] * P.inertia[0][l] * RP[3 * j + l];
      }
    for (int i = 0; i < 3; i++) {
      Iom[i] = IP[3 * i] * om[0] + IP[3 * i + 1] * om[1] + IP[3 * i + 2] * om[2];
      Ial[i] = IP[3 * i] * al[0] + IP[3 * i + 1] * al[1] + IP[3 * i + 2] * al[2];
    }
    double lhsM[3] = {Ial[0] + om[1] * Iom[2] - om[2] * Iom[1], Ial[1] + om[2] * Iom[0] - om[0] * Iom[2],
                      Ial[2] + om[0] * Iom[1] - om[1] * Iom[0]};
    double lhsF[3] = {0, 0, mP * qdd[2]};
    double fs = 0;
    for (int l = 0; l < 3; l++) fs = fmax(fs, norm(lam + 4 * l, 3));
    e_ne_f = fmax(e_ne_f, tu_relerr(lhsF, F, 3, fs));
    e_ne_m = fmax(e_ne_m, tu_relerr(lhsM, Mo, 3, fs * P.a));
  }
  tu_check(fails == 0, "reaction states evaluate", fails, 0);
  tu_check(e_HQ <= 1e-12, "H^T Q = 0 (relative to |H||Q|)", e_HQ, 1e-12);
  tu_check(e_trip <= 1e-12, "inverse dynamics of forward dynamics returns fd", e_trip, 1e-12);
  tu_check(e_all <= 1e-12, "Phi H qdd + K = Fbar + Q lambda (eq. 28), every body", e_all, 1e-12);
  tu_check(e_ne_f <= 1e-12, "platform force balance with the C-joint reactions", e_ne_f, 1e-12);
  tu_check(e_ne_m <= 1e-12, "platform moment balance with the C-joint reactions", e_ne_m, 1e-12);
  printf("reactions (200 states): H^T Q %.1e, fd round trip %.1e, eq. 28 %.1e, platform N-E %.1e / %.1e\n",
         e_HQ, e_trip, e_all, e_ne_f, e_ne_m);
}

/* The paper: w_R is symmetric in q1 (the machine is mirror-symmetric in y). */
static void test_w_r_symmetry(void)
{
  double e = 0;
  for (int n = 0; n < 50; n++) {
    double q[3] = {tu_uniform(-0.4, 0.4), tu_uniform(-0.6, 0.4), 0.0}, qm[3] = {-q[0], q[1], 0.0};
    double a, b;
    if (prru_ref_w_r(&P, W, q, &a) || prru_ref_w_r(&P, W, qm, &b)) continue;
    e = fmax(e, fabs(a - b) / a);
  }
  tu_check(e <= 1e-12, "w_R(q1) = w_R(-q1)", e, 1e-12);
}

static int all_nan(const double *x, int n)
{
  for (int i = 0; i < n; i++)
    if (!isnan(x[i])) return 0;
  return 1;
}

static void test_unreachable(void)
{
  const double bad[4][3] = {{1.4, 0, -0.8}, {0, 1.2, -0.8}, {NAN, 0, -0.8}, {0, 0, INFINITY}};
  const double qd[3] = {0.1, 0.2, 0.3}, f3[3] = {1, 2, 3};
  static double big[3420], big2[90];
  for (int k = 0; k < 4; k++) {
    const double *q = bad[k];
    double x[9], y[3], z[3], wr;
    int ok = 1;
    ok &= prru_ref_ik(&P, q, x) == GSL_EDOM && all_nan(x, 3);
    ok &= prru_ref_jd(&P, q, x) == GSL_EDOM && all_nan(x, 9);
    ok &= prru_ref_poses(&P, q, big2, big) == GSL_EDOM && all_nan(big2, 90) && all_nan(big, 30);
    ok &= prru_ref_jacobians(&P, W, q, big) == GSL_EDOM && all_nan(big, 180);
    ok &= prru_ref_bias_terms(&P, W, q, qd, big) == GSL_EDOM && all_nan(big, 60);
    ok &= prru_ref_mass(&P, W, q, x) == GSL_EDOM && all_nan(x, 9);
    ok &= prru_ref_bias(&P, W, q, qd, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_gravity(&P, W, q, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_dynamics(&P, W, q, qd, x, y, z) == GSL_EDOM && all_nan(x, 9) && all_nan(y, 3) && all_nan(z, 3);
    ok &= prru_ref_energy(&P, W, q, qd, y) == GSL_EDOM && all_nan(y, 2);
    ok &= prru_ref_forward_dynamics(&P, W, q, qd, f3, f3, f3, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_inverse_dynamics(&P, W, q, qd, f3, f3, f3, y) == GSL_EDOM && all_nan(y, 3);
    ok &= prru_ref_reaction_basis(&P, W, q, big) == GSL_EDOM && all_nan(big, 3420);
    ok &= prru_ref_reactions(&P, W, q, qd, f3, f3, f3, big) == GSL_EDOM && all_nan(big, 57);
    ok &= prru_ref_w_r(&P, W, q, &wr) == GSL_EDOM && isnan(wr);
    char what[80];
    snprintf(what, sizeof what, "unreachable/non-finite q #%d: every function GSL_EDOM and NaN", k);
    TU_TRUE(ok, what);
  }
}

int main(void)
{
  prru_ref_params_default(&P);
  W = prru_ref_alloc();
  if (!W) { fprintf(stderr, "prru_ref_alloc failed\n"); return 1; }
  test_reference_point();
  test_finite_differences();
  test_mass_energy();
  test_reactions();
  test_w_r_symmetry();
  test_unreachable();
  prru_ref_free(W);
  return tu_finish("test_reference");
}
