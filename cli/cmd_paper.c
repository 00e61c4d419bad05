/* prru paper: the paper's section 4.3 simulation study and its fig. 7
 * workspace map, written as CSVs, gnuplot PNGs and a text summary. */
#define _POSIX_C_SOURCE 200809L /* mkdir, mkdtemp */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "commands.h"
#include "paper.h"
#include "plot.h"
#include "prru.h"

static const char paper_help[] =
    "usage: prru paper --out DIR [--skip-map] [--clip W]\n"
    "Reproduces the paper's studies (Chen et al. 2017, section 4.3 and fig. 7):\n"
    "1 s from q(0) = (0, pi/6, -0.8) m/rad at rest under fd = (50, 40, 25) N and\n"
    "the platform force fp = 50 (sin 4 pi t, -cos 4 pi t, 0) N, then the w_R map.\n"
    "Writes DIR/paper_sim.csv (columns as `prru simulate`), fig_q.png, fig_d.png\n"
    "(q and d over time), the paper's figs. 4-6: fig4_u_joint_forces.png,\n"
    "fig5_p_joint_forces.png, fig6_p_joint_moments.png (joint reactions), its\n"
    "fig. 7: fig7_surface.png, fig7_contour.png, fig7a_ellipses.png (w_R), and\n"
    "DIR/summary.txt. Needs gnuplot for the PNGs.\n"
    "The files are built in DIR/paper.partial-XXXXXX and moved into DIR only\n"
    "when the run is complete: a run that fails or is stopped (SIGINT, SIGTERM,\n"
    "SIGHUP: exit 130, 143, 129) leaves DIR as it was. Without gnuplot the\n"
    "CSVs, scripts and summary are moved in, the PNGs of an earlier run removed,\n"
    "and the exit status is 1. --skip-map leaves earlier fig7_* files alone.\n"
    "--clip W: fig. 7's colours and surface stop at w_R = W (default: the 99th\n"
    "percentile of w_R over the map; the colour key says which).\n"
    "Every file names the model it computes with; with a model other than the\n"
    "paper's (models/3prru_paper.json) the study runs on that model and a warning\n"
    "says that the figures are not the paper's results.\n"
    "%s";

/* The loads of a redundant model (also `prru simulate --scenario paper`). */
static const char paper_help_redundant[] =
    "This model has %d actuators; the paper's loads name three. Limb 4 mirrors\n"
    "limb 3 and gets its force: fd = (%s) N. Distributing the paper's\n"
    "generalized actuation tau = J_d^T (50, 40, 25, 0) over the four sliders\n"
    "(least-norm or otherwise) is no alternative: every such fd moves the robot\n"
    "exactly as (50, 40, 25, 0) does, leaving limb 4's own weight unsupported;\n"
    "for models/4prru.json (3.5 kg in limb 4) the platform then leaves the\n"
    "workspace at t = 0.48 s, while with fd4 = 25 N it stays inside for the\n"
    "whole second. The joint reactions are the least-norm solution (see\n"
    "'prru eval --help').\n";

/* Keeps the samples in memory (for the summary) and writes the CSV. */
typedef struct {
  prru_cli_csv csv;
  prru_sample first, last;
  double work;         /* integral of prru_power's load power (trapezoid) */
  double work_passive; /* and of its passive power, the drives' */
  double prev_power, prev_passive;
  double max_abs[PRRU_MAX_LAMBDA];
  long n;
} paper_run;

static int on_sample(const prru_sample *s, void *ctx)
{
  paper_run *r = ctx;
  prru_loads l;
  prru_schedule_eval(r->csv.loads, s->t, &l);
  double power, passive;
  prru_power(prru_cli_model(), s->q, s->qd, &l, &power, &passive);
  if (r->n == 0) {
    r->first = *s;
  } else {
    r->work += 0.5 * (power + r->prev_power) * (s->t - r->last.t);
    r->work_passive += 0.5 * (passive + r->prev_passive) * (s->t - r->last.t);
  }
  r->prev_power = power;
  r->prev_passive = passive;
  r->last = *s;
  for (int i = 0; i < prru_cli_model()->mech->nlambda; i++)
    if (fabs(s->lambda[i]) > r->max_abs[i]) r->max_abs[i] = fabs(s->lambda[i]);
  r->n++;
  return prru_cli_csv_row(s, &r->csv);
}

