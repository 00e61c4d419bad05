/* Time-optimal parameterisation (prru_topp_solve, prru_traj.h) on the
 * build's model (any number of limbs) and, with three actuators, the
 * prototype model file (drives with damping and friction): the profile
 * re-checked with the exact inverse dynamics at rows every 0.1 ms and at
 * every grid point stays within the limits; some limit is active at
 * >= 95 % of the grid intervals; it is faster than the fastest uniformly
 * time-scaled quintic under the same limits (itself checked to be the
 * fastest by bisection); the sampled motion is the path with s(t)
 * consistent (q, qd at the grid, qd the derivative of q); infeasible limits
 * name the first infeasible grid point and the limit. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru_traj.h"
#include "testutil.h"

static const double WP[9] = {0, 0, 0, 0.1, -0.08, 0.02, 0, 0, 0};

/* The largest |static load| of the path's poses (no motion). */
static double static_load(const prru_model *m, prru_data *d)
{
  double big = 0, z[3] = {0, 0, 0}, f[PRRU_NACT];
  for (int k = 0; k <= 100; k++) {
    double q[3], s = 2.0 * k / 100;
    int seg = s < 1 ? 0 : 1;
    for (int i = 0; i < 3; i++) q[i] = WP[3 * seg + i] + (s - seg) * (WP[3 * seg + 3 + i] - WP[3 * seg + i]);
    prru_limits lim;
    prru_limits_none(&lim);
    prru_limits_ratio(m, d, &lim, q, z, z, f, NULL, NULL, NULL, NULL);
    for (int i = 0; i < PRRU_NACT; i++) big = fmax(big, fabs(f[i]));
  }
  return big;
}

/* The largest limit ratio over rows every dt of the profile, and over the
 * grid's intervals at both ends with each interval's s'' (the states the
 * programme constrains); *active: intervals with a ratio >= 1 - 1e-3 at
 * an end. */
static double profile_ratio(const prru_model *m, prru_data *d, const prru_limits *lim,
                            const prru_topp *tp, double dt, double *active)
{
  double worst = 0, r;
  double q[3], qd[3], qdd[3];
  const long rows = (long)ceil(tp->duration / dt);
  for (long k = 0; k <= rows; k++) {
    double t = k == rows ? tp->duration : k * dt;
    if (prru_topp_eval(tp, t, q, qd, qdd) != PRRU_OK ||
        prru_limits_ratio(m, d, lim, q, qd, qdd, NULL, NULL, &r, NULL, NULL) != PRRU_OK)
      return INFINITY;
    worst = fmax(worst, r);
  }
  const int N = tp->grid;
  int act = 0;
  for (int s = 0; s < tp->nseg; s++)
    for (int j = 0; j < N; j++) {
      const double *x = tp->x + s * (N + 1), *u = tp->u + s * (N + 1), *qa = tp->q + 3 * s;
      int a = 0;
      for (int e = 0; e <= 1; e++) {
        for (int i = 0; i < 3; i++) {
          const double dq = qa[3 + i] - qa[i];
          q[i] = qa[i] + (double)(j + e) / N * dq, qd[i] = dq * sqrt(x[j + e]), qdd[i] = dq * u[j];
        }
        if (prru_limits_ratio(m, d, lim, q, qd, qdd, NULL, NULL, &r, NULL, NULL) != PRRU_OK)
          return INFINITY;
        worst = fmax(worst, r);
        a |= r >= 1 - 1e-3;
      }
      act += a;
    }
  *active = (double)act / (tp->nseg * N);
  return worst;
}

/* q and qd at the grid times are the path's point and q' s'; qd is the
 * derivative of q (central differences over 1e-6 s, error h^2 |q'''| / 6
 * plus rounding 1e-16 / h: 1e-9 of the peak speed). */
