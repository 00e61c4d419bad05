/* Output files that are never left half-written: rows formatted whole into
 * a buffer and written with a loop that survives EINTR and short writes;
 * a regular file built as FILE.partial-XXXXXX beside FILE and renamed onto
 * it at the end, so that FILE keeps its old contents until the run has
 * something to show (prru_cli_out_close). */
#define _POSIX_C_SOURCE 200809L /* mkstemp, fchmod, fsync */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "commands.h"
#include "prru.h"

/* Flush after 64 kB, or 0.2 s after the last flush: big writes for fast
 * producers (map), and a slow run killed with SIGKILL still leaves its
 * rows in the partial file. */
#define OUT_FLUSH_BYTES (64 * 1024)
#define OUT_FLUSH_SECONDS 0.2

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(prru_cli_out *o, int err)
{
  if (!o->err) o->err = err ? err : EIO;
  return -1;
}

/* Writes all of p, retrying after EINTR and short writes: a signal never
 * cuts a row (the handlers only set a flag, see prru_cli_catch_signals). */
static int write_all(int fd, const char *p, size_t n)
{
  while (n > 0) {
    ssize_t w = write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno ? errno : EIO;
    }
    if (w == 0) return EIO;
    p += w;
    n -= (size_t)w;
  }
  return 0;
}

int prru_cli_out_flush(prru_cli_out *o)
{
  if (o->err) return -1;
  if (o->whole == 0) return 0;
  if (o->truncate_first) { /* direct mode on a regular file: keep it until now */
    o->truncate_first = 0;
    if (ftruncate(o->fd, 0) != 0) return fail(o, errno);
  }
  int e = write_all(o->fd, o->buf, o->whole);
  if (e) return fail(o, e);
  memmove(o->buf, o->buf + o->whole, o->len - o->whole);
  o->len -= o->whole;
  o->whole = 0;
  o->flushed_at = now();
  return 0;
}

static int reserve(prru_cli_out *o, size_t more)
{
  if (o->len + more + 1 <= o->cap) return 0;
  size_t cap = o->cap ? o->cap : 2 * OUT_FLUSH_BYTES;
  while (cap < o->len + more + 1) cap *= 2;
  char *b = realloc(o->buf, cap);
  if (!b) return fail(o, ENOMEM);
  o->buf = b;
  o->cap = cap;
  return 0;
}

void prru_cli_out_printf(prru_cli_out *o, const char *fmt, ...)
{
  if (o->err) return;
  for (int pass = 0; pass < 2; pass++) {
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(o->buf ? o->buf + o->len : NULL, o->buf ? o->cap - o->len : 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
      fail(o, EINVAL);
      return;
    }
    if (o->buf && o->len + (size_t)n < o->cap) {
      o->len += (size_t)n;
      return;
    }
    if (reserve(o, (size_t)n)) return;
  }
}

void prru_cli_out_write(prru_cli_out *o, const void *data, size_t n)
{
  if (o->err || reserve(o, n)) return;
  memcpy(o->buf + o->len, data, n);
  o->len += n;
}

void prru_cli_out_motor_names(prru_cli_out *o, int motor, int current)
{
  const int nact = prru_cli_model()->mech->nact;
  char names[256];
  if (motor) prru_cli_out_printf(o, ",%s", prru_cli_names(names, sizeof names, "tau", nact, ","));
  if (motor && current) prru_cli_out_printf(o, ",%s", prru_cli_names(names, sizeof names, "i", nact, ","));
}

void prru_cli_out_motor(prru_cli_out *o, const prru_model *m, const double fd[], int motor, int current)
{
  const int nact = m->mech->nact;
  double tau[PRRU_MAX_ACT], cur[PRRU_MAX_ACT];
  if (!motor) return;
  if (prru_model_motor_units(m, fd, tau, cur) != PRRU_OK) /* checked by prru_cli_units */
    for (int i = 0; i < nact; i++) tau[i] = cur[i] = NAN;
  prru_cli_out_numbers(o, tau, nact);
  if (current) prru_cli_out_numbers(o, cur, nact);
}

void prru_cli_out_numbers(prru_cli_out *o, const double *v, int n)
{
  for (int i = 0; i < n; i++) prru_cli_out_printf(o, ",%.17g", v[i]);
}

void prru_cli_out_json_string(prru_cli_out *o, const char *s)
{
  prru_cli_out_write(o, "\"", 1);
  while (*s) {
    char text[8];
    size_t used;
    prru_cli_out_write(o, text, prru_json_char(s, text, &used));
    s += used;
  }
  prru_cli_out_write(o, "\"", 1);
}

int prru_cli_out_line(prru_cli_out *o)
{
  if (o->err) return -1;
  o->whole = o->len;
  return o->whole >= OUT_FLUSH_BYTES ? prru_cli_out_flush(o) : 0;
}

int prru_cli_out_row(prru_cli_out *o)
{
  if (o->err) return -1;
  o->whole = o->len;
  o->rows++;
  if (o->whole >= OUT_FLUSH_BYTES || now() - o->flushed_at >= OUT_FLUSH_SECONDS)
    return prru_cli_out_flush(o);
  return 0;
}

void prru_cli_out_comment(prru_cli_out *o)
{
  prru_cli_out_printf(o, "# prru %s model %s\n", PRRU_VERSION, prru_cli_model_id());
  prru_cli_out_line(o);
}

