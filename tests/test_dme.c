/* Dynamic manipulability (prru_dme.h) against evidence built another way:
 * the reference library's M, J_d and platform Jacobian (paper equations
 * with GSL, not the generated kernels), a pseudo-inverse of JtR from the
 * regularized normal equations instead of a rotation, GSL's symmetric
 * eigensolver on the 2x2 quadratic form of the ellipse instead of a Jacobi
 * rotation, and the reference's own GSL-SVD w_R. Then the geometry
 * (ellipse in span{e1, v}, segment along z), singular and unreachable
 * poses, and maps: threads vs serial, summary vs a recount. Properties of
 * any model; the paper's claims are in paper_dme.c.
 * With four actuators (spec section 12) J_d^-1 is J_d^+ throughout (the
 * independent route takes it from GSL's SVD least squares), Mt is 4x4 and
 * JtR, JtT 3x4, and the singular locus is sought where the scaled J_d
 * loses rank (its smallest singular value), not where det changes sign. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>

#include "testbuild.h"
#include "prru_dme.h"
#include "prru_ref.h"
#include "testutil.h"

#define PI 3.14159265358979323846

#define NA PRRU_NACT

static prru_model M;
static prru_data *D;
static prru_ref_params P;
static prru_ref_ws *W;

static void solve3(const double A[9], const double *B, int ncols, double *X)
{
  double a[9], b[3], x[3];
  gsl_permutation *perm = gsl_permutation_alloc(3);
  int sign;
  memcpy(a, A, sizeof a);
  gsl_matrix_view av = gsl_matrix_view_array(a, 3, 3);
  gsl_linalg_LU_decomp(&av.matrix, perm, &sign);
  for (int c = 0; c < ncols; c++) {
    for (int i = 0; i < 3; i++) b[i] = B[i * ncols + c];
    gsl_vector_view bv = gsl_vector_view_array(b, 3), xv = gsl_vector_view_array(x, 3);
    gsl_linalg_LU_solve(&av.matrix, perm, &bv.vector, &xv.vector);
    for (int i = 0; i < 3; i++) X[i * ncols + c] = x[i];
  }
  gsl_permutation_free(perm);
}

static void matmul(const double *A, const double *B, double *C, int n, int k, int m, int ta)
{
  for (int i = 0; i < n; i++)
    for (int j = 0; j < m; j++) {
      double s = 0;
      for (int l = 0; l < k; l++) s += (ta ? A[l * n + i] : A[i * k + l]) * B[l * m + j];
      C[i * m + j] = s;
    }
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double dotn(const double *a, const double *b, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* GSL's SVD of an m x n matrix A (row-major), m or n equal to NA or 3:
 * GSL wants rows >= columns, so a wide A is decomposed as A^T. On return
 * A = U S V^T with U m x k, V n x k, k = min(m, n), S descending (U, V
 * row-major with k columns). */
static void svd(const double *A, int m, int n, double *U, double *S, double *V)
{
  const int tr = m < n, r = tr ? n : m, k = tr ? m : n;
  double a[NA * NA], v[NA * NA], s[NA], wk[NA];
  for (int i = 0; i < m; i++)
    for (int j = 0; j < n; j++) a[tr ? j * k + i : i * k + j] = A[i * n + j];
  gsl_matrix_view av = gsl_matrix_view_array(a, r, k), vv = gsl_matrix_view_array(v, k, k);
  gsl_vector_view sv = gsl_vector_view_array(s, k), wv = gsl_vector_view_array(wk, k);
  gsl_linalg_SV_decomp(&av.matrix, &vv.matrix, &sv.vector, &wv.vector);
  /* a (r x k) holds the left vectors of the decomposed matrix, v its right ones. */
  memcpy(tr ? V : U, a, (size_t)r * k * sizeof a[0]);
  memcpy(tr ? U : V, v, (size_t)k * k * sizeof v[0]);
  memcpy(S, s, (size_t)k * sizeof s[0]);
}

