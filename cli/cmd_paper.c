/* prru paper: the paper's section 4.3 simulation study and its fig. 7
 * workspace map, written as CSVs, gnuplot PNGs and a text summary. */
#define _POSIX_C_SOURCE 200809L /* mkdir */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "commands.h"
#include "prru.h"

static const char paper_help[] =
    "usage: prru paper --out DIR [--skip-map]\n"
    "Reproduces the paper's studies (Chen et al. 2017, section 4.3 and fig. 7):\n"
    "1 s from q(0) = (0, pi/6, -0.8) m/rad at rest under fd = (50, 40, 25) N and\n"
    "the platform force fp = 50 (sin 4 pi t, -cos 4 pi t, 0) N, then the w_R map.\n"
    "Writes DIR/paper_sim.csv (columns as `prru simulate`), fig_q.png, fig_d.png,\n"
    "fig4_u_joint_forces.png, fig6_p_joint_reactions.png, the fig. 7 files and\n"
    "DIR/summary.txt. Needs gnuplot for the PNGs.\n";

/* Keeps the samples in memory (for the summary) and writes the CSV. */
typedef struct {
  prru_cli_csv csv;
  prru_sample first, last;
  double work;      /* integral of fd . dd/dt + fp . v_P (trapezoid) */
  double prev_power;
  double max_abs[PRRU_NLAMBDA];
  long n;
} paper_run;

static int on_sample(const prru_sample *s, void *ctx)
{
  paper_run *r = ctx;
  prru_loads l;
  prru_schedule_eval(r->csv.loads, s->t, &l);
  double Jd[9], JP[18], power = 0;
  prru_jd(s->q, Jd);
  prru_platform_jacobian(s->q, JP);
  for (int i = 0; i < 3; i++) {
    double dd = Jd[3 * i] * s->qd[0] + Jd[3 * i + 1] * s->qd[1] + Jd[3 * i + 2] * s->qd[2];
    double w = JP[3 * i] * s->qd[0] + JP[3 * i + 1] * s->qd[1] + JP[3 * i + 2] * s->qd[2];
    double v = JP[9 + 3 * i] * s->qd[0] + JP[9 + 3 * i + 1] * s->qd[1] + JP[9 + 3 * i + 2] * s->qd[2];
    power += l.fd[i] * dd + l.fp[i] * v + l.mp[i] * w;
  }
  if (r->n == 0)
    r->first = *s;
  else
    r->work += 0.5 * (power + r->prev_power) * (s->t - r->last.t);
  r->prev_power = power;
  r->last = *s;
  for (int i = 0; i < PRRU_NLAMBDA; i++)
    if (fabs(s->lambda[i]) > r->max_abs[i]) r->max_abs[i] = fabs(s->lambda[i]);
  r->n++;
  return prru_cli_csv_row(s, &r->csv);
}