static void consistent(const prru_topp *tp, const char *what)
{
  const int N = tp->grid;
  double err = 0, derr = 0, vmax = 0;
  for (int s = 0; s < tp->nseg; s++)
    for (int j = 0; j <= N; j++) {
      const double *qa = tp->q + 3 * s;
      double q[3], qd[3];
      prru_topp_eval(tp, tp->t[s * (N + 1) + j], q, qd, NULL);
      for (int i = 0; i < 3; i++) {
        const double dq = qa[3 + i] - qa[i];
        err = fmax(err, fabs(q[i] - (qa[i] + (double)j / N * dq)));
        derr = fmax(derr, fabs(qd[i] - dq * sqrt(tp->x[s * (N + 1) + j])));
        vmax = fmax(vmax, fabs(qd[i]));
      }
    }
  char buf[200];
  snprintf(buf, sizeof buf, "%s: q at the grid times is the path's grid point", what);
  tu_check(err <= 1e-14, buf, err, 1e-14);
  snprintf(buf, sizeof buf, "%s: qd at the grid times is q' s'", what);
  tu_check(derr <= 1e-12 * vmax, buf, derr / vmax, 1e-12);
  const double h = 1e-6;
  double fd = 0;
  for (int k = 1; k < 200; k++) {
    double t = tp->duration * k / 200, a[3], b[3], qd[3];
    prru_topp_eval(tp, t - h, a, NULL, NULL);
    prru_topp_eval(tp, t + h, b, NULL, NULL);
    prru_topp_eval(tp, t, NULL, qd, NULL);
    for (int i = 0; i < 3; i++) fd = fmax(fd, fabs((b[i] - a[i]) / (2 * h) - qd[i]));
  }
  snprintf(buf, sizeof buf, "%s: qd is the derivative of q(t)", what);
  tu_check(fd <= 1e-6 * vmax, buf, fd / vmax, 1e-6);
}

