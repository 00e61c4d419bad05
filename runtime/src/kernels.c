/* The kernel tables of a build (prru_kernel_table in prru.h): the
 * specialised kernels of the build's model, and the parameter kernels of
 * its topology, which a model loaded at run time evaluates with, in two
 * structures: general, and the simple variant for models with no
 * centre-of-mass offsets, products of inertia or drives and gravity along
 * -z (prru_param_structure_simple). Thin adapters to one signature; the
 * topology is the build's (the runtime computes with its sizes), the
 * only place the runtime chooses between the three- and four-limb kernel
 * sets. */
#include <math.h>
#include <stddef.h>

#include "internal.h"
#include "prru.h"
#include "prru_param_kernels.h"
#include "prru_derivs.h"
#include "prru_regressor.h"

#if PRRU_NLIMB == 3
#include "prru_p3_kernels.h"
#include "prru_p3s_kernels.h"
#define P(name) prru_p3_##name
#define G(name) prru_p3_##name /* the regressor of every structure */
#define UNSEEN_P(name) PRRU_P3_UNSEEN_FINITE_##name
#define PS(name) prru_p3s_##name
#define UNSEEN_PS(name) PRRU_P3S_UNSEEN_FINITE_##name
typedef prru_params3 topo_params;
typedef prru_p3_derived topo_derived;
typedef prru_p3s_derived simple_derived;
#elif PRRU_NLIMB == 4
#include "prru_p4_kernels.h"
#include "prru_p4s_kernels.h"
#define P(name) prru_p4_##name
#define G(name) prru_p4_##name
#define UNSEEN_P(name) PRRU_P4_UNSEEN_FINITE_##name
#define PS(name) prru_p4s_##name
#define UNSEEN_PS(name) PRRU_P4S_UNSEEN_FINITE_##name
typedef prru_params4 topo_params;
typedef prru_p4_derived topo_derived;
typedef prru_p4s_derived simple_derived;
#else
#error "prru: a build's model has 3 or 4 limbs"
#endif

/* The loaded numbers are stored as prru_param_derived (the build's
 * layout) and read as the topology's: the same members in the same
 * order. */
typedef char params_layout_check[sizeof(topo_derived) == sizeof(prru_param_derived) ? 1 : -1];

#define TP(p) ((const topo_derived *)(p))

/* Whether the simple variant's kernels are exact for these numbers: every
 * centre of mass at its body frame's origin, every product of inertia,
 * armature, damping and Coulomb force zero, gravity along z. Exactly zero,
 * not small: a number the variant drops must not matter at all. */
int prru_param_structure_simple(const prru_param_derived *d)
{
  const topo_params *p = &TP(d)->params;
  int ok = p->gravity[0] == 0 && p->gravity[1] == 0;
  for (int b = 0; b < PRRU_NBODY && ok; b++)
    ok = p->com[b][0] == 0 && p->com[b][1] == 0 && p->com[b][2] == 0 && p->inertia[b][3] == 0 &&
         p->inertia[b][4] == 0 && p->inertia[b][5] == 0;
  for (int i = 0; i < PRRU_NACT && ok; i++)
    ok = p->armature[i] == 0 && p->damping[i] == 0 && p->coulomb[i] == 0;
  return ok;
}

size_t prru_param_simple_size(void) { return sizeof(simple_derived); }

void prru_params_derive(const prru_params *p, prru_param_derived *d)
{
  topo_params t;
  for (int i = 0; i < PRRU_NLIMB; i++) t.b[i] = p->b[i], t.l1[i] = p->l1[i], t.l2[i] = p->l2[i], t.a[i] = p->a[i];
  for (int k = 0; k < 3; k++) t.gravity[k] = p->gravity[k];
  for (int b = 0; b < PRRU_NBODY; b++) {
    t.mass[b] = p->mass[b];
    for (int k = 0; k < 3; k++) t.com[b][k] = p->com[b][k];
    for (int k = 0; k < 6; k++) t.inertia[b][k] = p->inertia[b][k];
  }
  for (int i = 0; i < PRRU_NACT; i++)
    t.armature[i] = p->armature[i], t.damping[i] = p->damping[i], t.coulomb[i] = p->coulomb[i];
  t.coulomb_velocity = p->coulomb_velocity;
  P(derive)(&t, (topo_derived *)d);
}

void prru_param_simple_derive(const prru_param_derived *d, void *out)
{
  PS(derive)(&TP(d)->params, out);
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

const prru_kernel_table prru_kernels_specialised = {
  "specialised",  s_ik,      s_jd,
  s_ik_jd,        s_mass,    s_dynamics,
  s_eom,          s_eom_solve, s_unseen_eom_solve,
  s_inverse_terms, s_unseen_inverse_terms, s_joint_reactions,
  s_platform_jacobian, s_poses, s_energy,
  s_actuator_rates, s_passive, s_batch_dme_terms,
  s_regressor,    s_eom_solve_derivs, s_unseen_eom_solve_derivs,
  s_inverse_derivs, s_unseen_inverse_derivs, s_batch_eom_solve_derivs,
};

/* ---- parameter: the topology's kernels, p its derived numbers ---- */
#define A(name) p_##name
#define TABLE prru_kernels_parameter
#include "kernels_param.inc"
#undef A
#undef TABLE

/* ---- the simple structural variant (prru_p3s_*, prru_p4s_*) ---- */
#undef P
#undef UNSEEN_P
#undef TP
#define P(name) PS(name)
#define UNSEEN_P(name) UNSEEN_PS(name)
#define TP(p) ((const simple_derived *)(p))
#define A(name) ps_##name
#define TABLE prru_kernels_parameter_simple
#include "kernels_param.inc"
