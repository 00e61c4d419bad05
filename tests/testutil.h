/* Minimal assertion helpers shared by the C tests: every check counts,
 * failures print what and by how much, main returns tu_finish(). */
#ifndef PRRU_TESTUTIL_H
#define PRRU_TESTUTIL_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru_kernels.h"

static int tu_checks, tu_failures;

/* max_i |a_i - b_i| / max(max_i |b_i|, floor): relative to the array's scale,
 * so that structurally-zero entries do not demand absolute 0. */
static inline double tu_relerr(const double *a, const double *b, int n, double floor)
{
  double err = 0, scale = floor;
  for (int i = 0; i < n; i++) {
    double e = fabs(a[i] - b[i]);
    if (!(e <= err)) err = e; /* NaN propagates as a failure */
    if (fabs(b[i]) > scale) scale = fabs(b[i]);
  }
  return err / scale;
}

static inline int tu_check(int ok, const char *what, double value, double bound)
{
  tu_checks++;
  if (!ok) {
    tu_failures++;
    fprintf(stderr, "FAIL %s: %.3e (bound %.1e)\n", what, value, bound);
  }
  return ok;
}

#define TU_CLOSE(a, b, n, rtol, what) \
  do { double tu_e_ = tu_relerr((a), (b), (n), 1e-300); \
       tu_check(tu_e_ <= (rtol), (what), tu_e_, (rtol)); } while (0)
#define TU_TRUE(cond, what) tu_check(!!(cond), (what), 0.0, 0.0)

/* The 1-norm of a rows x cols matrix (row-major) and the infinity norm of
 * a vector; NaN propagates (the tolerance checks then fail). */
static inline double tu_norm1(const double *A, int rows, int cols)
{
  double big = 0;
  for (int j = 0; j < cols; j++) {
    double s = 0;
    for (int i = 0; i < rows; i++) s += fabs(A[cols * i + j]);
    if (!(s <= big)) big = s;
  }
  return big;
}

static inline double tu_norm_inf(const double *v, int n)
{
  double big = 0;
  for (int i = 0; i < n; i++)
    if (!(fabs(v[i]) <= big)) big = fabs(v[i]);
  return big;
}

/* The inverse of a 3 x 3 by its adjugate (for a well-conditioned matrix;
 * no pivoting). */
static inline void tu_inverse3(const double M[9], double inv[9])
{
  double c[9];
  c[0] = M[4] * M[8] - M[5] * M[7], c[1] = M[2] * M[7] - M[1] * M[8];
  c[2] = M[1] * M[5] - M[2] * M[4], c[3] = M[5] * M[6] - M[3] * M[8];
  c[4] = M[0] * M[8] - M[2] * M[6], c[5] = M[2] * M[3] - M[0] * M[5];
  c[6] = M[3] * M[7] - M[4] * M[6], c[7] = M[1] * M[6] - M[0] * M[7];
  c[8] = M[0] * M[4] - M[1] * M[3];
  const double det = M[0] * c[0] + M[1] * c[3] + M[2] * c[6];
  for (int i = 0; i < 9; i++) inv[i] = c[i] / det;
}

static inline int tu_finish(const char *suite)
{
  printf("%s: %d passed, %d failed\n", suite, tu_checks - tu_failures, tu_failures);
  return tu_failures ? 1 : 0;
}

/* c = a x b, y = A x for row-major 3x3 A. */
static inline void tu_cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline void tu_matvec3(const double A[9], const double x[3], double y[3])
{
  for (int i = 0; i < 3; i++) y[i] = A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}

/* The dense Q (6 NBODY x NLAMBDA, row-major) from the entries that
 * prru_reaction_basis returns, those that are not identically zero. */
static inline void tu_reaction_basis_scatter(const double nz[PRRU_REACTION_BASIS_NNZ],
                                             double Q[6 * PRRU_NBODY * PRRU_NLAMBDA])
{
  memset(Q, 0, sizeof(double) * 6 * PRRU_NBODY * PRRU_NLAMBDA);
  for (int k = 0; k < PRRU_REACTION_BASIS_NNZ; k++) Q[prru_reaction_basis_index[k]] = nz[k];
}

/* The dense Q at q. */
static inline void tu_reaction_basis_dense(const double q[3], double Q[6 * PRRU_NBODY * PRRU_NLAMBDA])
{
  double nz[PRRU_REACTION_BASIS_NNZ];
  prru_reaction_basis(q, nz);
  tu_reaction_basis_scatter(nz, Q);
}

/* The vector tanh's share in a derivative in qd (drives with Coulomb
 * friction f_i, smoothing velocity vs; batched kernels against scalar
 * ones): the friction's derivative in qd is J_d^T diag(f_i / vs (1 -
 * t_i^2)) J_d, t_i = tanh(dd_i / vs); where t_i nears +-1, 1 - t_i^2
 * cancels and libmvec's few ulp in t_i (<= 4) move it by 2 t_i that,
 * absolutely: up to 8 eps f / vs |J_d|^2 |M^-1| in dqdd/dqd (Frobenius
 * norms, M given) and 8 eps f / vs |J_d| in dfd/dqd (M NULL: inverse
 * dynamics never solves by M, and J_d^-T J_d^T cancels); 16 eps for
 * margin. No input perturbation shows it: t_i's slope vanishes where it
 * cancels. 0 without friction. */
static inline double tu_tanh_share(const double *Jd, int nact, const double *M, double f, double vs)
{
  if (!(f > 0) || !(vs > 0)) return 0;
  double nj = 0;
  for (int i = 0; i < 3 * nact; i++) nj += Jd[i] * Jd[i];
  if (!M) return 16 * 2.220446049250313e-16 * f / vs * sqrt(nj);
  double c[9], ninv = 0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[3 * j + i] = M[3 * ((i + 1) % 3) + (j + 1) % 3] * M[3 * ((i + 2) % 3) + (j + 2) % 3] -
                     M[3 * ((i + 1) % 3) + (j + 2) % 3] * M[3 * ((i + 2) % 3) + (j + 1) % 3];
  const double det = M[0] * c[0] + M[1] * c[3] + M[2] * c[6];
  for (int i = 0; i < 9; i++) ninv += c[i] * c[i];
  return 16 * 2.220446049250313e-16 * f / vs * nj * sqrt(ninv) / fabs(det);
}

/* Deterministic uniform in [lo, hi] (xorshift64*): tests reproduce exactly. */
static unsigned long long tu_rng_state = 0x9E3779B97F4A7C15ULL;
static inline double tu_uniform(double lo, double hi)
{
  tu_rng_state ^= tu_rng_state >> 12;
  tu_rng_state ^= tu_rng_state << 25;
  tu_rng_state ^= tu_rng_state >> 27;
  unsigned long long r = tu_rng_state * 2685821657736338717ULL;
  return lo + (hi - lo) * ((double)(r >> 11) / 9007199254740992.0);
}
#endif
