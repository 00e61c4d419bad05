/* prru optimize, prru sensitivity, prru merge and the shards of prru map:
 * design optimisation of w_R over a workspace rectangle with the
 * runtime-parameter kernels (runtime/include/prru_design.h). */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, isatty, open_memstream */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "commands.h"
#include "mapgrid.h"
#include "plot.h"
#include "shard.h"
#include "prru.h"
#include "prru_control.h"
#include "prru_design.h"
#include "prru_dme.h"

/* ---- Options shared by optimize and sensitivity ---- */

typedef struct {
  const char *q1, *q2, *q3, *rcond, *objective, *set;
  int limits;              /* the drives' limits act (optimize) */
  prru_cli_limit_args lim; /* their overrides */
  prru_limits run;         /* out: the run's limits (when limits) */
} problem_text;

/* "LO:HI" with finite LO < HI; 0 or 2. */
static int parse_pair(const char *cmd, const char *opt, const char *text, double *lo, double *hi)
{
  char buf[256];
  const char *c = strchr(text, ':');
  if (!c || strchr(c + 1, ':') || strlen(text) >= sizeof buf) {
    prru_cli_error(cmd, "--%s '%s': expected LO:HI", opt, text);
    return 2;
  }
  memcpy(buf, text, strlen(text) + 1);
  buf[c - text] = '\0';
  if (prru_parse_double(buf, lo) != PRRU_OK || prru_parse_double(buf + (c - text) + 1, hi) != PRRU_OK) {
    prru_cli_error(cmd, "--%s '%s': LO and HI must be finite numbers", opt, text);
    return 2;
  }
  if (!(*lo < *hi)) {
    prru_cli_error(cmd, "--%s '%s': infeasible, LO must be less than HI", opt, text);
    return 2;
  }
  return 0;
}

/* --set NAME=VALUE[,NAME=VALUE...]: changes to the model's numbers that
 * make the start design (every tied parameter set to VALUE). 0 or 2. */
