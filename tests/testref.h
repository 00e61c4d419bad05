/* Shared by the tests that compare against the reference library. */
#ifndef PRRU_TESTREF_H
#define PRRU_TESTREF_H
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_mechanism.h"
#include "prru_ref.h"

/* How far a reachable q is from the singular boundaries, in (0, 1]: the
 * smallest |sin| of an upper link's angle (= sqrt(1 - r^2) for the acos
 * argument r; read off R_Ui = Rx(alpha_i): R[7], or Ry(alpha_3): R[2]) and
 * cos(phi) of limb 3's U joint (phi = asin(-sin q1 cos q2); gamma's
 * gradient grows like 1/cos^2 phi). -1 where q is out of reach. For P's
 * own topology (3 or 4 limbs); upper link i is body 1 + nlimb + i (body
 * order P, L1..Ln, U1..Un, S1..Sn). */
static inline double ref_margin(const prru_ref_params *P, const double q[3])
{
  double R[9 * PRRU_MAX_BODY], p[3 * PRRU_MAX_BODY];
  if (prru_ref_poses(P, q, R, p) != GSL_SUCCESS) return -1;
  double m = 1.0;
  for (int i = 0; i < P->nlimb; i++) {
    const double *Ru = R + 9 * (1 + P->nlimb + i);
    m = fmin(m, fabs(i < 2 ? Ru[7] : Ru[2]));
  }
  const double sp = sin(q[0]) * cos(q[1]);
  return fmin(m, sqrt(1.0 - sp * sp));
}
/* The reference's parameters of a model's descriptor (a model loaded at
 * run time: its own numbers and its own topology, whatever the build's). */
static inline void ref_params_of(const prru_mechanism *me, prru_ref_params *p)
{
  memset(p, 0, sizeof *p);
  p->nlimb = me->nlimb;
  for (int i = 0; i < 3; i++) p->g[i] = me->gravity[i];
  for (int l = 0; l < me->nlimb; l++) p->b[l] = me->b[l], p->l1[l] = me->l1[l], p->l2[l] = me->l2[l], p->a[l] = me->a[l];
  for (int b = 0; b < me->nbody; b++) {
    p->mass[b] = me->mass[b];
    memcpy(p->com[b], me->com[b], sizeof p->com[b]);
    memcpy(p->inertia[b], me->inertia[b], sizeof p->inertia[b]);
  }
  for (int i = 0; i < me->nact; i++)
    p->armature[i] = me->armature[i], p->damping[i] = me->damping[i], p->coulomb[i] = me->coulomb[i];
  p->coulomb_velocity = me->coulomb_velocity;
}
#endif
