/* Paper eqs. 25-30: H, Phi, K stacked in body order, M = H^T Phi H,
 * h = H^T K, G, and the forward and inverse dynamics, all with GSL; the
 * drives of spec section 11 on top.
 *
 * The drives act on the actuator coordinates d(q) only. An armature k_i is
 * a point mass that moves with d_i: kinetic energy k_i dd_i^2 / 2 with
 * dd = J_d qd, so (Lagrange, exactly as for a body with J_T = row i of
 * J_d) it adds J_d^T K J_d to M and, since dd' = J_d qdd + Jd' qd, adds
 * J_d^T K (Jd' qd) to h. Damping and Coulomb friction are forces along the
 * rails, phi_i = -c_i dd_i - f_i tanh(dd_i / v_s); by virtual power
 * (dd = J_d qd) they reach the generalized coordinates as Qp = J_d^T phi.
 * Qp is not part of h (spec section 11) but of every acceleration.
 *
 * With four limbs (spec section 12) J_d is 4x3: everything above holds as
 * written (J_d^T maps the four slider forces to the three coordinates); only
 * the inverse dynamics, which must undo J_d^T, changes (see there). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "ref_internal.h"

/* The workspace's model-sized matrices and vectors as views of their
 * storage at the counts n (see ref_priv.store). */
static gsl_matrix *view_matrix(ref_matrix *m, int n1, int n2)
{
  m->cur = gsl_matrix_view_array(m->max->data, n1, n2);
  return &m->cur.matrix;
}

static gsl_vector *view_vector(ref_vector *v, int n)
{
  v->cur = gsl_vector_view_array(v->max->data, n);
  return &v->cur.vector;
}

static void size_workspace(prru_ref_ws *w, const ref_size *n)
{
  ref_priv *s = w->priv;
  w->H = view_matrix(&s->store.H, n->nw, 3);
  w->Phi = view_matrix(&s->store.Phi, n->nw, n->nw);
  w->K = view_vector(&s->store.K, n->nw);
  w->dm = view_vector(&s->store.dm, n->nw);
  w->PhiH = view_matrix(&s->store.PhiH, n->nw, 3);
  w->Q = view_matrix(&s->store.Q, n->nw, n->nl);
  w->Jd = view_matrix(&s->store.Jd, n->na, 3);
  s->L = view_matrix(&s->store.L, n->nw, n->nw);
  s->Y = view_matrix(&s->store.Y, n->nw, n->nl);
  s->A = view_matrix(&s->store.A, n->nl, n->nl);
  s->V = view_matrix(&s->store.V, n->nl, n->nl);
  s->S = view_vector(&s->store.S, n->nl);
  s->svw = view_vector(&s->store.svw, n->nl);
  s->rW = view_vector(&s->store.rW, n->nw);
  s->rL = view_vector(&s->store.rL, n->nl);
  s->Fbar = view_vector(&s->store.Fbar, n->nw);
  s->Fg = view_vector(&s->store.Fg, n->nw);
  s->jdk = view_matrix(&s->store.jdk, n->na, 3);
}

