/* Rotational dynamic manipulability (paper section 5): w_R = sigma_1/sigma_2
 * of Mt JtR^+, Mt = J_d^-T M J_d^-1, JtR = J_R,P J_d^-1, with GSL's SVD.
 * M is the full mass matrix, the drives' armature included: Mt is then the
 * inertia the actuators feel. */
#include <math.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "ref_internal.h"

int prru_ref_w_r(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ], double *w_r)
{
  ref_priv *s = w->priv;
  *w_r = NAN;
  int st = ref_assemble(p, w, q, NULL);
  if (st) return st;
  ref_mass_matrix(p, w);

  double jinv[9], mt[9], tmp[9], jtr[9], u[9], v[9], pinv[9], bm[9], sv[3], work[3];
  gsl_matrix_view Jinv = gsl_matrix_view_array(jinv, 3, 3), Mt = gsl_matrix_view_array(mt, 3, 3),
                  T = gsl_matrix_view_array(tmp, 3, 3), JtR = gsl_matrix_view_array(jtr, 3, 3),
                  U = gsl_matrix_view_array(u, 3, 3), V = gsl_matrix_view_array(v, 3, 3),
                  Pinv = gsl_matrix_view_array(pinv, 3, 3), B = gsl_matrix_view_array(bm, 3, 3);
  gsl_vector_view S = gsl_vector_view_array(sv, 3), Work = gsl_vector_view_array(work, 3);

  gsl_matrix_memcpy(s->m3a, w->Jd);
  if (ref_lu3(s->m3a, s->perm3, &Jinv.matrix)) return GSL_ESING;
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, w->M, &Jinv.matrix, 0.0, &T.matrix);
  gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, &Jinv.matrix, &T.matrix, 0.0, &Mt.matrix);
  gsl_matrix_const_view JRP = gsl_matrix_const_submatrix(w->H, 3 * REF_P, 0, 3, 3);
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &JRP.matrix, &Jinv.matrix, 0.0, &JtR.matrix);

  /* JtR has rank 2 (the platform cannot turn about w): pseudo-inverse
   * V S^+ U^T dropping singular values at rounding level. */
  gsl_matrix_memcpy(&U.matrix, &JtR.matrix);
  gsl_linalg_SV_decomp(&U.matrix, &V.matrix, &S.vector, &Work.vector);
  const double tol = 3.0 * 2.220446049250313e-16 * sv[0];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double x = 0;
      for (int l = 0; l < 3; l++)
        if (sv[l] > tol) x += v[3 * i + l] * u[3 * j + l] / sv[l];
      pinv[3 * i + j] = x;
    }
  gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, &Mt.matrix, &Pinv.matrix, 0.0, &B.matrix);
  gsl_linalg_SV_decomp(&B.matrix, &V.matrix, &S.vector, &Work.vector);
  if (!(sv[1] > 0.0)) return GSL_ESING;
  *w_r = sv[0] / sv[1];
  return GSL_SUCCESS;
}
