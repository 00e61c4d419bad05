/* prru traj (quintic point-to-point trajectories) and prru track
 * (computed-torque or LQR tracking simulated in closed loop). */
#define _XOPEN_SOURCE 700 /* realpath, open_memstream */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"
#include "plot.h"
#include "prru.h"
#include "prru_control.h"
#include "prru_traj.h"

#define MAX_WAYPOINTS 1000

/* Up to max comma-separated numbers (multiples of pi allowed) into out;
 * *n the count. 0, or 2 after a message naming the option. */
static int parse_number_list(const char *cmd, const char *name, const char *text, double *out,
                             int max, int *n)
{
  *n = 0;
  const char *p = text;
  for (;;) {
    const char *end = strchr(p, ',');
    size_t len = end ? (size_t)(end - p) : strlen(p);
    char tok[128];
    if (*n >= max) {
      prru_cli_error(cmd, "--%s: more than %d numbers", name, max);
      return 2;
    }
    if (len == 0 || len >= sizeof tok) {
      prru_cli_error(cmd, "--%s: '%s': item %d is %s", name, text, *n + 1,
                     len == 0 ? "empty" : "too long");
      return 2;
    }
    memcpy(tok, p, len);
    tok[len] = '\0';
    if (prru_parse_value(tok, &out[*n]) != PRRU_OK) {
      prru_cli_error(cmd, "--%s: item %d, '%s', is not a finite number (decimal, or a multiple "
                     "of pi such as -pi/6)", name, *n + 1, tok);
      return 2;
    }
    (*n)++;
    if (!end) return 0;
    p = end + 1;
  }
}

/* Waypoints "q1,q2,q3;q1,q2,q3;..." into q (n x 3). 0 or 2. */
static int parse_waypoints(const char *cmd, const char *text, double *q, int *n)
{
  *n = 0;
  const char *p = text;
  for (;;) {
    const char *end = strchr(p, ';');
    size_t len = end ? (size_t)(end - p) : strlen(p);
    char tok[400];
    if (*n >= MAX_WAYPOINTS) {
      prru_cli_error(cmd, "--waypoints: more than %d waypoints", MAX_WAYPOINTS);
      return 2;
    }
    if (len >= sizeof tok) {
      prru_cli_error(cmd, "--waypoints: waypoint %d is too long", *n + 1);
      return 2;
    }
    memcpy(tok, p, len);
    tok[len] = '\0';
    if (prru_parse_values(tok, q + 3 * *n, 3) != PRRU_OK) {
      prru_cli_error(cmd, "--waypoints: waypoint %d, '%s', is not 3 comma-separated finite "
                     "numbers q1,q2,q3 (waypoints are separated by ';')", *n + 1, tok);
      return 2;
    }
    (*n)++;
    if (!end) return 0;
    p = end + 1;
  }
}