/* One model and limits: solve, check, compare with the scaled quintic. */
static void optimal(const prru_model *m, const prru_limits *lim, const char *what)
{
  prru_data *d = malloc(sizeof *d);
  prru_topp tp;
  char msg[600], buf[900];
  int st = prru_topp_solve(&tp, m, 3, WP, lim, 0, msg, sizeof msg);
  snprintf(buf, sizeof buf, "%s: solved (%s)", what, st ? msg : "ok");
  if (!TU_TRUE(st == PRRU_OK, buf)) {
    free(d);
    return;
  }
  double active = 0;
  /* The library maximises each force near its limit over every interval
   * to PRRU_TOPP_CHECK_TOL = 1e-9, from samples that resolve the
   * friction's ramp near rest: rows anywhere stay within 1e-6 of the
   * limits (the required bound; a random model's Coulomb ramp put rows
   * 1e-3 over when only 9 points of each interval were checked). */
  double worst = profile_ratio(m, d, lim, &tp, 1e-4, &active);
  snprintf(buf, sizeof buf, "%s: forces and speeds within the limits at every row", what);
  tu_check(worst <= 1 + 1e-6, buf, worst - 1, 1e-6);
  snprintf(buf, sizeof buf, "%s: a limit active on >= 95%% of the intervals", what);
  tu_check(active >= 0.95, buf, active, 0.95);
  tu_check(fabs(active - tp.active_fraction) <= 1e-12, "the reported active fraction is the "
           "measured one", fabs(active - tp.active_fraction), 1e-12);
  consistent(&tp, what);
  /* prru_topp_row: the rows pass under the planner's limits; a force
   * limit 1 % tighter than the profile's peak is refused, named. */
  {
    double q[3], qd[3], qdd[3], f[PRRU_NACT], v[PRRU_NACT], peak = 0;
    int rows_ok = 1;
    for (int k = 0; k <= 100 && rows_ok; k++) {
      rows_ok = prru_topp_row(m, d, lim, &tp, k == 100 ? tp.duration : tp.duration * k / 100, q, qd, qdd, f, v, msg, sizeof msg) == PRRU_OK;
      for (int i = 0; i < PRRU_NACT; i++) peak = fmax(peak, fabs(f[i]) / lim->force_max[i]);
    }
    snprintf(buf, sizeof buf, "%s: prru_topp_row passes the profile's rows (%s)", what, rows_ok ? "ok" : msg);
    TU_TRUE(rows_ok, buf);
    prru_limits tight = *lim;
    for (int i = 0; i < PRRU_NACT; i++) tight.force_max[i] *= 0.99 * peak;
    int refused = 0;
    for (int k = 0; k <= 100 && !refused; k++)
      refused = prru_topp_row(m, d, &tight, &tp, k == 100 ? tp.duration : tp.duration * k / 100, q, qd, qdd, f, v, msg, sizeof msg) ==
                    PRRU_ENOCONV && strstr(msg, "exceeds its limit");
    snprintf(buf, sizeof buf, "%s: prru_topp_row refuses a row over a tighter limit", what);
    TU_TRUE(refused, buf);
  }
  double dur[2];
  st = prru_quintic_fastest(m, 3, WP, lim, 2000, dur, msg, sizeof msg);
  snprintf(buf, sizeof buf, "%s: fastest scaled quintic (%s)", what, st ? msg : "ok");
  if (TU_TRUE(st == PRRU_OK, buf)) {
    /* The bisection's bracket: 1e-9 relative. */
    for (int k = 0; k < 2; k++) {
      prru_quintic tr;
      double w[6];
      memcpy(w, WP + 3 * k, sizeof w);
      double worst_q = 0, faster = 0, r, qv[3], qd[3], qdd[3];
      for (int pass = 0; pass < 2; pass++) {
        double T = pass ? dur[k] * (1 - 1e-8) : dur[k];
        prru_quintic_waypoints(&tr, 2, w, &T, 0, msg, sizeof msg);
        double big = 0;
        for (int i = 0; i <= 2000; i++) {
          prru_quintic_eval(&tr, T * i / 2000, qv, qd, qdd);
          prru_limits_ratio(m, d, lim, qv, qd, qdd, NULL, NULL, &r, NULL, NULL);
          big = fmax(big, r);
        }
        *(pass ? &faster : &worst_q) = big;
        prru_quintic_free(&tr);
      }
      /* Its own samples, evaluated by another route (the quintic's
       * coefficients): equal to rounding, 1e-12. */
      snprintf(buf, sizeof buf, "%s: segment %d's scaled quintic within the limits", what, k + 1);
      tu_check(worst_q <= 1 + 1e-12, buf, worst_q - 1, 1e-12);
      snprintf(buf, sizeof buf, "%s: segment %d's scaled quintic 1e-8 faster exceeds them", what, k + 1);
      tu_check(faster > 1, buf, faster - 1, 0);
    }
    snprintf(buf, sizeof buf, "%s: time-optimal %.6g s below the scaled quintic's %.6g s", what,
             tp.duration, dur[0] + dur[1]);
    tu_check(tp.duration < dur[0] + dur[1], buf, tp.duration, dur[0] + dur[1]);
    printf("%s: time-optimal %.6g s, scaled quintic %.6g s, active %.4f, %d passes\n", what,
           tp.duration, dur[0] + dur[1], tp.active_fraction, tp.iterations);
  }
  prru_topp_free(&tp);
  free(d);
}

static void limits_for(prru_limits *lim, double fmax_, double vmax)
{
  prru_limits_none(lim);
  for (int i = 0; i < PRRU_NACT; i++) lim->force_max[i] = fmax_, lim->speed_max[i] = vmax;
}

static void expect_fail(const prru_model *m, const double *q, int n, const prru_limits *lim,
                        int grid, const char *const *parts, const char *what)
{
  prru_topp tp;
  char msg[600] = "", buf[800];
  int st = prru_topp_solve(&tp, m, n, q, lim, grid, msg, sizeof msg);
  int ok = st == PRRU_EINPUT && tp.x == NULL && tp.nseg == 0;
  for (const char *const *p = parts; *p; p++) ok = ok && strstr(msg, *p);
  snprintf(buf, sizeof buf, "%s refused (status %d: %s)", what, st, msg);
  TU_TRUE(ok, buf);
  prru_topp_free(&tp);
}

