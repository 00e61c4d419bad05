/* prru measure: a simulated run as a prototype's sensors would report it
 * (runtime/include/prru_measure.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru_measure.h"

static const char measure_help[] =
    "usage: prru measure --run FILE.csv --out FILE.csv [--rate HZ]\n"
    "                    [--d-resolution M] [--force-noise N] [--seed N]\n"
    "Turns a simulated run (a CSV with t, %s and %s, as 'prru track'\n"
    "and 'prru simulate' write) into what the robot's sensors would report:\n"
    "the slider positions through encoders of resolution M (m per count:\n"
    "d = M round(d / M), an error uniform in +-M/2), the actuator forces with\n"
    "white Gaussian noise of standard deviation N (N), sampled at HZ (every row\n"
    "at t_0 + k / HZ; the run's rows must fall on that clock; default: every\n"
    "row). The noise comes from a generator seeded by --seed (default 1): the\n"
    "same seed gives the same file. Defaults: exact positions and forces.\n"
    "Writes t, %s, %s: no pose, velocity or acceleration columns, so\n"
    "'prru identify --data FILE' recovers q by forward kinematics and\n"
    "differentiates it, as it would a real robot's log.\n"
    "Differentiation: when the run has the exact accelerations qdd1..3 ('prru\n"
    "track' logs the plant's), every window 2W+1 (W = 1..%d) and degree 2 or 4\n"
    "of identify's differentiation is tried on the measured sliders, and the\n"
    "one whose qdd is nearest the exact one is reported (stderr and a comment\n"
    "line: '--window W --degree P' to give identify, with '--d-resolution M'\n"
    "for quantised sliders, its error and the default's, as max over q1..q3\n"
    "of RMS(qdd error) / RMS(qdd) over every ceil(rows / 1000)-th row).\n"
    "Exit 2 for bad options or a malformed run, 1 when a measured row has no\n"
    "pose. The output is built aside and renamed: nothing is half-written.\n";

typedef struct {
  const char *run, *out, *rate, *res, *noise, *seed;
  int help;
} measure_args;

static int measure_options(const measure_args *a, prru_measure_options *o)
{
  prru_measure_options_default(o);
  const char *const text[3] = {a->rate, a->res, a->noise};
  const char *const name[3] = {"rate", "d-resolution", "force-noise"};
  double *const val[3] = {&o->rate, &o->d_resolution, &o->force_sigma};
  for (int k = 0; k < 3; k++) {
    if (!text[k]) continue;
    if (prru_cli_number("measure", name[k], text[k], val[k])) return 2;
    if (!(*val[k] > 0)) {
      prru_cli_error("measure", "--%s: %s must be positive (leave the option out for %s)", name[k], text[k],
                     k == 0 ? "every row" : "exact values");
      return 2;
    }
  }
  if (a->seed) {
    double s;
    if (prru_cli_number("measure", "seed", a->seed, &s)) return 2;
    if (!(s >= 0 && s <= 4294967295.0 && s == floor(s))) {
      prru_cli_error("measure", "--seed: '%s' is not a whole number from 0 to 4294967295", a->seed);
      return 2;
    }
    o->seed = (unsigned long)s;
  }
  return 0;
}

/* The run's columns t, d1..N, fd1..N (required) and qdd1..3 (optional:
 * cq[0] < 0 when absent); 0 or 2 after naming the first one missing. */
static int run_columns(const char *path, const prru_table *t, int *ct, int *cd, int *cf, int *ca)
{
  char name[16];
  const int nact = prru_cli_model()->mech->nact;
  *ct = prru_table_column(t, "t");
  if (*ct < 0) {
    prru_cli_error("measure", "--run %s: missing column 't'", path);
    return 2;
  }
  for (int k = 0; k < nact; k++) {
    snprintf(name, sizeof name, "d%d", k + 1);
    cd[k] = prru_table_column(t, name);
    if (cd[k] < 0) break;
    snprintf(name, sizeof name, "fd%d", k + 1);
    cf[k] = prru_table_column(t, name);
    if (cf[k] < 0) break;
  }
  for (int k = 0; k < nact; k++)
    if (cd[k] < 0 || cf[k] < 0) {
      prru_cli_error("measure", "--run %s: missing column '%s%d' (a run has t, d1..%d and fd1..%d)", path,
                     cd[k] < 0 ? "d" : "fd", k + 1, nact, nact);
      return 2;
    }
  int nq = 0;
  for (int k = 0; k < 3; k++) {
    snprintf(name, sizeof name, "qdd%d", k + 1);
    ca[k] = prru_table_column(t, name);
    nq += ca[k] >= 0;
  }
  if (nq != 0 && nq != 3) {
    prru_cli_error("measure", "--run %s: has %d of the columns qdd1..3: all or none", path, nq);
    return 2;
  }
  return 0;
}

