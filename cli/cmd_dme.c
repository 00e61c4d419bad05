/* prru dme, prru map and the fig. 7 part of prru paper: the rotational
 * dynamic manipulability ellipse and w_R at one pose, w_R over a grid, and
 * the paper's workspace study with its gnuplot figures. */
#define _POSIX_C_SOURCE 200809L /* isatty, open_memstream */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"
#include "prru.h"
#include "prru_dme.h"

#define FIG7_PI 3.14159265358979323846
/* Fig. 7's practical-singularity tolerance: J_d counts as singular where
 * cond_1 > 250 (of J_d with its rotation columns in units of the model's
 * length, see prru_check_regular; the paper's home pose has about 4). With
 * the model's numerical 1e-8 no grid point is flagged, w_R spikes to
 * ~1e2-1e5 next to the locus det J_d = 0 and the global index depends on
 * the resolution (prru_dme.h); with 4e-3 the band around the locus is
 * marked and the index converges. The summary gives both. */
#define FIG7_RCOND_MIN 4e-3

/* %s: the inverse of J_d and its explanation. */
static const char dme_help[] =
    "usage: prru dme --q q1,q2,q3 [--rcond-min R]\n"
    "Dynamic manipulability at the pose q (rad, rad, m), paper section 5: with\n"
    "Mt = J_d^%s M J_d^%s and JtR = J_R,P J_d^%s, the rotational ellipse is the\n"
    "set of platform angular accelerations a in span{e1, v} with\n"
    "|Mt JtR^+ a| <= 1 N; its semi-axes have lengths 1/sigma_i (rad/s^2 per N)\n"
    "along the right singular vectors of Mt JtR^+ (unit, in {S});\n"
    "w_R = sigma_1/sigma_2 (>= 1). The translational segment runs along z with\n"
    "half-length 1/sigma_T (m/s^2 per N).\n"
    "%s"
    "Prints JSON: model (name, file, sha256), q, status (\"ok\", \"singular\" or\n"
    "\"unreachable\"), w_R, Jd_rcond,\n"
    "sigma, semi_axes (minor, major), axis_directions, sigma_T,\n"
    "translational_half_length, translational_direction, Mt (%dx%d), JtR and\n"
    "JtT (3x%d). At a singular or unreachable pose the status says so and\n"
    "every quantity that is not defined there is null; that is still a valid\n"
    "answer (exit 0).\n"
    "J_d counts as singular when 1/(|J|_1 |J^%s|_1) < R, J = J_d with its\n"
    "rotation columns divided by the mean upper-link length (default R: the\n"
    "model's 1e-8).\n";

static const char dme_inverse_3[] =
    "J_d^-1 is the inverse of the 3x3 J_d (three actuators).\n";
static const char dme_inverse_redundant[] =
    "This model has %d actuators: J_d is %dx3 and J_d^+ = (J_d^T J_d)^-1 J_d^T,\n"
    "its pseudo-inverse (for three actuators J_d^-1), so that Mt maps actuator\n"
    "accelerations in range(J_d) to the least-norm drive forces.\n";

static void print_dme_help(void)
{
  char inv[sizeof dme_inverse_redundant + 32];
  const char *pinv = PRRU_NACT > 3 ? "+" : "-1", *pinvT = PRRU_NACT > 3 ? "+T" : "-T";
  if (PRRU_NACT > 3)
    snprintf(inv, sizeof inv, dme_inverse_redundant, PRRU_NACT, PRRU_NACT);
  else
    snprintf(inv, sizeof inv, "%s", dme_inverse_3);
  printf(dme_help, pinvT, pinv, pinv, inv, PRRU_NACT, PRRU_NACT, PRRU_NACT, pinv);
}

static int parse_rcond(const char *cmd, const char *text, prru_model *m)
{
  if (!text) return 0;
  double r;
  if (prru_cli_number(cmd, "rcond-min", text, &r)) return 2;
  if (!(r >= 0.0 && r < 1.0)) {
    prru_cli_error(cmd, "--rcond-min '%s': must be in [0, 1)", text);
    return 2;
  }
  m->jd_rcond_min = r;
  return 0;
}

static void json_vec(FILE *f, const double *v, int n)
{
  prru_cli_json_array(f, v, n, 1);
}

