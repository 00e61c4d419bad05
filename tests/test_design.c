/* Design optimisation (prru_design.h) on any model: the objective through
 * the runtime-parameter kernels at the model's own numbers is the map's
 * global index through the constant kernels; finite-difference
 * sensitivities agree between two steps; invalid designs and variables
 * are refused with reasons; the optimiser keeps its bounds, never worsens
 * the start and is deterministic. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testbuild.h"
#include "prru_design.h"
#include "testutil.h"
#include "topology.h" /* the other topology's layout (runtime/src) */

#define PI 3.14159265358979323846

/* The build's model: the topology of the designs here but other_topology's. */
static prru_model model;

/* Fig. 7's rectangle: every model's generic tests use it; points that a
 * model cannot reach are counted as such by both paths. */
static const prru_map_grid fig7 = {-PI / 6, PI / 6, -PI / 4, PI / 6, 0.0, 61, 57};
/* A small rectangle around home, regular for any buildable model. */
static const prru_map_grid home = {-0.15, 0.15, -0.12, 0.14, 0.0, 17, 15};

/* det J_d's sign at q with the constant kernels (0 for four actuators). */
static int det_sign_at(double q1, double q2, double q3)
{
  if (PRRU_NACT != 3) return 0;
  const double q[3] = {q1, q2, q3};
  double d[PRRU_NACT], J[PRRU_NACT * 3];
  prru_ik_jd(q, d, J);
  double det = J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) +
               J[2] * (J[3] * J[7] - J[4] * J[6]);
  return det > 0 ? 1 : det < 0 ? -1 : 0;
}

static void objective_equals_map(void)
{
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &fig7);
  prru_design_data dd;
  TU_TRUE(prru_design_data_alloc(&dd, &fig7) == PRRU_OK, "alloc");
  prru_design_eval ev;
  TU_TRUE(prru_design_evaluate(&pr, &prru_params_model, &dd, &ev) == PRRU_OK, "evaluate model");

  prru_model m;
  prru_model_default(&m);
  m.jd_rcond_min = pr.rcond_min;
  long n = (long)fig7.n1 * fig7.n2;
  double *w = malloc((size_t)n * sizeof *w);
  unsigned char *st = malloc((size_t)n);
  prru_map_options o;
  prru_map_options_default(&o);
  prru_map_summary sum;
  TU_TRUE(prru_map_eval(&m, &fig7, &o, w, st, NULL) == PRRU_OK, "map");
  /* The other assembly mode as the map marks it, checked against this
   * file's det J_d with the constant kernels: an ok pose has home's sign,
   * an other_mode pose not. */
  long n_other = 0;
  int home_sign = det_sign_at(0.0, 0.0, fig7.q3), modes_agree = 1;
  for (long k = 0; k < n; k++) {
    int i = (int)(k / fig7.n2), j = (int)(k % fig7.n2);
    if (st[k] != PRRU_OK && st[k] != PRRU_DESIGN_OTHER_MODE) continue;
    int sign = det_sign_at(prru_map_axis(fig7.q1_lo, fig7.q1_hi, fig7.n1, i),
                           prru_map_axis(fig7.q2_lo, fig7.q2_hi, fig7.n2, j), fig7.q3);
    n_other += st[k] == PRRU_DESIGN_OTHER_MODE;
    if ((st[k] == PRRU_DESIGN_OTHER_MODE) != (home_sign != 0 && sign != home_sign)) modes_agree = 0;
  }
  prru_map_summarize(&fig7, w, st, &sum);
  TU_TRUE(sum.n_ok > 0, "the rectangle has regular points");
  TU_TRUE(modes_agree && (PRRU_NACT != 3 || n_other > 0), "the map's other assembly mode is det J_d's sign");
  TU_TRUE(ev.n_other_mode == n_other && sum.n_other_mode == n_other,
          "the same points in the other assembly mode");
  TU_TRUE(sum.n_ok == ev.sum.n_ok && sum.n_singular == ev.sum.n_singular &&
              sum.n_unreachable == ev.sum.n_unreachable,
          "same statuses counted");
  int same_status = 1;
  double werr = 0;
  for (long k = 0; k < n; k++) {
    if (st[k] != dd.status[k]) same_status = 0;
    if (st[k] == PRRU_OK) werr = fmax(werr, fabs(w[k] - dd.w_R[k]) / w[k]);
  }
  TU_TRUE(same_status, "the same status at every grid point");
  tu_check(werr <= 1e-12, "w_R per point, parameter vs constant kernels", werr, 1e-12);
  TU_CLOSE(&ev.sum.index, &sum.index, 1, 1e-12, "global index (mean w_R - 1)");
  TU_CLOSE(&ev.sum.index_log, &sum.index_log, 1, 1e-12, "mean ln w_R");
  TU_CLOSE(&ev.sum.w_max, &sum.w_max, 1, 1e-12, "max w_R");
  TU_CLOSE(&ev.objective, &sum.index, 1, 1e-12, "objective mean = index");
  TU_TRUE(ev.feasible == (sum.n_ok == sum.n_points), "feasible iff every point regular");
  TU_TRUE((ev.reg_violation > 0) == (sum.n_ok < sum.n_points), "violation iff a point is not ok");
  pr.objective = PRRU_OBJ_LOG;
  prru_design_evaluate(&pr, &prru_params_model, &dd, &ev);
  TU_CLOSE(&ev.objective, &sum.index_log, 1, 1e-12, "objective log = mean ln w_R");
  pr.objective = PRRU_OBJ_MAX;
  prru_design_evaluate(&pr, &prru_params_model, &dd, &ev);
  TU_CLOSE(&ev.objective, &sum.w_max, 1, 1e-12, "objective max = max w_R");
  free(w);
  free(st);
  prru_design_data_free(&dd);
}