/* Creates dir unless it is there; *created says which. */
static int make_dir(const char *dir, int *created)
{
  *created = 0;
  if (mkdir(dir, 0777) == 0) {
    *created = 1;
    return 0;
  }
  int e = errno;
  struct stat st;
  if (e == EEXIST && stat(dir, &st) == 0) {
    if (S_ISDIR(st.st_mode)) return 0;
    e = ENOTDIR;
  }
  prru_cli_error("paper", "--out %s: cannot create the directory: %s", dir, strerror(e));
  return 1;
}

/* Removes the regular files in dir (one level: all prru paper and gnuplot
 * write) and dir. */
static void remove_dir(const char *dir)
{
  DIR *d = opendir(dir);
  if (d) {
    struct dirent *e;
    char path[4400];
    while ((e = readdir(d)) != NULL) {
      if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
      snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
      unlink(path);
    }
    closedir(d);
  }
  rmdir(dir);
}

/* Moves every file of stage into out (summary.txt last, so that a summary
 * never describes files that are not there yet); 0 or 1 with a message. */
static int move_files(const char *stage, const char *out)
{
  DIR *d = opendir(stage);
  if (!d) {
    prru_cli_error("paper", "%s: %s", stage, strerror(errno));
    return 1;
  }
  struct dirent *e;
  char from[4400], to[4400];
  int rc = 0, has_summary = 0;
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    if (strcmp(e->d_name, "summary.txt") == 0) {
      has_summary = 1;
      continue;
    }
    snprintf(from, sizeof from, "%s/%s", stage, e->d_name);
    snprintf(to, sizeof to, "%s/%s", out, e->d_name);
    if (rename(from, to) != 0) {
      prru_cli_error("paper", "%s: cannot move into place: %s", to, strerror(errno));
      rc = 1;
    }
  }
  closedir(d);
  if (has_summary && rc == 0) {
    snprintf(from, sizeof from, "%s/summary.txt", stage);
    snprintf(to, sizeof to, "%s/summary.txt", out);
    if (rename(from, to) != 0) {
      prru_cli_error("paper", "%s: cannot move into place: %s", to, strerror(errno));
      rc = 1;
    }
  }
  return rc;
}

/* What gnuplot makes: without gnuplot, earlier copies are removed so that
 * DIR never shows figures of another run. */
static const char *const plot_outputs[] = {"fig_q.png", "fig_d.png", "fig4_u_joint_forces.png",
                                           "fig5_p_joint_forces.png", "fig6_p_joint_moments.png"};
static const char *const fig7_plot_outputs[] = {"fig7_surface.png", "fig7_contour.png",
                                                "fig7a_ellipses.png", "fig7_contours.dat"};

static void remove_stale(const char *out, const char *const *names, int n)
{
  char path[4400];
  for (int i = 0; i < n; i++) {
    snprintf(path, sizeof path, "%s/%s", out, names[i]);
    unlink(path);
  }
}

static void summarize(FILE *f, const paper_run *r, const prru_scenario *s, double t_stop,
                      int is_paper)
{
  const prru_mechanism *me = prru_cli_model()->mech;
  const char *const *labels = me->lambda_labels;
  const prru_sample *a = &r->first, *b = &r->last;
  fprintf(f, "Model: %s%s\n", prru_cli_model_id(),
          is_paper ? ", the paper's" : "; not the paper's model: the results below are this model's");
  fputs("Paper study (section 4.3): q(0) = (0, pi/6, -0.8), fd = (", f);
  for (int i = 0; i < me->nact; i++) fprintf(f, "%s%g", i ? ", " : "", s->loads.base.fd[i]);
  const double w_pi = s->loads.omega / 3.14159265358979323846;
  fprintf(f, ") N,\nfp = %g (sin %g pi t, -cos %g pi t, 0) N, rk8pd at 1e-10, %ld samples to t = %.3f s\n",
          s->loads.amp, w_pi, w_pi, r->n, t_stop);
  if (me->nact > 3)
    fprintf(f, "%d actuators: the paper's loads name three; limb 4 mirrors limb 3 and gets its force "
               "(see prru paper --help); reactions are the least-norm solution\n", me->nact);
  fprintf(f, "q(%.3f)   = (%.10f, %.10f, %.10f) rad, rad, m\n", b->t, b->q[0], b->q[1], b->q[2]);
  fprintf(f, "qd(%.3f)  = (%.10f, %.10f, %.10f)\n", b->t, b->qd[0], b->qd[1], b->qd[2]);
  fprintf(f, "d(%.3f)   = (", b->t);
  for (int i = 0; i < me->nact; i++) fprintf(f, "%s%.10f", i ? ", " : "", b->d[i]);
  fputs(") m\n", f);
  double dE = (b->T + b->V) - (a->T + a->V), W = r->work + r->work_passive;
  fprintf(f, "energy balance: change of T + V = %.9f J, work of fd, fp and mp = %.9f J, of the "
             "drives' damping and friction = %.9f J (trapezoid on the samples), difference %.2e J\n",
          dE, r->work, r->work_passive, dE - W);
  fprintf(f, "peak reaction magnitudes over the run:\n");
  for (int j = 0; j < me->nlambda; j++)
    fprintf(f, "  %-6s %12.4f%s", labels[j], r->max_abs[j], j % 4 == 3 || j == me->nlambda - 1 ? "\n" : "");
}

