/* The straightforward reference: the paper's closed-form equations 1-13
 * (with the errata of the spec) assembled with GSL vectors and matrices,
 * exactly as the paper writes them: per-body J_R, J_T, delta, mu, then
 * H (6 NBODY x 3), Phi, K, M = H^T Phi H and h = H^T K with
 * gsl_blas_dgemm / dgemv; the drives of model format 2 (spec section 11)
 * on top through the actuator coordinates d(q).
 *
 * It shares nothing with the generator but the model's numbers (prru_mech,
 * read by prru_ref_params_default, and the PRRU_N* sizes): it is the
 * independent check the tests compare the generated kernels against, and
 * the baseline bench/ measures them against. Plain and readable on purpose,
 * not fast.
 *
 * All arrays are row-major, body order P L1 L2 L3 U1 U2 U3 S1 S2 S3 (three
 * limbs) or P L1..L4 U1..U4 S1..S4 (four limbs, spec section 12).
 * Functions return GSL_SUCCESS, GSL_EDOM when q is unreachable (an acos
 * argument outside [-1, 1]) or not finite, GSL_ESING when a matrix that must
 * be inverted is singular; on failure every output element is NaN. */
#ifndef PRRU_REF_H
#define PRRU_REF_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "prru_kernels.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The derivation below covers the three-limb machine of spec sections 1-11
 * (ten bodies, 57 reaction coordinates) and the redundantly actuated
 * four-limb one of section 12 (limb 4 mirrors limb 3; 13 bodies, 76
 * reaction coordinates, one of them redundant): PRRU_NLIMB = 3 or 4. */
#if PRRU_NQ != 3 || (PRRU_NLIMB != 3 && PRRU_NLIMB != 4) || PRRU_NACT != PRRU_NLIMB || \
    PRRU_NBODY != 1 + 3 * PRRU_NLIMB || PRRU_NLAMBDA != 19 * PRRU_NLIMB
#error "the reference implements the 3-PRRU of spec sections 1-11 and the 4-PRRU of section 12 only"
#endif

/* Spec section 11 (format 2; a format-1 model is the special case with
 * equal limbs, gravity (0, 0, -g), com = 0, diagonal inertia, no drives). */
typedef struct {
  double g[3];                            /* gravity in {S}, m/s^2 */
  double b[PRRU_NLIMB];                   /* rail offsets, m (limb 1 at y = -b1, limb 4 at x = -b4) */
  double l1[PRRU_NLIMB], l2[PRRU_NLIMB];  /* upper and lower links, m */
  double a[PRRU_NLIMB];                   /* U-joint offsets, m; a[2] = a[3] = 0 (C_3 = C_4 = O') */
  double mass[PRRU_NBODY];                /* kg */
  double com[PRRU_NBODY][3];              /* centre of mass in the body frame, m */
  double inertia[PRRU_NBODY][9];          /* about the centre, body axes, row-major, kg m^2 */
  double armature[PRRU_NACT];             /* reflected drive inertia k_i, kg */
  double damping[PRRU_NACT];              /* c_i, N s/m */
  double coulomb[PRRU_NACT];              /* f_i, N */
  double coulomb_velocity;                /* v_s, m/s (unused where every f_i = 0) */
} prru_ref_params;

/* The model the kernels were generated from (prru_mech). */
void prru_ref_params_default(prru_ref_params *p);

/* Preallocated GSL workspace; the public members hold the last results. */
typedef struct {
  gsl_matrix *H;   /* 6 NBODY x 3 */
  gsl_matrix *Phi; /* 6 NBODY x 6 NBODY: the bodies only (the armature is not a body) */
  gsl_vector *K;   /* 6 NBODY: the bodies only */
  gsl_vector *dm;  /* 6 NBODY: [delta; mu] */
  gsl_matrix *PhiH, *M, *Q, *Jd; /* 6 NBODY x 3; 3x3 (with armature); 6 NBODY x NLAMBDA; NACT x 3 */
  void *priv;      /* further scratch owned by the reference */
} prru_ref_ws;

prru_ref_ws *prru_ref_alloc(void);
void prru_ref_free(prru_ref_ws *w);

int prru_ref_ik(const prru_ref_params *p, const double q[PRRU_NQ], double d[PRRU_NACT]);
int prru_ref_jd(const prru_ref_params *p, const double q[PRRU_NQ], double Jd[PRRU_NACT * PRRU_NQ]);
/* R_b and the centres of mass p_b = origin_b + R_b com_b. */
int prru_ref_poses(const prru_ref_params *p, const double q[PRRU_NQ], double R[9 * PRRU_NBODY],
                   double pos[3 * PRRU_NBODY]);
