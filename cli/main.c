/* prru: dynamics of the 3-PRRU parallel manipulator from the command line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru.h"

static const struct {
  const char *name;
  int (*run)(int, char **);
  const char *help;
} commands[] = {
    {"eval", prru_cmd_eval, "M, h, G, d, J_d, qdd and the joint reactions at one state (JSON)"},
    {"linearize", prru_cmd_linearize, "qdd and its derivatives, A, B (and Ad, Bd) at one state (JSON)"},
    {"simulate", prru_cmd_simulate, "integrate the equations of motion, CSV of the samples"},
    {"ik", prru_cmd_ik, "actuator displacements d and J_d for a pose q (JSON)"},
    {"fk", prru_cmd_fk, "pose q for actuator displacements d (JSON; --lsq: least squares)"},
    {"id", prru_cmd_id, "actuator forces along a CSV trajectory (inverse dynamics)"},
    {"traj", prru_cmd_traj, "quintic point-to-point trajectory through waypoints, CSV"},
    {"track", prru_cmd_track, "computed-torque tracking of a trajectory, simulated, CSV"},
    {"excite", prru_cmd_excite, "optimised periodic excitation trajectory for identification, CSV"},
    {"measure", prru_cmd_measure, "a simulated run as sensors see it: quantised d, noisy forces, CSV"},
    {"identify", prru_cmd_identify, "base inertial parameters from measured motion and forces (model)"},
    {"dme", prru_cmd_dme, "dynamic manipulability ellipsoid and w_R at one pose (JSON)"},
    {"map", prru_cmd_map, "w_R over a (q1, q2) grid, CSV, and the global index"},
    {"plot", prru_cmd_plot, "PNG of a CSV prru wrote: time series, tracking errors, w_R map"},
    {"animate", prru_cmd_animate, "animated GIF of the mechanism moving through a simulated run"},
    {"view", prru_cmd_view, "self-contained HTML page: the run in 3-D in a browser, w_R map"},
    {"optimize", prru_cmd_optimize, "choose geometry/inertia so w_R is nearest 1 over a workspace"},
    {"sensitivity", prru_cmd_sensitivity, "d(global index)/d(parameter) for every parameter, CSV"},
    {"merge", prru_cmd_merge, "join the --shard K/N outputs of map or sensitivity"},
    {"gen", prru_cmd_gen, "a model file's dynamics as C99 for your controller"},
    {"paper", prru_cmd_paper, "reproduce the paper's simulation study and fig. 7 into a directory"},
};

static void usage(FILE *f)
{
  /* The robot described is the model a command would compute with (main
   * loads --model or PRRU_MODEL before this runs); "built in" is the
   * build's own model. */
  const prru_mechanism *me = prru_cli_model()->mech;
  prru_model built;
  prru_model_default(&built);
  fprintf(f, "usage: prru [--model FILE] COMMAND [OPTIONS]\n"
             "       prru --help | --version\n"
             "(prru COMMAND --help for the command's options)\n\n"
             "Dynamics of the %d-PRRU 1T2R parallel manipulator%s:\n"
             "q = (q1, q2) rad rotations of the platform about x then y', q3 its height\n"
             "(m); d the %d slider heights (m).\n"
             "Model: %s (%s), built in,\n"
             "or any model file (3 or 4 limbs) given by --model FILE (see prru --version).\n"
             "Every JSON output names it in \"model\", every CSV in its first line:\n"
             "  # prru VERSION model NAME (FILE, sha256 HASH, KERNELS kernels)\n"
             "KERNELS: specialised (the built-in model's numbers, folded into the code\n"
             "when it was built: the fastest) or parameter (any other numbers, read\n"
             "from FILE).\n\n"
             "commands:\n",
          me->nlimb, me->nact > 3 ? " (redundantly actuated)" : "", me->nact, built.mech->name,
          built.mech->model_file);
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
             "  --version      version and model (also prru COMMAND --version)\n"
             "  --model FILE   compute with the model file FILE (format of models/*.json,\n"
             "                 %d limbs, as this build) instead of the built-in model;\n"
             "                 before the command or among its options (--model=FILE\n"
             "                 too). A file the model checks refuse: exit 2, nothing\n"
             "                 computed. identify and excite need the built-in model's\n"
             "                 geometry and gravity.\n\n"
             "environment:\n"
             "  PRRU_MODEL     the model file when no --model is given (empty: the\n"
             "                 built-in model)\n",
          built.mech->nlimb);
}

