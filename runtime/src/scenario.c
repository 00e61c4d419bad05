/* Scenario files: `key = value` lines describing one simulation. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"
#include "internal.h"

static void scenario_defaults(prru_scenario *s)
{
  memset(s, 0, sizeof *s);
  prru_loads zero;
  memset(&zero, 0, sizeof zero);
  prru_schedule_constant(&s->loads, &zero);
  prru_sim_options_default(&s->opt);
  s->opt.loads = &s->loads;
}

void prru_scenario_paper(prru_scenario *s)
{
  scenario_defaults(s);
  s->q0[1] = PRRU_PI / 6;
  s->q0[2] = -0.8;
  prru_schedule_paper(&s->loads);
}

void prru_scenario_free(prru_scenario *s)
{
  prru_schedule_free(&s->loads);
}

static char *trim(char *s)
{
  while (*s == ' ' || *s == '\t') s++;
  size_t n = strlen(s);
  while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r')) s[--n] = '\0';
  return s;
}

/* Applies one key; returns PRRU_OK or fills msg. Numbers are read as on
 * the command line (prru_parse_value/s: decimal or [+-][K[*]]pi[/N]), so a
 * scenario file and the flags it stands for accept the same values. */
static int apply_key(const prru_model *m, prru_scenario *s, const char *key, const char *val, const char *where,
                     const char *base_dir, int *has_table, char *msg, int msglen)
{
  struct { const char *name; double *dst; int n; } vec[] = {
      {"q0", s->q0, 3}, {"qd0", s->qd0, 3}, {"fd", s->loads.base.fd, m->mech->nact},
      {"fp", s->loads.base.fp, 3}, {"mp", s->loads.base.mp, 3}};
  for (size_t i = 0; i < sizeof vec / sizeof vec[0]; i++)
    if (strcmp(key, vec[i].name) == 0) {
      if (prru_parse_values(val, vec[i].dst, vec[i].n) != PRRU_OK)
        return prru_fail(msg, msglen, PRRU_EPARSE, "%s: %s: expected %d comma-separated finite numbers (decimal, or multiples of pi such as -pi/6), got '%.60s'", where, key, vec[i].n, val);
      return PRRU_OK;
    }
  struct { const char *name; double *dst; int positive; } num[] = {
      {"t_end", &s->opt.t_end, 1}, {"dt", &s->opt.dt_out, 1}, {"atol", &s->opt.abs_tol, 0},
      {"rtol", &s->opt.rel_tol, 0}, {"h0", &s->opt.h0, 1}};
  for (size_t i = 0; i < sizeof num / sizeof num[0]; i++)
    if (strcmp(key, num[i].name) == 0) {
      double v;
      if (prru_parse_value(val, &v) != PRRU_OK || v < 0 || (num[i].positive && v == 0))
        return prru_fail(msg, msglen, PRRU_EPARSE, "%s: %s: expected a %s number, got '%.60s'", where, key, num[i].positive ? "positive" : "non-negative", val);
      if ((num[i].dst == &s->opt.abs_tol || num[i].dst == &s->opt.rel_tol) && v > 0 &&
          v < PRRU_TOL_MIN)
        return prru_fail(msg, msglen, PRRU_EPARSE, "%s: %s: %g is below %.2g (100 x DBL_EPSILON), which no double-precision step can resolve: use 0 (off) or at least %.2g", where, key, v, PRRU_TOL_MIN, PRRU_TOL_MIN);
      *num[i].dst = v;
      return PRRU_OK;
    }
  if (strcmp(key, "max_steps") == 0) {
    double v;
    if (prru_parse_value(val, &v) != PRRU_OK || !(v >= 0 && v < (double)LONG_MAX && v == floor(v)))
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: max_steps: expected a whole number of steps per output interval (0: default %ld), got '%.60s'", where, PRRU_MAX_STEPS_DEFAULT, val);
    s->opt.max_steps = (long)v;
    return PRRU_OK;
  }
  if (strcmp(key, "stepper") == 0) {
    if (prru_stepper_parse(val, &s->opt.stepper) != PRRU_OK)
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: stepper: '%.60s' is not one of rk8pd, rkf45, rkck, msbdf", where, val);
    return PRRU_OK;
  }
  if (strcmp(key, "harmonic") == 0) {
    double v[2];
    if (*has_table)
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: harmonic: cannot be combined with a loads table", where);
    if (prru_parse_values(val, v, 2) != PRRU_OK)
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: harmonic: expected 'amplitude, angular frequency', got '%.60s'", where, val);
    s->loads.kind = PRRU_LOAD_HARMONIC;
    s->loads.amp = v[0];
    s->loads.omega = v[1];
    return PRRU_OK;
  }
  if (strcmp(key, "loads") == 0) {
    if (!base_dir)
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: loads: tables are not allowed here", where);
    if (s->loads.kind != PRRU_LOAD_CONSTANT)
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: loads: only one of harmonic/loads may be given", where);
    char path[4096];
    int n = val[0] == '/' ? snprintf(path, sizeof path, "%s", val)
                          : snprintf(path, sizeof path, "%s/%s", base_dir, val);
    if (n < 0 || (size_t)n >= sizeof path)
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s: loads: path too long", where);
    prru_load_schedule t;
    char why[600];
    int st = prru_schedule_read_csv(m, &t, path, why, (int)sizeof why);
    /* why names the loads file; where, the scenario file and line. */
    if (st != PRRU_OK) return prru_fail(msg, msglen, st, "%s: loads: %s", where, why);
    t.base = s->loads.base; /* constant parts given before add to the table */
    s->loads = t;
    s->opt.loads = &s->loads;
    *has_table = 1;
    return PRRU_OK;
  }
  return prru_fail(msg, msglen, PRRU_EPARSE, "%s: unknown key '%.40s' (known: q0 qd0 fd fp mp harmonic loads t_end dt stepper atol rtol h0 max_steps)", where, key);
}