/* X = A^+ (n x m) from svd() of the m x n A, keeping the first `rank`
 * singular values. */
static void pinv(const double *A, int m, int n, int rank, double *X)
{
  const int k = m < n ? m : n;
  double U[NA * NA], V[NA * NA], S[NA];
  svd(A, m, n, U, S, V);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < m; j++) {
      double x = 0;
      for (int l = 0; l < rank; l++) x += V[i * k + l] * U[j * k + l] / S[l];
      X[i * m + j] = x;
    }
}

typedef struct {
  double w_R, semi[2], dir[2][3], half_T, Mt[NA * NA];
} indep;

/* The DME from the reference library, built without the runtime's route.
 * Errors found over the sample (w_R, lengths, relative): 3e-13 for the
 * paper's model, 8e-14 for the prototype, 2e-15 for the 4-PRRU, so the
 * 1e-12 bounds below leave a margin of at least 3 and still catch any
 * real slip.
 * J_d^+ (spec section 12): J_d^-1 by GSL's LU for three actuators; for more,
 * the least-squares solutions of J_d x = e_i by GSL's SVD, column by column
 * (the runtime uses a Householder QR of the column-scaled J_d). */
static int independent(const double q[3], indep *r)
{
  double Mref[9], Jd[3 * NA], H[3 * PRRU_NH], Jinv[3 * NA];
  if (prru_ref_mass(&P, W, q, Mref) || prru_ref_jd(&P, q, Jd) || prru_ref_jacobians(&P, W, q, H))
    return 1;
  if (NA == 3) {
    const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    solve3(Jd, I3, 3, Jinv);
  } else {
    double U[NA * 3], S[3], V[9];
    svd(Jd, NA, 3, U, S, V);
    for (int c = 0; c < NA; c++) {
      double b[NA] = {0}, x[3];
      b[c] = 1.0;
      /* x = V S^-1 U^T e_c, GSL's SVD least-squares solve. */
      gsl_matrix_view Uv = gsl_matrix_view_array(U, NA, 3), Vv = gsl_matrix_view_array(V, 3, 3);
      gsl_vector_view Sv = gsl_vector_view_array(S, 3), bv = gsl_vector_view_array(b, NA),
                      xv = gsl_vector_view_array(x, 3);
      gsl_linalg_SV_solve(&Uv.matrix, &Vv.matrix, &Sv.vector, &bv.vector, &xv.vector);
      for (int i = 0; i < 3; i++) Jinv[i * NA + c] = x[i];
    }
  }
  double tmp[3 * NA], Mt[NA * NA], JtR[3 * NA], JtT[3 * NA];
  matmul(Mref, Jinv, tmp, 3, 3, NA, 0);
  matmul(Jinv, tmp, Mt, NA, 3, NA, 1);
  matmul(H, Jinv, JtR, 3, 3, NA, 0);        /* rows 0-2 of H: J_R,P */
  /* The translational DME is the tool point's, O' = (0, 0, q3) by the
   * definition of q, so J_T,O' = e3 e3^T whatever the platform's centre of
   * mass (H's J_T,P rows are the centre's). */
  const double JTO[9] = {0, 0, 0, 0, 0, 0, 0, 0, 1};
  matmul(JTO, Jinv, JtT, 3, 3, NA, 0);

  /* n: unit normal of range(JtR) = range(J_R,P), from its columns 0 and 1. */
  double c0[3] = {H[0], H[3], H[6]}, c1[3] = {H[1], H[4], H[7]}, n[3], qa[3], qb[3];
  tu_cross(c0, c1, n);
  double nn = sqrt(dot(n, n));
  for (int i = 0; i < 3; i++) n[i] /= nn;
  double e1[3] = {1, 0, 0}, t = dot(e1, n);
  for (int i = 0; i < 3; i++) qa[i] = e1[i] - t * n[i];
  t = sqrt(dot(qa, qa));
  for (int i = 0; i < 3; i++) qa[i] /= t;
  tu_cross(n, qa, qb);
  /* JtR^+ Q = JtR^T (JtR JtR^T + n n^T)^-1 Q (see the header of this file). */
  double K[9], Q[6], Z[6], X[2 * NA], BQ[2 * NA];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = 0;
      for (int l = 0; l < NA; l++) s += JtR[NA * i + l] * JtR[NA * j + l];
      K[3 * i + j] = s + n[i] * n[j];
    }
  for (int i = 0; i < 3; i++) {
    Q[2 * i] = qa[i];
    Q[2 * i + 1] = qb[i];
  }
  solve3(K, Q, 2, Z);
  matmul(JtR, Z, X, NA, 3, 2, 1);
  matmul(Mt, X, BQ, NA, NA, 2, 0);
  double F[4];
  matmul(BQ, BQ, F, 2, NA, 2, 1);
  gsl_matrix_view Fv = gsl_matrix_view_array(F, 2, 2);
  double ev[2], evec[4];
  gsl_vector_view evv = gsl_vector_view_array(ev, 2);
  gsl_matrix_view evecv = gsl_matrix_view_array(evec, 2, 2);
  gsl_eigen_symmv_workspace *ws = gsl_eigen_symmv_alloc(2);
  gsl_eigen_symmv(&Fv.matrix, &evv.vector, &evecv.matrix, ws);
  gsl_eigen_symmv_free(ws);
  gsl_eigen_symmv_sort(&evv.vector, &evecv.matrix, GSL_EIGEN_SORT_VAL_DESC);
  memcpy(r->Mt, Mt, sizeof Mt);
  r->w_R = sqrt(ev[0] / ev[1]);
  for (int k = 0; k < 2; k++) {
    r->semi[k] = 1.0 / sqrt(ev[k]);
    for (int i = 0; i < 3; i++) r->dir[k][i] = Q[2 * i] * evec[k] + Q[2 * i + 1] * evec[2 + k];
  }
  /* Translational: GSL SVD of JtT, pseudo-inverse from its one singular
   * value, then the largest singular value of Mt JtT^+. */
  double Pi[3 * NA], B[3 * NA], U[NA * NA], V[NA * NA], S[NA];
  pinv(JtT, 3, NA, 1, Pi);
  matmul(Mt, Pi, B, NA, NA, 3, 0);
  svd(B, NA, 3, U, S, V);
  r->half_T = 1.0 / S[0];
  return 0;
}

