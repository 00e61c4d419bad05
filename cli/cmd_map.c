/* prru map: w_R over a (q1, q2) grid as CSV, and the global index. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "mapgrid.h"
#include "progress.h"
#include "prru.h"
#include "prru_dme.h"
#include "shard.h"

static const char map_help[] =
    "usage: prru map --q1 START:STOP:COUNT --q2 START:STOP:COUNT [--q3 Z]\n"
    "                --out FILE.csv|- [--rcond-min R] [--threads N] [--progress]\n"
    "                [--shard K/N] [--precision double|float]\n"
    "w_R (see 'prru dme --help') at every grid point q1 = START..STOP (COUNT\n"
    "equally spaced values, rad, COUNT >= 2, START < STOP; START and STOP may be\n"
    "multiples of pi: -pi/6:pi/6:201), q2 likewise, q3 = Z (m, default 0).\n"
    "Writes FILE.csv (--out -: stdout): the model line (# prru ... model ...),\n"
    "then the columns q1,q2,q3,w_R,status (q1 outer). status is ok, singular,\n"
    "unreachable, out_of_stroke (a slider beyond the model's actuators.stroke:\n"
    "the stroke ends bound the workspace), or other_mode: a regular pose of\n"
    "the other assembly mode, where det J_d has the opposite sign to the home\n"
    "pose's (q1 = q2 = 0 at this q3),\n"
    "cut off from it by the singular locus, so the robot cannot get there\n"
    "without passing a singularity.\n"
    "%s"
    "w_R is NaN unless the status is ok.\n"
    "Prints the model (name, file, sha256, ...) and the global index: the mean of\n"
    "w_R - 1 over the ok points, with the share of the grid that is not ok (the\n"
    "index alone favours a design that loses workspace); also the mean of ln w_R\n"
    "and the range of w_R; to stdout, or to stderr when the CSV goes to stdout.\n"
    "J_d counts as singular when 1/(|J|_1 |J^%s|_1) < R, J = J_d with its\n"
    "rotation columns divided by the mean upper-link length; the default R =\n"
    "%g (cond_1 > %g), the tolerance of prru paper's fig. 7, marks a band\n"
    "around the singular locus, so that the index does not depend on how close\n"
    "grid points happen to fall to it (--rcond-min 1e-8: numerical singularity\n"
    "only). Uses N threads (default 2). Progress: a bar on stderr when it is a\n"
    "terminal, for grids over 10000 points or with --progress; with --progress\n"
    "and stderr not a terminal (a log), a line per 10 %%.\n"
    "FILE is checked before the grid is computed, built as FILE.partial-XXXXXX\n"
    "and renamed at the end: it keeps its old contents until then. SIGINT,\n"
    "SIGTERM or SIGHUP (exit 130, 143, 129) stop the computation; the complete\n"
    "q1 rows computed so far are then written (a second signal stops that too,\n"
    "at a row boundary) and no summary is printed. A write error exits 1 with\n"
    "the reason and leaves FILE unchanged.\n"
    "--precision float: w_R computed in single precision, 8 points a vector\n"
    "with AVX2 (relative error below 64 x 2^-23 x w_R / rcond: 1e-5 at most\n"
    "points with rcond >= 1e-2, up to 7e-5 where w_R ~ 20); every status is\n"
    "still double's (a point single precision cannot decide surely is\n"
    "evaluated again in double); the summary says so. Only the build's own\n"
    "model has single-precision code: with --model FILE of other numbers it\n"
    "exits 2. Default double.\n"
    "--shard K/N: only the K-th of N contiguous blocks of q1 rows (a cluster job\n"
    "array runs one block per task), with a second comment line naming the\n"
    "shard and the settings and no summary; 'prru merge' joins the N files into\n"
    "exactly the file one run writes and prints its summary. An interrupted\n"
    "shard keeps nothing.\n";

int prru_cmd_map(int argc, char **argv)
{
  const char *q1s = NULL, *q2s = NULL, *q3s = NULL, *out = NULL, *rcs = NULL, *ths = NULL;
  const char *shs = NULL, *prs = NULL;
  int help = 0, progress = 0;
  prru_cli_option opts[] = {{"q1", 1, &q1s, NULL},        {"q2", 1, &q2s, NULL},
                            {"q3", 1, &q3s, NULL},        {"out", 1, &out, NULL},
                            {"rcond-min", 1, &rcs, NULL}, {"threads", 1, &ths, NULL},
                            {"progress", 0, NULL, &progress}, {"help", 0, NULL, &help},
                            {"shard", 1, &shs, NULL},     {"precision", 1, &prs, NULL}};
  if (prru_cli_parse("map", argc, argv, opts, 10)) return 2;
  if (help) {
    const int redundant = prru_cli_model()->mech->nact > 3;
    printf(map_help, redundant ? "(The test needs a square J_d: with more actuators than coordinates no\n"
                                 "point is other_mode.)\n" : "",
           redundant ? "+" : "-1", PRRU_CLI_MAP_RCOND_MIN, 1.0 / PRRU_CLI_MAP_RCOND_MIN);
    return 0;
  }
  const char *missing = !q1s ? "--q1" : !q2s ? "--q2" : !out ? "--out" : NULL;
  if (missing) {
    prru_cli_error("map", "%s is required (see 'prru map --help')", missing);
    return 2;
  }
  prru_map_grid g = {0, 0, 0, 0, 0.0, 0, 0};
  if (prru_cli_parse_range("map", "q1", q1s, &g.q1_lo, &g.q1_hi, &g.n1)) return 2;
  if (prru_cli_parse_range("map", "q2", q2s, &g.q2_lo, &g.q2_hi, &g.n2)) return 2;
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
  prru_model m = *prru_cli_model();
  m.jd_rcond_min = PRRU_CLI_MAP_RCOND_MIN;
  if (prru_cli_parse_rcond("map", rcs, &m)) return 2;
  int precision;
  if (prru_cli_parse_precision("map", prs, &m, &precision)) return 2;
  if (shs) {
    int k, n;
    if (prru_cli_parse_shard("map", shs, &k, &n)) return 2;
    return prru_cli_map_shard(&m, &g, nthreads, precision, k, n, out);
  }
  /* With the CSV on stdout the summary goes to stderr. */
  FILE *summary = strcmp(out, "-") == 0 ? stderr : stdout;
  long npts = (long)g.n1 * g.n2;
  prru_cli_progress bar;
  prru_cli_progress_init(&bar, "map", "points", progress, npts > 10000);
  /* The output is created (and so checked) before the grid is computed. */
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, "map", out)) return 1;
  double *w = NULL;
  unsigned char *st = NULL;
  prru_map_summary sum;
  int rc = prru_cli_map_run("map", &m, &g, nthreads, precision, &bar, &w, &st, &sum);
  int nrows = rc == PRRU_OK ? g.n1 : rc == PRRU_EINTERRUPTED ? prru_cli_map_rows_done(&g, st) : 0;
  /* After a first signal the rows computed are still written; a later
   * one stops that too. */
  int wst = nrows > 0 ? prru_cli_map_write_csv(&o, &g, w, st, nrows, prru_cli_signal_count) : PRRU_OK;
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
    prru_cli_map_print_summary(summary, &sum, m.jd_rcond_min, precision);
    status = 0;
  }
  free(w);
  free(st);
  return status;
}