/* The reference from --waypoints and --durations. 0, or 2 after a message. */
static int waypoint_reference(const char *cmd, const char *wps, const char *durs,
                              prru_quintic *tr)
{
  static double q[3 * MAX_WAYPOINTS], dur[MAX_WAYPOINTS];
  int n, nd;
  if (!durs) {
    prru_cli_error(cmd, "--waypoints needs --durations (one per segment, s)");
    return 2;
  }
  if (parse_waypoints(cmd, wps, q, &n) || parse_number_list(cmd, "durations", durs, dur, MAX_WAYPOINTS, &nd))
    return 2;
  if (n < 2) {
    prru_cli_error(cmd, "--waypoints: %d waypoint given, at least 2 needed", n);
    return 2;
  }
  if (nd != n - 1) {
    prru_cli_error(cmd, "--durations: %d given for %d waypoints, need %d (one per segment)", nd, n,
                   n - 1);
    return 2;
  }
  char msg[300];
  if (prru_quintic_waypoints(tr, n, q, dur, 0.0, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error(cmd, "--waypoints/--durations: %s", msg);
    return 2;
  }
  return 0;
}

/* Where a pose is not usable: "unreachable" or "J_d singular (...)". */
static const char *pose_problem(int st)
{
  return st == PRRU_EUNREACHABLE ? "outside the workspace (unreachable)"
         : st == PRRU_ESINGULAR  ? "at a singularity (J_d singular)"
                                 : prru_strerror(st);
}

/* ---- prru traj --time-optimal ---- */

static const char topp_help[] =
    "usage: prru traj --time-optimal --waypoints 'q1,q2,q3;q1,q2,q3;...'\n"
    "                 [--force-max F|F1,..] [--speed-max V|V1,..]\n"
    "                 [--stroke LO,HI|LO1,HI1,..] [--no-limits] [--grid N]\n"
    "                 [--dt S|grid] [--units rail|motor] [--out FILE.csv|-]\n"
    "The fastest motion along the same path as the quintic trajectory (straight\n"
    "lines in q, at rest at every waypoint) within the drives' limits: each\n"
    "rail force |fd_i| <= --force-max (N; --fmax and --fd-max are the same\n"
    "option), each slider speed |dd_i| <= --speed-max (m/s), each slider within\n"
    "--stroke (m); one value for every actuator or one each. The forces are\n"
    "the model's inverse dynamics without platform loads, drives included.\n%s"
    "The model file's limits (spec 13: force_max or torque_max, speed_max or\n"
    "motor_speed_max, stroke) act unless --no-limits; each option replaces\n"
    "its kind. At least one force limit is needed (speed limits alone leave\n"
    "the accelerations unbounded).\n"
    "Method: reachability analysis on a grid of N intervals per segment\n"
    "(default 400), constant path acceleration on each, every interval\n"
    "checked with the exact inverse dynamics at 9 points (more through the\n"
    "ramp of the drives' Coulomb friction, each force near its limit\n"
    "maximised between them) and tightened where a limit is exceeded by\n"
    "more than 1e-9 of it. Writes the model line,\n"
    "summary lines (duration; share of the grid intervals on which a limit is\n"
    "active; the fastest uniformly time-scaled quintic under the same limits,\n"
    "checked at 2001 points per segment; peak forces and speeds against their\n"
    "limits) and the columns\n"
    "  t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,\n"
    "  %s,%s,%s\n"
    "(with --units motor also the motor torques tau1.. in N m, and the\n"
    "currents i1.. in A where the model gives torque_constant)\n"
    "every dt (default 1 ms; the last row at the end) or, with --dt grid, at\n"
    "the grid points; every row is checked again (a limit exceeded by more\n"
    "than 1e-6 of it is an error, exit 1). Limits that the path cannot meet\n"
    "(a pose outside the stroke or the workspace, a static load above\n"
    "--force-max) stop with a message naming the first such grid point\n"
    "(segment, s, limit) and exit 1, nothing written. Bad options exit 2.\n";

typedef struct {
  const char *force[3]; /* --force-max, --fmax, --fd-max */
  const char *speed, *stroke;
  int none;
} topp_limit_args;

/* The run's limits: the model file's (spec 13) unless --no-limits, each
 * kind given as an option replacing the model's (prru_cli_limits, shared
 * with excite, optimize and track); --fmax and --fd-max are older names of
 * --force-max. *forces, *speeds: how many actuators have such a limit.
 * 0 or 2. */
static int topp_limits(const topp_limit_args *a, prru_limits *lim, int *forces, int *speeds)
{
  if (a->force[1] && a->force[2]) {
    prru_cli_error("traj", "--fmax and --fd-max are the same limit: give one");
    return 2;
  }
  const int alias = a->force[1] ? 1 : 2;
  const prru_cli_limit_args la = {a->force[0], a->force[alias], a->speed, a->stroke, a->none};
  if (prru_cli_limits("traj", alias == 1 ? "fmax" : "fd-max", &la, lim)) return 2;
  *forces = *speeds = 0;
  for (int i = 0; i < prru_cli_model()->mech->nact; i++)
    *forces += isfinite(lim->force_max[i]), *speeds += isfinite(lim->speed_max[i]);
  return 0;
}

/* Peak |fd_i| and |dd_i| over the rows (each row checked again by
 * prru_topp_row). */
typedef struct {
  double f[PRRU_MAX_ACT], v[PRRU_MAX_ACT];
} topp_peaks;

/* The row times: every dt from 0 and the end, or (dt = 0) the grid's
 * distinct times. */
static long topp_nrows(const prru_topp *tp, double dt)
{
  if (dt > 0) return prru_row_count(0.0, tp->duration, dt);
  return (long)tp->nseg * tp->grid + 1;
}

static double topp_time(const prru_topp *tp, double dt, long k, long n)
{
  if (dt > 0) return prru_row_time(0.0, tp->duration, dt, k, n);
  const long N = tp->grid;
  if (k == n - 1) return tp->duration;
  return tp->t[(k / N) * (N + 1) + k % N];
}

/* The rows (out NULL: only the check and the peaks). */
static int topp_rows(prru_cli_out *o, const prru_model *m, const prru_limits *lim,
                     const prru_topp *tp, double dt, const int units[2], topp_peaks *pk, char *why,
                     size_t whylen)
{
  prru_data *d = malloc(sizeof *d);
  if (!d) {
    snprintf(why, whylen, "out of memory");
    return PRRU_ENOMEM;
  }
  memset(pk, 0, sizeof *pk);
  const long n = topp_nrows(tp, dt);
  int st = PRRU_OK;
  for (long k = 0; k < n && st == PRRU_OK && !(o && o->err); k++) {
    double q[3], qd[3], qdd[3], fd[PRRU_MAX_ACT], dd[PRRU_MAX_ACT];
    const double t = topp_time(tp, dt, k, n);
    if (prru_cli_interrupted) {
      st = PRRU_EINTERRUPTED;
      snprintf(why, whylen, "interrupted (%s) before row %ld", prru_cli_signal_name(), k + 1);
      break;
    }
    st = prru_topp_row(m, d, lim, tp, t, q, qd, qdd, fd, dd, why, (int)whylen);
    if (st != PRRU_OK) continue;
    for (int i = 0; i < m->mech->nact; i++) pk->f[i] = fmax(pk->f[i], fabs(fd[i])), pk->v[i] = fmax(pk->v[i], fabs(dd[i]));
    if (!o) continue;
    prru_cli_out_printf(o, "%.17g", t);
    prru_cli_out_numbers(o, q, 3);
    prru_cli_out_numbers(o, qd, 3);
    prru_cli_out_numbers(o, qdd, 3);
    prru_cli_out_numbers(o, d->d, m->mech->nact);
    prru_cli_out_numbers(o, dd, m->mech->nact);
    prru_cli_out_numbers(o, fd, m->mech->nact);
    prru_cli_out_motor(o, m, fd, units[0], units[1]);
    prru_cli_out_printf(o, "\n");
    prru_cli_out_row(o);
  }
  free(d);
  return st;
}

/* "a,b,c" of n numbers to %.6g ("inf" for none). */
static const char *list6(char *buf, size_t len, const double *v, int n)
{
  size_t k = 0;
  buf[0] = '\0';
  for (int i = 0; i < n && k < len; i++)
    k += (size_t)snprintf(buf + k, len - k, isnan(v[i]) ? "%s-" : "%s%.6g", i ? "," : "", v[i]);
  return buf;
}

static void topp_summary(prru_cli_out *o, const prru_topp *tp, const prru_limits *lim,
                         const double *qdur, const topp_peaks *pk, FILE *err)
{
  const int nact = prru_cli_model()->mech->nact;
  char a[400], b[400];
  double qsum = 0, rf[PRRU_MAX_ACT], rv[PRRU_MAX_ACT];
  for (int k = 0; k < tp->nseg; k++) qsum += qdur[k];
  for (int i = 0; i < nact; i++)
    rf[i] = isfinite(lim->force_max[i]) ? pk->f[i] / lim->force_max[i] : NAN,
    rv[i] = isfinite(lim->speed_max[i]) ? pk->v[i] / lim->speed_max[i] : NAN;
  char lines[5][900];
  snprintf(lines[0], sizeof lines[0], "time-optimal (reachability analysis): %d waypoints, "
           "%.9g s; %d grid intervals per segment, a limit active on %.2f%% of them",
           tp->nseg + 1, tp->duration, tp->grid, 100 * tp->active_fraction);
  snprintf(lines[1], sizeof lines[1], "fastest uniformly time-scaled quintic within the same "
           "limits: %.9g s (%.3gx the time-optimal)", qsum, qsum / tp->duration);
  snprintf(lines[2], sizeof lines[2], "limits: force_max (N) %s; speed_max (m/s) %s",
           list6(a, sizeof a, lim->force_max, nact), list6(b, sizeof b, lim->speed_max, nact));
  snprintf(lines[3], sizeof lines[3], "peak |fd| (N) %s, of force_max %s%s",
           list6(a, sizeof a, pk->f, nact), list6(b, sizeof b, rf, nact),
           strchr(b, '-') ? " (- no limit)" : "");
  snprintf(lines[4], sizeof lines[4], "peak |dd| (m/s) %s, of speed_max %s%s",
           list6(a, sizeof a, pk->v, nact), list6(b, sizeof b, rv, nact),
           strchr(b, '-') ? " (- no limit)" : "");
  for (int k = 0; k < 5; k++) {
    prru_cli_out_comment_line(o, "%s", lines[k]);
    if (err) fprintf(err, "prru traj: %s\n", lines[k]);
  }
}

typedef struct {
  const char *wps, *durs, *dts, *out, *grid, *units;
  topp_limit_args lim;
} topp_args;

/* The waypoints and the settings: 0, or 2 after a message. */
static int topp_settings(const topp_args *a, double *q, int *n, prru_limits *lim, int *grid,
                         double *dt)
{
  int forces, speeds;
  if (!a->wps) {
    prru_cli_error("traj", "--waypoints is required (see 'prru traj --help')");
    return 2;
  }
  if (a->durs) {
    prru_cli_error("traj", "--durations does not apply with --time-optimal (the limits set the "
                   "times)");
    return 2;
  }
  if (parse_waypoints("traj", a->wps, q, n)) return 2;
  if (*n < 2) {
    prru_cli_error("traj", "--waypoints: %d waypoint given, at least 2 needed", *n);
    return 2;
  }
  for (int k = 1; k < *n; k++)
    if (q[3 * k] == q[3 * k - 3] && q[3 * k + 1] == q[3 * k - 2] && q[3 * k + 2] == q[3 * k - 1]) {
      prru_cli_error("traj", "--waypoints: waypoints %d and %d coincide (a segment of length 0)", k,
                     k + 1);
      return 2;
    }
  if (topp_limits(&a->lim, lim, &forces, &speeds)) return 2;
  if (!forces) {
    if (speeds)
      prru_cli_error("traj", "--time-optimal: --speed-max alone leaves the accelerations "
                     "unbounded: give --force-max as well");
    else
      prru_cli_error("traj", "--time-optimal needs at least one force or speed limit, and neither "
                     "the options nor the model file give one: --force-max F (N), with or without "
                     "--speed-max V (m/s)");
    return 2;
  }
  double g = 0;
  if (a->grid && (prru_cli_number("traj", "grid", a->grid, &g) || !(g >= 2 && g <= 100000) ||
                  g != floor(g))) {
    prru_cli_error("traj", "--grid: '%s' is not a whole number of intervals from 2 to 100000",
                   a->grid);
    return 2;
  }
  *grid = (int)g;
  *dt = 1e-3;
  if (a->dts && strcmp(a->dts, "grid") == 0)
    *dt = 0;
  else if (a->dts && (prru_cli_number("traj", "dt", a->dts, dt) || !(*dt > 0))) {
    prru_cli_error("traj", "--dt: '%s' is not a positive time step (s) or 'grid'", a->dts);
    return 2;
  }
  return 0;
}

static int traj_time_optimal(const topp_args *a)
{
  static double q[3 * MAX_WAYPOINTS], qdur[MAX_WAYPOINTS];
  prru_limits lim;
  int n, grid;
  double dt;
  int units[2]; /* --units motor: torques, and currents where the model gives torque_constant */
  if (topp_settings(a, q, &n, &lim, &grid, &dt) || prru_cli_units("traj", a->units, &units[0], &units[1]))
    return 2;
  const prru_model *m = prru_cli_model();
  char msg[600], why[600] = "";
  prru_topp tp;
  prru_cli_catch_signals();
  int st = prru_topp_solve(&tp, m, n, q, &lim, grid, msg, sizeof msg);
  if (st == PRRU_OK) st = prru_quintic_fastest(m, n, q, &lim, 2000, qdur, msg, sizeof msg);
  if (st != PRRU_OK) {
    prru_topp_free(&tp);
    prru_cli_error("traj", "--time-optimal: %s; nothing written", msg);
    return 1;
  }
  if (dt > 0 && prru_row_count(0.0, tp.duration, dt) == 0) {
    prru_cli_error("traj", "--dt: %g s gives more than 1e8 rows over %g s", dt, tp.duration);
    prru_topp_free(&tp);
    return 2;
  }
  /* The rows twice: checked first (the summary needs their peaks), then
   * written. */
  topp_peaks pk;
  st = topp_rows(NULL, m, &lim, &tp, dt, units, &pk, why, sizeof why);
  if (st != PRRU_OK) {
    prru_topp_free(&tp);
    prru_cli_error("traj", "--time-optimal: %s; nothing written", why);
    return prru_cli_exit_for(st);
  }
  prru_cli_out o;
  if (prru_cli_out_open(&o, "traj", a->out)) {
    prru_topp_free(&tp);
    return 1;
  }
  char dn[256], ddn[256], fn[256];
  prru_cli_names(dn, sizeof dn, "d", m->mech->nact, ",");
  prru_cli_names(ddn, sizeof ddn, "dd", m->mech->nact, ",");
  prru_cli_names(fn, sizeof fn, "fd", m->mech->nact, ",");
  prru_cli_out_comment(&o);
  const int to_stdout = !a->out || strcmp(a->out, "-") == 0;
  topp_summary(&o, &tp, &lim, qdur, &pk, to_stdout ? NULL : stderr);
  prru_cli_out_printf(&o, "t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,%s,%s,%s", dn, ddn, fn);
  prru_cli_out_motor_names(&o, units[0], units[1]);
  prru_cli_out_printf(&o, "\n");
  prru_cli_out_line(&o);
  st = topp_rows(&o, m, &lim, &tp, dt, units, &pk, why, sizeof why);
  prru_topp_free(&tp);
  return prru_cli_out_finish(&o, st, why);
}

/* ---- prru traj ---- */

static const char traj_help[] =
    "usage: prru traj [--quintic] --waypoints 'q1,q2,q3;q1,q2,q3;...'\n"
    "                 --durations T1,T2,... [--dt S] [--out FILE.csv|-]\n"
    "A point-to-point trajectory: from each waypoint to the next in the given\n"
    "time, along the straight line in q with the quintic time law\n"
    "s = 10 u^3 - 15 u^4 + 6 u^5 (u the fraction of the segment's time), which\n"
    "starts and ends every segment at rest (zero velocity and acceleration);\n"
    "the peak speed is 1.875 |dq| / T, the peak acceleration 5.77 |dq| / T^2.\n"
    "(--quintic names this profile; 'prru traj --time-optimal --help' tells of\n"
    "the fastest one within the drives' limits.) Angles may be written as\n"
    "multiples of pi (pi/12). Writes the model line, a line naming the\n"
    "waypoints, and the columns\n"
    "  t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,%s,%s\n"
    "(d the slider heights, dd their velocities) every dt (default 1 ms; the\n"
    "last row at the end). The file is a trajectory for 'prru id --traj' and\n"
    "'prru track --ref'. Every sample is checked: a pose outside the workspace\n"
    "or at a singularity (J_d singular to the model's tolerance), or, with three\n"
    "actuators, a sign change of det J_d since the previous sample (the path\n"
    "crossed a singularity in between), stops with a message naming the sample,\n"
    "its time, segment and pose, and exit 1; the rows before it are kept, none\n"
    "holds NaN. Bad options exit 2 with nothing written; --out FILE is built as\n"
    "FILE.partial-XXXXXX and renamed.\n";

static int traj_rows(prru_cli_out *o, const prru_quintic *tr, double dt, char *why, size_t whylen)
{
  prru_model m = *prru_cli_model();
  prru_data *d = malloc(sizeof *d);
  if (!d) {
    snprintf(why, whylen, "out of memory");
    return PRRU_ENOMEM;
  }
  const double t0 = prru_quintic_t_begin(tr), t1 = prru_quintic_t_end(tr);
  /* The rows t0 + k dt and t1 (prru_row_count, checked by the caller). */
  const long n = prru_row_count(t0, t1, dt) - 1;
  int st = PRRU_OK, crossed;
  prru_path_side side;
  prru_path_side_init(&side);
  double t_prev = t0;
  for (long k = 0; k <= n && !o->err; k++) {
    double t = prru_row_time(t0, t1, dt, k, n + 1), q[3], qd[3], qdd[3], dd[PRRU_MAX_ACT],
           ddb[PRRU_MAX_ACT], rc;
    if (prru_cli_interrupted) {
      st = PRRU_EINTERRUPTED;
      snprintf(why, whylen, "interrupted (%s) before sample %ld", prru_cli_signal_name(), k + 1);
      break;
    }
    prru_quintic_eval(tr, t, q, qd, qdd);
    st = prru_path_sample(&side, &m, d, q, &rc, &crossed);
    if (st != PRRU_OK) {
      int seg = 0;
      while (seg + 2 < tr->n && tr->t[seg + 1] <= t) seg++;
      if (crossed) {
        snprintf(why, whylen, "sample %ld (t = %.9g s, segment %d: waypoint %d to %d): the path "
                 "crosses a singularity (J_d singular) after t = %.9g s: det J_d changes sign "
                 "at q = (%.9g, %.9g, %.9g)", k + 1, t, seg + 1, seg + 1, seg + 2, t_prev, q[0],
                 q[1], q[2]);
      } else {
        snprintf(why, whylen, "sample %ld (t = %.9g s, segment %d: waypoint %d to %d): q = (%.9g, "
                 "%.9g, %.9g) is %s", k + 1, t, seg + 1, seg + 1, seg + 2, q[0], q[1], q[2],
                 pose_problem(st));
      }
      break;
    }
    t_prev = t;
    prru_model_actuator_rates(&m, q, qd, dd, ddb);
    prru_cli_out_motion_row(o, t, q, qd, qdd, d->d, dd);
  }
  free(d);
  return st;
}

int prru_cmd_traj(int argc, char **argv)
{
  const char *wps = NULL, *durs = NULL, *dts = NULL, *out = NULL;
  int help = 0, quintic = 0, topp = 0;
  topp_args ta = {NULL, NULL, NULL, NULL, NULL, NULL, {{NULL, NULL, NULL}, NULL, NULL, 0}};
  prru_cli_option opts[] = {{"quintic", 0, NULL, &quintic},
                            {"waypoints", 1, &wps, NULL},
                            {"durations", 1, &durs, NULL},
                            {"dt", 1, &dts, NULL},
                            {"out", 1, &out, NULL},
                            {"help", 0, NULL, &help},
                            {"time-optimal", 0, NULL, &topp},
                            {"force-max", 1, &ta.lim.force[0], NULL},
                            {"fmax", 1, &ta.lim.force[1], NULL},
                            {"fd-max", 1, &ta.lim.force[2], NULL},
                            {"speed-max", 1, &ta.lim.speed, NULL},
                            {"stroke", 1, &ta.lim.stroke, NULL},
                            {"no-limits", 0, NULL, &ta.lim.none},
                            {"grid", 1, &ta.grid, NULL},
                            {"units", 1, &ta.units, NULL}};
  if (prru_cli_parse("traj", argc, argv, opts, (int)(sizeof opts / sizeof *opts))) return 2;
  const int nact = prru_cli_model()->mech->nact;
  char dn[256], ddn[256], fn[256];
  prru_cli_names(dn, sizeof dn, "d", nact, ",");
  prru_cli_names(ddn, sizeof ddn, "dd", nact, ",");
  prru_cli_names(fn, sizeof fn, "fd", nact, ",");
  if (help && topp) {
    printf(topp_help,
           nact > 3 ? "With redundant actuators, the forces of least norm (no internal preload).\n"
                         : "",
           dn, ddn, fn);
    return 0;
  }
  if (help) {
    printf(traj_help, dn, ddn);
    return 0;
  }
  if (topp && quintic) {
    prru_cli_error("traj", "--quintic and --time-optimal are two profiles: give one");
    return 2;
  }
  if (topp) {
    ta.wps = wps, ta.durs = durs, ta.dts = dts, ta.out = out;
    return traj_time_optimal(&ta);
  }
  if (ta.lim.force[0] || ta.lim.force[1] || ta.lim.force[2] || ta.lim.speed || ta.lim.stroke ||
      ta.lim.none || ta.grid || ta.units) {
    prru_cli_error("traj", "the limits, --grid and --units apply only with --time-optimal");
    return 2;
  }
  if (!wps) {
    prru_cli_error("traj", "--waypoints is required (see 'prru traj --help')");
    return 2;
  }
  double dt = 1e-3;
  if (dts && prru_cli_number("traj", "dt", dts, &dt)) return 2;
  if (!(dt > 0)) {
    prru_cli_error("traj", "--dt: %g is not a positive time step (s)", dt);
    return 2;
  }
  prru_quintic tr;
  if (waypoint_reference("traj", wps, durs, &tr)) return 2;
  double span = prru_quintic_t_end(&tr) - prru_quintic_t_begin(&tr);
  if (prru_row_count(prru_quintic_t_begin(&tr), prru_quintic_t_end(&tr), dt) == 0) {
    prru_cli_error("traj", "--dt: %g s gives more than 1e8 samples over %g s", dt, span);
    prru_quintic_free(&tr);
    return 2;
  }
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, "traj", out)) {
    prru_quintic_free(&tr);
    return 1;
  }
  prru_cli_out_comment(&o);
  prru_cli_out_printf(&o, "# quintic point-to-point: %d waypoints, %.17g s\n", tr.n, span);
  prru_cli_out_line(&o);
  prru_cli_out_printf(&o, "t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,%s,%s\n", dn, ddn);
  prru_cli_out_line(&o);
  char why[600] = "";
  int st = traj_rows(&o, &tr, dt, why, sizeof why);
  prru_quintic_free(&tr);
  return prru_cli_out_finish(&o, st, why);
}

