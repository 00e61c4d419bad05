/* Plotting for the `prru` tool: every gnuplot script and every gnuplot run
 * lives in cli/plot.c. Commands hand it data files (CSVs as the tool
 * writes them) and get PNGs back; they never write gnuplot themselves.
 *
 * All functions name the command (`cmd`) in their messages. A return of
 * 0 is success; PRRU_PLOT_NO_GNUPLOT means gnuplot is not installed (no
 * message printed: the caller says what was still made); 1 means gnuplot
 * or a file failed (message printed); 128 + signal when prru was stopped
 * (prru_cli_interrupted) while gnuplot ran. */
#ifndef PRRU_CLI_PLOT_H
#define PRRU_CLI_PLOT_H

#include <stdio.h>

#define PRRU_PLOT_NO_GNUPLOT 3

/* Writes script to dir/script_name and runs gnuplot in dir, so that the
 * script's relative file names (data and PNGs) are dir's. Messages name
 * shown_dir/script_name instead (shown_dir: where the files will end up
 * when dir is a staging directory; pass dir otherwise). Waits while
 * polling prru_cli_interrupted: on a signal gnuplot gets SIGTERM. */
int prru_plot_run(const char *cmd, const char *dir, const char *shown_dir,
                  const char *script_name, const char *script);

/* The line `model = '<model name>'`: a gnuplot string for titles (quotes
 * doubled, enhanced-text specials escaped). */
void prru_plot_model_var(FILE *g);

/* Text as a gnuplot single-quoted string literal, quotes doubled and
 * control characters dropped: prru_plot_string for file names,
 * prru_plot_label for titles (enhanced-text specials _ ^ { } @ & ~
 * escaped so that they print as themselves). */
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

#endif
