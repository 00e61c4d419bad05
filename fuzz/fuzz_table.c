/* libFuzzer harness: prru_table_parse, the CSV reader behind `prru id
 * --traj` and the load tables. The input is passed with its exact length
 * and no terminator, as prru_read_file delivers it.
 * Oracles: on success at least one column and one row, every name
 * non-empty and unique, every value finite; on failure a message and an
 * emptied table. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char msg[256] = "";
  prru_table t;
  int st = prru_table_parse(&t, (const char *)data, size, "fuzz.csv", msg, sizeof msg);
  if (st == PRRU_OK) {
    if (t.ncols < 1 || t.nrows < 1 || !t.names || !t.data) abort();
    for (int j = 0; j < t.ncols; j++) {
      if (!t.names[j] || !t.names[j][0]) abort();
      if (prru_table_column(&t, t.names[j]) != j) abort();
    }
    for (size_t i = 0; i < (size_t)t.nrows * (size_t)t.ncols; i++)
      if (!isfinite(t.data[i])) abort();
    prru_table_free(&t);
  } else {
    if (!msg[0] || strncmp(msg, "fuzz.csv", 8) != 0) abort();
    if (t.names || t.data || t.ncols || t.nrows) abort();
  }
  return 0;
}
