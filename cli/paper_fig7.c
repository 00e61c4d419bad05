/* The fig. 7 part of prru paper: the w_R map over the paper's rectangle,
 * the data files of its figures, the ellipses of fig. 7a and the summary
 * lines. The figures themselves are drawn by cli/plot.c. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "mapgrid.h"
#include "paper.h"
#include "plot.h"
#include "prru.h"
#include "prru_dme.h"

#define FIG7_PI 3.14159265358979323846
/* The CLI's map tolerance (mapgrid.h); the summary also gives the grid at
 * the model's numerical 1e-8 to show why. */
#define FIG7_RCOND_MIN PRRU_CLI_MAP_RCOND_MIN

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
    double q[3] = {fig7a_poses[k][0], fig7a_poses[k][1], 0.0};
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

int prru_paper_fig7(const char *stage, const char *outdir, FILE *summary, double clip)
{
  const fig7_dirs dirs = {stage, outdir};
  prru_model m = *prru_cli_model();
  const double rcond_numeric = m.jd_rcond_min;
  m.jd_rcond_min = FIG7_RCOND_MIN;
  prru_map_grid g = {-FIG7_PI / 6, FIG7_PI / 6, -FIG7_PI / 4, FIG7_PI / 6, 0.0, 201, 201};
  double *w = NULL;
  unsigned char *st = NULL;
  prru_map_summary csum, csum_numeric;
  int rc = fig7_status(prru_cli_map_run("paper", &m, &g, 2, PRRU_PRECISION_DOUBLE, NULL, &w, &st, &csum));
  if (rc == 0) {
    /* The same grid at the numerical tolerance, for the summary only. */
    prru_model mn = m;
    mn.jd_rcond_min = rcond_numeric;
    double *w2 = NULL;
    unsigned char *st2 = NULL;
    rc = fig7_status(prru_cli_map_run("paper", &mn, &g, 2, PRRU_PRECISION_DOUBLE, NULL, &w2, &st2, &csum_numeric));
    free(w2);
    free(st2);
  }
  const prru_map_summary *sum = &csum, *sum_numeric = &csum_numeric;
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
      int ws = prru_cli_map_write_csv(&o, &g, w, st, g.n1, prru_cli_signal_count);
      rc = prru_cli_out_close(&o, ws == PRRU_OK);
      if (rc == 0 && ws != PRRU_OK) rc = fig7_status(ws);
    }
  }
  /* gnuplot's pm3d and image want scans separated by blank lines. */
  FILE *f = rc == 0 ? open_out(&dirs, "fig7_grid.dat", path, sizeof path) : NULL;
  if (rc == 0 && !f) rc = 1;
  if (f) {
    prru_cli_csv_comment(f);
    fputs("# q1 (rad) q2 (rad) w_R (NaN: singular, unreachable or other assembly mode)\n", f);
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
    fputs("# q1 (rad) q2 (rad) kind (0 singular or unreachable, 1 other assembly mode) of the\n"
          "# grid points that are not ok\n", f);
    for (long k = 0; k < (long)g.n1 * g.n2; k++)
      if (st[k] != PRRU_OK)
        fprintf(f, "%.9g %.9g %d\n", prru_map_axis(g.q1_lo, g.q1_hi, g.n1, (int)(k / g.n2)),
                prru_map_axis(g.q2_lo, g.q2_hi, g.n2, (int)(k % g.n2)),
                st[k] == PRRU_DME_OTHER_MODE);
    /* gnuplot refuses a selection without points: one of each kind outside
     * the plotted range. */
    fputs("1e3 1e3 0\n1e3 1e3 1\n", f);
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
    /* The clip from the ok values (the percentile), unless --clip. */
    size_t n_ok = 0, n = (size_t)g.n1 * (size_t)g.n2;
    double *ok_w = malloc(n * sizeof *ok_w);
    for (size_t k = 0; ok_w && k < n; k++)
      if (st[k] == PRRU_OK) ok_w[n_ok++] = w[k];
    double cv = ok_w || !isnan(clip) ? prru_plot_clip_value(clip, ok_w, n_ok, sum->w_max) : NAN;
    free(ok_w);
    char *script = isnan(cv) ? NULL : prru_plot_fig7_script(FIG7A_NPOSE, FIG7_RCOND_MIN, cv, isnan(clip),
                                                            sum->w_max);
    if (!script) {
      prru_cli_error("paper", "out of memory for the fig. 7 script");
      rc = 1;
    } else {
      rc = prru_plot_run("paper", stage, outdir, "fig7_plots.gp", script);
    }
    free(script);
  }
  /* Without gnuplot the data and the summary are still complete. */
  if (rc == 0 || rc == PRRU_PLOT_NO_GNUPLOT) {
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
      fprintf(s, "  global index (mean of w_R - 1 over the ok points) = %.10g\n", sum->index);
      fprintf(s, "  singular fraction = %.6g (%ld singular, %ld unreachable, %ld in the other assembly "
                 "mode of %ld points)\n",
              sum->singular_fraction, sum->n_singular - sum->n_other_mode, sum->n_unreachable,
              sum->n_other_mode, sum->n_points);
      fprintf(s, "  mean ln w_R = %.10g; w_R from %.6g at (%.4f, %.4f) to %.6g at (%.4f, %.4f)\n",
              sum->index_log, sum->w_min, sum->w_min_q[0], sum->w_min_q[1], sum->w_max,
              sum->w_max_q[0], sum->w_max_q[1]);
      if (prru_map_home_mode(&m, &g) != 0)
        fputs("  other assembly mode: det J_d of the opposite sign to the home pose's, beyond the "
              "singular locus\n", s);
      fprintf(s, "with the numerical tolerance only (rcond < %g): global index = %.10g, not-ok "
                 "fraction = %.6g, max w_R = %.6g\n%s",
              rcond_numeric, sum_numeric->index, sum_numeric->singular_fraction, sum_numeric->w_max,
              sum->n_singular + sum->n_unreachable > 0
                  ? "  (no band: the index is dominated by the grid points nearest det J_d = 0 and "
                    "changes with the resolution)\n"
                  : "  (the grid has no singular or unreachable point: both tolerances agree)\n");
    }
  }
  free(w);
  free(st);
  return rc;
}