prru_ref_ws *prru_ref_alloc(void)
{
  prru_ref_ws *w = calloc(1, sizeof *w);
  ref_priv *s = calloc(1, sizeof *s);
  if (!w || !s) { free(w); free(s); return NULL; }
  w->priv = s;
  /* Storage for the largest model: every model's views fit in it. */
  const ref_size n = ref_size_of_nlimb(PRRU_MAX_LIMB);
  s->store.H.max = gsl_matrix_calloc(n.nw, 3);
  s->store.Phi.max = gsl_matrix_calloc(n.nw, n.nw);
  s->store.K.max = gsl_vector_calloc(n.nw);
  s->store.dm.max = gsl_vector_calloc(n.nw);
  s->store.PhiH.max = gsl_matrix_calloc(n.nw, 3);
  w->M = gsl_matrix_calloc(3, 3);
  s->store.Q.max = gsl_matrix_calloc(n.nw, n.nl);
  s->store.Jd.max = gsl_matrix_calloc(n.na, 3);
  s->store.L.max = gsl_matrix_calloc(n.nw, n.nw);
  s->store.Y.max = gsl_matrix_calloc(n.nw, n.nl);
  s->store.A.max = gsl_matrix_calloc(n.nl, n.nl);
  s->store.V.max = gsl_matrix_calloc(n.nl, n.nl);
  s->store.S.max = gsl_vector_calloc(n.nl);
  s->store.svw.max = gsl_vector_calloc(n.nl);
  s->store.rW.max = gsl_vector_calloc(n.nw);
  s->store.rL.max = gsl_vector_calloc(n.nl);
  s->store.Fbar.max = gsl_vector_calloc(n.nw);
  s->store.Fg.max = gsl_vector_calloc(n.nw);
  s->m3a = gsl_matrix_calloc(3, 3);
  s->m3b = gsl_matrix_calloc(3, 3);
  s->m3c = gsl_matrix_calloc(3, 3);
  s->store.jdk.max = gsl_matrix_calloc(n.na, 3);
  s->v3a = gsl_vector_calloc(3);
  s->v3b = gsl_vector_calloc(3);
  s->v3c = gsl_vector_calloc(3);
  s->perm3 = gsl_permutation_calloc(3);
  if (!s->store.H.max || !s->store.Phi.max || !s->store.K.max || !s->store.dm.max ||
      !s->store.PhiH.max || !w->M || !s->store.Q.max || !s->store.Jd.max || !s->store.L.max ||
      !s->store.Y.max || !s->store.A.max || !s->store.V.max || !s->store.S.max || !s->store.svw.max ||
      !s->store.rW.max || !s->store.rL.max || !s->store.Fbar.max || !s->store.Fg.max || !s->m3a ||
      !s->m3b || !s->m3c || !s->store.jdk.max || !s->v3a || !s->v3b || !s->v3c || !s->perm3) {
    prru_ref_free(w);
    return NULL;
  }
  size_workspace(w, &n);
  return w;
}

void prru_ref_free(prru_ref_ws *w)
{
  if (!w) return;
  ref_priv *s = w->priv;
  /* gsl_*_free accept NULL, so a partly failed allocation frees cleanly;
   * the model-sized members are views of s->store. */
  gsl_matrix_free(w->M);
  if (s) {
    gsl_matrix_free(s->store.H.max);
    gsl_matrix_free(s->store.Phi.max);
    gsl_vector_free(s->store.K.max);
    gsl_vector_free(s->store.dm.max);
    gsl_matrix_free(s->store.PhiH.max);
    gsl_matrix_free(s->store.Q.max);
    gsl_matrix_free(s->store.Jd.max);
    gsl_matrix_free(s->store.L.max);
    gsl_matrix_free(s->store.Y.max);
    gsl_matrix_free(s->store.A.max);
    gsl_matrix_free(s->store.V.max);
    gsl_vector_free(s->store.S.max);
    gsl_vector_free(s->store.svw.max);
    gsl_vector_free(s->store.rW.max);
    gsl_vector_free(s->store.rL.max);
    gsl_vector_free(s->store.Fbar.max);
    gsl_vector_free(s->store.Fg.max);
    gsl_matrix_free(s->m3a);
    gsl_matrix_free(s->m3b);
    gsl_matrix_free(s->m3c);
    gsl_matrix_free(s->store.jdk.max);
    gsl_vector_free(s->v3a);
    gsl_vector_free(s->v3b);
    gsl_vector_free(s->v3c);
    gsl_permutation_free(s->perm3);
    free(s);
  }
  free(w);
}

int ref_cholesky(gsl_matrix *A)
{
  /* GSL's default handler aborts on a non-positive-definite matrix; the
   * reference reports it instead. */
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  int st = gsl_linalg_cholesky_decomp1(A);
  gsl_set_error_handler(old);
  return st ? GSL_ESING : GSL_SUCCESS;
}

