/* Numeric CSV tables: load schedules and trajectories for `prru id`. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"
#include "internal.h"

#define MAX_ROWS 1000000
#define MAX_COLS 1024
#define MAX_FILE_BYTES (256L * 1024 * 1024)

int prru_fail(char *msg, int msglen, int status, const char *fmt, ...)
{
  if (msg && msglen > 0) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, (size_t)msglen, fmt, ap);
    va_end(ap);
  }
  return status;
}

void prru_table_free(prru_table *t)
{
  if (t->names)
    for (int i = 0; i < t->ncols; i++) free(t->names[i]);
  free(t->names);
  free(t->data);
  memset(t, 0, sizeof *t);
}

int prru_table_column(const prru_table *t, const char *name)
{
  for (int i = 0; i < t->ncols; i++)
    if (strcmp(t->names[i], name) == 0) return i;
  return -1;
}

/* Copies line [s, e) without a trailing '\r' into a NUL-terminated buffer. */
static char *dup_line(const char *s, const char *e)
{
  if (e > s && e[-1] == '\r') e--;
  size_t n = (size_t)(e - s);
  char *b = malloc(n + 1);
  if (!b) return NULL;
  memcpy(b, s, n);
  b[n] = '\0';
  return b;
}

static int parse_header(prru_table *t, char *line, int lineno, const char *name, char *msg,
                        int msglen)
{
  int n = 1;
  for (char *c = line; *c; c++) n += *c == ',';
  if (n > MAX_COLS) return prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: more than %d columns", name, lineno, MAX_COLS);
  t->names = calloc((size_t)n, sizeof *t->names);
  if (!t->names) return prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", name);
  char *s = line;
  for (int i = 0; i < n; i++) {
    char *e = strchr(s, ',');
    if (e) *e = '\0';
    while (*s == ' ' || *s == '\t') s++;
    size_t len = strlen(s);
    while (len > 0 && (s[len - 1] == ' ' || s[len - 1] == '\t')) s[--len] = '\0';
    if (len == 0) return prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: column %d has no name", name, lineno, i + 1);
    for (int j = 0; j < i; j++)
      if (strcmp(t->names[j], s) == 0)
        return prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: column '%s' appears twice", name, lineno, s);
    t->names[i] = malloc(len + 1);
    if (!t->names[i]) return prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", name);
    memcpy(t->names[i], s, len + 1);
    t->ncols = i + 1;
    s = e ? e + 1 : s + len;
  }
  return PRRU_OK;
}

int prru_table_parse(prru_table *t, const char *text, size_t len, const char *name, char *msg,
                     int msglen)
{
  memset(t, 0, sizeof *t);
  const char *p = text, *end = text + len;
  if (memchr(text, '\0', len)) {
    return prru_fail(msg, msglen, PRRU_EPARSE, "%s: contains a NUL byte (not a text file)", name);
  }
  int lineno = 0, st = PRRU_OK, cap = 0;
  char *line = NULL;
  while (p < end) {
    const char *e = memchr(p, '\n', (size_t)(end - p));
    if (!e) e = end;
    lineno++;
    free(line);
    line = dup_line(p, e);
    p = e + 1;
    if (!line) { st = prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", name); break; }
    char *s = line;
    while (*s == ' ' || *s == '\t') s++;
    /* Blank lines and '#' comments anywhere, so the '# prru ... model ...'
     * line the CLI writes before the header is skipped. */
    if (*s == '\0' || *s == '#') continue;
    if (t->ncols == 0) {
      st = parse_header(t, s, lineno, name, msg, msglen);
      if (st != PRRU_OK) break;
      continue;
    }
    if (t->nrows >= MAX_ROWS) { st = prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: more than %d rows", name, lineno, MAX_ROWS); break; }
    if (t->nrows == cap) {
      int ncap = cap ? 2 * cap : 64;
      double *nd = realloc(t->data, (size_t)ncap * (size_t)t->ncols * sizeof *nd);
      if (!nd) { st = prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", name); break; }
      t->data = nd;
      cap = ncap;
    }
    double *row = t->data + (size_t)t->nrows * (size_t)t->ncols;
    char *c = s;
    for (int j = 0; j < t->ncols; j++) {
      char *comma = strchr(c, ',');
      if (j < t->ncols - 1 && !comma) {
        st = prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: %d values, the header has %d columns", name, lineno, j + 1, t->ncols);
        break;
      }
      if (j == t->ncols - 1 && comma) {
        st = prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: more values than the header's %d columns", name, lineno, t->ncols);
        break;
      }
      if (comma) *comma = '\0';
      if (prru_parse_double(c, &row[j]) != PRRU_OK) {
        st = prru_fail(msg, msglen, PRRU_EPARSE, "%s:%d: column '%s': '%.40s' is not a finite number", name, lineno, t->names[j], c);
        break;
      }
      c = comma ? comma + 1 : c;
    }
    if (st != PRRU_OK) break;
    t->nrows++;
  }
  free(line);
  if (st == PRRU_OK && t->ncols == 0) st = prru_fail(msg, msglen, PRRU_EPARSE, "%s: no header row", name);
  if (st == PRRU_OK && t->nrows == 0) st = prru_fail(msg, msglen, PRRU_EPARSE, "%s: no data rows", name);
  if (st != PRRU_OK) prru_table_free(t);
  return st;
}

char *prru_read_file(const char *path, size_t *len, char *msg, int msglen)
{
  FILE *f = fopen(path, "rb");
  if (!f) { prru_fail(msg, msglen, PRRU_EIO, "%s: cannot open for reading: %s", path, strerror(errno)); return NULL; }
  size_t cap = 4096, n = 0;
  char *buf = malloc(cap);
  while (buf) {
    if (n == cap) {
      if (cap >= (size_t)MAX_FILE_BYTES) {
        prru_fail(msg, msglen, PRRU_EIO, "%s: larger than %ld bytes", path, MAX_FILE_BYTES);
        free(buf); buf = NULL; break;
      }
      char *nb = realloc(buf, cap * 2);
      if (!nb) { free(buf); buf = NULL; prru_fail(msg, msglen, PRRU_ENOMEM, "%s: out of memory", path); break; }
      buf = nb; cap *= 2;
    }
    errno = 0;
    size_t r = fread(buf + n, 1, cap - n, f);
    n += r;
    if (r == 0) {
      if (ferror(f)) {
        prru_fail(msg, msglen, PRRU_EIO, "%s: read error: %s", path, errno ? strerror(errno) : "unknown");
        free(buf); buf = NULL;
      }
      break;
    }
  }
  fclose(f);
  if (buf) *len = n;
  return buf;
}

int prru_table_read(prru_table *t, const char *path, char *msg, int msglen)
{
  size_t len;
  memset(t, 0, sizeof *t);
  char *text = prru_read_file(path, &len, msg, msglen);
  if (!text) return PRRU_EIO;
  int st = prru_table_parse(t, text, len, path, msg, msglen);
  free(text);
  return st;
}
