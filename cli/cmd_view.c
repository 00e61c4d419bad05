/* prru view: one self-contained HTML file that shows a run in 3-D in a
 * browser, offline. The body poses of every frame are the pose kernel's
 * (prru_poses, in double), written as JSON numbers with 17 digits; the
 * page's script (web/view.js) only places meshes by those frames, and
 * three.js (web/vendor/three.module.min.js, r170) travels inside the page.
 * Both are embedded in the binary at build time (web/embed.py). */
#define _POSIX_C_SOURCE 200809L /* getline */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "mapgrid.h"
#include "prru.h"
#include "prru_dme.h"

/* The page parts (build/cli/view_assets.c, from web/). */
extern const unsigned char prru_view_html[], prru_view_js[], prru_view_three[];
extern const size_t prru_view_html_len, prru_view_js_len, prru_view_three_len;

static const char view_help[] =
    "usage: prru view FILE.csv [--out FILE.html|-] [--map MAP.csv] [--frames N]\n"
    "One HTML file that shows a run of prru simulate, id, traj, track or excite\n"
    "(any CSV with the columns t, q1, q2, q3) in 3-D in a web browser, with no\n"
    "network: the rails (grey), sliders (black), upper links (blue), lower\n"
    "links (orange) and the platform (green), placed at every frame by this\n"
    "build's pose kernel in double precision; play, pause and a slider to\n"
    "scrub; drag to turn the view, the wheel to zoom. When the run has the\n"
    "joint reactions (simulate writes them unless --no-reactions), the forces\n"
    "of the lower links on the platform at the U joints can be shown as\n"
    "arrows. --map adds the w_R map of a prru map CSV (viridis, log scale,\n"
    "the run's path on it). N frames equally spaced over the rows (default\n"
    "all rows up to 2000; 2 to 100000). three.js r170 (MIT) is inside the page.\n"
    "Writes FILE.html beside FILE.csv unless --out says where (-: stdout); the\n"
    "file is replaced only when the new one is complete. A FILE or MAP whose\n"
    "first line names another model (a different sha256) is refused. Exit 2\n"
    "on a bad file or option, 1 when a row's pose is out of reach or on a\n"
    "write error.\n";

#define VIEW_MAX_COMMENTS 16

/* What the page shows of a CSV: its name and first comment lines. */
typedef struct {
  const char *path;
  char *comment[VIEW_MAX_COMMENTS];
  int ncomments;
} csv_source;

static void source_free(csv_source *s)
{
  for (int i = 0; i < s->ncomments; i++) free(s->comment[i]);
  s->ncomments = 0;
}

/* The leading '#' lines of path (at most VIEW_MAX_COMMENTS); 0, or 2 after
 * a message when the first one names another model than this build's. */
static int read_comments(const char *opt, const char *path, csv_source *s)
{
  s->path = path;
  s->ncomments = 0;
  FILE *f = fopen(path, "r");
  if (!f) return 0; /* the readers report it */
  char *line = NULL;
  size_t cap = 0;
  int rc = 0;
  while (s->ncomments < VIEW_MAX_COMMENTS && getline(&line, &cap, f) > 0 && line[0] == '#') {
    line[strcspn(line, "\r\n")] = '\0';
    const char *h = strstr(line, "sha256 "), *sha = prru_cli_model()->mech->sha256;
    if (s->ncomments == 0 && h && strncmp(h + 7, sha, strlen(sha)) != 0) {
      prru_cli_error("view", "%s%s was computed with another model (%s); this prru draws %s: give that model's "
                     "file as --model, or use the prru built from it", opt, path, line + (line[1] == ' ' ? 2 : 1), prru_cli_model_id());
      rc = 2;
      break;
    }
    char *c = strdup(line + (line[1] == ' ' ? 2 : 1));
    if (!c) break;
    s->comment[s->ncomments++] = c;
  }
  free(line);
  fclose(f);
  return rc;
}

/* ---- text into the page ---- */

