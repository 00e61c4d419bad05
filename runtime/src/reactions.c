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
#include "internal.h"

#define NL PRRU_NLAMBDA
#define NB PRRU_NBODY
#define NH PRRU_NH

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
  arrowhead a;
  arrowhead_layout(me, &a);
  if (solve_arrowhead(&a, d->A, d->r, d->P) != PRRU_OK) return PRRU_ESINGULAR;
  for (int i = 0; i < NL; i++)
    if (!isfinite(d->r[i])) return PRRU_EINPUT; /* loads so large the solve overflows */
  memcpy(lambda, d->r, sizeof d->r);
  return PRRU_OK;
}
