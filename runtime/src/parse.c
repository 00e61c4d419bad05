/* Strict number parsing for command-line values and files: a value is
 * accepted only if all of it is one finite number, so "1,2" for three
 * numbers, "0.5x" or "nan" are errors, never silently truncated. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include "prru.h"

/* Parses one number starting at s, returns the end (NULL on failure).
 * Leading/trailing blanks are allowed, nothing else. */
static const char *parse_one(const char *s, double *out)
{
  while (*s == ' ' || *s == '\t') s++;
  if (*s == '\0' || *s == ',') return NULL;
  /* strtod accepts "nan", "inf" and hex floats; only decimal is meant. */
  const char *c = s;
  if (*c == '+' || *c == '-') c++;
  if (!(isdigit((unsigned char)*c) || *c == '.')) return NULL;
  if (c[0] == '0' && (c[1] == 'x' || c[1] == 'X')) return NULL;
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  /* ERANGE also flags underflow (1e-400 -> 0 or a subnormal): that is a
   * finite number, only overflow is refused. */
  if (end == s || !isfinite(v) || (errno == ERANGE && fabs(v) == HUGE_VAL)) return NULL;
  while (*end == ' ' || *end == '\t') end++;
  *out = v;
  return end;
}

int prru_parse_double(const char *s, double *out)
{
  if (!s) return PRRU_EPARSE;
  double v;
  const char *end = parse_one(s, &v);
  if (!end || *end != '\0') return PRRU_EPARSE;
  *out = v;
  return PRRU_OK;
}

int prru_parse_list(const char *s, double *out, int n)
{
  if (!s || n < 1) return PRRU_EPARSE;
  for (int i = 0; i < n; i++) {
    double v;
    const char *end = parse_one(s, &v);
    if (!end) return PRRU_EPARSE;
    if (i < n - 1 ? *end != ',' : *end != '\0') return PRRU_EPARSE;
    out[i] = v;
    s = end + 1;
  }
  return PRRU_OK;
}