/* ---- prru track ---- */

static const char track_help[] =
    "usage: prru track (--ref FILE.csv | --waypoints 'q;q;..' --durations T1,..)\n"
    "                  [--bandwidth W | --kp K1,K2,K3 --kd D1,D2,D3] [--period S]\n"
    "                  [--controller ct|lqr] [--lqr-q Q1,..,Q6] [--lqr-r %s]\n"
    "                  [--dt S] [--plant MODEL.json] [--mismatch KEY=F[,KEY=F..]]\n"
    "                  [--noise SQ,SQD]\n"
    "                  [--seed N] [--force-max F|%s] [--speed-max V|..]\n"
    "                  [--stroke LO,HI|LO1,HI1,..] [--no-limits] [--units rail|motor]\n"
    "                  [--q0-offset E1,E2,E3] [--atol X] [--rtol X]\n"
    "                  [--out FILE.csv|-] [--summary FILE.json] [--plot FILE.png]\n"
    "Simulates the robot following a reference trajectory under computed-torque\n"
    "control: the model's inverse dynamics at the measured state with the\n"
    "commanded acceleration qdd_c = qdd_ref + Kd (qd_ref - qd) + Kp (q_ref - q),\n"
    "  fd = J_d^-T (M qdd_c + h - G - passive)%s,\n"
    "each force clipped to its limit (saturation). With the model exact and no\n"
    "saturation each error e = q_ref - q obeys e'' + Kd e' + Kp e = 0.\n"
    "Reference: --ref, a CSV with t, q1..3 and qd1..3, qdd1..3 (as 'prru traj'\n"
    "writes; interpolated by quintics matching q, qd, qdd at every row), or\n"
    "--waypoints and --durations as for 'prru traj'.\n"
    "Gains: --bandwidth W (rad/s, default 20) sets Kp = W^2, Kd = 2 W (critically\n"
    "damped); --kp and --kd set them per coordinate (1/s^2, 1/s).\n"
    "--controller lqr (needs --period > 0) replaces computed torque by a\n"
    "time-varying discrete LQR: at every control tick the model's inverse\n"
    "dynamics on the reference (the feed-forward u_ff) and its zero-order-hold\n"
    "linearisation there (A_k, B_k); gains K_k from the backward Riccati\n"
    "recursion along the whole reference (terminal cost Q), computed before the\n"
    "run; fd = u_ff - K_k (x - x_ref) with x = (q, qd), clipped as above.\n"
    "Weights: --lqr-q on q1..3 then qd1..3 (>= 0), --lqr-r per actuator\n"
    "(1/N^2, > 0); each left out or all 0: Bryson's rule matched to computed\n"
    "torque's default: R = 1/F^2 (F the feed-forward peak), Q = 1/e^2 with the\n"
    "errors e_q = a/20^2, e_qd = a/(sqrt(2) 20) where a = F |dqdd/dfd| is the\n"
    "acceleration that force scale gives each coordinate (the summary gives\n"
    "the weights used).\n";

