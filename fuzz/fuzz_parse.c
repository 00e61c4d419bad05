/* libFuzzer harness: prru_parse_double and prru_parse_list, the parsers
 * behind every number the CLI accepts (--q, --qd, --fd, ...).
 * Oracles beyond "no crash, no UB": an accepted value is finite, and a list
 * of n values is accepted only when the text has exactly n - 1 commas
 * (nothing truncated, nothing silently ignored). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  if (size > 4096) return 0; /* command-line values are short */
  /* Exact-size copy so ASan sees any read past the terminator. */
  char *s = malloc(size + 1);
  if (!s) return 0;
  memcpy(s, data, size);
  s[size] = '\0';
  size_t commas = 0;
  for (size_t i = 0; i < size && s[i]; i++) commas += s[i] == ',';

  double v = 12345.0;
  if (prru_parse_double(s, &v) == PRRU_OK) {
    /* Same value strtod gives: the parser validates, it does not round. */
    if (!isfinite(v) || commas != 0 || v != strtod(s, NULL)) abort();
  } else if (v != 12345.0) {
    abort(); /* a rejected value must not be written */
  }
  for (int n = 1; n <= 4; n++) {
    double out[4] = {0, 0, 0, 0};
    if (prru_parse_list(s, out, n) == PRRU_OK) {
      if (commas != (size_t)(n - 1)) abort();
      for (int i = 0; i < n; i++)
        if (!isfinite(out[i])) abort();
    }
  }
  free(s);
  return 0;
}
