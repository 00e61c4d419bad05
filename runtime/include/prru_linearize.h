/* Linearisation of the dynamics, for LQR and MPC: the closed-form
 * derivatives of forward dynamics (the generated prru_eom_solve_derivs,
 * one evaluation with qdd) and of inverse dynamics (prru_inverse_derivs;
 * with four actuators composed from its dtau/dx and dJ_d/dq).
 *
 * State x = (q, qd) (6), input u = fd (nact), x' = f(x, u) =
 * (qd, qdd(q, qd, fd, fp, mp)):
 *     A = df/dx = [0 I; dqdd/dq dqdd/dqd],  B = df/du = [0; dqdd/dfd].
 * Every matrix is row-major; row i of a derivative block is qdd_i (fd_i),
 * column k the k-th variable.
 *
 * Both kernel sets have them: the specialised one (constant-folded from
 * the build's model file) and the topology's parameter set, for a model
 * loaded at run time (prru_model_load) with other numbers. */
#ifndef PRRU_LINEARIZE_H
#define PRRU_LINEARIZE_H

#include "prru.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The matrices with a column per actuator are compact (row stride nact,
 * the model's m->mech->nact); their entries past it are 0. */
typedef struct {
  double qdd[3];
  double dqdd_dq[9], dqdd_dqd[9];  /* 3x3 */
  double dqdd_dfd[3 * PRRU_MAX_ACT]; /* 3 x nact */
  double dqdd_dfp[9], dqdd_dmp[9]; /* 3x3: the platform force and moment */
  double A[36];                    /* 6x6 */
  double B[6 * PRRU_MAX_ACT];        /* 6 x nact */
  /* With dt > 0: the zero-order-hold discrete pair x_{k+1} = Ad x_k + Bd
   * u_k, [Ad Bd; 0 I] = exp([A B; 0 0] dt) (gsl_linalg_exponential_ss,
   * GSL_PREC_DOUBLE); with dt = 0 they are not computed (left 0). */
  double dt;
  double Ad[36];
  double Bd[6 * PRRU_MAX_ACT];
} prru_linearization;

/* Whether this model's kernel table has the derivative kernels (every
 * table of this build has). */
PRRU_API int prru_linearize_available(const prru_model *m);

/* The linearisation at (q, qd) under the loads l, into out. PRRU_OK; or
 * the status prru_forward_dynamics gives at the same state where qdd is
 * not trusted (PRRU_EUNREACHABLE, PRRU_ESTROKE, PRRU_ESINGULAR: the same
 * criterion, mass_rcond_min included; PRRU_EINPUT for non-finite input),
 * and PRRU_EINPUT for dt < 0 or not finite, for a kernel table without
 * the derivative kernels (prru_linearize_available), or where the exponential
 * overflows (dt far beyond the dynamics' time scales). On failure out is
 * all zeros: no number of it is a result. */
PRRU_API int prru_linearize(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                            const prru_loads *l, double dt, prru_linearization *out);

/* prru_linearize with the reason of a failure in msg (as
 * prru_forward_dynamics_why). */
PRRU_API int prru_linearize_why(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                                const prru_loads *l, double dt, prru_linearization *out, char *msg,
                                int msglen);

/* prru_linearize at n states in one call, through the batched derivative
 * kernel (the table's batch_eom_solve_derivs: the loops a build
 * vectorises). State k is q[3k..3k+2], qd[3k..3k+2] under l[k]; its
 * linearisation goes to out[k] and its status to status[k] (status may be
 * NULL): prru_linearize's statuses and zeroed output on failure, by the
 * same trust test on the batched kernel's outputs. Those equal the scalar
 * kernel's bit for bit unless the build provides vector sin and cos (the
 * batched kernels' note in prru_kernels.h), then they agree within a few
 * ulp of q1 and q2 propagated. A state the test fails is evaluated again
 * by prru_linearize, whose status it gets; so only a state within those
 * few ulp of a threshold (the reach, mass_rcond_min) could be trusted here
 * and not there. Returns PRRU_OK when
 * every state is PRRU_OK, else the first state's failure status;
 * PRRU_EINPUT for n < 0 (nothing written), and for dt < 0 or not finite
 * or a kernel table without the batched kernel (every state PRRU_EINPUT).
 * The arrays must not overlap. */
PRRU_API int prru_linearize_batch(const prru_model *m, int n, const double *q, const double *qd,
                                  const prru_loads *l, double dt, prru_linearization *out,
                                  int *status);

/* Inverse dynamics fd (as prru_inverse_dynamics: the same statuses and
 * trust test, and the same fd) and its derivatives dfd/dq, dfd/dqd,
 * dfd/dqdd (nact x 3 each), any of them NULL if not wanted. Three
 * actuators: dfd/dqdd = J_d^-T M, from one generated evaluation. Four: the
 * minimum-norm fd = J_d^+T tau, dfd/dqdd = J_d^+T M; the derivatives are
 * composed from the generated dtau/dx and dJ_d/dq with the J_d^+ and n of
 * prru_inverse_dynamics_preload (see linearize.c). */
PRRU_API int prru_inverse_dynamics_derivs(const prru_model *m, prru_data *d, const double q[3],
                                          const double qd[3], const double qdd[3], const prru_loads *l,
                                          double fd[], double dfd_dq[],
                                          double dfd_dqd[], double dfd_dqdd[]);

/* The same for prru_inverse_dynamics_preload's fd = J_d^+T tau + t n with
 * the preload t held fixed: dfd/dq then also has t dn/dq (n turns with
 * J_d), dfd/dqd and dfd/dqdd are those of t = 0. PRRU_EINPUT for a
 * non-finite t and a non-zero t with three actuators, as there. */
PRRU_API int prru_inverse_dynamics_preload_derivs(const prru_model *m, prru_data *d, const double q[3],
                                                  const double qd[3], const double qdd[3],
                                                  const prru_loads *l, double preload,
                                                  double fd[], double dfd_dq[],
                                                  double dfd_dqd[],
                                                  double dfd_dqdd[]);

#ifdef __cplusplus
}
#endif

#endif