int prru_cmd_dme(int argc, char **argv)
{
  const char *qs = NULL, *rcs = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL}, {"rcond-min", 1, &rcs, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("dme", argc, argv, opts, 3)) return 2;
  if (help) {
    print_dme_help();
    return 0;
  }
  if (!qs) {
    prru_cli_error("dme", "--q is required (see 'prru dme --help')");
    return 2;
  }
  double q[PRRU_NQ];
  if (prru_cli_numbers("dme", "q", qs, q, PRRU_NQ)) return 2;
  prru_model m;
  prru_model_default(&m);
  if (parse_rcond("dme", rcs, &m)) return 2;
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  prru_dme r;
  int st = prru_dme_eval(&m, d, q, &r);
  free(d);
  if (st == PRRU_EINPUT) { /* cannot happen after prru_cli_numbers; kept as a guard */
    prru_cli_error("dme", "q: %s", prru_strerror(st));
    return 2;
  }
  FILE *f = stdout;
  fputc('{', f);
  prru_cli_json_model(f);
  fputs(",\n \"q\": ", f);
  json_vec(f, q, PRRU_NQ);
  fprintf(f, ", \"status\": \"%s\", \"w_R\": ", prru_dme_status_name(st));
  prru_cli_json_number(f, r.w_R);
  fputs(", \"Jd_rcond\": ", f);
  prru_cli_json_number(f, st == PRRU_EUNREACHABLE ? NAN : r.jd_rcond);
  fputs(", \"sigma\": ", f);
  json_vec(f, r.sigma, 2);
  fputs(", \"semi_axes\": ", f);
  json_vec(f, r.semi_axis, 2);
  fputs(", \"axis_directions\": ", f);
  prru_cli_json_array(f, &r.axis_dir[0][0], 6, 2);
  fputs(", \"sigma_T\": ", f);
  prru_cli_json_number(f, r.sigma_T);
  fputs(", \"translational_half_length\": ", f);
  prru_cli_json_number(f, r.half_length_T);
  fputs(", \"translational_direction\": ", f);
  json_vec(f, r.dir_T, 3);
  fputs(", \"Mt\": ", f);
  prru_cli_json_array(f, r.Mt, PRRU_NACT * PRRU_NACT, PRRU_NACT);
  fputs(", \"JtR\": ", f);
  prru_cli_json_array(f, r.JtR, 3 * PRRU_NACT, 3);
  fputs(", \"JtT\": ", f);
  prru_cli_json_array(f, r.JtT, 3 * PRRU_NACT, 3);
  fputs("}\n", f);
  return ferror(f) ? 1 : 0;
}

/* ---- prru map ---- */

static const char map_help[] =
    "usage: prru map --q1 START:STOP:COUNT --q2 START:STOP:COUNT [--q3 Z]\n"
    "                --out FILE.csv [--rcond-min R] [--threads N] [--progress]\n"
    "w_R (see 'prru dme --help') at every grid point q1 = START..STOP (COUNT\n"
    "equally spaced values, rad, COUNT >= 2, START < STOP), q2 likewise, q3 = Z\n"
    "(m, default 0). Writes FILE.csv: the model line (# prru ... model ...), then\n"
    "the columns q1,q2,q3,w_R,status (q1 outer); where the pose is singular or\n"
    "unreachable w_R is NaN and status says which. Prints to stdout the model\n"
    "(name, file, sha256) and the global index: the mean of w_R - 1 over the ok\n"
    "points, with the fraction of the grid that is singular or unreachable (the\n"
    "index alone favours a design that loses workspace); also the mean of ln w_R\n"
    "and the range of w_R. J_d counts as singular when 1/(|J|_1 |J^%s|_1) < R,\n"
    "J = J_d with its rotation columns divided by the mean upper-link length\n"
    "(default R: 1e-8). If the grid crosses the singular locus, the mean of\n"
    "w_R - 1 depends on how close grid points fall to it: compare designs with\n"
    "a practical tolerance such as --rcond-min 4e-3. Uses N threads\n"
    "(default 2); a progress bar goes to stderr for grids over 10000 points when\n"
    "stderr is a terminal, or always with --progress.\n"
    "FILE is checked before the grid is computed, built as FILE.partial-XXXXXX\n"
    "and renamed at the end: it keeps its old contents until then. SIGINT,\n"
    "SIGTERM or SIGHUP (exit 130, 143, 129) stop the computation; the complete\n"
    "q1 rows computed so far are then written (a second signal stops that too,\n"
    "at a row boundary) and no summary is printed. A write error exits 1 with\n"
    "the reason and leaves FILE unchanged.\n";

