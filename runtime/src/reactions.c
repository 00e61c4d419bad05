/* Equations of reaction (spec section 7, paper eq. 31):
 *   lambda = (Q^T Phi^-1 Q)^-1 Q^T Phi^-1 (K - Fbar).
 * Phi is block diagonal, so Phi^-1 is applied body by body (R D^-1 R^T and
 * 1/m), and every column of Q touches at most two bodies (the two ends of
 * its joint), so Q^T Phi^-1 Q is accumulated body by body over the columns
 * that body sees: the dense 60x60 products of the reference are never
 * formed. The 57x57 system is SPD (Q has full column rank): Cholesky in
 * the arrowhead order below.
 *
 * The redundant 4-PRRU (spec section 12): 76 coordinates, 78 - 3 = 75
 * independent equations, so Q has a one-dimensional null space and
 * Q^T Phi^-1 Q (76x76) is positive semidefinite of rank 75. Its limb
 * blocks stay SPD (each limb alone is a serial chain from the rail); the
 * singular part is the Schur complement S of the U-joint block (16x16).
 * That one is factored by Cholesky with diagonal pivoting, stopped after
 * rank(S) = 15 steps (the rank is structural: PRRU_NREACTION_NULL); the
 * pivoting puts the null direction last, so the factor gives one
 * particular solution and S's null vector, which the limb blocks extend to
 * the null vector z of the whole matrix; the reactions are then the
 * particular solution less its component along z (least norm). */
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "prru.h"
#include "internal.h"

#define NL PRRU_NLAMBDA
#define NB PRRU_NBODY
#define NH PRRU_NH

#if PRRU_NREACTION_NULL < 0 || PRRU_NREACTION_NULL > 1
#error "the reactions handle at most one redundant reaction direction"
#endif

/* Body b's six rows of the stacking: 3b..3b+2 rotational, 3 NB + 3b..
 * translational. */
static int body_row(int b, int k) { return k < 3 ? 3 * b + k : 3 * NB + 3 * b + (k - 3); }

/* The force the drive delivers to slider i: the actuator force less what
 * the armature takes to accelerate (k_i dd_i'') and the drive's damping and
 * friction, -c_i dd_i - f_i tanh(dd_i / v_s) (zero for format-1 models). */
static void slider_forces(const prru_mechanism *me, const prru_data *d, const double q[3],
                          const double qd[3], const prru_loads *l, double f[PRRU_NACT])
{
  double dd[PRRU_NACT], ddb[PRRU_NACT];
  int drives = 0;
  for (int i = 0; i < PRRU_NACT; i++) {
    f[i] = l->fd[i];
    drives |= me->armature[i] != 0 || me->damping[i] != 0 || me->coulomb[i] != 0;
  }
  if (!drives) return;
  prru_actuator_rates(q, qd, dd, ddb);
  for (int i = 0; i < PRRU_NACT; i++) {
    double acc = ddb[i];
    for (int j = 0; j < 3; j++) acc += d->Jd[3 * i + j] * d->qdd[j];
    f[i] -= me->armature[i] * acc + me->damping[i] * dd[i];
    if (me->coulomb[i] != 0) f[i] -= me->coulomb[i] * tanh(dd[i] / me->coulomb_velocity);
  }
}

/* Fbar: gravity on every body, the drives' forces along +e3 on the
 * sliders, the platform force at the tool point O' = (0, 0, q3) and the
 * platform moment, both reduced to the platform's centre p (which differs
 * from O' when the platform's centre of mass is offset). */