/* The same bits with any number of threads (rows summed in order). */
static void threads_same_bits(void)
{
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &fig7);
  pr.stroke = 1;
  pr.stroke_lo = 0.1;
  pr.stroke_hi = 0.3;
  prru_design_data a, b;
  prru_design_data_alloc(&a, &fig7);
  prru_design_data_alloc(&b, &fig7);
  prru_design_eval ea, eb;
  a.nthreads = 1;
  prru_design_evaluate(&pr, &prru_params_model, &a, &ea);
  int same = 1;
  for (int t = 2; t <= 5; t++) {
    b.nthreads = t;
    prru_design_evaluate(&pr, &prru_params_model, &b, &eb);
    same = same && memcmp(&ea, &eb, sizeof ea) == 0 && memcmp(a.status, b.status, (size_t)a.n) == 0;
    for (long k = 0; k < a.n; k++)
      if (a.status[k] == PRRU_OK && a.w_R[k] != b.w_R[k]) same = 0;
  }
  TU_TRUE(same, "evaluation with 1 to 5 threads: the same bits");
  prru_design_data_free(&a);
  prru_design_data_free(&b);
}

/* prru_design_data.precision float (prru optimize --precision float): on
 * a grid with every status and a stroke that cuts it, every status and the
 * violations are the double evaluation's bit for bit (statuses decided in
 * double, rcond and d double's wherever they are penalised: elsewhere both
 * penalties are 0), w_R within test_map_batch.c's derived bound 64
 * FLT_EPSILON w_R / rcond (rcond >= rcond_min at every ok point), the
 * slider range within the float kernels' d error (256 FLT_EPSILON (|d| +
 * 4 L), as the runtime's margin). */
