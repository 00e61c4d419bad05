/* prru excite and prru identify: excitation trajectories and least-squares
 * identification of the base inertial parameters (prru_ident.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru_measure.h"
#include "prru_model_file.h"
#include "prru_control.h"
#include "prru_ident.h"
#include "prru_traj.h"

/* The Coulomb smoothing velocity the regressor uses: --coulomb-velocity,
 * else the model's, else 1 mm/s. */
static int coulomb_velocity(const char *cmd, const char *text, double *vs)
{
  *vs = prru_ident_default_vs(prru_cli_model());
  if (!text) return 0;
  if (prru_cli_number(cmd, "coulomb-velocity", text, vs)) return 2;
  if (!(*vs > 0)) {
    prru_cli_error(cmd, "--coulomb-velocity: %s must be positive (m/s)", text);
    return 2;
  }
  return 0;
}

static int base_or_fail(const char *cmd, const prru_model *m, double vs, prru_base **b)
{
  *b = malloc(sizeof **b);
  int st = *b ? prru_base_compute(m, vs, 0, 1, *b) : PRRU_ENOMEM;
  if (st != PRRU_OK) prru_cli_error(cmd, "base parameters: %s", prru_strerror(st));
  return st == PRRU_OK ? 0 : 1;
}

/* ------------------------------------------------------------ excite --- */

static const char excite_help[] =
    "usage: prru excite [--out FILE.csv|-] [--period T] [--harmonics L] [--periods N]\n"
    "         [--dt DT] [--centre q1,q2,q3] [--amplitude A1,A2,A3]\n"
    "         [--force-max F|F1,..] [--speed-max V|V1,..] [--stroke LO,HI|LO1,HI1,..]\n"
    "         [--no-limits] [--rcond-min R] [--evals N] [--samples N] [--seed S]\n"
    "         [--coulomb-velocity VS]\n"
    "An excitation trajectory for identification: each coordinate a Fourier\n"
    "series q_k(t) = c_k + sum_l (a_kl sin(l w t) + b_kl cos(l w t)), w = 2 pi / T\n"
    "(default T = 10 s, L = 5 harmonics, centre c = 0), whose coefficients are\n"
    "chosen (Nelder-Mead, deterministic for a --seed, default 1; --evals\n"
    "evaluations, default 3000) for the smallest condition number of the base\n"
    "regressor (columns scaled to unit norm) stacked over --samples points per\n"
    "period (default 100), subject to: every point reachable, J_d regular\n"
    "(rcond >= --rcond-min, default 1e-2, prru ik's Jd_rcond) in the centre's\n"
    "assembly mode, |q_k - c_k| <= A_k (default 0.25 rad, 0.25 rad, 0.1 L with L\n"
    "the mean upper-link length), and the actuator forces of this model's\n"
    "inverse dynamics (no platform loads), the slider speeds and the sliders\n"
    "within the drives' limits. The limits are the model's (its actuators keys:\n"
    "force_max or torque_max, speed_max or motor_speed_max, stroke) unless\n"
    "--force-max (N; alias --fd-max), --speed-max (m/s) or --stroke (m) replace\n"
    "them, one value (pair) for all or one per actuator, or --no-limits drops\n"
    "them; without a force limit, 500 N. A comment line names the limits\n"
    "applied. The result is then checked at 20 times\n"
    "as many points, and shrunk about the centre until it passes.\n"
    "Writes the model line, comment lines with the coefficients and the\n"
    "condition number, then the columns\n"
    "  t,q1..q3,qd1..qd3,qdd1..qdd3,%s,%s\n"
    "at --dt (default 0.01 s) over --periods periods (default 1; the last row\n"
    "at N T), to\n"
    "--out (default stdout): a trajectory for `prru id --traj` and, with\n"
    "measured forces in the fd columns, data for `prru identify`. A summary goes\n"
    "to stderr. Exit 2 for bad options or an unreachable or singular centre, 1\n"
    "when no feasible trajectory is found (nothing written).\n";

typedef struct {
  const char *out, *period, *harm, *periods, *dt, *centre, *amp, *rcond, *evals, *samples, *seed, *vs;
  prru_cli_limit_args lim;
  int help;
} excite_args;

static int parse_count(const char *cmd, const char *name, const char *text, int lo, int hi, int *out)
{
  double v;
  if (prru_cli_number(cmd, name, text, &v)) return 2;
  if (v != floor(v) || v < lo || v > hi) {
    prru_cli_error(cmd, "--%s: %s must be a whole number in %d..%d", name, text, lo, hi);
    return 2;
  }
  *out = (int)v;
  return 0;
}