static int parse_set(const char *cmd, const char *text, prru_params *p)
{
  char buf[4096];
  if (strlen(text) >= sizeof buf) {
    prru_cli_error(cmd, "--set: too long");
    return 2;
  }
  memcpy(buf, text, strlen(text) + 1);
  for (char *save = NULL, *item = strtok_r(buf, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
    char *eq = strchr(item, '=');
    char msg[512];
    prru_design_var v;
    double x;
    if (!eq) {
      prru_cli_error(cmd, "--set '%s': expected NAME=VALUE", item);
      return 2;
    }
    *eq = '\0';
    if (prru_design_var_parse(prru_cli_model(), item, &v, msg, sizeof msg) != PRRU_OK) {
      prru_cli_error(cmd, "--set: %s", msg);
      return 2;
    }
    if (prru_parse_double(eq + 1, &x) != PRRU_OK) {
      prru_cli_error(cmd, "--set %s='%s': not a finite number", item, eq + 1);
      return 2;
    }
    prru_design_assign(p, &v, x);
  }
  return 0;
}

/* The design's stroke (prru_design_problem_stroke). 0 or 2. */
static int design_stroke(const char *cmd, const prru_limits *l, prru_design_problem *pr)
{
  char msg[300];
  if (prru_design_problem_stroke(pr, l, msg, sizeof msg) == PRRU_OK) return 0;
  prru_cli_error(cmd, "%s; give --stroke LO,HI", msg);
  return 2;
}

static int parse_problem(const char *cmd, problem_text *t, prru_design_problem *pr,
                         prru_params *start)
{
  prru_map_grid g = {0, 0, 0, 0, 0.0, 0, 0};
  if (prru_cli_parse_range(cmd, "q1", t->q1, &g.q1_lo, &g.q1_hi, &g.n1)) return 2;
  if (prru_cli_parse_range(cmd, "q2", t->q2, &g.q2_lo, &g.q2_hi, &g.n2)) return 2;
  if (t->q3 && prru_cli_number(cmd, "q3", t->q3, &g.q3)) return 2;
  if ((double)g.n1 * (double)g.n2 > 1e7) {
    prru_cli_error(cmd, "--q1/--q2: %d x %d points is more than the limit of 1e7", g.n1, g.n2);
    return 2;
  }
  prru_design_problem_default(prru_cli_model(), pr, &g);
  if (t->rcond) {
    if (prru_cli_number(cmd, "rcond-min", t->rcond, &pr->rcond_min)) return 2;
    if (!(pr->rcond_min > 0 && pr->rcond_min < 1)) {
      prru_cli_error(cmd, "--rcond-min '%s': must be in (0, 1)", t->rcond);
      return 2;
    }
  }
  if (t->limits && (prru_cli_limits(cmd, "force-max", &t->lim, &t->run) || design_stroke(cmd, &t->run, pr)))
    return 2;
  if (t->objective && prru_objective_parse(t->objective, &pr->objective) != PRRU_OK) {
    prru_cli_error(cmd, "--objective '%s': one of mean, max, log", t->objective);
    return 2;
  }
  prru_model_params(prru_cli_model(), start); /* the current (--model's) numbers */
  if (t->set && parse_set(cmd, t->set, start)) return 2;
  char msg[512];
  if (prru_design_check(prru_cli_model(), start, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error(cmd, "the start design is not a buildable robot: %s", msg);
    return 2;
  }
  return 0;
}

/* --threads N: 1 to 256 (the result is the same for any); 0 or 2. */
static int parse_threads(const char *cmd, const char *text, int *n)
{
  if (!text) return 0;
  char *end;
  long v = strtol(text, &end, 10);
  if (!*text || *end || v < 1 || v > 256) {
    prru_cli_error(cmd, "--threads '%s': must be an integer from 1 to 256", text);
    return 2;
  }
  *n = (int)v;
  return 0;
}

/* The settings that define a result, one line: shards of one sweep must
 * agree on it. */
static void problem_line(char *buf, size_t len, const prru_design_problem *pr, const char *extra)
{
  const prru_map_grid *g = &pr->grid;
  int n = snprintf(buf, len, "q1=%.17g:%.17g:%d q2=%.17g:%.17g:%d q3=%.17g rcond_min=%.17g objective=%s",
                   g->q1_lo, g->q1_hi, g->n1, g->q2_lo, g->q2_hi, g->n2, g->q3, pr->rcond_min,
                   prru_objective_name(pr->objective));
  if (n > 0 && (size_t)n < len && extra) snprintf(buf + n, len - (size_t)n, " %s", extra);
}

static const char *objective_text(prru_objective o)
{
  return o == PRRU_OBJ_MAX ? "the largest w_R" : o == PRRU_OBJ_LOG ? "mean of ln w_R"
                                                                    : "mean of w_R - 1";
}

/* One map row as prru map writes it. */
static void map_row(prru_cli_out *o, double q1, double q2, double q3, double w, int st)
{
  if (st == PRRU_OK)
    prru_cli_out_printf(o, "%.17g,%.17g,%.17g,%.17g,ok\n", q1, q2, q3, w);
  else
    prru_cli_out_printf(o, "%.17g,%.17g,%.17g,NaN,%s\n", q1, q2, q3,
                        prru_dme_status_name(st));
}

/* ---- Sensitivity rows (shared by sensitivity and merge) ---- */

typedef struct {
  char name[24];
  double value, scale, step, f_plus, f_minus, derivative, scaled;
  int changed;
} sens_row;

static const char sens_header[] =
    "parameter,value,scale,step,objective_plus,objective_minus,derivative,scaled,set_changed\n";

static void sens_write_row(prru_cli_out *o, const sens_row *r)
{
  prru_cli_out_printf(o, "%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d\n", r->name, r->value,
                      r->scale, r->step, r->f_plus, r->f_minus, r->derivative, r->scaled, r->changed);
}

static int cmp_scaled(const void *a, const void *b)
{
  const sens_row *x = *(const sens_row *const *)a, *y = *(const sens_row *const *)b;
  double fx = fabs(x->scaled), fy = fabs(y->scaled);
  if (fx != fy) return fx < fy ? 1 : -1;
  return strcmp(x->name, y->name); /* a total order: the same table every time */
}

/* The table on stdout, largest |scaled| first. */
static int sens_print(const sens_row *rows, long n, const char *settings)
{
  const sens_row **ord = malloc((size_t)(n ? n : 1) * sizeof *ord);
  if (!ord) return 1;
  for (long i = 0; i < n; i++) ord[i] = &rows[i];
  qsort(ord, (size_t)n, sizeof *ord, cmp_scaled);
  printf("model: %s\nsettings: %s\n", prru_cli_model_id(), settings);
  printf("%-12s %14s %14s %14s %14s %s\n", "parameter", "value", "d obj/d p", "scale",
         "scaled", "(scaled = d obj/d p x scale; * = a grid point changed status)");
  for (long i = 0; i < n; i++)
    printf("%-12s %14.7g %14.7g %14.7g %14.7g%s\n", ord[i]->name, ord[i]->value, ord[i]->derivative,
           ord[i]->scale, ord[i]->scaled, ord[i]->changed ? " *" : "");
  free(ord);
  return 0;
}

/* The bar chart of the largest scaled sensitivities into png (built in a
 * directory beside it, renamed when gnuplot is done). */
static int sens_plot(const char *cmd, const sens_row *rows, long n, const char *png)
{
  char stage[4200];
  snprintf(stage, sizeof stage, "%s.partial-XXXXXX", png);
  if (strlen(png) > 4000 || !mkdtemp(stage)) {
    prru_cli_error(cmd, "%s: cannot create a directory beside it: %s", png, strerror(errno));
    return 1;
  }
  char path[4300];
  snprintf(path, sizeof path, "%s/sens.dat", stage);
  FILE *f = fopen(path, "w");
  int rc = f ? 0 : 1;
  if (f) {
    const sens_row **ord = malloc((size_t)(n ? n : 1) * sizeof *ord);
    if (!ord) rc = 1;
    for (long i = 0; ord && i < n; i++) ord[i] = &rows[i];
    if (ord) qsort(ord, (size_t)n, sizeof *ord, cmp_scaled);
    for (long i = 0; ord && i < n && i < 30; i++)
      fprintf(f, "%ld %s%s %.9g\n", i, ord[i]->name, ord[i]->changed ? "*" : "", ord[i]->scaled);
    free(ord);
    if (fclose(f) != 0) rc = 1;
  }
  char *script = rc ? NULL : prru_plot_sensitivity_script("sens.dat", "sens.png");
  if (!rc && !script) rc = 1;
  if (!rc) rc = prru_plot_run(cmd, stage, stage, "sens.gp", script);
  free(script);
  if (!rc) {
    snprintf(path, sizeof path, "%s/sens.png", stage);
    if (rename(path, png) != 0) {
      prru_cli_error(cmd, "%s: %s", png, strerror(errno));
      rc = 1;
    }
  }
  if (rc == PRRU_PLOT_NO_GNUPLOT) prru_cli_error(cmd, "gnuplot is not installed: %s not drawn", png);
  const char *names[] = {"sens.dat", "sens.png", "sens.gp"};
  for (int i = 0; i < 3; i++) {
    snprintf(path, sizeof path, "%s/%s", stage, names[i]);
    remove(path);
  }
  rmdir(stage);
  return rc;
}

/* ---- prru sensitivity ---- */

static const char sens_help[] =
    "usage: prru sensitivity --q1 START:STOP:COUNT --q2 START:STOP:COUNT [--q3 Z]\n"
    "                        --out FILE.csv [--params NAME,...] [--step H]\n"
    "                        [--objective mean|max|log] [--rcond-min R]\n"
    "                        [--set NAME=VALUE,...] [--shard K/N] [--plot FILE.png]\n"
    "                        [--threads N]\n"
    "The derivative of the global index (the objective: mean of w_R - 1 over the\n"
    "regular grid points, or max w_R, or mean ln w_R) with respect to every\n"
    "parameter of the design (the paper's influence of the kinematic and inertial\n"
    "parameters on w_R), by central differences with the step h = H x scale\n"
    "(default H 1e-4; scale: the parameter's magnitude, or where it may be 0 the\n"
    "body's mean principal moment, the mean upper link, the mean slider mass);\n"
    "H in (0, 0.5), and h at least 100 x 2.2e-16 (the rounding unit) x the\n"
    "parameter's magnitude (a smaller step is lost to rounding: exit 2).\n"
    "The design is the model's numbers with the --set changes (names as in\n"
    "'prru optimize --help'); the grid as in 'prru map'; J_d regular where\n"
    "1/(|J|_1 |J^-1|_1) >= R (default 4e-3). --params: the parameters (default:\n"
    "every one: b_i l1_i l2_i a_i, m_B com_B_x.. I_B_xx.. for every body B,\n"
    "armature_i).\n"
    "Writes FILE.csv: the model line, a settings line, the columns\n"
    "parameter,value,scale,step,objective_plus,objective_minus,derivative,scaled,\n"
    "set_changed (scaled = derivative x scale: the change of the objective for a\n"
    "change of the parameter by its scale; set_changed = 1 when a grid point\n"
    "crossed the singularity tolerance between the two evaluations, so that the\n"
    "difference includes a jump). Prints the table, largest |scaled| first.\n"
    "--plot: a bar chart of the 30 largest |scaled|.\n"
    "--shard K/N: only the K-th of N contiguous parts of the parameter list (a\n"
    "cluster job array runs one part per task); 'prru merge' joins the parts into\n"
    "exactly the file one run writes. --threads: per evaluation (default 2; the\n"
    "numbers are the same for any).\n";

typedef struct {
  int nparam;
  prru_design_var *vars;
} param_list;

static int parse_params(const char *cmd, const char *text, param_list *pl)
{
  int cap = prru_design_param_count(prru_cli_model()) + 64;
  pl->vars = calloc((size_t)cap, sizeof *pl->vars);
  pl->nparam = 0;
  if (!pl->vars) return 1;
  if (!text) {
    for (int k = 0; k < prru_design_param_count(prru_cli_model()); k++)
      prru_design_param(prru_cli_model(), k, &pl->vars[pl->nparam++]);
    return 0;
  }
  char *buf = strdup(text);
  if (!buf) return 1;
  int rc = 0;
  for (char *save = NULL, *it = strtok_r(buf, ",", &save); it && !rc; it = strtok_r(NULL, ",", &save)) {
    char msg[512];
    if (pl->nparam >= cap) {
      prru_cli_error(cmd, "--params: more than %d parameters", cap);
      rc = 2;
    } else if (prru_design_var_parse(prru_cli_model(), it, &pl->vars[pl->nparam], msg, sizeof msg) !=
               PRRU_OK) {
      prru_cli_error(cmd, "--params: %s", msg);
      rc = 2;
    } else {
      pl->nparam++;
    }
  }
  free(buf);
  if (!rc && pl->nparam == 0) {
    prru_cli_error(cmd, "--params: no parameter given");
    rc = 2;
  }
  return rc;
}

/* The evaluation at the design, or exit status 1 with a message when no
 * grid point is regular. */
static int base_eval(const char *cmd, const prru_design_problem *pr, const prru_params *p,
                     prru_design_data *dd, prru_design_eval *ev)
{
  prru_design_evaluate(pr, p, dd, ev);
  if (ev->sum.n_ok > 0) return 0;
  /* The runtime counts the other assembly mode among the singular points. */
  prru_cli_error(cmd, "no grid point of the workspace is regular (%ld singular, %ld in the other "
                      "assembly mode, %ld unreachable, of %ld): the objective is not defined there",
                 ev->sum.n_singular - ev->n_other_mode, ev->n_other_mode, ev->sum.n_unreachable,
                 ev->sum.n_points);
  return 1;
}

int prru_cmd_sensitivity(int argc, char **argv)
{
  const char *cmd = "sensitivity";
  problem_text t = {0};
  const char *out = NULL, *params = NULL, *steps = NULL, *shards = NULL, *plot = NULL, *ths = NULL;
  int help = 0, nthreads = 2;
  prru_cli_option opts[] = {
      {"q1", 1, &t.q1, NULL},         {"q2", 1, &t.q2, NULL},       {"q3", 1, &t.q3, NULL},
      {"rcond-min", 1, &t.rcond, NULL}, {"objective", 1, &t.objective, NULL},
      {"set", 1, &t.set, NULL},       {"out", 1, &out, NULL},       {"params", 1, &params, NULL},
      {"step", 1, &steps, NULL},      {"shard", 1, &shards, NULL},  {"plot", 1, &plot, NULL},
      {"threads", 1, &ths, NULL},     {"help", 0, NULL, &help}};
  if (prru_cli_parse(cmd, argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  if (help) {
    fputs(sens_help, stdout);
    return 0;
  }
  const char *missing = !t.q1 ? "--q1" : !t.q2 ? "--q2" : !out ? "--out" : NULL;
  if (missing) {
    prru_cli_error(cmd, "%s is required (see 'prru sensitivity --help')", missing);
    return 2;
  }
  prru_design_problem pr;
  prru_params p;
  if (parse_problem(cmd, &t, &pr, &p) || parse_threads(cmd, ths, &nthreads)) return 2;
  double h = 1e-4;
  if (steps && prru_cli_number(cmd, "step", steps, &h)) return 2;
  if (!(h > 0 && h < 0.5)) {
    prru_cli_error(cmd, "--step '%s': must be in (0, 0.5)", steps);
    return 2;
  }
  int k = 1, n = 1;
  if (shards && prru_cli_parse_shard(cmd, shards, &k, &n)) return 2;
  if (shards && plot) {
    prru_cli_error(cmd, "--plot with --shard: plot the merged file ('prru merge --plot')");
    return 2;
  }
  param_list pl;
  int rc = parse_params(cmd, params, &pl);
  for (int i = 0; i < pl.nparam && !rc; i++) {
    char msg[512];
    if (prru_design_step_check(pr.model, &p, &pl.vars[i], h, msg, sizeof msg) != PRRU_OK) {
      prru_cli_error(cmd, "--step '%s': %s", steps, msg);
      rc = 2;
    }
  }
  if (rc) {
    free(pl.vars);
    return rc;
  }
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, cmd, out)) {
    free(pl.vars);
    return 1;
  }
  prru_design_data dd;
  prru_design_eval ev;
  sens_row *rows = calloc((size_t)pl.nparam, sizeof *rows);
  rc = rows && prru_design_data_alloc(&dd, &pr.grid) == PRRU_OK ? 0 : 1;
  dd.nthreads = nthreads;
  if (rc) prru_cli_error(cmd, "out of memory");
  else rc = base_eval(cmd, &pr, &p, &dd, &ev);
  char extra[128], settings[1024];
  snprintf(extra, sizeof extra, "step=%.17g params=%d base=%.17g", h, pl.nparam, ev.objective);
  problem_line(settings, sizeof settings, &pr, extra);
  long b0 = 0, b1 = 0;
  prru_cli_shard_range(pl.nparam, k, n, &b0, &b1);
  for (long i = b0; i < b1 && !rc; i++) {
    if (prru_cli_interrupted) {
      rc = prru_cli_exit_interrupted();
      break;
    }
    prru_design_sens s;
    sens_row *r = &rows[i - b0];
    int st = prru_design_sensitivity(&pr, &p, &pl.vars[i], h, &dd, &s);
    snprintf(r->name, sizeof r->name, "%s", pl.vars[i].name);
    r->value = s.value;
    r->scale = s.scale;
    r->step = s.step;
    r->f_plus = s.f_plus;
    r->f_minus = s.f_minus;
    r->derivative = st == PRRU_OK ? s.derivative : NAN;
    r->scaled = r->derivative * s.scale;
    r->changed = s.set_changed;
  }
  if (!rc) {
    prru_cli_out_comment(&o);
    if (shards) prru_cli_out_printf(&o, "# shard %d/%d sensitivity %s\n", k, n, settings);
    else prru_cli_out_printf(&o, "# sensitivity %s\n", settings);
    prru_cli_out_line(&o);
    prru_cli_out_printf(&o, "%s", sens_header);
    prru_cli_out_line(&o);
    for (long i = 0; i < b1 - b0; i++) {
      sens_write_row(&o, &rows[i]);
      prru_cli_out_row(&o);
    }
  }
  if (prru_cli_out_close(&o, rc == 0 && !o.err) && !rc) rc = 1;
  if (rc > 1) prru_cli_error(cmd, "interrupted (%s): %s is not changed", prru_cli_signal_name(), out);
  if (!rc && plot) rc = sens_plot(cmd, rows, b1 - b0, plot);
  if (!rc && !shards) rc = sens_print(rows, b1 - b0, settings);
  if (!rc && shards)
    printf("model: %s\nshard %d/%d: parameters %ld to %ld of %d written to %s\n", prru_cli_model_id(),
           k, n, b0 + 1, b1, pl.nparam, out);
  free(rows);
  free(pl.vars);
  prru_design_data_free(&dd);
  return rc;
}

/* ---- prru merge ---- */

static const char merge_help[] =
    "usage: prru merge --in SHARD1,SHARD2,... --out FILE [--plot FILE.png]\n"
    "Joins the shard files of one 'prru map --shard K/N' or 'prru sensitivity\n"
    "--shard K/N' sweep (all N of them, in any order; file names without\n"
    "commas) into FILE, byte for byte what one run without --shard writes, and\n"
    "prints what that run prints. Every shard must come from this model and\n"
    "program version with the same settings (checked), each K from 1 to N\n"
    "exactly once. --plot: the sensitivity bar chart. FILE is written only when\n"
    "every check passes.\n";

typedef struct {
  char *text;       /* whole file */
  size_t len;
  int k, n;
  char *kind_line;  /* after "# shard K/N " */
  char *header, *rows; /* third line, the rest */
} shard_file;

static char *next_line(char *s)
{
  char *e = strchr(s, '\n');
  if (!e) return NULL;
  *e = '\0';
  return e + 1;
}

/* Reads and splits one shard; 0 or 2 after a message naming the file. */
static int read_shard(const char *path, const char *model_line, shard_file *s)
{
  FILE *f = fopen(path, "rb");
  if (!f) {
    prru_cli_error("merge", "%s: cannot open: %s", path, strerror(errno));
    return 2;
  }
  size_t cap = 1 << 16;
  s->text = malloc(cap);
  s->len = 0;
  size_t got;
  while (s->text && (got = fread(s->text + s->len, 1, cap - s->len - 1, f)) > 0) {
    s->len += got;
    if (s->len + 1 == cap) {
      char *t = realloc(s->text, cap *= 2);
      if (!t) free(s->text);
      s->text = t;
    }
  }
  int err = ferror(f);
  fclose(f);
  if (!s->text || err) {
    prru_cli_error("merge", "%s: cannot read", path);
    return 2;
  }
  s->text[s->len] = '\0';
  char *l2 = next_line(s->text), *l3 = l2 ? next_line(l2) : NULL, *l4 = l3 ? next_line(l3) : NULL;
  if (!l4 || strcmp(s->text, model_line) != 0) {
    prru_cli_error("merge", "%s: not a shard of this model and program version (first line must be '%s')",
                   path, model_line);
    return 2;
  }
  int used = 0;
  if (sscanf(l2, "# shard %d/%d %n", &s->k, &s->n, &used) != 2 || used == 0) {
    prru_cli_error("merge", "%s: line 2 is not '# shard K/N ...': not a shard file", path);
    return 2;
  }
  s->kind_line = l2 + used;
  s->header = l3;
  s->rows = l4;
  return 0;
}

/* Map rows back to w_R and statuses (exactly: they were written with 17
 * digits); 0 or 2. */
static int parse_map_rows(const char *path, char *rows, const prru_map_grid *g, long first, long count,
                          double *w, unsigned char *st)
{
  long k = 0;
  for (char *line = rows, *next; *line; line = next) {
    next = next_line(line);
    if (!next) next = line + strlen(line);
    double q[3], v;
    int s;
    const char *why = k < count ? prru_cli_map_parse_row(line, q, &v, &s) : "more rows than the shard has";
    if (why) {
      prru_cli_error("merge", "%s: row %ld: %s", path, k + 1, why);
      return 2;
    }
    long idx = first + k;
    int i = (int)(idx / g->n2), j = (int)(idx % g->n2);
    if (q[0] != prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i) ||
        q[1] != prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j) || q[2] != g->q3) {
      prru_cli_error("merge", "%s: row %ld does not belong to this grid", path, k + 1);
      return 2;
    }
    w[idx] = s == PRRU_OK ? v : NAN;
    st[idx] = (unsigned char)s;
    k++;
  }
  if (k != count) {
    prru_cli_error("merge", "%s: %ld rows, the shard has %ld (incomplete file)", path, k, count);
    return 2;
  }
  return 0;
}