static void applied_wrenches(const prru_mechanism *me, const double fs[PRRU_NACT],
                             const prru_loads *l, const double q[3], const double p[3 * NB],
                             double F[NH])
{
  memset(F, 0, NH * sizeof F[0]);
  for (int b = 0; b < NB; b++)
    for (int k = 0; k < 3; k++) F[body_row(b, 3 + k)] = me->mass[b] * me->gravity[k];
  for (int i = 0; i < PRRU_NACT; i++) F[body_row(me->slider[i], 5)] += fs[i];
  const double *pp = p + 3 * me->platform;
  double r[3] = {-pp[0], -pp[1], q[2] - pp[2]}; /* O' - p */
  double rxf[3] = {r[1] * l->fp[2] - r[2] * l->fp[1], r[2] * l->fp[0] - r[0] * l->fp[2],
                   r[0] * l->fp[1] - r[1] * l->fp[0]};
  for (int k = 0; k < 3; k++) {
    F[body_row(me->platform, k)] += l->mp[k] + rxf[k];
    F[body_row(me->platform, 3 + k)] += l->fp[k];
  }
}

/* Q^T Phi^-1 Q couples a limb's own joints (B, A, P) only with themselves
 * and with the platform's U joints: no body touches two limbs except the
 * platform. Ordered limb by limb, then the U joints, it is an arrowhead
 * matrix whose Cholesky factor has no fill outside the limbs' diagonal
 * blocks and the U rows, so the factorization visits only those: about a
 * third of a dense Cholesky. The blocks come from the descriptor's joint
 * table. */
typedef struct {
  int pos[NL];                  /* arrowhead position of lambda coordinate c */
  int start[PRRU_NLIMB], len[PRRU_NLIMB];
  int c0, nc;                   /* the U-joint block */
} arrowhead;

static void arrowhead_layout(const prru_mechanism *me, arrowhead *a)
{
  int at = 0;
  for (int k = 0; k < PRRU_NLIMB; k++) {
    a->start[k] = at;
    for (int j = 0; j < PRRU_NJOINT; j++) {
      const prru_joint_info *jt = &me->joint[j];
      if (jt->type == 'U' || jt->limb != k) continue;
      for (int c = 0; c < jt->lambda_count; c++) a->pos[jt->lambda_offset + c] = at++;
    }
    a->len[k] = at - a->start[k];
  }
  a->c0 = at;
  for (int j = 0; j < PRRU_NJOINT; j++) {
    const prru_joint_info *jt = &me->joint[j];
    if (jt->type != 'U') continue;
    for (int c = 0; c < jt->lambda_count; c++) a->pos[jt->lambda_offset + c] = at++;
  }
  a->nc = at - a->c0;
}

#if PRRU_NREACTION_NULL == 0
/* Solves A x = r (x returned in r), A the 57x57 SPD matrix in lambda
 * order, by block Cholesky in the arrowhead order with GSL:
 *   A = [L_k 0; W_k^T L_C] [L_k^T W_k; 0 L_C^T],  A_kk = L_k L_k^T,
 *   W_k = L_k^-1 A_kC,  L_C L_C^T = A_CC - sum_k W_k^T W_k.
 * P is scratch (57x57). */
