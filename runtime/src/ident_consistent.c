/* Physically consistent identified parameters (prru_ident.h): a phase-I
 * feasibility problem, the prior-nearest consistent set with the estimate's
 * base parameters, and, where that set is empty, the consistent set nearest
 * the estimate in the Mahalanobis distance. All three are convex over
 * linear matrix inequalities (4 x 4 pseudo-inertias) and linear
 * inequalities (drive coefficients), solved by one log-barrier method. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>

#include "ident_internal.h"
#include "internal.h"
#include "prru_control.h"
#include "prru_ident.h"
/* The bounded set the barrier needs: T_b^-1 J T_b^-T <= UPPER I (a body up
 * to 1e4 times its prior's mass and second moments) and x_k <= UPPER w_k. */
#define UPPER 1e4
/* Drive coefficients >= DRIVE_MARGIN w_k: the rounding of pi = p0 + P x
 * (1e-16 of its terms, of the order of w_k: a slider's mass beside its
 * armature) cannot take one below 0, and a truth without drives moves
 * the base parameters by 1e-12 w_k only (well inside 1e-8 of their
 * resolution). */
#define DRIVE_MARGIN 1e-12

void prru_consistent_options_default(prru_consistent_options *o)
{
  o->mu = 1e-6;
  o->alpha = 1e-3;
  o->sigma_floor = 1e-8;
  o->eps = 1e-9;
  o->max_newton = 5000;
}

/* ---- A small log-barrier solver ----
 * minimise f(x) = x^T Q x / 2 + c^T x + f0 subject to
 *   F_b(x) = F0_b + sum_i x_i F_bi > 0 (4 x 4, b < nlmi) and
 *   g_k(x) = a0_k + a_k^T x > 0 (k < nlin),
 * by Newton's method on t f - sum log det F_b - sum log g_k for growing t;
 * the duality gap of a centred point is theta / t, theta = 4 nlmi + nlin.
 * Phase I is the same with a variable s subtracted from every constraint
 * and f = -s, stopped once s >= s_goal. */
typedef struct {
  int n, nlmi, nlin;
  double *F0, *F;  /* nlmi x 16; nlmi x n x 16 */
  int *cnt, *idx;  /* per block, the variables with F_bi != 0: cnt[b], idx[b n + ...] */
  double *a0, *a;  /* nlin; nlin x n */
  double *Q, *c, f0;
  double *H, *g, *dx, *xt, *A; /* workspace: n x n, n, n, n, n x 16 */
  int phase1;      /* s = x[n - 1] */
  double s_goal;
} barrier;

static void barrier_free(barrier *p)
{
  free(p->F0), free(p->F), free(p->cnt), free(p->idx), free(p->a0), free(p->a);
  free(p->Q), free(p->c), free(p->H), free(p->g), free(p->dx), free(p->xt), free(p->A);
  memset(p, 0, sizeof *p);
}

static int barrier_alloc(barrier *p, int n, int nlmi, int nlin)
{
  memset(p, 0, sizeof *p);
  p->n = n, p->nlmi = nlmi, p->nlin = nlin;
  const size_t N = (size_t)n;
  p->F0 = calloc((size_t)nlmi * 16, sizeof(double));
  p->F = calloc((size_t)nlmi * N * 16, sizeof(double));
  p->cnt = calloc((size_t)nlmi, sizeof(int));
  p->idx = calloc((size_t)nlmi * N, sizeof(int));
  p->a0 = calloc((size_t)nlin + 1, sizeof(double));
  p->a = calloc(((size_t)nlin + 1) * N, sizeof(double));
  p->Q = calloc(N * N, sizeof(double));
  p->c = calloc(N, sizeof(double));
  p->H = calloc(N * N, sizeof(double));
  p->g = calloc(N, sizeof(double));
  p->dx = calloc(N, sizeof(double));
  p->xt = calloc(N, sizeof(double));
  p->A = calloc(N * 16, sizeof(double));
  if (p->F0 && p->F && p->cnt && p->idx && p->a0 && p->a && p->Q && p->c && p->H && p->g && p->dx &&
      p->xt && p->A)
    return PRRU_OK;
  barrier_free(p);
  return PRRU_ENOMEM;
}

/* The variables each block depends on (after F is filled). */
static void barrier_index(barrier *p)
{
  for (int b = 0; b < p->nlmi; b++) {
    p->cnt[b] = 0;
    for (int i = 0; i < p->n; i++) {
      const double *Fi = p->F + ((size_t)b * p->n + i) * 16;
      int nz = 0;
      for (int k = 0; k < 16; k++) nz |= Fi[k] != 0;
      if (nz) p->idx[(size_t)b * p->n + p->cnt[b]++] = i;
    }
  }
}

/* Cholesky of a symmetric 4 x 4 (lower L, row-major); 0 unless positive
 * definite. */