int prru_scenario_parse(const prru_model *m, prru_scenario *s, const char *text, size_t len, const char *name,
                        const char *base_dir, char *msg, int msglen)
{
  scenario_defaults(s);
  if (memchr(text, '\0', len))
    return prru_fail(msg, msglen, PRRU_EPARSE, "%s: contains a NUL byte (not a text file)", name);
  const char *p = text, *end = text + len;
  int lineno = 0, st = PRRU_OK, has_table = 0;
  unsigned seen = 0;
  static const char *const keys[] = {"q0", "qd0", "fd", "fp", "mp", "harmonic", "loads",
                                     "t_end", "dt", "stepper", "atol", "rtol", "h0",
                                     "max_steps"};
  while (p < end && st == PRRU_OK) {
    const char *e = memchr(p, '\n', (size_t)(end - p));
    if (!e) e = end;
    lineno++;
    size_t n = (size_t)(e - p);
    char *line = malloc(n + 1);
    if (!line) return prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", name);
    memcpy(line, p, n);
    line[n] = '\0';
    p = e + 1;
    char *hash = strchr(line, '#');
    if (hash) *hash = '\0';
    char *s0 = trim(line);
    if (*s0) {
      char where[300];
      snprintf(where, sizeof where, "%.250s:%d", name, lineno);
      char *eq = strchr(s0, '=');
      if (!eq) {
        st = prru_fail(msg, msglen, PRRU_EPARSE, "%s: expected 'key = value'", where);
      } else {
        *eq = '\0';
        char *key = trim(s0), *val = trim(eq + 1);
        for (unsigned k = 0; k < sizeof keys / sizeof keys[0]; k++)
          if (strcmp(key, keys[k]) == 0) {
            if (seen & (1u << k))
              st = prru_fail(msg, msglen, PRRU_EPARSE, "%s: %s given twice", where, key);
            seen |= 1u << k;
          }
        if (st == PRRU_OK) st = apply_key(m, s, key, val, where, base_dir, &has_table, msg, msglen);
      }
    }
    free(line);
  }
  if (st == PRRU_OK && !(s->opt.dt_out <= s->opt.t_end))
    st = prru_fail(msg, msglen, PRRU_EPARSE, "%s: dt (%g) is larger than t_end (%g)", name, s->opt.dt_out, s->opt.t_end);
  if (st != PRRU_OK) prru_scenario_free(s);
  return st;
}

int prru_scenario_read(const prru_model *m, prru_scenario *s, const char *path, char *msg, int msglen)
{
  size_t len;
  scenario_defaults(s);
  char *text = prru_read_file(path, &len, msg, msglen);
  if (!text) return PRRU_EIO;
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = '\0'; else snprintf(dir, sizeof dir, ".");
  int st = prru_scenario_parse(m, s, text, len, path, dir, msg, msglen);
  free(text);
  return st;
}
