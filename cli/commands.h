/* Sub-commands of the `prru` tool. Each takes the arguments after its name
 * and returns the process exit status: 0 success, 1 failure (I/O, a state
 * out of the workspace, no convergence), 2 usage error, 130 interrupted. */
#ifndef PRRU_CLI_COMMANDS_H
#define PRRU_CLI_COMMANDS_H

#include <stdio.h>

int prru_cmd_eval(int argc, char **argv);
int prru_cmd_simulate(int argc, char **argv);
int prru_cmd_ik(int argc, char **argv);
int prru_cmd_fk(int argc, char **argv);
int prru_cmd_id(int argc, char **argv);
int prru_cmd_paper(int argc, char **argv);
int prru_cmd_dme(int argc, char **argv);
int prru_cmd_map(int argc, char **argv);

/* The fig. 7 part of `prru paper`: map CSV, surface/contour/ellipse PNGs in
 * outdir, summary lines appended to summary. Returns an exit status. */
int prru_paper_fig7(const char *outdir, FILE *summary);

/* Shared helpers (cli/util.c). */
void prru_cli_error(const char *cmd, const char *fmt, ...);
/* Status code of a runtime call turned into an exit status (1, or 130 when
 * interrupted). */
int prru_cli_exit_for(int status);

#endif