static int chol4(const double *F, double *L)
{
  memset(L, 0, 16 * sizeof(double));
  for (int j = 0; j < 4; j++) {
    double d = F[5 * j];
    for (int k = 0; k < j; k++) d -= L[4 * j + k] * L[4 * j + k];
    if (!(d > 0)) return 0;
    L[5 * j] = sqrt(d);
    for (int i = j + 1; i < 4; i++) {
      double s = F[4 * i + j];
      for (int k = 0; k < j; k++) s -= L[4 * i + k] * L[4 * j + k];
      L[4 * i + j] = s / L[5 * j];
    }
  }
  return 1;
}

/* L^-1 of a lower triangular 4 x 4 with a positive diagonal. */
static void lower_inverse4(const double *L, double *Li)
{
  memset(Li, 0, 16 * sizeof(double));
  for (int j = 0; j < 4; j++) {
    Li[5 * j] = 1 / L[5 * j];
    for (int i = j + 1; i < 4; i++) {
      double s = 0;
      for (int k = j; k < i; k++) s -= L[4 * i + k] * Li[4 * k + j];
      Li[4 * i + j] = s / L[5 * i];
    }
  }
}

static void block_at(const barrier *p, int b, const double *x, double *F)
{
  memcpy(F, p->F0 + 16 * b, 16 * sizeof(double));
  for (int m = 0; m < p->cnt[b]; m++) {
    const int i = p->idx[(size_t)b * p->n + m];
    const double *Fi = p->F + ((size_t)b * p->n + i) * 16;
    for (int k = 0; k < 16; k++) F[k] += x[i] * Fi[k];
  }
}

static double lin_at(const barrier *p, int k, const double *x)
{
  double s = p->a0[k];
  for (int i = 0; i < p->n; i++) s += p->a[(size_t)k * p->n + i] * x[i];
  return s;
}

static double objective(const barrier *p, const double *x)
{
  double f = p->f0;
  for (int i = 0; i < p->n; i++) {
    double qx = 0;
    for (int j = 0; j < p->n; j++) qx += p->Q[(size_t)i * p->n + j] * x[j];
    f += x[i] * (0.5 * qx + p->c[i]);
  }
  return f;
}

/* t f(x) + barrier, or +inf outside the domain. */
static double merit(const barrier *p, double t, const double *x)
{
  double phi = t * objective(p, x), F[16], L[16];
  for (int b = 0; b < p->nlmi; b++) {
    block_at(p, b, x, F);
    if (!chol4(F, L)) return INFINITY;
    for (int j = 0; j < 4; j++) phi -= 2 * log(L[5 * j]);
  }
  for (int k = 0; k < p->nlin; k++) {
    const double v = lin_at(p, k, x);
    if (!(v > 0)) return INFINITY;
    phi -= log(v);
  }
  return isfinite(phi) ? phi : INFINITY;
}

/* Gradient g and Hessian H of the merit at a point of the domain. */
static void derivatives(barrier *p, double t, const double *x)
{
  const int n = p->n;
  for (int i = 0; i < n; i++) {
    double qx = 0;
    for (int j = 0; j < n; j++) {
      qx += p->Q[(size_t)i * n + j] * x[j];
      p->H[(size_t)i * n + j] = t * p->Q[(size_t)i * n + j];
    }
    p->g[i] = t * (qx + p->c[i]);
  }
  double F[16], L[16], Li[16];
  for (int b = 0; b < p->nlmi; b++) {
    block_at(p, b, x, F);
    chol4(F, L);
    lower_inverse4(L, Li);
    const int cnt = p->cnt[b];
    const int *idx = p->idx + (size_t)b * n;
    /* With F = L L^T and B_m = L^-1 F_bm L^-T (symmetric): the gradient of
     * -log det F is -tr(B_m), its Hessian <B_m, B_l> (Frobenius): a Gram
     * matrix, positive semidefinite as computed, however ill-conditioned
     * F is (tr(F^-1 F_m F^-1 F_l) formed as written is not). */
    for (int m = 0; m < cnt; m++) {
      const double *Fi = p->F + ((size_t)b * n + idx[m]) * 16;
      double T[16], *Bm = p->A + (size_t)m * 16, tr = 0;
      for (int r = 0; r < 4; r++)
        for (int q = 0; q < 4; q++) {
          double s = 0;
          for (int k = 0; k <= r; k++) s += Li[4 * r + k] * Fi[4 * k + q];
          T[4 * r + q] = s;
        }
      for (int r = 0; r < 4; r++)
        for (int q = 0; q <= r; q++) {
          double s = 0;
          for (int k = 0; k <= q; k++) s += T[4 * r + k] * Li[4 * q + k];
          Bm[4 * r + q] = Bm[4 * q + r] = s;
        }
      for (int r = 0; r < 4; r++) tr += Bm[5 * r];
      p->g[idx[m]] -= tr;
    }
    for (int m = 0; m < cnt; m++)
      for (int l = 0; l <= m; l++) {
        const double *Bm = p->A + (size_t)m * 16, *Bl = p->A + (size_t)l * 16;
        double s = 0;
        for (int q = 0; q < 16; q++) s += Bm[q] * Bl[q];
        p->H[(size_t)idx[m] * n + idx[l]] += s;
        if (l != m) p->H[(size_t)idx[l] * n + idx[m]] += s;
      }
  }
  for (int k = 0; k < p->nlin; k++) {
    const double v = lin_at(p, k, x), *ak = p->a + (size_t)k * n;
    for (int i = 0; i < n; i++) {
      if (ak[i] == 0) continue;
      p->g[i] -= ak[i] / v;
      for (int j = 0; j < n; j++) p->H[(size_t)i * n + j] += ak[i] * ak[j] / (v * v);
    }
  }
}