static const char plot_script[] =
    "set datafile separator ','\n"
    "set terminal pngcairo size 1000,700 enhanced font 'Sans,11'\n"
    "set grid\n"
    "set key outside right\n"
    "f = 'paper_sim.csv'\n"
    "set output 'fig_q.png'\n"
    "set multiplot layout 2,1 title 'Generalized coordinates, paper scenario (section 4.3)'\n"
    "set ylabel 'rotation (rad)'\n"
    "plot f using 't':'q1' with lines lw 2 title 'q_1', '' using 't':'q2' with lines lw 2 title 'q_2'\n"
    "set xlabel 'time t (s)'\n"
    "set ylabel 'height (m)'\n"
    "plot f using 't':'q3' with lines lw 2 title 'q_3'\n"
    "unset multiplot\n"
    "set output 'fig_d.png'\n"
    "set title 'Actuator displacements (slider heights)'\n"
    "set xlabel 'time t (s)'\n"
    "set ylabel 'd_i (m)'\n"
    "plot f using 't':'d1' with lines lw 2 title 'd_1', '' using 't':'d2' with lines lw 2 title 'd_2', '' using 't':'d3' with lines lw 2 title 'd_3'\n"
    "unset title\n"
    "set output 'fig4_u_joint_forces.png'\n"
    "set multiplot layout 3,1 title 'Reaction forces in the U joints C_i (force of the lower link on the platform, base frame S; paper fig. 4)'\n"
    "set xlabel ''\n"
    "set ylabel 'C_1 force (N)'\n"
    "plot f using 't':'C1_fx' w l lw 2 t 'f_x', '' using 't':'C1_fy' w l lw 2 t 'f_y', '' using 't':'C1_fz' w l lw 2 t 'f_z'\n"
    "set ylabel 'C_2 force (N)'\n"
    "plot f using 't':'C2_fx' w l lw 2 t 'f_x', '' using 't':'C2_fy' w l lw 2 t 'f_y', '' using 't':'C2_fz' w l lw 2 t 'f_z'\n"
    "set xlabel 'time t (s)'\n"
    "set ylabel 'C_3 force (N)'\n"
    "plot f using 't':'C3_fx' w l lw 2 t 'f_x', '' using 't':'C3_fy' w l lw 2 t 'f_y', '' using 't':'C3_fz' w l lw 2 t 'f_z'\n"
    "unset multiplot\n"
    "set output 'fig6_p_joint_reactions.png'\n"
    "set terminal pngcairo size 1200,800 enhanced font 'Sans,11'\n"
    "set multiplot layout 3,2 title 'Reactions in the prismatic joints P_i (rail on slider, base frame S; paper fig. 6)'\n"
    "do for [i=1:3] {\n"
    "  set xlabel (i == 3 ? 'time t (s)' : '')\n"
    "  set ylabel sprintf('P_%d force (N)', i)\n"
    "  plot f using 't':sprintf('P%d_fx', i) w l lw 2 t 'f_x', '' using 't':sprintf('P%d_fy', i) w l lw 2 t 'f_y'\n"
    "  set ylabel sprintf('P_%d moment (N m)', i)\n"
    "  plot f using 't':sprintf('P%d_mx', i) w l lw 2 t 'm_x', '' using 't':sprintf('P%d_my', i) w l lw 2 t 'm_y', '' using 't':sprintf('P%d_mz', i) w l lw 2 t 'm_z'\n"
    "}\n"
    "unset multiplot\n";

/* Runs gnuplot on a script in dir (cd there so outputs land beside it). */
int prru_cli_gnuplot(const char *dir, const char *script_name, const char *script)
{
  char path[4200], cmd[8600];
  snprintf(path, sizeof path, "%s/%s", dir, script_name);
  FILE *f = fopen(path, "w");
  if (!f || fputs(script, f) < 0 || fclose(f) != 0) {
    prru_cli_error("paper", "%s: cannot write", path);
    return 1;
  }
  if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
    prru_cli_error("paper", "gnuplot not found: CSVs and %s written, PNGs not made "
                   "(install gnuplot-nox, e.g. with 'make deps')", script_name);
    return 1;
  }
  snprintf(cmd, sizeof cmd, "cd '%s' && gnuplot '%s'", dir, script_name);
  if (strchr(dir, '\'') || system(cmd) != 0) {
    prru_cli_error("paper", "gnuplot failed on %s", path);
    return 1;
  }
  return 0;
}

static int make_dir(const char *dir)
{
  if (mkdir(dir, 0777) == 0 || errno == EEXIST) {
    struct stat st;
    if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode)) return 0;
  }
  prru_cli_error("paper", "--out %s: cannot create the directory", dir);
  return 1;
}