int ref_lu3(gsl_matrix *A, gsl_permutation *perm, gsl_matrix *inv)
{
  double norm = 0, inorm = 0;
  int signum;
  for (int j = 0; j < 3; j++) {
    double c = 0;
    for (int i = 0; i < 3; i++) c += fabs(gsl_matrix_get(A, i, j));
    norm = fmax(norm, c);
  }
  gsl_linalg_LU_decomp(A, perm, &signum);
  for (int i = 0; i < 3; i++)
    if (!(gsl_matrix_get(A, i, i) != 0.0)) return GSL_ESING;
  gsl_linalg_LU_invert(A, perm, inv);
  for (int j = 0; j < 3; j++) {
    double c = 0;
    for (int i = 0; i < 3; i++) c += fabs(gsl_matrix_get(inv, i, j));
    inorm = fmax(inorm, c);
  }
  return 1.0 / (norm * inorm) >= DBL_EPSILON ? GSL_SUCCESS : GSL_ESING;
}

/* Stacks the per-body quantities of paper eqs. 25-28 into the workspace. */
int ref_assemble(const prru_ref_params *p, prru_ref_ws *w, const double q[3], const double *qd)
{
  ref_priv *s = w->priv;
  ref_kin *k = &s->kin;
  int st = ref_kinematics(p, q, qd, k);
  if (st) return st;
  const int nb = k->n.nb;
  size_workspace(w, &k->n);
  gsl_matrix_set_zero(w->Phi);
  gsl_vector_set_zero(s->Fg);
  gsl_vector_set_zero(w->K);
  for (int b = 0; b < nb; b++) {
    const double *R = k->R[b], *Ib = p->inertia[b];
    for (int i = 0; i < 3; i++) {
      for (int j = 0; j < 3; j++) {
        gsl_matrix_set(w->H, 3 * b + i, j, k->JR[b][3 * i + j]);
        gsl_matrix_set(w->H, 3 * nb + 3 * b + i, j, k->JT[b][3 * i + j]);
        /* I_b = R I R^T: the body-axes tensor about the centre seen in
         * {S} (the angular momentum R I R^T omega = R (I (R^T omega))). */
        double Iij = 0;
        for (int l = 0; l < 3; l++)
          for (int m = 0; m < 3; m++) Iij += R[3 * i + l] * Ib[3 * l + m] * R[3 * j + m];
        gsl_matrix_set(w->Phi, 3 * b + i, 3 * b + j, Iij);
      }
      gsl_matrix_set(w->Phi, 3 * nb + 3 * b + i, 3 * nb + 3 * b + i, p->mass[b]);
      gsl_vector_set(w->dm, 3 * b + i, qd ? k->delta[b][i] : 0.0);
      gsl_vector_set(w->dm, 3 * nb + 3 * b + i, qd ? k->mu[b][i] : 0.0);
      /* Gravity: the force m_b g at the centre of mass, no moment about it. */
      gsl_vector_set(s->Fg, 3 * nb + 3 * b + i, p->mass[b] * p->g[i]);
    }
  }
  if (qd) {
    /* K: I delta + omega x (I omega) (paper eq. 28, errata), m mu. */
    for (int b = 0; b < nb; b++) {
      double Id[3] = {0, 0, 0}, Iw[3] = {0, 0, 0};
      const double *om = k->omega[b];
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
          double Iij = gsl_matrix_get(w->Phi, 3 * b + i, 3 * b + j);
          Id[i] += Iij * k->delta[b][j];
          Iw[i] += Iij * om[j];
        }
      double gyro[3] = {om[1] * Iw[2] - om[2] * Iw[1], om[2] * Iw[0] - om[0] * Iw[2],
                        om[0] * Iw[1] - om[1] * Iw[0]};
      for (int i = 0; i < 3; i++) {
        gsl_vector_set(w->K, 3 * b + i, Id[i] + gyro[i]);
        gsl_vector_set(w->K, 3 * nb + 3 * b + i, p->mass[b] * k->mu[b][i]);
      }
    }
  }
  for (int i = 0; i < k->n.na; i++)
    for (int j = 0; j < 3; j++) gsl_matrix_set(w->Jd, i, j, k->Jd[3 * i + j]);
  return GSL_SUCCESS;
}

