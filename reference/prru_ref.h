/* The straightforward reference: the paper's closed-form equations 1-13
 * (with the errata of docs/model.md) assembled with GSL vectors and
 * matrices, exactly as the paper writes them: per-body J_R, J_T, delta, mu,
 * then H (60x3), Phi (60x60), K (60), M = H^T Phi H and h = H^T K with
 * gsl_blas_dgemm / dgemv.
 *
 * It shares nothing with the generator but the model's numbers (PRRU_*
 * macros): it is the independent check the tests compare the generated
 * kernels against, and the baseline bench/ measures them against. Plain and
 * readable on purpose, not fast.
 *
 * All arrays are row-major, body order P L1 L2 L3 U1 U2 U3 S1 S2 S3.
 * Functions return GSL_SUCCESS, GSL_EDOM when q is unreachable (an acos
 * argument outside [-1, 1]) or not finite, GSL_ESING when a matrix that must
 * be inverted is singular. */
#ifndef PRRU_REF_H
#define PRRU_REF_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PRRU_REF_NBODY 10

typedef struct {
  double g;                          /* m/s^2, along -z */
  double b12, b3, l1, l2, a;         /* m */
  double mass[PRRU_REF_NBODY];       /* kg */
  double inertia[PRRU_REF_NBODY][3]; /* principal moments in the body frame */
} prru_ref_params;

/* The model the kernels were generated from (PRRU_* macros). */
void prru_ref_params_default(prru_ref_params *p);

/* Preallocated GSL workspace; the public members hold the last results. */
typedef struct {
  gsl_matrix *H;   /* 60 x 3  */
  gsl_matrix *Phi; /* 60 x 60 */
  gsl_vector *K;   /* 60 */
  gsl_vector *dm;  /* 60: [delta; mu] */
  gsl_matrix *PhiH, *M, *Q, *Jd; /* 60x3, 3x3, 60x57, 3x3 */
  void *priv;      /* further scratch owned by the reference */
} prru_ref_ws;

prru_ref_ws *prru_ref_alloc(void);
void prru_ref_free(prru_ref_ws *w);

int prru_ref_ik(const prru_ref_params *p, const double q[3], double d[3]);
int prru_ref_jd(const prru_ref_params *p, const double q[3], double Jd[9]);
int prru_ref_poses(const prru_ref_params *p, const double q[3], double R[90], double pos[30]);
int prru_ref_jacobians(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double H[180]);
int prru_ref_bias_terms(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                        const double qd[3], double dm[60]);
int prru_ref_mass(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double M[9]);
int prru_ref_bias(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                  const double qd[3], double h[3]);
int prru_ref_gravity(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double G[3]);
int prru_ref_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                      const double qd[3], double M[9], double h[3], double G[3]);
/* T and V = g sum m_b z_b. */
int prru_ref_energy(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                    const double qd[3], double E[2]);
/* M qdd = G + J_d^T fd + J_T,P^T fp + J_R,P^T mp - h, solved with GSL. */
int prru_ref_forward_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                              const double qd[3], const double fd[3], const double fp[3],
                              const double mp[3], double qdd[3]);
/* The fd that produce qdd under fp, mp. */
int prru_ref_inverse_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                              const double qd[3], const double qdd[3], const double fp[3],
                              const double mp[3], double fd[3]);
/* Q (60x57), spec section 7 joint table, lambda order of PRRU_LAMBDA_LABELS. */
int prru_ref_reaction_basis(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                            double Q[3420]);
/* lambda by eq. 31 with the dense 60x60 Phi. */
int prru_ref_reactions(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                       const double qd[3], const double fd[3], const double fp[3],
                       const double mp[3], double lambda[57]);
/* w_R = sigma_1/sigma_2 of Mt JtR^+ (spec section 8), GSL SVD; GSL_ESING
 * when J_d is singular. */
int prru_ref_w_r(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double *w_r);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_REF_H */
