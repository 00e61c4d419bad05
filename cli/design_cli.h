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

#endif
