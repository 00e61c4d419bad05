/* prru animate: an animated GIF of a simulated run, the mechanism's bodies
 * (rails, sliders, upper and lower links, platform) placed at every frame
 * by the generated pose kernel prru_poses, limb by limb as the mechanism
 * descriptor lists them (the frame origins of docs/model.md section 4,
 * not the centres of mass). */
#define _POSIX_C_SOURCE 200809L /* getline */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"
#include "plot.h"
#include "prru.h"

static const char animate_help[] =
    "usage: prru animate FILE.csv [--out FILE.gif|-] [--frames N] [--fps F]\n"
    "                    [--segments FILE.dat]\n"
    "An animated GIF of a run written by prru simulate (or prru paper's\n"
    "paper_sim.csv): the mechanism drawn in 3-D at N instants equally spaced\n"
    "over the run (default 50, at most the number of rows, 2 to 1000), shown\n"
    "at F frames per second (default 25, 1 to 100): the rails (grey), the\n"
    "sliders (black), the upper links (blue), the lower links (orange) and\n"
    "the platform (green: its plate, normal and outline through the U joints),\n"
    "in metres in the base frame {S}, with their shadows on the floor.\n"
    "The poses are the current model's; a FILE whose first line names another\n"
    "model (a different sha256) is refused. Writes FILE.gif beside FILE.csv\n"
    "unless --out says where (--out -: stdout); the GIF is replaced only when\n"
    "the new one is complete. --segments also writes what is drawn: one line\n"
    "per segment, x y z dx dy dz body (m, in {S}; body 1 rail, 2 slider, 3\n"
    "upper link, 4 lower link, 5 platform), frames separated by two blank\n"
    "lines. Needs gnuplot. Exit 2 on a bad file or option, 1 when gnuplot is\n"
    "missing or fails or a row's pose is out of reach.\n";

/* Body colours: gnuplot line types set in the script. */
enum { COL_RAIL = 1, COL_SLIDER, COL_UPPER, COL_LOWER, COL_PLATFORM };

/* One segment as a row "x y z dx dy dz colour" (gnuplot vectors: lines
 * between rows would be drawn as a mesh by splot). */
static void seg(FILE *f, const double a[3], const double b[3], int col)
{
  fprintf(f, "%.12g %.12g %.12g %.12g %.12g %.12g %d\n", a[0], a[1], a[2], b[0] - a[0], b[1] - a[1],
          b[2] - a[2], col);
}

/* The drawing's extent, updated with point x. */
typedef struct {
  double lo[3], hi[3];
} extent;

static void grow(extent *e, const double x[3])
{
  for (int c = 0; c < 3; c++) {
    if (x[c] < e->lo[c]) e->lo[c] = x[c];
    if (x[c] > e->hi[c]) e->hi[c] = x[c];
  }
}

/* Half the side of the drawn platform plate: the U-joint offset a, or a
 * quarter of the mean upper link when a is 0. */
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

/* One frame (pass 1: extent only, out NULL); 0, or -1 when q is out of
 * reach. */
static int frame(FILE *out, const double q[3], extent *e)
{
  const int nlimb = prru_cli_model()->mech->nlimb;
  double R[9 * PRRU_MAX_BODY], p[3 * PRRU_MAX_BODY];
  prru_model_poses(prru_cli_model(), q, R, p);
  for (int k = 0; k < 3 * prru_cli_model()->mech->nbody; k++)
    if (!isfinite(p[k])) return -1;
  const int P = prru_cli_model()->mech->platform;
  const double *RP = R + 9 * P, h = plate_half();
  double O[3];
  prru_body_origin(prru_cli_model(), R, p, P, O);
  double corner[4][3], normal[3];
  for (int k = 0; k < 4; k++) {
    double x = (k == 0 || k == 3) ? -h : h, y = k < 2 ? -h : h;
    for (int c = 0; c < 3; c++) corner[k][c] = O[c] + RP[3 * c] * x + RP[3 * c + 1] * y;
  }
  for (int c = 0; c < 3; c++) normal[c] = O[c] + RP[3 * c + 2] * h;
  for (int i = 0; i < nlimb; i++) {
    double A[3], B[3], C[3];
    prru_limb_joints(prru_cli_model(), R, p, i, A, B, C);
    if (!out) {
      grow(e, A);
      grow(e, B);
      grow(e, C);
      continue;
    }
    const double r0[3] = {A[0], A[1], e->lo[2]}, r1[3] = {A[0], A[1], e->hi[2]};
    const double s0[3] = {A[0], A[1], A[2] - 0.03}, s1[3] = {A[0], A[1], A[2] + 0.03};
    seg(out, r0, r1, COL_RAIL);
    seg(out, s0, s1, COL_SLIDER);
    seg(out, A, B, COL_UPPER);
    seg(out, B, C, COL_LOWER);
    seg(out, O, C, COL_PLATFORM); /* the platform's arm to the U joint */
  }
  if (!out) {
    for (int k = 0; k < 4; k++) grow(e, corner[k]);
    return 0;
  }
  for (int k = 0; k < 4; k++) seg(out, corner[k], corner[(k + 1) % 4], COL_PLATFORM);
  seg(out, O, normal, COL_PLATFORM);
  /* The platform's outline through its U joints: the plate of side 2a
   * alone is small beside the links. */
  for (int i = 0; i < nlimb; i++) {
    double A[3], B[3], C[3], A2[3], B2[3], C2[3];
    prru_limb_joints(prru_cli_model(), R, p, i, A, B, C);
    prru_limb_joints(prru_cli_model(), R, p, (i + 1) % nlimb, A2, B2, C2);
    seg(out, C, C2, COL_PLATFORM);
  }
  fputs("\n\n", out); /* frames are gnuplot data blocks (index) */
  return 0;
}