/* Every command's stdout (JSON, summaries, help) is checked once flushed
 * and closed: "> /dev/full" is an error with the reason, exit 1. */
static int finish(const char *cmd, int rc)
{
  if (prru_cli_close_stdout(cmd)) return rc == 0 ? 1 : rc;
  return rc;
}

/* argv[i] is --model FILE or --model=FILE: its value (NULL when none
 * follows) and how many arguments it spans; 0 when argv[i] is no --model. */
static int model_option(int argc, char **argv, int i, const char **file)
{
  if (strcmp(argv[i], "--model") == 0) {
    *file = i + 1 < argc ? argv[i + 1] : NULL;
    return *file ? 2 : 1;
  }
  if (strncmp(argv[i], "--model=", 8) == 0) {
    *file = argv[i] + 8;
    return 1;
  }
  return 0;
}

static void version_usage(FILE *f)
{
  fprintf(f, "usage: prru version   (the same: prru --version, prru COMMAND --version)\n"
             "The program's version, then the model it computes with, a line each:\n"
             "  prru VERSION\n"
             "  model: NAME\n"
             "  model file: FILE\n"
             "  model format: 1 or 2\n"
             "  model actuators: N\n"
             "  model sha256: HASH (of FILE's bytes)\n"
             "  model kernels: specialised or parameter (see prru --help)\n"
             "The model is the built-in one, or --model FILE / PRRU_MODEL.\n");
}

/* Takes the global --model out of argv (before the command or anywhere
 * among its arguments: every command's options are its own, so "--model"
 * there is never another option's value unless written --opt=--model),
 * argc updated. 0, or 2 after the reason. */
static int take_model_option(int *argc, char **argv, const char **file)
{
  int n = 1;
  *file = NULL;
  for (int i = 1; i < *argc;) {
    const char *f = NULL;
    const int k = model_option(*argc, argv, i, &f);
    if (k == 0) {
      argv[n++] = argv[i++];
      continue;
    }
    if (!f || !*f) {
      fprintf(stderr, "prru: --model needs a model file (--model FILE; see prru --help)\n");
      return 2;
    }
    if (*file) {
      fprintf(stderr, "prru: --model given twice ('%s' and '%s')\n", *file, f);
      return 2;
    }
    *file = f;
    i += k;
  }
  *argc = n;
  argv[n] = NULL;
  return 0;
}

/* The model of --model, else $PRRU_MODEL, else the built-in one: loaded
 * once, before any command runs. 0, or the exit status after the reason. */
static int load_model(const char *file)
{
  if (!file) file = getenv("PRRU_MODEL");
  if (!file || !*file) return 0;
  return prru_cli_load_model(file);
}

static int run(int argc, char **argv)
{
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
    usage(stdout);
    return finish("help", 0);
  }
  if (strcmp(argv[1], "version") == 0 && argc == 3 &&
      (strcmp(argv[2], "--help") == 0 || strcmp(argv[2], "-h") == 0)) {
    version_usage(stdout); /* every command prru --help lists answers --help */
    return finish("version", 0);
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

int main(int argc, char **argv)
{
  const char *file;
  int rc = take_model_option(&argc, argv, &file);
  if (rc == 0) rc = load_model(file);
  if (rc == 0) rc = run(argc, argv);
  prru_cli_free_model();
  return rc;
}