static void float_evaluation(void)
{
  const prru_map_grid g = {-1.55, 1.55, -1.55, 1.55, 0.0, 47, 53}; /* as test_map_batch's: every status */
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &g);
  prru_design_data a, b;
  prru_design_data_alloc(&a, &g);
  prru_design_data_alloc(&b, &g);
  prru_design_eval ea, eb;
  prru_design_evaluate(&pr, &prru_params_model, &a, &ea);
  pr.stroke = 1;
  pr.stroke_lo = ea.d_min + 0.1 * (ea.d_max - ea.d_min);
  pr.stroke_hi = ea.d_max - 0.1 * (ea.d_max - ea.d_min);
  prru_design_evaluate(&pr, &prru_params_model, &a, &ea);
  b.precision = PRRU_PRECISION_FLOAT;
  prru_design_evaluate(&pr, &prru_params_model, &b, &eb);
  int kinds[256] = {0}, w_ok = 1;
  for (long k = 0; k < a.n; k++) {
    kinds[a.status[k]] = 1;
    if (a.status[k] == PRRU_OK &&
        !(fabs(b.w_R[k] - a.w_R[k]) <= 64 * FLT_EPSILON * a.w_R[k] * a.w_R[k] / pr.rcond_min))
      w_ok = 0;
  }
  /* A redundant robot's 4 x 3 J_d keeps its rank over this grid and has
   * no assembly modes to leave: only ok and out of reach there. */
  TU_TRUE(kinds[PRRU_OK] && kinds[PRRU_EUNREACHABLE] &&
              (PRRU_NACT != 3 || (kinds[PRRU_ESINGULAR] && kinds[PRRU_DESIGN_OTHER_MODE])),
          "float evaluation: the grid has every status");
  TU_TRUE(memcmp(a.status, b.status, (size_t)a.n) == 0, "float evaluation: the statuses are double's");
  TU_TRUE(ea.reg_violation == eb.reg_violation && ea.stroke_violation > 0 &&
              ea.stroke_violation == eb.stroke_violation && ea.feasible == eb.feasible,
          "float evaluation: the violations are double's, bit for bit");
  TU_TRUE(w_ok, "float evaluation: w_R within 64 FLT_EPSILON w_R / rcond of double's");
  const double L = prru_design_length_scale(&model, &prru_params_model);
  TU_TRUE(fabs(eb.d_min - ea.d_min) <= 256 * FLT_EPSILON * (fabs(ea.d_min) + 4 * L) &&
              fabs(eb.d_max - ea.d_max) <= 256 * FLT_EPSILON * (fabs(ea.d_max) + 4 * L),
          "float evaluation: the slider range within float's error");
  prru_design_data_free(&a);
  prru_design_data_free(&b);
}

static void stroke_limits(void)
{
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &home);
  prru_design_data dd;
  prru_design_data_alloc(&dd, &home);
  prru_design_eval ev;
  prru_design_evaluate(&pr, &prru_params_model, &dd, &ev);
  TU_TRUE(ev.feasible && ev.stroke_violation == 0 && ev.d_min < ev.d_max, "home rectangle regular");
  pr.stroke = 1;
  pr.stroke_lo = ev.d_min;
  pr.stroke_hi = ev.d_max;
  prru_design_eval ev2;
  prru_design_evaluate(&pr, &prru_params_model, &dd, &ev2);
  TU_TRUE(ev2.feasible && ev2.stroke_violation == 0, "stroke exactly the range used: feasible");
  pr.stroke_hi = ev.d_max - 0.01 * (ev.d_max - ev.d_min);
  prru_design_evaluate(&pr, &prru_params_model, &dd, &ev2);
  TU_TRUE(!ev2.feasible && ev2.stroke_violation > 0 && ev2.merit > ev.merit,
          "a shorter stroke is violated and penalized");
  prru_design_data_free(&dd);
}

