/* Rotational dynamic manipulability (paper section 5): w_R = sigma_1/sigma_2
 * of Mt JtR^+, Mt = J_d^-T M J_d^-1, JtR = J_R,P J_d^-1, with GSL's SVD.
 * M is the full mass matrix, the drives' armature included: Mt is then the
 * inertia the actuators feel.
 *
 * Four limbs (spec section 12): J_d is 4x3 and J_d^-1 becomes J_d^+ =
 * (J_d^T J_d)^-1 J_d^T (ref_jd_pinv), so Mt is 4x4 and JtR 3x4; for three
 * limbs J_d^+ is J_d^-1 itself (the same LU inverse as ever). */
#include <float.h>
#include <math.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "ref_internal.h"

int prru_ref_w_r(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double *w_r)
{
  const int na = ref_size_of(p).na;
  *w_r = NAN;
  int st = ref_assemble(p, w, q, NULL);
  if (st) return st;
  ref_mass_matrix(p, w);

  /* Room for the largest model, viewed at this one's size. */
  double jp[3 * PRRU_MAX_ACT], mt[PRRU_MAX_ACT * PRRU_MAX_ACT], tmp[3 * PRRU_MAX_ACT],
      jtr[3 * PRRU_MAX_ACT], u[PRRU_MAX_ACT * 3], v[9], pinv[PRRU_MAX_ACT * 3], bm[PRRU_MAX_ACT * 3],
      sv[3], work[3];
  gsl_matrix_view Jp = gsl_matrix_view_array(jp, 3, na), Mt = gsl_matrix_view_array(mt, na, na),
                  T = gsl_matrix_view_array(tmp, 3, na), JtR = gsl_matrix_view_array(jtr, 3, na),
                  U = gsl_matrix_view_array(u, na, 3), V = gsl_matrix_view_array(v, 3, 3),
                  Pinv = gsl_matrix_view_array(pinv, na, 3), B = gsl_matrix_view_array(bm, na, 3);
  gsl_vector_view S = gsl_vector_view_array(sv, 3), Work = gsl_vector_view_array(work, 3);

  if (ref_jd_pinv(w, &Jp.matrix)) return GSL_ESING;
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, w->M, &Jp.matrix, 0.0, &T.matrix);
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, &Jp.matrix, &T.matrix, 0.0, &Mt.matrix);
  gsl_matrix_const_view JRP = gsl_matrix_const_submatrix(w->H, 3 * REF_P, 0, 3, 3);
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &JRP.matrix, &Jp.matrix, 0.0, &JtR.matrix);

  /* JtR has rank 2 (the platform cannot turn about w): pseudo-inverse from
   * an SVD X = U S V^T, dropping singular values at or below
   * na DBL_EPSILON sigma_1 (max(rows, columns) eps sigma_1: rounding). GSL
   * wants rows >= columns: for three limbs X = JtR and JtR^+ = V S^+ U^T,
   * for four X = JtR^T (4x3) and JtR^+ = U S^+ V^T. */
  if (na == 3) gsl_matrix_memcpy(&U.matrix, &JtR.matrix);
  else gsl_matrix_transpose_memcpy(&U.matrix, &JtR.matrix);
  gsl_linalg_SV_decomp(&U.matrix, &V.matrix, &S.vector, &Work.vector);
  const double tol = na * DBL_EPSILON * sv[0];
  for (int i = 0; i < na; i++)
    for (int j = 0; j < 3; j++) {
      double x = 0;
      for (int l = 0; l < 3; l++)
        if (sv[l] > tol)
          x += (na == 3 ? v[3 * i + l] * u[3 * j + l] : u[3 * i + l] * v[3 * j + l]) / sv[l];
      pinv[3 * i + j] = x;
    }
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &Mt.matrix, &Pinv.matrix, 0.0, &B.matrix);
  gsl_linalg_SV_decomp(&B.matrix, &V.matrix, &S.vector, &Work.vector);
  if (!(sv[1] > 0.0)) return GSL_ESING;
  *w_r = sv[0] / sv[1];
  return GSL_SUCCESS;
}
