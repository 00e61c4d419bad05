/* The parameter kernels of each topology (three and four limbs), compiled
 * into every build: what evaluates a model loaded at run time, whatever
 * model the build's specialised kernels were generated from. Internal to
 * the runtime, its tests and benchmarks. */
#ifndef PRRU_TOPOLOGY_H
#define PRRU_TOPOLOGY_H
#include <stddef.h>

#include "prru_descriptor.h"
#include "prru_dynamics.h"
#include "prru_p3_kernels.h"
#include "prru_p3s_kernels.h"
#include "prru_p4_kernels.h"
#include "prru_p4s_kernels.h"

/* A model's numbers as its topology's kernels read them (prru_p3_derived
 * or prru_p4_derived), and as their simple variant reads them: storage
 * for either topology, so that a model object has one layout. */
typedef union {
  prru_p3_derived p3;
  prru_p4_derived p4;
} prru_topo_derived;
typedef union {
  prru_p3s_derived p3;
  prru_p4s_derived p4;
} prru_topo_simple;

typedef struct {
  int nlimb, nact, nbody, nlambda;
  /* The kernel tables (prru_kernel_table): general, and the simple
   * structural variant for numbers with no centre-of-mass offset, product
   * of inertia or drive and gravity along z (structure_simple). */
  const prru_kernel_table *general, *simple;
  /* d from p's entries of this topology's limbs, bodies and actuators
   * (the rest of p is not read). */
  void (*derive)(const prru_params *p, prru_topo_derived *d);
  /* Whether d's numbers have the simple structure exactly (zero, not
   * small: a number the variant drops must not matter at all). */
  int (*structure_simple)(const prru_topo_derived *d);
  void (*simple_derive)(const prru_topo_derived *d, prru_topo_simple *s);
  /* The batched manipulability terms in single precision (the general
   * kernels' prru_pN_f_batch_dme_terms). */
  void (*f_batch_dme_terms)(const prru_topo_derived *d, int n, const float *q, float *dd, float *Jd,
                            float *M, float *JP);
  const char *const *lambda_labels; /* the kernels' names of lambda's entries */
} prru_topology;

/* The topology of nlimb limbs; NULL for another number. */
const prru_topology *prru_topology_of(int nlimb);
/* The members of a descriptor that are the topology's, not the model's:
 * sizes, bodies and their order (P, L1.., U1.., S1..), joints in lambda
 * order (C_i, B_i, A_i, P_i) and lambda's labels; the generator's layout
 * (tests/test_model_load.c compares them with the build's descriptor).
 * Every other member of me is left as it was. */
void prru_topology_layout(const prru_topology *t, prru_mechanism *me);

#endif