/* The Newton direction dx = -H^-1 g (Cholesky; where rounding makes H
 * indefinite, H + shift diag(H) with shift growing from 1e-14); 0 when
 * none is found. */
static int newton_direction(barrier *p)
{
  const size_t n = (size_t)p->n;
  gsl_matrix *C = gsl_matrix_alloc(n, n);
  if (!C) return 0;
  int ok = 0;
  for (double shift = 0; !ok && shift <= 1e-2; shift = shift > 0 ? 100 * shift : 1e-14) {
    for (size_t i = 0; i < n; i++)
      for (size_t j = 0; j < n; j++) gsl_matrix_set(C, i, j, p->H[i * n + j] * (i == j ? 1 + shift : 1));
    if (gsl_linalg_cholesky_decomp1(C) != GSL_SUCCESS) continue;
    gsl_vector_view g = gsl_vector_view_array(p->g, n), d = gsl_vector_view_array(p->dx, n);
    ok = gsl_linalg_cholesky_solve(C, &g.vector, &d.vector) == GSL_SUCCESS;
    for (size_t i = 0; i < n; i++) p->dx[i] = -p->dx[i];
  }
  gsl_matrix_free(C);
  return ok;
}

/* Centres x for t: damped Newton until the decrement lambda^2 is below
 * 1e-9 or the merit's rounding, or no step of 1e-10 of Newton's or more
 * decreases the merit (rounding: H's conditioning limits the direction's
 * accuracy). Near the central path the gap is then theta / t to 1e-9.
 * PRRU_ENOCONV when the budget *steps runs out or H cannot be factored. */
static int centre(barrier *p, double t, double *x, int *steps)
{
  for (;;) {
    derivatives(p, t, x);
    if (!newton_direction(p)) return PRRU_ENOCONV;
    double dec = 0;
    for (int i = 0; i < p->n; i++) dec -= p->g[i] * p->dx[i];
    if (!(dec >= 0) || dec <= 1e-9) return PRRU_OK;
    if (--*steps < 0) return PRRU_ENOCONV;
    const double phi = merit(p, t, x);
    /* A decrease below the merit's rounding is no progress: centred as
     * far as double precision can tell. */
    if (dec <= 1e-13 * fabs(phi)) return PRRU_OK;
    double alpha = 1, ph;
    for (;;) {
      for (int i = 0; i < p->n; i++) p->xt[i] = x[i] + alpha * p->dx[i];
      ph = merit(p, t, p->xt);
      if (ph <= phi - 0.25 * alpha * dec) break;
      alpha *= 0.5;
      if (alpha < 1e-10) return PRRU_OK;
    }
    if (!(ph < phi)) return PRRU_OK; /* accepted by the merit's rounding only */
    memcpy(x, p->xt, sizeof(double) * (size_t)p->n);
    if (p->phase1 && x[p->n - 1] >= p->s_goal) return PRRU_OK;
  }
}

/* Minimises from a strictly feasible x until the duality gap is below
 * gap_tol (phase I: until s >= s_goal, or the gap is below gap_tol). */
static int barrier_solve(barrier *p, double *x, double gap_tol, int *steps)
{
  const double theta = 4.0 * p->nlmi + p->nlin;
  if (!isfinite(merit(p, 1, x))) return PRRU_ENOCONV; /* an infeasible start */
  const double f = objective(p, x);
  double t = p->phase1 ? 1 : theta / fmax(fabs(f), 1e3 * gap_tol);
  for (;;) {
    const int st = centre(p, t, x, steps);
    if (st != PRRU_OK) return st;
    if (p->phase1 && x[p->n - 1] >= p->s_goal) return PRRU_OK;
    /* Phase I: at a centred point the optimum s* <= s + theta / t, so once
     * that is negative the set is empty: the answer, without the last
     * digits of s* (which cost the ill-conditioned Newton steps of a
     * boundary the answer does not need). */
    if (p->phase1 && x[p->n - 1] + theta / t < 0) return PRRU_OK;
    /* Absolute, or relative where the optimum is large (data far from any
     * physical robot: its size, not its last digits, is the answer). */
    if (theta / t <= fmax(gap_tol, 1e-12 * fabs(objective(p, x)))) return PRRU_OK;
    t *= 20;
  }
}

/* ---- The identification problems ---- */

/* The pseudo-inertia of 10 standard parameters (m, m c, I_O). */
static void pseudo_inertia(const double *pb, double *J)
{
  const double half = 0.5 * (pb[4] + pb[5] + pb[6]);
  const double S[9] = {half - pb[4], -pb[7], -pb[8], -pb[7], half - pb[5], -pb[9], -pb[8], -pb[9], half - pb[6]};
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) J[4 * i + j] = S[3 * i + j];
    J[4 * i + 3] = J[12 + i] = pb[1 + i];
  }
  J[15] = pb[0];
}

