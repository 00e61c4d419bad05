/* prru plot: a PNG of any CSV prru writes with time or a map in it. */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "plot.h"
#include "prru.h"

static const char plot_help[] =
    "usage: prru plot FILE.csv [--out FILE.png|-] [--clip W]\n"
    "Draws a CSV written by prru simulate (or prru paper's paper_sim.csv), map\n"
    "(or fig7_map.csv), track, traj, excite or id, recognised by its header:\n"
    "  t,q1,q2,q3,qd1,...      (simulate) time series panels: q1 and q2, q3,\n"
    "                          the slider heights d, and the energies T, V,\n"
    "                          T + V;\n"
    "  q1,q2,q3,w_R,status     (map) the w_R contour map (viridis), colours\n"
    "                          clipped at --clip W or, by default, at the 99th\n"
    "                          percentile of w_R (the colour key says which);\n"
    "                          singular or unreachable points red, the other\n"
    "                          assembly mode grey;\n"
    "  t,qr1,qr2,qr3,q1,...    (track) the figure of 'prru track --plot': q with\n"
    "                          the reference, the errors e (rad, then m), and\n"
    "                          the forces fd with each force limit\n"
    "                          the run reached (a clipped force is the limit; a\n"
    "                          limit never reached is not in the file);\n"
    "  t,q1,..,qdd3,d1,..,dd1  (traj) q1 and q2, q3, d, and the slider\n"
    "                          velocities dd;\n"
    "  t,q1,..,qdd3,d1,..,fd1  (excite) q1 and q2, q3, d, and the actuator\n"
    "                          forces fd;\n"
    "  t,q1,..,dd1,..,fd1      (traj --time-optimal) q1 and q2, q3, the slider\n"
    "                          velocities and the actuator forces, each with\n"
    "                          the limits of the file's '# limits:' line;\n"
    "  t,fd1,...               (id) the actuator forces fd;\n"
    "  index,parameter,...     (identify's --report) per base parameter the\n"
    "                          estimate with 3 standard errors and the written\n"
    "                          model's value, as (value - prior) / max(|prior|,\n"
    "                          resolution): the prior is the zero line.\n"
    "The title names the model of the file's first '#' line; the file's name\n"
    "and '#' lines (numbers to 4 digits, the SHA-256 to 12) are the footer.\n"
    "Writes FILE.png beside FILE.csv unless --out says where (--out -:\n"
    "stdout); the PNG is replaced only when the new one is complete. Needs\n"
    "gnuplot. Exit 2 when FILE cannot be read or is not such a CSV (the\n"
    "message names the line and the reason), 1 when gnuplot is missing or\n"
    "fails.\n";

int prru_cmd_plot(int argc, char **argv)
{
  const char *file, *out = NULL;
  int help = 0;
  const char *clip_s = NULL;
  prru_cli_option opts[] = {{"out", 1, &out, NULL}, {"clip", 1, &clip_s, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse_file("plot", argc, argv, opts, 3, &file)) return 2;
  if (help) {
    fputs(plot_help, stdout);
    return 0;
  }
  if (!file) {
    prru_cli_error("plot", "a CSV file is required (see 'prru plot --help')");
    return 2;
  }
  double clip;
  if (prru_plot_parse_clip("plot", clip_s, &clip)) return 2;
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
  return prru_plot_csv("plot", file, out, clip);
}
