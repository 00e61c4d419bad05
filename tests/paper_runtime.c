/* The paper's simulation study (section 4.3): q(0) = (0, pi/6, -0.8), the
 * paper's loads, 1 s. Three steppers agree, an independent RK4 on the
 * reference dynamics agrees, and the reactions at the final state match
 * the dense reference. The paper model only (registered for it alone). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "prru.h"
#include "prru_ref.h"
#include "testsim.h"
#include "testutil.h"

static prru_model model;
static prru_data data;

/* Independent integration: classical RK4 on the reference's forward
 * dynamics (GSL assembly, hand-derived Jacobians), fixed step. */
static void ref_rhs(prru_ref_params *p, prru_ref_ws *w, prru_load_schedule *ls, double t,
                    const double y[6], double f[6])
{
  prru_loads l;
  prru_schedule_eval(ls, t, &l);
  memcpy(f, y + 3, 3 * sizeof f[0]);
  prru_ref_forward_dynamics(p, w, y, y + 3, l.fd, l.fp, l.mp, f + 3);
}

static void test_paper_scenario(void)
{
  char msg[300];
  prru_scenario s;
  prru_scenario_paper(&s);
  keep a, b, c;
  int sa = run_sim(&model, s.q0, s.qd0, &s.loads, PRRU_RK8PD, 1e-12, 1.0, &a, msg);
  int sb = run_sim(&model, s.q0, s.qd0, &s.loads, PRRU_RKCK, 1e-12, 1.0, &b, msg);
  int sc = run_sim(&model, s.q0, s.qd0, &s.loads, PRRU_MSBDF, 1e-11, 1.0, &c, msg);
  TU_TRUE(sa == PRRU_OK && sb == PRRU_OK && sc == PRRU_OK, "paper scenario runs with three steppers");
  double e = tu_relerr(a.last.q, b.last.q, 3, 1.0);
  printf("paper q(1 s) = (%.10f, %.10f, %.10f); rk8pd vs rkck %.1e, vs msbdf %.1e\n",
         a.last.q[0], a.last.q[1], a.last.q[2], e, tu_relerr(a.last.q, c.last.q, 3, 1.0));
  tu_check(e <= 1e-8, "rk8pd and rkck agree on q(1 s)", e, 1e-8);
  e = tu_relerr(a.last.q, c.last.q, 3, 1.0);
  tu_check(e <= 1e-6, "rk8pd and msbdf agree on q(1 s)", e, 1e-6);

  prru_ref_params p;
  prru_ref_params_default(&p);
  prru_ref_ws *w = prru_ref_alloc();
  double y[6] = {s.q0[0], s.q0[1], s.q0[2], 0, 0, 0}, k1[6], k2[6], k3[6], k4[6], yt[6];
  int n = 4000;
  double h = 1.0 / n;
  for (int i = 0; i < n; i++) {
    double t = i * h;
    ref_rhs(&p, w, &s.loads, t, y, k1);
    for (int j = 0; j < 6; j++) yt[j] = y[j] + 0.5 * h * k1[j];
    ref_rhs(&p, w, &s.loads, t + 0.5 * h, yt, k2);
    for (int j = 0; j < 6; j++) yt[j] = y[j] + 0.5 * h * k2[j];
    ref_rhs(&p, w, &s.loads, t + 0.5 * h, yt, k3);
    for (int j = 0; j < 6; j++) yt[j] = y[j] + h * k3[j];
    ref_rhs(&p, w, &s.loads, t + h, yt, k4);
    for (int j = 0; j < 6; j++) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
  }
  e = tu_relerr(a.last.q, y, 3, 1.0);
  printf("paper q(1 s) vs RK4 on the reference dynamics: %.1e\n", e);
  tu_check(e <= 1e-8, "paper q(1 s) = RK4 on the reference dynamics", e, 1e-8);
  e = tu_relerr(a.last.qd, y + 3, 3, 1.0);
  tu_check(e <= 1e-7, "paper qd(1 s) = RK4 on the reference dynamics", e, 1e-7);
  /* Reactions at the independently integrated final state. */
  double lam_ref[PRRU_NLAMBDA];
  prru_loads l;
  prru_schedule_eval(&s.loads, 1.0, &l);
  double lam[PRRU_NLAMBDA];
  prru_reactions(&model, &data, y, y + 3, &l, lam);
  prru_ref_reactions(&p, w, y, y + 3, l.fd, l.fp, l.mp, lam_ref);
  e = tu_relerr(lam, lam_ref, PRRU_NLAMBDA, 1.0);
  tu_check(e <= 1e-10, "paper reactions at t = 1 s vs the dense reference", e, 1e-10);
  prru_ref_free(w);
  prru_scenario_free(&s);
}

int main(void)
{
  prru_model_default(&model);
  test_paper_scenario();
  return tu_finish("paper_runtime");
}
