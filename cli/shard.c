/* Shards of a sweep (`--shard K/N`): the grid rows of prru map or the
 * parameters of prru sensitivity split into N contiguous blocks, which
 * `prru merge` joins into exactly what one run writes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "mapgrid.h"
#include "prru.h"
#include "prru_dme.h"
#include "shard.h"

/* "K/N" with 1 <= K <= N <= 100000; 0 or 2. */
int prru_cli_parse_shard(const char *cmd, const char *text, int *k, int *n)
{
  char *end;
  long a = strtol(text, &end, 10);
  if (end == text || *end != '/') goto bad;
  const char *s = end + 1;
  long b = strtol(s, &end, 10);
  if (end == s || *end || a < 1 || b < 1 || a > b || b > 100000) goto bad;
  *k = (int)a;
  *n = (int)b;
  return 0;
bad:
  prru_cli_error(cmd, "--shard '%s': expected K/N with 1 <= K <= N (e.g. 3/8: the third of 8)", text);
  return 2;
}

/* Items [begin, end) of count for shard k of n: contiguous, in order. */
void prru_cli_shard_range(long count, int k, int n, long *begin, long *end)
{
  *begin = count * (k - 1) / n;
  *end = count * k / n;
}

int prru_cli_map_shard(const prru_model *m, const prru_map_grid *g, int nthreads, int precision, int k,
                       int n, const char *out)
{
  long r0, r1;
  prru_cli_shard_range(g->n1, k, n, &r0, &r1);
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, "map", out)) return 1;
  double *w = NULL;
  unsigned char *st = NULL;
  /* More shards than rows leaves some empty: they still write their
   * header, so that every task of a job array succeeds alike. */
  int rc = r0 < r1 ? prru_cli_map_run_rows("map", m, g, (int)r0, (int)r1, nthreads, precision, NULL, &w, &st) : PRRU_OK;
  if (rc == PRRU_OK) {
    prru_cli_out_comment(&o);
    /* The precision only where float (the double shards' line as before). */
    prru_cli_out_printf(&o, "# shard %d/%d map q1=%.17g:%.17g:%d q2=%.17g:%.17g:%d q3=%.17g rcond_min=%.17g%s\n",
                        k, n, g->q1_lo, g->q1_hi, g->n1, g->q2_lo, g->q2_hi, g->n2, g->q3, m->jd_rcond_min,
                        precision == PRRU_PRECISION_FLOAT ? " precision=float" : "");
    prru_cli_out_line(&o);
    prru_cli_out_printf(&o, "q1,q2,q3,w_R,status\n");
    prru_cli_out_line(&o);
    rc = prru_cli_map_write_rows(&o, g, w, st, (int)r0, (int)r1, prru_cli_signal_count);
  }
  free(w);
  free(st);
  /* A shard is merged whole or not at all: an interrupted one is dropped. */
  if (prru_cli_out_close(&o, rc == PRRU_OK && !o.err)) return 1;
  if (rc == PRRU_EINTERRUPTED) {
    prru_cli_error("map", "interrupted (%s): %s is not changed", prru_cli_signal_name(), out);
    return prru_cli_exit_interrupted();
  }
  if (rc != PRRU_OK) return 1;
  /* The summary needs every shard: 'prru merge' prints it. */
  FILE *f = strcmp(out, "-") == 0 ? stderr : stdout;
  fprintf(f, "model: %s\nshard %d/%d: q1 rows %ld to %ld of %d written to %s (no summary: see prru merge)\n",
          prru_cli_model_id(), k, n, r0 + 1, r1, g->n1, out);
  return 0;
}