/* The sampled rows: times, sliders, forces, exact qdd (NULL when absent). */
typedef struct {
  int n;
  double *t, *d, *fd, *qdd;
} measured;

static void measured_free(measured *s) { free(s->t), free(s->d), free(s->fd), free(s->qdd); }

static int take_rows(const prru_table *t, const int *idx, int n, int ct, const int *cd, const int *cf,
                     const int *ca, measured *s)
{
  const int nact = prru_cli_model()->mech->nact;
  s->n = n;
  s->t = malloc(sizeof(double) * (size_t)n);
  s->d = malloc(sizeof(double) * (size_t)nact * (size_t)n);
  s->fd = malloc(sizeof(double) * (size_t)nact * (size_t)n);
  s->qdd = ca[0] >= 0 ? malloc(sizeof(double) * 3 * (size_t)n) : NULL;
  if (!s->t || !s->d || !s->fd || (ca[0] >= 0 && !s->qdd)) return 1;
  for (int i = 0; i < n; i++) {
    const double *row = t->data + (size_t)idx[i] * (size_t)t->ncols;
    s->t[i] = row[ct];
    for (int k = 0; k < nact; k++) s->d[nact * i + k] = row[cd[k]], s->fd[nact * i + k] = row[cf[k]];
    if (s->qdd)
      for (int k = 0; k < 3; k++) s->qdd[3 * i + k] = row[ca[k]];
  }
  return 0;
}

static int write_measured(const measure_args *a, const prru_measure_options *o, const measured *s,
                          const prru_diff_choice *c, const char *no_choice)
{
  prru_cli_out out;
  if (prru_cli_out_open(&out, "measure", a->out)) return 1;
  prru_cli_out_comment(&out);
  prru_cli_out_comment_line(&out, "measure: %d samples of %s; rate %s, d resolution %.9g m, force noise sigma "
                            "%.9g N, seed %lu",
                            s->n, a->run, o->rate > 0 ? a->rate : "every row", o->d_resolution, o->force_sigma,
                            o->seed);
  char dres[64] = "";
  if (o->d_resolution > 0) snprintf(dres, sizeof dres, " --d-resolution %.9g", o->d_resolution);
  if (c)
    prru_cli_out_comment_line(&out, "for identify: --window %d --degree %d%s (qdd error %.3g of its RMS; the "
                              "default --window 4 --degree 4: %.3g)",
                              c->best.half_width, c->best.degree, dres, c->best_error, c->default_error);
  else
    prru_cli_out_comment_line(&out, "differentiation not assessed: %s", no_choice);
  const int nact = prru_cli_model()->mech->nact;
  char dn[256], fn[256];
  prru_cli_out_printf(&out, "t,%s,%s\n", prru_cli_names(dn, sizeof dn, "d", nact, ","),
                      prru_cli_names(fn, sizeof fn, "fd", nact, ","));
  prru_cli_out_line(&out);
  for (int i = 0; i < s->n; i++) {
    prru_cli_out_printf(&out, "%.17g", s->t[i]);
    prru_cli_out_numbers(&out, s->d + (size_t)nact * (size_t)i, nact);
    prru_cli_out_numbers(&out, s->fd + (size_t)nact * (size_t)i, nact);
    prru_cli_out_printf(&out, "\n");
    prru_cli_out_row(&out);
  }
  return prru_cli_out_close(&out, 1);
}

