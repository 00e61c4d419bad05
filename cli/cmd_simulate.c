/* prru simulate: forward dynamics integrated with GSL, samples as CSV. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "progress.h"
#include "prru.h"

void prru_cli_csv_header(prru_cli_csv *c)
{
  const prru_mechanism *me = prru_cli_model()->mech;
  char names[256];
  prru_cli_out_comment(c->out);
  prru_cli_out_printf(c->out, "t,q1,q2,q3,qd1,qd2,qd3,%s",
                      prru_cli_names(names, sizeof names, "d", me->nact, ","));
  if (c->reactions)
    for (int i = 0; i < me->nlambda; i++) prru_cli_out_printf(c->out, ",%s", me->lambda_labels[i]);
  prru_cli_out_printf(c->out, ",qdd1,qdd2,qdd3,%s", prru_cli_names(names, sizeof names, "fd", me->nact, ","));
  prru_cli_out_printf(c->out, ",fp1,fp2,fp3,mp1,mp2,mp3,T,V\n");
  prru_cli_out_line(c->out);
}

int prru_cli_csv_row(const prru_sample *s, void *ctx)
{
  prru_cli_csv *c = ctx;
  const prru_mechanism *me = prru_cli_model()->mech;
  prru_loads l;
  prru_schedule_eval(c->loads, s->t, &l);
  /* The whole row is formatted before any of it is written. */
  prru_cli_out_printf(c->out, "%.17g", s->t);
  prru_cli_out_numbers(c->out, s->q, 3);
  prru_cli_out_numbers(c->out, s->qd, 3);
  prru_cli_out_numbers(c->out, s->d, me->nact);
  if (c->reactions) prru_cli_out_numbers(c->out, s->lambda, me->nlambda);
  prru_cli_out_numbers(c->out, s->qdd, 3);
  prru_cli_out_numbers(c->out, l.fd, me->nact);
  prru_cli_out_numbers(c->out, l.fp, 3);
  prru_cli_out_numbers(c->out, l.mp, 3);
  prru_cli_out_printf(c->out, ",%.17g,%.17g\n", s->T, s->V);
  return prru_cli_out_row(c->out) == 0 ? PRRU_OK : PRRU_EIO;
}

/* The CSV writer and the progress report, per sample. */
typedef struct {
  prru_cli_csv csv;
  prru_cli_progress bar;
  double t_end;
} sim_output;

static int on_sample(const prru_sample *s, void *ctx)
{
  sim_output *so = ctx;
  int rc = prru_cli_csv_row(s, &so->csv);
  prru_cli_progress_update(&so->bar, s->t, so->t_end);
  return rc;
}

/* %s: d names, %d: the model's nlambda, %s: the first label, %s: joint names in
 * column order, %s: fd names, %s: fd names. */
