/* The runtime's dynamics solves against GSL on the generated terms:
 * - forward dynamics (prru_eom_solve: M's adjugate inside the kernel)
 *   against GSL's LU solve of prru_eom's M qdd = b, 2000 states;
 * - inverse dynamics (prru_inverse_terms: J_d^-1 and fd fused for three
 *   actuators; J_d^+ by QR for four) against GSL solving J_d^T fd = tau,
 *   tau = M qdd - b from prru_eom and J_d from prru_jd (LU for three
 *   actuators, the SVD's least-norm solution for four), 2000 states;
 * - the regularity decision of inverse dynamics equals prru_check_regular's
 *   over a grid that crosses the singular locus, at the default and at a
 *   strict tolerance, and J_d, J_d^+ equal check_regular's. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_linalg.h>

#include "prru.h"
#include "testsim.h"
#include "testutil.h"

#define NA PRRU_NACT

static prru_model model;
static prru_data data;

/* x with A x = b for a 3x3 A, by GSL's LU with partial pivoting. */
static void lu_solve3(const double A[9], const double b[3], double x[3])
{
  double a[9], bb[3];
  memcpy(a, A, sizeof a);
  memcpy(bb, b, sizeof bb);
  gsl_matrix_view Av = gsl_matrix_view_array(a, 3, 3);
  gsl_vector_view bv = gsl_vector_view_array(bb, 3), xv = gsl_vector_view_array(x, 3);
  gsl_permutation *p = gsl_permutation_alloc(3);
  int s;
  gsl_linalg_LU_decomp(&Av.matrix, p, &s);
  gsl_linalg_LU_solve(&Av.matrix, p, &bv.vector, &xv.vector);
  gsl_permutation_free(p);
}

#if NA > 3
/* The least-norm fd with J_d^T fd = tau, by the SVD of J_d (NA x 3, full
 * column rank): fd = U S^-1 V^T tau. */
static void min_norm(const double Jd[3 * NA], const double tau[3], double fd[NA])
{
  double u[3 * NA], v[9], s[3], work[3];
  memcpy(u, Jd, sizeof u);
  gsl_matrix_view U = gsl_matrix_view_array(u, NA, 3), V = gsl_matrix_view_array(v, 3, 3);
  gsl_vector_view S = gsl_vector_view_array(s, 3), W = gsl_vector_view_array(work, 3);
  gsl_linalg_SV_decomp(&U.matrix, &V.matrix, &S.vector, &W.vector);
  double y[3];
  for (int k = 0; k < 3; k++) {
    double t = 0;
    for (int i = 0; i < 3; i++) t += v[3 * i + k] * tau[i];
    y[k] = t / s[k];
  }
  for (int i = 0; i < NA; i++) fd[i] = u[3 * i] * y[0] + u[3 * i + 1] * y[1] + u[3 * i + 2] * y[2];
}
#endif

static void test_forward(void)
{
  double e_qdd = 0, e_mb = 0;
  int ok = 1;
  for (int k = 0; k < 2000; k++) {
    double q[3], qd[3], qdd[3], ref[3], M[9], b[3];
    prru_loads l;
    ts_random_state(&model, &data, q, qd);
    for (int i = 0; i < 3; i++) qd[i] *= 2.0;
    ts_random_loads(&l);
    ok &= prru_forward_dynamics(&model, &data, q, qd, &l, qdd) == PRRU_OK;
    prru_eom(q, qd, l.fd, l.fp, l.mp, M, b);
    lu_solve3(M, b, ref);
    e_qdd = fmax(e_qdd, tu_relerr(qdd, ref, 3, 1e-300));
    e_mb = fmax(e_mb, fmax(tu_relerr(data.M, M, 9, 1e-300), tu_relerr(data.b, b, 3, 1e-300)));
  }
  printf("forward dynamics vs GSL LU on prru_eom: qdd %.1e, d->M and d->b vs prru_eom %.1e\n",
         e_qdd, e_mb);
  TU_TRUE(ok, "forward dynamics solves every state");
  tu_check(e_qdd <= 1e-13, "qdd = GSL LU solve of M qdd = b", e_qdd, 1e-13);
  tu_check(e_mb <= 1e-14, "d->M, d->b = prru_eom's", e_mb, 1e-14);
}

