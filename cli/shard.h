/* Shards of a sweep (`--shard K/N`, cli/shard.c), used by prru map,
 * prru sensitivity and prru merge. */
#ifndef PRRU_CLI_SHARD_H
#define PRRU_CLI_SHARD_H

#include "prru.h"
#include "prru_dme.h"

/* "K/N", 1 <= K <= N: 0, or 2 after a message naming cmd. */
int prru_cli_parse_shard(const char *cmd, const char *text, int *k, int *n);
/* Items [*begin, *end) of count for shard k of n: contiguous, in order. */
void prru_cli_shard_range(long count, int k, int n, long *begin, long *end);
/* `prru map --shard K/N`: the K-th of N contiguous blocks of q1 rows of
 * the grid into out (the map CSV with a second line "# shard K/N map
 * SETTINGS", which 'prru merge' checks and drops; " precision=float" ends
 * SETTINGS with --precision float). Returns the exit
 * status. */
int prru_cli_map_shard(const prru_model *m, const prru_map_grid *g, int nthreads, int precision, int k,
                       int n, const char *out);

#endif
