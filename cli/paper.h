/* The parts of `prru paper` (cli/cmd_paper.c, cli/paper_fig7.c). */
#ifndef PRRU_CLI_PAPER_H
#define PRRU_CLI_PAPER_H

#include <stdio.h>

/* The fig. 7 part of `prru paper`: map CSV, surface/contour/ellipse PNGs
 * built in stage (messages name outdir, where they will be moved),
 * summary lines appended to summary and printed. Returns 0, 1 (message
 * printed), 128 + signal, or PRRU_PLOT_NO_GNUPLOT (everything but the PNGs
 * made). */
int prru_paper_fig7(const char *stage, const char *outdir, FILE *summary, double clip);

#endif