/* "a:b:n" with finite a < b and an integer 2 <= n <= 1e6; 0 or 2. */
static int parse_range(const char *name, const char *text, double *lo, double *hi, int *n)
{
  char buf[256];
  const char *c1 = strchr(text, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
  if (!c1 || !c2 || strchr(c2 + 1, ':') || strlen(text) >= sizeof buf) {
    prru_cli_error("map", "--%s '%s': expected START:STOP:COUNT (e.g. -0.5:0.5:101)", name, text);
    return 2;
  }
  strcpy(buf, text);
  char *a = buf, *b = buf + (c1 - text) + 1, *cnt = buf + (c2 - text) + 1;
  b[-1] = cnt[-1] = '\0';
  if (prru_parse_double(a, lo) != PRRU_OK) {
    prru_cli_error("map", "--%s '%s': START '%s' is not a finite number", name, text, a);
    return 2;
  }
  if (prru_parse_double(b, hi) != PRRU_OK) {
    prru_cli_error("map", "--%s '%s': STOP '%s' is not a finite number", name, text, b);
    return 2;
  }
  char *end;
  long v = *cnt ? strtol(cnt, &end, 10) : 0;
  if (!*cnt || *end || v < 2 || v > 1000000) {
    prru_cli_error("map", "--%s '%s': COUNT '%s' must be an integer from 2 to 1000000", name,
                   text, cnt);
    return 2;
  }
  if (!(*lo < *hi)) {
    prru_cli_error("map", "--%s '%s': START must be less than STOP", name, text);
    return 2;
  }
  if (!isfinite(*hi - *lo)) {
    prru_cli_error("map", "--%s '%s': the range STOP - START overflows", name, text);
    return 2;
  }
  *n = (int)v;
  return 0;
}

typedef struct {
  int last; /* last percentage drawn */
} progress_bar;

static int draw_progress(long done, long total, void *ctx)
{
  progress_bar *p = ctx;
  int pct = (int)(100.0 * (double)done / (double)total);
  if (pct != p->last) {
    char bar[41];
    int fill = pct * 40 / 100;
    for (int i = 0; i < 40; i++) bar[i] = i < fill ? '#' : '.';
    bar[40] = '\0';
    fprintf(stderr, "\rmap [%s] %3d%% (%ld/%ld points)", bar, pct, done, total);
    if (done == total) fputc('\n', stderr);
    fflush(stderr);
    p->last = pct;
  }
  return 0;
}

/* Grid statuses start as this: prru_map_eval writes a prru_status (small)
 * for every point it evaluated. */
#define MAP_NOT_DONE 0xFF

/* The q1 rows of an interrupted map that are complete: prru_map_eval hands
 * rows out in order and finishes every row it started. */
static int map_rows_done(const prru_map_grid *g, const unsigned char *st)
{
  long n = (long)g->n1 * g->n2, k = 0;
  while (k < n && st[k] != MAP_NOT_DONE) k++;
  return (int)(k / g->n2);
}

/* The map's CSV (comment, header, the first nrows q1 rows) into o;
 * PRRU_OK, PRRU_EIO (o->err) or PRRU_EINTERRUPTED when a signal arrives
 * (one more than the signal_count it started with) before the last row. */
static int write_map_csv(prru_cli_out *o, const prru_map_grid *g, const double *w,
                         const unsigned char *st, int nrows, int signal_count)
{
  prru_cli_out_comment(o);
  prru_cli_out_printf(o, "q1,q2,q3,w_R,status\n");
  prru_cli_out_line(o);
  for (int i = 0; i < nrows; i++) {
    double q1 = prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i);
    for (int j = 0; j < g->n2; j++) {
      if (prru_cli_signal_count != signal_count) return PRRU_EINTERRUPTED;
      long k = (long)i * g->n2 + j;
      double q2 = prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j);
      if (st[k] == PRRU_OK)
        prru_cli_out_printf(o, "%.17g,%.17g,%.17g,%.17g,ok\n", q1, q2, g->q3, w[k]);
      else
        prru_cli_out_printf(o, "%.17g,%.17g,%.17g,NaN,%s\n", q1, q2, g->q3, prru_dme_status_name(st[k]));
      if (prru_cli_out_row(o)) return PRRU_EIO;
    }
  }
  return prru_cli_out_flush(o) ? PRRU_EIO : PRRU_OK;
}