/* Text as HTML character data (the title): markup characters as
 * references, control characters as '?', ill-formed UTF-8 as U+FFFD. */
static void out_html_text(prru_cli_out *o, const char *s)
{
  while (*s) {
    const unsigned char c = (unsigned char)*s;
    const size_t n = prru_utf8_char(s);
    if (c == '<')
      prru_cli_out_write(o, "&lt;", 4);
    else if (c == '>')
      prru_cli_out_write(o, "&gt;", 4);
    else if (c == '&')
      prru_cli_out_write(o, "&amp;", 5);
    else if (c == '"')
      prru_cli_out_write(o, "&quot;", 6);
    else if (c == '\'')
      prru_cli_out_write(o, "&#39;", 5);
    else if (c < 0x20 || c == 0x7f)
      prru_cli_out_write(o, "?", 1);
    else if (n == 0)
      prru_cli_out_write(o, "\xef\xbf\xbd", 3);
    else
      prru_cli_out_write(o, s, n);
    s += n ? n : 1;
  }
}

static void out_num(prru_cli_out *o, double v)
{
  if (isfinite(v))
    prru_cli_out_printf(o, "%.17g", v);
  else
    prru_cli_out_write(o, "null", 4);
}

static void out_array(prru_cli_out *o, const double *v, int n)
{
  prru_cli_out_write(o, "[", 1);
  for (int i = 0; i < n; i++) {
    if (i) prru_cli_out_write(o, ",", 1);
    out_num(o, v[i]);
  }
  prru_cli_out_write(o, "]", 1);
}

/* ---- the mechanism at a frame ---- */

/* A link's long axis in its own frame, unit, and its length: from the
 * joint centres at one pose (constant: the frame moves with the link). */
static void link_axis(const double *R, const double a[3], const double b[3], double axis[3], double *len)
{
  double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  *len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int k = 0; k < 3; k++) /* R^T d / |d| */
    axis[k] = (R[k] * d[0] + R[3 + k] * d[1] + R[6 + k] * d[2]) / *len;
}

/* ---- the run ---- */

typedef struct {
  long n;            /* frames */
  long *row;         /* their rows in the table */
  double *R, *p;     /* 9 nbody and 3 nbody per frame */
  double lo[3], hi[3];
  int react_col[PRRU_MAX_LIMB][3]; /* U-joint force columns, or -1 */
  int reactions;
} frames;

static void frames_free(frames *f)
{
  free(f->row);
  free(f->R);
  free(f->p);
}

static void grow(frames *f, const double x[3])
{
  for (int c = 0; c < 3; c++) {
    if (x[c] < f->lo[c]) f->lo[c] = x[c];
    if (x[c] > f->hi[c]) f->hi[c] = x[c];
  }
}

/* The U joint of limb i (the platform's joint in its chain), or -1. */
static int u_joint(int i)
{
  const prru_mechanism *me = prru_cli_model()->mech;
  for (int j = 0; j < me->njoint; j++)
    if (me->joint[j].type == 'U' && me->joint[j].limb == i) return j;
  return -1;
}

/* The poses of n frames equally spaced over the rows of t; 0, or 1 after
 * a message when a row is out of reach. */
