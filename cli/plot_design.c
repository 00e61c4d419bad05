/* The gnuplot scripts of the design commands (prru optimize, prru
 * sensitivity, prru merge); run by prru_plot_run (cli/plot.c). */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#include <stdio.h>
#include <stdlib.h>

#include "design_cli.h"
#include "plot.h"

static char *finish(FILE *g, char **buf)
{
  if (fclose(g) != 0) {
    free(*buf);
    return NULL;
  }
  return *buf;
}

char *prru_plot_sensitivity_script(const char *dat, const char *png)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return NULL;
  prru_plot_model_var(g);
  fputs("set terminal pngcairo size 1200,650 enhanced font 'Sans,11'\nset output ", g);
  prru_plot_string(g, png);
  fputs("\ndat = ", g);
  prru_plot_string(g, dat);
  fputs("\n"
        "set title \"Sensitivity of the objective to the design parameters, model \".model.\"\\n"
        "d(objective)/d(p) x scale of p (the parameter's magnitude; body inertia, length or slider mass where p may be 0), largest 30\\n"
        "*: a grid point changed status between p - h and p + h (the difference includes a jump)\"\n"
        "set style fill solid 0.8 border -1\n"
        "set boxwidth 0.7\n"
        "set xtics rotate by -60 noenhanced\n"
        "set ylabel 'change of the objective per scale of p'\n"
        "set grid ytics\n"
        "set key off\n"
        "set xzeroaxis lt -1\n"
        "plot dat using 1:3:($3 < 0 ? 0x3b528b : 0xd95f02):xtic(2) with boxes lc rgb variable\n",
        g);
  return finish(g, &buf);
}

char *prru_plot_optimize_script(const prru_map_grid *grid, double rcond_min, double index_before,
                                double index_after, double sing_before, double sing_after,
                                const char *name)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return NULL;
  prru_plot_model_var(g);
  fputs("opt = ", g);
  prru_plot_label(g, name);
  fprintf(g, "\nq1lo = %.17g\nq1hi = %.17g\nq2lo = %.17g\nq2hi = %.17g\nq3 = %.9g\n", grid->q1_lo,
          grid->q1_hi, grid->q2_lo, grid->q2_hi, grid->q3);
  fprintf(g, "cond = %.6g\nib = %.9g\nia = %.9g\nsb = %.6g\nsa = %.6g\n", 1.0 / rcond_min, index_before,
          index_after, 100 * sing_before, 100 * sing_after);
  fputs("set terminal pngcairo size 1400,640 enhanced font 'Sans,11'\n"
        "set output 'optimize_maps.png'\n"
        "set multiplot layout 1,2 title sprintf(\"Rotational dynamic manipulability w_R over the workspace, q_3 = %g m: \"."
        "\"before and after prru optimize\\nwhite: J_d singular (cond_1 > %g), other assembly mode or unreachable; one colour scale, w_R > 5 drawn as 5\", q3, cond)\n"
        "set xlabel 'q_1 (rad)'\n"
        "set ylabel 'q_2 (rad)'\n"
        "set cblabel 'w_R = {/Symbol s}_1/{/Symbol s}_2'\n"
        "set logscale cb\n"
        "set cbrange [1:5]\n"
        "set cbtics (1, 1.2, 1.5, 2, 3, 5)\n"
        "set palette rgbformulae 22,13,-31\n"
        "set xrange [q1lo:q1hi]\n"
        "set yrange [q2lo:q2hi]\n"
        "set size ratio -1\n"
        "unset key\n"
        "set title sprintf(\"before: model %s\\nglobal index %.4f, %.2f %% singular\", model, ib, sb)\n"
        "plot 'before.dat' using 1:2:($3 > 5 ? 5 : $3) with image\n"
        "set title sprintf(\"after: %s\\nglobal index %.4f, %.2f %% singular\", opt, ia, sa)\n"
        "plot 'after.dat' using 1:2:($3 > 5 ? 5 : $3) with image\n"
        "unset multiplot\n",
        g);
  return finish(g, &buf);
}
