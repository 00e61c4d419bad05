/* Equations of reaction (paper eqs. 14-24, 28-31 with the spec's single sign
 * convention): the basis Q of the joint reaction wrenches and lambda by
 * eq. 31 with the dense Phi. Joint centres are points of the section-4
 * geometry (C_i, B_i, A_i); the moment arms run to each body's centre of
 * mass p_b (not its frame origin), about which Phi, K and Fbar are taken. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "ref_internal.h"

#define NB REF_NB
#define NW REF_NW
#define NL REF_NL
#define GROUND (-1)

/* A unit force f through the joint centre c: on body b (centre p_b) it is
 * the force f and the moment (c - p_b) x f, with the sign of the side. */
static void add_force(gsl_matrix *Q, int col, const ref_kin *k, int b, const double c[3],
                      const double f[3], double sign)
{
  if (b == GROUND) return;
  const double r[3] = {c[0] - k->p[b][0], c[1] - k->p[b][1], c[2] - k->p[b][2]};
  const double m[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
  for (int i = 0; i < 3; i++) {
    gsl_matrix_set(Q, 3 * b + i, col, gsl_matrix_get(Q, 3 * b + i, col) + sign * m[i]);
    gsl_matrix_set(Q, 3 * NB + 3 * b + i, col, gsl_matrix_get(Q, 3 * NB + 3 * b + i, col) + sign * f[i]);
  }
}

static void add_moment(gsl_matrix *Q, int col, int b, const double n[3], double sign)
{
  if (b == GROUND) return;
  for (int i = 0; i < 3; i++)
    gsl_matrix_set(Q, 3 * b + i, col, gsl_matrix_get(Q, 3 * b + i, col) + sign * n[i]);
}

/* One joint: the proximal body exerts +(f, m) on the distal one and suffers
 * -(f, m). Appends nf force columns then nm moment columns at *col. */
static void joint(gsl_matrix *Q, int *col, const ref_kin *k, int proximal, int distal,
                  const double c[3], const double (*forces)[3], int nf,
                  const double (*moments)[3], int nm)
{
  for (int i = 0; i < nf; i++, (*col)++) {
    add_force(Q, *col, k, distal, c, forces[i], +1.0);
    add_force(Q, *col, k, proximal, c, forces[i], -1.0);
  }
  for (int i = 0; i < nm; i++, (*col)++) {
    add_moment(Q, *col, distal, moments[i], +1.0);
    add_moment(Q, *col, proximal, moments[i], -1.0);
  }
}

static void build_Q(const ref_kin *k, gsl_matrix *Q)
{
  static const double E[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double *RP = k->R[REF_P];
  int col = 0;
  gsl_matrix_set_zero(Q);

  /* C joints: the U joints turn about v and w (limbs 1, 2), x3 and w
   * (limb 3); the reaction moment is along their common normal. For limbs 1,
   * 2 that is v x w = u = R_P e1; for limb 3 n3 = w x x3 / |w x x3|. */
  const double u[3] = {RP[0], RP[3], RP[6]}, wv[3] = {RP[2], RP[5], RP[8]};
  const double *Rl3 = k->R[REF_L3];
  const double x3[3] = {Rl3[0], Rl3[3], Rl3[6]};
  double n3[3] = {wv[1] * x3[2] - wv[2] * x3[1], wv[2] * x3[0] - wv[0] * x3[2],
                  wv[0] * x3[1] - wv[1] * x3[0]};
  const double nn = sqrt(n3[0] * n3[0] + n3[1] * n3[1] + n3[2] * n3[2]);
  for (int i = 0; i < 3; i++) n3[i] /= nn;
  const double mu1[1][3] = {{u[0], u[1], u[2]}}, mn3[1][3] = {{n3[0], n3[1], n3[2]}};
  for (int l = 0; l < 3; l++)
    joint(Q, &col, k, REF_L1 + l, REF_P, k->C[l], E, 3, l < 2 ? mu1 : mn3, 1);

  /* R joints B_i, A_i: moments along the two coordinate axes normal to the
   * hinge axis (e1 in limbs 1, 2, e2 in limb 3). */
  const double m12[2][3] = {{0, 1, 0}, {0, 0, 1}}, m3[2][3] = {{1, 0, 0}, {0, 0, 1}};
  for (int l = 0; l < 3; l++)
    joint(Q, &col, k, REF_U1 + l, REF_L1 + l, k->B[l], E, 3, l < 2 ? m12 : m3, 2);
  for (int l = 0; l < 3; l++)
    joint(Q, &col, k, REF_S1 + l, REF_U1 + l, k->A[l], E, 3, l < 2 ? m12 : m3, 2);

  /* P joints: rail (ground) to slider, free along e3; the joint centre is
   * A_i, the slider's frame origin (its centre of mass lies com off it). */
  for (int l = 0; l < 3; l++) joint(Q, &col, k, GROUND, REF_S1 + l, k->A[l], E, 2, E, 3);
}

int prru_ref_reaction_basis(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                            double Q[6 * PRRU_NBODY * PRRU_NLAMBDA])
{
  int st = ref_assemble(p, w, q, NULL);
  if (st) {
    for (int i = 0; i < NW * NL; i++) Q[i] = NAN;
    return st;
  }
  build_Q(&((ref_priv *)w->priv)->kin, w->Q);
  for (int i = 0; i < NW; i++)
    for (int j = 0; j < NL; j++) Q[i * NL + j] = gsl_matrix_get(w->Q, i, j);
  return GSL_SUCCESS;
}

/* lambda = (Q^T Phi^-1 Q)^-1 Q^T Phi^-1 (K - Fbar) (eq. 31): with Phi = L L^T
 * and Y = L^-1 Q, Q^T Phi^-1 Q = Y^T Y and Q^T Phi^-1 x = Y^T L^-1 x.
 *
 * Fbar holds what acts on the bodies from outside the joints: gravity
 * m_b g at every centre, fp at the tool point O' and mp on the platform
 * (as in tau = J_T,O'^T fp + J_R,P^T mp) and, on slider i along e3, the
 * force its drive delivers. Of fd_i the drive keeps k_i dd_i'' to
 * accelerate its own armature (which is no body of Phi) and loses
 * c_i dd_i + f_i tanh(dd_i / v_s); the slider receives the rest. That
 * needs the actual d'' = J_d qdd + Jd' qd, so qdd comes from the forward
 * dynamics first; with it the bodies' equations Phi H qdd + K = Fbar +
 * Q lambda are consistent (their H^T projection is the EOM with the
 * armature moved to the right-hand side), and qdd itself drops out of
 * lambda through H^T Q = 0. */
int prru_ref_reactions(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                       const double qd[PRRU_NQ], const double fd[PRRU_NACT], const double fp[3],
                       const double mp[3], double lambda[PRRU_NLAMBDA])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, qd);
  if (!st) {
    ref_mass_matrix(p, w);
    st = ref_solve_qdd(p, w, fd, fp, mp, s->v3a);
  }
  if (!st) {
    const ref_kin *k = &s->kin;
    double phi[REF_NA];
    ref_drive_friction(p, k, phi);
    build_Q(k, w->Q);
    gsl_vector_memcpy(s->Fbar, s->Fg);
    /* fp at O' = (0, 0, q3) is fp at the platform's centre p_P plus the
     * moment (O' - p_P) x fp. */
    const double *pP = k->p[REF_P];
    const double r[3] = {-pP[0], -pP[1], q[2] - pP[2]};
    const double rxf[3] = {r[1] * fp[2] - r[2] * fp[1], r[2] * fp[0] - r[0] * fp[2],
                           r[0] * fp[1] - r[1] * fp[0]};
    for (int i = 0; i < 3; i++) {
      *gsl_vector_ptr(s->Fbar, 3 * REF_P + i) += mp[i] + rxf[i];
      *gsl_vector_ptr(s->Fbar, 3 * NB + 3 * REF_P + i) += fp[i];
    }
    for (int i = 0; i < REF_NA; i++) {
      double dd2 = k->ddb[i];
      for (int j = 0; j < 3; j++) dd2 += k->Jd[3 * i + j] * gsl_vector_get(s->v3a, j);
      *gsl_vector_ptr(s->Fbar, 3 * NB + 3 * (REF_S1 + i) + 2) +=
          fd[i] - p->armature[i] * dd2 + phi[i];
    }
    gsl_vector_memcpy(s->r60, w->K);
    gsl_vector_sub(s->r60, s->Fbar);
    gsl_matrix_memcpy(s->L, w->Phi);
    st = ref_cholesky(s->L);
  }
  if (!st) {
    gsl_matrix_memcpy(s->Y, w->Q);
    gsl_blas_dtrsm(CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, 1.0, s->L, s->Y);
    gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, s->Y, s->Y, 0.0, s->A);
    gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, s->L, s->r60);
    gsl_blas_dgemv(CblasTrans, 1.0, s->Y, s->r60, 0.0, s->r57);
    st = ref_cholesky(s->A);
  }
  if (st) {
    for (int i = 0; i < NL; i++) lambda[i] = NAN;
    return st;
  }
  gsl_vector_view lam = gsl_vector_view_array(lambda, NL);
  gsl_linalg_cholesky_solve(s->A, s->r57, &lam.vector);
  return GSL_SUCCESS;
}
