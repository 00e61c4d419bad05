/* The w_R map as the CLI runs it: `prru map` and the fig. 7 part of
 * `prru paper` (cli/mapgrid.c). */
#ifndef PRRU_CLI_MAPGRID_H
#define PRRU_CLI_MAPGRID_H

#include <stdio.h>

#include "commands.h"
#include "prru.h"
#include "prru_dme.h"

/* Grid statuses start as this: prru_map_eval writes a prru_status (small)
 * for every point it evaluated. */
#define PRRU_CLI_MAP_NOT_DONE 0xFF

/* --NAME "START:STOP:COUNT": finite START < STOP, an integer 2 <= COUNT <=
 * 1e6. 0, or 2 after a message naming cmd and the option. */
int prru_cli_parse_range(const char *cmd, const char *name, const char *text, double *lo, double *hi,
                         int *n);
/* --rcond-min R (R in [0, 1)) into m->jd_rcond_min; text NULL: unchanged.
 * 0 or 2. */
int prru_cli_parse_rcond(const char *cmd, const char *text, prru_model *m);

/* Allocates *w and *st (statuses PRRU_CLI_MAP_NOT_DONE where the run did
 * not get to) and evaluates the map with nthreads threads, a progress bar
 * on stderr when progress, stopping at prru_cli_interrupted. PRRU_OK,
 * PRRU_EINTERRUPTED (the rows done so far are in w and st) or another
 * status after a message. The caller frees *w and *st. */
int prru_cli_map_run(const char *cmd, const prru_model *m, const prru_map_grid *g, int nthreads,
                     int progress, double **w, unsigned char **st, prru_map_summary *sum);
/* The number of complete q1 rows of an interrupted map (prru_map_eval
 * hands rows out in order and finishes every row it started). */
int prru_cli_map_rows_done(const prru_map_grid *g, const unsigned char *st);
/* The map CSV into o: the model comment, the header q1,q2,q3,w_R,status
 * and the first nrows q1 rows. PRRU_OK, PRRU_EIO (o->err) or
 * PRRU_EINTERRUPTED when a signal arrives (prru_cli_signal_count differs
 * from signal_count) before the last row. */
int prru_cli_map_write_csv(prru_cli_out *o, const prru_map_grid *g, const double *w,
                           const unsigned char *st, int nrows, int signal_count);
/* The summary `prru map` prints: model, point counts, global index,
 * singular fraction, mean ln w_R, range. */
void prru_cli_map_print_summary(FILE *f, const prru_map_summary *s, double rcond_min);

#endif