static int compute_frames(const prru_table *t, const char *path, long n, frames *f)
{
  int ct = prru_table_column(t, "t"), cq[3] = {prru_table_column(t, "q1"), prru_table_column(t, "q2"),
                                                prru_table_column(t, "q3")};
  const prru_mechanism *me = prru_cli_model()->mech;
  const int nbody = me->nbody;
  memset(f, 0, sizeof *f);
  f->n = n;
  f->row = malloc((size_t)n * sizeof *f->row);
  f->R = malloc((size_t)n * 9 * (size_t)nbody * sizeof *f->R);
  f->p = malloc((size_t)n * 3 * (size_t)nbody * sizeof *f->p);
  if (!f->row || !f->R || !f->p) {
    prru_cli_error("view", "out of memory for %ld frames", n);
    return 1;
  }
  for (int c = 0; c < 3; c++) {
    f->lo[c] = INFINITY;
    f->hi[c] = -INFINITY;
  }
  for (long k = 0; k < n; k++) {
    f->row[k] = n == 1 ? 0 : (long)llround((double)k * (t->nrows - 1) / (n - 1));
    const double *r = t->data + (size_t)f->row[k] * (size_t)t->ncols;
    const double q[3] = {r[cq[0]], r[cq[1]], r[cq[2]]};
    double *R = f->R + (size_t)k * 9 * (size_t)nbody, *p = f->p + (size_t)k * 3 * (size_t)nbody;
    prru_model_poses(prru_cli_model(), q, R, p);
    int finite = 1;
    for (int i = 0; i < 9 * nbody; i++) finite &= isfinite(R[i]) != 0;
    for (int i = 0; i < 3 * nbody; i++) finite &= isfinite(p[i]) != 0;
    if (!finite) {
      char qs[128];
      prru_cli_error("view", "%s: row %ld (t = %g s): q = %s is out of reach of this model", path, f->row[k] + 1,
                     r[ct], prru_cli_vec(qs, sizeof qs, q, 3));
      return 1;
    }
    for (int i = 0; i < me->nlimb; i++) {
      double A[3], B[3], C[3];
      prru_limb_joints(prru_cli_model(), R, p, i, A, B, C);
      grow(f, A);
      grow(f, B);
      grow(f, C);
    }
  }
  f->reactions = 1;
  for (int i = 0; i < me->nlimb; i++) {
    int j = u_joint(i);
    for (int c = 0; c < 3; c++) {
      f->react_col[i][c] = j < 0 ? -1 : prru_table_column(t, me->lambda_labels[me->joint[j].lambda_offset + c]);
      if (f->react_col[i][c] < 0) f->reactions = 0;
    }
  }
  return 0;
}

/* ---- the map ---- */

typedef struct {
  long n1, n2, rows;
  long cap1, cap2, capw, caps; /* allocated elements */
  double q3, w_max;
  double *q1, *q2, *w;
  int *status;
} view_map;

static void map_free(view_map *m)
{
  free(m->q1);
  free(m->q2);
  free(m->w);
  free(m->status);
}

/* Room for element n of a growing array with *cap elements; 0 or -1. */
static int reserve_doubles(double **a, long *cap, long n)
{
  if (n < *cap) return 0;
  long c = *cap ? 2 * *cap : 64;
  double *b = realloc(*a, (size_t)c * sizeof *b);
  if (!b) return -1;
  *a = b;
  *cap = c;
  return 0;
}

static int reserve_ints(int **a, long *cap, long n)
{
  if (n < *cap) return 0;
  long c = *cap ? 2 * *cap : 64;
  int *b = realloc(*a, (size_t)c * sizeof *b);
  if (!b) return -1;
  *a = b;
  *cap = c;
  return 0;
}

/* One row into the grid read so far (q1 blocks, q1 increasing, each with
 * the first block's increasing q2 values, one q3); NULL or the reason. */
static const char *map_add(view_map *m, const double q[3], double w, int st, long *cur)
{
  if (m->rows == 0) {
    m->q3 = q[2];
  } else if (q[2] != m->q3) {
    return "q3 differs from the first row's (a map has one q3)";
  }
  if (m->rows == 0 || q[0] != m->q1[m->n1 - 1]) {
    if (m->n1 > 0 && !(q[0] > m->q1[m->n1 - 1])) return "q1 does not increase from block to block";
    if (m->n1 == 1) m->n2 = *cur;
    if (m->n1 > 0 && *cur != m->n2) return "the previous q1 block is shorter than the first";
    if (reserve_doubles(&m->q1, &m->cap1, m->n1)) return "out of memory";
    m->q1[m->n1++] = q[0];
    *cur = 0;
  }
  if (m->n1 == 1) {
    if (*cur > 0 && !(q[1] > m->q2[*cur - 1])) return "q2 does not increase within a q1 block";
    if (reserve_doubles(&m->q2, &m->cap2, *cur)) return "out of memory";
    m->q2[*cur] = q[1];
  } else if (*cur >= m->n2 || q[1] != m->q2[*cur]) {
    return "the q2 values differ from the first q1 block's (not a grid)";
  }
  if (reserve_doubles(&m->w, &m->capw, m->rows) || reserve_ints(&m->status, &m->caps, m->rows))
    return "out of memory";
  m->w[m->rows] = w;
  m->status[m->rows] = st;
  if (st == PRRU_OK && w > m->w_max) m->w_max = w;
  m->rows++;
  ++*cur;
  return NULL;
}