static int parse_positive(const char *cmd, const char *name, const char *text, double *out)
{
  if (prru_cli_number(cmd, name, text, out)) return 2;
  if (!(*out > 0)) {
    prru_cli_error(cmd, "--%s: %s must be positive", name, text);
    return 2;
  }
  return 0;
}

static int excite_options(const excite_args *a, prru_excite_options *o, prru_fourier *f, prru_limits *lim)
{
  const char *c = "excite";
  prru_excite_options_default(o);
  prru_fourier_default(f);
  if (a->period && parse_positive(c, "period", a->period, &f->period)) return 2;
  if (a->harm && parse_count(c, "harmonics", a->harm, 1, PRRU_EXCITE_MAX_HARMONICS, &f->harmonics)) return 2;
  if (a->periods && parse_count(c, "periods", a->periods, 1, 1000, &o->periods)) return 2;
  if (a->dt && parse_positive(c, "dt", a->dt, &o->dt)) return 2;
  if (a->centre && prru_cli_numbers(c, "centre", a->centre, f->centre, 3)) return 2;
  if (a->amp) {
    if (prru_cli_numbers(c, "amplitude", a->amp, o->amplitude_max, 3)) return 2;
    for (int k = 0; k < 3; k++)
      if (!(o->amplitude_max[k] > 0)) {
        prru_cli_error(c, "--amplitude: the bound of q%d must be positive", k + 1);
        return 2;
      }
  }
  /* The run's limits (the model's unless overridden; excite_model makes
   * the stroke the reach of the run's model too). Excitation needs a
   * force bound: 500 N (the default) where the run has none. */
  if (prru_cli_limits(c, "fd-max", &a->lim, lim)) return 2;
  prru_excite_options_limits(o, lim);
  if (a->rcond && prru_cli_number(c, "rcond-min", a->rcond, &o->rcond_min)) return 2;
  if (!(o->rcond_min > 0 && o->rcond_min < 1)) {
    prru_cli_error(c, "--rcond-min: %s must lie between 0 and 1", a->rcond);
    return 2;
  }
  if (a->evals && parse_count(c, "evals", a->evals, 1, 10000000, &o->max_evals)) return 2;
  if (a->samples && parse_count(c, "samples", a->samples, 1, 100000, &o->samples)) return 2;
  int seed;
  if (a->seed && parse_count(c, "seed", a->seed, 0, 2000000000, &seed)) return 2;
  if (a->seed) o->seed = (unsigned long)seed;
  const double run = f->period * o->periods;
  if (prru_excite_rows(f, o) == 0) {
    /* The library refuses; the words name the flags (and a dt the user
     * never gave). */
    if (o->dt > run)
      prru_cli_error(c, "--dt: %g s%s is longer than the run (%g s: --period %g s x --periods %d)", o->dt,
                     a->dt ? "" : " (the default)", run, f->period, o->periods);
    else
      prru_cli_error(c, "--dt: %g s gives more than 1e15 rows over the run (%g s)", o->dt, run);
    return 2;
  }
  return 0;
}

/* The limits the excitation kept: the run's, with the default force
 * bound where the run has none. */
static void excite_limits_comment(prru_cli_out *out, const prru_limits *run, const prru_excite_options *o)
{
  prru_limits applied = *run;
  int dflt = 0;
  char text[400];
  for (int i = 0; i < prru_cli_model()->mech->nact; i++) {
    dflt |= !isfinite(run->force_max[i]);
    applied.force_max[i] = o->fd_max[i];
  }
  prru_limits_describe(prru_cli_model(), &applied, text, sizeof text);
  prru_cli_out_comment_line(out, "limits: %s%s", text, dflt ? " (force: excite's default where the run has none)" : "");
}

/* The starting condition number, or why there is none. */
static void start_text(const prru_excite_result *r, char *buf, size_t len)
{
  if (isfinite(r->cond_start))
    snprintf(buf, len, "%.6g", r->cond_start);
  else
    snprintf(buf, len, "infeasible");
}

static void excite_comments(prru_cli_out *o, const prru_fourier *f, const prru_excite_result *r,
                            const prru_base *b)
{
  char start[64];
  start_text(r, start, sizeof start);
  prru_cli_out_printf(o, "# excitation: period %.17g s, %d harmonics, centre %.17g %.17g %.17g; "
                      "condition number %.6g (start %s) of the base regressor (%d base parameters)\n",
                      f->period, f->harmonics, f->centre[0], f->centre[1], f->centre[2], r->cond, start,
                      b->nbase);
  prru_cli_out_line(o);
  for (int k = 0; k < 3; k++) {
    prru_cli_out_printf(o, "# q%d: a", k + 1);
    for (int l = 0; l < f->harmonics; l++) prru_cli_out_printf(o, " %.17g", f->a[k][l]);
    prru_cli_out_printf(o, "; b");
    for (int l = 0; l < f->harmonics; l++) prru_cli_out_printf(o, " %.17g", f->b[k][l]);
    prru_cli_out_printf(o, "\n");
    prru_cli_out_line(o);
  }
}