static void sensitivity_two_steps(void)
{
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &home);
  prru_design_data dd;
  prru_design_data_alloc(&dd, &home);
  const char *names[] = {"b_1", "b3", "l1", "l2_2", "a", "m_P", "I_P_xx", "I_U_zz", "com_P_x",
                         "I_P_xy", "m_S", "armature"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
    prru_design_var v;
    TU_TRUE(prru_design_var_parse(&model, names[i], &v, NULL, 0) == PRRU_OK, names[i]);
    prru_design_sens s1, s2;
    int r1 = prru_design_sensitivity(&pr, &prru_params_model, &v, 1e-3, &dd, &s1);
    int r2 = prru_design_sensitivity(&pr, &prru_params_model, &v, 5e-4, &dd, &s2);
    char what[96];
    snprintf(what, sizeof what, "d index / d %s: both steps ok, no status change", names[i]);
    TU_TRUE(r1 == PRRU_OK && r2 == PRRU_OK && !s1.set_changed && !s2.set_changed, what);
    /* Central differences: error O(h^2), so halving h changes the result
     * by 3/4 of the first one's error. Scaled by the parameter's scale so
     * that a derivative of ~0 is compared in the index's own units. */
    double a = s1.derivative * s1.scale, b = s2.derivative * s2.scale;
    double err = fabs(a - b) / fmax(fabs(b), 1e-3 * fabs(s1.f_plus));
    snprintf(what, sizeof what, "d index / d %s with h and h/2", names[i]);
    tu_check(err <= 1e-5, what, err, 1e-5);
    snprintf(what, sizeof what, "step of %s = 1e-3 scale", names[i]);
    TU_CLOSE(&s1.step, &(double){1e-3 * s1.scale}, 1, 1e-15, what);
  }
  /* Physics as an independent check: a slider only translates along its
   * rail, so its mass and the drive's armature enter M the same way (equal
   * derivatives), and its centre of mass and inertia not at all. */
  for (int i = 0; i < PRRU_NLIMB; i++) {
    char nm[32], na[32], what[96];
    prru_design_var vm, va, vc, vi;
    snprintf(nm, sizeof nm, "m_S%d", i + 1);
    snprintf(na, sizeof na, "armature_%d", i + 1);
    prru_design_var_parse(&model, nm, &vm, NULL, 0);
    prru_design_var_parse(&model, na, &va, NULL, 0);
    snprintf(nm, sizeof nm, "com_S%d_y", i + 1);
    prru_design_var_parse(&model, nm, &vc, NULL, 0);
    snprintf(nm, sizeof nm, "I_S%d_zz", i + 1);
    prru_design_var_parse(&model, nm, &vi, NULL, 0);
    prru_design_sens sm, sa, sc, si;
    prru_design_sensitivity(&pr, &prru_params_model, &vm, 1e-3, &dd, &sm);
    /* the same step h for both */
    double ascale = prru_design_scale(&model, &prru_params_model, &va);
    prru_design_sensitivity(&pr, &prru_params_model, &va, 1e-3 * sm.scale / ascale, &dd, &sa);
    snprintf(what, sizeof what, "d/d m_S%d = d/d armature_%d", i + 1, i + 1);
    TU_CLOSE(&sa.derivative, &sm.derivative, 1, 1e-6, what);
    TU_TRUE(fabs(sm.derivative) > 0, "a slider's mass matters");
    prru_design_sensitivity(&pr, &prru_params_model, &vc, 1e-3, &dd, &sc);
    prru_design_sensitivity(&pr, &prru_params_model, &vi, 1e-3, &dd, &si);
    snprintf(what, sizeof what, "slider %d's com and inertia do not change w_R", i + 1);
    tu_check(fabs(sc.derivative * sc.scale) <= 1e-12 && fabs(si.derivative * si.scale) <= 1e-12, what,
             fmax(fabs(sc.derivative * sc.scale), fabs(si.derivative * si.scale)), 1e-12);
  }
  /* Every single parameter is reachable by name and perturbs the
   * objective only through itself. */
  int np = prru_design_param_count(&model), ok = 1;
  TU_TRUE(np == 3 * PRRU_NLIMB + 2 + 10 * PRRU_NBODY + PRRU_NACT, "parameter count");
  for (int k = 0; k < np; k++) {
    prru_design_var v, w;
    prru_design_param(&model, k, &v);
    if (prru_design_var_parse(&model, v.name, &w, NULL, 0) != PRRU_OK || w.n != 1 ||
        w.offset[0] != v.offset[0])
      ok = 0;
  }
  TU_TRUE(ok, "every canonical parameter name parses to itself");
  prru_design_data_free(&dd);
}