typedef struct {
  /* The model's counts: np = nbody bodies' parameters and ndrv drive
   * coefficients. */
  int nbody, np, ndrv;
  double G[PRRU_MAX_BODY][PRRU_NBODYPAR][16]; /* T_b^-1 J(e_k) T_b^-T */
  double W[PRRU_MAX_REG * PRRU_MAX_REG];      /* the prior norm: |dpi|_W^2 = dpi^T W dpi (row stride np) */
  double w[PRRU_MAX_REG];                     /* drive weights (0 elsewhere) */
} geometry;

/* T_b from the prior body, G and W; PRRU_EINPUT for a prior body that is
 * not physical. */
static int prior_geometry(const prru_model *m, const double *pi0, geometry *G)
{
  memset(G, 0, sizeof *G);
  const int nb = m->mech->nbody, na = m->mech->nact, np = PRRU_NBODYPAR * nb + 3 * na;
  G->nbody = nb, G->np = np, G->ndrv = 3 * na;
  for (int b = 0; b < nb; b++) {
    const double *pb = pi0 + PRRU_NBODYPAR * b;
    double J[16], L[16], Li[16];
    if (!(pb[0] > 0)) return PRRU_EINPUT;
    pseudo_inertia(pb, J);
    /* tr(S_c) = tr(S) - m |c|^2, S_c the second moment about the centre. */
    const double trc = J[0] + J[5] + J[10] - (pb[1] * pb[1] + pb[2] * pb[2] + pb[3] * pb[3]) / pb[0];
    for (int i = 0; i < 3; i++) J[5 * i] += 1e-6 * trc / 3;
    if (!(trc > 0) || !chol4(J, L)) return PRRU_EINPUT;
    lower_inverse4(L, Li);
    for (int k = 0; k < PRRU_NBODYPAR; k++) {
      double e[PRRU_NBODYPAR] = {0}, Je[16], T1[16];
      e[k] = 1;
      pseudo_inertia(e, Je);
      for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
          double s = 0;
          for (int l = 0; l < 4; l++) s += Li[4 * i + l] * Je[4 * l + j];
          T1[4 * i + j] = s;
        }
      for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
          double s = 0;
          for (int l = 0; l < 4; l++) s += T1[4 * i + l] * Li[4 * j + l];
          G->G[b][k][4 * i + j] = s;
        }
    }
    for (int k = 0; k < PRRU_NBODYPAR; k++)
      for (int l = 0; l < PRRU_NBODYPAR; l++) {
        double s = 0;
        for (int q = 0; q < 16; q++) s += G->G[b][k][q] * G->G[b][l][q];
        G->W[(size_t)(PRRU_NBODYPAR * b + k) * np + PRRU_NBODYPAR * b + l] = s;
      }
  }
  const double L = prru_length_scale(m->mech);
  const double *gv = m->mech->gravity;
  double g = sqrt(gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2]);
  if (!(g > 0)) g = 9.81;
  const double tau = sqrt(L / g);
  for (int k = 0; k < G->ndrv; k++) {
    const int j = PRRU_NBODYPAR * nb + k, limb = k % na, kind = k / na;
    const double ms = pi0[PRRU_NBODYPAR * m->mech->slider[limb]];
    const double unit = kind == 0 ? ms : kind == 1 ? ms / tau : ms * g;
    if (!(pi0[j] >= 0) || !isfinite(pi0[j])) return PRRU_EINPUT;
    G->w[j] = fmax(pi0[j], unit);
    G->W[(size_t)j * np + j] = 1 / (G->w[j] * G->w[j]);
  }
  return PRRU_OK;
}

/* The affine map of the variables to pi: pi = p0 + P x (P: np x n, np
 * the model's standard parameters). */
typedef struct {
  int n;
  double p0[PRRU_MAX_REG];
  double *P;
} affine;

/* The blocks F_b = T_b^-1 J(pi(x)) T_b^-T - (eps + s) I and the drives
 * x_k / w_k - dmargin >= s of the map a (with s = x[a->n] when phase1). */