static void print_summary(FILE *f, const prru_map_summary *s, double rcond_min)
{
  fprintf(f, "model: %s\n", prru_cli_model_id());
  fprintf(f, "points: %ld (ok %ld, singular %ld, unreachable %ld; J_d singular below rcond %g)\n",
          s->n_points, s->n_ok, s->n_singular, s->n_unreachable, rcond_min);
  fprintf(f, "global_index: %.10g (mean of w_R - 1 over the ok points)\n", s->index);
  fprintf(f, "singular_fraction: %.10g (singular or unreachable share of the grid)\n",
          s->singular_fraction);
  fprintf(f, "index_log: %.10g (mean of ln w_R over the ok points)\n", s->index_log);
  if (s->n_ok)
    fprintf(f, "w_R range: %.10g at (q1, q2) = (%.6f, %.6f) to %.10g at (%.6f, %.6f)\n", s->w_min,
            s->w_min_q[0], s->w_min_q[1], s->w_max, s->w_max_q[0], s->w_max_q[1]);
}

/* Allocates and evaluates a map (statuses MAP_NOT_DONE where it did not
 * get to): PRRU_OK, PRRU_EINTERRUPTED (a signal: the rows done so far are
 * in w and st) or another status after a message. */
static int run_map(const char *cmd, const prru_model *m, const prru_map_grid *g, int nthreads,
                   int progress, double **w, unsigned char **st, prru_map_summary *sum)
{
  size_t n = (size_t)g->n1 * (size_t)g->n2;
  *w = malloc(n * sizeof **w);
  *st = malloc(n);
  if (!*w || !*st) {
    prru_cli_error(cmd, "out of memory for %zu grid points", n);
    return PRRU_ENOMEM;
  }
  memset(*st, MAP_NOT_DONE, n);
  prru_map_options o;
  prru_map_options_default(&o);
  o.nthreads = nthreads;
  progress_bar bar = {-1};
  if (progress) {
    o.progress = draw_progress;
    o.ctx = &bar;
  }
  o.interrupt = &prru_cli_interrupted;
  int rc = prru_map_eval(m, g, &o, *w, *st, sum);
  if (rc != PRRU_OK) {
    if (progress) fputc('\n', stderr);
    if (rc != PRRU_EINTERRUPTED) prru_cli_error(cmd, "map: %s", prru_strerror(rc));
  }
  return rc;
}

int prru_cmd_map(int argc, char **argv)
{
  const char *q1s = NULL, *q2s = NULL, *q3s = NULL, *out = NULL, *rcs = NULL, *ths = NULL;
  int help = 0, progress = 0;
  prru_cli_option opts[] = {{"q1", 1, &q1s, NULL},        {"q2", 1, &q2s, NULL},
                            {"q3", 1, &q3s, NULL},        {"out", 1, &out, NULL},
                            {"rcond-min", 1, &rcs, NULL}, {"threads", 1, &ths, NULL},
                            {"progress", 0, NULL, &progress}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("map", argc, argv, opts, 8)) return 2;
  if (help) {
    printf(map_help, PRRU_NACT > 3 ? "+" : "-1");
    return 0;
  }
  const char *missing = !q1s ? "--q1" : !q2s ? "--q2" : !out ? "--out" : NULL;
  if (missing) {
    prru_cli_error("map", "%s is required (see 'prru map --help')", missing);
    return 2;
  }
  prru_map_grid g = {0, 0, 0, 0, 0.0, 0, 0};
  if (parse_range("q1", q1s, &g.q1_lo, &g.q1_hi, &g.n1)) return 2;
  if (parse_range("q2", q2s, &g.q2_lo, &g.q2_hi, &g.n2)) return 2;
  if (q3s && prru_cli_number("map", "q3", q3s, &g.q3)) return 2;
  if ((double)g.n1 * (double)g.n2 > 5e7) {
    prru_cli_error("map", "--q1/--q2: %d x %d points is more than the limit of 5e7", g.n1, g.n2);
    return 2;
  }
  int nthreads = 2;
  if (ths) {
    char *end;
    long v = strtol(ths, &end, 10);
    if (!*ths || *end || v < 1 || v > 256) {
      prru_cli_error("map", "--threads '%s': must be an integer from 1 to 256", ths);
      return 2;
    }
    nthreads = (int)v;
  }
  prru_model m;
  prru_model_default(&m);
  if (parse_rcond("map", rcs, &m)) return 2;
  if (strcmp(out, "-") == 0) {
    prru_cli_error("map", "--out -: the summary goes to stdout; give the CSV a file name");
    return 2;
  }
  long npts = (long)g.n1 * g.n2;
  int show = progress || (npts > 10000 && isatty(2));
  /* The output is created (and so checked) before the grid is computed. */
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, "map", out)) return 1;
  double *w = NULL;
  unsigned char *st = NULL;
  prru_map_summary sum;
  int rc = run_map("map", &m, &g, nthreads, show, &w, &st, &sum);
  int nrows = rc == PRRU_OK ? g.n1 : rc == PRRU_EINTERRUPTED ? map_rows_done(&g, st) : 0;
  /* After a first signal the rows computed are still written; a later
   * one stops that too. */
  int wst = nrows > 0 ? write_map_csv(&o, &g, w, st, nrows, prru_cli_signal_count) : PRRU_OK;
  if (wst == PRRU_EINTERRUPTED) rc = PRRU_EINTERRUPTED;
  long rows = o.rows;
  int status;
  if (prru_cli_out_close(&o, !o.err && rows > 0)) {
    status = 1;
  } else if (rc == PRRU_EINTERRUPTED) {
    if (rows > 0)
      prru_cli_error("map", "interrupted (%s): %ld of %ld grid points written to %s, no summary",
                     prru_cli_signal_name(), rows, npts, out);
    else
      prru_cli_error("map", "interrupted (%s): nothing written, %s is not changed",
                     prru_cli_signal_name(), out);
    status = prru_cli_exit_interrupted();
  } else if (rc != PRRU_OK) {
    status = 1;
  } else {
    print_summary(stdout, &sum, m.jd_rcond_min);
    status = 0;
  }
  free(w);
  free(st);
  return status;
}