static void variables(void)
{
  static const struct {
    const char *name;
    int n;
  } good[] = {{"b12", 2},   {"b_12", 2}, {"b3", 1},    {"b", PRRU_NLIMB}, {"l1", PRRU_NLIMB},
              {"l1_2", 1},  {"l2_13", 2}, {"a", 2},    {"a1", 1},         {"m_P", 1},
              {"m_U", PRRU_NLIMB}, {"m_L2", 1}, {"com_S_z", PRRU_NLIMB}, {"I_P_xy", 1},
              {"I_U1_zz", 1}, {"armature", PRRU_NACT}, {"armature_2", 1}};
  for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
    prru_design_var v;
    char what[64];
    snprintf(what, sizeof what, "variable %s ties %d", good[i].name, good[i].n);
    TU_TRUE(prru_design_var_parse(&model, good[i].name, &v, NULL, 0) == PRRU_OK && v.n == good[i].n, what);
  }
  const char *bad[] = {"", "b0", "b_", "b11", "l1_9", "l13", "a3", "foo", "I_P_xw", "m_Q", "com_P",
                       "m_", "armature_0", "l1_12345", "gravity", "damping"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    prru_design_var v;
    char msg[512] = "", what[64];
    snprintf(what, sizeof what, "'%s' refused with its name in the message", bad[i]);
    TU_TRUE(prru_design_var_parse(&model, bad[i], &v, msg, sizeof msg) == PRRU_EINPUT &&
                strstr(msg, bad[i]) && strstr(msg, "not a design parameter"),
            what);
  }
  /* Tied parameters move by the same amount. */
  prru_params p = prru_params_model;
  p.l1[1] += 0.01;
  prru_design_var v;
  prru_design_var_parse(&model, "l1", &v, NULL, 0);
  prru_design_set(&p, &p, &v, p.l1[0] + 0.002);
  TU_TRUE(p.l1[0] == prru_params_model.l1[0] + 0.002 &&
              fabs(p.l1[1] - (prru_params_model.l1[1] + 0.012)) < 1e-15,
          "tied variable shifts every member");
  /* Assigned, every tied member takes the value itself. */
  prru_design_assign(&p, &v, 0.5);
  int all = 1;
  for (int i = 0; i < PRRU_NLIMB; i++) all &= p.l1[i] == 0.5;
  TU_TRUE(all && p.l2[0] == prru_params_model.l2[0], "tied variable assigned: every member, nothing else");
}

static void check_refuses(const prru_params *p, const char *needle, const char *what)
{
  char msg[512] = "";
  int st = prru_design_check(&model, p, msg, sizeof msg);
  if (!TU_TRUE(st == PRRU_EINPUT && strstr(msg, needle), what))
    fprintf(stderr, "  message: %s\n", msg);
}

static void validity(void)
{
  char msg[512] = "";
  TU_TRUE(prru_design_check(&model, &prru_params_model, msg, sizeof msg) == PRRU_OK, "the model is valid");
  prru_params p = prru_params_model;
  p.l1[0] = -0.1;
  check_refuses(&p, "limb 1", "negative l1");
  p = prru_params_model;
  p.b[PRRU_NLIMB - 1] = 10.0;
  check_refuses(&p, "cannot be assembled", "a rail too far away");
  p = prru_params_model;
  p.mass[0] = 0;
  check_refuses(&p, "m_P", "zero mass");
  p = prru_params_model;
  p.inertia[0][3] = 10 * (p.inertia[0][0] + p.inertia[0][1]);
  check_refuses(&p, "not positive definite", "indefinite inertia");
  p = prru_params_model;
  p.inertia[0][2] = 1.5 * (p.inertia[0][0] + p.inertia[0][1]);
  check_refuses(&p, "triangle", "triangle inequality");
  p = prru_params_model;
  p.com[1][0] = 1e-12;
  check_refuses(&p, "com_", "a number the model file cannot hold");
  p = prru_params_model;
  p.armature[0] = -1;
  check_refuses(&p, "armature_1", "negative armature");
  p = prru_params_model;
  p.l1[0] = NAN;
  check_refuses(&p, "l1_1", "NaN");
  /* An invalid design gets the invalid merit, not an evaluation. */
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &home);
  prru_design_data dd;
  prru_design_data_alloc(&dd, &home);
  prru_design_eval ev;
  p = prru_params_model;
  p.mass[0] = -1;
  TU_TRUE(prru_design_evaluate(&pr, &p, &dd, &ev) == PRRU_EINPUT && !ev.valid && ev.merit >= 1e30,
          "invalid design evaluates to the invalid merit");
  prru_design_data_free(&dd);
}