/* The whole study into stage; an exit status, or PRRU_PLOT_NO_GNUPLOT when
 * everything but the PNGs is there. */
static int run_paper(const char *stage, const char *out, int skip_map, int is_paper, double clip)
{
  char path[4400], shown[4400], msg[600];
  prru_model m = *prru_cli_model();
  prru_scenario s;
  prru_scenario_paper(&s);
  paper_run *r = calloc(1, sizeof *r);
  if (!r) {
    prru_cli_error("paper", "out of memory");
    return 1;
  }
  prru_cli_out o;
  snprintf(path, sizeof path, "%s/paper_sim.csv", stage);
  snprintf(shown, sizeof shown, "%s/paper_sim.csv", out);
  if (prru_cli_out_open(&o, "paper", path)) {
    free(r);
    return 1;
  }
  o.name = shown;
  r->csv.out = &o;
  r->csv.loads = &s.loads;
  r->csv.reactions = 1;
  s.opt.loads = &s.loads;
  s.opt.reactions = 1;
  s.opt.on_sample = on_sample;
  s.opt.ctx = r;
  s.opt.interrupt = &prru_cli_interrupted;
  prru_cli_csv_header(&r->csv);
  double t_stop;
  int st = prru_simulate(&m, s.q0, s.qd0, &s.opt, &t_stop, msg, sizeof msg);
  /* A write error is an I/O error, not the "stop" the runtime saw. */
  int rc = prru_cli_out_close(&o, st == PRRU_OK && !o.err);
  if (rc == 0 && st != PRRU_OK) {
    if (st == PRRU_EINTERRUPTED)
      rc = prru_cli_exit_interrupted();
    else {
      prru_cli_error("paper", "simulation: %s", msg);
      rc = 1;
    }
  }
  FILE *sum = NULL;
  if (rc == 0) {
    snprintf(path, sizeof path, "%s/summary.txt", stage);
    sum = fopen(path, "w");
    if (!sum) {
      prru_cli_error("paper", "%s/summary.txt: cannot open for writing: %s", out, strerror(errno));
      rc = 1;
    }
  }
  if (rc == 0) {
    summarize(sum, r, &s, t_stop, is_paper);
    summarize(stdout, r, &s, t_stop, is_paper);
  }
  free(r);
  prru_scenario_free(&s);
  int no_gnuplot = 0;
  if (rc == 0) {
    char *script = prru_plot_paper_sim_script("paper_sim.csv");
    if (!script) {
      prru_cli_error("paper", "out of memory for the plot script");
      rc = 1;
    } else {
      rc = prru_plot_run("paper", stage, out, "paper_plots.gp", script);
    }
    free(script);
    if (rc == PRRU_PLOT_NO_GNUPLOT) {
      no_gnuplot = 1;
      rc = 0;
    }
  }
  if (rc == 0 && prru_cli_interrupted) rc = prru_cli_exit_interrupted();
  if (rc == 0 && !skip_map) {
    rc = prru_paper_fig7(stage, out, sum, clip);
    if (rc == PRRU_PLOT_NO_GNUPLOT) {
      no_gnuplot = 1;
      rc = 0;
    }
  }
  if (sum) {
    errno = 0;
    int bad = fflush(sum) != 0 || ferror(sum);
    int e = errno;
    if (fclose(sum) != 0 && !bad) {
      bad = 1;
      e = errno;
    }
    if (bad && rc == 0) {
      prru_cli_error("paper", "%s/summary.txt: write error: %s", out, e ? strerror(e) : "output lost");
      rc = 1;
    }
  }
  if (rc == 0 && prru_cli_interrupted) rc = prru_cli_exit_interrupted();
  return rc == 0 && no_gnuplot ? PRRU_PLOT_NO_GNUPLOT : rc;
}

