/* Equations of reaction (spec section 7, paper eq. 31):
 *   lambda = (Q^T Phi^-1 Q)^-1 Q^T Phi^-1 (K - Fbar).
 * Phi is block diagonal, so Phi^-1 is applied body by body (R D^-1 R^T and
 * 1/m), and every column of Q touches at most two bodies (the two ends of
 * its joint), so Q^T Phi^-1 Q is accumulated body by body over the columns
 * that body sees: the dense 60x60 products of the reference are never
 * formed. The 57x57 system is SPD (Q has full column rank): Cholesky. */
#include <math.h>
#include <string.h>

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
    double W[6][NL]; /* Phi_b^-1 Q_b over the columns body b sees */
    for (int c = 0; c < NL; c++) {
      int nz = 0;
      for (int k = 0; k < 6; k++) nz |= d->Q[body_row(b, k) * NL + c] != 0.0;
      if (nz) cols[nc++] = c;
    }
    for (int jj = 0; jj < nc; jj++) {
      int c = cols[jj];
      double v[6];
      for (int k = 0; k < 6; k++) v[k] = d->Q[body_row(b, k) * NL + c];
      for (int i = 0; i < 3; i++) {
        W[i][jj] = Pinv[i][0] * v[0] + Pinv[i][1] * v[1] + Pinv[i][2] * v[2];
        W[3 + i][jj] = minv * v[3 + i];
      }
    }
    double kb[6];
    for (int k = 0; k < 6; k++) kb[k] = d->K[body_row(b, k)];
    for (int ii = 0; ii < nc; ii++) {
      int ci = cols[ii];
      double s = 0;
      for (int k = 0; k < 6; k++) s += W[k][ii] * kb[k]; /* Phi^-1 symmetric */
      d->r[ci] += s;
      for (int jj = 0; jj < nc; jj++) {
        int cj = cols[jj];
        double a = 0;
        for (int k = 0; k < 6; k++) a += d->Q[body_row(b, k) * NL + ci] * W[k][jj];
        d->A[ci * NL + cj] += a;
      }
    }
  }
  gsl_matrix_view A = gsl_matrix_view_array(d->A, NL, NL);
  gsl_vector_view r = gsl_vector_view_array(d->r, NL);
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  st = gsl_linalg_cholesky_decomp1(&A.matrix);
  if (st == GSL_SUCCESS) st = gsl_linalg_cholesky_svx(&A.matrix, &r.vector);
  gsl_set_error_handler(old);
  if (st != GSL_SUCCESS) return PRRU_ESINGULAR;
  memcpy(lambda, d->r, sizeof d->r);
  return PRRU_OK;
}
