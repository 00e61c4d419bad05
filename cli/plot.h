/* Plotting for the `prru` tool, one module: every gnuplot script and every
 * gnuplot run lives in cli/plot.c; cli/plot_file.c reads and checks the
 * CSVs `prru plot` is given and hands the pictures over (scratch
 * directories, output files). Commands hand it data files (CSVs as the
 * tool writes them) and get PNGs back; they never write gnuplot themselves.
 *
 * All functions name the command (`cmd`) in their messages. A return of
 * 0 is success; PRRU_PLOT_NO_GNUPLOT means gnuplot is not installed (no
 * message printed: the caller says what was still made); 1 means gnuplot
 * or a file failed (message printed); 128 + signal when prru was stopped
 * (prru_cli_interrupted) while gnuplot ran. */
#ifndef PRRU_CLI_PLOT_H
#define PRRU_CLI_PLOT_H

#include <stddef.h>
#include <stdio.h>

#include "prru_dme.h" /* prru_map_grid */

#define PRRU_PLOT_NO_GNUPLOT 3

/* Room for a path (scratch directories, default output names). */
#define PRRU_PLOT_PATH 4096

/* ---- what every figure shares ---- */

/* The colour maps stop at a clip value of w_R (w_R climbs without bound
 * next to a singular band, and would leave one colour for everything
 * else): --clip W, or by default this percentile of the map's ok values. */
#define PRRU_PLOT_CLIP_PERCENTILE 99.0
#define PRRU_PLOT_CLIP_PERCENTILE_TEXT "99th"

/* The --clip option's text (NULL: not given) into *clip (NaN when not
 * given); 0, or 2 after a message naming the option. */
int prru_plot_parse_clip(const char *cmd, const char *text, double *clip);
/* The clip to draw with: clip when given (not NaN), else the percentile
 * of the n ok values ok_w; never below 1.001 (a colour range). */
double prru_plot_clip_value(double clip, const double *ok_w, size_t n, double w_max);
/* `set cblabel` saying where the colours stop and why (automatic: the
 * percentile, else --clip), when w_max is above the clip. */
void prru_plot_clip_label(FILE *g, double clip, int automatic, double w_max);
/* The p-th percentile (0..100, linear between ranks) of v; NaN when n is 0
 * or out of memory. */
double prru_plot_percentile(const double *v, size_t n, double p);
/* Text for a figure: numbers of more than 6 significant digits as %.4g
 * (CSV comment lines keep %.17g), a SHA-256 cut to 12 hex digits. */
void prru_plot_shorten(const char *in, char *out, size_t len);
/* "prru VERSION CMD; model NAME (FILE, sha256 PREFIX...)": a footer. */
void prru_plot_provenance(char *buf, size_t len, const char *cmd);
/* The variable footer and a small label 1000 of it at the bottom left
 * (multiplot figures unset it after their first panel). */
void prru_plot_footer(FILE *g, const char *text);

/* Writes script to dir/script_name and runs gnuplot in dir, so that the
 * script's relative file names (data and PNGs) are dir's. Messages name
 * shown_dir/script_name instead (shown_dir: where the files will end up
 * when dir is a staging directory; pass dir otherwise). Waits while
 * polling prru_cli_interrupted: on a signal gnuplot gets SIGTERM. When
 * gnuplot exits 0, every file the script's `set output` lines name must
 * be complete (a PNG ending in its IEND chunk, a GIF in its trailer):
 * else 1, so that the caller, which renders in a staging or scratch
 * directory, leaves the previous output as it was. */
int prru_plot_run(const char *cmd, const char *dir, const char *shown_dir,
                  const char *script_name, const char *script);

/* The line `model = '<model name>'`: a gnuplot string for titles (as
 * prru_plot_label writes it). */
void prru_plot_model_var(FILE *g);

/* Text as a gnuplot string expression: single-quoted pieces, a quote and
 * control characters joined in as octal escapes ('it'."\047".'s'), no
 * quote character anywhere that gnuplot's macro expansion could misread;
 * for where gnuplot takes an expression (assignments, set output).
 * prru_plot_string for file names (every byte kept),
 * prru_plot_label for titles (backslash and the enhanced-text specials
 * _ ^ { } @ & ~ escaped so that they print as themselves, a newline
 * breaks the line, other control characters dropped). */
void prru_plot_string(FILE *g, const char *s);
void prru_plot_label(FILE *g, const char *s);

/* The figures of a simulation CSV named csv (relative to the directory the
 * script runs in; columns as `prru simulate` writes them, with reactions):
 * fig_q.png, fig_d.png, fig4_u_joint_forces.png, fig5_p_joint_forces.png and
 * fig6_p_joint_moments.png (the paper's figs. 4-6).
 * A malloc'ed script, NULL when out of memory. */
char *prru_plot_paper_sim_script(const char *csv);

/* The fig. 7 figures (fig7_surface.png, fig7_contour.png,
 * fig7a_ellipses.png) from fig7_grid.dat, fig7_singular.dat,
 * fig7a_ellipses.dat (nposes blocks) and fig7a_segments.dat. rcond_min is
 * the singularity tolerance the map used (stated in the titles); clip
 * where the colours and the surface stop (clip_auto: the percentile, not
 * --clip), w_max the largest ok w_R. A malloc'ed script, NULL when out of
 * memory. */
char *prru_plot_fig7_script(int nposes, double rcond_min, double clip, int clip_auto, double w_max);

