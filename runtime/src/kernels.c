/* The specialised kernel table of a build (prru_kernel_table in
 * prru_dynamics.h): the constant-folded kernels of the build's model,
 * thin adapters to the table's one signature. The parameter kernels of
 * both topologies, which a model loaded at run time evaluates with, are
 * kernels_topology.c's. */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "internal.h"
#include "prru.h"
#include "prru_param_kernels.h"
#include "prru_derivs.h"
#include "prru_regressor.h"

#include "topology.h"

/* The tests and benchmarks call the build's parameter kernels directly:
 * its topology's, with prru_param_derived its derived type. */
typedef char params_layout_check[sizeof(prru_param_derived) <= sizeof(prru_topo_derived) ? 1 : -1];

void prru_params_derive(const prru_params *p, prru_param_derived *d)
{
  prru_topo_derived t;
  prru_topology_of(PRRU_NLIMB)->derive(p, &t);
  memcpy(d, &t, sizeof *d);
}

/* ---- specialised: the constant-folded kernels, p ignored ---- */
static void s_ik(const void *p, const double q[3], double d[PRRU_NACT]) { (void)p, prru_ik(q, d); }
static void s_jd(const void *p, const double q[3], double Jd[PRRU_NACT * 3]) { (void)p, prru_jd(q, Jd); }
static void s_ik_jd(const void *p, const double q[3], double d[PRRU_NACT], double Jd[PRRU_NACT * 3])
{
  (void)p, prru_ik_jd(q, d, Jd);
}
static void s_mass(const void *p, const double q[3], double M[9]) { (void)p, prru_mass(q, M); }
static void s_dynamics(const void *p, const double q[3], const double qd[3], double M[9], double h[3], double G[3])
{
  (void)p, prru_dynamics(q, qd, M, h, G);
}
static void s_eom(const void *p, const double q[3], const double qd[3], const double fd[PRRU_NACT],
                  const double fp[3], const double mp[3], double M[9], double b[3])
{
  (void)p, prru_eom(q, qd, fd, fp, mp, M, b);
}
static void s_eom_solve(const void *p, const double q[3], const double qd[3], const double fd[PRRU_NACT],
                        const double fp[3], const double mp[3], double M[9], double b[3], double qdd[3],
                        double minors[3])
{
  (void)p, prru_eom_solve(q, qd, fd, fp, mp, M, b, qdd, minors);
}
static int s_unseen_eom_solve(const double q[3], const double qd[3], const double fd[PRRU_NACT],
                              const double fp[3], const double mp[3])
{
  (void)q, (void)qd, (void)fd, (void)fp, (void)mp;
  return PRRU_UNSEEN_FINITE_EOM_SOLVE(q, qd, fd, fp, mp);
}
static void s_inverse_terms(const void *p, const double q[3], const double qd[3], const double qdd[3],
                            const double fp[3], const double mp[3], double d[PRRU_NACT],
                            double Jd[PRRU_NACT * 3], double Jdinv[3 * PRRU_NACT], double out[3])
{
  (void)p;
#if PRRU_NACT == 3
  prru_inverse_terms(q, qd, qdd, fp, mp, d, Jd, Jdinv, out);
#else
  (void)Jdinv;
  prru_inverse_terms(q, qd, qdd, fp, mp, d, Jd, out);
#endif
}
static int s_unseen_inverse_terms(const double q[3], const double qd[3], const double qdd[3],
                                  const double fp[3], const double mp[3])
{
  (void)q, (void)qd, (void)qdd, (void)fp, (void)mp;
  return PRRU_UNSEEN_FINITE_INVERSE_TERMS(q, qd, qdd, fp, mp);
}
static void s_joint_reactions(const void *p, const double q[3], const double qd[3], const double qdd[3],
                              const double fd[PRRU_NACT], const double fp[3], const double mp[3],
                              double lambda[PRRU_NLAMBDA], double z[PRRU_NLAMBDA])
{
  (void)p;
#if PRRU_NACT == 3
  (void)z;
  prru_joint_reactions(q, qd, qdd, fd, fp, mp, lambda);
#else
  prru_joint_reactions(q, qd, qdd, fd, fp, mp, lambda, z);
#endif
}
static void s_platform_jacobian(const void *p, const double q[3], double JP[18])
{
  (void)p, prru_platform_jacobian(q, JP);
}
static void s_poses(const void *p, const double q[3], double R[9 * PRRU_NBODY], double pos[3 * PRRU_NBODY])
{
  (void)p, prru_poses(q, R, pos);
}
static void s_energy(const void *p, const double q[3], const double qd[3], double E[2])
{
  (void)p, prru_energy(q, qd, E);
}
static void s_actuator_rates(const void *p, const double q[3], const double qd[3], double dd[PRRU_NACT],
                             double ddb[PRRU_NACT])
{
  (void)p, prru_actuator_rates(q, qd, dd, ddb);
}
static void s_passive(const void *p, const double q[3], const double qd[3], double Qp[3])
{
  (void)p, prru_passive(q, qd, Qp);
}
static void s_batch_dme_terms(const void *p, int n, const double *q, double *d, double *Jd, double *M, double *JP)
{
  (void)p, prru_batch_dme_terms(n, q, d, Jd, M, JP);
}

