/* Loads as functions of time: constant, the paper's harmonic platform
 * force, or a table with linear interpolation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <stdio.h>

#include "prru.h"
#include "internal.h"

/* A table row: t, then the load values in prru_loads order, na forces
 * first: NV(na) values, ROW(na) doubles. */
#define NV(na) ((na) + 6)
#define ROW(na) (1 + NV(na))

static void loads_add(int na, prru_loads *l, const double v[])
{
  for (int k = 0; k < na; k++) l->fd[k] += v[k];
  for (int k = 0; k < 3; k++) {
    l->fp[k] += v[na + k];
    l->mp[k] += v[na + 3 + k];
  }
}

void prru_schedule_constant(prru_load_schedule *s, const prru_loads *l)
{
  memset(s, 0, sizeof *s);
  s->kind = PRRU_LOAD_CONSTANT;
  s->base = *l;
}

void prru_schedule_paper(prru_load_schedule *s)
{
  prru_loads l = {{50.0, 40.0, 25.0}, {0, 0, 0}, {0, 0, 0}};
  /* A redundant limb mirrors limb 3 (spec 12) and is driven like it:
   * with no force it would leave its share of the weight to the others and
   * the 4-PRRU leaves its workspace at t = 0.48 s. */
  for (int i = 3; i < PRRU_MAX_ACT; i++) l.fd[i] = l.fd[2];
  prru_schedule_constant(s, &l);
  s->kind = PRRU_LOAD_HARMONIC;
  s->amp = 50.0;
  s->omega = 4.0 * PRRU_PI;
}

void prru_schedule_eval(const prru_load_schedule *s, double t, prru_loads *out)
{
  *out = s->base;
  if (s->kind == PRRU_LOAD_HARMONIC) {
    out->fp[0] += s->amp * sin(s->omega * t);
    out->fp[1] -= s->amp * cos(s->omega * t);
  } else if (s->kind == PRRU_LOAD_TABLE && s->nrows > 0) {
    const double *r = s->rows;
    const int n = s->nrows, na = s->nact, row = ROW(na), nv = NV(na);
    double v[NV(PRRU_MAX_ACT)];
    if (t <= r[0]) {
      memcpy(v, r + 1, (size_t)nv * sizeof *v);
    } else if (t >= r[row * (n - 1)]) {
      memcpy(v, r + row * (n - 1) + 1, (size_t)nv * sizeof *v);
    } else {
      int lo = 0, hi = n - 1; /* r[row lo] <= t < r[row hi] */
      while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (r[row * mid] <= t) lo = mid; else hi = mid;
      }
      const double *a = r + row * lo, *b = r + row * hi;
      /* Halved time differences, and a convex combination where b - a
       * overflows: no overflow for any finite table. a + w (b - a)
       * otherwise, so that a constant column stays exactly constant. */
      double w = (0.5 * t - 0.5 * a[0]) / (0.5 * b[0] - 0.5 * a[0]);
      for (int k = 0; k < nv; k++) {
        double diff = b[1 + k] - a[1 + k];
        v[k] = isfinite(diff) ? a[1 + k] + w * diff : (1.0 - w) * a[1 + k] + w * b[1 + k];
      }
    }
    loads_add(na, out, v);
  }
}

void prru_schedule_free(prru_load_schedule *s)
{
  free(s->rows);
  s->rows = NULL;
  s->nrows = 0;
}

int prru_schedule_parse_csv(const prru_model *m, prru_load_schedule *s, const char *text, size_t len,
                            const char *name, char *msg, int msglen)
{
  /* Column names: t, fd1..fdN (required), fp1..3, mp1..3 (optional). */
  const int na = m->mech->nact, row = ROW(na);
  char cols[ROW(PRRU_MAX_ACT)][16];
  snprintf(cols[0], sizeof cols[0], "t");
  for (int k = 0; k < NV(na); k++) {
    const char *base = k < na ? "fd" : k < na + 3 ? "fp" : "mp";
    int i = k < na ? k : (k - na) % 3;
    snprintf(cols[1 + k], sizeof cols[1 + k], "%s%d", base, i + 1);
  }
  prru_table t;
  memset(s, 0, sizeof *s);
  s->nact = na;
  int st = prru_table_parse(&t, text, len, name, msg, msglen);
  if (st != PRRU_OK) return st;
  int idx[ROW(PRRU_MAX_ACT)];
  for (int k = 0; k < row; k++) {
    idx[k] = prru_table_column(&t, cols[k]);
    if (idx[k] < 0 && k <= na) {
      prru_table_free(&t);
      return prru_fail(msg, msglen, PRRU_EPARSE, "%s:1: missing column '%s' (need t,fd1..fd%d; fp1..3, mp1..3 optional)", name, cols[k], na);
    }
  }
  for (int j = 0; j < t.ncols; j++) {
    int known = 0;
    for (int k = 0; k < row; k++) known |= idx[k] == j;
    if (!known) {
      prru_fail(msg, msglen, PRRU_EPARSE, "%s:1: unknown column '%s' (expected t,fd1..%d,fp1..3,mp1..3)", name, t.names[j], na);
      prru_table_free(&t);
      return PRRU_EPARSE;
    }
  }
  s->rows = malloc((size_t)t.nrows * (size_t)row * sizeof *s->rows);
  if (!s->rows) { prru_table_free(&t); return prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", name); }
  for (int i = 0; i < t.nrows; i++)
    for (int k = 0; k < row; k++)
      s->rows[row * i + k] = idx[k] < 0 ? 0.0 : t.data[(size_t)i * (size_t)t.ncols + (size_t)idx[k]];
  for (int i = 1; i < t.nrows; i++)
    if (!(s->rows[row * i] > s->rows[row * (i - 1)])) {
      prru_fail(msg, msglen, PRRU_EPARSE, "%s: data row %d: time %g does not increase", name,
                i + 1, s->rows[row * i]);
      prru_table_free(&t);
      prru_schedule_free(s);
      return PRRU_EPARSE;
    }
  s->nrows = t.nrows;
  s->kind = PRRU_LOAD_TABLE;
  prru_table_free(&t);
  return PRRU_OK;
}

int prru_schedule_read_csv(const prru_model *m, prru_load_schedule *s, const char *path, char *msg, int msglen)
{
  size_t len;
  memset(s, 0, sizeof *s);
  char *text = prru_read_file(path, &len, msg, msglen);
  if (!text) return PRRU_EIO;
  int st = prru_schedule_parse_csv(m, s, text, len, path, msg, msglen);
  free(text);
  return st;
}
