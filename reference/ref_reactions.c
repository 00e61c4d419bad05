/* Equations of reaction (paper eqs. 14-24, 28-31 with the spec's single sign
 * convention): the basis Q of the joint reaction wrenches and lambda by
 * eq. 31 with the dense Phi (its minimum-norm solution where, with four
 * limbs, one reaction direction is redundant). Joint centres are points of the section-4
 * geometry (C_i, B_i, A_i); the moment arms run to each body's centre of
 * mass p_b (not its frame origin), about which Phi, K and Fbar are taken. */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "ref_internal.h"

#define GROUND (-1)

/* A unit force f through the joint centre c: on body b (centre p_b) it is
 * the force f and the moment (c - p_b) x f, with the sign of the side. */
static void add_force(gsl_matrix *Q, int col, const ref_kin *k, int b, const double c[3],
                      const double f[3], double sign)
{
  if (b == GROUND) return;
  const int nb = k->n.nb;
  const double r[3] = {c[0] - k->p[b][0], c[1] - k->p[b][1], c[2] - k->p[b][2]};
  const double m[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
  for (int i = 0; i < 3; i++) {
    gsl_matrix_set(Q, 3 * b + i, col, gsl_matrix_get(Q, 3 * b + i, col) + sign * m[i]);
    gsl_matrix_set(Q, 3 * nb + 3 * b + i, col, gsl_matrix_get(Q, 3 * nb + 3 * b + i, col) + sign * f[i]);
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
  const int nlimb = k->n.nlimb;
  int col = 0;
  gsl_matrix_set_zero(Q);

  /* C joints: the U joints turn about v and w (limbs 1, 2), about the lower
   * link's outward axis x_l and w (limbs 3, 4); the reaction moment is along
   * their common normal. For limbs 1, 2 that is v x w = u = R_P e1; for
   * limb 3 n3 = w x x3 / |w x x3| with x3 = R_L3 e1, for limb 4 (spec
   * section 12) n4 = w x x4 / |w x x4| with x4 = -R_L4 e1 (its lower link
   * points along local -x). */
  const double u[3] = {RP[0], RP[3], RP[6]}, wv[3] = {RP[2], RP[5], RP[8]};
  for (int l = 0; l < nlimb; l++) {
    double n[3] = {u[0], u[1], u[2]};
    if (l >= 2) {
      const double *Rl = k->R[REF_L(nlimb, l)], s = l == 2 ? 1.0 : -1.0;
      const double x[3] = {s * Rl[0], s * Rl[3], s * Rl[6]};
      n[0] = wv[1] * x[2] - wv[2] * x[1];
      n[1] = wv[2] * x[0] - wv[0] * x[2];
      n[2] = wv[0] * x[1] - wv[1] * x[0];
      const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int i = 0; i < 3; i++) n[i] /= nn;
    }
    const double mn[1][3] = {{n[0], n[1], n[2]}};
    joint(Q, &col, k, REF_L(nlimb, l), REF_P, k->C[l], E, 3, mn, 1);
  }

  /* R joints B_i, A_i: moments along the two coordinate axes normal to the
   * hinge axis (e1 in limbs 1, 2, e2 in limbs 3, 4). */
  const double m12[2][3] = {{0, 1, 0}, {0, 0, 1}}, m34[2][3] = {{1, 0, 0}, {0, 0, 1}};
  for (int l = 0; l < nlimb; l++)
    joint(Q, &col, k, REF_U(nlimb, l), REF_L(nlimb, l), k->B[l], E, 3, l < 2 ? m12 : m34, 2);
  for (int l = 0; l < nlimb; l++)
    joint(Q, &col, k, REF_S(nlimb, l), REF_U(nlimb, l), k->A[l], E, 3, l < 2 ? m12 : m34, 2);

  /* P joints: rail (ground) to slider, free along e3; the joint centre is
   * A_i, the slider's frame origin (its centre of mass lies com off it). */
  for (int l = 0; l < nlimb; l++) joint(Q, &col, k, GROUND, REF_S(nlimb, l), k->A[l], E, 2, E, 3);
}

int prru_ref_reaction_basis(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double Q[])
{
  const ref_size n = ref_size_of(p);
  int st = ref_assemble(p, w, q, NULL);
  if (st) {
    for (int i = 0; i < n.nw * n.nl; i++) Q[i] = NAN;
    return st;
  }
  build_Q(&((ref_priv *)w->priv)->kin, w->Q);
  for (int i = 0; i < n.nw; i++)
    for (int j = 0; j < n.nl; j++) Q[i * n.nl + j] = gsl_matrix_get(w->Q, i, j);
  return GSL_SUCCESS;
}

/* Q from the kinematics, Phi = L L^T (Cholesky) and Y = L^-1 Q, after
 * ref_assemble: then Q^T Phi^-1 Q = Y^T Y, and Y's null space is Q's (L is
 * invertible). */
static int reaction_factor(prru_ref_ws *w)
{
  ref_priv *s = w->priv;
  build_Q(&s->kin, w->Q);
  gsl_matrix_memcpy(s->L, w->Phi);
  if (ref_cholesky(s->L)) return GSL_ESING;
  gsl_matrix_memcpy(s->Y, w->Q);
  gsl_blas_dtrsm(CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, 1.0, s->L, s->Y);
  return GSL_SUCCESS;
}

/* The singular value decomposition Y = L^-1 Q = U S V^T after
 * reaction_factor (GSL's Golub-Reinsch SVD, U overwriting s->Y, V in s->V,
 * S descending in s->S), so Q^T Phi^-1 Q = V S^2 V^T, and Q's null space is
 * spanned by the columns of V whose singular values are cut. The cut-off
 * is relative: sigma_i <= max(6 NBODY, NLAMBDA) DBL_EPSILON sigma_1 counts
 * as zero (the usual numerical-rank rule: the rounding error of Y and of
 * its SVD is about that size; measured over the reachable workspace, the
 * redundant direction of four limbs has sigma / sigma_1 ~ 1e-17 and the
 * smallest kept one ~ 1e-4). *rank counts the singular values kept;
 * GSL_ESING unless that is the rank 6 NBODY - 3 of the mechanism's Q
 * (ref_size.rank): fewer is a constraint singularity, more would leave the
 * redundant direction unresolved (H^T Q = 0 rules it out in exact
 * arithmetic). */
static int reaction_svd(prru_ref_ws *w, int *rank)
{
  ref_priv *s = w->priv;
  const ref_size n = s->kin.n;
  *rank = 0;
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  int st = gsl_linalg_SV_decomp(s->Y, s->V, s->S, s->svw);
  gsl_set_error_handler(old);
  if (st) return GSL_ESING;
  const double tol = (n.nw > n.nl ? n.nw : n.nl) * DBL_EPSILON * gsl_vector_get(s->S, 0);
  for (int i = 0; i < n.nl; i++) *rank += gsl_vector_get(s->S, i) > tol;
  return *rank == n.rank ? GSL_SUCCESS : GSL_ESING;
}

int prru_ref_reaction_null(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double z[],
                           int *nullity)
{
  ref_priv *s = w->priv;
  const int nl = ref_size_of(p).nl;
  int rank = 0, st = ref_assemble(p, w, q, NULL);
  if (!st) st = reaction_factor(w);
  if (st) {
    for (int i = 0; i < nl; i++) z[i] = NAN;
    *nullity = -1;
    return st;
  }
  st = reaction_svd(w, &rank);
  *nullity = nl - rank;
  /* The last column of V: the smallest singular value's right vector. */
  int imax = 0;
  for (int i = 0; i < nl; i++) {
    z[i] = gsl_matrix_get(s->V, i, nl - 1);
    if (fabs(z[i]) > fabs(z[imax])) imax = i;
  }
  if (z[imax] < 0)
    for (int i = 0; i < nl; i++) z[i] = -z[i];
  return st;
}

/* lambda = (Q^T Phi^-1 Q)^-1 Q^T Phi^-1 (K - Fbar) (eq. 31): with Phi = L L^T
 * and Y = L^-1 Q, Q^T Phi^-1 Q = Y^T Y and Q^T Phi^-1 x = Y^T L^-1 x.
 *
 * Three limbs: Y^T Y is positive definite, solved by Cholesky (GSL_ESING
 * where it is not numerically, a constraint singularity).
 *
 * Four limbs (spec section 12): Y^T Y is singular (rank 75 of 76) and eq.
 * 31's inverse becomes the pseudo-inverse: lambda = (Y^T Y)^+ Y^T L^-1 x =
 * Y^+ L^-1 x = V S^+ U^T L^-1 x with the SVD of reaction_svd (S^+ inverts
 * the singular values kept, zeroes the one cut). Of all lambda with
 * Q lambda = Phi H qdd + K - Fbar (they differ by multiples of Q's null
 * vector z, and they are exactly the solutions of the normal equations
 * Y^T Y lambda = Y^T L^-1 x, since H^T Q = 0 makes the qdd term drop out of
 * those) this is the one of least norm, the one with lambda . z = 0.
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
int prru_ref_reactions(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                       const double qd[3], const double fd[], const double fp[3],
                       const double mp[3], double lambda[])
{
  ref_priv *s = w->priv;
  const ref_size n = ref_size_of(p);
  int rank = n.nl;
  int st = ref_assemble(p, w, q, qd);
  if (!st) {
    ref_mass_matrix(p, w);
    st = ref_solve_qdd(p, w, fd, fp, mp, s->v3a);
  }
  if (!st) st = reaction_factor(w);
  if (!st) {
    if (n.rank == n.nl) {
      gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, s->Y, s->Y, 0.0, s->A);
      st = ref_cholesky(s->A);
    } else {
      st = reaction_svd(w, &rank);
    }
  }
  if (st) {
    for (int i = 0; i < n.nl; i++) lambda[i] = NAN;
    return st;
  }
  const ref_kin *k = &s->kin;
  double phi[PRRU_MAX_ACT];
  ref_drive_friction(p, k, phi);
  gsl_vector_memcpy(s->Fbar, s->Fg);
  /* fp at O' = (0, 0, q3) is fp at the platform's centre p_P plus the
   * moment (O' - p_P) x fp. */
  const double *pP = k->p[REF_P];
  const double r[3] = {-pP[0], -pP[1], q[2] - pP[2]};
  const double rxf[3] = {r[1] * fp[2] - r[2] * fp[1], r[2] * fp[0] - r[0] * fp[2],
                         r[0] * fp[1] - r[1] * fp[0]};
  for (int i = 0; i < 3; i++) {
    *gsl_vector_ptr(s->Fbar, 3 * REF_P + i) += mp[i] + rxf[i];
    *gsl_vector_ptr(s->Fbar, 3 * n.nb + 3 * REF_P + i) += fp[i];
  }
  for (int i = 0; i < n.na; i++) {
    double dd2 = k->ddb[i];
    for (int j = 0; j < 3; j++) dd2 += k->Jd[3 * i + j] * gsl_vector_get(s->v3a, j);
    *gsl_vector_ptr(s->Fbar, 3 * n.nb + 3 * REF_S(n.nlimb, i) + 2) += fd[i] - p->armature[i] * dd2 + phi[i];
  }
  /* rW = L^-1 (K - Fbar), rL = Y^T rW (three limbs) or U^T rW (four). */
  gsl_vector_memcpy(s->rW, w->K);
  gsl_vector_sub(s->rW, s->Fbar);
  gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, s->L, s->rW);
  gsl_blas_dgemv(CblasTrans, 1.0, s->Y, s->rW, 0.0, s->rL);
  gsl_vector_view lam = gsl_vector_view_array(lambda, n.nl);
  if (n.rank == n.nl) {
    gsl_linalg_cholesky_solve(s->A, s->rL, &lam.vector);
    return GSL_SUCCESS;
  }
  /* lambda = V S^+ (U^T rW). */
  for (int i = 0; i < n.nl; i++)
    gsl_vector_set(s->rL, i, i < rank ? gsl_vector_get(s->rL, i) / gsl_vector_get(s->S, i) : 0.0);
  gsl_blas_dgemv(CblasNoTrans, 1.0, s->V, s->rL, 0.0, &lam.vector);
  return GSL_SUCCESS;
}