/* 0 when the file's first '#' line names this build's model or no model;
 * 2 after a message when it names another one. */
static int check_model(const char *path)
{
  FILE *f = fopen(path, "r");
  if (!f) return 0; /* the table reader reports it */
  char *line = NULL;
  size_t cap = 0;
  int rc = 0;
  if (getline(&line, &cap, f) > 0 && line[0] == '#') {
    const char *h = strstr(line, "sha256 "), *sha = prru_cli_model()->mech->sha256;
    if (h && strncmp(h + 7, sha, strlen(sha)) != 0) {
      line[strcspn(line, "\r\n")] = '\0';
      prru_cli_error("animate", "%s was computed with another model (%s); this prru draws %s: "
                     "give that model's file as --model, or use the prru built from it", path, line + (line[1] == ' ' ? 2 : 1),
                     prru_cli_model_id());
      rc = 2;
    }
  }
  free(line);
  fclose(f);
  return rc;
}

/* An integer option in [lo, hi] (default def when text is NULL); 0 or 2. */
static int int_option(const char *name, const char *text, long lo, long hi, long def, long *v)
{
  *v = def;
  if (!text) return 0;
  char *end;
  errno = 0;
  long x = strtol(text, &end, 10);
  if (!*text || *end || errno || x < lo || x > hi) {
    prru_cli_error("animate", "--%s '%s': must be an integer from %ld to %ld", name, text, lo, hi);
    return 2;
  }
  *v = x;
  return 0;
}

/* The frame data (dat) and the script for the rows of t; 0, 1 or 2. */
static int write_frames(const char *cmd, const prru_table *t, const char *dir, long nframes, long fps,
                        const char *title, char **script)
{
  int ct = prru_table_column(t, "t"), cq[3] = {prru_table_column(t, "q1"), prru_table_column(t, "q2"),
                                                prru_table_column(t, "q3")};
  long *rows = malloc((size_t)nframes * sizeof *rows);
  if (!rows) return 1;
  for (long i = 0; i < nframes; i++) rows[i] = (long)llround((double)i * (t->nrows - 1) / (nframes - 1));
  extent e = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (long i = 0; i < nframes; i++) {
    const double *r = t->data + (size_t)rows[i] * (size_t)t->ncols;
    const double q[3] = {r[cq[0]], r[cq[1]], r[cq[2]]};
    if (frame(NULL, q, &e)) {
      prru_cli_error(cmd, "row %ld (t = %g s): q = (%g, %g, %g) is out of reach of this model", rows[i] + 1,
                     r[ct], q[0], q[1], q[2]);
      free(rows);
      return 1;
    }
  }
  /* Rails a little beyond the sliders' travel. */
  double margin = 0.1 * (e.hi[2] - e.lo[2]) + 0.05;
  e.lo[2] -= margin;
  e.hi[2] += margin;
  char path[PRRU_PLOT_PATH + 32];
  snprintf(path, sizeof path, "%s/frames.dat", dir);
  FILE *f = fopen(path, "w");
  if (!f) {
    prru_cli_error(cmd, "%s: %s", path, strerror(errno));
    free(rows);
    return 1;
  }
  fputs("# x y z dx dy dz body: segments from (x, y, z) (m, base frame); body 1 rail, 2 slider,\n"
        "# 3 upper link, 4 lower link, 5 platform; one block per frame\n", f);
  for (long i = 0; i < nframes; i++) {
    const double *r = t->data + (size_t)rows[i] * (size_t)t->ncols;
    const double q[3] = {r[cq[0]], r[cq[1]], r[cq[2]]};
    fprintf(f, "# frame %ld, t = %.9g s\n", i, r[ct]);
    frame(f, q, &e);
  }
  int bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad) {
    prru_cli_error(cmd, "%s: write error", path);
    free(rows);
    return 1;
  }
  double times[1000];
  for (long i = 0; i < nframes; i++) times[i] = t->data[(size_t)rows[i] * (size_t)t->ncols + (size_t)ct];
  free(rows);
  *script = prru_plot_animation_script("frames.dat", "anim.gif", title, nframes, times, fps, e.lo, e.hi);
  return *script ? 0 : 1;
}