int prru_cmd_paper(int argc, char **argv)
{
  const char *out = NULL;
  const char *clip_s = NULL;
  int help = 0, skip_map = 0;
  prru_cli_option opts[] = {{"out", 1, &out, NULL}, {"skip-map", 0, NULL, &skip_map},
                            {"clip", 1, &clip_s, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("paper", argc, argv, opts, 4)) return 2;
  if (help) {
    char extra[sizeof paper_help_redundant + 200] = "";
    const int nact = prru_cli_model()->mech->nact;
    if (nact > 3) snprintf(extra, sizeof extra, paper_help_redundant, nact, prru_cli_paper_fd_text());
    printf(paper_help, extra);
    return 0;
  }
  double clip;
  if (prru_plot_parse_clip("paper", clip_s, &clip)) return 2;
  if (!out) {
    prru_cli_error("paper", "--out DIR is required (see 'prru paper --help')");
    return 2;
  }
  /* "-" means stdout for every other command; a directory cannot be. */
  if (strcmp(out, "-") == 0) {
    prru_cli_error("paper", "--out -: the study is a directory of files (CSVs, PNGs, summary.txt), "
                   "it cannot go to stdout; give a directory name (./- for a directory named -)");
    return 2;
  }
  int is_paper = prru_cli_is_paper_model();
  if (!is_paper)
    prru_cli_error("paper", "warning: model %s is not the paper's; the figures show this model, "
                   "not the paper's results", prru_cli_model()->mech->name);
  /* Handlers first: no signal leaves the staging directory behind. */
  prru_cli_catch_signals();
  int created;
  if (make_dir(out, &created)) return 1;
  char stage[4096];
  snprintf(stage, sizeof stage, "%s/paper.partial-XXXXXX", out);
  if (strlen(out) > 4000 || !mkdtemp(stage)) {
    prru_cli_error("paper", "--out %s: cannot create a directory in it: %s", out,
                   strlen(out) > 4000 ? strerror(ENAMETOOLONG) : strerror(errno));
    if (created) rmdir(out);
    return 1;
  }
  int rc = run_paper(stage, out, skip_map, is_paper, clip);
  int no_gnuplot = rc == PRRU_PLOT_NO_GNUPLOT;
  if (rc == 0 || no_gnuplot) {
    if (no_gnuplot) {
      remove_stale(out, plot_outputs, (int)(sizeof plot_outputs / sizeof plot_outputs[0]));
      if (!skip_map)
        remove_stale(out, fig7_plot_outputs, (int)(sizeof fig7_plot_outputs / sizeof fig7_plot_outputs[0]));
    }
    rc = move_files(stage, out);
    if (rc == 0 && no_gnuplot) {
      prru_cli_error("paper", "gnuplot not found: CSVs, gnuplot scripts and summary written to %s, "
                     "PNGs not made (install gnuplot-nox, e.g. with 'make deps')", out);
      rc = 1;
    }
  } else if (rc >= 128) {
    prru_cli_error("paper", "interrupted (%s): %s is not changed", prru_cli_signal_name(), out);
  } else {
    prru_cli_error("paper", "%s is not changed", out);
  }
  remove_dir(stage);
  if (created && rc != 0 && !no_gnuplot) rmdir(out); /* only when empty */
  if (rc == 0)
    printf("wrote %s/: paper_sim.csv, fig_q.png, fig_d.png, fig4_u_joint_forces.png, "
           "fig5_p_joint_forces.png, fig6_p_joint_moments.png, %ssummary.txt\n", out,
           skip_map ? "" : "fig7_*, ");
  return rc;
}
