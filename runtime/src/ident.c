/* Standard and base parameters, and the least-squares identification
 * (prru_ident.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit.h>
#include <gsl/gsl_permutation.h>

#include "ident_internal.h"
#include "internal.h"
#include "prru_ident.h"

void prru_ident_standard(const prru_mechanism *me, double pi[])
{
  const int nb = me->nbody, na = me->nact;
  for (int b = 0; b < nb; b++) {
    double *p = pi + PRRU_NBODYPAR * b;
    const double m = me->mass[b], *c = me->com[b], *I = me->inertia[b];
    const double s = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    p[0] = m;
    for (int k = 0; k < 3; k++) p[1 + k] = m * c[k];
    /* Parallel axes: I_O = I_c + m (|c|^2 E - c c^T). */
    for (int k = 0; k < 3; k++) p[4 + k] = I[4 * k] + m * (s - c[k] * c[k]);
    p[7] = I[1] - m * c[0] * c[1];
    p[8] = I[2] - m * c[0] * c[2];
    p[9] = I[5] - m * c[1] * c[2];
  }
  double *dr = pi + PRRU_NBODYPAR * nb;
  for (int i = 0; i < na; i++) {
    dr[i] = me->armature[i];
    dr[na + i] = me->damping[i];
    dr[2 * na + i] = me->coulomb[i];
  }
}

int prru_ident_body(const double pib[PRRU_NBODYPAR], double *mass, double com[3], double inertia[6])
{
  for (int k = 0; k < PRRU_NBODYPAR; k++)
    if (!isfinite(pib[k])) return PRRU_EINPUT;
  const double m = pib[0];
  if (!(m > 0)) return PRRU_EINPUT;
  for (int k = 0; k < 3; k++) com[k] = pib[1 + k] / m;
  const double s = com[0] * com[0] + com[1] * com[1] + com[2] * com[2];
  for (int k = 0; k < 3; k++) inertia[k] = pib[4 + k] - m * (s - com[k] * com[k]);
  inertia[3] = pib[7] + m * com[0] * com[1];
  inertia[4] = pib[8] + m * com[0] * com[2];
  inertia[5] = pib[9] + m * com[1] * com[2];
  *mass = m;
  return PRRU_OK;
}