int prru_cmd_animate(int argc, char **argv)
{
  const char *file, *out = NULL, *frames_s = NULL, *fps_s = NULL, *segments = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"out", 1, &out, NULL},
                            {"frames", 1, &frames_s, NULL},
                            {"fps", 1, &fps_s, NULL},
                            {"segments", 1, &segments, NULL},
                            {"help", 0, NULL, &help}};
  if (prru_cli_parse_file("animate", argc, argv, opts, 5, &file)) return 2;
  if (help) {
    fputs(animate_help, stdout);
    return 0;
  }
  if (!file) {
    prru_cli_error("animate", "a simulation CSV is required (see 'prru animate --help')");
    return 2;
  }
  long nframes, fps;
  if (int_option("frames", frames_s, 2, 1000, 50, &nframes) || int_option("fps", fps_s, 1, 100, 25, &fps))
    return 2;
  char def[PRRU_PLOT_PATH];
  if (!out) {
    prru_plot_default_out(file, ".gif", def, sizeof def);
    out = def;
  }
  if (strcmp(out, file) == 0 || (segments && (strcmp(segments, file) == 0 || strcmp(segments, out) == 0))) {
    prru_cli_error("animate", "--%s %s: that is %s", strcmp(out, file) == 0 ? "out" : "segments",
                   strcmp(out, file) == 0 ? out : segments,
                   strcmp(out, file) == 0 || strcmp(segments, file) == 0 ? "the input file" : "--out");
    return 2;
  }
  if (check_model(file)) return 2;
  prru_table t;
  char msg[600];
  if (prru_table_read(&t, file, msg, sizeof msg) != PRRU_OK) {
    prru_cli_error("animate", "%s", msg);
    return 2;
  }
  const char *need[] = {"t", "q1", "q2", "q3"};
  for (int k = 0; k < 4; k++)
    if (prru_table_column(&t, need[k]) < 0) {
      prru_cli_error("animate", "%s: no column '%s': not a CSV of prru simulate", file, need[k]);
      prru_table_free(&t);
      return 2;
    }
  if (t.nrows < 2) {
    prru_cli_error("animate", "%s: fewer than 2 rows, nothing moves", file);
    prru_table_free(&t);
    return 2;
  }
  if (nframes > t.nrows) nframes = t.nrows;
  prru_cli_catch_signals();
  char dir[PRRU_PLOT_PATH], path[PRRU_PLOT_PATH + 32];
  if (prru_plot_scratch("animate", dir, sizeof dir)) {
    prru_table_free(&t);
    return 1;
  }
  char *script = NULL;
  int rc = write_frames("animate", &t, dir, nframes, fps, prru_cli_model()->mech->name, &script);
  prru_table_free(&t);
  if (rc == 0) rc = prru_plot_run("animate", dir, dir, "anim.gp", script);
  if (rc == PRRU_PLOT_NO_GNUPLOT) {
    prru_cli_error("animate", "gnuplot not found: install gnuplot-nox (e.g. with 'make deps')");
    rc = 1;
  }
  if (rc == 0) {
    snprintf(path, sizeof path, "%s/anim.gif", dir);
    rc = prru_plot_deliver("animate", path, out);
  }
  if (rc == 0 && segments) {
    snprintf(path, sizeof path, "%s/frames.dat", dir);
    rc = prru_plot_deliver("animate", path, segments);
  }
  free(script);
  static const char *const scratch[] = {"frames.dat", "anim.gp", "anim.gif"};
  for (int k = 0; k < 3; k++) {
    snprintf(path, sizeof path, "%s/%s", dir, scratch[k]);
    unlink(path);
  }
  rmdir(dir);
  return rc;
}
