/* prru ik, fk and id: kinematics both ways and inverse dynamics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru.h"
#include "prru_traj.h"

static const char ik_help[] =
    "usage: prru ik --q q1,q2,q3\n"
    "Prints JSON with model (name, file, sha256, ...), q, the actuator displacements\n"
    "d (m, slider heights), J_d = dd/dq (a list of rows: one per actuator, one\n"
    "column per coordinate), its reciprocal condition number and whether J_d\n"
    "is singular there; with redundant actuators (more sliders than\n"
    "coordinates) also actuator_null, the unit n with J_d^T n = 0 and a\n"
    "positive last component (not at a singular pose).\n"
    "Exit 1 when q is unreachable.\n";

int prru_cmd_ik(int argc, char **argv)
{
  const char *qs = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("ik", argc, argv, opts, 2)) return 2;
  if (help) {
    fputs(ik_help, stdout);
    return 0;
  }
  double q[3];
  if (!qs) {
    prru_cli_error("ik", "--q is required (see 'prru ik --help')");
    return 2;
  }
  if (prru_cli_numbers("ik", "q", qs, q, 3)) return 2;
  prru_model m = *prru_cli_model();
  const int nact = m.mech->nact;
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  double rcond;
  int st = prru_check_regular(&m, d, q, &rcond);
  if (st != PRRU_OK && st != PRRU_ESINGULAR) {
    char qtext[128];
    prru_cli_error("ik", "q = %s: %s", prru_cli_vec(qtext, sizeof qtext, q, 3), prru_strerror(st));
    free(d);
    return 1;
  }
  putchar('{');
  prru_cli_json_model(stdout);
  printf(",\n \"q\": ");
  prru_cli_json_array(stdout, q, 3);
  printf(", \"d\": ");
  prru_cli_json_array(stdout, d->d, nact);
  printf(", \"Jd\": ");
  prru_cli_json_matrix(stdout, d->Jd, nact, 3);
  printf(", \"Jd_rcond\": ");
  prru_cli_json_number(stdout, rcond);
  printf(", \"singular\": %s", st == PRRU_ESINGULAR ? "true" : "false");
  /* Redundant actuation: n spans null(J_d^T) (regular poses only). */
  double n[PRRU_MAX_ACT];
  if (prru_cli_npreload(&m) > 0 && st == PRRU_OK && prru_actuator_null(&m, d, q, n) == PRRU_OK) {
    printf(", \"actuator_null\": ");
    prru_cli_json_array(stdout, n, nact);
  }
  printf("}\n");
  free(d);
  return ferror(stdout) ? 1 : 0;
}

/* %s: the --d names; %s: how fk solves (by the number of actuators). */
static const char fk_help[] =
    "usage: prru fk --d %s [--seed q1,q2,q3] [--lsq]\n"
    "Solves d(q) = d for q from the seed (default: q1 = q2 = 0 and the height\n"
    "that matches the mean of d).\n%s"
    "The residual max |d(q) - d| (m) must be within 1000 eps max(L, |d|), eps =\n"
    "2.2e-16 the double-precision rounding unit and L the model's mean\n"
    "upper-link length, unless --lsq is given.\n"
    "--lsq: least squares, Gauss-Newton on |d(q) - d|^2 with J_d^+ =\n"
    "(J_d^T J_d)^-1 J_d^T: the pose of least squared residual is printed\n"
    "whatever the residual (measured or rounded slider positions), with\n"
    "consistent: false when the residual exceeds the tolerance.\n"
    "Prints JSON with model (name, file, sha256, ...), d, q, residual, method\n"
    "(\"newton\" or \"least-squares\") and, for least squares, consistent.\n"
    "Exit 1 when d is out of reach or the iteration meets a singularity%s.\n";

static const char fk_method_3[] =
    "Newton's method (a Powell hybrid solver with the exact J_d) unless --lsq.\n";
static const char fk_method_redundant[] =
    "With more sliders than coordinates, d(q) = d has a solution only when the\n"
    "sliders are consistent (the extra slider where the others put it): fk fits\n"
    "q by least squares (as --lsq) and refuses a fit whose residual shows that\n"
    "no pose reproduces all the sliders (exit 1, the best fit and its residual\n"
    "in the message).\n";