static void optimizer(void)
{
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &home);
  prru_design_var vars[2];
  prru_design_var_parse(&model, "b", &vars[0], NULL, 0);
  prru_design_var_parse(&model, "l2", &vars[1], NULL, 0);
  for (int i = 0; i < 2; i++) {
    double x = prru_design_get(&prru_params_model, &vars[i]);
    vars[i].lo = 0.95 * x;
    vars[i].hi = 1.05 * x;
  }
  prru_design_options o;
  prru_design_options_default(&o);
  o.max_iter = 60;
  prru_design_result r1, r2;
  char msg[512];
  TU_TRUE(prru_design_optimize(&pr, &prru_params_model, vars, 2, &o, &r1, msg, sizeof msg) == PRRU_OK,
          "optimize");
  TU_TRUE(prru_design_optimize(&pr, &prru_params_model, vars, 2, &o, &r2, msg, sizeof msg) == PRRU_OK,
          "optimize again");
  TU_TRUE(memcmp(&r1.best, &r2.best, sizeof r1.best) == 0 &&
              r1.best_eval.merit == r2.best_eval.merit && r1.evaluations == r2.evaluations,
          "deterministic: the same design, merit and evaluations");
  TU_TRUE(r1.best_eval.merit <= r1.start_eval.merit, "never worse than the start");
  TU_TRUE(r1.best_eval.merit < r1.start_eval.merit, "improves on this rectangle");
  int inside = 1;
  for (int i = 0; i < 2; i++) {
    double x = prru_design_get(&r1.best, &vars[i]);
    if (!(x >= vars[i].lo && x <= vars[i].hi) || x != r1.x[i]) inside = 0;
  }
  TU_TRUE(inside, "the best design keeps its bounds");
  /* Re-evaluated independently: the reported evaluation is the design's. */
  prru_design_data dd;
  prru_design_data_alloc(&dd, &home);
  prru_design_eval ev;
  prru_design_evaluate(&pr, &r1.best, &dd, &ev);
  TU_TRUE(ev.merit == r1.best_eval.merit && ev.sum.index == r1.best_eval.sum.index,
          "re-evaluation gives the same bits");
  prru_design_data_free(&dd);
  /* Bad bounds and variables. */
  prru_design_var bad = vars[0];
  bad.lo = bad.hi + 1;
  TU_TRUE(prru_design_optimize(&pr, &prru_params_model, &bad, 1, &o, &r1, msg, sizeof msg) ==
                  PRRU_EINPUT &&
              strstr(msg, "infeasible bounds"),
          "lo > hi refused");
  bad = vars[0];
  bad.lo = 2 * bad.hi;
  bad.hi = 3 * bad.hi;
  TU_TRUE(prru_design_optimize(&pr, &prru_params_model, &bad, 1, &o, &r1, msg, sizeof msg) ==
                  PRRU_EINPUT &&
              strstr(msg, "outside its bounds"),
          "start outside the bounds refused");
  prru_design_var dup[2] = {vars[0], vars[0]};
  TU_TRUE(prru_design_optimize(&pr, &prru_params_model, dup, 2, &o, &r1, msg, sizeof msg) ==
                  PRRU_EINPUT &&
              strstr(msg, "appears in both"),
          "a parameter in two variables refused");
}