static int merge_map(shard_file *sh, char **paths, int n, const char *out)
{
  prru_map_grid g = {0, 0, 0, 0, 0.0, 0, 0};
  double rcond;
  if (sscanf(sh[0].kind_line, "map q1=%lf:%lf:%d q2=%lf:%lf:%d q3=%lf rcond_min=%lf", &g.q1_lo, &g.q1_hi,
             &g.n1, &g.q2_lo, &g.q2_hi, &g.n2, &g.q3, &rcond) != 8 ||
      prru_map_check(&g) != PRRU_OK || (double)g.n1 * g.n2 > 5e7) {
    prru_cli_error("merge", "%s: malformed map settings line", paths[0]);
    return 2;
  }
  long npts = (long)g.n1 * g.n2;
  double *w = malloc((size_t)npts * sizeof *w);
  unsigned char *st = malloc((size_t)npts);
  int rc = w && st ? 0 : 1;
  for (int i = 0; i < n && !rc; i++) {
    long r0, r1;
    prru_cli_shard_range(g.n1, sh[i].k, n, &r0, &r1);
    rc = parse_map_rows(paths[i], sh[i].rows, &g, r0 * g.n2, (r1 - r0) * g.n2, w, st);
  }
  prru_map_summary sum;
  if (!rc) prru_map_summarize(&g, w, st, &sum);
  prru_cli_out o;
  if (!rc && prru_cli_out_open(&o, "merge", out)) rc = 1;
  if (!rc) {
    int ws = prru_cli_map_write_csv(&o, &g, w, st, g.n1, prru_cli_signal_count);
    if (prru_cli_out_close(&o, ws == PRRU_OK && !o.err)) rc = 1;
    else if (ws != PRRU_OK) rc = prru_cli_exit_for(ws);
  }
  const int precision = strstr(sh[0].kind_line, " precision=float") ? PRRU_PRECISION_FLOAT : PRRU_PRECISION_DOUBLE;
  if (!rc) prru_cli_map_print_summary(strcmp(out, "-") == 0 ? stderr : stdout, &sum, rcond, precision);
  free(w);
  free(st);
  return rc;
}

