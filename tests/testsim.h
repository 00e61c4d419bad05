/* Simulation helpers shared by the runtime tests: keep the first and last
 * samples of a run, optionally stop after n of them. */
#ifndef PRRU_TESTSIM_H
#define PRRU_TESTSIM_H
#include <string.h>

#include "prru.h"

typedef struct {
  prru_sample first, last;
  long n;
  long stop_after;
} keep;

static inline int keep_sample(const prru_sample *s, void *ctx)
{
  keep *k = ctx;
  if (k->n == 0) k->first = *s;
  k->last = *s;
  k->n++;
  return k->stop_after && k->n >= k->stop_after;
}

/* prru_simulate with samples every 10 ms into k; msg gets 300 bytes. */
static inline int run_sim(const prru_model *m, const double q0[3], const double qd0[3],
                          const prru_load_schedule *ls, prru_stepper st, double tol, double t_end,
                          keep *k, char *msg)
{
  prru_sim_options o;
  prru_sim_options_default(&o);
  o.stepper = st;
  o.abs_tol = o.rel_tol = tol;
  o.t_end = t_end;
  o.dt_out = 0.01;
  o.loads = ls;
  o.on_sample = keep_sample;
  o.ctx = k;
  double t_stop;
  memset(k, 0, sizeof *k);
  return prru_simulate(m, q0, qd0, &o, &t_stop, msg, 300);
}
#endif