int prru_ref_jacobians(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                       double H[6 * PRRU_NBODY * PRRU_NQ]);
int prru_ref_bias_terms(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                        const double qd[PRRU_NQ], double dm[6 * PRRU_NBODY]);
/* H^T Phi H + J_d^T diag(armature) J_d. */
int prru_ref_mass(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                  double M[PRRU_NQ * PRRU_NQ]);
/* H^T K + J_d^T diag(armature) (Jd' qd); without damping and friction. */
int prru_ref_bias(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                  const double qd[PRRU_NQ], double h[PRRU_NQ]);
/* G = sum_b J_T,b^T m_b g. */
int prru_ref_gravity(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                     double G[PRRU_NQ]);
int prru_ref_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                      const double qd[PRRU_NQ], double M[PRRU_NQ * PRRU_NQ], double h[PRRU_NQ],
                      double G[PRRU_NQ]);
/* E[0] = T (bodies, from their velocities, plus sum k_i dd_i^2 / 2),
 * E[1] = V = -sum_b m_b g . p_b. */
int prru_ref_energy(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                    const double qd[PRRU_NQ], double E[2]);
/* dd = J_d qd and ddb = Jd' qd, the qd-quadratic part of d''. */
int prru_ref_actuator_rates(const prru_ref_params *p, const double q[PRRU_NQ],
                            const double qd[PRRU_NQ], double dd[PRRU_NACT],
                            double ddb[PRRU_NACT]);
/* Qp = J_d^T (-c dd - f tanh(dd / v_s)): the drives' damping and friction. */
int prru_ref_passive(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                     const double qd[PRRU_NQ], double Qp[PRRU_NQ]);
/* M qdd = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp + Qp - h, solved with GSL;
 * fp acts at the tool point O' = (0, 0, q3), mp on the platform. */
int prru_ref_forward_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                              const double qd[PRRU_NQ], const double fd[PRRU_NACT],
                              const double fp[3], const double mp[3], double qdd[PRRU_NQ]);
/* The fd that produce qdd under fp, mp (and the drives' Qp): with J_d^T fd = tau the
 * generalized force the motion needs, fd = J_d^-T tau for three limbs and the
 * minimum-norm fd = J_d (J_d^T J_d)^-1 tau for four (spec section 12; no internal
 * preload). GSL_ESING when J_d (J_d^T J_d for four limbs) is singular. */
int prru_ref_inverse_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                              const double qd[PRRU_NQ], const double qdd[PRRU_NQ],
                              const double fp[3], const double mp[3], double fd[PRRU_NACT]);
/* Q (6 NBODY x NLAMBDA), spec section 7 joint table, lambda order of
 * prru_mech.lambda_labels. */
int prru_ref_reaction_basis(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                            double Q[6 * PRRU_NBODY * PRRU_NLAMBDA]);
/* lambda by eq. 31 with the dense Phi, at the qdd of the forward dynamics;
 * slider i receives fd_i - k_i dd_i'' - c_i dd_i - f_i tanh(dd_i / v_s).
 * Three limbs: the unique lambda, Q^T Phi^-1 Q by Cholesky (GSL_ESING where
 * it is not numerically positive definite, a constraint singularity). Four
 * limbs (spec section 12): Q^T Phi^-1 Q has rank 75 of 76 (limbs 3 and 4
 * both hold O' along e2) and lambda is the minimum-norm solution, through
 * the SVD of L^-1 Q (Phi = L L^T) with singular values at or below
 * max(6 NBODY, NLAMBDA) * DBL_EPSILON * sigma_1 treated as zero; lambda is
 * then orthogonal to Q's null direction (prru_ref_reaction_null).
 * GSL_ESING unless exactly one is cut (a constraint singularity beyond the
 * redundancy). */
int prru_ref_reactions(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                       const double qd[PRRU_NQ], const double fd[PRRU_NACT], const double fp[3],
                       const double mp[3], double lambda[PRRU_NLAMBDA]);
/* The null space of Q at q, from the same SVD as prru_ref_reactions: *nullity
 * = the number of singular values cut (0 for three limbs, 1 for four), z the
 * unit right singular vector of the smallest singular value (Q z = 0 when
 * *nullity = 1; with *nullity = 0 merely the least determined direction),
 * signed so that its largest component is positive. GSL_ESING, z still set,
 * where *nullity is not NLAMBDA - (6 NBODY - 3); GSL_EDOM (and GSL_ESING if
 * Phi is not positive definite) with z all NaN and *nullity = -1. */
int prru_ref_reaction_null(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ],
                           double z[PRRU_NLAMBDA], int *nullity);
/* w_R = sigma_1/sigma_2 of Mt JtR^+ (spec section 8, M with the armature),
 * GSL SVD, with J_d^+ = J_d^-1 for three limbs and (J_d^T J_d)^-1 J_d^T for
 * four (spec section 12): Mt = J_d^+T M J_d^+, JtR = J_R,P J_d^+; JtR^+ drops
 * singular values at or below NACT * DBL_EPSILON * sigma_1 (JtR has rank 2).
 * GSL_ESING when J_d is singular (J_d^T J_d for four limbs). */
int prru_ref_w_r(const prru_ref_params *p, prru_ref_ws *w, const double q[PRRU_NQ], double *w_r);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_REF_H */
