/* Strict number parsing for command-line values and files: a value is
 * accepted only if all of it is one finite number, so "1,2" for three
 * numbers, "0.5x" or "nan" are errors, never silently truncated. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"

#define PARSE_PI 3.14159265358979323846

/* One unsigned or signed decimal number at s (no blanks), returns its end
 * or NULL. strtod also accepts "nan", "inf" and hex floats; only decimal
 * is meant. */
static const char *parse_decimal(const char *s, double *out)
{
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
  *out = v;
  return end;
}

static const char *skip_blanks(const char *s)
{
  while (*s == ' ' || *s == '\t') s++;
  return s;
}

/* [K[*]]pi[/N] after the sign, K and N unsigned decimals, N > 0; NULL
 * when s is not of that form. */
static const char *parse_pi_multiple(const char *s, double *out)
{
  double k = 1.0, n = 1.0;
  const char *c = s;
  if (strncmp(c, "pi", 2) != 0) {
    if (*c == '+' || *c == '-' || !(c = parse_decimal(c, &k))) return NULL;
    if (*c == '*') c++;
    if (strncmp(c, "pi", 2) != 0) return NULL;
  }
  c += 2;
  if (*c == '/') {
    c++;
    if (*c == '+' || *c == '-' || !(c = parse_decimal(c, &n)) || !(n > 0)) return NULL;
  }
  double v = k * PARSE_PI / n;
  if (!isfinite(v)) return NULL;
  *out = v;
  return c;
}

/* Parses one number starting at s, returns the end (NULL on failure).
 * Leading/trailing blanks are allowed, nothing else; with_pi: a multiple
 * of pi is a number too. */
static const char *parse_number(const char *s, double *out, int with_pi)
{
  s = skip_blanks(s);
  if (*s == '\0' || *s == ',') return NULL;
  double v;
  const char *end = NULL;
  if (with_pi) {
    const char *c = s + (*s == '+' || *s == '-');
    end = parse_pi_multiple(c, &v);
    if (end && *s == '-') v = -v;
  }
  if (!end) end = parse_decimal(s, &v);
  if (!end) return NULL;
  *out = v;
  return skip_blanks(end);
}

static const char *parse_one(const char *s, double *out) { return parse_number(s, out, 0); }

int prru_parse_double(const char *s, double *out)
{
  if (!s) return PRRU_EPARSE;
  double v;
  const char *end = parse_one(s, &v);
  if (!end || *end != '\0') return PRRU_EPARSE;
  *out = v;
  return PRRU_OK;
}

static int parse_numbers(const char *s, double *out, int n, int with_pi)
{
  if (!s || n < 1) return PRRU_EPARSE;
  for (int i = 0; i < n; i++) {
    double v;
    const char *end = parse_number(s, &v, with_pi);
    if (!end) return PRRU_EPARSE;
    if (i < n - 1 ? *end != ',' : *end != '\0') return PRRU_EPARSE;
    out[i] = v;
    s = end + 1;
  }
  return PRRU_OK;
}

int prru_parse_list(const char *s, double *out, int n) { return parse_numbers(s, out, n, 0); }

int prru_parse_values(const char *s, double *out, int n) { return parse_numbers(s, out, n, 1); }

int prru_parse_value(const char *s, double *out)
{
  if (!s) return PRRU_EPARSE;
  double v;
  const char *end = parse_number(s, &v, 1);
  if (!end || *end != '\0') return PRRU_EPARSE;
  *out = v;
  return PRRU_OK;
}