static void refusals(const prru_model *m, double load)
{
  prru_limits lim;
  /* Below the static load at the start (gravity): the first grid point. */
  limits_for(&lim, 0.5 * load, INFINITY);
  prru_data d;
  double z[3] = {0, 0, 0}, f[PRRU_NACT];
  prru_limits_ratio(m, &d, &lim, WP, z, z, f, NULL, NULL, NULL, NULL);
  double f0 = 0;
  for (int i = 0; i < PRRU_NACT; i++) f0 = fmax(f0, fabs(f[i]));
  limits_for(&lim, 0.5 * f0, INFINITY);
  const char *rest[] = {"segment 1 (waypoint 1 to 2), s = 0 (grid point 0 of 400)", "at rest",
                        "force_max of actuator", NULL};
  expect_fail(m, WP, 3, &lim, 0, rest, "force_max below the static load");
  /* A stroke that the second waypoint leaves: named by slider and point. */
  limits_for(&lim, 3 * load, INFINITY);
  prru_actuators(m, &d, WP, f);
  for (int i = 0; i < PRRU_NACT; i++) lim.d_min[i] = f[i] - 1e-9, lim.d_max[i] = f[i] + 1e-9;
  const char *stroke[] = {"segment 1 (waypoint 1 to 2), s = 0.0025 (grid point 1 of 400)",
                          "outside its stroke", NULL};
  expect_fail(m, WP, 3, &lim, 0, stroke, "a stroke the path leaves");
  limits_for(&lim, INFINITY, 1.0);
  const char *noforce[] = {"force limit", NULL};
  expect_fail(m, WP, 3, &lim, 0, noforce, "speed limits alone");
  limits_for(&lim, 3 * load, INFINITY);
  const double same[6] = {0, 0, 0, 0, 0, 0};
  const char *coincide[] = {"waypoints 1 and 2 coincide", NULL};
  expect_fail(m, same, 2, &lim, 0, coincide, "a segment of length 0");
  const char *grid[] = {"grid", NULL};
  expect_fail(m, WP, 3, &lim, 1, grid, "a grid of 1 interval");
  lim.force_max[0] = -1;
  const char *neg[] = {"actuator 1", NULL};
  expect_fail(m, WP, 3, &lim, 0, neg, "a negative force limit");
}

int main(void)
{
  prru_model m;
  prru_model_default(&m);
  prru_data d;
  const double load = static_load(&m, &d);
  prru_limits lim;
  /* Force limits a few times the static load (reached at an acceleration
   * of a few g), then with slider speed limits as well. */
  limits_for(&lim, 2.5 * load, INFINITY);
  optimal(&m, &lim, "built model, force limits");
  limits_for(&lim, 2.5 * load, 0.05);
  optimal(&m, &lim, "built model, force and speed limits");
  refusals(&m, load);
#if PRRU_NACT == 3
  const char *src = getenv("PRRU_SOURCE_DIR");
  char path[4096], msg[600];
  snprintf(path, sizeof path, "%s/models/prototype_example.json", src ? src : ".");
  prru_model proto;
  int st = prru_model_load(&proto, path, msg, sizeof msg);
  if (TU_TRUE(st == PRRU_OK, "prototype model loads")) {
    const double pload = static_load(&proto, &d);
    /* Its drives' friction (3 N) and damping matter at these forces. */
    limits_for(&lim, 2.5 * pload, INFINITY);
    optimal(&proto, &lim, "prototype, force limits");
    limits_for(&lim, 2.5 * pload, 0.1);
    optimal(&proto, &lim, "prototype, force and speed limits");
    /* Limits 5 % above the static load, which friction (3 N) nearly eats:
     * a slow crawl, where the drives' linearisation converged too slowly
     * for 60 passes before tangents took over from secants. */
    limits_for(&lim, 1.05 * pload, INFINITY);
    optimal(&proto, &lim, "prototype, force limits near the static load");
    prru_model_free(&proto);
  }
#endif
  return tu_finish("test_topp");
}