/* ---- prru paper: fig. 7 ---- */

/* The surface and the contour map of w_R, singular points in red, and the
 * ellipses of fig. 7a. Run in the output directory. */
static const char fig7_script[] =
    "# Written by prru paper (cli/cmd_dme.c); run in the output directory.\n"
    "# Fig. 7 surface: log z so that both the 1.0-2.2 landscape and the rise to\n"
    "# ~15 at the edge of the singular band (red, on the base plane) show.\n"
    "set terminal pngcairo size 1100,800 enhanced font 'Sans,11'\n"
    "grid = 'fig7_grid.dat'\n"
    "sing = 'fig7_singular.dat'\n"
    "stats grid using 3 nooutput\n"
    "set xlabel 'q_1 (rad)'\n"
    "set ylabel 'q_2 (rad)'\n"
    "set xrange [-pi/6:pi/6]\n"
    "set yrange [-pi/4:pi/6]\n"
    "set palette defined (0 '#440154', 0.25 '#3b528b', 0.5 '#21918c', 0.75 '#5ec962', 1 '#fde725')\n"
    "set output 'fig7_surface.png'\n"
    "set title sprintf(\"Rotational dynamic manipulability index w_R over the workspace, q_3 = 0 m (paper fig. 7), model %s\\n201 x 201 grid, w_R from %.3f to %.3g; red: J_d singular, cond_1 > 250\", model, STATS_min, STATS_max)\n"
    "set zlabel 'w_R (-), log scale' rotate by 90\n"
    "set logscale z\n"
    "set logscale cb\n"
    "set zrange [1:20]\n"
    "set cbrange [1:20]\n"
    "set ztics (1, 1.2, 1.5, 2, 3, 5, 10, 20)\n"
    "set cbtics (1, 1.2, 1.5, 2, 3, 5, 10, 20)\n"
    "set cblabel 'w_R = {/Symbol s}_1/{/Symbol s}_2 (-)'\n"
    "set xyplane at 1\n"
    "set view 55, 35\n"
    "set pm3d depthorder border lc rgb '#303030' lw 0.2\n"
    "set key at screen 0.98, screen 0.90 box opaque\n"
    "set grid\n"
    "splot grid using 1:2:3 every 2:2 with pm3d title 'w_R(q_1, q_2)', \\\n"
    "      sing using 1:2:(1) with points pt 7 ps 0.5 lc rgb 'red' title 'singular / unreachable (base plane)'\n"
    "# Fig. 7 contour map: contours via a table, linear colours to 2.5 (the\n"
    "# band next to the singular points saturates).\n"
    "set output 'fig7_contour.png'\n"
    "set terminal pngcairo size 1000,850 enhanced font 'Sans,11'\n"
    "set contour base\n"
    "set cntrparam levels discrete 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 1.9, 2.0, 2.1, 2.5, 3, 5, 10\n"
    "unset surface\n"
    "unset logscale z\n"
    "set zrange [*:*]\n"
    "set table 'fig7_contours.dat'\n"
    "splot grid using 1:2:3 with lines notitle\n"
    "unset table\n"
    "unset contour\n"
    "set surface\n"
    "unset logscale cb\n"
    "set cbrange [1:2.5]\n"
    "set cbtics auto\n"
    "set title \"w_R over the workspace, q_3 = 0 m (paper fig. 7), model \".model.\", contours 1.1 to 2.1 by 0.1, then 2.5, 3, 5, 10\\nred: J_d singular, cond_1 > 250 (the corners beyond that band are another assembly mode)\"\n"
    "set size ratio -1\n"
    "set key inside left top textcolor rgb 'white' noopaque nobox\n"
    "set grid front\n"
    "plot grid using 1:2:(($3 > 2.5) ? 2.5 : $3) with image notitle, \\\n"
    "     'fig7_contours.dat' using 1:2 with lines lc rgb 'white' lw 1 title 'w_R contours', \\\n"
    "     sing using 1:2 with points pt 7 ps 0.35 lc rgb 'red' title 'singular / unreachable grid points'\n"
    "# Fig. 7a: ellipse outlines in (a.e1, a.v) and segment half-lengths.\n"
    "set output 'fig7a_ellipses.png'\n"
    "set terminal pngcairo size 1300,650 enhanced font 'Sans,11'\n"
    "set key default\n"
    "unset colorbox\n"
    "unset logscale\n"
    "set size noratio\n"
    "set key outside bottom center horizontal\n"
    "set multiplot layout 1,2 title 'Dynamic manipulability at a few poses, q_3 = 0 m: accelerations reachable with 1 N of actuator force (paper fig. 7a), model '.model\n"
    "set title 'Rotational DME (in the plane of e_1 and v)'\n"
    "set xlabel 'angular acceleration along e_1 (rad s^{-2} per N)'\n"
    "set ylabel 'angular acceleration along v (rad s^{-2} per N)'\n"
    "set size ratio -1\n"
    "set xrange [-1:1]\n"
    "set yrange [-2:2]\n"
    "set xtics 0.5\n"
    "plot for [i=0:NCONF-1] 'fig7a_ellipses.dat' index i using 1:2 with lines lw 2 lc i+1 title columnheader(1)\n"
    "set size noratio\n"
    "set title 'Translational DME (a segment along z)'\n"
    "set xlabel 'pose (q_1, q_2) (rad)'\n"
    "set ylabel 'linear acceleration along z (m s^{-2} per N)'\n"
    "set xrange [-0.5:NCONF-0.5]\n"
    "set yrange [*:*]\n"
    "set xtics 1\n"
    "set key off\n"
    "plot 'fig7a_segments.dat' using 1:(-$2):(0):(2*$2):($1+1):xtic(3) with vectors nohead lw 8 lc variable\n"
    "unset multiplot\n";