/* A map CSV of prru map (q1,q2,q3,w_R,status, a complete grid); 0, or 2
 * after a message naming the file and line. */
static int read_map(const char *path, view_map *m)
{
  memset(m, 0, sizeof *m);
  m->w_max = 1.0;
  FILE *f = fopen(path, "r");
  if (!f) {
    prru_cli_error("view", "--map %s: cannot open: %s", path, strerror(errno));
    return 2;
  }
  char *line = NULL;
  size_t cap = 0;
  long line_no = 0, cur = 0;
  int rc = 0, header = 0;
  while (getline(&line, &cap, f) > 0) {
    ++line_no;
    line[strcspn(line, "\r\n")] = '\0';
    if (line[0] == '#') continue;
    if (!header) {
      if (strcmp(line, "q1,q2,q3,w_R,status") != 0) {
        prru_cli_error("view", "--map %s:%ld: the header is not q1,q2,q3,w_R,status: not a CSV of prru map",
                       path, line_no);
        rc = 2;
        break;
      }
      header = 1;
      continue;
    }
    double q[3], w;
    int st;
    const char *why = prru_cli_map_parse_row(line, q, &w, &st);
    if (!why) why = map_add(m, q, w, st, &cur);
    if (why) {
      prru_cli_error("view", "--map %s:%ld: %s", path, line_no, why);
      rc = 2;
      break;
    }
  }
  free(line);
  if (rc == 0 && ferror(f)) {
    prru_cli_error("view", "--map %s: read error: %s", path, strerror(errno));
    rc = 2;
  }
  fclose(f);
  if (rc == 0 && m->n1 == 1) m->n2 = cur;
  if (rc == 0 && (m->n1 < 2 || m->n2 < 2 || cur != m->n2)) {
    prru_cli_error("view", "--map %s: %s", path, m->rows == 0 ? "no data rows" :
                   "not a complete grid of at least 2 x 2 points (the last q1 block is short)");
    rc = 2;
  }
  return rc;
}

/* ---- the page ---- */

static void out_source(prru_cli_out *o, const csv_source *s)
{
  prru_cli_out_write(o, "\"file\":", 7);
  prru_cli_out_json_string(o, s->path);
  prru_cli_out_write(o, ",\"comments\":[", 13);
  for (int i = 0; i < s->ncomments; i++) {
    if (i) prru_cli_out_write(o, ",", 1);
    prru_cli_out_json_string(o, s->comment[i]);
  }
  prru_cli_out_write(o, "]", 1);
}

/* The bodies: kind, limb, centre of mass in the body frame, and for the
 * links their long axis in the body frame and length (from frame 0). */
