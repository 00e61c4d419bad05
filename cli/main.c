/* prru: dynamics of the 3-PRRU parallel manipulator from the command line. */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "prru.h"

static const struct {
  const char *name;
  int (*run)(int, char **);
  const char *help;
} commands[] = {
    {"eval", prru_cmd_eval, "M, h, G, d, J_d, qdd and the joint reactions at one state (JSON)"},
    {"simulate", prru_cmd_simulate, "integrate the equations of motion, CSV of the samples"},
    {"ik", prru_cmd_ik, "actuator displacements d and J_d for a pose q (JSON)"},
    {"fk", prru_cmd_fk, "pose q for actuator displacements d (JSON; --lsq: least squares)"},
    {"id", prru_cmd_id, "actuator forces along a CSV trajectory (inverse dynamics)"},
    {"traj", prru_cmd_traj, "quintic point-to-point trajectory through waypoints, CSV"},
    {"track", prru_cmd_track, "computed-torque tracking of a trajectory, simulated, CSV"},
    {"excite", prru_cmd_excite, "optimised periodic excitation trajectory for identification, CSV"},
    {"identify", prru_cmd_identify, "base inertial parameters from measured motion and forces (model)"},
    {"dme", prru_cmd_dme, "dynamic manipulability ellipsoid and w_R at one pose (JSON)"},
    {"map", prru_cmd_map, "w_R over a (q1, q2) grid, CSV, and the global index"},
    {"plot", prru_cmd_plot, "PNG of a CSV prru wrote: time series, tracking errors, w_R map"},
    {"animate", prru_cmd_animate, "animated GIF of the mechanism moving through a simulated run"},
    {"view", prru_cmd_view, "self-contained HTML page: the run in 3-D in a browser, w_R map"},
    {"optimize", prru_cmd_optimize, "choose geometry/inertia so w_R is nearest 1 over a workspace"},
    {"sensitivity", prru_cmd_sensitivity, "d(global index)/d(parameter) for every parameter, CSV"},
    {"merge", prru_cmd_merge, "join the --shard K/N outputs of map or sensitivity"},
    {"paper", prru_cmd_paper, "reproduce the paper's simulation study and fig. 7 into a directory"},
};

static void usage(FILE *f)
{
  fprintf(f, "usage: prru COMMAND [OPTIONS]   (prru COMMAND --help for its options)\n"
             "       prru --help | --version\n\n"
             "Dynamics of the %d-PRRU 1T2R parallel manipulator%s:\n"
             "q = (q1, q2) rad rotations of the platform about x then y', q3 its height\n"
             "(m); d the %d slider heights (m).\n"
             "Model: %s (%s), built in (see prru --version).\n"
             "Every JSON output names it in \"model\", every CSV in its first line\n"
             "(# prru VERSION model NAME (FILE, sha256 HASH)).\n\n"
             "commands:\n",
          PRRU_NLIMB, PRRU_NACT > 3 ? " (redundantly actuated)" : "", PRRU_NACT, prru_mech.name,
          prru_mech.model_file);
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
    fprintf(f, "  %-9s %s\n", commands[i].name, commands[i].help);
  fprintf(f, "  %-9s %s\n", "version", "version and model: name, file, format, actuators, SHA-256");
  fprintf(f, "\nexit status: 0 success, 1 failure (state unreachable or singular, no\n"
             "convergence, I/O error: the reason on stderr), 2 usage error or bad input\n"
             "file, 130/143/129 stopped by SIGINT/SIGTERM/SIGHUP (simulate, id, map,\n"
             "paper: rows computed so far are kept, every file ends with a whole row).\n"
             "Output files are built beside their name and renamed when done: a run\n"
             "that fails before its first row leaves an existing file as it was.\n\n"
             "global options:\n"
             "  -h, --help     this text (prru COMMAND --help: the command's)\n"
             "  --version      version and model (also prru COMMAND --version)\n");
}

/* Every command's stdout (JSON, summaries, help) is checked once flushed
 * and closed: "> /dev/full" is an error with the reason, exit 1. */
static int finish(const char *cmd, int rc)
{
  if (prru_cli_close_stdout(cmd)) return rc == 0 ? 1 : rc;
  return rc;
}

int main(int argc, char **argv)
{
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
    usage(stdout);
    return finish("help", 0);
  }
  if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "version") == 0) {
    if (argc > 2) {
      fprintf(stderr, "prru: %s takes no arguments\n", argv[1]);
      return 2;
    }
    prru_cli_print_version(stdout);
    return finish("version", 0);
  }
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
    if (strcmp(argv[1], commands[i].name) == 0 && argc == 3 && strcmp(argv[2], "--version") == 0) {
      prru_cli_print_version(stdout); /* every command answers --version (help2man) */
      return finish(commands[i].name, 0);
    }
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
    if (strcmp(argv[1], commands[i].name) == 0)
      return finish(commands[i].name, commands[i].run(argc - 2, argv + 2));
  fprintf(stderr, "prru: unknown command '%s'\n\n", argv[1]);
  usage(stderr);
  return 2;
}