/* The help's second half (one literal stays within C99's 4095 bytes). */
static const char track_help2[] =
    "Timing: --period 0 (default) evaluates the controller continuously, inside\n"
    "the integrator, with rows every --dt (default 1 ms); --period S > 0 is a\n"
    "digital controller that samples the state every S seconds and holds its\n"
    "forces until the next sample (zero-order hold), one row per sample.\n"
    "Plant: the same equations of motion with the controller's model's numbers\n"
    "(the built-in model, or --model's), or --plant's (a model file with as\n"
    "many limbs: the robot the controller does not know exactly), with\n"
    "--mismatch scaling them: mass (every body's mass and inertia), inertia,\n"
    "armature, damping, coulomb, gravity, e.g. --mismatch mass=1.1.\n"
    "--noise SQ,SQD: Gaussian sensor noise on q and qd (standard deviations,\n"
    "rad or m, and per s; needs --period > 0), from a generator seeded by\n"
    "--seed (default 1): the same seed gives the same run.\n"
    "Limits: the model file's drives (force_max or torque_max, speed_max or\n"
    "motor_speed_max, stroke) act unless --no-limits; --force-max (N, alias\n"
    "--fmax), --speed-max (m/s) and --stroke LO,HI (m), one value for every\n"
    "actuator or one each, replace that kind for this run; a line of the CSV\n"
    "and the summary say which were active. Forces are clipped to force_max;\n"
    "computed torque cannot hold a speed, so the summary reports the plant's\n"
    "largest slider speeds (max_dd) and the fraction of samples above\n"
    "speed_max (over_speed_fraction). The\n"
    "reference must stay inside the workspace, away from singularities (and\n"
    "not cross one: det J_d keeps its sign) and in the stroke, checked at\n"
    "every row and at least every millisecond (else exit 2, nothing written).\n"
    "A plant that leaves its stroke, checked at every integration step, stops\n"
    "the run (exit 1, rows kept), as does a controller meeting a singular pose.\n"
    "--q0-offset E starts the plant at q_ref(0) - E (an initial error);\n"
    "--atol, --rtol: the integrator's tolerances (default 1e-12, at least\n"
    "2.2e-14).\n"
    "Output: the model line, a line with the settings, one with the limits,\n"
    "then\n"
    "  t,qr1,qr2,qr3,q1,q2,q3,e1,e2,e3,qd1,qd2,qd3,\n"
    "  %s,%s,\n"
    "  %s,%s,qdd1,qdd2,qdd3\n"
    "and with --units motor the motor torques tau1.. (N m; the model's lead\n"
    "and gear) and, where it gives torque_constant, the currents i1.. (A)\n"
    "(qr the reference, fdc the controller's forces before clipping, sat 1 where\n"
    "clipped, d the slider heights, qdd the plant's accelerations under fd:\n"
    "with q, qd and fd, exact identification data) to --out or stdout; a JSON\n"
    "summary (RMS and largest error per coordinate, largest force and saturated\n"
    "fraction of the samples per actuator, the feed-forward force peak along the\n"
    "reference) to --summary, else to stdout, or stderr when the CSV goes to\n"
    "stdout. --plot\n"
    "FILE.png draws the errors and forces (needs --out FILE and gnuplot).\n"
    "SIGINT/SIGTERM/SIGHUP stop with exit 130/143/129, the rows kept.\n";