static void out_bodies(prru_cli_out *o, const frames *f)
{
  const double *R = f->R, *p = f->p;
  prru_cli_out_printf(o, "\"bodies\":[");
  for (int b = 0; b < prru_cli_model()->mech->nbody; b++) {
    int i = prru_cli_model()->mech->body_limb[b];
    const char *kind = b == prru_cli_model()->mech->platform ? "platform" : "link";
    double axis[3] = {0, 0, 1}, len = 0, A[3], B[3], C[3];
    if (i >= 0) {
      prru_limb_joints(prru_cli_model(), R, p, i, A, B, C);
      if (b == prru_cli_model()->mech->slider[i]) kind = "slider";
      if (b == prru_cli_model()->mech->upper[i]) {
        kind = "upper";
        link_axis(R + 9 * b, A, B, axis, &len);
      }
      if (b == prru_cli_model()->mech->lower[i]) {
        kind = "lower";
        link_axis(R + 9 * b, B, C, axis, &len);
      }
    }
    prru_cli_out_printf(o, "%s{\"name\":", b ? "," : "");
    prru_cli_out_json_string(o, prru_cli_model()->mech->body_names[b]);
    prru_cli_out_printf(o, ",\"kind\":\"%s\",\"limb\":%d,\"com\":", kind, i);
    out_array(o, prru_cli_model()->mech->com[b], 3);
    prru_cli_out_printf(o, ",\"axis\":");
    out_array(o, axis, 3);
    prru_cli_out_printf(o, ",\"length\":%.17g}", len);
  }
  prru_cli_out_printf(o, "],");
}

/* Half the side of the drawn platform plate: the largest U-joint offset
 * a, or a quarter of the mean upper link when a is small. */
static double plate_half(void)
{
  const prru_mechanism *me = prru_cli_model()->mech;
  double h = 0.0, l = 0.0;
  for (int i = 0; i < me->nlimb; i++) {
    if (me->a[i] > h) h = me->a[i];
    l += me->l1[i] / me->nlimb;
  }
  return h > 0.1 * l ? h : 0.25 * l;
}

