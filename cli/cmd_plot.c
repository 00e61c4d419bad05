/* prru plot: a PNG of any simulation or map CSV prru wrote. */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "plot.h"
#include "prru.h"

static const char plot_help[] =
    "usage: prru plot FILE.csv [--out FILE.png|-]\n"
    "Draws a CSV written by prru simulate (or prru paper's paper_sim.csv) or\n"
    "prru map (or fig7_map.csv), recognised by its header:\n"
    "  t,q1,q2,q3,qd1,...   time series panels: q1 and q2, q3, the slider\n"
    "                       heights d, and the energies T, V, T + V;\n"
    "  q1,q2,q3,w_R,status  the w_R contour map, colours clipped at 3 (the key\n"
    "                       says so), singular or unreachable points red,\n"
    "                       the other assembly mode grey.\n"
    "The file's '#' lines (the model it was computed with) go into the title.\n"
    "Writes FILE.png beside FILE.csv unless --out says where (--out -:\n"
    "stdout); the PNG is replaced only when the new one is complete. Needs\n"
    "gnuplot. Exit 2 when FILE cannot be read or is not such a CSV (the\n"
    "message names the line and the reason), 1 when gnuplot is missing or\n"
    "fails.\n";

int prru_cmd_plot(int argc, char **argv)
{
  const char *file, *out = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"out", 1, &out, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse_file("plot", argc, argv, opts, 2, &file)) return 2;
  if (help) {
    fputs(plot_help, stdout);
    return 0;
  }
  if (!file) {
    prru_cli_error("plot", "a CSV file is required (see 'prru plot --help')");
    return 2;
  }
  char def[PRRU_PLOT_PATH];
  if (!out) {
    prru_plot_default_out(file, ".png", def, sizeof def);
    out = def;
  }
  if (strcmp(out, file) == 0) {
    prru_cli_error("plot", "--out %s: that is the input file", out);
    return 2;
  }
  prru_cli_catch_signals();
  return prru_plot_csv("plot", file, out);
}
