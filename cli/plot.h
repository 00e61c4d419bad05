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
 * the singularity tolerance the map used (stated in the titles). A
 * malloc'ed script, NULL when out of memory. */
char *prru_plot_fig7_script(int nposes, double rcond_min);

/* ---- prru plot and prru animate (cli/plot_file.c, cli/cmd_plot.c) ---- */

/* A PNG of a CSV written by prru simulate, map, track, traj, excite or id
 * (recognised by its header; '#' lines go into the title) at out ("-":
 * stdout; a file is replaced only when the picture is complete). 0; 2
 * when the file cannot be read or is not such a CSV (message with the
 * line); 1 when gnuplot is missing or fails. */
int prru_plot_csv(const char *cmd, const char *in, const char *out);

/* A map CSV as prru_plot_map_script draws it. */
typedef struct {
  double q3, w_max;       /* the map's q3; the largest ok w_R */
  long n1, n2;            /* grid size */
  long n_sing, n_other;   /* singular or unreachable points; other assembly mode */
} prru_plot_map_info;

/* The w_R contour map of dat (columns q1 q2 w_R kind, kind 0 ok, 1 singular
 * or unreachable, 2 other assembly mode; blank lines between q1 blocks)
 * into png; subtitle: the CSV's comment lines. Malloc'ed; NULL: no memory. */
char *prru_plot_map_script(const char *dat, const char *png, const char *subtitle,
                           const prru_plot_map_info *info);
/* Time series panels of a simulation CSV (absolute path csv): q1, q2; q3;
 * d1..d<nact>; T, V and T + V when energies. Malloc'ed, NULL: no memory. */
char *prru_plot_series_script(const char *csv, const char *png, const char *subtitle, int nact,
                              int energies);

/* The tracking figure of a `prru track` CSV (absolute path csv) into png:
 * the errors e1..e3, and the forces fd1..fd<nact> with dashed lines at
 * +-f_max[i] where f_max[i] is finite (the limit of actuator i). Title:
 * the model (compiled in) when subtitle is NULL, else subtitle (the CSV's
 * comment lines). Malloc'ed, NULL: no memory. */
char *prru_plot_track_script(const char *csv, const char *png, const char *subtitle, int nact,
                             const double *f_max);
/* Time series panels of a `prru traj` CSV (forces 0: q1, q2; q3; d; the
 * slider velocities dd) or of a `prru excite` CSV (forces 1: the same with
 * the actuator forces fd last). Malloc'ed, NULL: no memory. */
char *prru_plot_motion_script(const char *csv, const char *png, const char *subtitle, int nact,
                              int forces);
/* The actuator forces fd1..fd<nact> of a `prru id` CSV over time.
 * Malloc'ed, NULL: no memory. */
char *prru_plot_forces_script(const char *csv, const char *png, const char *subtitle, int nact);

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
 * the other assembly mode). Malloc'ed, NULL: no memory. */
char *prru_plot_optimize_script(const prru_map_grid *grid, double rcond_min, double index_before,
                                double index_after, double sing_before, double sing_after,
                                const char *name);

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