static void constraints(const geometry *G, const affine *a, double eps, double dmargin, int phase1, barrier *p)
{
  const int n = p->n, nb = G->nbody, ndrv = G->ndrv;
  for (int b = 0; b < nb; b++) {
    double *F0 = p->F0 + 16 * b;
    for (int k = 0; k < PRRU_NBODYPAR; k++) {
      const int j = PRRU_NBODYPAR * b + k;
      for (int q = 0; q < 16; q++) F0[q] += a->p0[j] * G->G[b][k][q];
      for (int i = 0; i < a->n; i++) {
        const double pij = a->P[(size_t)j * a->n + i];
        if (pij == 0) continue;
        double *Fi = p->F + ((size_t)b * n + i) * 16;
        for (int q = 0; q < 16; q++) Fi[q] += pij * G->G[b][k][q];
      }
    }
    for (int r = 0; r < 4; r++) {
      F0[5 * r] -= eps;
      if (phase1) p->F[((size_t)b * n + a->n) * 16 + 5 * r] = -1;
    }
  }
  for (int k = 0; k < ndrv; k++) {
    const int j = PRRU_NBODYPAR * nb + k;
    p->a0[k] = a->p0[j] / G->w[j] - dmargin;
    for (int i = 0; i < a->n; i++) p->a[(size_t)k * n + i] = a->P[(size_t)j * a->n + i] / G->w[j];
    if (phase1) p->a[(size_t)k * n + a->n] = -1;
  }
  /* The upper bounds: a log barrier needs a bounded set (a body no motion
   * reveals could otherwise grow without bound while the barrier falls). */
  for (int b = 0; b < nb; b++) {
    const int u = nb + b;
    for (int q = 0; q < 16; q++) p->F0[16 * u + q] = -p->F0[16 * b + q];
    for (int r = 0; r < 4; r++) p->F0[16 * u + 5 * r] += UPPER - eps;
    for (int i = 0; i < a->n; i++)
      for (int q = 0; q < 16; q++) p->F[((size_t)u * n + i) * 16 + q] = -p->F[((size_t)b * n + i) * 16 + q];
    if (phase1)
      for (int r = 0; r < 4; r++) p->F[((size_t)u * n + a->n) * 16 + 5 * r] = -1;
  }
  for (int k = 0; k < ndrv; k++) {
    const int u = ndrv + k;
    p->a0[u] = UPPER - dmargin - p->a0[k];
    for (int i = 0; i < a->n; i++) p->a[(size_t)u * n + i] = -p->a[(size_t)k * n + i];
    if (phase1) p->a[(size_t)u * n + a->n] = -1;
  }
  barrier_index(p);
}

/* mu |pi(x) - pi0|_W^2 added to p's objective; PRRU_ENOMEM. */
static int add_prior(const geometry *G, const affine *a, const double *pi0, double mu, barrier *p)
{
  const int n = a->n, np = G->np;
  double r0[PRRU_MAX_REG], Wr[PRRU_MAX_REG];
  for (int j = 0; j < np; j++) r0[j] = a->p0[j] - pi0[j];
  for (int j = 0; j < np; j++) {
    double s = 0;
    for (int k = 0; k < np; k++) s += G->W[(size_t)j * np + k] * r0[k];
    Wr[j] = s;
  }
  double f0 = 0;
  for (int j = 0; j < np; j++) f0 += r0[j] * Wr[j];
  p->f0 += mu * f0;
  /* Q += 2 mu P^T W P, c += 2 mu P^T W r0. */
  double *WP = malloc(sizeof(double) * (size_t)np * (size_t)n);
  if (!WP) return PRRU_ENOMEM;
  for (int j = 0; j < np; j++)
    for (int i = 0; i < n; i++) {
      double s = 0;
      for (int k = 0; k < np; k++) s += G->W[(size_t)j * np + k] * a->P[(size_t)k * n + i];
      WP[(size_t)j * n + i] = s;
    }
  for (int i = 0; i < n; i++) {
    double s = 0;
    for (int j = 0; j < np; j++) s += a->P[(size_t)j * n + i] * Wr[j];
    p->c[i] += 2 * mu * s;
    for (int l = 0; l < n; l++) {
      double q = 0;
      for (int j = 0; j < np; j++) q += a->P[(size_t)j * n + i] * WP[(size_t)j * n + l];
      p->Q[(size_t)i * p->n + l] += 2 * mu * q;
    }
  }
  free(WP);
  return PRRU_OK;
}

static void apply(const geometry *G, const affine *a, const double *x, double *pi)
{
  for (int j = 0; j < G->np; j++) {
    double s = a->p0[j];
    for (int i = 0; i < a->n; i++) s += a->P[(size_t)j * a->n + i] * x[i];
    pi[j] = s;
  }
}

static double prior_norm2(const geometry *G, const double *pi, const double *pi0)
{
  const int np = G->np;
  double s = 0;
  for (int j = 0; j < np; j++)
    for (int k = 0; k < np; k++) s += (pi[j] - pi0[j]) * G->W[(size_t)j * np + k] * (pi[k] - pi0[k]);
  return s;
}

/* The smallest eigenvalue of T_b^-1 J(pi_b) T_b^-T over the bodies. */
static double smallest_margin(const geometry *G, const double *pi)
{
  double lo = INFINITY;
  gsl_matrix *F = gsl_matrix_alloc(4, 4);
  gsl_vector *ev = gsl_vector_alloc(4);
  gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(4);
  if (!F || !ev || !w) lo = NAN;
  for (int b = 0; b < G->nbody && F && ev && w; b++) {
    for (int q = 0; q < 16; q++) {
      double s = 0;
      for (int k = 0; k < PRRU_NBODYPAR; k++) s += pi[PRRU_NBODYPAR * b + k] * G->G[b][k][q];
      F->data[q / 4 * F->tda + q % 4] = s;
    }
    gsl_eigen_symm(F, ev, w);
    for (int i = 0; i < 4; i++) lo = fmin(lo, gsl_vector_get(ev, i));
  }
  gsl_matrix_free(F), gsl_vector_free(ev);
  if (w) gsl_eigen_symm_free(w);
  return lo;
}

