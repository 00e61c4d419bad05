/* The straightforward reference: the paper's closed-form equations 1-13
 * (with the errata of the spec) assembled with GSL vectors and matrices,
 * exactly as the paper writes them: per-body J_R, J_T, delta, mu, then
 * H (6 NBODY x 3), Phi, K, M = H^T Phi H and h = H^T K with
 * gsl_blas_dgemm / dgemv; the drives of model format 2 (spec section 11)
 * on top through the actuator coordinates d(q).
 *
 * It shares nothing with the generator but the model's numbers (prru_mech,
 * read by prru_ref_params_default): it is the independent check the tests
 * compare the generated kernels against, and the baseline bench/ measures
 * them against. Plain and readable on purpose, not fast.
 *
 * The topology is the parameters' own (p->nlimb), not the build's: one
 * build evaluates a model of either. Its counts are nact = nlimb,
 * nbody = 1 + 3 nlimb and nlambda = 19 nlimb; the outputs have exactly
 * those lengths and are compact (J_d's row stride is 3, Q's nlambda), so
 * a caller's arrays sized for its model, or for the PRRU_MAX_* of
 * prru_sizes.h, fit.
 *
 * All arrays are row-major, body order P L1 L2 L3 U1 U2 U3 S1 S2 S3 (three
 * limbs) or P L1..L4 U1..U4 S1..S4 (four limbs, spec section 12).
 * Functions return GSL_SUCCESS, GSL_EDOM when q is unreachable (an acos
 * argument outside [-1, 1]) or not finite, GSL_ESING when a matrix that must
 * be inverted is singular; on failure every output element is NaN. An
 * nlimb other than 3 or 4 is GSL_EINVAL: the outputs whose length depends
 * on the counts are then left untouched (that length is unknown), the
 * others NaN. Below NACT, NBODY and NLAMBDA name the parameters' counts. */
#ifndef PRRU_REF_H
#define PRRU_REF_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "prru_sizes.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Spec section 11 (format 2; a format-1 model is the special case with
 * equal limbs, gravity (0, 0, -g), com = 0, diagonal inertia, no drives).
 * The derivation covers the three-limb machine of spec sections 1-11 (ten
 * bodies, 57 reaction coordinates) and the redundantly actuated four-limb
 * one of section 12 (limb 4 mirrors limb 3; 13 bodies, 76 reaction
 * coordinates, one of them redundant). The arrays hold the largest model;
 * only the first nlimb (nbody, nact) entries are read. */
typedef struct {
  int nlimb;                                   /* 3 or 4 */
  double g[3];                                 /* gravity in {S}, m/s^2 */
  double b[PRRU_MAX_LIMB];                     /* rail offsets, m (limb 1 at y = -b1, limb 4 at x = -b4) */
  double l1[PRRU_MAX_LIMB], l2[PRRU_MAX_LIMB]; /* upper and lower links, m */
  double a[PRRU_MAX_LIMB];                     /* U-joint offsets, m; a[2] = a[3] = 0 (C_3 = C_4 = O') */
  double mass[PRRU_MAX_BODY];                  /* kg */
  double com[PRRU_MAX_BODY][3];                /* centre of mass in the body frame, m */
  double inertia[PRRU_MAX_BODY][9];            /* about the centre, body axes, row-major, kg m^2 */
  double armature[PRRU_MAX_ACT];               /* reflected drive inertia k_i, kg */
  double damping[PRRU_MAX_ACT];                /* c_i, N s/m */
  double coulomb[PRRU_MAX_ACT];                /* f_i, N */
  double coulomb_velocity;                     /* v_s, m/s (unused where every f_i = 0) */
} prru_ref_params;

/* The model the kernels were generated from (prru_mech), its nlimb
 * included; the entries past its counts are 0. */
void prru_ref_params_default(prru_ref_params *p);

/* Preallocated GSL workspace, for either topology; the public members hold
 * the last results, sized for the last model evaluated. */
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

/* Array lengths: d, dd, ddb and fd NACT, Jd NACT x 3, R 9 NBODY, pos
 * 3 NBODY, H 6 NBODY x 3, dm 6 NBODY. */