static void summarize(FILE *f, const paper_run *r, double t_stop)
{
  const char *const *labels = prru_mech.lambda_labels;
  const prru_sample *a = &r->first, *b = &r->last;
  fprintf(f, "Paper study (section 4.3): q(0) = (0, pi/6, -0.8), fd = (50, 40, 25) N,\n"
             "fp = 50 (sin 4 pi t, -cos 4 pi t, 0) N, rk8pd at 1e-10, %ld samples to t = %.3f s\n",
          r->n, t_stop);
  fprintf(f, "q(%.3f)   = (%.10f, %.10f, %.10f) rad, rad, m\n", b->t, b->q[0], b->q[1], b->q[2]);
  fprintf(f, "qd(%.3f)  = (%.10f, %.10f, %.10f)\n", b->t, b->qd[0], b->qd[1], b->qd[2]);
  fprintf(f, "d(%.3f)   = (%.10f, %.10f, %.10f) m\n", b->t, b->d[0], b->d[1], b->d[2]);
  double dE = (b->T + b->V) - (a->T + a->V);
  fprintf(f, "energy balance: change of T + V = %.9f J, work of fd and fp = %.9f J "
             "(trapezoid on the samples), difference %.2e J\n", dE, r->work, dE - r->work);
  fprintf(f, "peak reaction magnitudes over the run:\n");
  for (int j = 0; j < PRRU_NLAMBDA; j++)
    fprintf(f, "  %-6s %12.4f%s", labels[j], r->max_abs[j], j % 4 == 3 || j == PRRU_NLAMBDA - 1 ? "\n" : "");
}

int prru_cmd_paper(int argc, char **argv)
{
  const char *out = NULL;
  int help = 0, skip_map = 0;
  prru_cli_option opts[] = {{"out", 1, &out, NULL}, {"skip-map", 0, NULL, &skip_map}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("paper", argc, argv, opts, 3)) return 2;
  if (help) {
    fputs(paper_help, stdout);
    return 0;
  }
  if (!out) {
    prru_cli_error("paper", "--out DIR is required (see 'prru paper --help')");
    return 2;
  }
  if (make_dir(out)) return 1;
  char path[4200], msg[600];
  snprintf(path, sizeof path, "%s/paper_sim.csv", out);
  FILE *f = fopen(path, "w");
  if (!f) {
    prru_cli_error("paper", "%s: cannot open for writing", path);
    return 1;
  }
  prru_model m;
  prru_model_default(&m);
  prru_scenario s;
  prru_scenario_paper(&s);
  paper_run *r = calloc(1, sizeof *r);
  if (!r) { fclose(f); return 1; }
  r->csv.f = f;
  r->csv.loads = &s.loads;
  r->csv.reactions = 1;
  s.opt.loads = &s.loads;
  s.opt.reactions = 1;
  s.opt.on_sample = on_sample;
  s.opt.ctx = r;
  prru_cli_catch_sigint();
  s.opt.interrupt = &prru_cli_interrupted;
  prru_cli_csv_header(&r->csv);
  double t_stop;
  int st = prru_simulate(&m, s.q0, s.qd0, &s.opt, &t_stop, msg, sizeof msg);
  if (fclose(f) != 0 && st == PRRU_OK) {
    prru_cli_error("paper", "%s: write error", path);
    st = PRRU_EIO;
  }
  if (st != PRRU_OK) {
    if (st != PRRU_EIO) prru_cli_error("paper", "simulation: %s (samples so far in %s)", msg, path);
    free(r);
    prru_scenario_free(&s);
    return prru_cli_exit_for(st);
  }
  snprintf(path, sizeof path, "%s/summary.txt", out);
  FILE *sum = fopen(path, "w");
  if (!sum) {
    prru_cli_error("paper", "%s: cannot open for writing", path);
    free(r);
    return 1;
  }
  summarize(sum, r, t_stop);
  summarize(stdout, r, t_stop);
  free(r);
  prru_scenario_free(&s);
  int rc = prru_cli_gnuplot(out, "paper_plots.gp", plot_script);
  if (rc == 0 && !skip_map) rc = prru_paper_fig7(out, sum);
  if (fclose(sum) != 0 && rc == 0) rc = 1;
  if (rc == 0) printf("wrote %s/: paper_sim.csv, fig_q.png, fig_d.png, fig4_u_joint_forces.png, "
                      "fig6_p_joint_reactions.png, %ssummary.txt\n", out, skip_map ? "" : "fig7_*, ");
  return rc;
}