/* Tied parameters whose values differ (the last limb's l2 10 % shorter,
 * as a model file may have it): the bounds prru_design_var_bounds gives
 * keep every limb within its own -+ 5 %, one of them on its edge, and
 * the optimiser's design stays inside them on every limb. Rounding: the
 * shift x - x0 and the sum x_k + shift are two roundings of numbers of
 * the size of l2, so a limb may pass its edge by 2 DBL_EPSILON l2 at most. */
static void tied_bounds(void)
{
  const double pct = 5, eps = 2 * DBL_EPSILON;
  prru_params p = prru_params_model;
  p.l2[PRRU_NLIMB - 1] *= 0.9;
  prru_design_var v;
  prru_design_var_parse(&model, "l2", &v, NULL, 0);
  TU_TRUE(prru_design_var_bounds(&model, &p, &v, pct) == PRRU_OK && v.lo < p.l2[0] && p.l2[0] < v.hi,
          "bounds of a tied variable around its value");
  TU_TRUE(prru_design_var_bounds(&model, &p, &v, 0) == PRRU_EINPUT &&
              prru_design_var_bounds(&model, &p, &v, 100) == PRRU_EINPUT,
          "a percentage outside (0, 100) refused");
  prru_design_var_bounds(&model, &p, &v, pct);
  double worst = 0;
  for (int e = 0; e < 2; e++) {
    prru_params q = p;
    prru_design_set(&q, &p, &v, e ? v.hi : v.lo);
    for (int k = 0; k < PRRU_NLIMB; k++)
      worst = fmax(worst, fabs(q.l2[k] - p.l2[k]) / (pct / 100 * p.l2[k]));
  }
  TU_TRUE(worst <= 1 + eps / (pct / 100) && worst >= 1 - eps / (pct / 100),
          "every limb within its own 5 %, the shortest on its edge");
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &home);
  prru_design_options o;
  prru_design_options_default(&o);
  o.max_iter = 40;
  prru_design_result r;
  char msg[512] = "";
  TU_TRUE(prru_design_optimize(&pr, &p, &v, 1, &o, &r, msg, sizeof msg) == PRRU_OK, "optimize tied l2");
  int inside = 1;
  for (int k = 0; k < PRRU_NLIMB; k++)
    if (!(fabs(r.best.l2[k] - p.l2[k]) <= pct / 100 * p.l2[k] + eps * p.l2[k])) inside = 0;
  TU_TRUE(inside, "the optimised l2 of every limb within its own 5 %");
}

/* Steps that rounding loses are refused (prru_design_step_check: h at
 * least 100 DBL_EPSILON times the magnitude): 1e-300 would give every
 * derivative exactly 0. */
static void tiny_steps(void)
{
  prru_design_problem pr;
  prru_design_problem_default(&model, &pr, &home);
  prru_design_data dd;
  TU_TRUE(prru_design_data_alloc(&dd, &home) == PRRU_OK, "alloc");
  prru_design_var b, arm;
  prru_design_var_parse(&model, "b_1", &b, NULL, 0);
  prru_design_var_parse(&model, "armature_1", &arm, NULL, 0);
  prru_design_sens s;
  char msg[512] = "";
  TU_TRUE(prru_design_sensitivity(&pr, &prru_params_model, &b, 1e-300, &dd, &s) == PRRU_EINPUT,
          "sensitivity with the step 1e-300 refused");
  TU_TRUE(prru_design_step_check(&model, &prru_params_model, &b, 1e-300, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "b_1") && strstr(msg, "lost to rounding"),
          "the message names the parameter and the reason");
  /* b_1 is its own scale: the smallest relative step is 100 DBL_EPSILON. */
  TU_TRUE(prru_design_step_check(&model, &prru_params_model, &b, 0.99 * 100 * DBL_EPSILON, NULL, 0) ==
                  PRRU_EINPUT &&
              prru_design_step_check(&model, &prru_params_model, &b, 1.01 * 100 * DBL_EPSILON, NULL, 0) ==
                  PRRU_OK,
          "the limit is 100 DBL_EPSILON of the value");
  TU_TRUE(prru_design_step_check(&model, &prru_params_model, &arm, 1e-300, NULL, 0) == PRRU_EINPUT,
          "a parameter at 0: the step is measured against its scale");
  TU_TRUE(prru_design_step_check(&model, &prru_params_model, &b, 1e-4, NULL, 0) == PRRU_OK &&
              prru_design_step_check(&model, &prru_params_model, &b, 0.5, NULL, 0) == PRRU_EINPUT,
          "the default step passes, 0.5 does not");
  prru_design_data_free(&dd);
}