void ref_mass_matrix(const prru_ref_params *p, prru_ref_ws *w)
{
  ref_priv *s = w->priv;
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, w->Phi, w->H, 0.0, w->PhiH);
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, w->H, w->PhiH, 0.0, w->M);
  /* + J_d^T diag(k) J_d (the armature, see the top of this file). */
  gsl_matrix_memcpy(s->jdk, w->Jd);
  for (int i = 0; i < s->kin.n.na; i++) {
    gsl_vector_view row = gsl_matrix_row(s->jdk, i);
    gsl_vector_scale(&row.vector, p->armature[i]);
  }
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, w->Jd, s->jdk, 1.0, w->M);
}

/* h = H^T K + J_d^T diag(k) (Jd' qd) after ref_assemble(.., qd). */
static void bias_vector(const prru_ref_params *p, prru_ref_ws *w, gsl_vector *h)
{
  ref_priv *s = w->priv;
  const int na = s->kin.n.na;
  double fa[PRRU_MAX_ACT];
  for (int i = 0; i < na; i++) fa[i] = p->armature[i] * s->kin.ddb[i];
  gsl_vector_view Fa = gsl_vector_view_array(fa, na);
  gsl_blas_dgemv(CblasTrans, 1.0, w->H, w->K, 0.0, h);
  gsl_blas_dgemv(CblasTrans, 1.0, w->Jd, &Fa.vector, 1.0, h);
}

/* phi_i = -c_i dd_i - f_i tanh(dd_i / v_s), the force drive i puts on its
 * slider besides fd_i and the armature's inertia (v_s is only defined,
 * and only read, where f_i != 0). */
void ref_drive_friction(const prru_ref_params *p, const ref_kin *k, double phi[PRRU_MAX_ACT])
{
  for (int i = 0; i < k->n.na; i++) {
    phi[i] = -p->damping[i] * k->dd[i];
    if (p->coulomb[i] != 0.0) phi[i] -= p->coulomb[i] * tanh(k->dd[i] / p->coulomb_velocity);
  }
}

/* Qp = J_d^T phi (virtual power: phi . dd = phi . J_d qd). */
static void passive_vector(const prru_ref_params *p, prru_ref_ws *w, gsl_vector *Qp)
{
  ref_priv *s = w->priv;
  double phi[PRRU_MAX_ACT];
  ref_drive_friction(p, &s->kin, phi);
  gsl_vector_view Phi = gsl_vector_view_array(phi, s->kin.n.na);
  gsl_blas_dgemv(CblasTrans, 1.0, w->Jd, &Phi.vector, 0.0, Qp);
}

static void fill_nan(double *x, int n)
{
  if (x)
    for (int i = 0; i < n; i++) x[i] = NAN;
}

static void copy_matrix(const gsl_matrix *A, double *out)
{
  for (size_t i = 0; i < A->size1; i++)
    for (size_t j = 0; j < A->size2; j++) out[i * A->size2 + j] = gsl_matrix_get(A, i, j);
}

static void copy_vector(const gsl_vector *v, double *out)
{
  for (size_t i = 0; i < v->size; i++) out[i] = gsl_vector_get(v, i);
}

int prru_ref_jacobians(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double H[])
{
  int st = ref_assemble(p, w, q, NULL);
  if (st) { fill_nan(H, ref_size_of(p).nw * 3); return st; }
  copy_matrix(w->H, H);
  return GSL_SUCCESS;
}

int prru_ref_bias_terms(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                        const double qd[3], double dm[])
{
  int st = ref_assemble(p, w, q, qd);
  if (st) { fill_nan(dm, ref_size_of(p).nw); return st; }
  copy_vector(w->dm, dm);
  return GSL_SUCCESS;
}

int prru_ref_mass(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double M[9])
{
  int st = ref_assemble(p, w, q, NULL);
  if (st) { fill_nan(M, 9); return st; }
  ref_mass_matrix(p, w);
  copy_matrix(w->M, M);
  return GSL_SUCCESS;
}

int prru_ref_bias(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                  const double qd[3], double h[3])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, qd);
  if (st) { fill_nan(h, 3); return st; }
  bias_vector(p, w, s->v3a);
  copy_vector(s->v3a, h);
  return GSL_SUCCESS;
}