/* xorshift64* in [0, 1): reproducible on every platform, unlike rand(). */
static double uniform(unsigned long long *s)
{
  *s ^= *s >> 12;
  *s ^= *s << 25;
  *s ^= *s >> 27;
  return (double)((*s * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

static double det3(const double *a)
{
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* The assembly mode at (0, 0, q3): det J_d's sign (three actuators; 1 for
 * four, whose J_d has no determinant and no second mode in reach). */
static int mode_sign(const double Jd[], int nact)
{
  return nact != 3 ? 1 : det3(Jd) > 0 ? 1 : -1;
}

int prru_ident_random_state(const prru_model *m, prru_data *d, unsigned long long *s,
                            double q[3], double qd[3], double qdd[3])
{
  const double L = prru_length_scale(m->mech);
  const double home[3] = {0.0, 0.0, 0.0};
  if (prru_check_regular(m, d, home, NULL) != PRRU_OK) return PRRU_ENOCONV;
  const int na = m->mech->nact, mode = mode_sign(d->Jd, na);
  for (int tries = 0; tries < 1000; tries++) {
    double rc;
    q[0] = 0.3 * (2 * uniform(s) - 1);
    q[1] = 0.3 * (2 * uniform(s) - 1);
    q[2] = 0.2 * L * (2 * uniform(s) - 1);
    if (prru_check_regular(m, d, q, &rc) != PRRU_OK || rc < 1e-3 || mode_sign(d->Jd, na) != mode)
      continue;
    for (int k = 0; k < 3; k++) {
      const double scale = k == 2 ? L : 1.0;
      qd[k] = scale * (2 * uniform(s) - 1);
      qdd[k] = 4 * scale * (2 * uniform(s) - 1);
    }
    return PRRU_OK;
  }
  return PRRU_ENOCONV;
}

/* Y stacked over the states (rows 3 per state). */
static int stack_states(const prru_model *m, double vs, int nstates, unsigned long seed,
                        gsl_matrix *W)
{
  prru_data *d = malloc(sizeof *d);
  if (!d) return PRRU_ENOMEM;
  unsigned long long s = 0x9E3779B97F4A7C15ULL ^ (unsigned long long)seed;
  if (!s) s = 1;
  const int nreg = (int)W->size2;
  int st = PRRU_OK;
  for (int i = 0; i < nstates && st == PRRU_OK; i++) {
    double q[3], qd[3], qdd[3], Y[3 * PRRU_MAX_REG];
    st = prru_ident_random_state(m, d, &s, q, qd, qdd);
    if (st != PRRU_OK) break;
    prru_model_regressor(m, q, qd, qdd, vs, Y);
    for (int r = 0; r < 3; r++)
      for (int j = 0; j < nreg; j++) gsl_matrix_set(W, 3 * (size_t)i + r, j, Y[r * nreg + j]);
  }
  free(d);
  return st;
}

/* Pivoted QR of W's non-zero columns scaled to unit norm; fills b (its
 * counts set). */
static int reduce(gsl_matrix *W, prru_base *b)
{
  const int nreg = b->nreg;
  double norm[PRRU_MAX_REG], big = 0;
  int nz[PRRU_MAX_REG], n = 0;
  for (int j = 0; j < nreg; j++) {
    gsl_vector_view c = gsl_matrix_column(W, j);
    norm[j] = gsl_blas_dnrm2(&c.vector);
    if (norm[j] > big) big = norm[j];
  }
  for (int j = 0; j < nreg; j++) {
    /* A column of rounding-level size is one the dynamics does not contain
     * (its entries cancel exactly in exact arithmetic). */
    b->role[j] = norm[j] > 1e-13 * big ? PRRU_PAR_COMBINED : PRRU_PAR_NONE;
    if (b->role[j] == PRRU_PAR_COMBINED) nz[n++] = j;
  }
  gsl_matrix *A = gsl_matrix_alloc(W->size1, (size_t)n);
  gsl_vector *tau = gsl_vector_alloc((size_t)(n < (int)W->size1 ? n : (int)W->size1));
  gsl_vector *work = gsl_vector_alloc((size_t)n);
  gsl_permutation *p = gsl_permutation_alloc((size_t)n);
  int sign;
  if (!A || !tau || !work || !p) {
    gsl_matrix_free(A), gsl_vector_free(tau), gsl_vector_free(work), gsl_permutation_free(p);
    return PRRU_ENOMEM;
  }
  for (size_t i = 0; i < W->size1; i++)
    for (int k = 0; k < n; k++) gsl_matrix_set(A, i, (size_t)k, gsl_matrix_get(W, i, nz[k]) / norm[nz[k]]);
  gsl_linalg_QRPT_decomp(A, tau, p, &sign, work);
  const double r00 = fabs(gsl_matrix_get(A, 0, 0));
  int r = 0;
  while (r < n && r < (int)W->size1 && fabs(gsl_matrix_get(A, (size_t)r, (size_t)r)) > PRRU_BASE_RTOL * r00) r++;
  b->nbase = r;
  b->last_kept = r > 0 ? fabs(gsl_matrix_get(A, (size_t)r - 1, (size_t)r - 1)) / r00 : 0;
  b->first_dropped = r < n && r < (int)W->size1 ? fabs(gsl_matrix_get(A, (size_t)r, (size_t)r)) / r00 : 0;
  memset(b->B, 0, sizeof b->B);
  for (int i = 0; i < r; i++) {
    const int ci = nz[gsl_permutation_get(p, (size_t)i)];
    b->col[i] = ci;
    b->role[ci] = PRRU_PAR_BASE;
    b->B[i * nreg + ci] = 1.0;
  }
  /* K = R11^-1 R12 in scaled columns, solved column by column. */
  gsl_matrix_view R11 = gsl_matrix_submatrix(A, 0, 0, (size_t)r, (size_t)r);
  gsl_vector *x = gsl_vector_alloc((size_t)(r > 0 ? r : 1));
  for (int k = r; k < n && x && r > 0; k++) {
    const int cj = nz[gsl_permutation_get(p, (size_t)k)];
    for (int i = 0; i < r; i++) gsl_vector_set(x, (size_t)i, gsl_matrix_get(A, (size_t)i, (size_t)k));
    gsl_blas_dtrsv(CblasUpper, CblasNoTrans, CblasNonUnit, &R11.matrix, x);
    for (int i = 0; i < r; i++)
      b->B[i * nreg + cj] = gsl_vector_get(x, (size_t)i) * norm[cj] / norm[b->col[i]];
  }
  int st = x ? PRRU_OK : PRRU_ENOMEM;
  int k = 0;
  for (int j = 0; j < nreg; j++)
    if (b->role[j] != PRRU_PAR_BASE) b->col[r + k++] = j;
  gsl_vector_free(x);
  gsl_matrix_free(A), gsl_vector_free(tau), gsl_vector_free(work), gsl_permutation_free(p);
  return st;
}

double prru_ident_default_vs(const prru_model *m)
{
  return m->mech->coulomb_velocity > 0 ? m->mech->coulomb_velocity : 1e-3;
}

int prru_base_compute(const prru_model *m, double vs, int nstates, unsigned long seed, prru_base *b)
{
  if (!(vs > 0) || !isfinite(vs)) return PRRU_EINPUT;
  /* The counts first: b is the model's, whatever the caller later pairs
   * it with (prru_identify and the others refuse another topology's). */
  b->nbody = m->mech->nbody;
  b->nact = m->mech->nact;
  b->nreg = PRRU_NBODYPAR * b->nbody + 3 * b->nact;
  if (nstates <= 0) nstates = PRRU_BASE_STATES;
  if (3 * nstates < b->nreg) nstates = b->nreg;
  prru_gsl_init();
  gsl_matrix *W = gsl_matrix_alloc(3 * (size_t)nstates, (size_t)b->nreg);
  if (!W) return PRRU_ENOMEM;
  b->vs = vs;
  b->nstates = nstates;
  b->seed = seed;
  /* the base is the model's structure: the stroke has no part in it */
  prru_mechanism *me = malloc(sizeof *me);
  prru_model um;
  if (!me) {
    gsl_matrix_free(W);
    return PRRU_ENOMEM;
  }
  prru_model_unbounded(m, &um, me);
  int st = stack_states(&um, vs, nstates, seed, W);
  free(me);
  if (st == PRRU_OK) st = reduce(W, b);
  gsl_matrix_free(W);
  return st;
}

void prru_base_params(const prru_base *b, const double pi[], double beta[])
{
  for (int i = 0; i < b->nbase; i++) {
    double s = 0;
    for (int j = 0; j < b->nreg; j++) s += b->B[i * b->nreg + j] * pi[j];
    beta[i] = s;
  }
}

void prru_base_regressor(const prru_base *b, const double *Y, int rows, double *Yb)
{
  for (int r = 0; r < rows; r++)
    for (int i = 0; i < b->nbase; i++) Yb[r * b->nbase + i] = Y[r * b->nreg + b->col[i]];
}

void prru_base_to_standard(const prru_base *b, const double beta[],
                           const double pi0[], double pi[])
{
  memcpy(pi, pi0, sizeof(double) * (size_t)b->nreg);
  /* Row i of B has 1 at col[i] and otherwise entries only at non-base
   * parameters, which keep pi0's values. */
  for (int i = 0; i < b->nbase; i++) {
    double s = beta[i];
    for (int j = 0; j < b->nreg; j++)
      if (j != b->col[i]) s -= b->B[i * b->nreg + j] * pi0[j];
    pi[b->col[i]] = s;
  }
}

/* The regressor's column names of each topology, in prru_topology_layout's
 * body order (P, the lower links, the upper links, the sliders): the
 * generated prru_regressor_names names the build's model's only, and a
 * base of either topology is named in any build (test_ident compares the
 * two). */
#define BODY_PARAMS(b) b ".m", b ".mcx", b ".mcy", b ".mcz", b ".Ixx", b ".Iyy", b ".Izz", b ".Ixy", b ".Ixz", b ".Iyz"
static const char *const names3[] = {
    BODY_PARAMS("P"),  BODY_PARAMS("L1"), BODY_PARAMS("L2"), BODY_PARAMS("L3"), BODY_PARAMS("U1"),
    BODY_PARAMS("U2"), BODY_PARAMS("U3"), BODY_PARAMS("S1"), BODY_PARAMS("S2"), BODY_PARAMS("S3"),
    "armature1", "armature2", "armature3", "damping1", "damping2", "damping3", "coulomb1", "coulomb2", "coulomb3"};
static const char *const names4[] = {
    BODY_PARAMS("P"),  BODY_PARAMS("L1"), BODY_PARAMS("L2"), BODY_PARAMS("L3"), BODY_PARAMS("L4"),
    BODY_PARAMS("U1"), BODY_PARAMS("U2"), BODY_PARAMS("U3"), BODY_PARAMS("U4"), BODY_PARAMS("S1"),
    BODY_PARAMS("S2"), BODY_PARAMS("S3"), BODY_PARAMS("S4"),
    "armature1", "armature2", "armature3", "armature4", "damping1", "damping2", "damping3", "damping4",
    "coulomb1", "coulomb2", "coulomb3", "coulomb4"};
#undef BODY_PARAMS
typedef char names_cover_both_topologies[sizeof names3 / sizeof *names3 == (1 + 3 * 3) * PRRU_NBODYPAR + 3 * 3 &&
                                                 sizeof names4 / sizeof *names4 == PRRU_MAX_REG
                                             ? 1
                                             : -1];

const char *prru_base_param_name(const prru_base *b, int j)
{
  if (j < 0 || j >= b->nreg) return NULL;
  if (b->nbody == 10 && b->nact == 3) return names3[j];
  if (b->nbody == 13 && b->nact == 4) return names4[j];
  return NULL;
}

int prru_ident_rows(const prru_model *m, prru_data *d, const prru_base *b, const double q[3],
                    const double qd[3], const double qdd[3], const double fd[],
                    double *A, double y[])
{
  const int na = m->mech->nact;
  if (!prru_base_fits(m, b)) return PRRU_EINPUT;
  for (int k = 0; k < 3; k++)
    if (!isfinite(qd[k]) || !isfinite(qdd[k])) return PRRU_EINPUT;
  for (int i = 0; i < na; i++)
    if (!isfinite(fd[i])) return PRRU_EINPUT;
  int st = prru_check_regular(m, d, q, NULL);
  if (st != PRRU_OK) return st;
  double Y[3 * PRRU_MAX_REG], Yb[3 * PRRU_MAX_REG], tau[3];
  prru_model_regressor(m, q, qd, qdd, b->vs, Y);
  prru_base_regressor(b, Y, 3, Yb);
  for (int k = 0; k < 3; k++) {
    tau[k] = 0;
    for (int i = 0; i < na; i++) tau[k] += d->Jd[i * 3 + k] * fd[i];
  }
  /* J_d^+T: (J_d^+)^T[i][k] = Jdpinv[k * nact + i]. */
  for (int i = 0; i < na; i++) {
    y[i] = 0;
    for (int k = 0; k < 3; k++) y[i] += d->Jdpinv[k * na + i] * tau[k];
    for (int j = 0; j < b->nbase; j++) {
      double s = 0;
      for (int k = 0; k < 3; k++) s += d->Jdpinv[k * na + i] * Yb[k * b->nbase + j];
      A[i * b->nbase + j] = s;
    }
  }
  return PRRU_OK;
}

/* X and y of every sample; *bad the failing sample. */
static int fill_rows(const prru_model *m, const prru_base *b, int n, const double *q,
                     const double *qd, const double *qdd, const double *fd, gsl_matrix *X,
                     gsl_vector *y, int *bad)
{
  const int na = m->mech->nact;
  prru_data *d = malloc(sizeof *d);
  double *A = malloc(sizeof(double) * (size_t)na * (size_t)b->nbase);
  int st = d && A ? PRRU_OK : PRRU_ENOMEM;
  for (int s = 0; s < n && st == PRRU_OK; s++) {
    double ys[PRRU_MAX_ACT];
    st = prru_ident_rows(m, d, b, q + 3 * s, qd + 3 * s, qdd + 3 * s, fd + (size_t)na * s, A, ys);
    if (st != PRRU_OK) {
      if (bad) *bad = s;
      break;
    }
    for (int i = 0; i < na; i++) {
      const size_t row = (size_t)s * na + (size_t)i;
      gsl_vector_set(y, row, ys[i]);
      for (int j = 0; j < b->nbase; j++) gsl_matrix_set(X, row, (size_t)j, A[i * b->nbase + j]);
    }
  }
  free(A);
  free(d);
  return st;
}

/* (X^T X)^-1 and the 2-norm condition number of the column-scaled X, both
 * from the SVD Xs = U S V^T of X D (D scaling the columns to unit norm):
 * (X^T X)^-1 = D V S^-2 V^T D. Never the normal equations, whose
 * condition number is the square of X's (1e15 for a poor excitation). */
static int unit_covariance(const gsl_matrix *X, gsl_matrix *C, double *cond)
{
  const size_t p = X->size2;
  gsl_vector *sc = gsl_vector_alloc(p);
  gsl_matrix *Xs = gsl_matrix_alloc(X->size1, p);
  gsl_matrix *V = gsl_matrix_alloc(p, p);
  gsl_vector *sv = gsl_vector_alloc(p), *work = gsl_vector_alloc(p);
  int st = sc && Xs && V && sv && work ? PRRU_OK : PRRU_ENOMEM;
  if (st == PRRU_OK) {
    gsl_matrix_memcpy(Xs, X);
    for (size_t j = 0; j < p; j++) {
      gsl_vector_view c = gsl_matrix_column(Xs, j);
      double nrm = gsl_blas_dnrm2(&c.vector);
      if (!(nrm > 0)) nrm = 1;
      gsl_vector_set(sc, j, nrm);
      gsl_vector_scale(&c.vector, 1.0 / nrm);
    }
    if (gsl_linalg_SV_decomp(Xs, V, sv, work) != GSL_SUCCESS) st = PRRU_ESINGULAR;
    const double smin = gsl_vector_get(sv, p - 1);
    *cond = smin > 0 ? gsl_vector_get(sv, 0) / smin : INFINITY;
    if (!(smin > 0)) st = PRRU_ESINGULAR;
    for (size_t i = 0; i < p && st == PRRU_OK; i++)
      for (size_t j = 0; j < p; j++) {
        double s = 0;
        for (size_t k = 0; k < p; k++) {
          const double sk = gsl_vector_get(sv, k);
          s += gsl_matrix_get(V, i, k) * gsl_matrix_get(V, j, k) / (sk * sk);
        }
        gsl_matrix_set(C, i, j, s / (gsl_vector_get(sc, i) * gsl_vector_get(sc, j)));
      }
  }
  gsl_vector_free(sc), gsl_matrix_free(Xs), gsl_matrix_free(V), gsl_vector_free(sv), gsl_vector_free(work);
  return st;
}

/* The variance inflation of correlated residuals (prru_ident_result):
 * rho_k the residuals' autocorrelation at a lag of k samples (na rows
 * each), pooled over the actuators, and Bartlett's weights over L =
 * floor(4 (n / 100)^(2/9)) lags (Newey and West, Econometrica 55(3), 1987,
 * with their rule for L). */
static void residual_inflation(const gsl_vector *res, int n, int na, prru_ident_result *r)
{
  int L = (int)floor(4 * pow(n / 100.0, 2.0 / 9.0));
  if (L > n - 1) L = n - 1;
  double c0 = 0, f = 1;
  for (size_t j = 0; j < res->size; j++) c0 += gsl_vector_get(res, j) * gsl_vector_get(res, j);
  for (int k = 1; k <= L && c0 > 0; k++) {
    double ck = 0;
    for (size_t j = 0; j + (size_t)k * na < res->size; j++)
      ck += gsl_vector_get(res, j) * gsl_vector_get(res, j + (size_t)k * na);
    f += 2 * (1 - k / (L + 1.0)) * ck / c0;
  }
  r->hac_lags = L;
  r->inflation = fmax(1, f);
}

/* r->R (row stride nreg): the R of a Householder QR of X
 * (prru_ident_result). */
static int triangular_factor(const gsl_matrix *X, int nreg, prru_ident_result *r)
{
  const size_t p = X->size2;
  gsl_matrix *A = gsl_matrix_alloc(X->size1, p);
  gsl_vector *tau = gsl_vector_alloc(p);
  int st = A && tau ? PRRU_OK : PRRU_ENOMEM;
  if (st == PRRU_OK) {
    gsl_matrix_memcpy(A, X);
    if (gsl_linalg_QR_decomp(A, tau) != GSL_SUCCESS) st = PRRU_ESINGULAR;
    memset(r->R, 0, sizeof r->R);
    for (size_t i = 0; i < p && st == PRRU_OK; i++)
      for (size_t j = i; j < p; j++) r->R[i * nreg + j] = gsl_matrix_get(A, i, j);
  }
  gsl_matrix_free(A), gsl_vector_free(tau);
  return st;
}

static int solve(const gsl_matrix *X, const gsl_vector *y, int n, const prru_base *b,
                 prru_ident_result *r)
{
  const size_t p = (size_t)b->nbase;
  gsl_vector *c = gsl_vector_alloc(p), *res = gsl_vector_alloc(X->size1);
  gsl_matrix *cov = gsl_matrix_alloc(p, p), *C = gsl_matrix_alloc(p, p);
  gsl_multifit_linear_workspace *w = gsl_multifit_linear_alloc(X->size1, p);
  int st = c && res && cov && C && w ? PRRU_OK : PRRU_ENOMEM;
  if (st == PRRU_OK) st = unit_covariance(X, C, &r->cond);
  if (st == PRRU_OK && r->cond > 1e12) st = PRRU_ESINGULAR;
  double chisq = 0;
  if (st == PRRU_OK) {
    if (gsl_multifit_linear(X, y, c, cov, &chisq, w) != GSL_SUCCESS) st = PRRU_ESINGULAR;
  }
  if (st == PRRU_OK) {
    gsl_multifit_linear_residuals(X, y, c, res);
    r->dof = 3 * n - b->nbase;
    const double s2 = chisq / r->dof;
    r->sigma = sqrt(s2);
    for (size_t i = 0; i < p; i++) {
      r->beta[i] = gsl_vector_get(c, i);
      r->se[i] = sqrt(s2 * gsl_matrix_get(C, i, i));
    }
    gsl_vector_const_view yv = gsl_vector_const_subvector(y, 0, y->size);
    const double yn = gsl_blas_dnrm2(&yv.vector);
    r->yrms = yn / sqrt((double)y->size);
    for (size_t i = 0; i < p; i++) {
      gsl_vector_const_view col = gsl_matrix_const_column(X, i);
      const double xn = gsl_blas_dnrm2(&col.vector);
      r->scale[i] = xn > 0 ? yn / xn : INFINITY;
    }
    for (int i = 0; i < b->nact; i++) {
      double s = 0;
      for (int k = 0; k < n; k++) {
        const double e = gsl_vector_get(res, (size_t)k * b->nact + (size_t)i);
        s += e * e;
      }
      r->rms[i] = sqrt(s / n);
    }
    residual_inflation(res, n, b->nact, r);
  }
  if (st == PRRU_OK) st = triangular_factor(X, b->nreg, r);
  gsl_vector_free(c), gsl_vector_free(res), gsl_matrix_free(cov), gsl_matrix_free(C);
  if (w) gsl_multifit_linear_free(w);
  return st;
}

int prru_identify(const prru_model *m, const prru_base *b, int n, const double *q, const double *qd,
                  const double *qdd, const double *fd, prru_ident_result *r, int *bad)
{
  memset(r, 0, sizeof *r);
  prru_gsl_init();
  if (bad) *bad = -1;
  if (n <= 0 || 3 * n <= b->nbase || b->nbase <= 0 || !prru_base_fits(m, b)) return PRRU_EINPUT;
  r->nsamples = n;
  r->nrows = n * m->mech->nact;
  gsl_matrix *X = gsl_matrix_alloc((size_t)r->nrows, (size_t)b->nbase);
  gsl_vector *y = gsl_vector_alloc((size_t)r->nrows);
  int st = X && y ? PRRU_OK : PRRU_ENOMEM;
  if (st == PRRU_OK) st = fill_rows(m, b, n, q, qd, qdd, fd, X, y, bad);
  if (st == PRRU_OK) st = solve(X, y, n, b, r);
  gsl_matrix_free(X);
  gsl_vector_free(y);
  return st;
}
