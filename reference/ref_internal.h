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
#define REF_NLIMB PRRU_NLIMB
/* Rank of Q: 6 NBODY body coordinates less the 3 degrees of freedom
 * (H^T Q = 0); NLAMBDA - REF_RANK reaction directions are redundant. */
#define REF_RANK (6 * PRRU_NBODY - 3)

/* Body indices: the platform, then every limb's lower link, upper link,
 * slider (limb l = 0 .. NLIMB - 1). */
#define REF_P 0
#define REF_L(l) (1 + (l))
#define REF_U(l) (1 + REF_NLIMB + (l))
#define REF_S(l) (1 + 2 * REF_NLIMB + (l))

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
  double C[REF_NLIMB][3];       /* U joint centres C_i */
  double B[REF_NLIMB][3], A[REF_NLIMB][3]; /* joint centres B_i, A_i */
  double gamma;                 /* lower-link angle of limb 3 (and 4) */
  double d[REF_NA], Jd[REF_NA * 3];
  double dd[REF_NA], ddb[REF_NA]; /* J_d qd and Jd' qd (zero without qd) */
} ref_kin;

/* Fills k from q; qd may be NULL (then omega, v, delta, mu, dd, ddb are
 * zero). GSL_EDOM when q is not finite or unreachable. */
int ref_kinematics(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k);

typedef struct {
  ref_kin kin;
  gsl_matrix *L;          /* NW x NW: Cholesky factor of Phi */
  gsl_matrix *Y;          /* NW x NL: L^-1 Q, overwritten by U of its SVD */
  gsl_matrix *A;          /* NL x NL: Q^T Phi^-1 Q = Y^T Y (full rank), its Cholesky factor */
  gsl_matrix *V;          /* NL x NL: V of the SVD L^-1 Q = U S V^T */
  gsl_vector *S, *svw;    /* NL: singular values (descending), SVD work */
  gsl_vector *rW, *rL;    /* NW: L^-1 (K - Fbar); NL: its projection */
  gsl_vector *Fbar;       /* NW */
  gsl_vector *Fg;         /* NW: gravity wrenches only */
  gsl_matrix *m3a, *m3b, *m3c;       /* 3x3 scratch */
  gsl_matrix *jdk;                   /* NA x 3: diag(k) J_d */
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
/* J_d^+ (3 x NA) after ref_assemble: J_d^-1 for three limbs, (J_d^T J_d)^-1
 * J_d^T for four (spec section 12), via ref_lu3 (GSL_ESING as there). */
int ref_jd_pinv(prru_ref_ws *w, gsl_matrix *Jp);
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