static int solve_arrowhead(const arrowhead *a, const double *A, double *r, double *P)
{
  const int *pos = a->pos;
  double y[NL];
  for (int i = 0; i < NL; i++) {
    y[pos[i]] = r[i];
    for (int j = 0; j < NL; j++) P[pos[i] * NL + pos[j]] = A[i * NL + j];
  }
  const size_t C0 = (size_t)a->c0, NC = (size_t)a->nc;
  gsl_matrix_view Pm = gsl_matrix_view_array(P, NL, NL);
  gsl_matrix_view S = gsl_matrix_submatrix(&Pm.matrix, C0, C0, NC, NC);
  gsl_vector_view yv = gsl_vector_view_array(y, NL);
  gsl_vector_view yC = gsl_vector_subvector(&yv.vector, C0, NC);
  int st = GSL_SUCCESS;
  for (size_t k = 0; k < PRRU_NLIMB && st == GSL_SUCCESS; k++) {
    const size_t s0 = (size_t)a->start[k], L = (size_t)a->len[k];
    gsl_matrix_view Lk = gsl_matrix_submatrix(&Pm.matrix, s0, s0, L, L);
    gsl_matrix_view Wk = gsl_matrix_submatrix(&Pm.matrix, s0, C0, L, NC);
    gsl_vector_view yk = gsl_vector_subvector(&yv.vector, s0, L);
    st = gsl_linalg_cholesky_decomp1(&Lk.matrix);
    if (st != GSL_SUCCESS) break;
    gsl_blas_dtrsm(CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, 1.0, &Lk.matrix, &Wk.matrix);
    gsl_blas_dsyrk(CblasLower, CblasTrans, -1.0, &Wk.matrix, 1.0, &S.matrix);
    gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, &Lk.matrix, &yk.vector);
    gsl_blas_dgemv(CblasTrans, -1.0, &Wk.matrix, &yk.vector, 1.0, &yC.vector);
  }
  if (st == GSL_SUCCESS) st = gsl_linalg_cholesky_decomp1(&S.matrix);
  if (st == GSL_SUCCESS) {
    gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, &S.matrix, &yC.vector);
    gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &S.matrix, &yC.vector);
    for (size_t k = 0; k < PRRU_NLIMB; k++) {
      const size_t s0 = (size_t)a->start[k], L = (size_t)a->len[k];
      gsl_matrix_view Lk = gsl_matrix_submatrix(&Pm.matrix, s0, s0, L, L);
      gsl_matrix_view Wk = gsl_matrix_submatrix(&Pm.matrix, s0, C0, L, NC);
      gsl_vector_view yk = gsl_vector_subvector(&yv.vector, s0, L);
      gsl_blas_dgemv(CblasNoTrans, -1.0, &Wk.matrix, &yC.vector, 1.0, &yk.vector);
      gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &Lk.matrix, &yk.vector);
    }
  }
  if (st != GSL_SUCCESS) return PRRU_ESINGULAR;
  for (int c = 0; c < NL; c++) r[c] = y[pos[c]];
  return PRRU_OK;
}

#endif

#if PRRU_NREACTION_NULL == 1
/* Pivots of S below PIVOT_TOL times its largest diagonal entry are rank
 * loss beyond the structural one (a constraint singularity):
 * PRRU_ESINGULAR. The one dropped pivot must be below NULL_TOL times it:
 * otherwise S is not of the structural rank and the system is not what
 * this solver assumes (PRRU_ESINGULAR too; never seen on a valid model).
 * Measured on models/4prru.json at the 93444 regular poses of a
 * 201 x 201 x 3 grid (q1 in [-1.2, 1.2], q2 in [-1.4, 1], q3 = -0.5,
 * -0.65, -0.8; J_d's rcond down to the default 1e-8): kept pivots (squared
 * factor entries) at least 1.8e-7 of the largest, the dropped one at most
 * 2.4e-16. */
#define PIVOT_TOL 1e-10
#define NULL_TOL 1e-9

/* As solve_arrowhead, for the singular case: r (NULL: none, z only) is
 * replaced by the solution of least norm, z by the unit null vector
 * (lambda order; sign: see prru_reaction_null). */
