/* prru plot: a PNG of a CSV that prru wrote. A map CSV
 * (q1,q2,q3,w_R,status) becomes a w_R contour map, a track CSV the figure
 * of `prru track --plot`, the CSVs of simulate, traj, excite and id time
 * series panels; the kind is told by the header, and the '#' lines (the
 * model the file came from) go into the title. The file is checked before gnuplot
 * sees it, so that a bad file is a message with its line, not a gnuplot
 * error. */
#define _XOPEN_SOURCE 700 /* getline, mkdtemp, realpath */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "commands.h"
#include "mapgrid.h"
#include "plot.h"
#include "prru.h"

/* What a CSV holds, from its header. */
enum { CSV_UNKNOWN, CSV_SIMULATION, CSV_MAP, CSV_TRACK, CSV_TRAJ, CSV_EXCITE, CSV_ID, CSV_IDENT, CSV_TOPP };

/* The header of a map CSV, and the start of the others'. */
static const char map_header[] = "q1,q2,q3,w_R,status";
static const char sim_header[] = "t,q1,q2,q3,qd1,qd2,qd3,d1,";
static const char track_header[] = "t,qr1,qr2,qr3,q1,q2,q3,e1,e2,e3,qd1,qd2,qd3,fd1,";
static const char motion_header[] = "t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,d1,"; /* traj, excite */
static const char id_header[] = "t,fd1,";
/* prru identify's report (its base parameters). */
static const char ident_header[] = "index,parameter,estimate,se,prior,resolution,model,t,combination";

/* Whether the comma-separated header has the column name. */
static int has_column(const char *header, const char *name)
{
  size_t n = strlen(name);
  for (const char *c = header;; c++) {
    if (strncmp(c, name, n) == 0 && (c[n] == ',' || c[n] == '\0')) return 1;
    if (!(c = strchr(c, ','))) return 0;
  }
}