/* ---- prru plot and prru animate (cli/plot_file.c, cli/cmd_plot.c) ---- */

/* A PNG of a CSV written by prru simulate, map, track, traj, excite or id
 * (recognised by its header; the model named by its first '#' line goes
 * into the title, the '#' lines, shortened, into the footer) at out ("-":
 * stdout; a file is replaced only when the picture is complete). clip: a
 * map's colour clip (NaN: the percentile). 0; 2 when the file cannot be
 * read or is not such a CSV (message with the line); 1 when gnuplot is
 * missing or fails. */
int prru_plot_csv(const char *cmd, const char *in, const char *out, double clip);

/* A map CSV as prru_plot_map_script draws it. */
typedef struct {
  double q3, w_max;       /* the map's q3; the largest ok w_R */
  long n1, n2;            /* grid size */
  long n_sing, n_other;   /* singular or unreachable points; other assembly mode */
  double clip;            /* colours stop at clip (prru_plot_clip_value) */
  int clip_auto;          /* clip is the percentile, not --clip */
} prru_plot_map_info;

/* The w_R contour map of dat (columns q1 q2 w_R kind, kind 0 ok, 1 singular
 * or unreachable, 2 other assembly mode; blank lines between q1 blocks)
 * into png; title: the model; footer: provenance. Malloc'ed; NULL: no
 * memory. */
char *prru_plot_map_script(const char *dat, const char *png, const char *model, const char *footer,
                           const prru_plot_map_info *info);
/* Time series panels of a simulation CSV (absolute path csv): q1, q2; q3;
 * d1..d<nact>; T, V and T + V when energies. Title: the model; footer:
 * provenance. Malloc'ed, NULL: no memory. */
char *prru_plot_series_script(const char *csv, const char *png, const char *model, const char *footer,
                              int nact, int energies);

/* The tracking figure of a `prru track` CSV (absolute path csv) into png:
 * q1, q2 and q3 with the reference, the errors in rad and in m, and the
 * forces fd1..fd<nact> with lines at +-f_max[i] where f_max[i] is finite
 * (the limit of actuator i, in the key). Malloc'ed, NULL: no memory. */
char *prru_plot_track_script(const char *csv, const char *png, const char *model, const char *footer,
                             int nact, const double *f_max);
/* Time series panels of a `prru traj` CSV (forces 0: q1, q2; q3; d; the
 * slider velocities dd) or of a `prru excite` CSV (forces 1: the same with
 * the actuator forces fd last). Malloc'ed, NULL: no memory. */
char *prru_plot_motion_script(const char *csv, const char *png, const char *model, const char *footer,
                              int nact, int forces);
/* The actuator forces fd1..fd<nact> of a `prru id` CSV over time.
 * Malloc'ed, NULL: no memory. */
/* prru traj --time-optimal's CSV: q1 and q2, q3, the slider velocities
 * with +-v_max, the actuator forces with +-f_max (non-finite: no limit). */
char *prru_plot_topp_script(const char *csv, const char *png, const char *model, const char *footer, int nact,
                            const double *f_max, const double *v_max);
/* identify's report: per base parameter the estimate with 3 se and the
 * written model's value, relative to the prior (columns of dat: index,
 * (estimate - prior) / s, 3 se / s, (model - prior) / s, name). */
char *prru_plot_ident_script(const char *dat, const char *png, const char *model, const char *footer, long n);
char *prru_plot_forces_script(const char *csv, const char *png, const char *model, const char *footer,
                              int nact);

/* The animated GIF gif of dat: n frames (data blocks), one segment per
 * row: x y z dx dy dz colour (1..5 = rail, slider, upper link, lower
 * link, platform); frame i at time times[i], fps frames per
 * second, box lo..hi (m). title: the model. Malloc'ed, NULL: no memory. */
char *prru_plot_animation_script(const char *dat, const char *gif, const char *title, long n,
                                 const double *times, long fps, const double lo[3],
                                 const double hi[3]);

/* ---- prru optimize and prru sensitivity (cli/cmd_design.c) ---- */

/* The sensitivity bar chart of dat (lines "INDEX NAME SCALED") into png.
 * Malloc'ed, NULL: no memory. */
char *prru_plot_sensitivity_script(const char *dat, const char *png);
/* before.dat and after.dat (lines "q1 q2 w_R", NaN where not ok, blank
 * line between q1 scans) side by side into optimize_maps.png; the
 * fractions are of the grid points not ok (singular, unreachable or in
 * the other assembly mode); colours clipped at clip (clip_auto: the
 * percentile), w_max the largest ok w_R of both. Malloc'ed, NULL: no
 * memory. */
char *prru_plot_optimize_script(const prru_map_grid *grid, double rcond_min, double index_before,
                                double index_after, double sing_before, double sing_after,
                                const char *name, double clip, int clip_auto, double w_max);

/* ---- pictures out of a scratch directory (cli/plot_file.c) ---- */

/* A new scratch directory $TMPDIR/prru-plot-XXXXXX (or /tmp) into dir;
 * 0, or 1 after a message. */
int prru_plot_scratch(const char *cmd, char *dir, size_t len);
/* Copies the file png (a picture, or data made for gnuplot) to out ("-":
 * stdout) through the CLI's output file (never half-written); 0 or 1
 * after a message. */
int prru_plot_deliver(const char *cmd, const char *png, const char *out);
/* The default output name: FILE.csv -> FILE<ext>, other names + ext. */
void prru_plot_default_out(const char *in, const char *ext, char *out, size_t len);

#endif