/* The rows; a failing inverse dynamics (never after the check) stops. */
static int excite_rows(prru_cli_out *o, const prru_model *m, const prru_fourier *f, const prru_excite_options *eo)
{
  prru_data *d = malloc(sizeof *d);
  if (!d) return PRRU_ENOMEM;
  char dn[256], fn[256];
  prru_cli_names(dn, sizeof dn, "d", m->mech->nact, ",");
  prru_cli_names(fn, sizeof fn, "fd", m->mech->nact, ",");
  prru_cli_out_printf(o, "t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,%s,%s\n", dn, fn);
  prru_cli_out_line(o);
  const long n = prru_excite_rows(f, eo);
  prru_loads l;
  memset(&l, 0, sizeof l);
  int st = PRRU_OK;
  for (long i = 0; i < n && st == PRRU_OK && !o->err; i++) {
    if (prru_cli_interrupted) {
      st = PRRU_EINTERRUPTED;
      break;
    }
    const double t = i * eo->dt;
    double q[3], qd[3], qdd[3], fd[PRRU_MAX_ACT];
    prru_fourier_eval(f, t, q, qd, qdd);
    st = prru_inverse_dynamics(m, d, q, qd, qdd, &l, fd);
    if (st != PRRU_OK) break;
    prru_cli_out_motion_row(o, t, q, qd, qdd, d->d, fd);
  }
  free(d);
  return st;
}

