/* Private to the reference library: the per-body kinematics record and the
 * scratch behind prru_ref_ws.priv. */
#ifndef PRRU_REF_INTERNAL_H
#define PRRU_REF_INTERNAL_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include <gsl/gsl_vector.h>

#include "prru_ref.h"

enum { REF_P, REF_L1, REF_L2, REF_L3, REF_U1, REF_U2, REF_U3, REF_S1, REF_S2, REF_S3 };

/* Everything the paper's eqs. 1-13 give for one q (and qd): 3x3 matrices
 * row-major, column j = derivative with respect to q_j. */
typedef struct {
  double R[PRRU_REF_NBODY][9];  /* body rotation */
  double p[PRRU_REF_NBODY][3];  /* body centre */
  double JR[PRRU_REF_NBODY][9]; /* omega_b = JR qd */
  double JT[PRRU_REF_NBODY][9]; /* v_b = JT qd */
  double delta[PRRU_REF_NBODY][3], mu[PRRU_REF_NBODY][3]; /* qd-quadratic accelerations */
  double omega[PRRU_REF_NBODY][3], v[PRRU_REF_NBODY][3];
  double C[3][3];               /* U joint centres C_i */
  double B[3][3], A[3][3];      /* joint centres B_i, A_i */
  double gamma;                 /* limb 3's lower-link angle */
  double d[3], Jd[9];
} ref_kin;

/* Fills k from q; qd may be NULL (then omega, v, delta, mu are zero).
 * GSL_EDOM when q is not finite or unreachable. */
int ref_kinematics(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k);

typedef struct {
  ref_kin kin;
  gsl_matrix *L;          /* 60x60: Cholesky factor of Phi */
  gsl_matrix *Y;          /* 60x57: L^-1 Q */
  gsl_matrix *A;          /* 57x57: Q^T Phi^-1 Q */
  gsl_vector *r60, *r57;  /* K - Fbar and its projection */
  gsl_vector *Fbar;       /* 60 */
  gsl_vector *Fg;         /* 60: gravity wrenches only */
  gsl_matrix *m3a, *m3b, *m3c, *m3d; /* 3x3 scratch */
  gsl_vector *v3a, *v3b, *v3c;       /* 3 scratch */
  gsl_permutation *perm3;
} ref_priv;

/* Stacks H, Phi (and dm, K when qd != NULL) from the kinematics of q. */
int ref_assemble(const prru_ref_params *p, prru_ref_ws *w, const double q[3], const double *qd);
/* M = H^T Phi H after ref_assemble. */
void ref_mass_from_H(prru_ref_ws *w);
/* LU of A (3x3, overwritten by its LU) with inv = A^-1, and a check of the
 * reciprocal 1-norm condition number: GSL_ESING below machine precision. */
int ref_lu3(gsl_matrix *A, gsl_permutation *perm, gsl_matrix *inv);
/* Cholesky with GSL's abort-on-error handler suspended: GSL_ESING when the
 * matrix is not numerically positive definite. */
int ref_cholesky(gsl_matrix *A);

#endif