int prru_cmd_fk(int argc, char **argv)
{
  const char *ds = NULL, *seeds = NULL;
  int help = 0, lsq = 0;
  prru_cli_option opts[] = {{"d", 1, &ds, NULL},
                            {"seed", 1, &seeds, NULL},
                            {"lsq", 0, NULL, &lsq},
                            {"help", 0, NULL, &help}};
  if (prru_cli_parse("fk", argc, argv, opts, 4)) return 2;
  const int nact = prru_cli_model()->mech->nact;
  if (help) {
    char names[256];
    printf(fk_help, prru_cli_names(names, sizeof names, "d", nact, ","),
           nact > 3 ? fk_method_redundant : fk_method_3,
           nact > 3 ? ",\nand without --lsq when the sliders are inconsistent" : "");
    return 0;
  }
  double act[PRRU_MAX_ACT], seed[3], q[3];
  if (!ds) {
    prru_cli_error("fk", "--d is required (see 'prru fk --help')");
    return 2;
  }
  if (prru_cli_numbers("fk", "d", ds, act, nact)) return 2;
  prru_model m = *prru_cli_model();
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  if (seeds) {
    if (prru_cli_numbers("fk", "seed", seeds, seed, 3)) { free(d); return 2; }
  } else {
    prru_fk_default_seed(&m, act, seed);
  }
  /* Three sliders: Newton unless --lsq; more: always least squares. */
  int use_lsq = lsq || nact > 3;
  double res = NAN, tol = prru_fk_tolerance(&m, act);
  int st = use_lsq ? prru_forward_kinematics_lsq(&m, d, act, seed, q, &res)
                   : prru_forward_kinematics(&m, d, act, seed, q);
  char dtext[32 * PRRU_MAX_ACT], qs[128];
  prru_cli_vec(dtext, sizeof dtext, act, nact);
  if (st != PRRU_OK) {
    prru_cli_error("fk", "d = %s from seed %s: %s%s", dtext, prru_cli_vec(qs, sizeof qs, seed, 3), prru_strerror(st),
                   st == PRRU_ENOCONV ? " (d out of reach, or a singularity near the path; try another --seed)" : "");
    free(d);
    return 1;
  }
  if (!use_lsq) res = prru_fk_residual(&m, q, act);
  /* |d(q) - d|^2 overflows for |d| beyond ~1e154 m: no step of the
   * least-squares iteration can then be judged and it stops at the seed
   * as if stationary. Such sliders are out of any robot's reach. */
  if (use_lsq && !isfinite(res * res * nact)) {
    prru_cli_error("fk", "d = %s: out of reach (the squared residual overflows)", dtext);
    free(d);
    return 1;
  }
  int consistent = res <= tol;
  if (use_lsq && !lsq && !consistent) {
    prru_cli_error("fk", "d = %s: no pose reproduces all %d slider positions, they are "
                   "inconsistent (or out of reach): the best least-squares fit q = %s leaves a "
                   "residual of %.3g m, tolerance %.3g m; --lsq accepts that fit",
                   dtext, nact, prru_cli_vec(qs, sizeof qs, q, 3), res, tol);
    free(d);
    return 1;
  }
  putchar('{');
  prru_cli_json_model(stdout);
  printf(",\n \"d\": ");
  prru_cli_json_array(stdout, act, nact);
  printf(", \"q\": ");
  prru_cli_json_array(stdout, q, 3);
  printf(", \"residual\": ");
  prru_cli_json_number(stdout, res);
  printf(", \"method\": \"%s\"", use_lsq ? "least-squares" : "newton");
  if (use_lsq) printf(", \"consistent\": %s", consistent ? "true" : "false");
  printf("}\n");
  free(d);
  return ferror(stdout) ? 1 : 0;
}