/* The null-space map: pi = pi_p + sum over the non-base parameters j of
 * x_j u_j (e_j - sum_i B_ij e_col(i)), pi_p the estimate put into the
 * prior (prru_base_to_standard), u_j = W_jj^-1/2 so that x is in units of
 * the prior norm. B (pi_p + P x) = beta^ for every x. */
static void null_map(const prru_base *b, const geometry *G, const double *beta, const double *pi0, affine *a)
{
  prru_base_to_standard(b, beta, pi0, a->p0);
  const int n = a->n, np = b->nreg;
  memset(a->P, 0, sizeof(double) * (size_t)np * (size_t)n);
  for (int i = 0; i < n; i++) {
    const int j = b->col[b->nbase + i];
    const double u = 1 / sqrt(G->W[(size_t)j * np + j]);
    a->P[(size_t)j * n + i] = u;
    for (int r = 0; r < b->nbase; r++) a->P[(size_t)b->col[r] * n + i] -= u * b->B[r * np + j];
  }
}

/* R^-1 (nbase x nbase, row-major, allocated) and the scale v_i =
 * sigma_w sqrt(C_ii) of each base parameter, C = (R^T R)^-1 = R^-1 R^-T:
 * C_ii is the squared norm of row i of R^-1. PRRU_ESINGULAR unless R is
 * regular. */
static int inverse_R(const prru_base *b, const prru_ident_result *r, double sigma_w, double **Rinv, double *v)
{
  const int p = b->nbase, np = b->nreg;
  double *Ri = calloc((size_t)p * p, sizeof(double));
  if (!Ri) return PRRU_ENOMEM;
  int st = PRRU_OK;
  for (int j = p - 1; j >= 0 && st == PRRU_OK; j--) {
    const double rjj = r->R[j * np + j];
    if (!(rjj != 0) || !isfinite(rjj)) st = PRRU_ESINGULAR;
    else {
      Ri[j * p + j] = 1 / rjj;
      for (int i = j - 1; i >= 0; i--) {
        double s = 0;
        for (int k = i + 1; k <= j; k++) s += r->R[i * np + k] * Ri[k * p + j];
        Ri[i * p + j] = -s / r->R[i * np + i];
      }
    }
  }
  for (int i = 0; i < p && st == PRRU_OK; i++) {
    double s = 0;
    for (int j = i; j < p; j++) s += Ri[i * p + j] * Ri[i * p + j];
    v[i] = sigma_w * sqrt(s);
  }
  if (st != PRRU_OK) free(Ri), Ri = NULL;
  *Rinv = Ri;
  return st;
}

/* d^2 = |R (beta - beta^)|^2 / sigma_w^2. */
static double mahalanobis2(const prru_base *b, const prru_ident_result *r, double sigma_w, const double *beta)
{
  double d2 = 0;
  for (int i = 0; i < b->nbase; i++) {
    double s = 0;
    for (int j = i; j < b->nbase; j++) s += r->R[i * b->nreg + j] * (beta[j] - r->beta[j]);
    d2 += (s / sigma_w) * (s / sigma_w);
  }
  return d2;
}

/* Phase I: whether some x has every block >= eps + s and every drive >=
 * s for an s > 0; x the point found. */
static int exact_feasible(const geometry *G, const affine *a, double eps, double *x, int *steps, int *feasible)
{
  barrier p;
  const int n = a->n + 1;
  int st = barrier_alloc(&p, n, 2 * G->nbody, 2 * G->ndrv);
  if (st != PRRU_OK) return st;
  p.phase1 = 1;
  p.s_goal = 1e-3;
  constraints(G, a, eps, DRIVE_MARGIN, 1, &p);
  p.c[n - 1] = -1;
  /* Start: x = 0 and s below every constraint (|lambda| <= |F|_F). */
  double s = INFINITY;
  for (int b = 0; b < p.nlmi; b++) {
    double nf = 0;
    for (int q = 0; q < 16; q++) nf += p.F0[16 * b + q] * p.F0[16 * b + q];
    s = fmin(s, -sqrt(nf));
  }
  for (int k = 0; k < p.nlin; k++) s = fmin(s, p.a0[k]);
  memset(x, 0, sizeof(double) * (size_t)n);
  x[n - 1] = s - 1;
  st = barrier_solve(&p, x, 1e-11, steps);
  *feasible = st == PRRU_OK && x[n - 1] > 0;
  barrier_free(&p);
  return st;
}

/* Phase II: the prior-nearest x with every block >= eps, from a strictly
 * feasible x. */
static int nearest_prior(const geometry *G, const affine *a, const double *pi0, double eps, double *x, int *steps)
{
  barrier p;
  int st = barrier_alloc(&p, a->n, 2 * G->nbody, 2 * G->ndrv);
  if (st != PRRU_OK) return st;
  constraints(G, a, eps, DRIVE_MARGIN, 0, &p);
  st = add_prior(G, a, pi0, 1, &p);
  if (st == PRRU_OK) st = barrier_solve(&p, x, 1e-14, steps);
  barrier_free(&p);
  return st;
}

