/* Helpers shared by the runtime tests: random regular states; keep the
 * first and last samples of a run, optionally stop after n of them. */
#ifndef PRRU_TESTSIM_H
#define PRRU_TESTSIM_H
#include <string.h>

#include "prru.h"
#include "testutil.h"

/* A regular pose around q1 = q2 = 0 (every valid model assembles there;
 * reachability does not depend on the height q3), the range halved
 * whenever a model rejects too many draws; velocities in [-1, 1]. */
static inline void ts_random_state(const prru_model *m, prru_data *d, double q[3], double qd[3])
{
  double span = 1.0;
  for (int tries = 1;; tries++) {
    q[0] = span * tu_uniform(-0.4, 0.4);
    q[1] = span * tu_uniform(-0.5, 0.4);
    q[2] = tu_uniform(-1.0, -0.5);
    if (prru_check_regular(m, d, q, NULL) == PRRU_OK) break;
    if (tries % 100 == 0) span *= 0.5;
  }
  for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
}

/* Random loads: actuator forces in [-80, 80] N, platform force in
 * [-40, 40] N and moment in [-4, 4] N m per component (the rest of l as
 * it was). */
static inline void ts_random_loads(prru_loads *l)
{
  for (int i = 0; i < PRRU_NACT; i++) l->fd[i] = tu_uniform(-80, 80);
  for (int i = 0; i < 3; i++) {
    l->fp[i] = tu_uniform(-40, 40);
    l->mp[i] = tu_uniform(-4, 4);
  }
}

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