static int solve_arrowhead_null(const arrowhead *a, const double *A, double *r, double *P,
                                double z[NL])
{
  const int *pos = a->pos;
  double y[NL], zz[NL];
  for (int i = 0; i < NL; i++) {
    y[pos[i]] = r ? r[i] : 0.0;
    for (int j = 0; j < NL; j++) P[pos[i] * NL + pos[j]] = A[i * NL + j];
  }
  const size_t C0 = (size_t)a->c0, NC = (size_t)a->nc, RK = NC - 1;
  gsl_matrix_view Pm = gsl_matrix_view_array(P, NL, NL);
  gsl_matrix_view S = gsl_matrix_submatrix(&Pm.matrix, C0, C0, NC, NC);
  gsl_vector_view yv = gsl_vector_view_array(y, NL), zv = gsl_vector_view_array(zz, NL);
  gsl_vector_view yC = gsl_vector_subvector(&yv.vector, C0, NC);
  gsl_vector_view zC = gsl_vector_subvector(&zv.vector, C0, NC);
  /* The limbs: A_kk = L_k L_k^T, W_k = L_k^-1 A_kC, S = A_CC - sum W_k^T W_k,
   * y_k = L_k^-1 r_k, y_C = r_C - sum W_k^T y_k. */
  for (size_t k = 0; k < PRRU_NLIMB; k++) {
    const size_t s0 = (size_t)a->start[k], L = (size_t)a->len[k];
    gsl_matrix_view Lk = gsl_matrix_submatrix(&Pm.matrix, s0, s0, L, L);
    gsl_matrix_view Wk = gsl_matrix_submatrix(&Pm.matrix, s0, C0, L, NC);
    gsl_vector_view yk = gsl_vector_subvector(&yv.vector, s0, L);
    if (gsl_linalg_cholesky_decomp1(&Lk.matrix) != GSL_SUCCESS) return PRRU_ESINGULAR;
    gsl_blas_dtrsm(CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, 1.0, &Lk.matrix, &Wk.matrix);
    gsl_blas_dsyrk(CblasLower, CblasTrans, -1.0, &Wk.matrix, 1.0, &S.matrix);
    gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, &Lk.matrix, &yk.vector);
    gsl_blas_dgemv(CblasTrans, -1.0, &Wk.matrix, &yk.vector, 1.0, &yC.vector);
  }
  /* S (its lower triangle is current) by Cholesky with diagonal pivoting,
   * in place on the full symmetric block: P S P^T = [L11 0; l21 1] [L11^T
   * l21^T; 0 s], s the dropped pivot, perm[i] = S's row at position i. */
  double *Sd = S.matrix.data;
  const size_t ld = S.matrix.tda;
#define SE(i, j) Sd[(i) * ld + (j)]
  for (size_t i = 0; i < NC; i++)
    for (size_t j = i + 1; j < NC; j++) SE(i, j) = SE(j, i);
  size_t perm[NL];
  for (size_t i = 0; i < NC; i++) perm[i] = i;
  double d0 = 0;
  for (size_t i = 0; i < NC; i++) d0 = fmax(d0, SE(i, i));
  if (!(d0 > 0) || !isfinite(d0)) return PRRU_ESINGULAR;
  for (size_t k = 0; k < NC; k++) {
    size_t p = k;
    for (size_t i = k + 1; i < NC; i++)
      if (SE(i, i) > SE(p, p)) p = i;
    if (p != k) {
      for (size_t j = 0; j < NC; j++) {
        double t = SE(k, j);
        SE(k, j) = SE(p, j), SE(p, j) = t;
      }
      for (size_t i = 0; i < NC; i++) {
        double t = SE(i, k);
        SE(i, k) = SE(i, p), SE(i, p) = t;
      }
      size_t t = perm[k];
      perm[k] = perm[p], perm[p] = t;
    }
    if (k == RK) break; /* the dropped pivot, s = SE(RK, RK) */
    double piv = SE(k, k);
    if (!(piv > PIVOT_TOL * d0)) return PRRU_ESINGULAR;
    piv = sqrt(piv);
    SE(k, k) = piv;
    for (size_t i = k + 1; i < NC; i++) SE(i, k) /= piv;
    for (size_t j = k + 1; j < NC; j++)
      for (size_t i = j; i < NC; i++) SE(i, j) = SE(j, i) = SE(i, j) - SE(i, k) * SE(j, k);
  }
  if (!(fabs(SE(RK, RK)) <= NULL_TOL * d0)) return PRRU_ESINGULAR;
  /* Null vector of S, permuted: (-L11^-T l21^T, 1). */
  gsl_matrix_view L11 = gsl_matrix_submatrix(&S.matrix, 0, 0, RK, RK);
  double v[NL], x[NL];
  for (size_t i = 0; i < RK; i++) v[i] = -SE(RK, i);
  v[RK] = 1.0;
  gsl_vector_view v1 = gsl_vector_view_array(v, RK);
  gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &L11.matrix, &v1.vector);
  /* A particular solution of S x = y_C: L11 L11^T x1 = y1, x2 = 0 (the
   * equation dropped with the pivot holds to rounding: y_C is in
   * range(S)). */
  for (size_t i = 0; i < NC; i++) x[i] = gsl_vector_get(&yC.vector, perm[i]);
  x[RK] = 0.0;
  gsl_vector_view x1 = gsl_vector_view_array(x, RK);
  gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, &L11.matrix, &x1.vector);
  gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &L11.matrix, &x1.vector);
  for (size_t i = 0; i < NC; i++) {
    gsl_vector_set(&yC.vector, perm[i], x[i]);
    gsl_vector_set(&zC.vector, perm[i], v[i]);
  }