/* Within the covariance: x = (null-space part, y), the base parameters
 * beta^ + sigma_w R^-1 y, so that d^2 = |y|^2 (whitened: the quadratic is
 * as well conditioned as it can be, whatever the excitation's
 * conditioning); minimises |y|^2 + mu |pi - pi0|_W^2 from the prior
 * (moved inside the drives' bounds). */
static int nearest_estimate(const prru_base *b, const prru_ident_result *r, const geometry *G, const affine *a0,
                            const double *pi0, const double *Rinv, double sigma_w, const prru_consistent_options *o,
                            double *pi, int *steps)
{
  const int nb = b->nbase, nz = a0->n, n = nz + nb, np = G->np;
  affine a = {n, {0}, calloc((size_t)np * (size_t)n, sizeof(double))};
  double *x = calloc((size_t)n, sizeof(double));
  barrier p;
  int st = a.P && x ? barrier_alloc(&p, n, 2 * G->nbody, 2 * G->ndrv) : PRRU_ENOMEM;
  if (st != PRRU_OK) {
    free(a.P), free(x);
    return st;
  }
  memcpy(a.p0, a0->p0, sizeof(double) * (size_t)np);
  for (int j = 0; j < np; j++)
    for (int i = 0; i < nz; i++) a.P[(size_t)j * n + i] = a0->P[(size_t)j * nz + i];
  for (int i = 0; i < nb; i++)
    for (int k = i; k < nb; k++) a.P[(size_t)b->col[i] * n + nz + k] = sigma_w * Rinv[i * nb + k];
  /* Twice the margins: the prior-nearest step that follows, at these base
   * parameters, then starts with the margins' worth of room. */
  constraints(G, &a, 2 * o->eps, 2 * DRIVE_MARGIN, 0, &p);
  st = add_prior(G, &a, pi0, o->mu, &p);
  for (int i = 0; i < nb; i++) p.Q[(size_t)(nz + i) * n + nz + i] += 2;
  /* Start at the prior with each drive coefficient at least 1e-3 of its
   * weight (strictly inside); pi -> (x, y) inverts the map. */
  double ps[PRRU_MAX_REG], beta[PRRU_MAX_REG];
  memcpy(ps, pi0, sizeof(double) * (size_t)np);
  for (int k = 0; k < G->ndrv; k++) {
    const int j = PRRU_NBODYPAR * G->nbody + k;
    ps[j] = fmax(ps[j], 1e-3 * G->w[j]);
  }
  prru_base_params(b, ps, beta);
  for (int i = 0; i < nb; i++) {
    double s = 0;
    for (int k = i; k < nb; k++) s += r->R[i * np + k] * (beta[k] - r->beta[k]);
    x[nz + i] = s / sigma_w;
  }
  for (int i = 0; i < nz; i++) {
    const int j = b->col[nb + i];
    x[i] = (ps[j] - a.p0[j]) / a0->P[(size_t)j * nz + i];
  }
  if (st == PRRU_OK) st = barrier_solve(&p, x, 1e-10, steps);
  apply(G, &a, x, pi);
  barrier_free(&p);
  free(a.P), free(x);
  return st;
}