static const char simulate_help[] =
    "usage: prru simulate [--scenario paper|FILE] [--q0 ..] [--qd0 ..] [--fd ..]\n"
    "                     [--fp ..] [--mp ..] [--harmonic AMP,OMEGA]\n"
    "                     [--loads FILE.csv] [--t-end S] [--dt S]\n"
    "                     [--stepper rk8pd|rkf45|rkck|msbdf] [--atol X] [--rtol X]\n"
    "                     [--h0 S] [--max-steps N] [--no-reactions] [--progress]\n"
    "                     [--out FILE.csv|-]\n"
    "Integrates M qdd + h = G + J_d^T fd + J_T,P^T fp + J_R,P^T mp + passive drive\n"
    "forces from (q0, qd0) with an adaptive integrator (--stepper: rk8pd, the\n"
    "Runge-Kutta Prince-Dormand 8(9) pair; rkf45 Fehlberg 4(5); rkck Cash-Karp\n"
    "4(5); msbdf, a multistep BDF method for stiff runs) and writes a CSV: a\n"
    "first line `# prru VERSION model NAME (FILE, sha256 HASH, KERNELS kernels)`,\n"
    "the header, then one row per sample (every dt, last at t-end):\n"
    "  t,q1,q2,q3,qd1,qd2,qd3,%s,\n"
    "  the %d joint reaction coordinates (columns JOINT_COMPONENT, e.g. %s,\n"
    "  joint by joint in the order %s;\n"
    "  see 'prru eval --help'),\n"
    "  qdd1..3, %s, fp1..3, mp1..3, T, V (J).\n"
    "A scenario file has `key = value` lines (q0 qd0 fd fp mp harmonic loads\n"
    "t_end dt stepper atol rtol h0 max_steps); options override it.\n"
    "`--scenario paper` is the paper's section 4.3 study: q0 = (0, pi/6, -0.8),\n"
    "fd = (%s) N, fp = 50 (sin 4 pi t, -cos 4 pi t, 0) N%s.\n"
    "`--harmonic A,W` adds fp = A (sin W t, -cos W t, 0); `--loads` reads a table\n"
    "t,%s[,fp1..3[,mp1..3]] (linear interpolation).\n"
    "Defaults: zero state and loads, 1 s, dt 1 ms, rk8pd, atol = rtol = 1e-10.\n"
    "Each tolerance is 0 (off) or at least 100 eps = 2.2e-14 (eps the double-\n"
    "precision rounding unit): a smaller one\n"
    "cannot be met in double precision. --max-steps bounds the integrator's steps\n"
    "between two samples (default 100000); a run that needs more stops with exit 1,\n"
    "keeping its rows.\n"
    "Without --out (or with --out -) the CSV goes to stdout. --out FILE is built\n"
    "as FILE.partial-XXXXXX beside it and renamed onto FILE at the end, so FILE\n"
    "keeps its old contents until then, and a run stopped before its first row\n"
    "(or by a write error) leaves it unchanged.\n"
    "Progress: a bar on stderr when it is a terminal, for --progress or a run of\n"
    "2000 samples or more into a file; with --progress and stderr not a terminal\n"
    "(a log), a line per 10 %%.\n"
    "A run that leaves the workspace, meets a singular J_d or fails a step stops\n"
    "with a message and exit 1; SIGINT (Ctrl-C), SIGTERM or SIGHUP stop it with\n"
    "exit 130, 143 or 129. Either way every row computed so far is kept, and the\n"
    "file ends with a complete row. A write error (disk full) exits 1 with the\n"
    "reason.\n";

