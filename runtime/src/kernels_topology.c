/* The parameter kernels of both topologies (topology.h): thin adapters to
 * the one signature of prru_kernel_table, and the conversion of the public
 * prru_params (arrays of the maxima) to each topology's own type. The only
 * place the runtime chooses between the three- and four-limb kernel sets:
 * everything else reaches them through a model's table. */
#include <math.h>
#include <stddef.h>

#include "internal.h"
#include "topology.h"

#define T(name) prru_p3_##name
#define TS(name) prru_p3s_##name
#define TU(NAME) PRRU_P3_UNSEEN_FINITE_##NAME
#define TSU(NAME) PRRU_P3S_UNSEEN_FINITE_##NAME
#define L(name) p3_##name
#define TOPO_PARAMS prru_params3
#define TOPO_NLIMB PRRU_P3_NLIMB
#define TOPO_NACT PRRU_P3_NACT
#define TOPO_NBODY PRRU_P3_NBODY
#define TOPO_NLAMBDA PRRU_P3_NLAMBDA
#include "kernels_topology.inc"
#undef T
#undef TS
#undef TU
#undef TSU
#undef L
#undef TOPO_PARAMS
#undef TOPO_NLIMB
#undef TOPO_NACT
#undef TOPO_NBODY
#undef TOPO_NLAMBDA

#define T(name) prru_p4_##name
#define TS(name) prru_p4s_##name
#define TU(NAME) PRRU_P4_UNSEEN_FINITE_##NAME
#define TSU(NAME) PRRU_P4S_UNSEEN_FINITE_##NAME
#define L(name) p4_##name
#define TOPO_PARAMS prru_params4
#define TOPO_NLIMB PRRU_P4_NLIMB
#define TOPO_NACT PRRU_P4_NACT
#define TOPO_NBODY PRRU_P4_NBODY
#define TOPO_NLAMBDA PRRU_P4_NLAMBDA
#include "kernels_topology.inc"

/* The public structs hold either topology (prru_sizes.h). */
typedef char topology_fits_public_structs[(PRRU_P4_NACT <= PRRU_MAX_ACT && PRRU_P4_NLIMB <= PRRU_MAX_LIMB &&
                                           PRRU_P4_NBODY <= PRRU_MAX_BODY && PRRU_P4_NJOINT <= PRRU_MAX_JOINT &&
                                           PRRU_P4_NLAMBDA <= PRRU_MAX_LAMBDA)
                                              ? 1
                                              : -1];

const prru_topology *prru_topology_of(int nlimb)
{
  return nlimb == 3 ? &p3_topology : nlimb == 4 ? &p4_topology : NULL;
}

void prru_topology_layout(const prru_topology *t, prru_mechanism *me)
{
  /* Names for up to four limbs, by kind then limb: the descriptor points
   * at them, so they outlive every model. */
  static const char *const bodies[3][PRRU_MAX_LIMB] = {
      {"L1", "L2", "L3", "L4"}, {"U1", "U2", "U3", "U4"}, {"S1", "S2", "S3", "S4"}};
  static const char *const joints[4][PRRU_MAX_LIMB] = {
      {"C1", "C2", "C3", "C4"}, {"B1", "B2", "B3", "B4"}, {"A1", "A2", "A3", "A4"}, {"P1", "P2", "P3", "P4"}};
  const int n = t->nlimb;
  me->nq = 3, me->nact = t->nact, me->nlimb = n, me->nbody = t->nbody, me->nlambda = t->nlambda;
  me->njoint = 4 * n;
  me->platform = 0;
  me->body_names[0] = "P", me->body_limb[0] = -1;
  for (int i = 0; i < n; i++) {
    me->lower[i] = 1 + i, me->upper[i] = 1 + n + i, me->slider[i] = 1 + 2 * n + i;
    for (int k = 0; k < 3; k++) me->body_names[1 + k * n + i] = bodies[k][i], me->body_limb[1 + k * n + i] = i;
  }
  /* Joint k of limb i in lambda order: C_i (platform on the lower link,
   * 4 reactions), B_i (lower on upper), A_i (upper on slider), P_i
   * (slider on its rail, proximal -1): 5 reactions each. */
  int off = 0;
  for (int k = 0; k < 4; k++)
    for (int i = 0; i < n; i++) {
      prru_joint_info *j = &me->joint[k * n + i];
      static const int proximal_kind[4] = {0, 1, 2, -1}; /* lower, upper, slider, ground */
      j->name = joints[k][i];
      j->type = k == 0 ? 'U' : k == 3 ? 'P' : 'R';
      j->limb = i;
      j->proximal = proximal_kind[k] < 0 ? -1 : 1 + proximal_kind[k] * n + i;
      j->distal = k == 0 ? me->platform : 1 + (k - 1) * n + i;
      j->lambda_offset = off;
      j->lambda_count = k == 0 ? 4 : 5;
      off += j->lambda_count;
    }
  for (int r = 0; r < t->nlambda; r++) me->lambda_labels[r] = t->lambda_labels[r];
}