typedef struct {
  prru_cli_out *out;
  const prru_model *m;
  int motor, current;                 /* --units motor columns */
} track_output;

static int track_row(const prru_track_sample *s, void *ctx)
{
  track_output *to = ctx;
  prru_cli_out *o = to->out;
  const int nact = to->m->mech->nact;
  prru_cli_out_printf(o, "%.17g", s->t);
  prru_cli_out_numbers(o, s->q_ref, 3);
  prru_cli_out_numbers(o, s->q, 3);
  prru_cli_out_numbers(o, s->e, 3);
  prru_cli_out_numbers(o, s->qd, 3);
  prru_cli_out_numbers(o, s->fd, nact);
  prru_cli_out_numbers(o, s->fd_cmd, nact);
  for (int i = 0; i < nact; i++) prru_cli_out_printf(o, ",%d", s->saturated[i]);
  prru_cli_out_numbers(o, s->d, nact);
  prru_cli_out_numbers(o, s->qdd, 3);
  prru_cli_out_motor(o, to->m, s->fd, to->motor, to->current);
  prru_cli_out_printf(o, "\n");
  return prru_cli_out_row(o) == 0 ? PRRU_OK : PRRU_EIO;
}

/* --mismatch KEY=F[,KEY=F..] applied to p; text kept for the settings. */
static int parse_mismatch(const char *text, prru_params *p)
{
  const char *s = text;
  for (;;) {
    const char *end = strchr(s, ',');
    size_t len = end ? (size_t)(end - s) : strlen(s);
    char tok[128];
    const char *eq = memchr(s, '=', len);
    if (!eq || len >= sizeof tok) {
      prru_cli_error("track", "--mismatch: '%.*s' is not KEY=FACTOR (keys: mass, inertia, "
                     "armature, damping, coulomb, gravity)", (int)len, s);
      return 2;
    }
    memcpy(tok, s, len);
    tok[len] = '\0';
    tok[eq - s] = '\0';
    double f;
    if (prru_parse_double(tok + (eq - s) + 1, &f) != PRRU_OK || !(f > 0)) {
      prru_cli_error("track", "--mismatch %s: factor '%s' is not a number > 0", tok,
                     tok + (eq - s) + 1);
      return 2;
    }
    if (prru_params_scale(p, tok, f) != PRRU_OK) {
      prru_cli_error("track", "--mismatch: unknown key '%s' (keys: mass, inertia, armature, "
                     "damping, coulomb, gravity)", tok);
      return 2;
    }
    if (!end) return 0;
    s = end + 1;
  }
}