int prru_cmd_measure(int argc, char **argv)
{
  measure_args a;
  memset(&a, 0, sizeof a);
  prru_cli_option opts[] = {{"run", 1, &a.run, NULL},           {"out", 1, &a.out, NULL},
                            {"rate", 1, &a.rate, NULL},         {"d-resolution", 1, &a.res, NULL},
                            {"force-noise", 1, &a.noise, NULL}, {"seed", 1, &a.seed, NULL},
                            {"help", 0, NULL, &a.help}};
  if (prru_cli_parse("measure", argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  const int nact = prru_cli_model()->mech->nact;
  char dn[256], fn[256];
  prru_cli_names(dn, sizeof dn, "d", nact, ",");
  prru_cli_names(fn, sizeof fn, "fd", nact, ",");
  if (a.help) {
    printf(measure_help, dn, fn, dn, fn, PRRU_DIFF_MAX_HALF);
    return 0;
  }
  if (!a.run || !a.out) {
    prru_cli_error("measure", "--%s is required (see 'prru measure --help')", a.run ? "out" : "run");
    return 2;
  }
  if (prru_cli_refuse_same_file("measure", "run", a.run, "out", a.out)) return 2;
  prru_measure_options o;
  if (measure_options(&a, &o)) return 2;
  char msg[700];
  prru_table t;
  prru_cli_catch_signals();
  int st = prru_table_read(&t, a.run, msg, sizeof msg);
  int irc = prru_cli_read_interrupted("measure", "run", a.run);
  if (irc || st != PRRU_OK) {
    if (st == PRRU_OK) prru_table_free(&t);
    if (!irc) prru_cli_error("measure", "--run %s", msg);
    return irc ? irc : 2;
  }
  int ct, cd[PRRU_MAX_ACT], cf[PRRU_MAX_ACT], ca[3];
  int rc = run_columns(a.run, &t, &ct, cd, cf, ca);
  double *times = rc ? NULL : malloc(sizeof(double) * (size_t)t.nrows);
  int *idx = rc ? NULL : malloc(sizeof(int) * (size_t)t.nrows), n = 0;
  measured s;
  memset(&s, 0, sizeof s);
  if (!rc && (!times || !idx)) {
    prru_cli_error("measure", "out of memory for %d rows", t.nrows);
    rc = 1;
  }
  for (int i = 0; !rc && i < t.nrows; i++) {
    times[i] = t.data[(size_t)i * (size_t)t.ncols + (size_t)ct];
    if (i > 0 && !(times[i] > times[i - 1])) {
      prru_cli_error("measure", "--run %s: data row %d: t = %g is not after the previous row's", a.run, i + 1,
                     times[i]);
      rc = 2;
    }
  }
  if (!rc && prru_measure_rows(times, t.nrows, &o, idx, &n, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error("measure", "--run %s: --rate %s: %s", a.run, a.rate, msg);
    rc = 2;
  }
  if (!rc && take_rows(&t, idx, n, ct, cd, cf, ca, &s)) {
    prru_cli_error("measure", "out of memory for %d rows", n);
    rc = 1;
  }
  free(times);
  free(idx);
  prru_table_free(&t);
  if (!rc && (st = prru_measure_apply(&o, n, nact, s.d, s.fd, msg, sizeof msg)) != PRRU_OK) {
    prru_cli_error("measure", "%s", msg);
    rc = prru_cli_exit_for(st);
  }
  prru_diff_choice c;
  const char *no_choice = "the run has no qdd1..3 columns (prru track writes the plant's)";
  int have_choice = 0;
  if (!rc && s.qdd) {
    st = prru_measure_best_diff(prru_cli_model(), n, s.t, s.d, s.qdd, &c, msg, sizeof msg);
    if (st == PRRU_OK) {
      have_choice = 1;
    } else if (st == PRRU_EINPUT) {
      no_choice = msg;
    } else {
      prru_cli_error("measure", "--run %s: %s", a.run, msg);
      rc = prru_cli_exit_for(st);
    }
  }
  if (!rc) rc = write_measured(&a, &o, &s, have_choice ? &c : NULL, no_choice);
  if (!rc) {
    if (have_choice)
      fprintf(stderr, "prru measure: %d samples; for identify: --window %d --degree %d%s (qdd error %.3g of its "
                      "RMS; the default --window 4 --degree 4: %.3g)\n",
              n, c.best.half_width, c.best.degree, o.d_resolution > 0 ? " --d-resolution R" : "", c.best_error,
              c.default_error);
    else
      fprintf(stderr, "prru measure: %d samples; differentiation not assessed: %s\n", n, no_choice);
  }
  measured_free(&s);
  return rc;
}