/* G = sum_b J_T,b^T (m_b g) = H^T Fg with Fg the stacked gravity wrenches. */
int prru_ref_gravity(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double G[3])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, NULL);
  if (st) { fill_nan(G, 3); return st; }
  gsl_blas_dgemv(CblasTrans, 1.0, w->H, s->Fg, 0.0, s->v3a);
  copy_vector(s->v3a, G);
  return GSL_SUCCESS;
}

int prru_ref_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                      const double qd[3], double M[9], double h[3], double G[3])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, qd);
  if (st) { fill_nan(M, 9); fill_nan(h, 3); fill_nan(G, 3); return st; }
  ref_mass_matrix(p, w);
  copy_matrix(w->M, M);
  bias_vector(p, w, s->v3a);
  copy_vector(s->v3a, h);
  gsl_blas_dgemv(CblasTrans, 1.0, w->H, s->Fg, 0.0, s->v3a);
  copy_vector(s->v3a, G);
  return GSL_SUCCESS;
}

/* Body by body, from the velocities, not from M: the tests compare the two.
 * The armature's share is k_i dd_i^2 / 2; V is the work against the
 * constant field g: -sum_b m_b g . p_b. */
int prru_ref_energy(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                    const double qd[3], double E[2])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, qd);
  if (st) { fill_nan(E, 2); return st; }
  const ref_kin *k = &s->kin;
  double T = 0, V = 0;
  for (int b = 0; b < k->n.nb; b++) {
    for (int i = 0; i < 3; i++) {
      T += 0.5 * p->mass[b] * k->v[b][i] * k->v[b][i];
      for (int j = 0; j < 3; j++)
        T += 0.5 * k->omega[b][i] * gsl_matrix_get(w->Phi, 3 * b + i, 3 * b + j) * k->omega[b][j];
      V -= p->mass[b] * p->g[i] * k->p[b][i];
    }
  }
  for (int i = 0; i < k->n.na; i++) T += 0.5 * p->armature[i] * k->dd[i] * k->dd[i];
  E[0] = T;
  E[1] = V;
  return GSL_SUCCESS;
}

int prru_ref_passive(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                     const double qd[3], double Qp[3])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, qd);
  if (st) { fill_nan(Qp, 3); return st; }
  passive_vector(p, w, s->v3a);
  copy_vector(s->v3a, Qp);
  return GSL_SUCCESS;
}

/* tau = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp (eq. 30's right-hand side;
 * fd may be NULL). The platform force acts at the tool point O' (spec
 * section 5), which is the platform's centre of mass only when its com is
 * 0: its virtual power is fp . v_O'. */
static void generalized_load(prru_ref_ws *w, const double *fd, const double fp[3],
                             const double mp[3], gsl_vector *tau)
{
  ref_priv *s = w->priv;
  const double *JTO = s->kin.JTO;
  gsl_blas_dgemv(CblasTrans, 1.0, w->H, s->Fg, 0.0, tau);
  for (int j = 0; j < 3; j++) {
    double t = 0;
    for (int i = 0; i < 3; i++) {
      if (fd) t += gsl_matrix_get(w->Jd, i, j) * fd[i];
      t += JTO[3 * i + j] * fp[i];
      t += gsl_matrix_get(w->H, 3 * REF_P + i, j) * mp[i];
    }
    for (int i = 3; i < s->kin.n.na; i++)
      if (fd) t += gsl_matrix_get(w->Jd, i, j) * fd[i]; /* limb 4 */
    gsl_vector_set(tau, j, gsl_vector_get(tau, j) + t);
  }
}

int ref_solve_qdd(const prru_ref_params *p, prru_ref_ws *w, const double *fd, const double fp[3],
                  const double mp[3], gsl_vector *qdd)
{
  ref_priv *s = w->priv;
  generalized_load(w, fd, fp, mp, s->v3b);
  passive_vector(p, w, s->v3c);
  gsl_vector_add(s->v3b, s->v3c); /* + Qp */
  bias_vector(p, w, s->v3c);
  gsl_vector_sub(s->v3b, s->v3c); /* - h */
  gsl_matrix_memcpy(s->m3a, w->M);
  if (ref_cholesky(s->m3a)) return GSL_ESING;
  gsl_linalg_cholesky_solve(s->m3a, s->v3b, qdd);
  return GSL_SUCCESS;
}