static int cmp_double(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Per frame: row, t, q, R (9 nbody), p (3 nbody); the U-joint centres and
 * forces when the run has them. */
static void out_frames(prru_cli_out *o, const prru_table *t, const frames *f)
{
  int ct = prru_table_column(t, "t"), cq[3] = {prru_table_column(t, "q1"), prru_table_column(t, "q2"),
                                                prru_table_column(t, "q3")};
  const int nbody = prru_cli_model()->mech->nbody, nlimb = prru_cli_model()->mech->nlimb;
  prru_cli_out_printf(o, "\"frames\":{\"row\":[");
  for (long k = 0; k < f->n; k++) prru_cli_out_printf(o, "%s%ld", k ? "," : "", f->row[k]);
  prru_cli_out_printf(o, "],\"t\":[");
  for (long k = 0; k < f->n; k++) {
    if (k) prru_cli_out_write(o, ",", 1);
    out_num(o, t->data[(size_t)f->row[k] * (size_t)t->ncols + (size_t)ct]);
  }
  prru_cli_out_printf(o, "],\n\"q\":[");
  for (long k = 0; k < f->n; k++) {
    const double *r = t->data + (size_t)f->row[k] * (size_t)t->ncols, q[3] = {r[cq[0]], r[cq[1]], r[cq[2]]};
    if (k) prru_cli_out_write(o, ",", 1);
    out_array(o, q, 3);
  }
  prru_cli_out_printf(o, "],\n\"R\":[");
  for (long k = 0; k < f->n; k++) {
    if (k) prru_cli_out_write(o, ",\n", 2);
    out_array(o, f->R + (size_t)k * 9 * (size_t)nbody, 9 * nbody);
    prru_cli_out_line(o);
  }
  prru_cli_out_printf(o, "],\n\"p\":[");
  for (long k = 0; k < f->n; k++) {
    if (k) prru_cli_out_write(o, ",\n", 2);
    out_array(o, f->p + (size_t)k * 3 * (size_t)nbody, 3 * nbody);
    prru_cli_out_line(o);
  }
  prru_cli_out_printf(o, "]},\n\"reactions\":");
  if (!f->reactions) {
    prru_cli_out_printf(o, "null");
    return;
  }
  /* A force at the 90th percentile of the run's as long as the mean upper
   * link (the largest, at a jerk of the start, would make most arrows
   * invisible). */
  double *mag = malloc((size_t)f->n * (size_t)nlimb * sizeof *mag), fref = 0.0;
  if (mag) {
    for (long k = 0; k < f->n; k++)
      for (int i = 0; i < nlimb; i++) {
        const double *r = t->data + (size_t)f->row[k] * (size_t)t->ncols;
        double fx = r[f->react_col[i][0]], fy = r[f->react_col[i][1]], fz = r[f->react_col[i][2]];
        mag[k * nlimb + i] = sqrt(fx * fx + fy * fy + fz * fz);
      }
    qsort(mag, (size_t)f->n * (size_t)nlimb, sizeof *mag, cmp_double);
    fref = mag[(size_t)(0.9 * (double)(f->n * nlimb - 1))];
    free(mag);
  } else {
    o->err = ENOMEM;
  }
  prru_cli_out_printf(o, "{\"scale\":%.17g,\"labels\":[", fref > 0 ? prru_length_scale(prru_cli_model()->mech) / fref : 0.0);
  for (int i = 0; i < nlimb; i++) {
    if (i) prru_cli_out_write(o, ",", 1);
    prru_cli_out_json_string(o, prru_cli_model()->mech->joint[u_joint(i)].name);
  }
  prru_cli_out_printf(o, "],\"at\":[");
  for (long k = 0; k < f->n; k++) {
    double at[3 * PRRU_MAX_LIMB];
    const double *R = f->R + (size_t)k * 9 * (size_t)nbody, *p = f->p + (size_t)k * 3 * (size_t)nbody;
    for (int i = 0; i < nlimb; i++) {
      double A[3], B[3];
      prru_limb_joints(prru_cli_model(), R, p, i, A, B, at + 3 * i);
    }
    if (k) prru_cli_out_write(o, ",", 1);
    out_array(o, at, 3 * nlimb);
  }
  prru_cli_out_printf(o, "],\n\"f\":[");
  for (long k = 0; k < f->n; k++) {
    const double *r = t->data + (size_t)f->row[k] * (size_t)t->ncols;
    double fv[3 * PRRU_MAX_LIMB];
    for (int i = 0; i < nlimb; i++)
      for (int c = 0; c < 3; c++) fv[3 * i + c] = r[f->react_col[i][c]];
    if (k) prru_cli_out_write(o, ",", 1);
    out_array(o, fv, 3 * nlimb);
  }
  prru_cli_out_printf(o, "]}");
}

static void out_map(prru_cli_out *o, const view_map *m, const csv_source *s)
{
  prru_cli_out_printf(o, "\"map\":");
  if (!m) {
    prru_cli_out_printf(o, "null");
    return;
  }
  prru_cli_out_printf(o, "{");
  out_source(o, s);
  prru_cli_out_printf(o, ",\"q3\":%.17g,\"w_max\":%.17g,\"q1\":", m->q3, m->w_max);
  out_array(o, m->q1, (int)m->n1);
  prru_cli_out_printf(o, ",\"q2\":");
  out_array(o, m->q2, (int)m->n2);
  prru_cli_out_printf(o, ",\n\"w\":");
  out_array(o, m->w, (int)m->rows);
  prru_cli_out_printf(o, ",\n\"status\":[");
  for (long k = 0; k < m->rows; k++)
    prru_cli_out_printf(o, "%s\"%s\"", k ? "," : "",
                        m->status[k] == PRRU_EINPUT ? "invalid" : prru_dme_status_name(m->status[k]));
  prru_cli_out_printf(o, "]}");
}

/* The JSON data of the page. */
static void out_data(prru_cli_out *o, const prru_table *t, const frames *f, const csv_source *run,
                     const view_map *m, const csv_source *ms)
{
  prru_cli_out_printf(o, "{\"format\":1,\"prru\":");
  prru_cli_out_json_string(o, PRRU_VERSION);
  prru_cli_out_printf(o, ",\"model\":{\"name\":");
  prru_cli_out_json_string(o, prru_cli_model()->mech->name);
  prru_cli_out_printf(o, ",\"description\":");
  prru_cli_out_json_string(o, prru_cli_model()->mech->description);
  prru_cli_out_printf(o, ",\"file\":");
  prru_cli_out_json_string(o, prru_cli_model()->mech->model_file);
  prru_cli_out_printf(o, ",\"sha256\":");
  prru_cli_out_json_string(o, prru_cli_model()->mech->sha256);
  prru_cli_out_printf(o, ",\"kernels\":");
  prru_cli_out_json_string(o, prru_cli_model()->kernels->path);
  prru_cli_out_printf(o, "},\n\"source\":{");
  out_source(o, run);
  prru_cli_out_printf(o, ",\"rows\":%d},\n", t->nrows);
  prru_cli_out_printf(o, "\"length_scale\":%.17g,\"plate_half\":%.17g,", prru_length_scale(prru_cli_model()->mech), plate_half());
  /* Rails: vertical at the sliders' (x, y), a little beyond their travel. */
  double margin = 0.1 * (f->hi[2] - f->lo[2]) + 0.25 * prru_length_scale(prru_cli_model()->mech);
  double lo[3] = {f->lo[0], f->lo[1], f->lo[2] - margin}, hi[3] = {f->hi[0], f->hi[1], f->hi[2] + margin};
  prru_cli_out_printf(o, "\"extent\":{\"lo\":");
  out_array(o, lo, 3);
  prru_cli_out_printf(o, ",\"hi\":");
  out_array(o, hi, 3);
  prru_cli_out_printf(o, "},\"rails\":[");
  for (int i = 0; i < prru_cli_model()->mech->nlimb; i++) {
    double A[3], B[3], C[3];
    prru_limb_joints(prru_cli_model(), f->R, f->p, i, A, B, C);
    const double r[4] = {A[0], A[1], lo[2], hi[2]};
    if (i) prru_cli_out_write(o, ",", 1);
    out_array(o, r, 4);
  }
  prru_cli_out_printf(o, "],\n");
  out_bodies(o, f);
  prru_cli_out_line(o);
  out_frames(o, t, f);
  prru_cli_out_printf(o, ",\n");
  out_map(o, m, ms);
  prru_cli_out_printf(o, "}");
  prru_cli_out_line(o);
}

/* The page: the template with its @PRRU_...@ marks replaced. */
static void out_page(prru_cli_out *o, const prru_table *t, const frames *f, const csv_source *run,
                     const view_map *m, const csv_source *ms)
{
  const char *s = (const char *)prru_view_html, *end = s + prru_view_html_len;
  while (s < end) {
    const char *mark = strstr(s, "@PRRU_");
    if (!mark) mark = end;
    prru_cli_out_write(o, s, (size_t)(mark - s));
    if (mark == end) break;
    const char *close = strchr(mark + 1, '@');
    size_t n = close ? (size_t)(close - mark + 1) : strlen(mark);
    if (strncmp(mark, "@PRRU_TITLE@", n) == 0) {
      prru_cli_out_printf(o, "prru view: ");
      out_html_text(o, run->path);
      prru_cli_out_printf(o, " (model ");
      out_html_text(o, prru_cli_model()->mech->name);
      prru_cli_out_printf(o, ")");
    } else if (strncmp(mark, "@PRRU_DATA@", n) == 0) {
      out_data(o, t, f, run, m, ms);
    } else if (strncmp(mark, "@PRRU_THREE@", n) == 0) {
      prru_cli_out_write(o, prru_view_three, prru_view_three_len);
    } else if (strncmp(mark, "@PRRU_VIEW@", n) == 0) {
      prru_cli_out_write(o, prru_view_js, prru_view_js_len);
    } else {
      prru_cli_out_write(o, mark, n);
    }
    prru_cli_out_line(o);
    s = mark + n;
  }
  prru_cli_out_line(o);
}

/* ---- the command ---- */

static int frames_option(const char *text, long *v)
{
  if (!text) return 0;
  char *end;
  errno = 0;
  long x = strtol(text, &end, 10);
  if (!*text || *end || errno || x < 2 || x > 100000) {
    prru_cli_error("view", "--frames '%s': must be an integer from 2 to 100000", text);
    return 2;
  }
  *v = x;
  return 0;
}

/* The default output: FILE.csv -> FILE.html, else FILE.html appended. */
static char *default_out(const char *in)
{
  size_t n = strlen(in);
  if (n > 4 && strcmp(in + n - 4, ".csv") == 0) n -= 4;
  char *out = malloc(n + 6);
  if (out) snprintf(out, n + 6, "%.*s.html", (int)n, in);
  return out;
}

/* The run's table with the columns t, q1..q3 and at least 2 rows; 0 or 2. */
static int read_run(const char *file, prru_table *t)
{
  char msg[600];
  if (prru_table_read(t, file, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error("view", "%s", msg);
    return 2;
  }
  const char *need[] = {"t", "q1", "q2", "q3"};
  for (int k = 0; k < 4; k++)
    if (prru_table_column(t, need[k]) < 0) {
      prru_cli_error("view", "%s: no column '%s': not a CSV of prru simulate, id, traj, track or excite", file,
                     need[k]);
      prru_table_free(t);
      return 2;
    }
  if (t->nrows < 2) {
    prru_cli_error("view", "%s: fewer than 2 rows, nothing moves", file);
    prru_table_free(t);
    return 2;
  }
  return 0;
}

static int view_run(const char *file, const char *out, const char *map_file, long nframes)
{
  csv_source run = {0}, ms = {0};
  view_map map, *m = NULL;
  prru_table t;
  frames f = {0};
  int rc = read_comments("", file, &run);
  if (rc == 0 && map_file) rc = read_comments("--map ", map_file, &ms);
  if (rc == 0 && map_file) {
    rc = read_map(map_file, &map);
    m = &map;
  }
  if (rc == 0) rc = read_run(file, &t);
  if (rc == 0) {
    if (nframes <= 0) nframes = t.nrows < 2000 ? t.nrows : 2000;
    if (nframes > t.nrows) nframes = t.nrows;
    rc = compute_frames(&t, file, nframes, &f);
    prru_cli_out o;
    if (rc == 0) rc = prru_cli_out_open(&o, "view", out);
    if (rc == 0) {
      out_page(&o, &t, &f, &run, m, &ms);
      rc = prru_cli_out_close(&o, o.err == 0);
    }
    frames_free(&f);
    prru_table_free(&t);
  }
  if (m) map_free(m);
  source_free(&run);
  source_free(&ms);
  return rc;
}

int prru_cmd_view(int argc, char **argv)
{
  const char *file, *out = NULL, *map_file = NULL, *frames_s = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"out", 1, &out, NULL},
                            {"map", 1, &map_file, NULL},
                            {"frames", 1, &frames_s, NULL},
                            {"help", 0, NULL, &help}};
  if (prru_cli_parse_file("view", argc, argv, opts, 4, &file)) return 2;
  if (help) {
    fputs(view_help, stdout);
    return 0;
  }
  if (!file) {
    prru_cli_error("view", "a run CSV is required (see 'prru view --help')");
    return 2;
  }
  long nframes = 0;
  if (frames_option(frames_s, &nframes)) return 2;
  char *def = NULL;
  if (!out) {
    def = default_out(file);
    if (!def) return 1;
    out = def;
  }
  int rc = 0;
  if (prru_cli_same_file(file, out)) {
    prru_cli_error("view", "%s and --out %s are the same file: writing it would replace what is read "
                   "(give another --out)", file, out);
    rc = 2;
  } else if (map_file) {
    rc = prru_cli_refuse_same_file("view", "map", map_file, "out", out);
  }
  if (rc == 0) rc = view_run(file, out, map_file, nframes);
  free(def);
  return rc;
}