static const double fig7a_poses[][2] = {{0.0, 0.0}, {0.4, 0.0}, {0.0, 0.45}, {0.0, -0.6}, {0.3, -0.5}};
#define FIG7A_NPOSE ((int)(sizeof fig7a_poses / sizeof fig7a_poses[0]))

/* Where prru paper builds its files (stage) and where they will be (out,
 * named in messages). */
typedef struct {
  const char *stage, *out;
} fig7_dirs;

/* stage/name for writing; shown = out/name for messages. */
static FILE *open_out(const fig7_dirs *dirs, const char *name, char *shown, size_t len)
{
  char path[4200];
  snprintf(path, sizeof path, "%s/%s", dirs->stage, name);
  snprintf(shown, len, "%s/%s", dirs->out, name);
  FILE *f = fopen(path, "w");
  if (!f) prru_cli_error("paper", "%s: cannot open for writing: %s", shown, strerror(errno));
  return f;
}

static int close_out(FILE *f, const char *shown)
{
  errno = 0;
  int bad = ferror(f) != 0, e = 0;
  if (fflush(f) != 0) bad = 1;
  e = errno;
  if (fclose(f) != 0 && !bad) {
    bad = 1;
    e = errno;
  }
  if (bad) {
    prru_cli_error("paper", "%s: write error: %s", shown, e ? strerror(e) : "output lost");
    return 1;
  }
  return 0;
}

/* Ellipse outlines (a . e1, a . v) and segment half-lengths at the fig. 7a
 * poses; the script needs their count. */