static int parse_sens_rows(const char *path, char *rows, sens_row *out, long max, long *count)
{
  long k = 0;
  for (char *line = rows, *next; *line; line = next) {
    next = next_line(line);
    if (!next) next = line + strlen(line);
    char *comma = strchr(line, ',');
    sens_row *r = &out[k];
    if (k >= max || !comma || (size_t)(comma - line) >= sizeof r->name ||
        sscanf(comma + 1, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &r->value, &r->scale, &r->step, &r->f_plus,
               &r->f_minus, &r->derivative, &r->scaled, &r->changed) != 8) {
      prru_cli_error("merge", "%s: row %ld is not a sensitivity row", path, k + 1);
      return 2;
    }
    memcpy(r->name, line, (size_t)(comma - line));
    r->name[comma - line] = '\0';
    k++;
  }
  *count = k;
  return 0;
}

static int merge_sensitivity(shard_file *sh, char **paths, int n, const char *out, const char *plot)
{
  const char *settings = sh[0].kind_line + strlen("sensitivity ");
  const char *pp = strstr(settings, " params=");
  long np = pp ? strtol(pp + 8, NULL, 10) : 0;
  if (np < 1 || np > 100000) {
    prru_cli_error("merge", "%s: malformed sensitivity settings line", paths[0]);
    return 2;
  }
  sens_row *rows = calloc((size_t)np, sizeof *rows);
  if (!rows) return 1;
  int rc = 0;
  for (int i = 0; i < n && !rc; i++) {
    long b0, b1, got = 0;
    prru_cli_shard_range(np, sh[i].k, n, &b0, &b1);
    rc = parse_sens_rows(paths[i], sh[i].rows, rows + b0, b1 - b0, &got);
    if (!rc && got != b1 - b0) {
      prru_cli_error("merge", "%s: %ld rows, the shard has %ld (incomplete file)", paths[i], got, b1 - b0);
      rc = 2;
    }
  }
  prru_cli_out o;
  if (!rc && prru_cli_out_open(&o, "merge", out)) rc = 1;
  if (!rc) {
    prru_cli_out_comment(&o);
    prru_cli_out_printf(&o, "# sensitivity %s\n", settings);
    prru_cli_out_line(&o);
    prru_cli_out_printf(&o, "%s", sens_header);
    prru_cli_out_line(&o);
    for (long i = 0; i < np; i++) {
      sens_write_row(&o, &rows[i]);
      prru_cli_out_row(&o);
    }
    if (prru_cli_out_close(&o, !o.err)) rc = 1;
  }
  if (!rc && plot) rc = sens_plot("merge", rows, np, plot);
  if (!rc) rc = sens_print(rows, np, settings);
  free(rows);
  return rc;
}