/* The reference from --ref (t, q, qd, qdd columns). 0 or 2. */
static int csv_reference(const char *path, prru_quintic *tr)
{
  static const char *const need[10] = {"t", "q1", "q2", "q3", "qd1", "qd2", "qd3", "qdd1", "qdd2", "qdd3"};
  char msg[600];
  prru_table t;
  if (prru_table_read(&t, path, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error("track", "--ref %s", msg);
    return 2;
  }
  int col[10];
  for (int k = 0; k < 10; k++)
    if ((col[k] = prru_table_column(&t, need[k])) < 0) {
      prru_cli_error("track", "--ref %s: missing column '%s' (need t, q1..3, qd1..3, qdd1..3, "
                     "as 'prru traj' writes)", path, need[k]);
      prru_table_free(&t);
      return 2;
    }
  double *v = malloc((size_t)(t.nrows > 0 ? t.nrows : 1) * 10 * sizeof *v);
  if (!v) {
    prru_table_free(&t);
    prru_cli_error("track", "out of memory");
    return 1;
  }
  int n = t.nrows;
  double *tt = v, *q = v + n, *qd = v + 4 * n, *qdd = v + 7 * n;
  for (int i = 0; i < n; i++) {
    const double *row = t.data + (size_t)i * (size_t)t.ncols;
    tt[i] = row[col[0]];
    for (int c = 0; c < 3; c++) {
      q[3 * i + c] = row[col[1 + c]];
      qd[3 * i + c] = row[col[4 + c]];
      qdd[3 * i + c] = row[col[7 + c]];
    }
  }
  prru_table_free(&t);
  int st = prru_quintic_samples(tr, n, tt, q, qd, qdd, msg, sizeof msg);
  free(v);
  if (st != PRRU_OK) {
    prru_cli_error("track", "--ref %s: %s", path, msg);
    return 2;
  }
  return 0;
}

static void json_summary(FILE *f, const prru_track_summary *s, const prru_track_options *o,
                         const char *plant, const char *mismatch, double ff_peak, const char *status,
                         const char *limits)
{
  const int nact = prru_cli_model()->mech->nact;
  fputc('{', f);
  prru_cli_json_model(f);
  fprintf(f, ",\n \"control\": \"%s\", \"period\": ", o->control_period > 0 ? "zero-order hold" : "continuous");
  prru_cli_json_number(f, o->control_period);
  /* Each controller's own gains: the LQR's feedback comes from its
   * weights, kp and kd are not used. */
  if (o->controller == PRRU_TRACK_LQR) {
    fputs(",\n \"controller\": \"lqr\", \"lqr_q\": ", f);
    prru_cli_json_array(f, o->lqr_q, 6);
    fputs(", \"lqr_r\": ", f);
    prru_cli_json_array(f, o->lqr_r, nact);
  } else {
    fputs(",\n \"controller\": \"computed_torque\", \"kp\": ", f);
    prru_cli_json_array(f, o->kp, 3);
    fputs(", \"kd\": ", f);
    prru_cli_json_array(f, o->kd, 3);
  }
  fputs(",\n \"plant\": ", f);
  prru_cli_json_string(f, plant ? plant : "");
  fputs(", \"mismatch\": ", f);
  prru_cli_json_string(f, mismatch ? mismatch : "");
  fputs(", \"noise\": ", f);
  double nz[2] = {o->noise_q, o->noise_qd};
  prru_cli_json_array(f, nz, 2);
  fprintf(f, ", \"seed\": %lu,\n \"samples\": %ld, \"t_end\": ", o->seed, s->samples);
  prru_cli_json_number(f, s->t_end);
  fputs(", \"rms_error\": ", f);
  prru_cli_json_array(f, s->rms_e, 3);
  fputs(", \"max_error\": ", f);
  prru_cli_json_array(f, s->max_e, 3);
  fputs(",\n \"max_fd\": ", f);
  prru_cli_json_array(f, s->max_fd, nact);
  double frac[PRRU_MAX_ACT];
  for (int i = 0; i < nact; i++)
    frac[i] = s->samples ? (double)s->saturated[i] / (double)s->samples : 0.0;
  fputs(", \"saturated_fraction\": ", f);
  prru_cli_json_array(f, frac, nact);
  fputs(", \"any_saturated_fraction\": ", f);
  prru_cli_json_number(f, s->samples ? (double)s->any_saturated / (double)s->samples : 0.0);
  fputs(",\n \"limits\": ", f);
  prru_cli_json_string(f, limits);
  fputs(", \"max_dd\": ", f);
  prru_cli_json_array(f, s->max_dd, nact);
  fprintf(f, ", \"over_speed_fraction\": ");
  prru_cli_json_number(f, s->samples ? (double)s->over_speed / (double)s->samples : 0.0);
  fputs(",\n \"feedforward_peak\": ", f);
  prru_cli_json_number(f, ff_peak);
  fputs(", \"status\": ", f);
  prru_cli_json_string(f, status);
  fputs("}\n", f);
}

/* The summary to --summary (never half-written), else to stdout, or to
 * stderr when the CSV went to stdout. 0 or 1 after a message. */
static int write_summary(const char *sums, const char *out, const prru_track_summary *s,
                         const prru_track_options *o, const char *plant, const char *mismatch,
                         double ff_peak, const char *status, const char *limits)
{
  if (!sums) {
    json_summary((!out || strcmp(out, "-") == 0) ? stderr : stdout, s, o, plant, mismatch, ff_peak, status,
                 limits);
    return 0;
  }
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return 1;
  json_summary(g, s, o, plant, mismatch, ff_peak, status, limits);
  fclose(g);
  prru_cli_out so;
  int rc = prru_cli_out_open(&so, "track", sums);
  if (rc == 0) {
    prru_cli_out_write(&so, buf, len);
    prru_cli_out_line(&so);
    rc = prru_cli_out_close(&so, 1);
  }
  free(buf);
  return rc;
}

/* The tracking figure: errors, and applied forces with the limits. */
static int track_plot(const char *csv, const char *png, const prru_track_options *o)
{
  char abs_csv[PATH_MAX], dir[PRRU_PLOT_PATH], path[PRRU_PLOT_PATH + 32];
  if (!realpath(csv, abs_csv)) {
    prru_cli_error("track", "--plot: %s: cannot resolve the CSV's path", csv);
    return 1;
  }
  if (prru_plot_scratch("track", dir, sizeof dir)) return 1;
  char footer[1200];
  prru_plot_provenance(footer, sizeof footer, "track");
  char *buf = prru_plot_track_script(abs_csv, "track.png", prru_cli_model()->mech->name, footer,
                                     prru_cli_model()->mech->nact, o->f_max);
  int rc = buf ? prru_plot_run("track", dir, dir, "track.gp", buf) : 1;
  if (!buf) prru_cli_error("track", "--plot: out of memory");
  free(buf);
  if (rc == PRRU_PLOT_NO_GNUPLOT) {
    prru_cli_error("track", "--plot: gnuplot not found: install gnuplot-nox (e.g. with 'make deps')");
    rc = 1;
  }
  snprintf(path, sizeof path, "%s/track.png", dir);
  if (rc == 0) rc = prru_plot_deliver("track", path, png);
  unlink(path);
  snprintf(path, sizeof path, "%s/track.gp", dir);
  unlink(path);
  rmdir(dir);
  return rc;
}

/* Gains, timing, noise and tolerances into o, as numbers: their rules are
 * the library's (track_options_checked). 0 or 2. */
static int parse_track_settings(const char **a, prru_track_options *o)
{
  /* a: bandwidth kp kd period dt noise seed q0-offset atol rtol */
  double w, v[3];
  if (a[0] && prru_cli_number("track", "bandwidth", a[0], &w)) return 2;
  if (a[0] && prru_track_gains_bandwidth(w, o) != PRRU_OK) {
    prru_cli_error("track", "--bandwidth: %g is not > 0 with finite gains (rad/s)", w);
    return 2;
  }
  if (a[0] && (a[1] || a[2])) {
    prru_cli_error("track", "--bandwidth excludes --kp and --kd");
    return 2;
  }
  if (a[1] && prru_cli_numbers("track", "kp", a[1], o->kp, 3)) return 2;
  if (a[2] && prru_cli_numbers("track", "kd", a[2], o->kd, 3)) return 2;
  if (a[3] && prru_cli_number("track", "period", a[3], &o->control_period)) return 2;
  if (a[4] && prru_cli_number("track", "dt", a[4], &o->dt_out)) return 2;
  if (a[4] && o->control_period > 0) {
    prru_cli_error("track", "--dt: with --period > 0 there is one row per control period");
    return 2;
  }
  if (a[5]) {
    double nz[2];
    if (prru_cli_numbers("track", "noise", a[5], nz, 2)) return 2;
    o->noise_q = nz[0];
    o->noise_qd = nz[1];
  }
  if (a[6]) {
    double s;
    if (prru_cli_number("track", "seed", a[6], &s)) return 2;
    if (!(s >= 0 && s <= 4294967295.0 && s == floor(s))) {
      prru_cli_error("track", "--seed: '%s' is not a whole number from 0 to 4294967295", a[6]);
      return 2;
    }
    o->seed = (unsigned long)s;
  }
  if (a[7] && prru_cli_numbers("track", "q0-offset", a[7], v, 3)) return 2;
  if (a[7]) memcpy(o->q0_offset, v, sizeof v);
  if (a[8] && prru_cli_number("track", "atol", a[8], &o->abs_tol)) return 2;
  if (a[9] && prru_cli_number("track", "rtol", a[9], &o->rel_tol)) return 2;
  return 0;
}

/* --controller, --lqr-q, --lqr-r into o (after --period). 0 or 2. */
static int parse_controller(const char *ctl, const char *q, const char *r, prru_track_options *o)
{
  if (ctl && strcmp(ctl, "ct") != 0 && strcmp(ctl, "lqr") != 0) {
    prru_cli_error("track", "--controller: '%s' is neither ct (computed torque) nor lqr", ctl);
    return 2;
  }
  int lqr = ctl && strcmp(ctl, "lqr") == 0;
  if (!lqr && (q || r)) {
    prru_cli_error("track", "--%s belongs to --controller lqr", q ? "lqr-q" : "lqr-r");
    return 2;
  }
  if (!lqr) return 0;
  o->controller = PRRU_TRACK_LQR;
  if (q && prru_cli_numbers("track", "lqr-q", q, o->lqr_q, 6)) return 2;
  if (r && prru_cli_numbers("track", "lqr-r", r, o->lqr_r, prru_cli_model()->mech->nact)) return 2;
  return 0;
}

static int word_char(char c)
{
  return isalnum((unsigned char)c) || c == '_';
}

/* prru_track_options_check on the whole of o, its message in the flags'
 * words: the library names the options by its members. 0, or 2 after
 * the message. */
static int track_options_checked(const prru_track_options *o)
{
  static const char *const flag[][2] = {
      {"controller PRRU_TRACK_LQR", "--controller lqr"}, {"control period", "--period"},
      {"sensor noise", "--noise"}, {"dt_out", "--dt"}, {"kp", "--kp"}, {"kd", "--kd"},
      {"q0_offset", "--q0-offset"}, {"abs_tol", "--atol"}, {"rel_tol", "--rtol"},
      {"lqr_q", "--lqr-q"}, {"lqr_r", "--lqr-r"}};
  char msg[600], text[800];
  if (prru_track_options_check(prru_cli_model(), o, msg, sizeof msg) == PRRU_OK) return 0;
  const int nflag = (int)(sizeof flag / sizeof flag[0]);
  size_t n = 0;
  for (const char *p = msg; *p && n + 1 < sizeof text;) {
    int k = -1;
    for (int j = 0; j < nflag && k < 0 && (p == msg || !word_char(p[-1])); j++) {
      size_t len = strlen(flag[j][0]);
      if (strncmp(p, flag[j][0], len) == 0 && !word_char(p[len])) k = j;
    }
    if (k < 0) {
      text[n++] = *p++;
      continue;
    }
    int w = snprintf(text + n, sizeof text - n, "%s", flag[k][1]);
    n = w > 0 && (size_t)w < sizeof text - n ? n + (size_t)w : sizeof text - 1;
    p += strlen(flag[k][0]);
  }
  text[n] = '\0';
  prru_cli_error("track", "%s", text);
  return 2;
}

/* The weights of an LQR run that --lqr-q / --lqr-r left out: the
 * library's defaults, filled in so that the CSV and summary give them. 0,
 * or 1 after a message. */
static int lqr_default_weights(const prru_quintic *tr, prru_track_options *o)
{
  const size_t rsize = (size_t)prru_cli_model()->mech->nact * sizeof(double);
  double q[6], r[PRRU_MAX_ACT], zq[6] = {0}, zr[PRRU_MAX_ACT] = {0};
  int dq = memcmp(o->lqr_q, zq, sizeof zq) == 0, dr = memcmp(o->lqr_r, zr, rsize) == 0;
  if (!dq && !dr) return 0;
  char msg[600];
  int st = prru_lqr_default_weights(prru_cli_model(), tr, o->control_period, q, r, msg, sizeof msg);
  if (st != PRRU_OK) {
    prru_cli_error("track", "LQR default weights: %s", msg);
    return 1;
  }
  if (dq) memcpy(o->lqr_q, q, sizeof q);
  if (dr) memcpy(o->lqr_r, r, rsize);
  return 0;
}

static void lqr_weights_text(const prru_track_options *o, char *buf, size_t len)
{
  int n = snprintf(buf, len, "Q");
  for (int i = 0; i < 6 && n > 0 && (size_t)n < len; i++) n += snprintf(buf + n, len - (size_t)n, " %.6g", o->lqr_q[i]);
  if (n > 0 && (size_t)n < len) n += snprintf(buf + n, len - (size_t)n, ", R");
  for (int i = 0; i < prru_cli_model()->mech->nact && n > 0 && (size_t)n < len; i++)
    n += snprintf(buf + n, len - (size_t)n, " %.6g", o->lqr_r[i]);
}

/* The plant's numbers before --mismatch: the current model's (built in or
 * --model's), or the model file plant's (--plant). 0, or 2 after the
 * loader's message. */
static int plant_params(const char *plant, prru_params *p)
{
  if (!plant) {
    prru_model_params(prru_cli_model(), p);
    return 0;
  }
  prru_model pm;
  prru_model_default(&pm);
  char msg[1024];
  if (prru_model_load(&pm, plant, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error("track", "--plant: %s", msg);
    return 2;
  }
  /* The plant's numbers are read in the controller's topology. */
  if (pm.mech->nlimb != prru_cli_model()->mech->nlimb) {
    prru_cli_error("track", "--plant: %s: a model with %d limbs; the controller's model %s has %d", plant,
                   pm.mech->nlimb, prru_cli_model()->mech->name, prru_cli_model()->mech->nlimb);
    prru_model_free(&pm);
    return 2;
  }
  prru_model_params(&pm, p);
  prru_model_free(&pm);
  return 0;
}

int prru_cmd_track(int argc, char **argv)
{
  const char *refs = NULL, *wps = NULL, *durs = NULL, *mism = NULL, *units = NULL, *out = NULL, *sums = NULL,
             *plot = NULL, *plants = NULL;
  const char *a[10] = {NULL}, *ctl = NULL, *lqr_q = NULL, *lqr_r = NULL;
  int help = 0;
  prru_cli_limit_args lim = {NULL, NULL, NULL, NULL, 0};
  prru_cli_option opts[] = {
      {"ref", 1, &refs, NULL},        {"waypoints", 1, &wps, NULL},  {"durations", 1, &durs, NULL},
      {"bandwidth", 1, &a[0], NULL},  {"kp", 1, &a[1], NULL},        {"kd", 1, &a[2], NULL},
      {"period", 1, &a[3], NULL},     {"dt", 1, &a[4], NULL},        {"mismatch", 1, &mism, NULL},
      {"noise", 1, &a[5], NULL},      {"seed", 1, &a[6], NULL},      {"fmax", 1, &lim.alias, NULL},
      PRRU_CLI_LIMIT_OPTIONS(lim),    {"q0-offset", 1, &a[7], NULL}, {"atol", 1, &a[8], NULL},
      {"rtol", 1, &a[9], NULL},       {"out", 1, &out, NULL},        {"summary", 1, &sums, NULL},
      {"plot", 1, &plot, NULL},       {"plant", 1, &plants, NULL},   {"units", 1, &units, NULL},
      {"controller", 1, &ctl, NULL},  {"lqr-q", 1, &lqr_q, NULL},    {"lqr-r", 1, &lqr_r, NULL},
      {"help", 0, NULL, &help}};
  if (prru_cli_parse("track", argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  const int nact = prru_cli_model()->mech->nact;
  char fdn[256], fdcn[256], satn[256], dn[256];
  prru_cli_names(fdn, sizeof fdn, "fd", nact, ",");
  prru_cli_names(fdcn, sizeof fdcn, "fdc", nact, ",");
  prru_cli_names(satn, sizeof satn, "sat", nact, ",");
  prru_cli_names(dn, sizeof dn, "d", nact, ",");
  if (help) {
    char fl[256];
    char rl[256];
    printf(track_help, prru_cli_names(rl, sizeof rl, "R", nact, ","),
           prru_cli_names(fl, sizeof fl, "F", nact, ","),
           nact > 3 ? "\n  (J_d^+T, the least-norm forces, with redundant actuators)" : "");
    printf(track_help2, fdn, fdcn, satn, dn);
    return 0;
  }
  if (!refs == !wps) {
    prru_cli_error("track", "give the reference as --ref FILE or as --waypoints and --durations "
                   "(one of them; see 'prru track --help')");
    return 2;
  }
  if (refs && durs) {
    prru_cli_error("track", "--durations belongs to --waypoints, not --ref");
    return 2;
  }
  if (plot && (!out || strcmp(out, "-") == 0)) {
    prru_cli_error("track", "--plot needs --out FILE.csv (the figure is drawn from it)");
    return 2;
  }
  if (prru_cli_refuse_same_file("track", "ref", refs, "out", out) ||
      prru_cli_refuse_same_file("track", "ref", refs, "summary", sums) ||
      prru_cli_refuse_same_file("track", "ref", refs, "plot", plot))
    return 2;
  prru_track_options o;
  prru_track_options_default(prru_cli_model(), &o);
  if (plant_params(plants, &o.plant)) return 2;
  /* The drives' limits: the model file's unless overridden (spec 13). The
   * forces are clipped to force_max, the stroke ends the run like an end
   * stop; a speed cannot be held by computed torque, so the run reports
   * the plant's speeds against it (summary: max_dd, over_speed_fraction). */
  prru_limits limits;
  int motor, current;
  if (parse_track_settings(a, &o) || parse_controller(ctl, lqr_q, lqr_r, &o) ||
      prru_cli_limits("track", "fmax", &lim, &limits) || prru_cli_units("track", units, &motor, &current))
    return 2;
  for (int i = 0; i < nact; i++)
    o.f_max[i] = limits.force_max[i], o.speed_max[i] = limits.speed_max[i], o.d_min[i] = limits.d_min[i],
    o.d_max[i] = limits.d_max[i];
  if (track_options_checked(&o)) return 2;
  char limits_text[400];
  prru_limits_describe(prru_cli_model(), &limits, limits_text, sizeof limits_text);
  if (mism && parse_mismatch(mism, &o.plant)) return 2;
  prru_quintic tr;
  int rc = refs ? csv_reference(refs, &tr) : waypoint_reference("track", wps, durs, &tr);
  if (rc) return rc;
  double step = o.control_period > 0 ? o.control_period : o.dt_out, ff_peak;
  char msg[600];
  int st = prru_track_check_reference(prru_cli_model(), &tr, &o, step, &ff_peak, msg, sizeof msg);
  if (st != PRRU_OK) {
    prru_cli_error("track", st == PRRU_EINPUT ? "%s; nothing written" : "%s", msg);
    prru_quintic_free(&tr);
    return st == PRRU_EINPUT ? 2 : 1;
  }
  if (o.controller == PRRU_TRACK_LQR && lqr_default_weights(&tr, &o)) {
    prru_quintic_free(&tr);
    return 1;
  }
  prru_cli_catch_signals();
  prru_cli_out co;
  if (prru_cli_out_open(&co, "track", out)) {
    prru_quintic_free(&tr);
    return 1;
  }
  const char *name = co.name;
  prru_cli_out_comment(&co);
  /* The --plant path (any bytes) stays on the line: comment_line. */
  if (o.controller == PRRU_TRACK_LQR) {
    char gains[600];
    lqr_weights_text(&o, gains, sizeof gains);
    prru_cli_out_comment_line(&co, "LQR (time-varying, Riccati along the reference), zero-order hold every "
                              "%.9g s, %s, %s%s%smismatch '%s', noise %g %g, seed %lu", step, gains,
                              plants ? "plant " : "", plants ? plants : "", plants ? ", " : "",
                              mism ? mism : "", o.noise_q, o.noise_qd, o.seed);
  } else {
    prru_cli_out_comment_line(&co, "computed torque, %s%.9g s, kp %g %g %g, kd %g %g %g, %s%s%smismatch '%s', "
                              "noise %g %g, seed %lu",
                              o.control_period > 0 ? "zero-order hold every " : "continuous, rows every ",
                              step, o.kp[0], o.kp[1], o.kp[2], o.kd[0], o.kd[1], o.kd[2], plants ? "plant " : "",
                              plants ? plants : "", plants ? ", " : "", mism ? mism : "", o.noise_q, o.noise_qd,
                              o.seed);
  }
  prru_cli_out_comment_line(&co, "limits: %s", limits_text);
  prru_cli_out_printf(&co, "t,qr1,qr2,qr3,q1,q2,q3,e1,e2,e3,qd1,qd2,qd3,%s,%s,%s,%s,qdd1,qdd2,qdd3", fdn,
                      fdcn, satn, dn);
  prru_cli_out_motor_names(&co, motor, current);
  prru_cli_out_printf(&co, "\n");
  prru_cli_out_line(&co);
  prru_model m = *prru_cli_model();
  track_output to = {&co, &m, motor, current};
  o.on_sample = track_row;
  o.ctx = &to;
  o.interrupt = &prru_cli_interrupted;
  prru_track_summary sum;
  st = prru_track(&m, &tr, &o, &sum, msg, sizeof msg);
  prru_quintic_free(&tr);
  long rows = co.rows;
  int io = co.err != 0;
  if (prru_cli_out_close(&co, !io && rows > 0)) return 1;
  if (st != PRRU_OK) {
    if (st == PRRU_EINTERRUPTED && prru_cli_interrupted)
      prru_cli_error("track", "%s (%s); %ld rows written to %s", msg, prru_cli_signal_name(), rows, name);
    else
      prru_cli_error("track", "%s; %ld rows written to %s", msg, rows, name);
  }
  if (write_summary(sums, out, &sum, &o, plants, mism, ff_peak, st == PRRU_OK ? "complete" : msg, limits_text))
    return 1;
  if (st != PRRU_OK) return prru_cli_exit_for(st);
  if (plot) return track_plot(out, plot, &o);
  return 0;
}