static void s_regressor(const void *p, const double q[3], const double qd[3], const double qdd[3], double vs,
                        double *Y)
{
  (void)p, prru_regressor(q, qd, qdd, &vs, Y);
}

static void s_eom_solve_derivs(const void *p, const double q[3], const double qd[3],
                               const double fd[PRRU_NACT], const double fp[3], const double mp[3],
                               double M[9], double b[3], double qdd[3], double minors[3],
                               double Dq[9], double Dqd[9], double Dfd[3 * PRRU_NACT], double Dfp[9],
                               double Dmp[9])
{
  (void)p, prru_eom_solve_derivs(q, qd, fd, fp, mp, M, b, qdd, minors, Dq, Dqd, Dfd, Dfp, Dmp);
}
static int s_unseen_eom_solve_derivs(const double q[3], const double qd[3], const double fd[PRRU_NACT],
                                     const double fp[3], const double mp[3])
{
  (void)q, (void)qd, (void)fd, (void)fp, (void)mp;
  return PRRU_UNSEEN_FINITE_EOM_SOLVE_DERIVS(q, qd, fd, fp, mp);
}
static void s_inverse_derivs(const void *p, const double q[3], const double qd[3], const double qdd[3],
                             const double fp[3], const double mp[3], double d[PRRU_NACT],
                             double Jd[PRRU_NACT * 3], double Jdinv[3 * PRRU_NACT], double out[3],
                             double Dq[9], double Dqd[9], double Dqdd[9], double DJd[9 * PRRU_NACT])
{
  (void)p;
#if PRRU_NACT == 3
  (void)DJd;
  prru_inverse_derivs(q, qd, qdd, fp, mp, d, Jd, Jdinv, out, Dq, Dqd, Dqdd);
#else
  (void)Jdinv;
  prru_inverse_derivs(q, qd, qdd, fp, mp, d, Jd, out, Dq, Dqd, Dqdd, DJd);
#endif
}
static int s_unseen_inverse_derivs(const double q[3], const double qd[3], const double qdd[3],
                                   const double fp[3], const double mp[3])
{
  (void)q, (void)qd, (void)qdd, (void)fp, (void)mp;
  return PRRU_UNSEEN_FINITE_INVERSE_DERIVS(q, qd, qdd, fp, mp);
}

static void s_batch_eom_solve_derivs(const void *p, int n, const double *q, const double *qd,
                                     const double *fd, const double *fp, const double *mp, double *M,
                                     double *b, double *qdd, double *minors, double *Dq, double *Dqd,
                                     double *Dfd, double *Dfp, double *Dmp)
{
  (void)p, prru_batch_eom_solve_derivs(n, q, qd, fd, fp, mp, M, b, qdd, minors, Dq, Dqd, Dfd, Dfp, Dmp);
}

#if PRRU_NREACTION_NULL == 1
static void s_reaction_nullspace(const void *p, const double q[3], double z[])
{
  (void)p, prru_reaction_nullspace(q, z);
}
#define REACTION_NULLSPACE s_reaction_nullspace
#else
#define REACTION_NULLSPACE NULL
#endif

const prru_kernel_table prru_kernels_specialised = {
  "specialised",  s_ik,      s_jd,
  s_ik_jd,        s_mass,    s_dynamics,
  s_eom,          s_eom_solve, s_unseen_eom_solve,
  s_inverse_terms, s_unseen_inverse_terms, s_joint_reactions,
  s_platform_jacobian, s_poses, s_energy,
  s_actuator_rates, s_passive, s_batch_dme_terms,
  s_regressor,    s_eom_solve_derivs, s_unseen_eom_solve_derivs,
  s_inverse_derivs, s_unseen_inverse_derivs, s_batch_eom_solve_derivs,
  REACTION_NULLSPACE,
};