static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

static void test_against_independent(void)
{
  double worst_w = 0, worst_ref = 0, worst_len = 0, worst_dir = 0, worst_T = 0, worst_plane = 0,
         worst_z = 0, worst_orth = 0;
  int n_ok = 0;
  for (int k = 0; k < 400; k++) {
    double q[3] = {tu_uniform(-PI / 6, PI / 6), tu_uniform(-PI / 4, PI / 6), tu_uniform(-0.8, 0.1)};
    if (k == 0) q[0] = q[1] = q[2] = 0.0;
    prru_dme r;
    if (prru_dme_eval(&M, D, q, &r) != PRRU_OK || r.jd_rcond < 1e-3) continue;
    indep x;
    double wref;
    if (!TU_TRUE(independent(q, &x) == 0 && prru_ref_w_r(&P, W, q, &wref) == 0, "reference DME"))
      continue;
    n_ok++;
    if (k < 20) TU_CLOSE(r.Mt, x.Mt, NA * NA, 1e-12, "Mt vs J_d^+T M J_d^+ from the reference");
    const double scale = 1.0;
    double e = rel(r.w_R, x.w_R) / scale;
    if (!(e <= worst_w)) worst_w = e;
    e = rel(r.w_R, wref) / scale;
    if (!(e <= worst_ref)) worst_ref = e;
    e = rel(r.half_length_T, x.half_T) / scale;
    if (!(e <= worst_T)) worst_T = e;
    double v[3] = {0, cos(q[0]), sin(q[0])}, e1[3] = {1, 0, 0}, nrm[3]; /* v = Rx(q1) e2 */
    tu_cross(e1, v, nrm);
    for (int a = 0; a < 2; a++) {
      e = rel(r.semi_axis[a], x.semi[a]) / scale;
      if (!(e <= worst_len)) worst_len = e;
      e = 1.0 - fabs(dot(r.axis_dir[a], x.dir[a]));
      if (!(e <= worst_dir)) worst_dir = e;
      e = fabs(dot(r.axis_dir[a], nrm));
      if (!(e <= worst_plane)) worst_plane = e;
      e = fabs(dot(r.axis_dir[a], r.axis_dir[a]) - 1.0);
      if (!(e <= worst_orth)) worst_orth = e;
    }
    e = fabs(dot(r.axis_dir[0], r.axis_dir[1]));
    if (!(e <= worst_orth)) worst_orth = e;
    e = fabs(r.dir_T[0]) + fabs(r.dir_T[1]) + fabs(r.dir_T[2] - 1.0);
    if (!(e <= worst_z)) worst_z = e;
  }
  printf("DME over %d poses vs independent: w_R %.1e (vs prru_ref_w_r %.1e), semi-axes %.1e, "
         "directions %.1e, translational %.1e\n", n_ok, worst_w, worst_ref, worst_len, worst_dir, worst_T);
  TU_TRUE(n_ok > 300, "enough regular sample poses");
  tu_check(worst_w <= 1e-12, "w_R vs reference M and 2x2 eigenvalues", worst_w, 1e-12);
  tu_check(worst_ref <= 1e-12, "w_R vs prru_ref_w_r (GSL SVD)", worst_ref, 1e-12);
  tu_check(worst_len <= 1e-12, "semi-axis lengths vs 1/sqrt(eigenvalues)", worst_len, 1e-12);
  tu_check(worst_dir <= 1e-12, "semi-axis directions vs eigenvectors (1 - |cos|)", worst_dir, 1e-12);
  tu_check(worst_T <= 1e-12, "translational half-length vs GSL SVD", worst_T, 1e-12);
  tu_check(worst_plane <= 1e-14, "semi-axes lie in span{e1, v}", worst_plane, 1e-14);
  tu_check(worst_orth <= 1e-14, "semi-axis directions orthonormal", worst_orth, 1e-14);
  tu_check(worst_z <= 1e-15, "translational segment along +z", worst_z, 1e-15);
}

