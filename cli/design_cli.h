/* The design commands (cli/cmd_design.c): prru optimize, prru sensitivity,
 * prru merge, and the shards of prru map. */
#ifndef PRRU_CLI_DESIGN_H
#define PRRU_CLI_DESIGN_H

#include "prru.h"
#include "prru_dme.h"

int prru_cmd_optimize(int argc, char **argv);
int prru_cmd_sensitivity(int argc, char **argv);
int prru_cmd_merge(int argc, char **argv);

/* `prru map --shard K/N`: the K-th of N contiguous blocks of q1 rows of
 * the grid into out (the map CSV with a second line "# shard K/N map
 * SETTINGS", which 'prru merge' checks and drops). Returns the exit
 * status. */
int prru_cli_map_shard(const prru_model *m, const prru_map_grid *g, int nthreads, int k, int n,
                       const char *out);
/* "K/N", 1 <= K <= N: 0, or 2 after a message naming cmd. */
int prru_cli_parse_shard(const char *cmd, const char *text, int *k, int *n);

/* Gnuplot scripts (cli/plot_design.c; malloc'ed, NULL when out of
 * memory), run with prru_plot_run. The sensitivity bar chart of dat (lines
 * "INDEX NAME SCALED") into png. */
char *prru_plot_sensitivity_script(const char *dat, const char *png);
/* before.dat and after.dat (lines "q1 q2 w_R", NaN where not regular,
 * blank line between q1 scans) side by side into optimize_maps.png. */
char *prru_plot_optimize_script(const prru_map_grid *grid, double rcond_min, double index_before,
                                double index_after, double sing_before, double sing_after,
                                const char *name);

#endif