int prru_ref_forward_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                              const double qd[3], const double fd[], const double fp[3],
                              const double mp[3], double qdd[3])
{
  ref_priv *s = w->priv;
  int st = ref_assemble(p, w, q, qd);
  if (!st) {
    ref_mass_matrix(p, w);
    st = ref_solve_qdd(p, w, fd, fp, mp, s->v3a);
  }
  if (st) { fill_nan(qdd, 3); return st; }
  copy_vector(s->v3a, qdd);
  return GSL_SUCCESS;
}

int ref_jd_pinv(prru_ref_ws *w, gsl_matrix *Jp)
{
  ref_priv *s = w->priv;
  if (s->kin.n.na == 3) {
    gsl_matrix_memcpy(s->m3a, w->Jd);
    return ref_lu3(s->m3a, s->perm3, Jp);
  }
  /* J_d^T J_d is 3x3 and positive definite where J_d has full column rank;
   * its condition number is J_d's squared, still checked against the
   * machine precision by ref_lu3. */
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, w->Jd, w->Jd, 0.0, s->m3a);
  if (ref_lu3(s->m3a, s->perm3, s->m3b)) return GSL_ESING;
  gsl_blas_dgemm(CblasNoTrans, CblasTrans, 1.0, s->m3b, w->Jd, 0.0, Jp);
  return GSL_SUCCESS;
}

/* J_d^T fd = tau with tau = M qdd + h - G - J_T,O'^T fp - J_R,P^T mp - Qp:
 * fd = J_d^-T tau for three limbs; for four, J_d^T (4 unknowns, 3
 * equations) leaves fd free along the null vector of J_d^T (an internal
 * preload the platform does not feel) and the minimum-norm solution is the
 * one in the range of J_d, fd = J_d x with J_d^T J_d x = tau, i.e.
 * fd = J_d (J_d^T J_d)^-1 tau = J_d^+T tau (spec section 12). */
int prru_ref_inverse_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                              const double qd[3], const double qdd[3], const double fp[3],
                              const double mp[3], double fd[])
{
  ref_priv *s = w->priv;
  const int na = ref_size_of(p).na;
  int st = ref_assemble(p, w, q, qd);
  if (st) { fill_nan(fd, na); return st; }
  ref_mass_matrix(p, w);
  gsl_vector_const_view a = gsl_vector_const_view_array(qdd, 3);
  generalized_load(w, NULL, fp, mp, s->v3b);
  passive_vector(p, w, s->v3c);
  gsl_vector_add(s->v3b, s->v3c);                                  /* G + ... + Qp */
  bias_vector(p, w, s->v3c);
  gsl_vector_sub(s->v3c, s->v3b);                                  /* h - (G + ... + Qp) */
  gsl_blas_dgemv(CblasNoTrans, 1.0, w->M, &a.vector, 1.0, s->v3c); /* + M qdd */
  if (na == 3) {
    /* As J_d^-T tau, but by LU solve of J_d^T rather than the inverse. */
    gsl_matrix_transpose_memcpy(s->m3a, w->Jd);
    if (ref_lu3(s->m3a, s->perm3, s->m3b)) { fill_nan(fd, na); return GSL_ESING; }
    gsl_linalg_LU_solve(s->m3a, s->perm3, s->v3c, s->v3a);
    copy_vector(s->v3a, fd);
    return GSL_SUCCESS;
  }
  double jp[3 * PRRU_MAX_ACT];
  gsl_matrix_view Jp = gsl_matrix_view_array(jp, 3, na);
  gsl_vector_view Fd = gsl_vector_view_array(fd, na);
  if (ref_jd_pinv(w, &Jp.matrix)) { fill_nan(fd, na); return GSL_ESING; }
  gsl_blas_dgemv(CblasTrans, 1.0, &Jp.matrix, s->v3c, 0.0, &Fd.vector);
  return GSL_SUCCESS;
}