void prru_cli_out_comment_line(prru_cli_out *o, const char *fmt, ...)
{
  if (o->err) return;
  prru_cli_out_printf(o, "# ");
  const size_t start = o->len;
  for (int pass = 0; pass < 2 && !o->err; pass++) {
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(o->buf + o->len, o->cap - o->len, fmt, ap);
    va_end(ap);
    if (n < 0) {
      fail(o, EINVAL);
      return;
    }
    if (o->len + (size_t)n < o->cap) {
      o->len += (size_t)n;
      break;
    }
    reserve(o, (size_t)n);
  }
  for (size_t i = start; i < o->len; i++)
    if ((unsigned char)o->buf[i] < 0x20 || o->buf[i] == 0x7f) o->buf[i] = '?';
  prru_cli_out_printf(o, "\n");
  prru_cli_out_line(o);
}

/* dir/<base>.partial-XXXXXX for path dir/base (base shortened so that the
 * name stays within NAME_MAX). */
static char *partial_name(const char *path)
{
  const char *slash = strrchr(path, '/');
  size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
  size_t baselen = strlen(path + dirlen);
  if (baselen > 200) baselen = 200;
  char *t = malloc(dirlen + baselen + 32);
  if (!t) return NULL;
  memcpy(t, path, dirlen + baselen);
  strcpy(t + dirlen + baselen, ".partial-XXXXXX");
  return t;
}

int prru_cli_out_open(prru_cli_out *o, const char *cmd, const char *path)
{
  memset(o, 0, sizeof *o);
  o->cmd = cmd;
  o->fd = -1;
  o->flushed_at = now();
  if (!path || strcmp(path, "-") == 0) {
    o->name = "stdout";
    o->fd = STDOUT_FILENO;
    return 0;
  }
  o->name = path;
  struct stat st;
  int exists = lstat(path, &st) == 0;
  if (!exists && errno != ENOENT) {
    prru_cli_error(cmd, "%s: cannot open for writing: %s", path, strerror(errno));
    return 1;
  }
  if (exists && S_ISDIR(st.st_mode)) {
    prru_cli_error(cmd, "%s: cannot open for writing: %s", path, strerror(EISDIR));
    return 1;
  }
  if (!exists || S_ISREG(st.st_mode)) {
    /* A regular file (or none yet): build it beside, rename at the end. */
    o->final_path = malloc(strlen(path) + 1);
    o->tmp_path = partial_name(path);
    int e = ENOMEM;
    if (o->final_path && o->tmp_path) {
      strcpy(o->final_path, path);
      o->fd = mkstemp(o->tmp_path);
      e = errno;
    }
    if (o->fd >= 0) {
      /* The mode a plain open would give: the old file's, else 0666 & ~umask. */
      mode_t mode;
      if (exists) {
        mode = st.st_mode & 07777;
      } else {
        mode_t mask = umask(0);
        umask(mask);
        mode = 0666 & ~mask;
      }
      (void)fchmod(o->fd, mode); /* on failure the file keeps mode 0600: still right */
      return 0;
    }
    free(o->tmp_path);
    free(o->final_path);
    o->tmp_path = o->final_path = NULL;
    /* A writable file in a directory that takes no new file is written in
     * place (below), still untouched until the first line. */
    if (!(exists && (e == EACCES || e == EPERM))) {
      prru_cli_error(cmd, "%s: cannot open for writing (a temporary file beside it): %s", path,
                     strerror(e));
      return 1;
    }
  }
  /* A device, FIFO, socket or symbolic link: written in place (renaming
   * onto /dev/stdout or through a link would replace the wrong thing). A
   * regular file written in place is truncated only when the first line is
   * written. */
  o->fd = open(path, O_WRONLY | O_CREAT, 0666);
  if (o->fd < 0) {
    prru_cli_error(cmd, "%s: cannot open for writing: %s", path, strerror(errno));
    return 1;
  }
  struct stat fst;
  o->truncate_first = fstat(o->fd, &fst) == 0 && S_ISREG(fst.st_mode);
  return 0;
}

int prru_cli_out_close(prru_cli_out *o, int keep)
{
  if (keep && !o->err) {
    prru_cli_out_flush(o);
    /* On disk before the rename (EINVAL: a file system without fsync). */
    if (!o->err && o->tmp_path && fsync(o->fd) != 0 && errno != EINVAL && errno != EROFS) fail(o, errno);
  }
  if (o->fd >= 0 && o->fd != STDOUT_FILENO && close(o->fd) != 0 && keep && !o->err) fail(o, errno);
  o->fd = -1;
  if (o->tmp_path) {
    if (keep && !o->err && rename(o->tmp_path, o->final_path) != 0) fail(o, errno);
    if (!keep || o->err) unlink(o->tmp_path);
  }
  int rc = o->err != 0;
  if (rc)
    prru_cli_error(o->cmd, "%s: write error: %s%s", o->name, strerror(o->err),
                   o->tmp_path ? "; the file is not changed" : "");
  free(o->tmp_path);
  free(o->final_path);
  free(o->buf);
  o->tmp_path = o->final_path = o->buf = NULL;
  o->len = o->whole = o->cap = 0;
  return rc;
}

int prru_cli_out_finish(prru_cli_out *o, int st, const char *why)
{
  const char *name = o->name;
  const long rows = o->rows;
  const int in_place = o->tmp_path == NULL;
  if (prru_cli_out_close(o, !o->err && (rows > 0 || st == PRRU_OK))) return 1;
  if (st == PRRU_OK) return 0;
  if (rows > 0)
    prru_cli_error(o->cmd, "%s; the %ld rows before it written to %s", why, rows, name);
  else
    prru_cli_error(o->cmd, "%s; nothing written%s%s%s", why, in_place ? "" : ", ",
                   in_place ? "" : name, in_place ? "" : " is not changed");
  return prru_cli_exit_for(st);
}

const char *prru_cli_out_error(const prru_cli_out *o)
{
  return o->err ? strerror(o->err) : "no error";
}
