/* Shared by the identification sources (ident.c, ident_consistent.c,
 * excite.c); internal to the runtime. */
#ifndef PRRU_IDENT_INTERNAL_H
#define PRRU_IDENT_INTERNAL_H
#include "prru_dynamics.h"
#include "prru_ident.h"

/* Whether b was computed for a model of m's topology: its matrices are
 * sized and ordered by those counts, so a base of the other topology
 * would be read out of step. */
static inline int prru_base_fits(const prru_model *m, const prru_base *b)
{
  return b->nbody == m->mech->nbody && b->nact == m->mech->nact;
}

#endif
