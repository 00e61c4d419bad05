/* The w_R map as the CLI runs it (prru map, the fig. 7 part of prru paper):
 * grid ranges, the singularity tolerance option, the run with its progress
 * bar, and the map CSV. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "mapgrid.h"
#include "progress.h"
#include "prru.h"
#include "prru_dme.h"

int prru_cli_parse_rcond(const char *cmd, const char *text, prru_model *m)
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

/* "a:b:n" with finite a < b and an integer 2 <= n <= 1e6; 0 or 2. */
int prru_cli_parse_range(const char *cmd, const char *name, const char *text, double *lo, double *hi,
                         int *n)
{
  char buf[256];
  const char *c1 = strchr(text, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
  if (!c1 || !c2 || strchr(c2 + 1, ':') || strlen(text) >= sizeof buf) {
    prru_cli_error(cmd, "--%s '%s': expected START:STOP:COUNT (e.g. -0.5:0.5:101 or -pi/6:pi/6:201)", name, text);
    return 2;
  }
  strcpy(buf, text);
  char *a = buf, *b = buf + (c1 - text) + 1, *cnt = buf + (c2 - text) + 1;
  b[-1] = cnt[-1] = '\0';
  if (prru_parse_value(a, lo) != PRRU_OK) {
    prru_cli_error(cmd, "--%s '%s': START '%s' is not a finite number", name, text, a);
    return 2;
  }
  if (prru_parse_value(b, hi) != PRRU_OK) {
    prru_cli_error(cmd, "--%s '%s': STOP '%s' is not a finite number", name, text, b);
    return 2;
  }
  char *end;
  long v = *cnt ? strtol(cnt, &end, 10) : 0;
  if (!*cnt || *end || v < 2 || v > 1000000) {
    prru_cli_error(cmd, "--%s '%s': COUNT '%s' must be an integer from 2 to 1000000", name,
                   text, cnt);
    return 2;
  }
  if (!(*lo < *hi)) {
    prru_cli_error(cmd, "--%s '%s': START must be less than STOP", name, text);
    return 2;
  }
  if (!isfinite(*hi - *lo)) {
    prru_cli_error(cmd, "--%s '%s': the range STOP - START overflows", name, text);
    return 2;
  }
  *n = (int)v;
  return 0;
}

static int report_progress(long done, long total, void *ctx)
{
  prru_cli_progress_update(ctx, (double)done, (double)total);
  return 0;
}

/* The q1 rows of an interrupted map that are complete: prru_map_eval hands
 * rows out in order and finishes every row it started. */
int prru_cli_map_rows_done(const prru_map_grid *g, const unsigned char *st)
{
  long n = (long)g->n1 * g->n2, k = 0;
  while (k < n && st[k] != PRRU_CLI_MAP_NOT_DONE) k++;
  return (int)(k / g->n2);
}

int prru_cli_map_write_rows(prru_cli_out *o, const prru_map_grid *g, const double *w,
                            const unsigned char *st, int r0, int r1, int signal_count)
{
  for (int i = r0; i < r1; i++) {
    double q1 = prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i);
    for (int j = 0; j < g->n2; j++) {
      if (prru_cli_signal_count != signal_count) return PRRU_EINTERRUPTED;
      long k = (long)(i - r0) * g->n2 + j;
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

/* The map's CSV (comment, header, the first nrows q1 rows) into o;
 * PRRU_OK, PRRU_EIO (o->err) or PRRU_EINTERRUPTED when a signal arrives
 * (one more than the signal_count it started with) before the last row. */
int prru_cli_map_write_csv(prru_cli_out *o, const prru_map_grid *g, const double *w,
                         const unsigned char *st, int nrows, int signal_count)
{
  prru_cli_out_comment(o);
  prru_cli_out_printf(o, "q1,q2,q3,w_R,status\n");
  prru_cli_out_line(o);
  return prru_cli_map_write_rows(o, g, w, st, 0, nrows, signal_count);
}

const char *prru_cli_map_parse_row(char *line, double q[3], double *w, int *status)
{
  static const char expected[] = "expected q1,q2,q3,w_R,status with finite numbers, a status of "
                                 "prru map, w_R >= 1 where ok and NaN elsewhere";
  static const int codes[] = {PRRU_OK, PRRU_ESINGULAR, PRRU_EUNREACHABLE, PRRU_DME_OTHER_MODE,
                              PRRU_EINPUT, PRRU_ESTROKE};
  char *field[5];
  int n = 0;
  for (char *c = line; n < 5; c++) { /* empty fields are fields */
    field[n++] = c;
    if (!(c = strchr(c, ','))) break;
    *c = '\0';
  }
  if (n != 5 || strchr(field[4], ',')) return expected;
  for (int i = 0; i < 3; i++)
    if (prru_parse_double(field[i], &q[i]) != PRRU_OK) return expected;
  *status = -1;
  for (size_t c = 0; c < sizeof codes / sizeof codes[0]; c++)
    if (strcmp(field[4], prru_dme_status_name(codes[c])) == 0) *status = codes[c];
  if (*status < 0) return expected;
  if (*status != PRRU_OK) {
    *w = NAN;
    return strcmp(field[3], "NaN") == 0 ? NULL : expected;
  }
  /* prru_parse_double refuses NaN, inf and overflow (1e999). */
  return prru_parse_double(field[3], w) == PRRU_OK && *w >= 1.0 ? NULL : expected;
}

int prru_cli_parse_precision(const char *cmd, const char *text, const prru_model *m, int *precision)
{
  *precision = PRRU_PRECISION_DOUBLE;
  if (!text) return 0;
  const int p = prru_precision_parse(text);
  if (p < 0) {
    prru_cli_error(cmd, "--precision '%s': must be double or float", text);
    return 2;
  }
  if (prru_precision_available(m, p) != PRRU_OK) {
    prru_cli_error(cmd, "--precision float: model %s has no single-precision kernels: only the "
                        "build's own model (PRRU_MODEL) is generated in float; a model file of other "
                        "numbers runs the run-time parameter kernels, in double (use --precision double, "
                        "or build prru with PRRU_MODEL set to this file)", prru_cli_model_id());
    return 2;
  }
  *precision = p;
  return 0;
}

void prru_cli_map_print_summary(FILE *f, const prru_map_summary *s, double rcond_min, int precision)
{
  fprintf(f, "model: %s\n", prru_cli_model_id());
  if (precision == PRRU_PRECISION_FLOAT) fprintf(f, "%s\n", PRRU_CLI_PRECISION_FLOAT_LINE);
  fprintf(f, "points: %ld (ok %ld, singular %ld, unreachable %ld, other assembly mode %ld; J_d "
             "singular below rcond %g)\n",
          s->n_points, s->n_ok, s->n_singular - s->n_other_mode, s->n_unreachable, s->n_other_mode,
          rcond_min);
  fprintf(f, "global_index: %.10g (mean of w_R - 1 over the ok points)\n", s->index);
  fprintf(f, "singular_fraction: %.10g (share of the grid that is singular, unreachable, out of stroke or in the "
             "other assembly mode)\n", s->singular_fraction);
  fprintf(f, "index_log: %.10g (mean of ln w_R over the ok points)\n", s->index_log);
  if (s->n_ok)
    fprintf(f, "w_R range: %.10g at (q1, q2) = (%.6f, %.6f) to %.10g at (%.6f, %.6f)\n", s->w_min,
            s->w_min_q[0], s->w_min_q[1], s->w_max, s->w_max_q[0], s->w_max_q[1]);
}

int prru_cli_map_run_rows(const char *cmd, const prru_model *m, const prru_map_grid *g, int r0, int r1,
                          int nthreads, int precision, prru_cli_progress *progress, double **w,
                          unsigned char **st)
{
  size_t n = (size_t)(r1 - r0) * (size_t)g->n2;
  *w = malloc(n * sizeof **w);
  *st = malloc(n);
  if (!*w || !*st) {
    prru_cli_error(cmd, "out of memory for %zu grid points", n);
    return PRRU_ENOMEM;
  }
  memset(*st, PRRU_CLI_MAP_NOT_DONE, n);
  prru_map_options o;
  prru_map_options_default(&o);
  o.nthreads = nthreads;
  o.precision = precision;
  if (progress && progress->mode != PRRU_PROGRESS_OFF) {
    o.progress = report_progress;
    o.ctx = progress;
  }
  o.interrupt = &prru_cli_interrupted;
  int rc = prru_map_eval_rows(m, g, r0, r1, &o, *w, *st);
  if (rc != PRRU_OK) {
    if (progress) prru_cli_progress_end(progress);
    if (rc != PRRU_EINTERRUPTED) prru_cli_error(cmd, "map: %s", prru_strerror(rc));
  }
  return rc;
}

/* Allocates and evaluates a map (statuses PRRU_CLI_MAP_NOT_DONE where it did not
 * get to): PRRU_OK, PRRU_EINTERRUPTED (a signal: the rows done so far are
 * in w and st) or another status after a message. */
int prru_cli_map_run(const char *cmd, const prru_model *m, const prru_map_grid *g, int nthreads,
                   int precision, prru_cli_progress *progress, double **w, unsigned char **st,
                   prru_map_summary *sum)
{
  int rc = prru_cli_map_run_rows(cmd, m, g, 0, g->n1, nthreads, precision, progress, w, st);
  if (rc == PRRU_OK) prru_map_summarize(g, *w, *st, sum);
  return rc;
}
