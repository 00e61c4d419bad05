/* Redundant actuation and redundant reactions (spec section 12), as
 * properties that hold for any model: with three actuators they reduce to
 * the plain inverses (J_d^+ = J_d^-1, no preload, no reaction null
 * direction), with four (the 4-PRRU) they are checked against dense GSL
 * SVDs built from the generated kernels directly:
 *   - prru_check_regular: J_d^+ and its 1-norm conditioning;
 *   - inverse dynamics: J_d^T fd = tau, fd of least norm, the preload
 *     t n exactly, FD(ID(qdd)) = qdd;
 *   - reactions: Q lambda = the body wrenches of eq. 28, the least-norm
 *     solution of a dense SVD solve, lambda . z = 0, Q z = 0, the
 *     platform's Newton-Euler and the machine's horizontal force balance
 *     (every limb's U joint, limb 4's moment axis w x x4 included), the
 *     physical shape of z (a force along e2 through limbs 3 and 4);
 *   - forward kinematics: FK(IK(q)) = q, an inconsistent fourth slider
 *     refused, least squares with the first-order residual;
 *   - the DME with J_d^+: Mt, JtR and w_R against GSL SVDs of M, J_d and
 *     J_R,P, at q = 0 and over random poses.
 * Measured numbers are printed for the record. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_sort_vector.h>

#include "testbuild.h"
#include "prru.h"
#include "prru_dme.h"
#include "testsim.h"
#include "testutil.h"

#define NA PRRU_NACT
#define NL PRRU_NLAMBDA
#define NB PRRU_NBODY
#define NH PRRU_NH

static prru_model model;
static prru_data data;

static void random_state(double q[3], double qd[3]) { ts_random_state(&model, &data, q, qd); }

static void random_loads(prru_loads *l)
{
  for (int i = 0; i < NA; i++) l->fd[i] = tu_uniform(-60, 60);
  for (int i = 0; i < 3; i++) {
    l->fp[i] = tu_uniform(-30, 30);
    l->mp[i] = tu_uniform(-3, 3);
  }
}

/* The model's length scale (the runtime's: the mean upper-link length). */
static double length_scale(void)
{
  double s = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) s += prru_mech.l1[i];
  return s / PRRU_NLIMB;
}