int prru_cmd_merge(int argc, char **argv)
{
  const char *ins = NULL, *out = NULL, *plot = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"in", 1, &ins, NULL}, {"out", 1, &out, NULL}, {"plot", 1, &plot, NULL},
                            {"help", 0, NULL, &help}};
  if (prru_cli_parse("merge", argc, argv, opts, 4)) return 2;
  if (help) {
    fputs(merge_help, stdout);
    return 0;
  }
  if (!ins || !out) {
    prru_cli_error("merge", "%s is required (see 'prru merge --help')", !ins ? "--in" : "--out");
    return 2;
  }
  char *list = strdup(ins);
  char *paths[4096];
  int n = 0;
  for (char *save = NULL, *it = list ? strtok_r(list, ",", &save) : NULL; it; it = strtok_r(NULL, ",", &save)) {
    if (n == 4096) {
      prru_cli_error("merge", "--in: more than 4096 files");
      free(list);
      return 2;
    }
    paths[n++] = it;
  }
  if (n == 0) {
    prru_cli_error("merge", "--in: no file given");
    free(list);
    return 2;
  }
  char model_line[2048];
  snprintf(model_line, sizeof model_line, "# prru %s model %s", PRRU_VERSION, prru_cli_model_id());
  shard_file *sh = calloc((size_t)n, sizeof *sh);
  int rc = sh ? 0 : 1;
  for (int i = 0; i < n && !rc; i++) rc = read_shard(paths[i], model_line, &sh[i]);
  /* One sweep: the same N, settings and header everywhere, each K once;
   * then sorted by K. */
  for (int i = 0; i < n && !rc; i++) {
    if (sh[i].n != n || strcmp(sh[i].kind_line, sh[0].kind_line) != 0 ||
        strcmp(sh[i].header, sh[0].header) != 0) {
      prru_cli_error("merge", "%s: shard %d/%d does not belong with %s (shard %d/%d, %d files given): "
                              "another sweep or settings",
                     paths[i], sh[i].k, sh[i].n, paths[0], sh[0].k, sh[0].n, n);
      rc = 2;
    }
    for (int j = 0; j < i && !rc; j++)
      if (sh[j].k == sh[i].k) {
        prru_cli_error("merge", "%s and %s: both are shard %d/%d", paths[j], paths[i], sh[i].k, n);
        rc = 2;
      }
  }
  for (int i = 1; i < n && !rc; i++) /* insertion sort by K */
    for (int j = i; j > 0 && sh[j - 1].k > sh[j].k; j--) {
      shard_file t = sh[j];
      sh[j] = sh[j - 1];
      sh[j - 1] = t;
      char *p = paths[j];
      paths[j] = paths[j - 1];
      paths[j - 1] = p;
    }
  if (!rc) {
    if (strncmp(sh[0].kind_line, "map ", 4) == 0) {
      if (plot) {
        prru_cli_error("merge", "--plot: only for sensitivity shards (plot a map with 'prru plot')");
        rc = 2;
      } else {
        rc = merge_map(sh, paths, n, out);
      }
    } else if (strncmp(sh[0].kind_line, "sensitivity ", 12) == 0) {
      rc = merge_sensitivity(sh, paths, n, out, plot);
    } else {
      prru_cli_error("merge", "%s: unknown kind of shard", paths[0]);
      rc = 2;
    }
  }
  for (int i = 0; sh && i < n; i++) free(sh[i].text);
  free(sh);
  free(list);
  return rc;
}

/* ---- prru optimize ---- */

static const char opt_help[] =
    "usage: prru optimize --vars SPEC[,SPEC...] --q1 START:STOP:COUNT\n"
    "                     --q2 START:STOP:COUNT [--q3 Z] --out MODEL.json\n"
    "                     --report DIR [--range PCT] [--objective mean|max|log]\n"
    "                     [--rcond-min R] [--stroke LO,HI|LO1,HI1,..] [--no-limits]\n"
    "                     [--force-max F] [--speed-max V] [--set NAME=VALUE,...]\n"
    "                     [--max-iter N] [--penalty W] [--name NAME] [--threads N]\n"
    "                     [--progress] [--clip W] [--precision double|float]\n"
    "Chooses the design variables within their bounds so that the rotational\n"
    "dynamic manipulability w_R comes as close to 1 (isotropy) as it can over the\n"
    "workspace rectangle (grid as in 'prru map'), the paper's purpose for w_R.\n"
    "Objective (--objective): mean (default) the global index, the mean of w_R - 1\n"
    "over the grid; max the largest w_R; log the mean of ln w_R.\n"
    "Constraints: every grid point reachable and regular (J_d's scaled\n"
    "1/(|J|_1 |J^-1|_1) >= R, default 4e-3, i.e. cond_1 <= 250, the test of\n"
    "'prru map --rcond-min'; a pose of the other assembly mode counts as\n"
    "singular, as there), and every slider height d_i within the stroke (m) on\n"
    "the grid: the model's (actuators.stroke) unless --stroke replaces it (LO,HI\n"
    "or LO:HI for all sliders, or a pair each) or --no-limits drops it; one\n"
    "interval binds all sliders (their strokes' common part). --force-max and\n"
    "--speed-max are accepted (the limits options of every command) but w_R has\n"
    "no forces or speeds. The report names the limits. They enter as a penalty\n"
    "W x violation (default W\n"
    "1000), continuous so that an infeasible start (singular points in the\n"
    "rectangle) can move into feasibility; the result is accepted only when it\n"
    "is feasible.\n"
    "SPEC: NAME (bounds: the start value -+ PCT %%, default 20) or NAME=LO:HI.\n"
    "NAME: b l1 l2 (every limb), a (limbs 1, 2), or for some limbs b12 b3 a1\n"
    "l1_2 l2_13 ...; m_B com_B_x I_B_xx (I_B_yy I_B_zz I_B_xy I_B_xz I_B_yz) with\n"
    "B a body (P L1 U1 S1 ...) or L, U, S (that body of every limb); armature,\n"
    "armature_i. Tied parameters move by the same amount. --set: the start design\n"
    "is the model's numbers with these changes.\n"
    "Optimiser: the Nelder-Mead simplex method on a sine transform of each\n"
    "variable onto its bounds, restarted from the best point while that helps,\n"
    "at most N iterations in all (default 600); deterministic: the same command\n"
    "gives the same bits, whatever --threads (per evaluation, default 2).\n"
    "Progress on stderr (--progress, or a terminal).\n"
    "--precision float: each evaluation's w_R and slider range computed in\n"
    "single precision (as 'prru map --precision float': every point's status,\n"
    "and the conditioning where it is penalised, are double's); the report and\n"
    "the summary say so. Default double.\n"
    "Writes MODEL.json, the optimised design as a format-2 model file (name NAME,\n"
    "default the model's name + _opt), ready to build the tool and the dynamics\n"
    "code from ('make test MODEL=MODEL.json'), and DIR/ with report.txt (before\n"
    "and after: global index, mean ln w_R, max w_R, the share of the grid that\n"
    "is singular, unreachable or in the other assembly mode, slider range;\n"
    "every variable before, after and its bounds; iterations),\n"
    "before_map.csv and after_map.csv (as 'prru map' writes them) and\n"
    "optimize_maps.png (both w_R maps side by side on one viridis scale, colours\n"
    "clipped at --clip W, default the 99th percentile of both maps' w_R: the\n"
    "colour key says which). Nothing is written unless a\n"
    "feasible design is found (exit 1 otherwise); the files are built aside and\n"
    "renamed. Bad options, a start design that is not a buildable robot, bounds\n"
    "with LO >= HI or not around the start, a --report that is a file: exit 2.\n"
    "No regular grid point at the start: exit 1.\n";

static int parse_vars(const char *cmd, const char *text, double pct, const prru_params *p,
                      prru_design_var *vars, int *n)
{
  char *buf = strdup(text);
  int rc = buf ? 0 : 1;
  *n = 0;
  for (char *save = NULL, *it = buf ? strtok_r(buf, ",", &save) : NULL; it && !rc;
       it = strtok_r(NULL, ",", &save)) {
    char msg[512], *eq = strchr(it, '=');
    if (eq) *eq = '\0';
    if (*n >= PRRU_DESIGN_MAX_VARS) {
      prru_cli_error(cmd, "--vars: more than %d variables", PRRU_DESIGN_MAX_VARS);
      rc = 2;
    } else if (prru_design_var_parse(prru_cli_model(), it, &vars[*n], msg, sizeof msg) != PRRU_OK) {
      prru_cli_error(cmd, "--vars: %s", msg);
      rc = 2;
    } else if (eq) {
      char opt[64];
      snprintf(opt, sizeof opt, "vars %s=", it);
      rc = parse_pair(cmd, opt, eq + 1, &vars[*n].lo, &vars[*n].hi);
      (*n)++;
    } else {
      prru_design_var_bounds(prru_cli_model(), p, &vars[(*n)++], pct); /* every tied limb within pct % */
    }
  }
  free(buf);
  if (!rc && *n == 0) {
    prru_cli_error(cmd, "--vars: no variable given");
    rc = 2;
  }
  return rc;
}