static int starts_with(const char *s, const char *prefix)
{
  return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* The kind of CSV a header line begins. traj and excite share their
 * first columns: traj goes on with the slider velocities dd, excite with
 * the actuator forces fd. */
static int header_kind(const char *header)
{
  if (strcmp(header, map_header) == 0) return CSV_MAP;
  if (starts_with(header, sim_header)) return CSV_SIMULATION;
  if (starts_with(header, track_header)) return CSV_TRACK;
  if (starts_with(header, motion_header) && has_column(header, "dd1") && has_column(header, "fd1"))
    return CSV_TOPP;
  if (starts_with(header, motion_header) && has_column(header, "dd1")) return CSV_TRAJ;
  if (starts_with(header, motion_header) && has_column(header, "fd1")) return CSV_EXCITE;
  if (starts_with(header, id_header)) return CSV_ID;
  if (strcmp(header, ident_header) == 0) return CSV_IDENT;
  return CSV_UNKNOWN;
}

/* The '#' lines of a file: all of them joined for the footer (at most 3,
 * 400 bytes), and the model named by the first ("# prru VERSION model
 * NAME (FILE, sha256 HASH)") for the title. */
typedef struct {
  char text[400];
  char model[200];
  int count;
  char limits[400]; /* the line "# limits: ..." of a time-optimal trajectory, else "" */
} csv_comments;

/* NAME out of "prru VERSION model NAME (...": "" when line is not so. */
static void model_name(const char *line, char *name, size_t len)
{
  const char *m = strncmp(line, "prru ", 5) == 0 ? strstr(line, " model ") : NULL;
  const char *end = m ? strstr(m + 7, " (") : NULL;
  name[0] = '\0';
  if (end) snprintf(name, len, "%.*s", (int)(end - (m + 7)), m + 7);
}

static void add_comment(csv_comments *c, const char *line)
{
  if (c->count++ >= 3) return;
  size_t used = strlen(c->text);
  while (*line == '#' || *line == ' ') line++;
  if (c->count == 1) model_name(line, c->model, sizeof c->model);
  snprintf(c->text + used, sizeof c->text - used, "%s%s", used ? "; " : "", line);
}

/* Strips the line end (LF or CRLF). */
static void chomp(char *s)
{
  size_t n = strlen(s);
  while (n > 0 && (s[n - 1] == '\n' || s[n - 1] == '\r')) s[--n] = '\0';
}

/* Reads the comment lines and the header of f; the kind by the header. */
static int read_head(FILE *f, csv_comments *c, char **header, long *line_no)
{
  size_t cap = 0;
  memset(c, 0, sizeof *c);
  *header = NULL;
  while (getline(header, &cap, f) > 0) {
    ++*line_no;
    chomp(*header);
    if ((*header)[0] == '#') {
      if (starts_with(*header, "# limits: ")) snprintf(c->limits, sizeof c->limits, "%s", *header + 10);
      add_comment(c, *header);
      continue;
    }
    return header_kind(*header);
  }
  /* No header line: getline's buffer holds nothing meaningful. */
  free(*header);
  *header = NULL;
  return CSV_UNKNOWN;
}

/* ---- map CSVs ---- */

/* One map row (prru_cli_map_parse_row): NULL and the fields, else the
 * reason. kind: 0 ok, 1 singular, unreachable or invalid, 2 other
 * assembly mode. */
static const char *parse_map_row(char *line, double q[3], double *w, int *kind)
{
  int st;
  const char *why = prru_cli_map_parse_row(line, q, w, &st);
  *kind = st == PRRU_OK ? 0 : st == PRRU_DME_OTHER_MODE ? 2 : 1;
  return why;
}

/* The grid as read: q1 blocks (q1 outer, increasing) of n2 rows with the
 * first block's increasing q2 values, one q3. */
typedef struct {
  long rows, n1, n2, cur, n_sing, n_other; /* cur: rows in the current block */
  double q3, q1_last;
  double *q2; /* the first block's q2 values */
  double w_max;
  double *ok_w; /* the ok values of w_R, n_ok of them (for the clip) */
  long n_ok, cap_ok;
} map_scan;

/* Checks one row against the grid read so far; NULL or the reason. */
static const char *scan_row(map_scan *m, const double q[3], double w, int kind)
{
  if (m->rows == 0) {
    m->q3 = q[2];
    m->q1_last = q[0];
    m->n1 = 1;
  } else if (q[2] != m->q3) {
    return "q3 differs from the first row's (a map has one q3)";
  } else if (q[0] != m->q1_last) {
    if (!(q[0] > m->q1_last)) return "q1 does not increase from block to block";
    if (m->n1 == 1) m->n2 = m->cur;
    if (m->cur != m->n2) return "the previous q1 block is shorter than the first";
    m->n1++;
    m->q1_last = q[0];
    m->cur = 0;
  }
  if (m->n1 == 1) {
    if (m->cur > 0 && !(q[1] > m->q2[m->cur - 1])) return "q2 does not increase within a q1 block";
    double *q2 = realloc(m->q2, (size_t)(m->cur + 1) * sizeof *q2);
    if (!q2) return "out of memory";
    m->q2 = q2;
    m->q2[m->cur] = q[1];
  } else if (m->cur >= m->n2 || q[1] != m->q2[m->cur]) {
    return "the q2 values differ from the first q1 block's (not a grid)";
  }
  if (kind == 0 && w > m->w_max) m->w_max = w;
  if (kind == 0) {
    if (m->n_ok == m->cap_ok) {
      long cap = m->cap_ok ? 2 * m->cap_ok : 1024;
      double *v = realloc(m->ok_w, (size_t)cap * sizeof *v);
      if (!v) return "out of memory";
      m->ok_w = v;
      m->cap_ok = cap;
    }
    m->ok_w[m->n_ok++] = w;
  }
  m->n_sing += kind == 1;
  m->n_other += kind == 2;
  m->cur++;
  m->rows++;
  return NULL;
}

/* Converts the map rows of f into dat (gnuplot's grid format: blank lines
 * between q1 blocks; columns q1 q2 w_R kind); 0, or 2 after a message
 * naming path and line. */
static int convert_map(const char *cmd, const char *path, FILE *f, long line_no, FILE *dat,
                       map_scan *m)
{
  char *line = NULL;
  size_t cap = 0;
  int rc = 0;
  memset(m, 0, sizeof *m);
  m->w_max = 1.0;
  while (getline(&line, &cap, f) > 0) {
    ++line_no;
    chomp(line);
    if (line[0] == '#') continue;
    double q[3], w;
    int kind;
    const char *why = parse_map_row(line, q, &w, &kind);
    long n1_before = m->n1;
    if (!why) why = scan_row(m, q, w, kind);
    if (why) {
      prru_cli_error(cmd, "%s:%ld: %s", path, line_no, why);
      rc = 2;
      break;
    }
    if (m->n1 != n1_before && n1_before > 0) fputc('\n', dat); /* a new q1 block */
    fprintf(dat, "%.17g %.17g %.17g %d\n", q[0], q[1], w, kind);
  }
  free(line);
  if (rc == 0 && ferror(f)) {
    prru_cli_error(cmd, "%s: read error: %s", path, strerror(errno));
    rc = 2;
  }
  if (rc == 0 && m->n1 == 1) m->n2 = m->cur;
  if (rc == 0 && (m->n1 < 2 || m->n2 < 2 || m->cur != m->n2)) {
    prru_cli_error(cmd, "%s: %s", path,
                   m->rows == 0 ? "no data rows" :
                   "not a complete grid of at least 2 x 2 points (the last q1 block is short)");
    rc = 2;
  }
  return rc;
}

/* ---- identify's report ---- */

/* One report row "index,parameter,estimate,se,prior,resolution,model,t,
 * combination" into its name and numbers; NULL or why not. */
static const char *parse_ident_row(char *line, long want_index, char *name, size_t len, double v[6])
{
  char *end;
  errno = 0;
  long index = strtol(line, &end, 10);
  if (end == line || *end != ',' || index != want_index) return "the index is not the row's number";
  char *p = end + 1, *comma = strchr(p, ',');
  if (!comma || comma == p || (size_t)(comma - p) >= len) return "no parameter name";
  for (char *c = p; c < comma; c++)
    if (!(isalnum((unsigned char)*c) || *c == '.' || *c == '_')) return "the parameter name is not a name";
  snprintf(name, len, "%.*s", (int)(comma - p), p);
  p = comma + 1;
  for (int k = 0; k < 6; k++) {
    v[k] = strtod(p, &end);
    if (end == p || *end != ',' || !isfinite(v[k])) return "estimate, se, prior, resolution, model and t must be finite numbers";
    p = end + 1;
  }
  if (!(v[1] >= 0) || !(v[3] > 0)) return "se must be >= 0 and the resolution > 0";
  return NULL;
}

/* The report's rows into dat: index, (estimate - prior) / s, 3 se / s,
 * (model - prior) / s, name; s = max(|prior|, resolution), so drives with
 * a prior of 0 are measured by what the data resolve. 0, or 2 after a
 * message naming path and line; *n the rows. */
static int convert_ident(const char *cmd, const char *path, FILE *f, long line_no, FILE *dat, long *n)
{
  char *line = NULL, name[128];
  size_t cap = 0;
  int rc = 0;
  *n = 0;
  while (getline(&line, &cap, f) > 0) {
    ++line_no;
    chomp(line);
    if (line[0] == '#') continue;
    double v[6];
    const char *why = parse_ident_row(line, *n + 1, name, sizeof name, v);
    if (why) {
      prru_cli_error(cmd, "%s:%ld: %s", path, line_no, why);
      rc = 2;
      break;
    }
    const double s = fmax(fabs(v[2]), v[3]);
    fprintf(dat, "%ld %.17g %.17g %.17g %s\n", ++*n, (v[0] - v[2]) / s, 3 * v[1] / s, (v[4] - v[2]) / s, name);
  }
  free(line);
  if (rc == 0 && ferror(f)) {
    prru_cli_error(cmd, "%s: read error: %s", path, strerror(errno));
    rc = 2;
  }
  if (rc == 0 && *n == 0) {
    prru_cli_error(cmd, "%s: no base parameters (no rows after the header)", path);
    rc = 2;
  }
  return rc;
}

/* ---- time series CSVs (simulate, track, traj, excite, id) ---- */

/* What each kind is called in messages, by the enum. */
static const char *const kind_name[] = {"", "a simulation", "a map", "a tracking", "a trajectory",
                                        "an excitation", "an inverse dynamics", "an identification report",
                                        "a time-optimal trajectory"};

/* The number of columns <prefix>1, <prefix>2, ... of t. */
static int count_columns(const prru_table *t, const char *prefix)
{
  char name[32];
  int n = 0;
  for (;;) {
    snprintf(name, sizeof name, "%s%d", prefix, n + 1);
    if (prru_table_column(t, name) < 0) return n;
    n++;
  }
}

/* 0 when t has the columns <prefix>1..<prefix>n, else 2 after a message. */
static int need_columns(const char *cmd, const char *path, int kind, const prru_table *t,
                        const char *prefix, int n)
{
  if (count_columns(t, prefix) >= n) return 0;
  prru_cli_error(cmd, "%s: %s CSV with %d sliders needs the columns %s1..%s%d", path,
                 kind_name[kind], n, prefix, prefix, n);
  return 2;
}

/* The force limit of each actuator as a track CSV shows it: |fd_i| at a
 * row with sat_i = 1 (a clipped force is the limit itself); NaN for an
 * actuator never clipped, whose limit the file does not hold. */
static void track_limits(const prru_table *t, int nact, double *f_max)
{
  char name[32];
  for (int i = 0; i < nact; i++) {
    snprintf(name, sizeof name, "fd%d", i + 1);
    int fd = prru_table_column(t, name);
    snprintf(name, sizeof name, "sat%d", i + 1);
    int sat = prru_table_column(t, name);
    f_max[i] = NAN;
    for (int r = 0; r < t->nrows && isnan(f_max[i]); r++) {
      const double *row = t->data + (size_t)r * (size_t)t->ncols;
      if (row[sat] == 1) f_max[i] = fabs(row[fd]);
    }
  }
}

/* The limits of a time-optimal trajectory's line "force_max (N) F1,F2,..;
 * speed_max (m/s) V1,V2,..": each list as written, NAN where a kind is not
 * named (no limit of that kind: no line drawn). */
static void topp_limits(const char *line, int nact, double *f_max, double *v_max)
{
  static const char *const key[2] = {"force_max (N) ", "speed_max (m/s) "};
  double *out[2] = {f_max, v_max};
  for (int k = 0; k < 2; k++) {
    for (int i = 0; i < nact; i++) out[k][i] = NAN;
    const char *p = strstr(line, key[k]);
    if (!p) continue;
    p += strlen(key[k]);
    for (int i = 0; i < nact; i++) {
      char *end;
      const double v = strtod(p, &end);
      if (end == p) break;
      out[k][i] = v > 0 ? v : NAN;
      if (*end != ',') break;
      p = end + 1;
    }
  }
}

/* Checks a time series CSV of the kind (every row as long as the header,
 * finite numbers, the columns the figure draws) with the runtime's table
 * reader and writes its script (the CSV by its absolute path abs) into
 * *script; 0, 1 (no memory) or 2 after a message. */
static int series_script(const char *cmd, const char *path, const char *abs, int kind,
                         const char *model, const char *footer, const char *limits, char **script)
{
  prru_table t;
  char msg[600];
  *script = NULL;
  if (prru_table_read(&t, path, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error(cmd, "%s", msg);
    return 2;
  }
  int rc = 0;
  if (t.nrows < 2) {
    prru_cli_error(cmd, "%s: %s CSV with fewer than 2 rows has nothing to plot", path, kind_name[kind]);
    rc = 2;
  }
  int nact = count_columns(&t, kind == CSV_TRACK || kind == CSV_ID ? "fd" : "d");
  double v_max[64];
  double f_max[64];
  if (rc == 0 && (kind == CSV_TRACK || kind == CSV_TOPP) && nact > (int)(sizeof f_max / sizeof f_max[0])) {
    prru_cli_error(cmd, "%s: more than %d actuators", path, (int)(sizeof f_max / sizeof f_max[0]));
    rc = 2;
  }
  if (rc == 0 && kind == CSV_TRACK) rc = need_columns(cmd, path, kind, &t, "sat", nact);
  if (rc == 0 && kind == CSV_TRAJ) rc = need_columns(cmd, path, kind, &t, "dd", nact);
  if (rc == 0 && kind == CSV_EXCITE) rc = need_columns(cmd, path, kind, &t, "fd", nact);
  if (rc == 0 && kind == CSV_TOPP) rc = need_columns(cmd, path, kind, &t, "dd", nact);
  if (rc == 0 && kind == CSV_TOPP) rc = need_columns(cmd, path, kind, &t, "fd", nact);
  if (rc == 0) {
    if (kind == CSV_SIMULATION)
      *script = prru_plot_series_script(abs, "plot.png", model, footer, nact,
                                        prru_table_column(&t, "T") >= 0 && prru_table_column(&t, "V") >= 0);
    else if (kind == CSV_TRACK) {
      track_limits(&t, nact, f_max);
      *script = prru_plot_track_script(abs, "plot.png", model, footer, nact, f_max);
    } else if (kind == CSV_TOPP) {
      topp_limits(limits, nact, f_max, v_max);
      *script = prru_plot_topp_script(abs, "plot.png", model, footer, nact, f_max, v_max);
    } else if (kind == CSV_ID)
      *script = prru_plot_forces_script(abs, "plot.png", model, footer, nact);
    else
      *script = prru_plot_motion_script(abs, "plot.png", model, footer, nact, kind == CSV_EXCITE);
    if (!*script) {
      prru_cli_error(cmd, "out of memory");
      rc = 1;
    }
  }
  prru_table_free(&t);
  return rc;
}

/* ---- the command's work ---- */

/* Removes dir and the files in it (a scratch directory of ours). */
static void remove_scratch(const char *dir, const char *const *names, int n)
{
  char path[PRRU_PLOT_PATH + 64];
  for (int i = 0; i < n; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    unlink(path);
  }
  rmdir(dir);
}

int prru_plot_deliver(const char *cmd, const char *png, const char *out)
{
  FILE *f = fopen(png, "rb");
  if (!f) {
    prru_cli_error(cmd, "%s (made by gnuplot or for it): %s", png, strerror(errno));
    return 1;
  }
  prru_cli_out o;
  if (prru_cli_out_open(&o, cmd, out)) {
    fclose(f);
    return 1;
  }
  char buf[65536];
  size_t n, total = 0;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
    prru_cli_out_write(&o, buf, n);
    total += n;
  }
  int read_bad = ferror(f);
  fclose(f);
  if (read_bad) {
    prru_cli_out_close(&o, 0);
    prru_cli_error(cmd, "%s: read error", png);
    return 1;
  }
  prru_cli_out_line(&o);
  return prru_cli_out_close(&o, total > 0);
}

int prru_plot_scratch(const char *cmd, char *dir, size_t len)
{
  const char *base = getenv("TMPDIR");
  if (!base || !*base) base = "/tmp";
  if ((size_t)snprintf(dir, len, "%s/prru-plot-XXXXXX", base) >= len || !mkdtemp(dir)) {
    prru_cli_error(cmd, "cannot create a scratch directory in %s: %s", base, strerror(errno));
    return 1;
  }
  return 0;
}

/* The default output: FILE.csv -> FILE.png (ext given), else FILE.ext. */
void prru_plot_default_out(const char *in, const char *ext, char *out, size_t len)
{
  size_t n = strlen(in);
  if (n > 4 && strcmp(in + n - 4, ".csv") == 0) n -= 4;
  snprintf(out, len, "%.*s%s", (int)n, in, ext);
}

/* The footer of a figure of the file in: its name and its comment lines,
 * numbers and hashes shortened. */
static void csv_footer(const char *in, const csv_comments *com, char *footer, size_t len)
{
  char text[1000];
  const char *base = strrchr(in, '/');
  snprintf(text, sizeof text, "prru plot %s: %s", base ? base + 1 : in, com->text);
  prru_plot_shorten(text, footer, len);
}

int prru_plot_csv(const char *cmd, const char *in, const char *out, double clip)
{
  FILE *f = fopen(in, "r");
  if (!f) {
    prru_cli_error(cmd, "%s: cannot open: %s", in, strerror(errno));
    return 2;
  }
  csv_comments com;
  char *header = NULL;
  long line_no = 0;
  int kind = read_head(f, &com, &header, &line_no);
  if (kind == CSV_UNKNOWN) {
    if (header)
      prru_cli_error(cmd, "%s:%ld: not a CSV of prru simulate, map, track, traj, excite, id or an identify report "
                     "(their headers: see 'prru plot --help'): the header is '%.60s'", in, line_no,
                     header);
    else
      prru_cli_error(cmd, "%s: no header line (%s): not a CSV of prru simulate, map, track, traj, "
                     "excite, id or an identify report", in, line_no ? "only comments" : "empty");
    free(header);
    fclose(f);
    return 2;
  }
  free(header);
  if (kind != CSV_MAP && !isnan(clip)) {
    prru_cli_error(cmd, "--clip: only for a map CSV (%s is %s CSV)", in, kind_name[kind]);
    fclose(f);
    return 2;
  }
  char footer[1000];
  csv_footer(in, &com, footer, sizeof footer);
  const char *model = com.model[0] ? com.model : "(not named in the file)";
  char dir[PRRU_PLOT_PATH], path[PRRU_PLOT_PATH + 64], abs_in[PRRU_PLOT_PATH];
  static const char *const scratch[] = {"map.dat", "contours.dat", "plot.gp", "plot.png"};
  if (prru_plot_scratch(cmd, dir, sizeof dir)) {
    fclose(f);
    return 1;
  }
  int rc = 0;
  char *script = NULL;
  if (kind == CSV_IDENT) {
    snprintf(path, sizeof path, "%s/map.dat", dir);
    FILE *dat = fopen(path, "w");
    long n = 0;
    rc = dat ? convert_ident(cmd, in, f, line_no, dat, &n) : 1;
    if (!dat) prru_cli_error(cmd, "%s: %s", path, strerror(errno));
    if (dat && fclose(dat) != 0 && rc == 0) {
      prru_cli_error(cmd, "%s: write error: %s", path, strerror(errno));
      rc = 1;
    }
    if (rc == 0 && !(script = prru_plot_ident_script("map.dat", "plot.png", model, footer, n))) rc = 1;
    fclose(f);
  } else if (kind == CSV_MAP) {
    snprintf(path, sizeof path, "%s/map.dat", dir);
    FILE *dat = fopen(path, "w");
    map_scan m = {0};
    rc = dat ? convert_map(cmd, in, f, line_no, dat, &m) : 1;
    if (!dat) prru_cli_error(cmd, "%s: %s", path, strerror(errno));
    if (dat && fclose(dat) != 0 && rc == 0) {
      prru_cli_error(cmd, "%s: write error: %s", path, strerror(errno));
      rc = 1;
    }
    if (rc == 0) {
      prru_plot_map_info info = {m.q3, m.w_max, m.n1, m.n2, m.n_sing, m.n_other,
                                 prru_plot_clip_value(clip, m.ok_w, (size_t)m.n_ok, m.w_max), isnan(clip)};
      script = prru_plot_map_script("map.dat", "plot.png", model, footer, &info);
      if (!script) rc = 1;
    }
    free(m.q2);
    free(m.ok_w);
    fclose(f);
  } else {
    fclose(f);
    if (!realpath(in, abs_in)) {
      prru_cli_error(cmd, "%s: %s", in, strerror(errno));
      rc = 2;
    }
    if (rc == 0) rc = series_script(cmd, in, abs_in, kind, model, footer, com.limits, &script);
  }
  if (rc == 0) rc = prru_plot_run(cmd, dir, dir, "plot.gp", script);
  if (rc == PRRU_PLOT_NO_GNUPLOT) {
    prru_cli_error(cmd, "gnuplot not found: install gnuplot-nox (e.g. with 'make deps')");
    rc = 1;
  }
  if (rc == 0) {
    snprintf(path, sizeof path, "%s/plot.png", dir);
    rc = prru_plot_deliver(cmd, path, out);
  }
  free(script);
  remove_scratch(dir, scratch, (int)(sizeof scratch / sizeof scratch[0]));
  return rc;
}