#undef SE
  /* The limbs: x_k = L_k^-T (y_k - W_k x_C), and the null vector of the
   * whole matrix z_k = -A_kk^-1 A_kC z_C = -L_k^-T W_k z_C. */
  for (size_t k = 0; k < PRRU_NLIMB; k++) {
    const size_t s0 = (size_t)a->start[k], L = (size_t)a->len[k];
    gsl_matrix_view Lk = gsl_matrix_submatrix(&Pm.matrix, s0, s0, L, L);
    gsl_matrix_view Wk = gsl_matrix_submatrix(&Pm.matrix, s0, C0, L, NC);
    gsl_vector_view yk = gsl_vector_subvector(&yv.vector, s0, L);
    gsl_vector_view zk = gsl_vector_subvector(&zv.vector, s0, L);
    gsl_blas_dgemv(CblasNoTrans, -1.0, &Wk.matrix, &yC.vector, 1.0, &yk.vector);
    gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &Lk.matrix, &yk.vector);
    gsl_blas_dgemv(CblasNoTrans, -1.0, &Wk.matrix, &zC.vector, 0.0, &zk.vector);
    gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &Lk.matrix, &zk.vector);
  }
  /* Least norm: y - (z . y / z . z) z; then z to unit length. */
  double zn = 0, zy = 0, big = 0;
  for (int i = 0; i < NL; i++) {
    zn += zz[i] * zz[i];
    zy += zz[i] * y[i];
    big = fmax(big, fabs(zz[i]));
  }
  if (!(zn > 0) || !isfinite(zn)) return PRRU_ESINGULAR;
  const double c = zy / zn;
  zn = sqrt(zn);
  /* Sign: the first coordinate in lambda order of at least half the largest
   * magnitude is positive (stable under rounding: ties between equal
   * magnitudes, as between C3's and P3's force along e2, cannot flip it). */
  double sg = 1.0;
  for (int i = 0; i < NL; i++)
    if (fabs(zz[pos[i]]) >= 0.5 * big) {
      sg = zz[pos[i]] < 0 ? -1.0 : 1.0;
      break;
    }
  for (int i = 0; i < NL; i++) {
    if (r) r[i] = y[pos[i]] - c * zz[pos[i]];
    z[i] = sg * zz[pos[i]] / zn;
  }
  return PRRU_OK;
}
#endif

/* A = Q^T Phi^-1 Q (and r = Q^T Phi^-1 d->K when rhs) into d->A, d->r,
 * from d->Q, d->K and the body rotations R. */