int prru_cmd_excite(int argc, char **argv)
{
  excite_args a;
  memset(&a, 0, sizeof a);
  prru_cli_option opts[] = {
      {"out", 1, &a.out, NULL},         {"period", 1, &a.period, NULL},   {"harmonics", 1, &a.harm, NULL},
      {"periods", 1, &a.periods, NULL}, {"dt", 1, &a.dt, NULL},           {"centre", 1, &a.centre, NULL},
      {"amplitude", 1, &a.amp, NULL},   {"fd-max", 1, &a.lim.alias, NULL}, {"rcond-min", 1, &a.rcond, NULL},
      {"evals", 1, &a.evals, NULL},     {"samples", 1, &a.samples, NULL}, {"seed", 1, &a.seed, NULL},
      {"coulomb-velocity", 1, &a.vs, NULL}, PRRU_CLI_LIMIT_OPTIONS(a.lim), {"help", 0, NULL, &a.help}};
  if (prru_cli_parse("excite", argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  if (a.help) {
    const int nact = prru_cli_model()->mech->nact;
    char dn[256], fn[256];
    printf(excite_help, prru_cli_names(dn, sizeof dn, "d", nact, ","), prru_cli_names(fn, sizeof fn, "fd", nact, ","));
    return 0;
  }
  prru_excite_options o;
  prru_fourier f;
  double vs;
  prru_limits lim;
  if (excite_options(&a, &o, &f, &lim) || coulomb_velocity("excite", a.vs, &vs)) return 2;
  /* the run's model: the run's stroke bounds its reach */
  prru_model m;
  if (prru_model_with_limits(&m, prru_cli_model(), &lim) != PRRU_OK) return 1;
  prru_base *b;
  if (base_or_fail("excite", &m, vs, &b)) {
    free(b);
    prru_model_free(&m);
    return 1;
  }
  prru_cli_catch_signals();
  prru_excite_result r;
  char msg[512];
  int st = prru_excite(&m, b, &o, &prru_cli_interrupted, &f, &r, msg, sizeof msg);
  if (st != PRRU_OK) {
    free(b);
    prru_model_free(&m);
    if (st == PRRU_EINTERRUPTED) {
      prru_cli_error("excite", "interrupted (%s); nothing written", prru_cli_signal_name());
      return prru_cli_exit_interrupted();
    }
    prru_cli_error("excite", "%s; nothing written", msg);
    return st == PRRU_EINPUT ? 2 : 1;
  }
  prru_cli_out out;
  if (prru_cli_out_open(&out, "excite", a.out)) {
    free(b);
    prru_model_free(&m);
    return 1;
  }
  prru_cli_out_comment(&out);
  excite_limits_comment(&out, &lim, &o);
  excite_comments(&out, &f, &r, b);
  st = excite_rows(&out, &m, &f, &o);
  int io = out.err != 0;
  if (prru_cli_out_close(&out, !io && st == PRRU_OK)) {
    free(b);
    prru_model_free(&m);
    return 1;
  }
  if (st != PRRU_OK) {
    free(b);
    prru_model_free(&m);
    prru_cli_error("excite", "%s; nothing written", prru_strerror(st));
    return st == PRRU_EINTERRUPTED ? prru_cli_exit_interrupted() : 1;
  }
  char start[64];
  start_text(&r, start, sizeof start);
  fprintf(stderr, "excite: %d base parameters; condition number %.6g (start %s, %d evaluations%s); "
                  "worst J_d rcond %.4g; peak |fd|",
          b->nbase, r.cond, start, r.evals, r.shrunk ? ", shrunk to pass the dense check" : "", r.rcond_worst);
  for (int i = 0; i < m.mech->nact; i++) fprintf(stderr, " %.4g", r.fd_peak[i]);
  fprintf(stderr, " N\n");
  free(b);
  prru_model_free(&m);
  return 0;
}

/* ---------------------------------------------------------- identify --- */

static const char identify_help[] =
    "usage: prru identify --data FILE.csv --out MODEL.json [--report FILE.csv|-]\n"
    "         [--name NAME] [--coulomb-velocity VS] [--window M] [--degree P]\n"
    "         [--d-resolution R]\n"
    "Least-squares identification of the base inertial parameters from measured\n"
    "motion and actuator forces. FILE (header row, '#' lines skipped, columns in\n"
    "any order) has t (s, increasing), the forces %s (N) and the pose as\n"
    "q1,q2,q3 or as the slider positions %s (m, turned into q by forward\n"
    "kinematics from the previous row's pose; with four sliders quantised\n"
    "readings disagree by up to the encoders' resolution: give it as\n"
    "--d-resolution R (m), and the least-squares pose is accepted within R).\n"
    "Velocities and accelerations are the columns qd1..qd3 and qdd1..qdd3 when\n"
    "present (prru excite writes the exact ones, prru track the plant's), else\n"
    "derivatives of q by a local polynomial fit (Savitzky-Golay, 2M+1 samples,\n"
    "degree P; default M = 4, P = 4; prru measure suggests M and P for a\n"
    "simulated run of the motion). The platform must carry no\n"
    "load. Each sample gives J_d^T fd = Y(q, qd, qdd) pi, pi the standard\n"
    "parameters (per body m, m c, inertia about the body-frame origin; per\n"
    "actuator armature, damping, Coulomb force for the smoothing velocity VS,\n"
    "default the model's); only the base parameters, fixed combinations of them,\n"
    "can be identified (docs/model.md, identification). They are fitted to the\n"
    "actuator forces (linear least squares) with standard errors from the\n"
    "residual variance.\n"
    "--out: a format-2 model file named NAME (default: this model's name + _id):\n"
    "this model's geometry and gravity, and a physically consistent parameter\n"
    "set (every body's pseudo-inertia positive definite, drive coefficients\n"
    "nonnegative): the estimate's base parameters when a consistent robot has\n"
    "them, else the consistent ones nearest them within their covariance\n"
    "(Mahalanobis distance^2 at most the chi^2 quantile at 1 - 0.001); among\n"
    "those, the set nearest the prior (this model's numbers) in the\n"
    "pseudo-inertia norm, so parameters no motion reveals keep the prior's.\n"
    "--report (default stdout): comment lines with the fit (samples, residual\n"
    "sigma, condition number, the distance to the estimate, the standard\n"
    "parameters moved), then\n"
    "index,parameter,estimate,se,prior,resolution,model,t,combination per base\n"
    "parameter (prior: the combination at this model's numbers; resolution:\n"
    "the value at which it alone would give forces of the data's RMS size;\n"
    "model: the written model's; t: (model - estimate) / se).\n"
    "Model files hold no magnitude below 1e-9 but 0: smaller values are\n"
    "written as 0 (a mass or a principal moment of inertia as 1e-9).\n"
    "Exit 2 for bad options or a malformed FILE, 1 when a row is unreachable or\n"
    "singular (named), the data do not excite every base parameter, or the\n"
    "data contradict physics (no consistent robot within the covariance: a\n"
    "force sign, a gear ratio, or differentiated rates' error; the report is\n"
    "written, the model file is not). Nothing is half-written.\n";

typedef struct {
  int n;
  double *t, *q, *qd, *qdd, *fd;
  int differentiated; /* qd, qdd from q by dopt (the file has no rates) */
  prru_diff_options dopt;
} ident_data;

static void data_free(ident_data *D)
{
  free(D->t), free(D->q), free(D->qd), free(D->qdd), free(D->fd);
}

/* The table's columns into D; 0, or 2 after a message. */
static int data_columns(const char *path, const prru_table *t, int *cq, int *cd, int *cv, int *ca, int *cf)
{
  char name[32];
  const int nact = prru_cli_model()->mech->nact;
  int have_q = 1, have_d = 1, have_v = 1, have_a = 1;
  for (int k = 0; k < 3; k++) {
    snprintf(name, sizeof name, "q%d", k + 1);
    have_q &= (cq[k] = prru_table_column(t, name)) >= 0;
    snprintf(name, sizeof name, "qd%d", k + 1);
    have_v &= (cv[k] = prru_table_column(t, name)) >= 0;
    snprintf(name, sizeof name, "qdd%d", k + 1);
    have_a &= (ca[k] = prru_table_column(t, name)) >= 0;
  }
  for (int i = 0; i < nact; i++) {
    snprintf(name, sizeof name, "d%d", i + 1);
    have_d &= (cd[i] = prru_table_column(t, name)) >= 0;
    snprintf(name, sizeof name, "fd%d", i + 1);
    if ((cf[i] = prru_table_column(t, name)) < 0) {
      prru_cli_error("identify", "--data %s: missing column '%s' (the measured actuator forces)", path, name);
      return 2;
    }
  }
  if (prru_table_column(t, "t") < 0) {
    prru_cli_error("identify", "--data %s: missing column 't'", path);
    return 2;
  }
  if (!have_q && !have_d) {
    prru_cli_error("identify", "--data %s: no pose: need the columns q1,q2,q3 or d1..d%d", path, nact);
    return 2;
  }
  if (!have_q) cq[0] = -1;
  if (!(have_v && have_a)) cv[0] = -1;
  return 0;
}

/* q of every row by forward kinematics from the slider columns
 * (prru_measure_poses: the residual judged against --d-resolution). */
static int poses_from_sliders(const char *path, const prru_table *t, const int *cd, double dres, ident_data *D)
{
  const int nact = prru_cli_model()->mech->nact;
  double *act = malloc(sizeof(double) * (size_t)nact * (size_t)(t->nrows > 0 ? t->nrows : 1));
  if (!act) {
    prru_cli_error("identify", "out of memory for %d rows", t->nrows);
    return 1;
  }
  for (int i = 0; i < t->nrows; i++)
    for (int k = 0; k < nact; k++) act[nact * i + k] = t->data[(size_t)i * (size_t)t->ncols + (size_t)cd[k]];
  int row;
  double res;
  const int st = prru_measure_poses(prru_cli_model(), t->nrows, act, dres, D->q, &row, &res, NULL, 0);
  free(act);
  if (st == PRRU_ENOMEM) {
    prru_cli_error("identify", "out of memory for %d rows", t->nrows);
    return 1;
  }
  if (st != PRRU_OK)
    prru_cli_error("identify", "%s: data row %d: no pose for the sliders (%s)", path, row + 1,
                   isnan(res) ? prru_strerror(st) :
                   dres > 0 ? "inconsistent slider positions: beyond --d-resolution" :
                              "inconsistent slider positions: quantised readings? give --d-resolution");
  return st != PRRU_OK;
}

static int read_data(const char *path, const prru_diff_options *dopt, double dres, ident_data *D)
{
  char msg[700];
  prru_table t;
  memset(D, 0, sizeof *D);
  int st = prru_table_read(&t, path, msg, sizeof msg);
  if (prru_cli_interrupted) { /* the caller reports it */
    if (st == PRRU_OK) prru_table_free(&t);
    return 0;
  }
  if (st != PRRU_OK) {
    prru_cli_error("identify", "--data %s", msg);
    return 2;
  }
  const int nact = prru_cli_model()->mech->nact;
  int cq[3], cd[PRRU_MAX_ACT], cv[3], ca[3], cf[PRRU_MAX_ACT];
  int rc = data_columns(path, &t, cq, cd, cv, ca, cf);
  const int ct = prru_table_column(&t, "t");
  const size_t n = (size_t)t.nrows;
  D->n = t.nrows;
  if (!rc) {
    D->t = malloc(sizeof(double) * (n + 1));
    D->q = malloc(sizeof(double) * 3 * (n + 1));
    D->qd = malloc(sizeof(double) * 3 * (n + 1));
    D->qdd = malloc(sizeof(double) * 3 * (n + 1));
    D->fd = malloc(sizeof(double) * (size_t)nact * (n + 1));
    if (!D->t || !D->q || !D->qd || !D->qdd || !D->fd) {
      prru_cli_error("identify", "out of memory for %d rows", t.nrows);
      rc = 1;
    }
  }
  for (size_t i = 0; i < n && !rc; i++) {
    const double *row = t.data + i * (size_t)t.ncols;
    D->t[i] = row[ct];
    for (int k = 0; k < 3; k++) {
      if (cq[0] >= 0) D->q[3 * i + k] = row[cq[k]];
      if (cv[0] >= 0) D->qd[3 * i + k] = row[cv[k]], D->qdd[3 * i + k] = row[ca[k]];
    }
    for (int k = 0; k < nact; k++) D->fd[(size_t)nact * i + (size_t)k] = row[cf[k]];
    if (i > 0 && !(D->t[i] > D->t[i - 1])) {
      prru_cli_error("identify", "%s: data row %zu: t = %g is not after the previous row's", path, i + 1, D->t[i]);
      rc = 2;
    }
  }
  if (!rc && cq[0] < 0) rc = poses_from_sliders(path, &t, cd, dres, D);
  D->differentiated = cv[0] < 0;
  D->dopt = *dopt;
  if (!rc && cv[0] < 0 &&
      prru_diff_signal(D->t, D->n, D->q, 3, dopt, NULL, D->qd, D->qdd, NULL, NULL, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error("identify", "%s: differentiating q: %s", path, msg);
    rc = 2;
  }
  prru_table_free(&t);
  return rc;
}

/* "U1.Ixx + 0.25 L1.m - ...": base parameter i as a combination. */
static void combination(const prru_base *b, int i, char *buf, size_t len)
{
  const int n = b->nreg;
  size_t k = (size_t)snprintf(buf, len, "%s", prru_base_param_name(b, b->col[i]));
  for (int j = 0; j < n && k < len; j++) {
    const double c = b->B[i * n + j];
    if (j == b->col[i] || fabs(c) < 1e-12) continue;
    k += (size_t)snprintf(buf + k, len - k, " %c %.10g %s", c < 0 ? '-' : '+', fabs(c), prru_base_param_name(b, j));
  }
}

/* The base parameters furthest from the estimate: "#3 P.m at 5.2 se, ...". */
static void write_report(prru_cli_out *o, const prru_base *b, const prru_ident_result *r, const double *prior,
                         const prru_consistent_options *co, const prru_consistent_result *c, const double *pi0,
                         const double *pi)
{
  const int n = b->nreg;
  prru_cli_out_comment(o);
  prru_cli_out_printf(o, "# identify: %d samples, %d rows, %d base parameters of %d, %d degrees of freedom; "
                      "residual sigma %.6g N; condition number %.6g; Coulomb smoothing velocity %.6g m/s\n",
                      r->nsamples, r->nrows, b->nbase, n, r->dof, r->sigma, r->cond, b->vs);
  prru_cli_out_line(o);
  prru_cli_out_printf(o, "# residual RMS per actuator (N):");
  for (int i = 0; i < prru_cli_model()->mech->nact; i++) prru_cli_out_printf(o, " %.6g", r->rms[i]);
  prru_cli_out_printf(o, "\n# no effect on any actuator force (set by the prior):");
  prru_cli_out_line(o);
  for (int j = 0; j < n; j++)
    if (b->role[j] == PRRU_PAR_NONE) prru_cli_out_printf(o, " %s", prru_base_param_name(b, j));
  prru_cli_out_printf(o, "\n# only in combinations (split by the prior):");
  for (int j = 0; j < n; j++)
    if (b->role[j] == PRRU_PAR_COMBINED) prru_cli_out_printf(o, " %s", prru_base_param_name(b, j));
  prru_cli_out_printf(o, "\n# physically consistent model (docs/control.md): %s; Mahalanobis distance^2 of its "
                      "base parameters to the estimate %.4g, chi^2 quantile (%d dof, 1 - %g) %.4g, sigma_w %.4g N "
                      "= max(sigma sqrt(inflation), %g rms(y)); distance to the prior %.4g (pseudo-inertia norm); smallest "
                      "pseudo-inertia eigenvalue %.3g of the prior's; %d Newton steps; residual variance inflation %.4g (%d lags, "
                      "Newey-West)\n",
                      c->how == PRRU_CONSISTENT_EXACT ?
                        "the estimate's own base parameters (a consistent robot has them)" :
                        "no consistent robot has the estimate's base parameters: the consistent set nearest "
                        "them within their covariance",
                      c->d2, b->nbase, co->alpha, c->d2_max, c->sigma_w, co->sigma_floor, c->prior_dist, c->margin,
                      c->newton, r->inflation, r->hac_lags);
  prru_cli_out_line(o);
  char worst[512];
  prru_consistent_worst(b, c, 5, worst, (int)sizeof worst);
  prru_cli_out_printf(o, "# largest deviations of the model's base parameters from the estimate: %s\n", worst);
  prru_cli_out_line(o);
  prru_cli_out_printf(o, "# standard parameters moved from the prior (relative change):");
  int moved = 0;
  for (int j = 0; j < n; j++) {
    /* Relative to the prior's value, or to the drive's weight where
     * the prior has none; below 1e-9 it is rounding. */
    const double ref = c->w[j] > 0 ? fmax(fabs(pi0[j]), c->w[j]) : fabs(pi0[j]);
    if (fabs(pi[j] - pi0[j]) <= 1e-9 * ref) continue;
    if (ref > 0)
      prru_cli_out_printf(o, "\n#   %s %.4g (prior %.4g, %+.3g %%)", prru_base_param_name(b, j), pi[j], pi0[j],
                          100 * (pi[j] - pi0[j]) / ref);
    else
      prru_cli_out_printf(o, "\n#   %s %.4g (prior 0)", prru_base_param_name(b, j), pi[j]);
    moved++;
  }
  if (!moved) prru_cli_out_printf(o, " none");
  prru_cli_out_printf(o, "\nindex,parameter,estimate,se,prior,resolution,model,t,combination\n");
  prru_cli_out_line(o);
  for (int i = 0; i < b->nbase; i++) {
    char comb[4096];
    combination(b, i, comb, sizeof comb);
    prru_cli_out_printf(o, "%d,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.6g,%s\n", i + 1, prru_base_param_name(b, b->col[i]),
                        r->beta[i], r->se[i], prior[i], r->scale[i], c->beta[i], c->t[i], comb);
    prru_cli_out_row(o);
  }
}

typedef struct {
  const char *data, *out, *report, *name, *vs, *window, *degree, *dres;
  int help;
} identify_args;

static int identify_options(identify_args *a, char *name, size_t len, prru_diff_options *dopt, double *vs)
{
  if (!a->data || !a->out) {
    prru_cli_error("identify", "--data and --out are required (see 'prru identify --help')");
    return 2;
  }
  if (strcmp(a->out, "-") == 0 && (!a->report || strcmp(a->report, "-") == 0)) {
    prru_cli_error("identify", "--out - and the report would both go to stdout: give --report FILE");
    return 2;
  }
  if (a->report && strcmp(a->report, "-") != 0 &&
      (strcmp(a->report, a->out) == 0 || prru_cli_same_file(a->report, a->out))) {
    prru_cli_error("identify", "--report %s and --out %s are the same file", a->report, a->out);
    return 2;
  }
  if (prru_cli_refuse_same_file("identify", "data", a->data, "out", a->out) ||
      prru_cli_refuse_same_file("identify", "data", a->data, "report", a->report))
    return 2;
  char derived[PRRU_MODEL_NAME_MAX + 1];
  prru_model_name_derive(prru_cli_model()->mech->name, "_id", derived);
  snprintf(name, len, "%s", derived);
  if (a->name) {
    if (!prru_model_name_valid(a->name)) {
      prru_cli_error("identify", "--name: '%s' must be a lower-case C identifier of at most 16 characters",
                     a->name);
      return 2;
    }
    snprintf(name, len, "%s", a->name);
  }
  prru_diff_options_default(dopt);
  if (a->window && parse_count("identify", "window", a->window, 1, PRRU_DIFF_MAX_HALF, &dopt->half_width))
    return 2;
  if (a->degree && parse_count("identify", "degree", a->degree, 2, PRRU_DIFF_MAX_DEGREE, &dopt->degree)) return 2;
  if (dopt->degree > 2 * dopt->half_width) {
    prru_cli_error("identify", "--degree %d needs --window of at least %d", dopt->degree, (dopt->degree + 1) / 2);
    return 2;
  }
  return coulomb_velocity("identify", a->vs, vs);
}

/* --d-resolution: the encoders' resolution R (m, > 0), 0 when not given. */
static int d_resolution(const identify_args *a, double *r)
{
  *r = 0;
  if (!a->dres) return 0;
  if (prru_cli_number("identify", "d-resolution", a->dres, r)) return 2;
  if (!(*r > 0)) {
    prru_cli_error("identify", "--d-resolution: %s must be positive (m)", a->dres);
    return 2;
  }
  return 0;
}

/* Fit and outputs once the data are read; the exit status. */
static int identify_run(const identify_args *a, const char *name, const ident_data *D, prru_base *b)
{
  const prru_model *m = prru_cli_model();
  prru_identification *r = malloc(sizeof *r);
  static const char fmt[] = "Identified by prru identify from %s (prior: model %s)";
  const size_t len = sizeof fmt + strlen(a->data) + strlen(m->mech->name);
  char *desc = malloc(len);
  if (!r || !desc) {
    free(r), free(desc);
    prru_cli_error("identify", "out of memory");
    return 1;
  }
  snprintf(desc, len, fmt, a->data, m->mech->name);
  const int st = prru_identify_model(m, b, D->n, D->q, D->qd, D->qdd, D->fd, name, desc, r);
  free(desc);
  if (prru_cli_interrupted) {
    prru_cli_error("identify", "interrupted (%s) during the fit of %s; nothing written",
                   prru_cli_signal_name(), a->data);
    free(r->text), free(r);
    return prru_cli_exit_interrupted();
  }
  int rc = 0;
  prru_cli_out ro;
  /* The report once a consistent fit exists, also when the data contradict physics. */
  if (r->stage >= PRRU_IDENTIFY_PHYSICS) {
    if (prru_cli_out_open(&ro, "identify", a->report)) rc = 1;
    if (!rc) {
      write_report(&ro, b, &r->fit, r->prior, &r->options, &r->consistent, r->pi0, r->pi);
      if (prru_cli_out_close(&ro, !ro.err)) rc = 1;
    }
  }
  if (!rc && st != PRRU_OK) {
    if (r->stage == PRRU_IDENTIFY_FIT && r->bad >= 0)
      prru_cli_error("identify", "%s: data row %d (t = %g): %s; nothing written", a->data, r->bad + 1,
                     D->t[r->bad], prru_strerror(st));
    else if (r->stage == PRRU_IDENTIFY_FIT)
      prru_cli_error("identify", "%s: %s; nothing written", a->data, r->msg);
    else if (r->stage == PRRU_IDENTIFY_PHYSICS && D->differentiated)
      /* Differentiated rates carry a truncation error the covariance does
       * not hold: with quantised encoders a too narrow window alone
       * produces this refusal (docs/guide.md, measurements). */
      prru_cli_error("identify", "%s; or else qd and qdd were differentiated from q (--window %d --degree %d), "
                     "whose error the covariance does not hold: try the window 'prru measure' suggests for a "
                     "simulated run of this motion (a wider window for quantised encoders); %s not written (see "
                     "the report)", r->msg, D->dopt.half_width, D->dopt.degree, a->out);
    else
      prru_cli_error("identify", "%s; %s not written%s", r->msg, a->out,
                     r->stage == PRRU_IDENTIFY_PHYSICS ? " (see the report)" : "");
    rc = 1;
  }
  prru_cli_out mo;
  if (!rc && prru_cli_out_open(&mo, "identify", a->out)) rc = 1;
  if (!rc) {
    prru_cli_out_write(&mo, r->text, strlen(r->text));
    prru_cli_out_line(&mo);
    if (prru_cli_out_close(&mo, !mo.err)) rc = 1;
  }
  if (!rc)
    fprintf(stderr, "identify: %d base parameters from %d samples, residual sigma %.6g N, condition number "
                    "%.6g; model %s written to %s\n", b->nbase, D->n, r->fit.sigma, r->fit.cond, name, a->out);
  free(r->text), free(r);
  return rc;
}

int prru_cmd_identify(int argc, char **argv)
{
  identify_args a;
  memset(&a, 0, sizeof a);
  prru_cli_option opts[] = {{"data", 1, &a.data, NULL},     {"out", 1, &a.out, NULL},
                            {"report", 1, &a.report, NULL}, {"name", 1, &a.name, NULL},
                            {"coulomb-velocity", 1, &a.vs, NULL}, {"window", 1, &a.window, NULL},
                            {"degree", 1, &a.degree, NULL}, {"d-resolution", 1, &a.dres, NULL},
                            {"help", 0, NULL, &a.help}};
  if (prru_cli_parse("identify", argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  if (a.help) {
    const int nact = prru_cli_model()->mech->nact;
    char dn[256], fn[256];
    printf(identify_help, prru_cli_names(fn, sizeof fn, "fd", nact, ","), prru_cli_names(dn, sizeof dn, "d", nact, ","));
    return 0;
  }
  char name[32];
  prru_diff_options dopt;
  double vs;
  double dres;
  int rc = identify_options(&a, name, sizeof name, &dopt, &vs);
  if (!rc) rc = d_resolution(&a, &dres);
  if (rc) return rc;
  ident_data D;
  /* A large file takes a while: a signal meanwhile is reported. */
  prru_cli_catch_signals();
  rc = read_data(a.data, &dopt, dres, &D);
  int irc = prru_cli_read_interrupted("identify", "data", a.data);
  if (rc || irc) {
    data_free(&D);
    return irc ? irc : rc;
  }
  prru_model m = *prru_cli_model();
  prru_base *b = NULL;
  if (base_or_fail("identify", &m, vs, &b))
    rc = 1;
  else
    rc = identify_run(&a, name, &D, b);
  free(b);
  data_free(&D);
  return rc;
}
