/* The joint reactions (docs/model.md section 7, paper eq. 28): at the
 * accelerations of the forward dynamics, the generated closed form
 * prru_joint_reactions gives every coordinate limb by limb (gen/prrugen/
 * reactions.py derives it): each limb's joints from its U-joint wrench, that
 * wrench from the limb's hinge and rail conditions, and the three limbs'
 * constraint forces from the platform's balance. It equals eq. 31,
 * lambda = (Q^T Phi^-1 Q)^-1 Q^T Phi^-1 (K - Fbar), where that system is
 * regular, without forming Q or solving anything at run time.
 *
 * The redundant 4-PRRU (docs/model.md section 13): Q has a one-dimensional
 * null space z (limbs 3 and 4 pushing O' against each other along e2); the
 * kernel returns the solution of least Euclidean norm (lambda . z = 0) and
 * the unit z, whose sign is fixed here (prru_reaction_null). */
#include <math.h>
#include <string.h>

#include "prru.h"
#include "internal.h"

/* Sign of z (nl coordinates): the first coordinate in lambda order of at
 * least half the largest magnitude is positive (stable under rounding:
 * ties between equal magnitudes, as between C3's and P3's force along e2,
 * cannot flip it). */
static void orient_null(int nl, double z[])
{
  double big = 0;
  for (int i = 0; i < nl; i++) /* not fmax: a libm call per element here */
    if (fabs(z[i]) > big) big = fabs(z[i]);
  for (int i = 0; i < nl; i++)
    if (fabs(z[i]) >= 0.5 * big) {
      if (z[i] < 0)
        for (int k = 0; k < nl; k++) z[k] = -z[k];
      return;
    }
}

/* Whether m's reactions have a null space: four actuators (one direction,
 * prru_sizes.h's largest topology), three none. */
static int has_null(const prru_model *m) { return m->mech->nact == 4; }

/* The closed form into lam (and d->lambda_null). */
static void closed_form(const prru_model *m, prru_data *d, const double q[3], const double qd[3], const double qdd[3],
                        const double fd[], const double fp[3], const double mp[3], double lam[])
{
  if (!has_null(m)) {
    KERNEL(m, joint_reactions)(m->kernel_params, q, qd, qdd, fd, fp, mp, lam, NULL);
    memset(d->lambda_null, 0, sizeof d->lambda_null);
  } else {
    KERNEL(m, joint_reactions)(m->kernel_params, q, qd, qdd, fd, fp, mp, lam, d->lambda_null);
    orient_null(m->mech->nlambda, d->lambda_null);
  }
}

/* Why the closed form is not finite at a state whose forward dynamics is:
 * a pose where the joints cannot carry some load at all (the hinge
 * equations' divisors vanish: a U joint's constraint axis normal to its
 * limb's hinges, an upper link horizontal), which shows at rest too; or
 * loads and velocities so large that the arithmetic overflows. */
static int classify_failure(const prru_model *m, prru_data *d, const double q[3])
{
  static const double zero[3] = {0, 0, 0}, zero_fd[PRRU_MAX_ACT] = {0};
  const int nl = m->mech->nlambda;
  double lam[PRRU_MAX_LAMBDA];
  closed_form(m, d, q, zero, zero, zero_fd, zero, zero, lam);
  int rest_ok = prru_finite_n(lam, nl);
  if (has_null(m)) rest_ok = rest_ok && prru_finite_n(d->lambda_null, nl);
  return rest_ok ? PRRU_EINPUT : PRRU_ESINGULAR;
}

int prru_reaction_null(const prru_model *m, prru_data *d, const double q[3],
                       double z[])
{
  if (!has_null(m)) return PRRU_EINPUT;
  const int nl = m->mech->nlambda;
  int st = prru_check_regular(m, d, q, NULL);
  if (st != PRRU_OK) return st;
  KERNEL(m, reaction_nullspace)(m->kernel_params, q, d->lambda_null);
  if (!prru_finite_n(d->lambda_null, nl)) return PRRU_ESINGULAR;
  orient_null(nl, d->lambda_null);
  memcpy(z, d->lambda_null, (size_t)nl * sizeof(double));
  return PRRU_OK;
}

int prru_reactions(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                   const prru_loads *l, double lambda[])
{
  double qdd[3];
  int st = prru_forward_dynamics(m, d, q, qd, l, qdd);
  if (st != PRRU_OK) return st;
  const int nl = m->mech->nlambda;
  closed_form(m, d, q, qd, qdd, l->fd, l->fp, l->mp, d->r);
  int ok = prru_finite_n(d->r, nl);
  if (has_null(m)) ok = ok && prru_finite_n(d->lambda_null, nl);
  if (!ok) {
    st = classify_failure(m, d, q);
    memset(d->lambda_null, 0, sizeof d->lambda_null);
    return st;
  }
  memcpy(lambda, d->r, (size_t)nl * sizeof(double));
  return PRRU_OK;
}