int prru_cmd_simulate(int argc, char **argv)
{
  const char *scen = NULL, *q0s = NULL, *qd0s = NULL, *fds = NULL, *fps = NULL, *mps = NULL,
             *harm = NULL, *loads = NULL, *tend = NULL, *dts = NULL, *stepper = NULL,
             *atol = NULL, *rtol = NULL, *h0 = NULL, *out = NULL, *maxs = NULL;
  int help = 0, no_reactions = 0, progress = 0;
  prru_cli_option opts[] = {
      {"scenario", 1, &scen, NULL}, {"q0", 1, &q0s, NULL},        {"qd0", 1, &qd0s, NULL},
      {"fd", 1, &fds, NULL},        {"fp", 1, &fps, NULL},        {"mp", 1, &mps, NULL},
      {"harmonic", 1, &harm, NULL}, {"loads", 1, &loads, NULL},   {"t-end", 1, &tend, NULL},
      {"dt", 1, &dts, NULL},        {"stepper", 1, &stepper, NULL}, {"atol", 1, &atol, NULL},
      {"rtol", 1, &rtol, NULL},     {"h0", 1, &h0, NULL},         {"out", 1, &out, NULL},
      {"max-steps", 1, &maxs, NULL},
      {"no-reactions", 0, NULL, &no_reactions}, {"progress", 0, NULL, &progress},
      {"help", 0, NULL, &help}};
  if (prru_cli_parse("simulate", argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  const prru_mechanism *me = prru_cli_model()->mech;
  if (help) {
    char dn[256], fdn[256], joints[16 * PRRU_MAX_JOINT + 1];
    size_t used = 0;
    joints[0] = '\0';
    for (int j = 0; j < me->njoint && used < sizeof joints; j++)
      used += (size_t)snprintf(joints + used, sizeof joints - used, "%s%.12s", j ? " " : "", me->joint[j].name);
    prru_cli_names(dn, sizeof dn, "d", me->nact, ",");
    prru_cli_names(fdn, sizeof fdn, "fd", me->nact, ",");
    printf(simulate_help, dn, me->nlambda, me->lambda_labels[0], joints, fdn, prru_cli_paper_fd_text(),
           me->nact > 3 ? "\n(the redundant actuator gets limb 3's force, see 'prru paper --help')" : "", fdn);
    return 0;
  }
  prru_scenario s;
  char msg[600];
  if (scen && strcmp(scen, "paper") == 0) {
    prru_scenario_paper(&s);
  } else if (scen) {
    if (prru_scenario_read(prru_cli_model(), &s, scen, msg, sizeof msg) != PRRU_OK) {
      prru_cli_error("simulate", "--scenario %s", msg);
      return 2;
    }
  } else {
    prru_scenario_parse(prru_cli_model(), &s, "", 0, "defaults", NULL, msg, sizeof msg);
  }
  int bad = 0;
  if (q0s) bad |= prru_cli_numbers("simulate", "q0", q0s, s.q0, 3);
  if (qd0s) bad |= prru_cli_numbers("simulate", "qd0", qd0s, s.qd0, 3);
  if (fds) bad |= prru_cli_numbers("simulate", "fd", fds, s.loads.base.fd, me->nact);
  if (fps) bad |= prru_cli_numbers("simulate", "fp", fps, s.loads.base.fp, 3);
  if (mps) bad |= prru_cli_numbers("simulate", "mp", mps, s.loads.base.mp, 3);
  if (tend) bad |= prru_cli_number("simulate", "t-end", tend, &s.opt.t_end);
  if (dts) bad |= prru_cli_number("simulate", "dt", dts, &s.opt.dt_out);
  if (atol) bad |= prru_cli_number("simulate", "atol", atol, &s.opt.abs_tol);
  if (rtol) bad |= prru_cli_number("simulate", "rtol", rtol, &s.opt.rel_tol);
  if (h0) bad |= prru_cli_number("simulate", "h0", h0, &s.opt.h0);
  if (maxs) {
    double v;
    if (prru_cli_number("simulate", "max-steps", maxs, &v)) {
      bad = 2;
    } else if (!(v >= 1 && v <= 1e12 && v == floor(v))) {
      prru_cli_error("simulate", "--max-steps '%s': must be a whole number from 1 to 1e12", maxs);
      bad = 2;
    } else {
      s.opt.max_steps = (long)v;
    }
  }
  if (stepper && prru_stepper_parse(stepper, &s.opt.stepper) != PRRU_OK) {
    prru_cli_error("simulate", "--stepper: '%s' is not one of rk8pd, rkf45, rkck, msbdf", stepper);
    bad = 2;
  }
  /* The library's checks, with its member names turned into the options. */
  static const char *const option_of[][2] = {{"t_end", "t-end"}, {"dt_out", "dt"}, {"abs_tol", "atol"},
                                             {"rel_tol", "rtol"}, {"h0", "h0"}, {"max_steps", "max-steps"},
                                             {"stepper", "stepper"}};
  const char *field = NULL;
  if (!bad && prru_sim_options_check(&s.opt, &field, msg, sizeof msg) != PRRU_OK) {
    const char *opt = "scenario";
    for (size_t k = 0; field && k < sizeof option_of / sizeof *option_of; k++)
      if (strcmp(field, option_of[k][0]) == 0) opt = option_of[k][1];
    prru_cli_error("simulate", "--%s: %s", opt, msg);
    bad = 2;
  }
  if (harm && loads) {
    prru_cli_error("simulate", "--harmonic and --loads exclude each other");
    bad = 2;
  }
  if (harm) {
    double v[2];
    if (prru_cli_numbers("simulate", "harmonic", harm, v, 2)) {
      bad = 2;
    } else {
      prru_schedule_free(&s.loads);
      s.loads.kind = PRRU_LOAD_HARMONIC;
      s.loads.amp = v[0];
      s.loads.omega = v[1];
    }
  }
  if (loads && !bad) {
    prru_load_schedule t;
    if (prru_schedule_read_csv(prru_cli_model(), &t, loads, msg, sizeof msg) != PRRU_OK) {
      prru_cli_error("simulate", "--loads %s", msg);
      bad = 2;
    } else {
      t.base = s.loads.base;
      prru_schedule_free(&s.loads);
      s.loads = t;
    }
  }
  /* Check everything the run needs before the output is created: the
   * initial state must be regular and its dynamics and energies finite. */
  prru_model m = *prru_cli_model();
  prru_data *d = bad ? NULL : malloc(sizeof *d);
  if (!bad && !d) {
    prru_cli_error("simulate", "out of memory");
    bad = 1;
  }
  if (!bad) {
    s.opt.loads = &s.loads;
    char state[200];
    snprintf(state, sizeof state, "initial state q0 = (%.9g, %.9g, %.9g), qd0 = (%.9g, %.9g, %.9g)",
             s.q0[0], s.q0[1], s.q0[2], s.qd0[0], s.qd0[1], s.qd0[2]);
    int st = prru_check_regular(&m, d, s.q0, NULL);
    if (st != PRRU_OK) {
      prru_cli_error("simulate", "initial q0 = (%.9g, %.9g, %.9g): %s", s.q0[0], s.q0[1], s.q0[2],
                     prru_strerror(st));
      bad = 1;
    }
    prru_loads l0;
    double qdd[3], T, V;
    prru_schedule_eval(&s.loads, 0.0, &l0);
    if (!bad && (st = prru_forward_dynamics(&m, d, s.q0, s.qd0, &l0, qdd)) != PRRU_OK) {
      /* q0 is regular: what fails is the arithmetic (velocities or loads
       * so large that it overflows). */
      if (st == PRRU_EINPUT)
        prru_cli_error("simulate", "%s: the dynamics overflow (velocities or loads too large)",
                       state);
      else
        prru_cli_error("simulate", "%s: %s", state, prru_strerror(st));
      bad = 1;
    }
    if (!bad && prru_energies(&m, s.q0, s.qd0, &T, &V) != PRRU_OK) {
      prru_cli_error("simulate", "%s: the kinetic energy overflows (velocities too large)", state);
      bad = 1;
    }
  }
  free(d);
  if (bad) {
    prru_scenario_free(&s);
    return bad == 1 ? 1 : 2;
  }
  /* Handlers first, so that no signal can leave the partial file behind. */
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, "simulate", out)) {
    prru_scenario_free(&s);
    return 1;
  }
  const char *name = o.name;
  int in_place = o.tmp_path == NULL;
  sim_output so = {{&o, &s.loads, !no_reactions}, {0}, s.opt.t_end};
  /* A bar by default only when the CSV does not go to the same terminal. */
  prru_cli_progress_init(&so.bar, "simulate", NULL, progress,
                         out && strcmp(out, "-") != 0 && s.opt.t_end / s.opt.dt_out >= 2000);
  s.opt.reactions = !no_reactions;
  s.opt.on_sample = on_sample;
  s.opt.ctx = &so;
  s.opt.loads = &s.loads;
  s.opt.interrupt = &prru_cli_interrupted;
  prru_cli_csv_header(&so.csv);
  double t_stop;
  int st = prru_simulate(&m, s.q0, s.qd0, &s.opt, &t_stop, msg, sizeof msg);
  if (st != PRRU_OK) prru_cli_progress_end(&so.bar);
  long rows = o.rows;
  /* A write error is reported as such (the runtime only saw the consumer
   * stop); otherwise every row computed is kept, whatever stopped the run. */
  int io = o.err != 0;
  if (prru_cli_out_close(&o, !io && rows > 0)) {
    prru_scenario_free(&s);
    return 1;
  }
  if (st != PRRU_OK) {
    char kept[4200];
    if (rows > 0)
      snprintf(kept, sizeof kept, "%ld samples written to %s", rows, name);
    else
      snprintf(kept, sizeof kept, "nothing written%s%s%s", in_place ? "" : "; ",
               in_place ? "" : name, in_place ? "" : " is not changed");
    if (st == PRRU_EINTERRUPTED && prru_cli_interrupted)
      prru_cli_error("simulate", "%s (%s); %s", msg, prru_cli_signal_name(), kept);
    else
      prru_cli_error("simulate", "%s; %s", msg, kept);
  }
  prru_scenario_free(&s);
  return st == PRRU_OK ? 0 : prru_cli_exit_for(st);
}