static int write_fig7a(const fig7_dirs *dirs, const prru_model *m, prru_data *d)
{
  char path[4200];
  FILE *fe = open_out(dirs, "fig7a_ellipses.dat", path, sizeof path);
  if (!fe) return 1;
  char path2[4200];
  FILE *fs = open_out(dirs, "fig7a_segments.dat", path2, sizeof path2);
  if (!fs) {
    fclose(fe);
    return 1;
  }
  prru_cli_csv_comment(fe);
  prru_cli_csv_comment(fs);
  fputs("# pose index, half-length (m/s^2 per N), label\n", fs);
  for (int k = 0; k < FIG7A_NPOSE; k++) {
    double q[PRRU_NQ] = {fig7a_poses[k][0], fig7a_poses[k][1], 0.0};
    prru_dme r;
    int st = prru_dme_eval(m, d, q, &r);
    char label[96];
    snprintf(label, sizeof label, "q=(%.2f, %.2f) w_R=%.3f", q[0], q[1], r.w_R);
    fprintf(fe, "\"%s\"\n", label);
    if (st == PRRU_OK) {
      const double v[3] = {0.0, cos(q[0]), sin(q[0])}; /* R_P e2 = Rx(q1) e2 */
      for (int i = 0; i <= 180; i++) {
        double t = 2.0 * FIG7_PI * i / 180.0, a[3];
        for (int c = 0; c < 3; c++)
          a[c] = r.semi_axis[0] * cos(t) * r.axis_dir[0][c] + r.semi_axis[1] * sin(t) * r.axis_dir[1][c];
        fprintf(fe, "%.9g %.9g\n", a[0], a[1] * v[1] + a[2] * v[2]);
      }
    }
    fputs("\n\n", fe);
    fprintf(fs, "%d %.9g \"(%.2f, %.2f)\"\n", k, r.half_length_T, q[0], q[1]);
  }
  int rc = close_out(fe, path);
  rc |= close_out(fs, path2);
  return rc;
}

/* The exit status for a map or write status of the fig. 7 part. */
static int fig7_status(int st)
{
  return st == PRRU_OK ? 0 : prru_cli_exit_for(st);
}