typedef struct {
  int show;
  long last_ms;
} opt_progress;

static int on_iteration(int iter, int evals, const prru_design_eval *best, double size, void *ctx)
{
  opt_progress *p = ctx;
  if (p->show)
    fprintf(stderr, "\roptimize: iteration %4d, %5d evaluations, merit %.10g, index %.8g, "
                    "singular/unreachable/other mode %.3g %%, simplex %.2g   ",
            iter, evals, best->merit, best->sum.index, 100 * best->sum.singular_fraction, size);
  return prru_cli_interrupted != 0;
}

/* A map CSV as prru map writes it (after a second comment line saying
 * which design it is). */
static int write_map_file(const char *cmd, const char *path, const char *shown, const char *design,
                          const prru_map_grid *g, const prru_design_data *dd)
{
  prru_cli_out o;
  if (prru_cli_out_open(&o, cmd, path)) return 1;
  o.name = shown;
  prru_cli_out_comment(&o);
  prru_cli_out_comment_line(&o, "design: %s", design);
  prru_cli_out_printf(&o, "q1,q2,q3,w_R,status\n");
  prru_cli_out_line(&o);
  for (int i = 0; i < g->n1; i++)
    for (int j = 0; j < g->n2; j++) {
      long k = (long)i * g->n2 + j;
      map_row(&o, prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i), prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j),
              g->q3, dd->w_R[k], dd->status[k]);
      prru_cli_out_row(&o);
    }
  return prru_cli_out_close(&o, !o.err);
}

/* gnuplot's image plots want scans separated by blank lines. */
static int write_grid_dat(const char *path, const prru_map_grid *g, const prru_design_data *dd)
{
  FILE *f = fopen(path, "w");
  if (!f) return 1;
  for (int i = 0; i < g->n1; i++) {
    for (int j = 0; j < g->n2; j++) {
      long k = (long)i * g->n2 + j;
      fprintf(f, "%.9g %.9g ", prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i),
              prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j));
      if (dd->status[k] == PRRU_OK)
        fprintf(f, "%.9g\n", dd->w_R[k]);
      else
        fputs("NaN\n", f);
    }
    fputc('\n', f);
  }
  int bad = ferror(f) != 0;
  return (fclose(f) != 0 || bad) ? 1 : 0;
}

static void report_eval_rows(FILE *f, const prru_design_eval *a, const prru_design_eval *b)
{
  fprintf(f, "%-34s %22s %22s\n", "", "before", "after");
  fprintf(f, "%-34s %22.12g %22.12g\n", "global index (mean of w_R - 1)", a->sum.index, b->sum.index);
  fprintf(f, "%-34s %22.12g %22.12g\n", "mean of ln w_R", a->sum.index_log, b->sum.index_log);
  fprintf(f, "%-34s %22.12g %22.12g\n", "min w_R", a->sum.w_min, b->sum.w_min);
  fprintf(f, "%-34s %22.12g %22.12g\n", "max w_R", a->sum.w_max, b->sum.w_max);
  /* sum.n_singular counts the other assembly mode too (n_other_mode). */
  fprintf(f, "%-34s %21.6f%% %21.6f%%\n", "singular, unreachable, other mode",
          100 * a->sum.singular_fraction, 100 * b->sum.singular_fraction);
  fprintf(f, "%-34s %22ld %22ld\n", "  grid points", a->sum.n_singular + a->sum.n_unreachable,
          b->sum.n_singular + b->sum.n_unreachable);
  fprintf(f, "%-34s %22ld %22ld\n", "  of them in the other assembly mode", a->n_other_mode, b->n_other_mode);
  fprintf(f, "%-34s %10.6f..%-10.6f %10.6f..%-10.6f\n", "slider heights d (m)", a->d_min, a->d_max, b->d_min,
          b->d_max);
  fprintf(f, "%-34s %22.12g %22.12g\n", "objective", a->objective, b->objective);
  fprintf(f, "%-34s %22.12g %22.12g\n", "merit (objective + penalty)", a->merit, b->merit);
}

typedef struct {
  const prru_design_problem *pr;
  const prru_design_var *vars;
  int nvar;
  const prru_design_result *r;
  const prru_params *start;
  const char *out, *name;
  const char *set;
  double clip; /* the maps' colour clip, NaN: the percentile */
  int precision; /* of the evaluations (prru_design_options.precision) */
  const prru_limits *limits; /* the run's (optimize keeps the stroke) */
} opt_report;

static int write_report(const char *path, const opt_report *rp)
{
  FILE *f = fopen(path, "w");
  if (!f) return 1;
  const prru_design_problem *pr = rp->pr;
  const prru_map_grid *g = &pr->grid;
  const prru_design_result *r = rp->r;
  fprintf(f, "prru optimize: design optimisation of the rotational dynamic manipulability w_R\n");
  fprintf(f, "model: %s%s%s\n", prru_cli_model_id(), rp->set ? ", start changed by --set " : "",
          rp->set ? rp->set : "");
  if (rp->precision == PRRU_PRECISION_FLOAT) fprintf(f, "%s\n", PRRU_CLI_PRECISION_FLOAT_LINE);
  fprintf(f, "workspace: q1 in [%.17g, %.17g] (%d points), q2 in [%.17g, %.17g] (%d points), q3 = %.17g m\n",
          g->q1_lo, g->q1_hi, g->n1, g->q2_lo, g->q2_hi, g->n2, g->q3);
  fprintf(f, "regular: J_d's scaled rcond >= %g (cond_1 <= %g) at every grid point", pr->rcond_min,
          1 / pr->rcond_min);
  if (pr->stroke) fprintf(f, "; sliders within [%.17g, %.17g] m", pr->stroke_lo, pr->stroke_hi);
  {
    char lt[400];
    prru_limits_describe(prru_cli_model(), rp->limits, lt, sizeof lt);
    fprintf(f, "\nlimits: %s (w_R has no forces or speeds: only the stroke acts)", lt);
  }
  fprintf(f, "\nobjective: %s (%s), penalty weight %g\n", prru_objective_name(pr->objective),
          objective_text(pr->objective), pr->penalty_weight);
  fprintf(f, "optimiser: GSL nmsimplex2 on sine-transformed bounds, %d iterations, %d evaluations, "
             "%d restarts, %s\n\n",
          r->iterations, r->evaluations, r->restarts_done,
          r->converged ? "converged (simplex below tolerance)" : "stopped at the iteration limit");
  report_eval_rows(f, &r->start_eval, &r->best_eval);
  fprintf(f, "\n%-12s %22s %22s %22s %22s\n", "variable", "before", "after", "lower bound", "upper bound");
  for (int i = 0; i < rp->nvar; i++) {
    const prru_design_var *v = &rp->vars[i];
    fprintf(f, "%-12s %22.17g %22.17g %22.17g %22.17g%s\n", v->name, r->x0[i], r->x[i], v->lo, v->hi,
            r->x[i] <= v->lo + 1e-9 * (v->hi - v->lo) || r->x[i] >= v->hi - 1e-9 * (v->hi - v->lo)
                ? "  (at its bound)" : "");
  }
  fprintf(f, "\nbefore_index: %.17g\nafter_index: %.17g\n", r->start_eval.sum.index, r->best_eval.sum.index);
  fprintf(f, "before_objective: %.17g\nafter_objective: %.17g\n", r->start_eval.objective,
          r->best_eval.objective);
  fprintf(f, "before_singular_fraction: %.17g\nafter_singular_fraction: %.17g\n",
          r->start_eval.sum.singular_fraction, r->best_eval.sum.singular_fraction);
  fprintf(f, "after_max_w_R: %.17g\nafter_index_log: %.17g\n", r->best_eval.sum.w_max, r->best_eval.sum.index_log);
  fprintf(f, "model_file: %s (name %s)\n", rp->out, rp->name);
  int bad = ferror(f) != 0;
  return (fclose(f) != 0 || bad) ? 1 : 0;
}