static void test_inverse(void)
{
  static const double zero_fd[NA] = {0};
  double e_fd = 0, e_terms = 0;
  int ok = 1;
  for (int k = 0; k < 2000; k++) {
    double q[3], qd[3], qdd[3], fd[NA], ref[NA], M[9], b[3], Jd[3 * NA], tau[3];
    prru_loads l;
    ts_random_state(&model, &data, q, qd);
    ts_random_loads(&l);
    for (int i = 0; i < 3; i++) qdd[i] = tu_uniform(-20, 20);
    ok &= prru_inverse_dynamics(&model, &data, q, qd, qdd, &l, fd) == PRRU_OK;
    double dd[NA], jd[3 * NA], jp[3 * NA];
    memcpy(dd, data.d, sizeof dd);
    memcpy(jd, data.Jd, sizeof jd);
    memcpy(jp, data.Jdpinv, sizeof jp);
    prru_eom(q, qd, zero_fd, l.fp, l.mp, M, b);
    prru_jd(q, Jd);
    for (int i = 0; i < 3; i++) tau[i] = M[3 * i] * qdd[0] + M[3 * i + 1] * qdd[1] + M[3 * i + 2] * qdd[2] - b[i];
#if NA == 3
    double JT[9];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) JT[3 * i + j] = Jd[3 * j + i];
    lu_solve3(JT, tau, ref);
#else
    min_norm(Jd, tau, ref);
#endif
    e_fd = fmax(e_fd, tu_relerr(fd, ref, NA, 1e-300));
    ok &= prru_check_regular(&model, &data, q, NULL) == PRRU_OK;
    e_terms = fmax(e_terms, tu_relerr(dd, data.d, NA, 1e-300));
    e_terms = fmax(e_terms, tu_relerr(jd, data.Jd, 3 * NA, 1e-300));
    e_terms = fmax(e_terms, tu_relerr(jp, data.Jdpinv, 3 * NA, 1e-300));
  }
  printf("inverse dynamics vs GSL on prru_eom and prru_jd: fd %.1e; d, J_d, J_d^+ vs "
         "prru_check_regular %.1e\n", e_fd, e_terms);
  TU_TRUE(ok, "inverse dynamics solves every state");
  tu_check(e_fd <= 1e-12, "fd = GSL solve of J_d^T fd = M qdd - b", e_fd, 1e-12);
  tu_check(e_terms <= 1e-14, "d, J_d, J_d^+ = prru_check_regular's", e_terms, 1e-14);
}

/* Across the singular locus (for the paper's model, fig. 7's lower
 * corners), inverse dynamics refuses exactly where prru_check_regular
 * does, at the default tolerance and at a strict one. */
static void test_regularity_decision(void)
{
  int differ = 0, singular = 0, regular = 0;
  for (int t = 0; t < 2; t++) {
    prru_model mm = model;
    if (t) mm.jd_rcond_min = 0.05;
    for (int i = 0; i < 61; i++)
      for (int j = 0; j < 61; j++) {
        double q[3] = {-1.0 + 2.0 * i / 60, -1.2 + 2.2 * j / 60, -0.7}, qd[3] = {0.1, 0.2, -0.1};
        double qdd[3] = {1, -2, 3}, fd[NA];
        prru_loads l;
        memset(&l, 0, sizeof l);
        int a = prru_check_regular(&mm, &data, q, NULL);
        int b = prru_inverse_dynamics(&mm, &data, q, qd, qdd, &l, fd);
        differ += a != b;
        singular += a == PRRU_ESINGULAR;
        regular += a == PRRU_OK;
      }
  }
  printf("regularity over 2 x 61 x 61 poses: %d regular, %d singular, %d decided differently\n",
         regular, singular, differ);
  TU_TRUE(differ == 0, "inverse dynamics' status = prru_check_regular's");
  TU_TRUE(singular > 0 && regular > 0, "the grid crosses the singular locus");
}

int main(void)
{
  prru_model_default(&model);
  test_forward();
  test_inverse();
  test_regularity_decision();
  return tu_finish("test_solves");
}
