/* Private to the reference library: the per-body kinematics record and the
 * scratch behind prru_ref_ws.priv. */
#ifndef PRRU_REF_INTERNAL_H
#define PRRU_REF_INTERNAL_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include <gsl/gsl_vector.h>

#include "prru_ref.h"

#define REF_NB PRRU_NBODY
#define REF_NW (6 * PRRU_NBODY)
#define REF_NL PRRU_NLAMBDA
#define REF_NA PRRU_NACT

enum { REF_P, REF_L1, REF_L2, REF_L3, REF_U1, REF_U2, REF_U3, REF_S1, REF_S2, REF_S3 };

/* Everything the paper's eqs. 1-13 give for one q (and qd): 3x3 matrices
 * row-major, column j = derivative with respect to q_j. */
typedef struct {
  double R[REF_NB][9];  /* body rotation */
  double p[REF_NB][3];  /* centre of mass origin_b + R_b com_b */
  double JR[REF_NB][9]; /* omega_b = JR qd */
  double JT[REF_NB][9]; /* v_b = JT qd */
  double JTO[9];        /* velocity of the tool point O' = J_T,O' qd */
  double delta[REF_NB][3], mu[REF_NB][3]; /* qd-quadratic accelerations */
  double omega[REF_NB][3], v[REF_NB][3];
  double C[3][3];               /* U joint centres C_i */
  double B[3][3], A[3][3];      /* joint centres B_i, A_i */
  double gamma;                 /* limb 3's lower-link angle */
  double d[REF_NA], Jd[REF_NA * 3];
  double dd[REF_NA], ddb[REF_NA]; /* J_d qd and Jd' qd (zero without qd) */
} ref_kin;

/* Fills k from q; qd may be NULL (then omega, v, delta, mu, dd, ddb are
 * zero). GSL_EDOM when q is not finite or unreachable. */
int ref_kinematics(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k);

typedef struct {
  ref_kin kin;
  gsl_matrix *L;          /* NW x NW: Cholesky factor of Phi */
  gsl_matrix *Y;          /* NW x NL: L^-1 Q */
  gsl_matrix *A;          /* NL x NL: Q^T Phi^-1 Q */
  gsl_vector *r60, *r57;  /* K - Fbar and its projection */
  gsl_vector *Fbar;       /* NW */
  gsl_vector *Fg;         /* NW: gravity wrenches only */
  gsl_matrix *m3a, *m3b, *m3c, *m3d; /* 3x3 scratch */
  gsl_vector *v3a, *v3b, *v3c;       /* 3 scratch */
  gsl_permutation *perm3;
} ref_priv;

/* Stacks H, Phi, Fg, J_d (and dm, K when qd != NULL) from the kinematics
 * of q. */
int ref_assemble(const prru_ref_params *p, prru_ref_ws *w, const double q[3], const double *qd);
/* w->M = H^T Phi H + J_d^T diag(k) J_d after ref_assemble. */
void ref_mass_matrix(const prru_ref_params *p, prru_ref_ws *w);
/* LU of A (3x3, overwritten by its LU) with inv = A^-1, and a check of the
 * reciprocal 1-norm condition number: GSL_ESING below machine precision. */
int ref_lu3(gsl_matrix *A, gsl_permutation *perm, gsl_matrix *inv);
/* Cholesky with GSL's abort-on-error handler suspended: GSL_ESING when the
 * matrix is not numerically positive definite. */
int ref_cholesky(gsl_matrix *A);
/* phi_i = -c_i dd_i - f_i tanh(dd_i / v_s): drive i's damping and friction
 * force on its slider, from k->dd. */
void ref_drive_friction(const prru_ref_params *p, const ref_kin *k, double phi[REF_NA]);
/* qdd of the forward dynamics after ref_assemble(.., qd) and
 * ref_mass_matrix (fd may be NULL: no actuator force). */
int ref_solve_qdd(const prru_ref_params *p, prru_ref_ws *w, const double *fd, const double fp[3],
                  const double mp[3], gsl_vector *qdd);

#endif
