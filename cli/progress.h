/* Progress reports of the long-running commands (map, simulate) on stderr.
 * A bar redrawn in place (carriage return) only when stderr is a terminal;
 * in a log (stderr redirected) carriage returns would pile up, so there a
 * report is made only on request (--progress), as one plain line per 10 %. */
#ifndef PRRU_CLI_PROGRESS_H
#define PRRU_CLI_PROGRESS_H

typedef struct {
  const char *label; /* "map", "simulate" */
  const char *unit;  /* what done/total count, e.g. "points" (NULL: none) */
  int mode;          /* PRRU_PROGRESS_OFF, _BAR, _LINES */
  int last;          /* the last percentage (bar) or tenth (lines) shown */
} prru_cli_progress;

enum { PRRU_PROGRESS_OFF, PRRU_PROGRESS_BAR, PRRU_PROGRESS_LINES };

/* Chooses the mode: a bar when stderr is a terminal and (requested or
 * long), lines when requested and stderr is not a terminal, else off. */
void prru_cli_progress_init(prru_cli_progress *p, const char *label, const char *unit, int requested,
                            int long_run);
/* Reports done of total (done == total ends the bar's line). */
void prru_cli_progress_update(prru_cli_progress *p, double done, double total);
/* Ends a bar left unfinished (a stopped run), so that messages start on a
 * new line. */
void prru_cli_progress_end(prru_cli_progress *p);

#endif