static double maxabs(const double *v, int n)
{
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

static double dotn(const double *a, const double *b, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* X (n x m) = A^+ for A (m x n, row-major) by GSL's SVD, singular values
 * below cut * sigma_max dropped; returns the rank and, if non-NULL, the
 * singular values (min(m, n), descending). Allocates: test code. */
static int pinv_svd(const double *A, int m, int n, double cut, double *X, double *sv)
{
  const int tr = m < n; /* GSL's SVD wants rows >= columns: use A^T */
  const int r = tr ? n : m, c = tr ? m : n;
  gsl_matrix *U = gsl_matrix_alloc((size_t)r, (size_t)c), *V = gsl_matrix_alloc((size_t)c, (size_t)c);
  gsl_vector *S = gsl_vector_alloc((size_t)c), *w = gsl_vector_alloc((size_t)c);
  for (int i = 0; i < m; i++)
    for (int j = 0; j < n; j++)
      gsl_matrix_set(U, (size_t)(tr ? j : i), (size_t)(tr ? i : j), A[n * i + j]);
  gsl_linalg_SV_decomp(U, V, S, w);
  const double s0 = gsl_vector_get(S, 0);
  int rank = 0;
  for (int k = 0; k < c; k++) {
    if (sv) sv[k] = gsl_vector_get(S, (size_t)k);
    if (gsl_vector_get(S, (size_t)k) > cut * s0) rank++;
  }
  /* A' = U S V^T (A' = A or A^T); A'^+ = V S^+ U^T; A^+ = (A'^+)^T if tr. */
  for (int i = 0; i < n; i++)
    for (int j = 0; j < m; j++) {
      double s = 0;
      for (int k = 0; k < rank; k++) {
        double a = tr ? gsl_matrix_get(U, (size_t)i, (size_t)k) : gsl_matrix_get(V, (size_t)i, (size_t)k);
        double b = tr ? gsl_matrix_get(V, (size_t)j, (size_t)k) : gsl_matrix_get(U, (size_t)j, (size_t)k);
        s += a * b / gsl_vector_get(S, (size_t)k);
      }
      X[m * i + j] = s;
    }
  gsl_matrix_free(U);
  gsl_matrix_free(V);
  gsl_vector_free(S);
  gsl_vector_free(w);
  return rank;
}

/* C (n x p) = A (n x k) B (k x p), row-major. */
static void matmul(const double *A, const double *B, double *C, int n, int k, int p)
{
  for (int i = 0; i < n; i++)
    for (int j = 0; j < p; j++) {
      double s = 0;
      for (int l = 0; l < k; l++) s += A[k * i + l] * B[p * l + j];
      C[p * i + j] = s;
    }
}

/* ---- J_d^+ and the conditioning ---- */
static void test_regular(void)
{
  const double L = length_scale();
  double e_pinv = 0, e_left = 0, e_rc = 0;
  for (int k = 0; k < 300; k++) {
    double q[3], qd[3], rc, X[3 * NA], Js[3 * NA], Xs[3 * NA];
    random_state(q, qd);
    if (!TU_TRUE(prru_check_regular(&model, &data, q, &rc) == PRRU_OK, "regular")) continue;
    pinv_svd(data.Jd, NA, 3, 1e-13, X, NULL);
    e_pinv = fmax(e_pinv, tu_relerr(data.Jdpinv, X, 3 * NA, 1e-300));
    double I[9];
    matmul(data.Jdpinv, data.Jd, I, 3, NA, 3);
    for (int i = 0; i < 3; i++) I[4 * i] -= 1.0;
    e_left = fmax(e_left, maxabs(I, 9));
    /* 1 / (|Js|_1 |Js^+|_1), Js = J_d diag(1/L, 1/L, 1), by the SVD. */
    for (int i = 0; i < NA; i++)
      for (int j = 0; j < 3; j++) Js[3 * i + j] = data.Jd[3 * i + j] / (j < 2 ? L : 1.0);
    pinv_svd(Js, NA, 3, 1e-13, Xs, NULL);
    double na = 0, nx = 0;
    for (int j = 0; j < 3; j++) {
      double c = 0;
      for (int i = 0; i < NA; i++) c += fabs(Js[3 * i + j]);
      na = fmax(na, c);
    }
    for (int j = 0; j < NA; j++) nx = fmax(nx, fabs(Xs[j]) + fabs(Xs[NA + j]) + fabs(Xs[2 * NA + j]));
    e_rc = fmax(e_rc, fabs(rc * na * nx - 1.0));
  }
  printf("J_d^+ vs GSL SVD %.1e, |J_d^+ J_d - I| %.1e, rcond vs 1/(|J|_1 |J^+|_1) by SVD %.1e\n",
         e_pinv, e_left, e_rc);
  tu_check(e_pinv <= 1e-12, "J_d^+ = GSL SVD pseudo-inverse", e_pinv, 1e-12);
  tu_check(e_left <= 1e-12, "J_d^+ J_d = I", e_left, 1e-12);
  tu_check(e_rc <= 1e-12, "rcond = 1 / (|J|_1 |J^+|_1)", e_rc, 1e-12);
}

/* ---- inverse dynamics, preload ---- */
static void test_inverse_dynamics(void)
{
  static const double zero_fd[NA] = {0};
  double e_tau = 0, e_svd = 0, e_fd = 0, e_pre = 0, e_null = 0, e_orth = 0;
  for (int k = 0; k < 300; k++) {
    double q[3], qd[3], qdd[3], fd[NA], fdt[NA], n[NA], M[9], b[3], tau[3];
    prru_loads l;
    random_state(q, qd);
    random_loads(&l);
    for (int i = 0; i < 3; i++) qdd[i] = tu_uniform(-3, 3);
    if (!TU_TRUE(prru_inverse_dynamics(&model, &data, q, qd, qdd, &l, fd) == PRRU_OK, "ID status"))
      continue;
    /* tau = M qdd - b(fd = 0) from the kernel directly. */
    prru_eom(q, qd, zero_fd, l.fp, l.mp, M, b);
    double Jd[3 * NA], X[3 * NA], scale = 1.0;
    prru_jd(q, Jd);
    for (int i = 0; i < 3; i++) {
      tau[i] = M[3 * i] * qdd[0] + M[3 * i + 1] * qdd[1] + M[3 * i + 2] * qdd[2] - b[i];
      scale = fmax(scale, fabs(tau[i]));
    }
    double jt[3];
    for (int j = 0; j < 3; j++) {
      jt[j] = 0;
      for (int i = 0; i < NA; i++) jt[j] += Jd[3 * i + j] * fd[i];
    }
    e_tau = fmax(e_tau, tu_relerr(jt, tau, 3, scale));
    /* Least norm: fd = (J_d^T)^+ tau = (J_d^+)^T tau, by GSL's SVD. */
    pinv_svd(Jd, NA, 3, 1e-13, X, NULL);
    double ref[NA];
    for (int i = 0; i < NA; i++) ref[i] = X[i] * tau[0] + X[NA + i] * tau[1] + X[2 * NA + i] * tau[2];
    e_svd = fmax(e_svd, tu_relerr(fd, ref, NA, 1.0));
    /* FD(ID(qdd)) = qdd. */
    prru_loads lf = l;
    memcpy(lf.fd, fd, sizeof fd);
    double a[3];
    if (TU_TRUE(prru_forward_dynamics(&model, &data, q, qd, &lf, a) == PRRU_OK, "FD status"))
      e_fd = fmax(e_fd, tu_relerr(a, qdd, 3, 1.0));
    const double t = tu_uniform(-100, 100);
    if (PRRU_NPRELOAD == 0) {
      TU_TRUE(prru_inverse_dynamics_preload(&model, &data, q, qd, qdd, &l, t, fdt) == PRRU_EINPUT,
              "a preload on a model without redundant actuators is refused");
      TU_TRUE(prru_actuator_null(&model, &data, q, n) == PRRU_EINPUT,
              "no null vector of J_d^T without redundant actuators");
      TU_TRUE(prru_inverse_dynamics_preload(&model, &data, q, qd, qdd, &l, 0.0, fdt) == PRRU_OK &&
                  memcmp(fdt, fd, sizeof fd) == 0,
              "preload 0 is prru_inverse_dynamics");
      continue;
    }
    if (!TU_TRUE(prru_actuator_null(&model, &data, q, n) == PRRU_OK, "null vector status") ||
        !TU_TRUE(prru_inverse_dynamics_preload(&model, &data, q, qd, qdd, &l, t, fdt) == PRRU_OK,
                 "ID with preload status"))
      continue;
    /* n: unit, J_d^T n = 0 (relative to |J_d|), n_NACT > 0. */
    double jn[3], nj = 0;
    for (int j = 0; j < 3; j++) {
      jn[j] = 0;
      for (int i = 0; i < NA; i++) {
        jn[j] += Jd[3 * i + j] * n[i];
        nj = fmax(nj, fabs(Jd[3 * i + j]));
      }
    }
    e_null = fmax(e_null, fmax(maxabs(jn, 3) / nj, fabs(sqrt(dotn(n, n, NA)) - 1.0)));
    TU_TRUE(n[NA - 1] > 0, "n_NACT > 0");
    /* fd is orthogonal to n (least norm); fd + t n exactly; same motion. */
    e_orth = fmax(e_orth, fabs(dotn(fd, n, NA)) / fmax(1.0, maxabs(fd, NA)));
    e_pre = fmax(e_pre, fabs(dotn(fdt, n, NA) - t) / fmax(fabs(t), maxabs(fd, NA)));
    memcpy(lf.fd, fdt, sizeof fdt);
    if (TU_TRUE(prru_forward_dynamics(&model, &data, q, qd, &lf, a) == PRRU_OK, "FD status"))
      e_fd = fmax(e_fd, tu_relerr(a, qdd, 3, 1.0));
    TU_TRUE(dotn(fd, fd, NA) <= dotn(fdt, fdt, NA), "the preload-free fd has the least norm");
  }
  printf("ID: J_d^T fd - tau %.1e, fd vs SVD least norm %.1e, FD(ID(qdd)) %.1e", e_tau, e_svd, e_fd);
  if (PRRU_NPRELOAD) printf(", |J_d^T n| %.1e, fd . n %.1e, fd_t . n - t %.1e", e_null, e_orth, e_pre);
  printf("\n");
  tu_check(e_tau <= 1e-12, "J_d^T fd = tau", e_tau, 1e-12);
  tu_check(e_svd <= 1e-10, "fd = the least-norm solution (GSL SVD)", e_svd, 1e-10);
  tu_check(e_fd <= 1e-10, "FD(ID(qdd)) = qdd, with and without preload", e_fd, 1e-10);
  tu_check(e_null <= 1e-13, "n unit and in null(J_d^T)", e_null, 1e-13);
  tu_check(e_orth <= 1e-12, "fd . n = 0", e_orth, 1e-12);
  tu_check(e_pre <= 1e-12, "fd . n = preload", e_pre, 1e-12);
  if (PRRU_NPRELOAD) {
    /* n at the home orientation, for the record (models/4prru.json:
     * (-1, -1, 1, 1)/2, limbs 3 and 4 against limbs 1 and 2). */
    double q0[3] = {0, 0, -0.8}, n[NA];
    if (prru_actuator_null(&model, &data, q0, n) == PRRU_OK) {
      printf("n at q = (0, 0, -0.8): (");
      for (int i = 0; i < NA; i++) printf("%s%.6f", i ? ", " : "", n[i]);
      printf(")\n");
    }
    prru_loads l;
    memset(&l, 0, sizeof l);
    double fd[NA];
    TU_TRUE(prru_inverse_dynamics_preload(&model, &data, q0, q0, q0, &l, NAN, fd) == PRRU_EINPUT,
            "a NaN preload is refused");
  }
}

/* ---- reactions ---- */
/* Fbar (eq. 28) from the descriptor: gravity, the drives' net forces on
 * the sliders, fp at O' and mp, reduced to each body's centre. */
static void applied(const double q[3], const double qd[3], const double qdd[3],
                    const prru_loads *l, const double *p, double F[NH])
{
  const prru_mechanism *me = &prru_mech;
  double Jd[3 * NA], dd[NA], ddb[NA];
  prru_jd(q, Jd);
  prru_actuator_rates(q, qd, dd, ddb);
  memset(F, 0, NH * sizeof F[0]);
  for (int b = 0; b < NB; b++)
    for (int k = 0; k < 3; k++) F[3 * NB + 3 * b + k] = me->mass[b] * me->gravity[k];
  for (int i = 0; i < NA; i++) {
    double acc = ddb[i] + Jd[3 * i] * qdd[0] + Jd[3 * i + 1] * qdd[1] + Jd[3 * i + 2] * qdd[2];
    double f = l->fd[i] - me->armature[i] * acc - me->damping[i] * dd[i];
    if (me->coulomb[i] != 0) f -= me->coulomb[i] * tanh(dd[i] / me->coulomb_velocity);
    F[3 * NB + 3 * me->slider[i] + 2] += f;
  }
  const double *pp = p + 3 * me->platform;
  double r[3] = {-pp[0], -pp[1], q[2] - pp[2]}, rxf[3];
  tu_cross(r, l->fp, rxf);
  for (int k = 0; k < 3; k++) {
    F[3 * me->platform + k] += l->mp[k] + rxf[k];
    F[3 * NB + 3 * me->platform + k] += l->fp[k];
  }
}

static double q_frob(const double *Q)
{
  double s = 0;
  for (int i = 0; i < NH * NL; i++) s += Q[i] * Q[i];
  return sqrt(s);
}

static void test_reactions(void)
{
  const prru_mechanism *me = &prru_mech;
  static double H[3 * NH], dm[NH], Q[NH * NL], R[9 * NB], p[3 * NB], I[9 * NB], K[NH], F[NH],
      w[NH], Qp[NL * NH];
  double e_eq28 = 0, e_svd = 0, e_lz = 0, e_qz = 0,
         e_zshape = 0, e_zfield = 0, worst_lambda = 0;
  int rank_min = NL, rank_max = 0, zsign_ok = 1;
  for (int k = 0; k < 200; k++) {
    double q[3], qd[3], lam[NL], z[NL], qdd[3];
    prru_loads l;
    random_state(q, qd);
    random_loads(&l);
    if (!TU_TRUE(prru_reactions(&model, &data, q, qd, &l, lam) == PRRU_OK, "reactions status"))
      continue;
    memcpy(qdd, data.qdd, sizeof qdd);
    double zfield[NL];
    memcpy(zfield, data.lambda_null, sizeof zfield);
    worst_lambda = fmax(worst_lambda, maxabs(lam, NL));
    prru_jacobians(q, H);
    prru_bias_terms(q, qd, dm);
    tu_reaction_basis_dense(q, Q);
    prru_poses(q, R, p);
    prru_inertia_world(q, I);
    prru_wrench_bias(q, qd, K);
    applied(q, qd, qdd, &l, p, F);
    /* w = Phi H qdd + K - Fbar, body by body. */
    double scale = 1.0;
    for (int b = 0; b < NB; b++) {
      double al[3], ac[3];
      for (int i = 0; i < 3; i++) {
        al[i] = H[3 * (3 * b + i)] * qdd[0] + H[3 * (3 * b + i) + 1] * qdd[1] + H[3 * (3 * b + i) + 2] * qdd[2];
        const int t = 3 * NB + 3 * b + i;
        ac[i] = H[3 * t] * qdd[0] + H[3 * t + 1] * qdd[1] + H[3 * t + 2] * qdd[2];
      }
      for (int i = 0; i < 3; i++) {
        const int t = 3 * NB + 3 * b + i;
        w[3 * b + i] = I[9 * b + 3 * i] * al[0] + I[9 * b + 3 * i + 1] * al[1] +
                       I[9 * b + 3 * i + 2] * al[2] + K[3 * b + i] - F[3 * b + i];
        w[t] = me->mass[b] * ac[i] + K[t] - F[t];
        scale = fmax(scale, fmax(fabs(F[3 * b + i]), fabs(F[t])));
        scale = fmax(scale, fmax(fabs(w[3 * b + i]), fabs(w[t])));
      }
    }
    double ql[NH];
    matmul(Q, lam, ql, NH, NL, 1);
    e_eq28 = fmax(e_eq28, tu_relerr(ql, w, NH, scale));
    /* Least-norm solution of Q lambda = w by a dense SVD of Q (78x76 for
     * the 4-PRRU, rank 75; 60x57 full rank for three limbs). */
    double sv[NL], ref[NL];
    int rank = pinv_svd(Q, NH, NL, 1e-11, Qp, sv);
    rank_min = rank < rank_min ? rank : rank_min;
    rank_max = rank > rank_max ? rank : rank_max;
    matmul(Qp, w, ref, NL, NH, 1);
    e_svd = fmax(e_svd, tu_relerr(lam, ref, NL, 1.0));
    if (PRRU_NREACTION_NULL == 0) {
      TU_TRUE(maxabs(zfield, NL) == 0, "no null direction: d->lambda_null is 0");
      TU_TRUE(prru_reaction_null(&model, &data, q, z) == PRRU_EINPUT,
              "prru_reaction_null refused without a redundant direction");
    } else if (TU_TRUE(prru_reaction_null(&model, &data, q, z) == PRRU_OK, "reaction null status")) {
      e_zfield = fmax(e_zfield, tu_relerr(zfield, z, NL, 1.0));
      double qz[NH];
      matmul(Q, z, qz, NH, NL, 1);
      e_qz = fmax(e_qz, maxabs(qz, NH) / q_frob(Q));
      e_lz = fmax(e_lz, fabs(dotn(lam, z, NL)) / maxabs(lam, NL));
      TU_TRUE(fabs(sqrt(dotn(z, z, NL)) - 1.0) <= 1e-14, "|z| = 1");
      /* Shape (spec 12): only the joints of limbs 3 and 4 (0-based 2, 3);
       * their forces along e2 only, all of one magnitude f; C3's force
       * along e2 = +f (the sign convention), C4's = -f. */
      double f = 0;
      for (int j = 0; j < PRRU_NJOINT; j++) {
        const prru_joint_info *jt = &me->joint[j];
        const double *zj = z + jt->lambda_offset;
        if (jt->limb < 2) {
          e_zshape = fmax(e_zshape, maxabs(zj, jt->lambda_count));
          continue;
        }
        /* force coordinates: e1, e2(, e3) first (P joints: e1, e2). */
        e_zshape = fmax(e_zshape, fabs(zj[0]));
        if (jt->type != 'P') e_zshape = fmax(e_zshape, fabs(zj[2]));
        if (f == 0) f = fabs(zj[1]);
        e_zshape = fmax(e_zshape, fabs(fabs(zj[1]) - f));
        if (jt->type == 'U') zsign_ok &= jt->limb == 2 ? zj[1] > 0 : zj[1] < 0;
      }
    }
  }
  /* The platform's Newton-Euler and the machine's force balance are
   * test_runtime's, for every model. */
  printf("reactions (max |lambda| %.0f): eq. 28 residual %.1e, vs dense SVD least norm %.1e "
         "(rank of Q %d..%d of %d)\n",
         worst_lambda, e_eq28, e_svd, rank_min, rank_max, NL);
  tu_check(e_eq28 <= 1e-10, "Q lambda = Phi H qdd + K - Fbar (eq. 28)", e_eq28, 1e-10);
  tu_check(e_svd <= 1e-10, "lambda = least-norm solution of a dense SVD solve", e_svd, 1e-10);
  TU_TRUE(rank_min == NH - 3 && rank_max == NH - 3, "rank Q = 6 NBODY - 3 everywhere");
  if (PRRU_NREACTION_NULL) {
    printf("null direction z: |Q z| / |Q|_F %.1e, lambda . z / |lambda| %.1e, shape %.1e, "
           "d->lambda_null vs prru_reaction_null %.1e\n", e_qz, e_lz, e_zshape, e_zfield);
    tu_check(e_qz <= 1e-14, "Q z = 0", e_qz, 1e-14);
    tu_check(e_lz <= 1e-13, "lambda . z = 0 (least norm)", e_lz, 1e-13);
    tu_check(e_zshape <= 1e-12, "z: a force along e2 through limbs 3 and 4 only", e_zshape, 1e-12);
    tu_check(e_zfield == 0, "d->lambda_null = prru_reaction_null", e_zfield, 0);
    TU_TRUE(zsign_ok, "z: C3 pushes the platform along +e2, C4 along -e2");
  }
}

/* A = Q^T Phi^-1 Q at q, from the generated basis and the world-frame
 * inertias (Phi^-1 body by body: I_b^-1 by GSL's LU, 1/m_b). */
static void phi_inv_gram(const double q[3], gsl_matrix *A)
{
  static double Q[NH * NL], I[9 * NB], Y[NH * NL];
  tu_reaction_basis_dense(q, Q);
  prru_inertia_world(q, I);
  for (int b = 0; b < NB; b++) {
    double Ib[9], Iinv[9];
    memcpy(Ib, I + 9 * b, sizeof Ib);
    gsl_matrix_view Iv = gsl_matrix_view_array(Ib, 3, 3), Jv = gsl_matrix_view_array(Iinv, 3, 3);
    gsl_permutation *perm = gsl_permutation_alloc(3);
    int sgn;
    gsl_linalg_LU_decomp(&Iv.matrix, perm, &sgn);
    gsl_linalg_LU_invert(&Iv.matrix, perm, &Jv.matrix);
    gsl_permutation_free(perm);
    for (int c = 0; c < NL; c++)
      for (int i = 0; i < 3; i++) {
        double s = 0;
        for (int k = 0; k < 3; k++) s += Iinv[3 * i + k] * Q[NL * (3 * b + k) + c];
        Y[NL * (3 * b + i) + c] = s;
        Y[NL * (3 * NB + 3 * b + i) + c] = Q[NL * (3 * NB + 3 * b + i) + c] / prru_mech.mass[b];
      }
  }
  for (int a = 0; a < NL; a++)
    for (int c = 0; c < NL; c++) {
      double s = 0;
      for (int r = 0; r < NH; r++) s += Q[NL * r + a] * Y[NL * r + c];
      gsl_matrix_set(A, (size_t)a, (size_t)c, s);
    }
}

/* The spectrum of A = Q^T Phi^-1 Q over a grid of the workspace: the
 * structural null eigenvalue(s) and the smallest other one, relative to the
 * largest (the reactions are determined up to the structural null
 * direction alone, well away from any other), and every regular pose
 * solved. */
static void test_reaction_spectrum(void)
{
  const int n1 = 13, n2 = 13;
  double worst_null = 0, worst_gap = INFINITY;
  int solved = 0, regular = 0;
  gsl_eigen_symm_workspace *ws = gsl_eigen_symm_alloc(NL);
  gsl_matrix *A = gsl_matrix_alloc(NL, NL);
  gsl_vector *ev = gsl_vector_alloc(NL);
  for (int i = 0; i < n1; i++)
    for (int j = 0; j < n2; j++) {
      double q[3] = {-0.6 + 1.2 * i / (n1 - 1), -0.8 + 1.4 * j / (n2 - 1), -0.8}, qd[3] = {0.3, -0.2, 0.1};
      if (prru_check_regular(&model, &data, q, NULL) != PRRU_OK) continue;
      regular++;
      prru_loads l;
      memset(&l, 0, sizeof l);
      double lam[NL];
      if (prru_reactions(&model, &data, q, qd, &l, lam) != PRRU_OK) continue;
      solved++;
      phi_inv_gram(q, A);
      gsl_eigen_symm(A, ev, ws);
      gsl_sort_vector(ev);
      double top = gsl_vector_get(ev, NL - 1);
      for (int k = 0; k < PRRU_NREACTION_NULL; k++)
        worst_null = fmax(worst_null, fabs(gsl_vector_get(ev, (size_t)k)) / top);
      worst_gap = fmin(worst_gap, gsl_vector_get(ev, PRRU_NREACTION_NULL) / top);
    }
  gsl_eigen_symm_free(ws);
  gsl_matrix_free(A);
  gsl_vector_free(ev);
  printf("Q^T Phi^-1 Q over %d regular poses: null eigenvalue(s) <= %.1e, the others >= %.1e "
         "(relative to the largest)\n", regular, worst_null, worst_gap);
  TU_TRUE(solved == regular && regular > 50, "reactions solve at every regular grid pose");
  tu_check(worst_gap >= 1e-8, "the non-null spectrum is well separated from 0", worst_gap, 1e-8);
}

/* ---- forward kinematics ---- */
static void test_fk(void)
{
  const double L = length_scale();
  double worst = 0, worst_far = 0, worst_lsq = 0, e_first = 0;
  int fails = 0, fails_far = 0;
  for (int k = 0; k < 300; k++) {
    double q[3], qd[3], act[NA], seed[3], sol[3], res;
    random_state(q, qd);
    prru_ik(q, act);
    for (int i = 0; i < 3; i++) seed[i] = q[i] + tu_uniform(-0.05, 0.05);
    if (prru_forward_kinematics(&model, &data, act, seed, sol) != PRRU_OK) fails++;
    else worst = fmax(worst, tu_relerr(sol, q, 3, 1.0));
    if (prru_forward_kinematics_lsq(&model, &data, act, seed, sol, &res) == PRRU_OK)
      worst_lsq = fmax(worst_lsq, fmax(tu_relerr(sol, q, 3, 1.0), res / L));
    else
      TU_TRUE(0, "least-squares FK of a consistent d");
    /* A far seed: home orientation at the mean height (as the CLI seeds). */
    double d0[NA], z3[3] = {0, 0, 0}, sum = 0;
    prru_ik(z3, d0);
    for (int i = 0; i < NA; i++) sum += act[i] - d0[i];
    double far[3] = {0, 0, sum / NA};
    if (prru_forward_kinematics(&model, &data, act, far, sol) != PRRU_OK) fails_far++;
    else worst_far = fmax(worst_far, tu_relerr(sol, q, 3, 1.0));
    if (PRRU_NPRELOAD == 1) {
      /* The fourth slider off by delta: no pose; least squares leaves, to
       * first order, the residual (I - J J^+) delta e_4 = n n_4 delta. */
      const double delta = 1e-4 * L;
      double bad[NA], n[NA];
      memcpy(bad, act, sizeof bad);
      bad[NA - 1] += delta;
      TU_TRUE(prru_forward_kinematics(&model, &data, bad, seed, sol) == PRRU_ENOCONV,
              "FK of an inconsistent d fails with PRRU_ENOCONV");
      if (TU_TRUE(prru_actuator_null(&model, &data, q, n) == PRRU_OK, "null") &&
          TU_TRUE(prru_forward_kinematics_lsq(&model, &data, bad, seed, sol, &res) == PRRU_OK,
                  "least-squares FK of an inconsistent d")) {
        double expect = fabs(n[NA - 1]) * maxabs(n, NA) * delta;
        e_first = fmax(e_first, fabs(res - expect) / expect);
      }
    }
  }
  printf("FK(IK(q)) %.1e (nearby seeds), %.1e (far seeds, %d failed), least squares %.1e", worst,
         worst_far, fails_far, worst_lsq);
  if (PRRU_NPRELOAD) printf(", inconsistent d: residual vs first order %.1e", e_first);
  printf("\n");
  tu_check(fails == 0, "FK converges from a nearby seed", fails, 0);
  tu_check(worst <= 1e-12, "FK(IK(q)) = q", worst, 1e-12);
  tu_check(worst_lsq <= 1e-12, "least-squares FK of a consistent d: q and residual 0", worst_lsq, 1e-12);
  tu_check(fails_far <= 3, "FK converges from the home-orientation seed", fails_far, 3);
  tu_check(worst_far <= 1e-12, "FK(IK(q)) = q from the far seed", worst_far, 1e-12);
  if (PRRU_NPRELOAD) tu_check(e_first <= 1e-3, "least-squares residual = n_4 n delta to first order", e_first, 1e-3);
  double nan_act[NA], seed[3] = {0, 0, -0.8}, sol[3], res;
  for (int i = 0; i < NA; i++) nan_act[i] = 0.0;
  nan_act[NA - 1] = NAN;
  TU_TRUE(prru_forward_kinematics(&model, &data, nan_act, seed, sol) == PRRU_EINPUT &&
              prru_forward_kinematics_lsq(&model, &data, nan_act, seed, sol, &res) == PRRU_EINPUT,
          "FK of a NaN d (last slider)");
  /* Finite but so far out that |r|^2 overflows: refused, not "fitted". */
  double huge[NA];
  for (int i = 0; i < NA; i++) huge[i] = i == 0 ? 1e200 : 0.0;
  TU_TRUE(prru_forward_kinematics_lsq(&model, &data, huge, seed, sol, &res) == PRRU_EINPUT,
          "least-squares FK of a d whose residual overflows is refused");
}

/* ---- DME with J_d^+ ---- */
/* w_R, Mt, JtR by GSL SVDs from the kernels' M, J_d and J_R,P. */
static int dme_svd(const double q[3], double *w_R, double Mt[NA * NA], double JtR[3 * NA])
{
  double M[9], Jd[3 * NA], X[3 * NA], JP[18], tmp[3 * NA], B[3 * NA], sv[3];
  prru_mass(q, M);
  prru_jd(q, Jd);
  prru_platform_jacobian(q, JP);
  if (pinv_svd(Jd, NA, 3, 1e-13, X, NULL) != 3) return 1;
  matmul(M, X, tmp, 3, 3, NA);
  double Xt[3 * NA];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < NA; j++) Xt[3 * j + i] = X[NA * i + j];
  matmul(Xt, tmp, Mt, NA, 3, NA);
  matmul(JP, X, JtR, 3, 3, NA); /* rows 0-2: J_R,P */
  double JtRp[3 * NA];
  if (pinv_svd(JtR, 3, NA, 1e-10, JtRp, NULL) != 2) return 1;
  matmul(Mt, JtRp, B, NA, NA, 3);
  pinv_svd(B, NA, 3, 0.0, tmp, sv); /* only the singular values */
  *w_R = sv[0] / sv[1];
  return sv[2] > 1e-10 * sv[0];
}

static void test_dme(void)
{
  prru_dme out;
  double w, Mt[NA * NA], JtR[3 * NA];
  const double q0[3] = {0, 0, 0};
  if (TU_TRUE(prru_dme_eval(&model, &data, q0, &out) == PRRU_OK, "DME at q = 0") &&
      TU_TRUE(dme_svd(q0, &w, Mt, JtR) == 0, "independent DME at q = 0")) {
    printf("w_R at q = 0: runtime %.15f, GSL SVDs %.15f (sigma %.9g, %.9g), difference %.1e\n",
           out.w_R, w, out.sigma[0], out.sigma[1], fabs(out.w_R - w) / w);
    tu_check(fabs(out.w_R - w) <= 1e-12 * w, "w_R(0) = GSL SVD of Mt JtR^+", fabs(out.w_R - w) / w, 1e-12);
  }
  double e_w = 0, e_mt = 0, e_jtr = 0;
  int n = 0;
  for (int k = 0; k < 300; k++) {
    double q[3], qd[3];
    random_state(q, qd);
    if (prru_dme_eval(&model, &data, q, &out) != PRRU_OK || dme_svd(q, &w, Mt, JtR) != 0) continue;
    n++;
    e_w = fmax(e_w, fabs(out.w_R - w) / w);
    e_mt = fmax(e_mt, tu_relerr(out.Mt, Mt, NA * NA, 1e-300));
    e_jtr = fmax(e_jtr, tu_relerr(out.JtR, JtR, 3 * NA, 1e-300));
  }
  printf("DME over %d poses vs GSL SVDs: w_R %.1e, Mt %.1e, JtR %.1e\n", n, e_w, e_mt, e_jtr);
  TU_TRUE(n >= 250, "DME regular at most random poses");
  tu_check(e_w <= 1e-10, "w_R = GSL SVD", e_w, 1e-10);
  tu_check(e_mt <= 1e-11, "Mt = J_d^+T M J_d^+", e_mt, 1e-11);
  tu_check(e_jtr <= 1e-11, "JtR = J_R,P J_d^+", e_jtr, 1e-11);
}

/* ---- timing (printed, not checked) ---- */
static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void time_reactions(void)
{
  enum { NS = 64 };
  static double qs[NS][3], qds[NS][3];
  static prru_loads ls[NS];
  for (int k = 0; k < NS; k++) {
    random_state(qs[k], qds[k]);
    random_loads(&ls[k]);
  }
  double lam[NL];
  volatile double sink = 0;
  long n = 0;
  double t0 = now(), t;
  do {
    for (int k = 0; k < NS; k++, n++) {
      prru_reactions(&model, &data, qs[k], qds[k], &ls[k], lam);
      sink += lam[0];
    }
  } while ((t = now() - t0) < 0.3);
  printf("prru_reactions (%d limbs, %d coordinates): %.2f us per call (%ld calls)\n", PRRU_NLIMB,
         NL, 1e6 * t / (double)n, n);
}

int main(void)
{
  gsl_set_error_handler_off();
  prru_model_default(&model);
  test_regular();
  test_inverse_dynamics();
  test_reactions();
  test_reaction_spectrum();
  test_fk();
  test_dme();
  time_reactions();
  return tu_finish("test_redundant");
}
