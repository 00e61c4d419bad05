/* Sub-commands of the `prru` tool. Each takes the arguments after its name
 * and returns the process exit status: 0 success, 1 failure (I/O, a state
 * out of the workspace, no convergence), 2 usage error, 130 interrupted. */
#ifndef PRRU_CLI_COMMANDS_H
#define PRRU_CLI_COMMANDS_H

#include <signal.h>
#include <stdio.h>

#include "prru.h"

/* The program's version, the CMake project version (cli/CMakeLists.txt). */
#ifndef PRRU_VERSION
#error "PRRU_VERSION (the program version string) must be defined by the build"
#endif

/* The CLI writes q as q1,q2,q3 (names, help texts): the 3-PRRU's three
 * coordinates. Everything else sized by the mechanism uses prru_mech and
 * the PRRU_N* macros. */
typedef char prru_cli_nq_is_3[PRRU_NQ == 3 ? 1 : -1];

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
/* `prru --version`: program version and the model's name, file, format
 * and SHA-256, one per line. */
void prru_cli_print_version(FILE *f);
/* 1 when the kernels were generated from the paper's model file
 * (models/3prru_paper.json, by its SHA-256), 0 otherwise. */
int prru_cli_is_paper_model(void);
/* Model identity in outputs. JSON: the member
 * "model": {"name": .., "file": .., "sha256": ..} (no separator around it);
 * CSV: the first line "# prru VERSION model NAME (FILE, sha256 HASH)". */
void prru_cli_json_model(FILE *f);
void prru_cli_csv_comment(FILE *f);
/* "NAME (FILE, sha256 HASH)", control characters replaced by '?'. */
const char *prru_cli_model_id(void);
/* JSON string literal with escapes. */
void prru_cli_json_string(FILE *f, const char *s);
/* prefix1<sep>prefix2<sep>...prefixN into buf ("f1,f2,f3"); returns buf. */
const char *prru_cli_names(char *buf, size_t len, const char *prefix, int n, const char *sep);
void prru_cli_error(const char *cmd, const char *fmt, ...);
/* Status code of a runtime call turned into an exit status (1, or 130 when
 * interrupted). */
int prru_cli_exit_for(int status);

/* Options of one sub-command: `--name value` or `--name=value`; flags take
 * no value. Unknown options, missing values, repeats and positional
 * arguments are usage errors. */
typedef struct {
  const char *name;   /* without the leading "--" */
  int takes_value;
  const char **value; /* set when given (takes_value) */
  int *flag;          /* set to 1 when given (flags) */
} prru_cli_option;
/* 0 on success, else 2 after printing the reason and `prru CMD --help`. */
int prru_cli_parse(const char *cmd, int argc, char **argv, const prru_cli_option *opts,
                   int nopts);
/* Exactly n comma-separated finite numbers for option `name`: 0, else 2
 * after printing what was wrong. */
int prru_cli_numbers(const char *cmd, const char *name, const char *text, double *out, int n);
/* One finite number, 0 or 2. */
int prru_cli_number(const char *cmd, const char *name, const char *text, double *out);
/* Writes a JSON number (%.17g) or null when not finite. */
void prru_cli_json_number(FILE *f, double v);
/* JSON array of n numbers; rows > 1 writes n/rows rows as nested arrays. */
void prru_cli_json_array(FILE *f, const double *v, int n, int rows);
/* Set by SIGINT once prru_cli_catch_sigint() ran. */
extern volatile sig_atomic_t prru_cli_interrupted;
void prru_cli_catch_sigint(void);

/* CSV of simulation samples: the model comment line, then the header
 * t,q1..3,qd1..3,d1..dNACT, the PRRU_NLAMBDA reactions (named by
 * prru_mech.lambda_labels, when computed), qdd1..3, fd1..fdNACT, fp1..3,
 * mp1..3, T, V. */
typedef struct {
  FILE *f;
  const prru_load_schedule *loads;
  int reactions;
  long rows;
} prru_cli_csv;
/* The comment line and the header row. */
void prru_cli_csv_header(prru_cli_csv *c);
/* prru_sample_fn: writes one row; non-zero on a write error. */
int prru_cli_csv_row(const prru_sample *s, void *ctx);
/* Writes script to dir/script_name and runs gnuplot there; 0 or 1 with a
 * message (gnuplot missing or failing). */
int prru_cli_gnuplot(const char *dir, const char *script_name, const char *script);
/* Writes the line model = '<model name>' (a gnuplot string for titles). */
void prru_cli_gnuplot_model(FILE *g);

#endif