/* %s: the output's columns. */
static const char id_help[] =
    "usage: prru id --traj FILE.csv [--out FILE.csv|-] [--preload T] [--null-vector]\n"
    "               [--differentiate] [--window M] [--degree P] [--derivatives]\n"
    "               [--rates] [--reactions] [--units rail|motor]\n"
    "Inverse dynamics along a trajectory: FILE has a header row and columns\n"
    "t, q1..q3, qd1..qd3, qdd1..qdd3 (any order, other columns ignored) and\n"
    "optionally fp1..fp3, mp1..mp3 (platform loads, default 0); lines starting\n"
    "with '#' are skipped, so `prru simulate` output qualifies. Writes the model\n"
    "line (# prru ... model ...) and t,%s (N) to --out or stdout (also\n"
    "--out -); --out FILE keeps its old contents until the first row is ready\n"
    "(it is built as FILE.partial-XXXXXX and renamed). The output is a load\n"
    "table for `prru simulate --loads` (actuator forces only).\n"
    "Without the columns qd1..3 and qdd1..3 (or with --differentiate) the\n"
    "velocities and accelerations come from q(t) alone: at each row, the\n"
    "least-squares polynomial of degree P (--degree, default 4) through the\n"
    "2M + 1 rows around it (--window M, default 4; the 2M + 1 first or last\n"
    "rows near the ends; times may be uneven). It is exact for polynomials of\n"
    "degree P. For a smooth q the error of qdd is at most TRUNC times the\n"
    "largest (P+1)-th derivative of q, and white noise of size s on q becomes\n"
    "noise of size GAIN s on qdd; a comment line of the output gives both\n"
    "(the worst over the rows, which is at the ends). At 1 ms rows with the\n"
    "defaults, TRUNC = 2.7e-7 s^3 (2.2e-9 s^3 away from the ends) and\n"
    "GAIN = 2.2e6 s^-2 (4.4e5 s^-2): a wider window or a lower degree averages\n"
    "noise away, a narrower one follows fast motion better.\n"
    "--derivatives adds the columns qd1..3, qdd1..3 used; --rates the slider\n"
    "velocities %s (m/s) and the actuator powers\n"
    "%s = fd dd (W);\n"
    "--reactions the joint reactions (columns as in 'prru simulate'); --units\n"
    "motor the motor torques tau1.. (N m, fd lead / (2 pi gear)) and, where the\n"
    "model gives torque_constant, the currents i1.. (A): the model file's\n"
    "actuators.lead is required (exit 2 without). With any of them the output\n"
    "is no longer a load table.\n"
    "%s"
    "A row where the pose is unreachable or J_d singular, or where det J_d has\n"
    "changed sign since the row before (the motion crossed a singular pose in\n"
    "between), stops with exit 1,\n"
    "SIGINT/SIGTERM/SIGHUP with exit 130/143/129; the rows before it are kept.\n"
    "A write error exits 1 with the reason; an unreadable or malformed FILE\n"
    "exits 2.\n";

/* %d: actuators, %s: the n columns. */
static const char id_help_redundant[] =
    "This model has %d actuators for 3 coordinates: many force sets give the\n"
    "same motion, fd and fd + t n alike, n the unit vector with J_d^T n = 0 and a\n"
    "positive last component (the pattern that is in equilibrium by itself,\n"
    "see actuator_null in 'prru eval --help'). The forces written are the\n"
    "least-norm ones, J_d^+T tau with J_d^+ = (J_d^T J_d)^-1 J_d^T, plus\n"
    "T n for --preload T (N, default 0): fd . n = T at every row, and\n"
    "J_d^T fd (what moves the robot) does not depend on T. A second comment\n"
    "line gives T. --null-vector adds the columns %s (n at each row;\n"
    "such a file is no longer a load table for simulate).\n";

static const char id_help_3[] =
    "The forces are unique (J_d^-T tau): --preload and --null-vector need a\n"
    "model with redundant actuators (e.g. models/4prru.json) and are usage\n"
    "errors here.\n";

/* qd, qdd from q(t) (prru_traj.h) for every row of t: arrays of 3 per
 * row, malloc'ed in *qd (qd then qdd); the comment line for the output in
 * note. 0, or 2 after a message naming the file and row. */