int prru_paper_fig7(const char *stage, const char *outdir, FILE *summary)
{
  const fig7_dirs dirs = {stage, outdir};
  prru_model m;
  prru_model_default(&m);
  const double rcond_numeric = m.jd_rcond_min;
  m.jd_rcond_min = FIG7_RCOND_MIN;
  prru_map_grid g = {-FIG7_PI / 6, FIG7_PI / 6, -FIG7_PI / 4, FIG7_PI / 6, 0.0, 201, 201};
  double *w = NULL;
  unsigned char *st = NULL;
  prru_map_summary sum, sum_numeric;
  int rc = fig7_status(run_map("paper", &m, &g, 2, 0, &w, &st, &sum));
  if (rc == 0) {
    /* The same grid at the numerical tolerance, for the summary only. */
    prru_model mn = m;
    mn.jd_rcond_min = rcond_numeric;
    prru_map_options o;
    prru_map_options_default(&o);
    o.interrupt = &prru_cli_interrupted;
    double *w2 = malloc((size_t)g.n1 * g.n2 * sizeof *w2);
    unsigned char *st2 = malloc((size_t)g.n1 * g.n2);
    int s2 = w2 && st2 ? prru_map_eval(&mn, &g, &o, w2, st2, &sum_numeric) : PRRU_ENOMEM;
    if (s2 == PRRU_EINTERRUPTED) {
      rc = prru_cli_exit_interrupted();
    } else if (s2 != PRRU_OK) {
      prru_cli_error("paper", "fig. 7 map at the numerical tolerance: %s", prru_strerror(s2));
      rc = 1;
    }
    free(w2);
    free(st2);
  }
  char path[4200];
  if (rc == 0) {
    char shown[4200];
    prru_cli_out o;
    snprintf(path, sizeof path, "%s/fig7_map.csv", stage);
    snprintf(shown, sizeof shown, "%s/fig7_map.csv", outdir);
    rc = prru_cli_out_open(&o, "paper", path);
    if (rc == 0) {
      o.name = shown;
      /* A signal stops it (and the run: nothing of it is kept). */
      int ws = write_map_csv(&o, &g, w, st, g.n1, prru_cli_signal_count);
      rc = prru_cli_out_close(&o, ws == PRRU_OK);
      if (rc == 0 && ws != PRRU_OK) rc = fig7_status(ws);
    }
  }
  /* gnuplot's pm3d and image want scans separated by blank lines. */
  FILE *f = rc == 0 ? open_out(&dirs, "fig7_grid.dat", path, sizeof path) : NULL;
  if (rc == 0 && !f) rc = 1;
  if (f) {
    prru_cli_csv_comment(f);
    fputs("# q1 (rad) q2 (rad) w_R (NaN: singular or unreachable)\n", f);
    for (int i = 0; i < g.n1; i++) {
      for (int j = 0; j < g.n2; j++) {
        long k = (long)i * g.n2 + j;
        fprintf(f, "%.9g %.9g ", prru_map_axis(g.q1_lo, g.q1_hi, g.n1, i),
                prru_map_axis(g.q2_lo, g.q2_hi, g.n2, j));
        if (st[k] == PRRU_OK)
          fprintf(f, "%.9g\n", w[k]);
        else
          fputs("NaN\n", f);
      }
      fputc('\n', f);
    }
    rc = close_out(f, path);
  }
  f = rc == 0 ? open_out(&dirs, "fig7_singular.dat", path, sizeof path) : NULL;
  if (rc == 0 && !f) rc = 1;
  if (f) {
    prru_cli_csv_comment(f);
    fputs("# q1 (rad) q2 (rad) of the singular or unreachable grid points\n", f);
    for (long k = 0; k < (long)g.n1 * g.n2; k++)
      if (st[k] != PRRU_OK)
        fprintf(f, "%.9g %.9g\n", prru_map_axis(g.q1_lo, g.q1_hi, g.n1, (int)(k / g.n2)),
                prru_map_axis(g.q2_lo, g.q2_hi, g.n2, (int)(k % g.n2)));
    /* gnuplot refuses an empty file: one point outside the plotted range. */
    if (sum.n_ok == sum.n_points) fputs("1e3 1e3\n", f);
    rc = close_out(f, path);
  }
  prru_data *d = rc == 0 ? malloc(sizeof *d) : NULL;
  if (rc == 0 && !d) rc = 1;
  prru_dme home;
  if (rc == 0) {
    prru_dme_eval(&m, d, (const double[3]){0.0, 0.0, 0.0}, &home);
    rc = write_fig7a(&dirs, &m, d);
  }
  free(d);
  if (rc == 0 && prru_cli_interrupted) rc = prru_cli_exit_interrupted();
  if (rc == 0) {
    char *script = NULL;
    size_t len = 0;
    FILE *gp = open_memstream(&script, &len);
    if (gp) {
      prru_cli_gnuplot_model(gp);
      fprintf(gp, "NCONF = %d\n%s", FIG7A_NPOSE, fig7_script);
    }
    if (!gp || fclose(gp) != 0) {
      prru_cli_error("paper", "out of memory for the fig. 7 script");
      rc = 1;
    } else {
      rc = prru_cli_gnuplot(stage, outdir, "fig7_plots.gp", script);
    }
    free(script);
  }
  /* Without gnuplot the data and the summary are still complete. */
  if (rc == 0 || rc == PRRU_CLI_NO_GNUPLOT) {
    FILE *outs[2] = {summary, stdout};
    for (int i = 0; i < 2; i++) {
      FILE *s = outs[i];
      if (!s) continue;
      fprintf(s, "\nWorkspace map (paper fig. 7): q3 = 0, q1 in [-pi/6, pi/6], q2 in [-pi/4, pi/6], "
                 "201 x 201 grid\n");
      fprintf(s, "w_R(0, 0) = %.12g%s; rotational semi-axes %.6g, %.6g rad/s^2 per N; "
                 "translational half-length %.6g m/s^2 per N\n",
              home.w_R, prru_cli_is_paper_model() ? " (the paper's value: 1.80468)" : "",
              home.semi_axis[0], home.semi_axis[1], home.half_length_T);
      fprintf(s, "with J_d singular where cond_1(J_d) > %g (rcond < %g):\n", 1.0 / FIG7_RCOND_MIN,
              FIG7_RCOND_MIN);
      fprintf(s, "  global index (mean of w_R - 1 over the ok points) = %.10g\n", sum.index);
      fprintf(s, "  singular fraction = %.6g (%ld singular, %ld unreachable of %ld points)\n",
              sum.singular_fraction, sum.n_singular, sum.n_unreachable, sum.n_points);
      fprintf(s, "  mean ln w_R = %.10g; w_R from %.6g at (%.4f, %.4f) to %.6g at (%.4f, %.4f)\n",
              sum.index_log, sum.w_min, sum.w_min_q[0], sum.w_min_q[1], sum.w_max, sum.w_max_q[0],
              sum.w_max_q[1]);
      fprintf(s, "with the numerical tolerance only (rcond < %g): global index = %.10g, singular "
                 "fraction = %.6g, max w_R = %.6g\n%s",
              rcond_numeric, sum_numeric.index, sum_numeric.singular_fraction, sum_numeric.w_max,
              sum.n_singular + sum.n_unreachable > 0
                  ? "  (no band: the index is dominated by the grid points nearest det J_d = 0 and "
                    "changes with the resolution)\n"
                  : "  (the grid has no singular or unreachable point: both tolerances agree)\n");
    }
  }
  free(w);
  free(st);
  return rc;
}