static int is_dir(const char *p)
{
  struct stat s;
  return stat(p, &s) == 0 && S_ISDIR(s.st_mode);
}

static const char *const report_files[] = {"report.txt", "before_map.csv", "after_map.csv", "before.dat",
                                           "after.dat", "optimize_maps.gp", "optimize_maps.png"};
#define NREPORT ((int)(sizeof report_files / sizeof report_files[0]))

static void remove_stage(const char *stage)
{
  char path[4400];
  for (int i = 0; i < NREPORT; i++) {
    snprintf(path, sizeof path, "%s/%s", stage, report_files[i]);
    remove(path);
  }
  rmdir(stage);
}

/* The staged report becomes dir: renamed when dir is new, else its files
 * moved in (the data files, not the gnuplot inputs). */
static int publish_report(const char *cmd, const char *stage, const char *dir)
{
  if (!is_dir(dir)) {
    if (rename(stage, dir) == 0) return 0;
    prru_cli_error(cmd, "%s: %s", dir, strerror(errno));
    return 1;
  }
  char from[4400], to[4400];
  for (int i = 0; i < NREPORT; i++) {
    snprintf(from, sizeof from, "%s/%s", stage, report_files[i]);
    snprintf(to, sizeof to, "%s/%s", dir, report_files[i]);
    if (access(from, F_OK) == 0 && rename(from, to) != 0) {
      prru_cli_error(cmd, "%s: %s", to, strerror(errno));
      return 1;
    }
  }
  rmdir(stage);
  return 0;
}

/* The colour clip of the two maps a and b (one colour scale): clip when
 * given, else the percentile of both maps' ok values; NaN: no memory. */
static double map_clip(const prru_map_grid *g, const prru_design_data *a, const prru_design_data *b,
                       double clip)
{
  const size_t n = (size_t)g->n1 * (size_t)g->n2;
  double *ok = malloc(2 * n * sizeof *ok), w_max = 1.0;
  if (!ok) return isnan(clip) ? NAN : clip;
  size_t m = 0;
  const prru_design_data *dd[2] = {a, b};
  for (int s = 0; s < 2; s++)
    for (size_t k = 0; k < n; k++)
      if (dd[s]->status[k] == PRRU_OK) {
        ok[m++] = dd[s]->w_R[k];
        if (dd[s]->w_R[k] > w_max) w_max = dd[s]->w_R[k];
      }
  double c = prru_plot_clip_value(clip, ok, m, w_max);
  free(ok);
  return c;
}

/* Report files into stage; 0, 1 or 128 + signal (PNG missing without
 * gnuplot: a note, still 0). */
static int stage_report(const char *cmd, const char *stage, const char *dir, const opt_report *rp)
{
  const prru_design_problem *pr = rp->pr;
  prru_design_data a, b;
  prru_design_eval ea, eb;
  if (prru_design_data_alloc(&a, &pr->grid) != PRRU_OK) return 1;
  if (prru_design_data_alloc(&b, &pr->grid) != PRRU_OK) {
    prru_design_data_free(&a);
    return 1;
  }
  prru_design_evaluate(pr, rp->start, &a, &ea);
  prru_design_evaluate(pr, &rp->r->best, &b, &eb);
  char path[4400], shown[4400], design[512];
  int rc = 0;
  snprintf(path, sizeof path, "%s/report.txt", stage);
  if (write_report(path, rp)) {
    prru_cli_error(cmd, "%s/report.txt: write error", dir);
    rc = 1;
  }
  const char *names[2] = {"before_map.csv", "after_map.csv"};
  for (int s = 0; s < 2 && !rc; s++) {
    snprintf(path, sizeof path, "%s/%s", stage, names[s]);
    snprintf(shown, sizeof shown, "%s/%s", dir, names[s]);
    if (s == 0) snprintf(design, sizeof design, "start%s%s", rp->set ? " --set " : "", rp->set ? rp->set : "");
    else snprintf(design, sizeof design, "optimised, %s (name %s)", rp->out, rp->name);
    rc = write_map_file(cmd, path, shown, design, &pr->grid, s ? &b : &a);
  }
  const prru_design_data *dds[2] = {&a, &b};
  const char *dats[2] = {"before.dat", "after.dat"};
  for (int s = 0; s < 2 && !rc; s++) {
    snprintf(path, sizeof path, "%s/%s", stage, dats[s]);
    if (write_grid_dat(path, &pr->grid, dds[s])) {
      prru_cli_error(cmd, "%s/%s: write error", dir, dats[s]);
      rc = 1;
    }
  }
  if (!rc) {
    char *script = NULL;
    double clip = map_clip(&pr->grid, &a, &b, rp->clip), w_max = fmax(ea.sum.w_max, eb.sum.w_max);
    if (!isnan(clip))
      script = prru_plot_optimize_script(&pr->grid, pr->rcond_min, ea.sum.index, eb.sum.index,
                                         ea.sum.singular_fraction, eb.sum.singular_fraction, rp->name,
                                         clip, isnan(rp->clip), w_max);
    rc = script ? prru_plot_run(cmd, stage, dir, "optimize_maps.gp", script) : 1;
    free(script);
    if (rc == PRRU_PLOT_NO_GNUPLOT) {
      fprintf(stderr, "prru %s: gnuplot is not installed: %s/optimize_maps.png not drawn\n", cmd, dir);
      rc = 0;
    }
  }
  prru_design_data_free(&a);
  prru_design_data_free(&b);
  return rc;
}

static int check_name(const char *cmd, const char *name)
{
  const int ok = prru_model_name_valid(name);
  if (!ok) prru_cli_error(cmd, "--name '%s': a lower-case C identifier of at most 16 characters", name);
  return ok ? 0 : 2;
}

/* The model file's description: one line of at most 400 characters. */
static void describe(char *buf, size_t len, const prru_design_problem *pr, const prru_design_var *vars,
                     int nvar)
{
  const prru_map_grid *g = &pr->grid;
  int n = snprintf(buf, len, "%s optimised by prru optimize (%s over q1 in [%.4g, %.4g], q2 in [%.4g, %.4g], "
                             "q3 = %.4g; variables",
                   prru_cli_model()->mech->name, objective_text(pr->objective), g->q1_lo, g->q1_hi, g->q2_lo, g->q2_hi, g->q3);
  for (int i = 0; i < nvar && n > 0 && (size_t)n < len - 40; i++)
    n += snprintf(buf + n, len - (size_t)n, " %s", vars[i].name);
  if (n > 0 && (size_t)n < len - 2) snprintf(buf + n, len - (size_t)n, ")");
}