int prru_ident_consistent(const prru_model *m, const prru_base *b, const prru_ident_result *r,
                          const double pi0[], const prru_consistent_options *o,
                          double pi[], prru_consistent_result *c)
{
  memset(c, 0, sizeof *c);
  if (!(o->mu > 0) || !isfinite(o->mu) || !(o->alpha > 0 && o->alpha < 1) || !(o->sigma_floor >= 0) ||
      !isfinite(o->sigma_floor) || !(o->eps >= 0 && o->eps <= 1e-3) || o->max_newton <= 0 || b->nbase <= 0 ||
      !prru_base_fits(m, b))
    return PRRU_EINPUT;
  const int np = b->nreg;
  for (int j = 0; j < np; j++)
    if (!isfinite(pi0[j])) return PRRU_EINPUT;
  prru_gsl_init();
  geometry *G = malloc(sizeof *G);
  const int nz = np - b->nbase;
  affine a = {nz, {0}, calloc((size_t)np * (size_t)(nz > 0 ? nz : 1), sizeof(double))};
  double *x = calloc((size_t)nz + 1, sizeof(double));
  double v[PRRU_MAX_REG], *Rinv = NULL;
  int st = G && a.P && x ? PRRU_OK : PRRU_ENOMEM;
  if (st == PRRU_OK) st = prior_geometry(m, pi0, G);
  c->sigma_w = fmax(r->sigma * sqrt(r->inflation > 1 ? r->inflation : 1), o->sigma_floor * r->yrms);
  if (st == PRRU_OK && !(c->sigma_w > 0)) st = PRRU_EINPUT; /* no force in the data */
  if (st == PRRU_OK) st = inverse_R(b, r, c->sigma_w, &Rinv, v);
  int steps = o->max_newton, feasible = 0;
  if (st == PRRU_OK) {
    null_map(b, G, r->beta, pi0, &a);
    st = exact_feasible(G, &a, o->eps, x, &steps, &feasible);
  }
  if (st == PRRU_OK && feasible) {
    c->how = PRRU_CONSISTENT_EXACT;
    st = nearest_prior(G, &a, pi0, o->eps, x, &steps);
    apply(G, &a, x, pi);
  } else if (st == PRRU_OK) {
    c->how = PRRU_CONSISTENT_COVARIANCE;
    st = nearest_estimate(b, r, G, &a, pi0, Rinv, c->sigma_w, o, pi, &steps);
    /* Then the prior alone decides the directions no motion reveals, at
     * those base parameters: in the problem above its weight mu makes
     * them converge only to sqrt(gap / mu). pi is strictly feasible. */
    double beta[PRRU_MAX_REG];
    if (st == PRRU_OK) prru_base_params(b, pi, beta);
    if (st == PRRU_OK && mahalanobis2(b, r, c->sigma_w, beta) <= gsl_cdf_chisq_Qinv(o->alpha, b->nbase)) {
      /* A start from phase I: pi's own coordinates in this map can round
       * outside (its margins are at the barrier's last 1 / t). */
      null_map(b, G, beta, pi0, &a);
      int sf = exact_feasible(G, &a, o->eps, x, &steps, &feasible);
      /* A refinement: where it fails (the Newton budget), pi stands. */
      if (sf == PRRU_OK && feasible && nearest_prior(G, &a, pi0, o->eps, x, &steps) == PRRU_OK) apply(G, &a, x, pi);
      steps = steps < 0 ? 0 : steps;
    }
  }
  if (st == PRRU_OK) {
    prru_base_params(b, pi, c->beta);
    c->d2 = mahalanobis2(b, r, c->sigma_w, c->beta);
    c->d2_max = gsl_cdf_chisq_Qinv(o->alpha, b->nbase);
    for (int i = 0; i < b->nbase; i++) c->t[i] = (c->beta[i] - r->beta[i]) / v[i];
    memcpy(c->w, G->w, sizeof(double) * (size_t)np);
    c->prior_dist = sqrt(prior_norm2(G, pi, pi0));
    c->margin = smallest_margin(G, pi);
    c->newton = o->max_newton - steps;
    if (c->d2 > c->d2_max) st = PRRU_ESINGULAR;
  }
  free(G), free(a.P), free(x), free(Rinv);
  return st;
}

/* Masses and principal moments below this are written as 0 in a model
 * file (prru_model_file_text), which the loader refuses. */
#define FILE_FLOOR 1e-9

int prru_ident_model_params(const prru_model *m, const prru_base *b, const double pi[], prru_params *p,
                            char *why, int len)
{
  const int nb = m->mech->nbody, na = m->mech->nact;
  if (!prru_base_fits(m, b))
    return prru_fail(why, len, PRRU_EINPUT, "the base parameters were computed for a model of %d bodies and %d "
                     "actuators, not this one's %d and %d", b->nbody, b->nact, nb, na);
  /* Geometry and gravity: the model's (the regressor's, which identification needs). */
  prru_model_params(m, p);
  for (int k = 0; k < nb; k++) {
    double mass, c[3], I[6];
    if (prru_ident_body(pi + PRRU_NBODYPAR * k, &mass, c, I) != PRRU_OK)
      return prru_fail(why, len, PRRU_EINPUT, "body %s: mass %.6g kg is not positive", m->mech->body_names[k],
                       pi[PRRU_NBODYPAR * k]);
    /* A mass or principal moment the fit left below the file's floor (a
     * body on the consistent set's boundary, whose margin is 1e-9 of the
     * prior body: data that hardly reveal a slider's mass beside its
     * armature can put it there) is raised to 1e-9 kg or kg m^2, which
     * keeps the body consistent (the centre of mass stays; the second
     * moments about it change by +-5e-10); prru_model_file_text's read
     * back catches anything this misses. */
    mass = fmax(mass, FILE_FLOOR);
    for (int d = 0; d < 3; d++) I[d] = fmax(I[d], FILE_FLOOR);
    const double m2 = I[0] * I[1] - I[3] * I[3];
    const double m3 = I[0] * (I[1] * I[2] - I[5] * I[5]) - I[3] * (I[3] * I[2] - I[5] * I[4]) +
                      I[4] * (I[3] * I[5] - I[1] * I[4]);
    if (!(I[0] > 0 && m2 > 0 && m3 > 0))
      return prru_fail(why, len, PRRU_EINPUT, "body %s: the inertia about the centre of mass is not positive "
                       "definite", m->mech->body_names[k]);
    p->mass[k] = mass;
    memcpy(p->com[k], c, sizeof c);
    memcpy(p->inertia[k], I, sizeof I);
  }
  double *dr[3] = {p->armature, p->damping, p->coulomb};
  static const char *const dn[3] = {"armature", "damping", "coulomb"};
  for (int g = 0; g < 3; g++)
    for (int i = 0; i < na; i++) {
      const double v = pi[PRRU_NBODYPAR * nb + g * na + i];
      if (!(v >= 0)) return prru_fail(why, len, PRRU_EINPUT, "%s%d = %.6g is negative", dn[g], i + 1, v);
      dr[g][i] = v;
    }
  p->coulomb_velocity = b->vs;
  return PRRU_OK;
}
