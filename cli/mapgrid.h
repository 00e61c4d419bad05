/* The w_R map as the CLI runs it: `prru map` and the fig. 7 part of
 * `prru paper` (cli/mapgrid.c). */
#ifndef PRRU_CLI_MAPGRID_H
#define PRRU_CLI_MAPGRID_H

#include <stdio.h>

#include "commands.h"
#include "progress.h"
#include "prru.h"
#include "prru_dme.h"

/* Grid statuses start as this: prru_map_eval writes a status (a
 * prru_status or PRRU_DME_OTHER_MODE) for every point it evaluated. */
#define PRRU_CLI_MAP_NOT_DONE 0xFF

/* The singularity tolerance of every w_R map the CLI computes (prru map's
 * default, prru paper's fig. 7): J_d counts as singular where cond_1 > 250
 * (of J_d with its rotation columns in units of the model's length, see
 * prru_check_regular; the paper's home pose has about 4). With the model's
 * numerical 1e-8 almost no grid point is flagged, w_R spikes to ~1e2-1e5
 * next to the locus det J_d = 0 and the global index depends on the
 * resolution (prru_dme.h); with 4e-3 the band around the locus is marked
 * and the index converges. */
#define PRRU_CLI_MAP_RCOND_MIN 4e-3

/* The summary's line for --precision float (after the model's). */
#define PRRU_CLI_PRECISION_FLOAT_LINE                                                           \
  "precision: float (w_R computed in single precision, relative error below 64 x 2^-23 x w_R / " \
  "rcond; statuses decided in double)"

/* --NAME "START:STOP:COUNT": finite START < STOP, an integer 2 <= COUNT <=
 * 1e6. 0, or 2 after a message naming cmd and the option. */
int prru_cli_parse_range(const char *cmd, const char *name, const char *text, double *lo, double *hi,
                         int *n);
/* --rcond-min R (R in [0, 1)) into m->jd_rcond_min; text NULL: unchanged.
 * 0 or 2. */
int prru_cli_parse_rcond(const char *cmd, const char *text, prru_model *m);

/* Allocates *w and *st (statuses PRRU_CLI_MAP_NOT_DONE where the run did
 * not get to) and evaluates the map with nthreads threads, reporting to
 * progress (NULL: none), stopping at prru_cli_interrupted (the runtime
 * marks the poses of the other assembly mode, PRRU_DME_OTHER_MODE). PRRU_OK,
 * PRRU_EINTERRUPTED (the rows done so far are in w and st) or another
 * status after a message. The caller frees *w and *st. */
int prru_cli_map_run(const char *cmd, const prru_model *m, const prru_map_grid *g, int nthreads,
                     int precision, prru_cli_progress *progress, double **w, unsigned char **st,
                     prru_map_summary *sum);
/* Only the q1 rows r0 .. r1 - 1 (a shard: `prru map --shard K/N`): *w and
 * *st hold (r1 - r0) n2 points from row r0's first, the values
 * prru_cli_map_run gives them; no summary (prru_map_summarize on the
 * joined shards: `prru merge`). Statuses as prru_cli_map_run. precision:
 * prru_map_options.precision. */
int prru_cli_map_run_rows(const char *cmd, const prru_model *m, const prru_map_grid *g, int r0, int r1,
                          int nthreads, int precision, prru_cli_progress *progress, double **w,
                          unsigned char **st);
/* --precision double|float (text NULL: double) into *precision, checked
 * against m (prru_precision_available). 0, or 2 after a message naming cmd,
 * the option and the reason. */
int prru_cli_parse_precision(const char *cmd, const char *text, const prru_model *m, int *precision);
/* The number of complete q1 rows of an interrupted map (prru_map_eval
 * hands rows out in order and finishes every row it started). */
int prru_cli_map_rows_done(const prru_map_grid *g, const unsigned char *st);
/* The map CSV into o: the model comment, the header q1,q2,q3,w_R,status
 * and the first nrows q1 rows. PRRU_OK, PRRU_EIO (o->err) or
 * PRRU_EINTERRUPTED when a signal arrives (prru_cli_signal_count differs
 * from signal_count) before the last row. */
int prru_cli_map_write_csv(prru_cli_out *o, const prru_map_grid *g, const double *w,
                           const unsigned char *st, int nrows, int signal_count);
/* The data rows r0 .. r1 - 1 (w[0], st[0]: row r0's first point) into o,
 * as prru_cli_map_write_csv writes them. */
int prru_cli_map_write_rows(prru_cli_out *o, const prru_map_grid *g, const double *w,
                            const unsigned char *st, int r0, int r1, int signal_count);
/* Checks one data row of a map CSV, "q1,q2,q3,w_R,status" as
 * prru_cli_map_write_rows writes it (line without its end; changed in
 * place): finite numbers q, a status name of prru_dme_status_name, w_R a
 * finite number >= 1 (w_R = sigma_1/sigma_2) where ok and NaN elsewhere.
 * NULL and the fields (*status: PRRU_OK, PRRU_ESINGULAR, PRRU_EUNREACHABLE,
 * PRRU_DME_OTHER_MODE, or PRRU_EINPUT for "invalid"; *w NaN where not ok),
 * else what a row must be (for a message naming the file and the row).
 * The one check of the rows that prru plot and prru merge read. */
const char *prru_cli_map_parse_row(char *line, double q[3], double *w, int *status);
/* The summary `prru map` prints: model, point counts, global index,
 * singular fraction, mean ln w_R, range (key: value lines); with
 * PRRU_PRECISION_FLOAT a precision line after the model's. */
void prru_cli_map_print_summary(FILE *f, const prru_map_summary *s, double rcond_min, int precision);

#endif