/* The ellipse's boundary: |Mt JtR^+ a| = 1 at a = semi_axis_i dir_i, with
 * JtR^+ a found as the minimum-norm solution by GSL's SVD least squares
 * (JtR is 3 x NACT of rank 2: the rounding-level singular value dropped). */
static void test_boundary(void)
{
  double q[3] = {0.23, -0.31, -0.2}, worst = 0;
  prru_dme r;
  if (!TU_TRUE(prru_dme_eval(&M, D, q, &r) == PRRU_OK, "regular pose for the boundary test")) return;
  double X[NA * 3];
  pinv(r.JtR, 3, NA, 2, X);
  for (int a = 0; a < 2; a++) {
    double x[NA], b[3], f[NA];
    for (int i = 0; i < 3; i++) b[i] = r.semi_axis[a] * r.axis_dir[a][i];
    matmul(X, b, x, NA, 3, 1, 0);
    matmul(r.Mt, x, f, NA, NA, 1, 0);
    double e = fabs(sqrt(dotn(f, f, NA)) - 1.0);
    if (e > worst) worst = e;
  }
  tu_check(worst <= 1e-12, "|Mt JtR^+ a| = 1 at the semi-axis tips", worst, 1e-12);
}

static double det3(const double a[9])
{
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

static int all_nan(const prru_dme *r)
{
  return isnan(r->w_R) && isnan(r->sigma[0]) && isnan(r->sigma[1]) && isnan(r->semi_axis[1]) &&
         isnan(r->axis_dir[1][2]) && isnan(r->sigma_T) && isnan(r->half_length_T) &&
         isnan(r->dir_T[2]) && isnan(r->Mt[4]) && isnan(r->Mt[NA * NA - 1]) && isnan(r->JtR[0]) &&
         isnan(r->JtT[3 * NA - 1]);
}

/* sigma_3 / sigma_1 of Js = J_d diag(1/L, 1/L, 1) at (q1, q2, 0), L the
 * mean upper-link length (the runtime's scaling); NaN where unreachable,
 * and where margin > 0, also when a point at distance margin along q1,
 * q2 or a diagonal is unreachable. */
static double sigma_ratio(double q1, double q2, double margin)
{
  for (int di = -1; margin > 0 && di <= 1; di++)
    for (int dj = -1; dj <= 1; dj++)
      if ((di || dj) && isnan(sigma_ratio(q1 + di * margin, q2 + dj * margin, 0))) return NAN;
  double L = 0, J[3 * NA], U[3 * NA], S[3], V[9];
  for (int i = 0; i < PRRU_NLIMB; i++) L += prru_mech.l1[i] / PRRU_NLIMB;
  prru_jd((const double[3]){q1, q2, 0}, J);
  for (int i = 0; i < 3 * NA; i++) {
    if (!isfinite(J[i])) return NAN;
    if (i % 3 < 2) J[i] /= L;
  }
  svd(J, NA, 3, U, S, V);
  return S[2] / S[0];
}

/* A pose of the model's own singular locus in |q1|, |q2| <= pi/3 at
 * q3 = 0 (J_d does not depend on q3); 0 when the grid finds none.
 * Three actuators: a sign change of det J_d between two regular grid
 * neighbours, bisected to the last bit.
 * More (spec section 12): J_d is NACT x 3 and singular where it loses
 * rank, i.e. where the smallest singular value of the scaled J_d vanishes.
 * That does not change sign: the locus (generically isolated points) is
 * sought as the least sigma_3 / sigma_1 over the 61 x 61 grid, refined by
 * a shrinking pattern search and accepted below 1e-12, among the points
 * whose grid neighbours (one spacing, 0.035 rad, away) are all reachable:
 * at the edge of reach a limb stretches out and a row of J_d grows without
 * bound, which drives the ratio to 0 without any loss of rank. *best gets
 * the least ratio found. */
static int find_singular(double qs[3], double *best)
{
  *best = NAN;
  if (NA > 3) {
    const int n = 61;
    static double g[61][61];
    const double h0 = (PI / 1.5) / (n - 1);
    for (int i = 0; i < n; i++)
      for (int j = 0; j < n; j++) g[i][j] = sigma_ratio(-PI / 3 + h0 * i, -PI / 3 + h0 * j, 0);
    double b = INFINITY, c[2] = {0, 0};
    for (int i = 1; i < n - 1; i++)
      for (int j = 1; j < n - 1; j++) {
        int inner = 1;
        for (int di = -1; di <= 1; di++)
          for (int dj = -1; dj <= 1; dj++) inner &= isfinite(g[i + di][j + dj]);
        if (inner && g[i][j] < b) b = g[i][j], c[0] = -PI / 3 + h0 * i, c[1] = -PI / 3 + h0 * j;
      }
    if (!isfinite(b)) return 0;
    for (double h = h0; h > 1e-17; h *= 0.5) /* pattern search: move while it helps */
      for (int moved = 1; moved;) {
        moved = 0;
        for (int k = 0; k < 4; k++) {
          double t[2] = {c[0] + (k == 0 ? h : k == 1 ? -h : 0), c[1] + (k == 2 ? h : k == 3 ? -h : 0)};
          double v = sigma_ratio(t[0], t[1], h0);
          if (v < b) b = v, c[0] = t[0], c[1] = t[1], moved = 1;
        }
      }
    *best = b;
    qs[0] = c[0], qs[1] = c[1], qs[2] = 0;
    return b < 1e-12;
  }
  double prev_det = 0, prev_q1 = 0, Jd[3 * NA];
  for (int j = 0; j <= 60; j++) {
    double q2 = -PI / 3 + (PI / 1.5) * j / 60;
    for (int i = 0; i <= 60; i++) {
      double q[3] = {-PI / 3 + (PI / 1.5) * i / 60, q2, 0};
      prru_jd(q, Jd);
      double dt = det3(Jd);
      if (i > 0 && isfinite(dt) && isfinite(prev_det) && dt * prev_det < 0) {
        double lo = prev_q1, hi = q[0], slo = prev_det;
        for (int k = 0; k < 200; k++) {
          double mid = 0.5 * (lo + hi);
          if (mid == lo || mid == hi) break;
          prru_jd((const double[3]){mid, q2, 0}, Jd);
          if (det3(Jd) * slo > 0) lo = mid; else hi = mid;
        }
        qs[0] = lo, qs[1] = q2, qs[2] = 0;
        return 1;
      }
      prev_det = dt;
      prev_q1 = q[0];
    }
  }
  return 0;
}

static void test_singular(void)
{
  prru_dme r;
  /* Some pose of a wide grid is out of reach for any model. */
  int found = 0;
  for (int i = 0; i <= 40 && !found; i++)
    for (int j = 0; j <= 40 && !found; j++) {
      double q[3] = {-PI + 2 * PI * i / 40, -1.5 + 3.0 * j / 40, 0}, d[PRRU_NACT];
      prru_ik(q, d);
      if (isnan(d[0])) {
        found = 1;
        TU_TRUE(prru_dme_eval(&M, D, q, &r) == PRRU_EUNREACHABLE && r.status == PRRU_EUNREACHABLE &&
                    all_nan(&r),
                "unreachable pose flagged, outputs NaN");
      }
    }
  TU_TRUE(found, "the grid has an unreachable pose");
  TU_TRUE(prru_dme_eval(&M, D, (const double[3]){NAN, 0, 0}, &r) == PRRU_EINPUT && all_nan(&r),
          "NaN pose rejected");
  double qs[3], best;
  if (find_singular(qs, &best)) {
    int st = prru_dme_eval(&M, D, qs, &r);
    tu_check(st == PRRU_ESINGULAR && r.jd_rcond < M.jd_rcond_min && all_nan(&r),
             "pose on det J_d = 0 flagged singular, outputs NaN (rcond)", r.jd_rcond, M.jd_rcond_min);
    /* Slightly off the locus: singular at a practical tolerance. */
    double qn[3] = {qs[0] - 1e-4, qs[1], 0};
    prru_model m3 = M;
    m3.jd_rcond_min = 1e-3;
    TU_TRUE(prru_dme_eval(&m3, D, qn, &r) == PRRU_ESINGULAR && isnan(r.w_R),
            "near the locus: singular with jd_rcond_min = 1e-3");
  } else if (NA > 3) {
    printf("no rank-deficient J_d in |q1|, |q2| <= pi/3 away from the edge of reach (least "
           "sigma_3/sigma_1 of the scaled J_d %.3g at q = (%.6f, %.6f, 0)): singular-pose checks "
           "skipped\n", best, qs[0], qs[1]);
  } else {
    printf("no singular locus in |q1|, |q2| <= pi/3: singular-pose checks skipped\n");
  }
  /* The tolerance itself, at a regular pose: jd_rcond_min just above the
   * pose's jd_rcond flags it singular (outputs NaN, jd_rcond still
   * reported), just below leaves it regular. */
  const double qt[3] = {0.23, -0.31, -0.2};
  if (TU_TRUE(prru_dme_eval(&M, D, qt, &r) == PRRU_OK, "regular pose for the tolerance test")) {
    const double rc = r.jd_rcond;
    prru_model mt = M;
    mt.jd_rcond_min = rc * (1 + 1e-9);
    TU_TRUE(prru_dme_eval(&mt, D, qt, &r) == PRRU_ESINGULAR && all_nan(&r) && r.jd_rcond == rc,
            "jd_rcond_min just above jd_rcond: singular, outputs NaN, jd_rcond reported");
    mt.jd_rcond_min = rc * (1 - 1e-9);
    TU_TRUE(prru_dme_eval(&mt, D, qt, &r) == PRRU_OK && isfinite(r.w_R),
            "jd_rcond_min just below jd_rcond: regular");
  }
  TU_TRUE(strcmp(prru_dme_status_name(PRRU_OK), "ok") == 0 &&
              strcmp(prru_dme_status_name(PRRU_ESINGULAR), "singular") == 0 &&
              strcmp(prru_dme_status_name(PRRU_EUNREACHABLE), "unreachable") == 0 &&
              strcmp(prru_dme_status_name(PRRU_DME_OTHER_MODE), "other_mode") == 0,
          "status names");
}

typedef struct {
  long calls, last_done, last_total, stop_after;
} prog;

static int on_progress(long done, long total, void *ctx)
{
  prog *p = ctx;
  p->calls++;
  TU_TRUE(done >= p->last_done && done <= total, "progress monotone and bounded");
  p->last_done = done;
  p->last_total = total;
  return p->stop_after && p->calls >= p->stop_after;
}

static void test_map(void)
{
  prru_model m3 = M;
  m3.jd_rcond_min = 1e-3; /* a visible singular band */
  /* The paper's rectangle, q2 extended to 1.2 rad (unreachable for the
   * paper's geometry). */
  prru_map_grid g = {-PI / 6, PI / 6, -PI / 4, 1.2, 0.0, 57, 43};
  long n = (long)g.n1 * g.n2;
  double *w[3];
  unsigned char *st[3];
  prru_map_summary sum[3];
  prog pr = {0, 0, 0, 0};
  for (int t = 0; t < 3; t++) {
    w[t] = malloc(n * sizeof(double));
    st[t] = malloc(n);
    prru_map_options o;
    prru_map_options_default(&o);
    o.nthreads = t + 1;
    if (t == 1) {
      o.progress = on_progress;
      o.ctx = &pr;
    }
    TU_TRUE(prru_map_eval(&m3, &g, &o, w[t], st[t], &sum[t]) == PRRU_OK, "map runs");
  }
  TU_TRUE(pr.calls > 0 && pr.last_done == n && pr.last_total == n, "progress reaches the total");
  TU_TRUE(memcmp(w[0], w[1], n * sizeof(double)) == 0 && memcmp(w[0], w[2], n * sizeof(double)) == 0,
          "1, 2 and 3 threads give bit-identical w_R");
  TU_TRUE(memcmp(st[0], st[1], n) == 0 && memcmp(st[0], st[2], n) == 0, "and identical statuses");
  TU_TRUE(memcmp(&sum[0], &sum[1], sizeof sum[0]) == 0 && memcmp(&sum[0], &sum[2], sizeof sum[0]) == 0,
          "and identical summaries");
  /* Every point as prru_dme_eval computes it alone, a regular one whose
   * det J_d (this file's det3) has not the home pose's sign being the
   * other assembly mode; the summary recounted. */
  double dh[PRRU_NACT], Jh[3 * PRRU_NACT];
  prru_ik_jd((const double[3]){0.0, 0.0, g.q3}, dh, Jh);
  const double home_det = PRRU_NACT == 3 ? det3(Jh) : 0.0;
  int same = 1;
  long n_ok = 0, n_sing = 0, n_unr = 0, n_oth = 0;
  double acc = 0;
  for (int i = 0; i < g.n1; i++)
    for (int j = 0; j < g.n2; j++) {
      long k = (long)i * g.n2 + j;
      /* The grid's own abscissae: a point on the tolerance's edge must be
       * the same double in both. */
      double q[3] = {prru_map_axis(g.q1_lo, g.q1_hi, g.n1, i), prru_map_axis(g.q2_lo, g.q2_hi, g.n2, j),
                     g.q3};
      prru_dme r;
      int s = prru_dme_eval(&m3, D, q, &r);
      if (s == PRRU_OK && home_det != 0.0 && !(det3(D->Jd) * home_det > 0.0)) {
        s = PRRU_DME_OTHER_MODE;
        n_oth++;
      }
      if (s != st[0][k] || (s == PRRU_OK ? fabs(r.w_R - w[0][k]) > 1e-13 * r.w_R : !isnan(w[0][k])))
        same = 0;
      if (s == PRRU_OK) {
        n_ok++;
        acc += r.w_R - 1.0;
      } else if (s == PRRU_EUNREACHABLE) {
        n_unr++;
      } else {
        n_sing++;
      }
    }
  TU_TRUE(same, "map points equal prru_dme_eval at the same q");
  TU_TRUE(n_ok > 0, "the grid has regular points");
  TU_TRUE(sum[0].n_ok == n_ok && sum[0].n_singular == n_sing && sum[0].n_unreachable == n_unr &&
              sum[0].n_other_mode == n_oth && sum[0].n_points == n,
          "summary counts");
  TU_TRUE(PRRU_NACT != 3 || n_oth > 0, "the grid reaches into the other assembly mode");
  tu_check(rel(sum[0].index, acc / n_ok) <= 1e-12, "global index = mean of w_R - 1",
           rel(sum[0].index, acc / n_ok), 1e-12);
  tu_check(fabs(sum[0].singular_fraction - (double)(n_sing + n_unr) / n) <= 1e-15,
           "singular fraction", fabs(sum[0].singular_fraction - (double)(n_sing + n_unr) / n), 1e-15);
  /* Stopping from the progress callback, and bad grids. */
  prru_map_options o;
  prru_map_options_default(&o);
  prru_map_summary sum_nost;
  TU_TRUE(prru_map_eval(&m3, &g, &o, w[0], NULL, &sum_nost) == PRRU_OK &&
              memcmp(&sum_nost, &sum[0], sizeof sum_nost) == 0,
          "the same summary without statuses");
  prog stop = {0, 0, 0, 1};
  o.progress = on_progress;
  o.ctx = &stop;
  TU_TRUE(prru_map_eval(&m3, &g, &o, w[0], st[0], &sum[0]) == PRRU_EINTERRUPTED, "progress can stop");
  prru_map_options_default(&o);
  prru_map_grid bad[4] = {g, g, g, g};
  bad[0].n1 = 1;
  bad[1].q2_lo = bad[1].q2_hi;
  bad[2].q1_lo = 1.0;
  bad[3].q3 = NAN;
  for (int b = 0; b < 4; b++)
    TU_TRUE(prru_map_eval(&m3, &bad[b], &o, w[0], st[0], NULL) == PRRU_EINPUT, "bad grid rejected");
  o.nthreads = 0;
  TU_TRUE(prru_map_eval(&m3, &g, &o, w[0], st[0], NULL) == PRRU_EINPUT, "0 threads rejected");
  for (int t = 0; t < 3; t++) {
    free(w[t]);
    free(st[t]);
  }
}

int main(void)
{
  prru_model_default(&M);
  prru_ref_params_default(&P);
  D = malloc(sizeof *D);
  W = prru_ref_alloc();
  test_against_independent();
  test_boundary();
  test_singular();
  test_map();
  prru_ref_free(W);
  free(D);
  return tu_finish("test_dme");
}
