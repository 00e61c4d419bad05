/* The reference path of the "simulated second": the paper's section 4.3
 * scenario (spec section 9) integrated with a plain gsl_odeiv2 driver whose
 * right-hand side is prru_ref_forward_dynamics, i.e. what a user of the
 * paper's equations with GSL would write. It shares no code with
 * prru_simulate, so the final-state agreement of the two is evidence too. */
#ifndef PRRU_BENCH_REFSIM_H
#define PRRU_BENCH_REFSIM_H

typedef struct {
  double h0, abs_tol, rel_tol; /* same meaning as prru_sim_options */
  double t_end;                /* s; the state is only sampled at t_end */
} bench_refsim_options;

/* The paper's initial state: q = (0, pi/6, -0.8), qd = 0. */
void bench_refsim_initial(double q0[3], double qd0[3]);

/* Integrates from bench_refsim_initial() to o->t_end; y = (q, qd) there and
 * *steps the driver's step count. Returns 0 or the GSL status of the failure
 * (with a message on stderr). */
int bench_refsim_paper(const bench_refsim_options *o, double y[6], unsigned long *steps);

#endif
