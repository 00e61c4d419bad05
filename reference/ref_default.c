/* The build's model as the reference's parameters. The only file of the
 * reference that sees the generated code: prru_mech, the descriptor the
 * kernels were generated from. Everything else computes with the
 * parameters' own topology. */
#include <string.h>

#include "prru_mechanism.h"
#include "prru_ref.h"

void prru_ref_params_default(prru_ref_params *p)
{
  const prru_mechanism *me = &prru_mech;
  memset(p, 0, sizeof *p);
  p->nlimb = me->nlimb;
  for (int i = 0; i < 3; i++) p->g[i] = me->gravity[i];
  for (int l = 0; l < me->nlimb; l++) {
    p->b[l] = me->b[l];
    p->l1[l] = me->l1[l];
    p->l2[l] = me->l2[l];
    p->a[l] = me->a[l];
  }
  for (int b = 0; b < me->nbody; b++) {
    p->mass[b] = me->mass[b];
    for (int i = 0; i < 3; i++) p->com[b][i] = me->com[b][i];
    for (int i = 0; i < 9; i++) p->inertia[b][i] = me->inertia[b][i];
  }
  for (int i = 0; i < me->nact; i++) {
    p->armature[i] = me->armature[i];
    p->damping[i] = me->damping[i];
    p->coulomb[i] = me->coulomb[i];
  }
  p->coulomb_velocity = me->coulomb_velocity;
}