int prru_cmd_optimize(int argc, char **argv)
{
  const char *cmd = "optimize";
  problem_text t = {0};
  const char *vars_s = NULL, *out = NULL, *report = NULL, *range = NULL, *iters = NULL, *pen = NULL,
             *name_s = NULL, *ths = NULL, *clip_s = NULL, *prs = NULL;
  int help = 0, progress = 0;
  prru_cli_option opts[] = {
      {"vars", 1, &vars_s, NULL},      {"q1", 1, &t.q1, NULL},       {"q2", 1, &t.q2, NULL},
      {"q3", 1, &t.q3, NULL},          {"out", 1, &out, NULL},       {"report", 1, &report, NULL},
      {"range", 1, &range, NULL},      {"objective", 1, &t.objective, NULL},
      {"rcond-min", 1, &t.rcond, NULL}, PRRU_CLI_LIMIT_OPTIONS(t.lim), {"set", 1, &t.set, NULL},
      {"max-iter", 1, &iters, NULL},   {"penalty", 1, &pen, NULL},   {"name", 1, &name_s, NULL},
      {"threads", 1, &ths, NULL},      {"progress", 0, NULL, &progress}, {"clip", 1, &clip_s, NULL},
      {"help", 0, NULL, &help},        {"precision", 1, &prs, NULL}};
  if (prru_cli_parse(cmd, argc, argv, opts, (int)(sizeof opts / sizeof opts[0]))) return 2;
  if (help) {
    printf(opt_help);
    return 0;
  }
  double clip;
  if (prru_plot_parse_clip(cmd, clip_s, &clip)) return 2;
  const char *missing = !vars_s ? "--vars" : !t.q1 ? "--q1" : !t.q2 ? "--q2" : !out ? "--out"
                        : !report ? "--report" : NULL;
  if (missing) {
    prru_cli_error(cmd, "%s is required (see 'prru optimize --help')", missing);
    return 2;
  }
  prru_design_problem pr;
  prru_params start;
  t.limits = 1;
  if (parse_problem(cmd, &t, &pr, &start)) return 2;
  double pct = 20;
  if (range && (prru_cli_number(cmd, "range", range, &pct) || !(pct > 0 && pct < 100))) {
    if (pct > 0 && pct < 100) return 2;
    prru_cli_error(cmd, "--range '%s': a percentage in (0, 100)", range);
    return 2;
  }
  prru_design_options o;
  prru_design_options_default(&o);
  if (parse_threads(cmd, ths, &o.nthreads)) return 2;
  /* Every model's design runs on the parameter kernels, which have a float
   * batch: any precision named is available. */
  if (prs && (o.precision = prru_precision_parse(prs)) < 0) {
    prru_cli_error(cmd, "--precision '%s': must be double or float", prs);
    return 2;
  }
  if (iters) {
    char *end;
    long v = strtol(iters, &end, 10);
    if (!*iters || *end || v < 1 || v > 1000000) {
      prru_cli_error(cmd, "--max-iter '%s': an integer from 1 to 1000000", iters);
      return 2;
    }
    o.max_iter = (int)v;
  }
  if (pen && (prru_cli_number(cmd, "penalty", pen, &pr.penalty_weight) || !(pr.penalty_weight > 0))) {
    if (pr.penalty_weight > 0) return 2;
    prru_cli_error(cmd, "--penalty '%s': must be positive", pen);
    return 2;
  }
  char name[32];
  if (name_s) {
    if (check_name(cmd, name_s)) return 2;
    snprintf(name, sizeof name, "%s", name_s);
  } else {
    prru_model_name_derive(prru_cli_model()->mech->name, "_opt", name);
  }
  prru_design_var vars[PRRU_DESIGN_MAX_VARS];
  int nvar = 0, rc = parse_vars(cmd, vars_s, pct, &start, vars, &nvar);
  if (rc) return rc;
  char msg[512];
  for (int i = 0; i < nvar; i++) {
    double x = prru_design_get(&start, &vars[i]);
    if (!(x >= vars[i].lo && x <= vars[i].hi)) {
      prru_cli_error(cmd, "--vars %s: the start value %.17g is outside the bounds %.17g:%.17g", vars[i].name,
                     x, vars[i].lo, vars[i].hi);
      return 2;
    }
  }
  /* "DIR/" names DIR: its staging directory is a sibling. */
  char report_dir[4100];
  snprintf(report_dir, sizeof report_dir, "%s", report);
  for (size_t l = strlen(report_dir); l > 1 && report_dir[l - 1] == '/'; l--) report_dir[l - 1] = '\0';
  report = report_dir;
  struct stat rs;
  if (stat(report, &rs) == 0 && !S_ISDIR(rs.st_mode)) {
    prru_cli_error(cmd, "--report %s: exists and is not a directory", report);
    return 2;
  }
  /* Both outputs are checked before the optimisation runs. */
  prru_cli_catch_signals();
  prru_cli_out jo;
  if (prru_cli_out_open(&jo, cmd, out)) return 1;
  char stage[4200];
  snprintf(stage, sizeof stage, "%s.partial-XXXXXX", report);
  if (strlen(report) > 4000 || !mkdtemp(stage)) {
    prru_cli_error(cmd, "--report %s: cannot create a directory beside it: %s", report, strerror(errno));
    prru_cli_out_close(&jo, 0);
    return 1;
  }
  /* The stage becomes DIR: the mode mkdir(DIR, 0777) would give it, not
   * mkdtemp's private 0700. */
  mode_t mask = umask(0);
  umask(mask);
  chmod(stage, 0777 & ~mask);
  prru_design_data dd;
  prru_design_eval ev0;
  rc = prru_design_data_alloc(&dd, &pr.grid) == PRRU_OK ? 0 : 1;
  if (!rc) rc = base_eval(cmd, &pr, &start, &dd, &ev0);
  prru_design_data_free(&dd);
  opt_progress prog = {progress || isatty(2), 0};
  o.progress = on_iteration;
  o.ctx = &prog;
  prru_design_result *r = malloc(sizeof *r);
  if (!rc && !r) rc = 1;
  if (!rc) {
    int st = prru_design_optimize(&pr, &start, vars, nvar, &o, r, msg, sizeof msg);
    if (prog.show) fputc('\n', stderr);
    if (st == PRRU_EINTERRUPTED) {
      prru_cli_error(cmd, "interrupted (%s): nothing written", prru_cli_signal_name());
      rc = prru_cli_exit_interrupted();
    } else if (st != PRRU_OK) {
      prru_cli_error(cmd, "%s", msg);
      rc = st == PRRU_EINPUT ? 2 : 1;
    } else if (!r->best_eval.feasible) {
      prru_cli_error(cmd, "no feasible design found: the best has %.4g %% of the grid singular, "
                          "unreachable or in the other assembly mode and a stroke violation of "
                          "%.3g; nothing written (widen the bounds, shrink the rectangle or "
                          "loosen --rcond-min / --stroke)",
                     100 * r->best_eval.sum.singular_fraction, r->best_eval.stroke_violation);
      rc = 1;
    }
  }
  char desc[420];
  if (!rc) {
    describe(desc, sizeof desc, &pr, vars, nvar);
    char *text = NULL, why[800];
    if (prru_model_file_text(prru_cli_model(), &r->best, name, desc, &text, why, sizeof why) != PRRU_OK) {
      prru_cli_error(cmd, "internal error: %s; %s not written", why, out);
      rc = 1;
    } else {
      prru_cli_out_write(&jo, text, strlen(text));
      prru_cli_out_line(&jo);
    }
    free(text);
  }
  if (!rc) {
    opt_report rp = {&pr, vars, nvar, r, &start, out, name, t.set, clip, o.precision, &t.run};
    rc = stage_report(cmd, stage, report, &rp);
  }
  if (prru_cli_out_close(&jo, rc == 0 && !jo.err) && !rc) rc = 1;
  if (!rc) rc = publish_report(cmd, stage, report);
  if (rc) remove_stage(stage);
  if (!rc) {
    printf("model: %s\n", prru_cli_model_id());
    if (o.precision == PRRU_PRECISION_FLOAT) printf("%s\n", PRRU_CLI_PRECISION_FLOAT_LINE);
    report_eval_rows(stdout, &r->start_eval, &r->best_eval);
    for (int i = 0; i < nvar; i++)
      printf("%-12s %.10g -> %.10g  [%.10g, %.10g]\n", vars[i].name, r->x0[i], r->x[i], vars[i].lo, vars[i].hi);
    printf("before_index: %.17g\nafter_index: %.17g\nwrote %s and %s/\n", r->start_eval.sum.index,
           r->best_eval.sum.index, out, report);
  }
  free(r);
  return rc;
}