int prru_ref_ik(const prru_ref_params *p, const double q[3], double d[]);
int prru_ref_jd(const prru_ref_params *p, const double q[3], double Jd[]);
/* R_b and the centres of mass p_b = origin_b + R_b com_b. */
int prru_ref_poses(const prru_ref_params *p, const double q[3], double R[], double pos[]);
int prru_ref_jacobians(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double H[]);
int prru_ref_bias_terms(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                        const double qd[3], double dm[]);
/* H^T Phi H + J_d^T diag(armature) J_d. */
int prru_ref_mass(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double M[9]);
/* H^T K + J_d^T diag(armature) (Jd' qd); without damping and friction. */
int prru_ref_bias(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                  const double qd[3], double h[3]);
/* G = sum_b J_T,b^T m_b g. */
int prru_ref_gravity(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double G[3]);
int prru_ref_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                      const double qd[3], double M[9], double h[3], double G[3]);
/* E[0] = T (bodies, from their velocities, plus sum k_i dd_i^2 / 2),
 * E[1] = V = -sum_b m_b g . p_b. */
int prru_ref_energy(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                    const double qd[3], double E[2]);
/* dd = J_d qd and ddb = Jd' qd, the qd-quadratic part of d''. */
int prru_ref_actuator_rates(const prru_ref_params *p, const double q[3], const double qd[3],
                            double dd[], double ddb[]);
/* Qp = J_d^T (-c dd - f tanh(dd / v_s)): the drives' damping and friction. */
int prru_ref_passive(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                     const double qd[3], double Qp[3]);
/* M qdd = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp + Qp - h, solved with GSL;
 * fp acts at the tool point O' = (0, 0, q3), mp on the platform. */
int prru_ref_forward_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                              const double qd[3], const double fd[], const double fp[3],
                              const double mp[3], double qdd[3]);
/* The fd that produce qdd under fp, mp (and the drives' Qp): with J_d^T fd = tau the
 * generalized force the motion needs, fd = J_d^-T tau for three limbs and the
 * minimum-norm fd = J_d (J_d^T J_d)^-1 tau for four (spec section 12; no internal
 * preload). GSL_ESING when J_d (J_d^T J_d for four limbs) is singular. */
int prru_ref_inverse_dynamics(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                              const double qd[3], const double qdd[3], const double fp[3],
                              const double mp[3], double fd[]);
/* Q (6 NBODY x NLAMBDA), spec section 7 joint table, lambda order of the
 * descriptor's lambda_labels. */
int prru_ref_reaction_basis(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double Q[]);
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
int prru_ref_reactions(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                       const double qd[3], const double fd[], const double fp[3],
                       const double mp[3], double lambda[]);
/* The null space of Q at q, from the same SVD as prru_ref_reactions: *nullity
 * = the number of singular values cut (0 for three limbs, 1 for four), z the
 * unit right singular vector of the smallest singular value (Q z = 0 when
 * *nullity = 1; with *nullity = 0 merely the least determined direction),
 * signed so that its largest component is positive. GSL_ESING, z still set,
 * where *nullity is not NLAMBDA - (6 NBODY - 3); GSL_EDOM (and GSL_ESING if
 * Phi is not positive definite) with z all NaN and *nullity = -1. */
int prru_ref_reaction_null(const prru_ref_params *p, prru_ref_ws *w, const double q[3],
                           double z[], int *nullity);
/* w_R = sigma_1/sigma_2 of Mt JtR^+ (spec section 8, M with the armature),
 * GSL SVD, with J_d^+ = J_d^-1 for three limbs and (J_d^T J_d)^-1 J_d^T for
 * four (spec section 12): Mt = J_d^+T M J_d^+, JtR = J_R,P J_d^+; JtR^+ drops
 * singular values at or below NACT * DBL_EPSILON * sigma_1 (JtR has rank 2).
 * GSL_ESING when J_d is singular (J_d^T J_d for four limbs). */
int prru_ref_w_r(const prru_ref_params *p, prru_ref_ws *w, const double q[3], double *w_r);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_REF_H */