static void assemble(const prru_mechanism *me, prru_data *d, const double *R, int rhs)
{
  memset(d->A, 0, sizeof d->A);
  memset(d->r, 0, sizeof d->r);
  for (int b = 0; b < NB; b++) {
    /* Phi_b^-1 = blkdiag(R_b D_b^-1 R_b^T, E3 / m_b). */
    double Pinv[3][3], RD[3][3];
    const double *Rb = R + 9 * b, *Di = me->inertia_inv[b];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        RD[i][j] = Rb[3 * i] * Di[j] + Rb[3 * i + 1] * Di[3 + j] + Rb[3 * i + 2] * Di[6 + j];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        Pinv[i][j] = RD[i][0] * Rb[3 * j] + RD[i][1] * Rb[3 * j + 1] + RD[i][2] * Rb[3 * j + 2];
    double minv = 1.0 / me->mass[b];
    int cols[NL], nc = 0;
    double Qb[6][NL], W[6][NL]; /* body b's rows of Q; Phi_b^-1 Q_b over the columns b sees */
    for (int k = 0; k < 6; k++) memcpy(Qb[k], d->Q + body_row(b, k) * NL, sizeof Qb[k]);
    for (int c = 0; c < NL; c++)
      if (Qb[0][c] != 0.0 || Qb[1][c] != 0.0 || Qb[2][c] != 0.0 || Qb[3][c] != 0.0 ||
          Qb[4][c] != 0.0 || Qb[5][c] != 0.0)
        cols[nc++] = c;
    for (int jj = 0; jj < nc; jj++) {
      int c = cols[jj];
      for (int i = 0; i < 3; i++) {
        W[i][jj] = Pinv[i][0] * Qb[0][c] + Pinv[i][1] * Qb[1][c] + Pinv[i][2] * Qb[2][c];
        W[3 + i][jj] = minv * Qb[3 + i][c];
      }
    }
    double kb[6] = {0, 0, 0, 0, 0, 0};
    if (rhs)
      for (int k = 0; k < 6; k++) kb[k] = d->K[body_row(b, k)];
    for (int ii = 0; ii < nc; ii++) {
      int ci = cols[ii];
      double s = 0, qc[6];
      for (int k = 0; k < 6; k++) {
        s += W[k][ii] * kb[k]; /* Phi^-1 symmetric */
        qc[k] = Qb[k][ci];
      }
      d->r[ci] += s;
      for (int jj = 0; jj < nc; jj++) {
        int cj = cols[jj];
        double a = qc[0] * W[0][jj] + qc[1] * W[1][jj] + qc[2] * W[2][jj] + qc[3] * W[3][jj] +
                   qc[4] * W[4][jj] + qc[5] * W[5][jj];
        d->A[ci * NL + cj] += a;
      }
    }
  }
}

int prru_reaction_null(const prru_model *m, prru_data *d, const double q[3],
                       double z[PRRU_NLAMBDA])
{
#if PRRU_NREACTION_NULL == 0
  (void)m, (void)d, (void)q, (void)z;
  return PRRU_EINPUT;
#else
  int st = prru_check_regular(m, d, q, NULL);
  if (st != PRRU_OK) return st;
  prru_gsl_init();
  double R[9 * NB], p[3 * NB];
  prru_poses(q, R, p);
  prru_reaction_basis(q, d->Q);
  assemble(m->mech, d, R, 0);
  arrowhead a;
  arrowhead_layout(m->mech, &a);
  st = solve_arrowhead_null(&a, d->A, NULL, d->P, d->lambda_null);
  if (st != PRRU_OK) return st;
  memcpy(z, d->lambda_null, sizeof d->lambda_null);
  return PRRU_OK;
#endif
}

int prru_reactions(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                   const prru_loads *l, double lambda[NL])
{
  const prru_mechanism *me = m->mech;
  double qdd[3];
  int st = prru_forward_dynamics(m, d, q, qd, l, qdd);
  if (st != PRRU_OK) return st;
  prru_gsl_init();
  double R[9 * NB], p[3 * NB], F[NH], fs[PRRU_NACT];
  prru_poses(q, R, p);
  prru_reaction_basis(q, d->Q);
  prru_wrench_bias(q, qd, d->K);
  prru_jd(q, d->Jd);
  slider_forces(me, d, q, qd, l, fs);
  applied_wrenches(me, fs, l, q, p, F);
  for (int i = 0; i < NH; i++) d->K[i] -= F[i]; /* K - Fbar */

  assemble(me, d, R, 1);
  arrowhead a;
  arrowhead_layout(me, &a);
#if PRRU_NREACTION_NULL == 0
  memset(d->lambda_null, 0, sizeof d->lambda_null);
  if (solve_arrowhead(&a, d->A, d->r, d->P) != PRRU_OK) return PRRU_ESINGULAR;
#else
  if (solve_arrowhead_null(&a, d->A, d->r, d->P, d->lambda_null) != PRRU_OK)
    return PRRU_ESINGULAR;
#endif
  for (int i = 0; i < NL; i++)
    if (!isfinite(d->r[i])) return PRRU_EINPUT; /* loads so large the solve overflows */
  memcpy(lambda, d->r, sizeof d->r);
  return PRRU_OK;
}