static int id_differentiate(const char *traj, const prru_table *t, const int col[4],
                            const prru_diff_options *o, double **qd, char *note, size_t notelen)
{
  const size_t n = (size_t)t->nrows;
  double *buf = malloc((n ? n : 1) * 16 * sizeof *buf);
  if (!buf) {
    prru_cli_error("id", "out of memory");
    return 1;
  }
  double *tt = buf, *q = buf + n, *trunc = buf + 4 * n, *gain = buf + 7 * n, *res = buf + 10 * n;
  for (size_t i = 0; i < n; i++) {
    const double *row = t->data + i * (size_t)t->ncols;
    tt[i] = row[col[0]];
    for (int c = 0; c < 3; c++) q[3 * i + c] = row[col[1 + c]];
  }
  char msg[300];
  if (prru_diff_signal(tt, t->nrows, q, 3, o, NULL, res, res + 3 * n, trunc, gain, msg,
                       sizeof msg) != PRRU_OK) {
    prru_cli_error("id", "--traj %s: cannot differentiate q(t): %s", traj, msg);
    free(buf);
    return 2;
  }
  double w[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < n; i++) {
    w[0] = fmax(w[0], trunc[3 * i + 1]);
    w[1] = fmax(w[1], trunc[3 * i + 2]);
    w[2] = fmax(w[2], gain[3 * i + 1]);
    w[3] = fmax(w[3], gain[3 * i + 2]);
  }
  snprintf(note, notelen, "# qd, qdd from q(t): least-squares polynomials of degree %d over %d rows; "
           "error bound factors TRUNC qd %.3g s^%d, qdd %.3g s^%d (times the largest derivative "
           "%d of q); noise gains GAIN qd %.3g s^-1, qdd %.3g s^-2\n", o->degree,
           2 * o->half_width + 1, w[0], o->degree, w[1], o->degree - 1, o->degree + 1, w[2], w[3]);
  memmove(buf, res, 6 * n * sizeof *buf);
  *qd = buf;
  return 0;
}

/* --window and --degree into o. 0 or 2. */
static int id_diff_options(const char *wins, const char *degs, prru_diff_options *o)
{
  prru_diff_options_default(o);
  double v;
  if (wins) {
    if (prru_cli_number("id", "window", wins, &v)) return 2;
    if (!(v >= 1 && v <= PRRU_DIFF_MAX_HALF && v == floor(v))) {
      prru_cli_error("id", "--window '%s': must be a whole number from 1 to %d (rows on each side)",
                     wins, PRRU_DIFF_MAX_HALF);
      return 2;
    }
    o->half_width = (int)v;
  }
  if (degs) {
    if (prru_cli_number("id", "degree", degs, &v)) return 2;
    if (!(v >= 2 && v <= PRRU_DIFF_MAX_DEGREE && v == floor(v))) {
      prru_cli_error("id", "--degree '%s': must be a whole number from 2 to %d", degs,
                     PRRU_DIFF_MAX_DEGREE);
      return 2;
    }
    o->degree = (int)v;
  }
  if (o->degree > 2 * o->half_width) {
    prru_cli_error("id", "--degree %d needs --window %d or more (a polynomial of degree P needs "
                   "P + 1 rows; the window has 2M + 1)", o->degree, (o->degree + 1) / 2);
    return 2;
  }
  return 0;
}

