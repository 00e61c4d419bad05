/* Equations of reaction (spec section 7, paper eq. 31):
 *   lambda = (Q^T Phi^-1 Q)^-1 Q^T Phi^-1 (K - Fbar).
 * Phi is block diagonal, so Phi^-1 is applied body by body (R D^-1 R^T and
 * 1/m), and every column of Q touches at most two bodies (the two ends of
 * its joint), so Q^T Phi^-1 Q is accumulated body by body over the columns
 * that body sees: the dense 60x60 products of the reference are never
 * formed. The 57x57 system is SPD (Q has full column rank): Cholesky in
 * the arrowhead order below. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "prru.h"

#define NL PRRU_NLAMBDA
#define NB PRRU_NBODY

/* Body b's six rows of the 60-row stacking: 3b..3b+2 rotational,
 * 30+3b..30+3b+2 translational. */
static int body_row(int b, int k) { return k < 3 ? 3 * b + k : 30 + 3 * b + (k - 3); }

/* Fbar: gravity on every body, actuator forces on the sliders, platform
 * force and moment at O' (the platform's centre). */
static void applied_wrenches(const prru_model *m, const prru_loads *l, double F[60])
{
  memset(F, 0, 60 * sizeof F[0]);
  for (int b = 0; b < NB; b++) F[30 + 3 * b + 2] = -m->mass[b] * m->gravity;
  for (int i = 0; i < 3; i++) {
    F[30 + 3 * (7 + i) + 2] += l->fd[i];
    F[i] += l->mp[i];
    F[30 + i] += l->fp[i];
  }
}

/* Q^T Phi^-1 Q couples limb k's own joints (B_k, A_k, P_k: 15 columns)
 * only with themselves and with the platform's U joints C_1..C_3 (12): no
 * body touches two limbs except the platform. Ordered limb 1, limb 2,
 * limb 3, C, it is an arrowhead matrix whose Cholesky factor has no fill
 * outside the limbs' diagonal blocks and the C rows, so the factorization
 * visits only those: about a third of a dense 57x57 Cholesky. */
#define NC 12        /* U-joint coordinates, lambda[0..11] */
#define NLIMB 15     /* B_k, A_k, P_k coordinates of one limb */

/* Position in the arrowhead order of lambda coordinate c. */
static int arrow_pos(int c)
{
  if (c < NC) return 3 * NLIMB + c;
  int joint = (c - NC) / 15, within = (c - NC) % 15; /* joint: B, A, P */
  int limb = within / 5, k = within % 5;
  return NLIMB * limb + 5 * joint + k;
}

/* Solves A x = r (x returned in r), A the 57x57 SPD matrix in lambda
 * order, by block Cholesky in the arrowhead order with GSL:
 *   A = [L_k 0; W_k^T L_C] [L_k^T W_k; 0 L_C^T],  A_kk = L_k L_k^T,
 *   W_k = L_k^-1 A_kC,  L_C L_C^T = A_CC - sum_k W_k^T W_k.
 * P is scratch (57x57). */
static int solve_arrowhead(const double *A, double *r, double *P)
{
  int pos[NL];
  double y[NL];
  for (int c = 0; c < NL; c++) pos[c] = arrow_pos(c);
  for (int i = 0; i < NL; i++) {
    y[pos[i]] = r[i];
    for (int j = 0; j < NL; j++) P[pos[i] * NL + pos[j]] = A[i * NL + j];
  }
  const size_t L = NLIMB, C0 = 3 * NLIMB;
  gsl_matrix_view Pm = gsl_matrix_view_array(P, NL, NL);
  gsl_matrix_view S = gsl_matrix_submatrix(&Pm.matrix, C0, C0, NC, NC);
  gsl_vector_view yv = gsl_vector_view_array(y, NL);
  gsl_vector_view yC = gsl_vector_subvector(&yv.vector, C0, NC);
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  int st = GSL_SUCCESS;
  for (size_t k = 0; k < 3 && st == GSL_SUCCESS; k++) {
    gsl_matrix_view Lk = gsl_matrix_submatrix(&Pm.matrix, k * L, k * L, L, L);
    gsl_matrix_view Wk = gsl_matrix_submatrix(&Pm.matrix, k * L, C0, L, NC);
    gsl_vector_view yk = gsl_vector_subvector(&yv.vector, k * L, L);
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
    for (size_t k = 0; k < 3; k++) {
      gsl_matrix_view Lk = gsl_matrix_submatrix(&Pm.matrix, k * L, k * L, L, L);
      gsl_matrix_view Wk = gsl_matrix_submatrix(&Pm.matrix, k * L, C0, L, NC);
      gsl_vector_view yk = gsl_vector_subvector(&yv.vector, k * L, L);
      gsl_blas_dgemv(CblasNoTrans, -1.0, &Wk.matrix, &yC.vector, 1.0, &yk.vector);
      gsl_blas_dtrsv(CblasLower, CblasTrans, CblasNonUnit, &Lk.matrix, &yk.vector);
    }
  }
  gsl_set_error_handler(old);
  if (st != GSL_SUCCESS) return PRRU_ESINGULAR;
  for (int c = 0; c < NL; c++) r[c] = y[pos[c]];
  return PRRU_OK;
}

int prru_reactions(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                   const prru_loads *l, double lambda[NL])
{
  double qdd[3];
  int st = prru_forward_dynamics(m, d, q, qd, l, qdd);
  if (st != PRRU_OK) return st;
  double R[90], p[30], F[60];
  prru_poses(q, R, p);
  prru_reaction_basis(q, d->Q);
  prru_wrench_bias(q, qd, d->K);
  applied_wrenches(m, l, F);
  for (int i = 0; i < 60; i++) d->K[i] -= F[i]; /* K - Fbar */

  memset(d->A, 0, sizeof d->A);
  memset(d->r, 0, sizeof d->r);
  for (int b = 0; b < NB; b++) {
    /* Phi_b^-1 = blkdiag(R_b D_b^-1 R_b^T, E3 / m_b). */
    double Pinv[3][3];
    const double *Rb = R + 9 * b, *D = m->inertia + 3 * b;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        Pinv[i][j] = Rb[3 * i] * Rb[3 * j] / D[0] + Rb[3 * i + 1] * Rb[3 * j + 1] / D[1] +
                     Rb[3 * i + 2] * Rb[3 * j + 2] / D[2];
    double minv = 1.0 / m->mass[b];
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
    double kb[6];
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
  if (solve_arrowhead(d->A, d->r, d->P) != PRRU_OK) return PRRU_ESINGULAR;
  for (int i = 0; i < NL; i++)
    if (!isfinite(d->r[i])) return PRRU_EINPUT; /* loads so large the solve overflows */
  memcpy(lambda, d->r, sizeof d->r);
  return PRRU_OK;
}
