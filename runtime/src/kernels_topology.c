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