/* Names and counts are the designed model's topology's, not the build's:
 * a model with the other topology's layout (prru_topology_layout, as a
 * model of it loaded at run time has) gets its own limbs, bodies and
 * actuators. */
static void other_topology(void)
{
  const int n = PRRU_NLIMB == 3 ? 4 : 3, nbody = 1 + 3 * n;
  static prru_mechanism me; /* about 4 kB */
  me = prru_mech;
  prru_topology_layout(prru_topology_of(n), &me);
  prru_model other = model;
  other.mech = &me;
  TU_TRUE(prru_design_param_count(&other) == 3 * n + 2 + 10 * nbody + n,
          "other topology: its parameter count");
  int ok = 1;
  for (int k = 0; k < prru_design_param_count(&other); k++) {
    prru_design_var v, w;
    if (prru_design_param(&other, k, &v) != PRRU_OK ||
        prru_design_var_parse(&other, v.name, &w, NULL, 0) != PRRU_OK || w.n != 1 ||
        w.offset[0] != v.offset[0])
      ok = 0;
  }
  TU_TRUE(ok, "other topology: every canonical parameter name parses to itself");
  static const struct {
    const char *name;
    int n;
  } tied[] = {{"b", 0}, {"l1", 0}, {"m_U", 0}, {"com_S_z", 0}, {"armature", 0}, {"a", 2}, {"b12", 2}};
  for (size_t i = 0; i < sizeof tied / sizeof tied[0]; i++) {
    prru_design_var v;
    char what[64];
    const int want = tied[i].n ? tied[i].n : n;
    snprintf(what, sizeof what, "other topology: %s ties %d", tied[i].name, want);
    TU_TRUE(prru_design_var_parse(&other, tied[i].name, &v, NULL, 0) == PRRU_OK && v.n == want, what);
  }
  /* The first upper link follows the lower links of every limb. */
  prru_design_var u;
  prru_design_var_parse(&other, "m_U1", &u, NULL, 0);
  TU_TRUE(u.n == 1 && u.offset[0] == offsetof(prru_params, mass) + (size_t)(1 + n) * sizeof(double),
          "other topology: U1 is body 1 + nlimb");
  prru_design_var v4;
  TU_TRUE((prru_design_var_parse(&other, "b4", &v4, NULL, 0) == PRRU_OK) == (n == 4) &&
              (prru_design_var_parse(&other, "armature_4", &v4, NULL, 0) == PRRU_OK) == (n == 4) &&
              (prru_design_var_parse(&other, "m_S4", &v4, NULL, 0) == PRRU_OK) == (n == 4),
          "other topology: a fourth limb exactly when it has one");
  prru_params p = prru_params_model;
  double s = 0;
  for (int i = 0; i < n; i++) s += p.l1[i] = 0.1 + 0.01 * i;
  TU_TRUE(prru_design_length_scale(&other, &p) == s / n, "other topology: the mean of its upper links");
}

int main(void)
{
  prru_model_default(&model);
  objective_equals_map();
  threads_same_bits();
  float_evaluation();
  stroke_limits();
  sensitivity_two_steps();
  variables();
  validity();
  optimizer();
  tied_bounds();
  tiny_steps();
  other_topology();
  return tu_finish("test_design");
}