int prru_cmd_id(int argc, char **argv)
{
  const char *traj = NULL, *out = NULL, *pre = NULL, *wins = NULL, *degs = NULL, *units = NULL;
  int help = 0, null_vector = 0, force_diff = 0, derivs = 0, rates = 0, reactions = 0;
  prru_cli_option opts[] = {{"traj", 1, &traj, NULL},
                            {"out", 1, &out, NULL},
                            {"preload", 1, &pre, NULL},
                            {"null-vector", 0, NULL, &null_vector},
                            {"differentiate", 0, NULL, &force_diff},
                            {"window", 1, &wins, NULL},
                            {"degree", 1, &degs, NULL},
                            {"derivatives", 0, NULL, &derivs},
                            {"rates", 0, NULL, &rates},
                            {"reactions", 0, NULL, &reactions},
                            {"units", 1, &units, NULL},
                            {"help", 0, NULL, &help}};
  if (prru_cli_parse("id", argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  const prru_model *cm = prru_cli_model();
  const int nact = cm->mech->nact, npreload = prru_cli_npreload(cm);
  char fd_names[256], n_names[256], dd_names[256], pow_names[256];
  prru_cli_names(fd_names, sizeof fd_names, "fd", nact, ",");
  prru_cli_names(n_names, sizeof n_names, "n", nact, ",");
  prru_cli_names(dd_names, sizeof dd_names, "dd", nact, ",");
  prru_cli_names(pow_names, sizeof pow_names, "pow", nact, ",");
  if (help) {
    char extra[sizeof id_help_redundant + 300];
    if (npreload > 0)
      snprintf(extra, sizeof extra, id_help_redundant, nact, n_names);
    else
      snprintf(extra, sizeof extra, "%s", id_help_3);
    printf(id_help, fd_names, dd_names, pow_names, extra);
    return 0;
  }
  if (!traj) {
    prru_cli_error("id", "--traj is required (see 'prru id --help')");
    return 2;
  }
  if (prru_cli_refuse_same_file("id", "traj", traj, "out", out)) return 2;
  int motor = 0, current = 0;
  if (prru_cli_units("id", units, &motor, &current)) return 2;
  double preload = 0.0;
  if (pre && prru_cli_number("id", "preload", pre, &preload)) return 2;
  if ((pre || null_vector) && npreload == 0) {
    prru_cli_error("id", "%s: model %s has %d actuators for 3 coordinates, so the actuator forces "
                   "are unique and no internal preload exists; it needs a model with a redundant "
                   "actuator such as models/4prru.json (see 'prru id --help')",
                   pre ? "--preload" : "--null-vector", cm->mech->name, nact);
    return 2;
  }
  static const char *const need[10] = {"t", "q1", "q2", "q3", "qd1", "qd2", "qd3", "qdd1", "qdd2", "qdd3"};
  static const char *const opt[6] = {"fp1", "fp2", "fp3", "mp1", "mp2", "mp3"};
  char msg[512];
  prru_table t;
  /* A large file takes a while: a signal meanwhile is reported. */
  prru_cli_catch_signals();
  int st = prru_table_read(&t, traj, msg, sizeof msg);
  int irc = prru_cli_read_interrupted("id", "traj", traj);
  if (irc) {
    if (st == PRRU_OK) prru_table_free(&t);
    return irc;
  }
  if (st != PRRU_OK) {
    prru_cli_error("id", "--traj %s", msg);
    return 2;
  }
  int col[16], nrates = 0;
  for (int k = 0; k < 10; k++) {
    col[k] = prru_table_column(&t, need[k]);
    nrates += k >= 4 && col[k] >= 0;
    if (k < 4 && col[k] < 0) {
      prru_cli_error("id", "--traj %s: missing column '%s' (need t, q1..3, and qd1..3, qdd1..3 "
                     "unless they are to be computed from q)", traj, need[k]);
      prru_table_free(&t);
      return 2;
    }
  }
  /* Velocities and accelerations from q(t) when the file has none. */
  const int diff = force_diff || nrates == 0;
  if (!diff && nrates < 6) {
    prru_cli_error("id", "--traj %s: has %d of the 6 columns qd1..3, qdd1..3: give all of them, "
                   "or none (or --differentiate) to compute them from q(t)", traj, nrates);
    prru_table_free(&t);
    return 2;
  }
  if (!diff && (wins || degs)) {
    prru_cli_error("id", "--%s applies when qd, qdd are computed from q(t): %s has them (add "
                   "--differentiate to recompute them)", wins ? "window" : "degree", traj);
    prru_table_free(&t);
    return 2;
  }
  for (int k = 0; k < 6; k++) col[10 + k] = prru_table_column(&t, opt[k]);
  prru_diff_options dopt;
  double *rates_q = NULL;
  char note[600] = "";
  if (diff && (id_diff_options(wins, degs, &dopt) ||
               (st = id_differentiate(traj, &t, col, &dopt, &rates_q, note, sizeof note)) != 0)) {
    prru_table_free(&t);
    irc = prru_cli_read_interrupted("id", "traj", traj);
    return irc ? irc : st == 1 ? 1 : 2;
  }
  if ((irc = prru_cli_read_interrupted("id", "traj", traj)) != 0) {
    prru_table_free(&t);
    free(rates_q);
    return irc;
  }
  prru_cli_out o;
  if (prru_cli_out_open(&o, "id", out)) {
    prru_table_free(&t);
    free(rates_q);
    return 1;
  }
  prru_model m = *prru_cli_model();
  prru_data *d = malloc(sizeof *d);
  st = d ? PRRU_OK : PRRU_ENOMEM;
  prru_cli_out_comment(&o);
  if (npreload > 0) {
    /* (No "null" in the text: it reads as a JSON null to a checker.) */
    prru_cli_out_printf(&o, "# fd = least-norm actuator forces + preload %.17g N along n, the unit "
                            "vector with J_d^T n = 0 (fd . n = %.17g)\n", preload, preload);
    prru_cli_out_line(&o);
  }
  if (diff) {
    prru_cli_out_printf(&o, "%s", note);
    prru_cli_out_line(&o);
  }
  prru_cli_out_printf(&o, "t,%s%s%s", fd_names, null_vector ? "," : "", null_vector ? n_names : "");
  if (derivs) prru_cli_out_printf(&o, ",qd1,qd2,qd3,qdd1,qdd2,qdd3");
  if (rates) prru_cli_out_printf(&o, ",%s,%s", dd_names, pow_names);
  for (int k = 0; reactions && k < cm->mech->nlambda; k++)
    prru_cli_out_printf(&o, ",%s", cm->mech->lambda_labels[k]);
  prru_cli_out_motor_names(&o, motor, current);
  prru_cli_out_printf(&o, "\n");
  prru_cli_out_line(&o);
  char why[700] = "";
  prru_path_side side;
  prru_path_side_init(&side);
  double t_prev = 0;
  for (int i = 0; st == PRRU_OK && !o.err && i < t.nrows; i++) {
    if (prru_cli_interrupted) {
      st = PRRU_EINTERRUPTED;
      snprintf(why, sizeof why, "interrupted (%s) before data row %d", prru_cli_signal_name(), i + 1);
      break;
    }
    const double *row = t.data + (size_t)i * (size_t)t.ncols;
    double v[16], fd[PRRU_MAX_ACT];
    for (int k = 0; k < 16; k++) v[k] = col[k] < 0 ? 0.0 : row[col[k]];
    if (diff) {
      memcpy(v + 4, rates_q + 3 * i, 3 * sizeof v[0]);
      memcpy(v + 7, rates_q + 3 * ((size_t)t.nrows + (size_t)i), 3 * sizeof v[0]);
    }
    prru_loads l;
    memset(&l, 0, sizeof l);
    memcpy(l.fp, v + 10, sizeof l.fp);
    memcpy(l.mp, v + 13, sizeof l.mp);
    double n[PRRU_MAX_ACT];
    st = prru_inverse_dynamics_preload(&m, d, v + 1, v + 4, v + 7, &l, preload, fd);
    /* J_d of this row: on the side of the rows before? */
    const int crossed = st == PRRU_OK && prru_path_side_crossed(&side, d->Jd, m.mech->nact);
    if (st == PRRU_OK && null_vector) st = prru_actuator_null(&m, d, v + 1, n);
    double dd[PRRU_MAX_ACT], ddb[PRRU_MAX_ACT], pw[PRRU_MAX_ACT], lambda[PRRU_MAX_LAMBDA];
    if (st == PRRU_OK && rates) {
      prru_model_actuator_rates(&m, v + 1, v + 4, dd, ddb);
      for (int k = 0; k < nact; k++) pw[k] = fd[k] * dd[k];
    }
    if (st == PRRU_OK && reactions) {
      memcpy(l.fd, fd, (size_t)nact * sizeof(double));
      st = prru_reactions(&m, d, v + 1, v + 4, &l, lambda);
    }
    if (st != PRRU_OK) {
      snprintf(why, sizeof why, "%s: data row %d (t = %g): %s", traj, i + 1, v[0], prru_strerror(st));
      break;
    }
    /* Each row is regular on its own, but the motion between two rows
     * passed a singular pose when det J_d changed sign (as in 'prru traj'):
     * what it would take is not these forces. */
    if (crossed) {
      st = PRRU_ESINGULAR;
      snprintf(why, sizeof why, "%s: data row %d (t = %g): the motion crosses a singularity "
               "(J_d singular) after the row before (t = %g): det J_d changes sign at q = (%.9g, "
               "%.9g, %.9g)", traj, i + 1, v[0], t_prev, v[1], v[2], v[3]);
      break;
    }
    t_prev = v[0];
    prru_cli_out_printf(&o, "%.17g", v[0]);
    prru_cli_out_numbers(&o, fd, nact);
    if (null_vector) prru_cli_out_numbers(&o, n, nact);
    if (derivs) prru_cli_out_numbers(&o, v + 4, 6);
    if (rates) {
      prru_cli_out_numbers(&o, dd, nact);
      prru_cli_out_numbers(&o, pw, nact);
    }
    if (reactions) prru_cli_out_numbers(&o, lambda, cm->mech->nlambda);
    prru_cli_out_motor(&o, &m, fd, motor, current);
    prru_cli_out_printf(&o, "\n");
    prru_cli_out_row(&o);
  }
  free(d);
  free(rates_q);
  prru_table_free(&t);
  return prru_cli_out_finish(&o, st, why);
}
