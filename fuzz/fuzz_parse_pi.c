/* libFuzzer harness: prru_parse_value and prru_parse_values, the parsers
 * behind the command line's numbers and scenario files, which take a
 * decimal or a multiple of pi, [+-][K[*]]pi[/N] (K, N unsigned decimals,
 * N > 0).
 * Oracle beyond "no crash, no UB": a second, deliberately naive reading of
 * that grammar (split the field at "pi", read K and N with the plain
 * decimal parser prru_parse_double). Both must accept exactly the same
 * texts and give the same double, bit for bit (sign of zero included);
 * a list of n values is accepted exactly when it has n fields that each
 * read as one value; a rejected single value is never written. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"

#define REF_PI 3.14159265358979323846

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int is_blank(char c) { return c == ' ' || c == '\t'; }

/* K or N of the pi form: an unsigned decimal with nothing around it (the
 * decimal parser itself allows blanks and a sign, the grammar does not). */
static int ref_unsigned(const char *t, double *out)
{
  if (!(t[0] == '.' || (t[0] >= '0' && t[0] <= '9'))) return 0;
  for (const char *c = t; *c; c++)
    if (is_blank(*c)) return 0;
  return prru_parse_double(t, out) == PRRU_OK;
}

/* One field (a copy the function may cut up): 1 and *out when it is a
 * value, else 0. */
static int ref_value(char *f, double *out)
{
  while (is_blank(*f)) f++;
  size_t len = strlen(f);
  while (len > 0 && is_blank(f[len - 1])) f[--len] = '\0';
  char *pi = strstr(f, "pi");
  if (!pi) return prru_parse_double(f, out) == PRRU_OK && len > 0;
  int negative = f[0] == '-';
  char *k_text = f + (f[0] == '-' || f[0] == '+');
  double k = 1.0, n = 1.0;
  if (pi > k_text) {
    if (pi[-1] == '*') pi[-1] = '\0';
    *pi = '\0';
    if (!ref_unsigned(k_text, &k)) return 0;
  }
  char *rest = pi + 2;
  if (*rest != '\0') {
    if (*rest != '/' || !ref_unsigned(rest + 1, &n) || !(n > 0)) return 0;
  }
  double v = k * REF_PI / n;
  if (!isfinite(v)) return 0;
  *out = negative ? -v : v;
  return 1;
}

static int same(double a, double b) { return a == b && signbit(a) == signbit(b); }

/* prru_parse_values for n fields against ref_value field by field. */
static void check_list(const char *s, size_t len, size_t commas, int n)
{
  double got[4] = {0, 0, 0, 0}, want[4] = {0, 0, 0, 0};
  int accepted = prru_parse_values(s, got, n) == PRRU_OK;
  int expected = commas == (size_t)(n - 1);
  char *copy = malloc(len + 1);
  if (!copy) return;
  memcpy(copy, s, len + 1);
  char *field = copy;
  for (int i = 0; i < n && expected; i++) {
    char *comma = strchr(field, ',');
    if (comma) *comma = '\0';
    expected = ref_value(field, &want[i]);
    field = comma ? comma + 1 : field + strlen(field);
  }
  free(copy);
  if (accepted != expected) abort();
  for (int i = 0; i < n && accepted; i++)
    if (!same(got[i], want[i])) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  if (size > 4096) return 0; /* command-line values and scenario lines are short */
  /* Exact-size copy so ASan sees any read past the terminator. */
  char *s = malloc(size + 1);
  char *work = malloc(size + 1);
  if (!s || !work) {
    free(s);
    free(work);
    return 0;
  }
  memcpy(s, data, size);
  s[size] = '\0';
  size_t len = strlen(s), commas = 0;
  for (size_t i = 0; i < len; i++) commas += s[i] == ',';

  double v = 12345.0, want = 0;
  memcpy(work, s, len + 1);
  int expected = commas == 0 && ref_value(work, &want);
  if (prru_parse_value(s, &v) == PRRU_OK) {
    if (!expected || !isfinite(v) || !same(v, want)) abort();
  } else if (expected || v != 12345.0) {
    abort(); /* a value the grammar allows was refused, or a refused one written */
  }
  for (int n = 1; n <= 4; n++) check_list(s, len, commas, n);
  free(work);
  free(s);
  return 0;
}
