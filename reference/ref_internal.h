/* Private to the reference library: the per-body kinematics record and the
 * scratch behind prru_ref_ws.priv. */
#ifndef PRRU_REF_INTERNAL_H
#define PRRU_REF_INTERNAL_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include <gsl/gsl_vector.h>

#include "prru_ref.h"

/* The counts of the parameters' topology (spec sections 11, 12; the
 * descriptor's formulas). All 0 for an nlimb the reference does not know:
 * ref_kinematics refuses it, and an output of no entries is never written. */
typedef struct {
  int nlimb;
  int na;   /* actuators: one per limb */
  int nb;   /* bodies: the platform and three per limb */
  int nw;   /* 6 nb body coordinates (H's rows) */
  int nl;   /* reaction coordinates: 19 per limb */
  int rank; /* of Q: nw less the 3 degrees of freedom (H^T Q = 0); nl - rank
               reaction directions are redundant */
} ref_size;

static inline ref_size ref_size_of_nlimb(int nlimb)
{
  ref_size n = {0, 0, 0, 0, 0, 0};
  if (nlimb != 3 && nlimb != 4) return n;
  n.nlimb = nlimb;
  n.na = nlimb;
  n.nb = 1 + 3 * nlimb;
  n.nw = 6 * n.nb;
  n.nl = 19 * nlimb;
  n.rank = n.nw - 3;
  return n;
}

static inline ref_size ref_size_of(const prru_ref_params *p) { return ref_size_of_nlimb(p->nlimb); }

/* Body indices: the platform, then every limb's lower link, upper link,
 * slider (limb l = 0 .. nlimb - 1); each takes nlimb, though the lower
 * links' do not depend on it, so that no call can leave it out. */
#define REF_P 0
#define REF_L(nlimb, l) (1 + (l))
#define REF_U(nlimb, l) (1 + (nlimb) + (l))
#define REF_S(nlimb, l) (1 + 2 * (nlimb) + (l))

/* Everything the paper's eqs. 1-13 give for one q (and qd): 3x3 matrices
 * row-major, column j = derivative with respect to q_j. */
typedef struct {
  ref_size n;                   /* the first n.nb bodies, n.nlimb limbs, n.na actuators are set */
  double R[PRRU_MAX_BODY][9];   /* body rotation */
  double p[PRRU_MAX_BODY][3];   /* centre of mass origin_b + R_b com_b */
  double JR[PRRU_MAX_BODY][9];  /* omega_b = JR qd */
  double JT[PRRU_MAX_BODY][9];  /* v_b = JT qd */
  double JTO[9];                /* velocity of the tool point O' = J_T,O' qd */
  double delta[PRRU_MAX_BODY][3], mu[PRRU_MAX_BODY][3]; /* qd-quadratic accelerations */
  double omega[PRRU_MAX_BODY][3], v[PRRU_MAX_BODY][3];
  double C[PRRU_MAX_LIMB][3];   /* U joint centres C_i */
  double B[PRRU_MAX_LIMB][3], A[PRRU_MAX_LIMB][3]; /* joint centres B_i, A_i */
  double gamma;                 /* lower-link angle of limb 3 (and 4) */
  double d[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3];
  double dd[PRRU_MAX_ACT], ddb[PRRU_MAX_ACT]; /* J_d qd and Jd' qd (zero without qd) */
} ref_kin;

/* Fills k from q; qd may be NULL (then omega, v, delta, mu, dd, ddb are
 * zero). GSL_EINVAL for an nlimb other than 3 or 4, GSL_EDOM when q is not
 * finite or unreachable. */
int ref_kinematics(const prru_ref_params *p, const double q[3], const double *qd, ref_kin *k);

/* A matrix (vector) of the workspace whose size is the model's: storage
 * for the largest model, and the view of it at the current model's size
 * that the computation uses. The view is compact (row stride = its
 * columns), laid out as a matrix allocated at that size would be. */
typedef struct { gsl_matrix *max; gsl_matrix_view cur; } ref_matrix;
typedef struct { gsl_vector *max; gsl_vector_view cur; } ref_vector;

typedef struct {
  ref_kin kin;
  /* NW, NL, NA: the current model's 6 nbody, nlambda, nact. */
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
  /* Behind the model-sized pointers above and in prru_ref_ws: allocated
   * once, viewed at each model's size by ref_assemble, so that one
   * workspace serves both topologies without allocating per call. */
  struct {
    ref_matrix H, Phi, PhiH, Q, Jd, L, Y, A, V, jdk;
    ref_vector K, dm, S, svw, rW, rL, Fbar, Fg;
  } store;
} ref_priv;

/* Sizes the workspace for p's topology and stacks H, Phi, Fg, J_d (and
 * dm, K when qd != NULL) from the kinematics of q. */
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
void ref_drive_friction(const prru_ref_params *p, const ref_kin *k, double phi[PRRU_MAX_ACT]);
/* qdd of the forward dynamics after ref_assemble(.., qd) and
 * ref_mass_matrix (fd may be NULL: no actuator force). */
int ref_solve_qdd(const prru_ref_params *p, prru_ref_ws *w, const double *fd, const double fp[3],
                  const double mp[3], gsl_vector *qdd);

#endif
