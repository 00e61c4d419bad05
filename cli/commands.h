/* Sub-commands of the `prru` tool. Each takes the arguments after its name
 * and returns the process exit status: 0 success, 1 failure (I/O, a state
 * out of the workspace, no convergence), 2 usage error, 128 + the signal
 * number when stopped by SIGINT (130), SIGTERM (143) or SIGHUP (129). */
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
 * coordinates. Everything else sized by the mechanism comes from the
 * model a command computes with (prru_cli_model()->mech: its counts,
 * names and numbers), so that one build serves every model the library
 * loads; fixed arrays have the public maxima of prru_sizes.h. */

int prru_cmd_eval(int argc, char **argv);
int prru_cmd_gen(int argc, char **argv);
int prru_cmd_linearize(int argc, char **argv);
int prru_cmd_simulate(int argc, char **argv);
int prru_cmd_ik(int argc, char **argv);
int prru_cmd_fk(int argc, char **argv);
int prru_cmd_id(int argc, char **argv);
int prru_cmd_excite(int argc, char **argv);
int prru_cmd_measure(int argc, char **argv);
int prru_cmd_identify(int argc, char **argv);
int prru_cmd_paper(int argc, char **argv);
int prru_cmd_dme(int argc, char **argv);
int prru_cmd_map(int argc, char **argv);
int prru_cmd_plot(int argc, char **argv);
int prru_cmd_animate(int argc, char **argv);
int prru_cmd_view(int argc, char **argv);
int prru_cmd_traj(int argc, char **argv);
int prru_cmd_track(int argc, char **argv);
int prru_cmd_optimize(int argc, char **argv);
int prru_cmd_sensitivity(int argc, char **argv);
int prru_cmd_merge(int argc, char **argv);

/* Shared helpers (cli/util.c). */
/* The model every command computes with: the one main loaded from
 * --model FILE or $PRRU_MODEL (prru_cli_load_model), else the built-in
 * one (prru_model_default). A command that changes settings copies it
 * (prru_model m = *prru_cli_model()): the copy shares the loaded storage,
 * which lives until prru_cli_free_model at exit. */
const prru_model *prru_cli_model(void);
/* Loads path as the current model: 0, or 2 (1 out of memory) after
 * "prru: FILE: key: reason" (the library's message) on stderr, the
 * current model unchanged. */
int prru_cli_load_model(const char *path);
/* Frees a loaded model (the built-in one again). */
void prru_cli_free_model(void);
/* `prru --version`: program version and the model's name, file, format,
 * number of actuators, SHA-256 and kernels, one per line. */
void prru_cli_print_version(FILE *f);
/* 1 when the kernels were generated from the paper's model file
 * (models/3prru_paper.json, by its SHA-256), 0 otherwise. */
int prru_cli_is_paper_model(void);
/* The dimensions of null(J_d^T), actuator forces that move nothing (an
 * internal preload), and of null(Q), reaction coordinates no motion or
 * load determines, for the model m: 0 and 0 with three limbs, 1 and 1
 * with four (docs/model.md section 13). */
int prru_cli_npreload(const prru_model *m);
int prru_cli_nreaction_null(const prru_model *m);
/* The paper's section 4.3 scenario as the CLI runs it (`prru paper`,
 * `prru simulate --scenario paper`): prru_scenario_paper, and on a model
 * with redundant actuators every actuator beyond the third gets the third's
 * force (limb 4 mirrors limb 3): fd = (50, 40, 25, 25) N. */
/* The fd list of the paper scenario as text, "50, 40, 25[, 25]". */
const char *prru_cli_paper_fd_text(void);
/* The model's length scale L, the mean upper-link length (m), as the
 * runtime uses it for its tolerances (prru_model). */
/* Model identity in outputs. JSON: the member
 * "model": {"name": .., "file": .., "sha256": .., "kernels": ..} (no
 * separator around it); CSV: the first line
 * "# prru VERSION model NAME (FILE, sha256 HASH, KERNELS kernels)"
 * (prru_model_identity; KERNELS "specialised" or "parameter"). */
void prru_cli_json_model(FILE *f);
void prru_cli_csv_comment(FILE *f);
/* "NAME (FILE, sha256 HASH, KERNELS kernels)" of the current model,
 * control characters replaced by '?'. */
const char *prru_cli_model_id(void);
/* JSON string literal with escapes. */
void prru_cli_json_string(FILE *f, const char *s);
/* prefix1<sep>prefix2<sep>...prefixN into buf ("f1,f2,f3"); returns buf. */
const char *prru_cli_names(char *buf, size_t len, const char *prefix, int n, const char *sep);
void prru_cli_error(const char *cmd, const char *fmt, ...);
/* "(a, b, c)": each number with the fewest digits that read back as it
 * (0.2, not 0.20000000000000001), for messages that name a state; buf of
 * len bytes (32 n suffices). */
const char *prru_cli_vec(char *buf, size_t len, const double *v, int n);
/* Status code of a runtime call turned into an exit status: 1, or 128 +
 * the signal caught (130 when none was recorded) for PRRU_EINTERRUPTED. */
int prru_cli_exit_for(int status);
/* The exit status of a run stopped by the signal in prru_cli_interrupted. */
int prru_cli_exit_interrupted(void);
/* "SIGINT", "SIGTERM", "SIGHUP" for prru_cli_interrupted, "a signal" else. */
const char *prru_cli_signal_name(void);
/* After reading the input of option opt (path) with the signals caught:
 * 0, or, when a signal came meanwhile, the exit status after "interrupted
 * (SIGINT) while reading --opt PATH; nothing written". */
int prru_cli_read_interrupted(const char *cmd, const char *opt, const char *path);
/* At exit: flushes and closes stdout and reports a write error on it
 * (with the reason): 0, or 1 after "prru CMD: stdout: write error: REASON". */
int prru_cli_close_stdout(const char *cmd);

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
/* The same for a command that takes one file argument besides its options
 * (plot, animate): *file is it, or NULL when none was given; a second one
 * is a usage error. */
int prru_cli_parse_file(const char *cmd, int argc, char **argv, const prru_cli_option *opts,
                        int nopts, const char **file);
/* Exactly n comma-separated finite numbers for option `name`: 0, else 2
 * after printing what was wrong. */
int prru_cli_numbers(const char *cmd, const char *name, const char *text, double *out, int n);

/* The drives' limits of a run (spec 13): the model's unless overridden.
 * One set of options for every command that plans, tracks, excites or
 * optimises: --no-limits, --force-max F|F1,..., --speed-max V|V1,...,
 * --stroke LO,HI|LO1,HI1,...; alias: the command's older name of
 * --force-max (--fd-max, --fmax; NULL: none). */
typedef struct {
  const char *force_max, *alias, *speed_max, *stroke;
  int none;
} prru_cli_limit_args;
/* The entries of a command's option table (the alias's, {NAME, 1,
 * &a.alias, NULL}, beside them where the command has one). */
#define PRRU_CLI_LIMIT_OPTIONS(a)                                                                              \
  {"force-max", 1, &(a).force_max, NULL}, {"speed-max", 1, &(a).speed_max, NULL},                             \
      {"stroke", 1, &(a).stroke, NULL}, {"no-limits", 0, NULL, &(a).none}
/* --units rail|motor (NULL: rail): *motor = 1 for motor units, *current
 * = 1 when the model also gives torque_constant. 0, or 2 after the
 * message (an unknown unit; motor units without the model's lead). */
int prru_cli_units(const char *cmd, const char *units, int *motor, int *current);
/* prru_limits_for_run with the options: 0, or 2 after the message naming
 * the option (also when --force-max and its alias are both given). */
int prru_cli_limits(const char *cmd, const char *alias_name, const prru_cli_limit_args *a, prru_limits *out);
/* 1 when paths a and b name the same existing file, compared by device
 * and inode (so "f", "./f", a hard or symbolic link to f alike); 0 when
 * either is NULL, "-" (stdout) or does not exist. */
int prru_cli_same_file(const char *a, const char *b);
/* 0, or 2 after "--IN_OPT IN and --OUT_OPT OUT are the same file ..." when
 * the output would replace the input (prru_cli_same_file). */
int prru_cli_refuse_same_file(const char *cmd, const char *in_opt, const char *in,
                              const char *out_opt, const char *out);
/* One finite number, 0 or 2. */
int prru_cli_number(const char *cmd, const char *name, const char *text, double *out);
/* Writes a JSON number (%.17g) or null when not finite. */
void prru_cli_json_number(FILE *f, double v);
/* JSON array of n numbers (a vector). */
void prru_cli_json_array(FILE *f, const double *v, int n);
/* Every matrix in the CLI's JSON: a list of rows, [[a11, a12, ..], [a21,
 * ..], ..], from the row-major rows x cols array v (even for one row). */
void prru_cli_json_matrix(FILE *f, const double *v, int rows, int cols);
/* The number of the last SIGINT, SIGTERM or SIGHUP once
 * prru_cli_catch_signals() ran, 0 before: every long-running command
 * (simulate, id, map, paper) passes it to the runtime as the interrupt flag
 * and polls it between rows. The handlers only set it and stay installed
 * (sigaction, no SA_RESETHAND), so a second signal during the clean-up
 * changes nothing; SA_RESTART is set so that a signal never turns into a
 * stdio write error (EINTR); the loops that wait poll instead, and a
 * write blocked on a full pipe completes its rows first. A signal that
 * was ignored when prru started (nohup; SIGINT in a background job of a
 * shell without job control) stays ignored, as in the GNU tools. */
extern volatile sig_atomic_t prru_cli_interrupted;
/* How many of those signals arrived: a clean-up that takes a while (map
 * writing the rows it computed) stops early at a second one. */
extern volatile sig_atomic_t prru_cli_signal_count;
void prru_cli_catch_signals(void);

/* An output file that is never left half-written. Text goes to a buffer
 * (prru_cli_out_printf) and becomes part of the file only when the line is
 * complete (prru_cli_out_line, prru_cli_out_row); whole lines are written
 * with a loop that retries after EINTR and short writes. A regular file
 * (or a new one) is built as FILE.partial-XXXXXX in its directory and
 * renamed onto FILE by prru_cli_out_close(o, 1): until then FILE keeps its
 * old contents, and prru_cli_out_close(o, 0) (nothing worth keeping)
 * removes the partial file. stdout ("-" or NULL), devices, FIFOs and
 * symbolic links are written in place. The first write error is kept
 * (errno in err); every later call is then a no-op. */
typedef struct {
  const char *cmd;    /* for messages */
  const char *name;   /* the path as given, or "stdout" */
  char *final_path, *tmp_path; /* rename target and partial file, or NULL */
  int fd;
  int truncate_first; /* in place on a regular file: truncate at the first write */
  int err;            /* errno of the first failure, 0 */
  char *buf;
  size_t len, whole, cap; /* bytes buffered, of them complete lines, allocated */
  long rows;
  double flushed_at;  /* CLOCK_MONOTONIC seconds of the last flush */
} prru_cli_out;
/* The columns of motor units after a row's others: ",tau1..,i1.." names
 * and the values for rail forces fd (prru_model_motor_units); nothing
 * when !motor. */
void prru_cli_out_motor_names(prru_cli_out *o, int motor, int current);
void prru_cli_out_motor(prru_cli_out *o, const prru_model *m, const double fd[], int motor, int current);
/* Opens (checks that it can be written: the directory exists and takes a
 * new file); 0, or 1 after a message with the reason. */
int prru_cli_out_open(prru_cli_out *o, const char *cmd, const char *path);
void prru_cli_out_printf(prru_cli_out *o, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* n raw bytes (a picture): part of the file at the next
 * prru_cli_out_line. */
void prru_cli_out_write(prru_cli_out *o, const void *data, size_t n);
/* ",%.17g" for each of n numbers. */
void prru_cli_out_numbers(prru_cli_out *o, const double *v, int n);
/* s as a JSON string literal: quotes, backslashes and control characters
 * escaped, a byte that is not well-formed UTF-8 written as U+FFFD (JSON
 * text is UTF-8); also safe inside an HTML <script> (prru view): '<', '>',
 * '&' and U+2028/2029 as \u escapes, so no "</script>" or "<!--" can end
 * or change the element (every JSON reader decodes them back). */
void prru_cli_out_json_string(prru_cli_out *o, const char *s);
/* Ends a complete line that is not a data row (comment, header); 0 or -1. */
int prru_cli_out_line(prru_cli_out *o);
/* Ends a data row (counted in rows); flushes at 64 kB or 0.2 s after the
 * last flush. 0 or -1 after a write error. */
int prru_cli_out_row(prru_cli_out *o);
/* A data row of a motion CSV (cli/util.c): t, q, qd, qdd (3 numbers
 * each), d and v (nact each, of the current model: the actuators'
 * positions and a quantity per actuator, their forces or rates);
 * prru_cli_out_row's result. */
int prru_cli_out_motion_row(prru_cli_out *o, double t, const double q[3], const double qd[3],
                            const double qdd[3], const double d[], const double v[]);
int prru_cli_out_flush(prru_cli_out *o);
/* The model comment line, as prru_cli_csv_comment. */
void prru_cli_out_comment(prru_cli_out *o);
/* The comment line "# TEXT" (a whole line), TEXT formatted as by printf
 * with every control character in it (a line break) written as '?': user
 * text in it (a path) never starts a data row. */
void prru_cli_out_comment_line(prru_cli_out *o, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* keep = 1: writes the rest, syncs and renames onto the target; keep = 0:
 * drops what is unwritten and removes the partial file (the target keeps
 * its old contents). 0, or 1 after "prru CMD: FILE: write error: REASON"
 * when a write, sync, close or rename failed (the partial file removed). */
int prru_cli_out_close(prru_cli_out *o, int keep);
/* Closes o after a run that ended with status st, why saying why when it
 * is not PRRU_OK: the rows are kept when there are some or the run
 * succeeded, and a stop is reported with what was kept (the rows before
 * it, or nothing and the old file unchanged). The command's exit status. */
int prru_cli_out_finish(prru_cli_out *o, int st, const char *why);

/* CSV of simulation samples: the model comment line, then the header
 * t,q1..3,qd1..3,d1..dN, the model's nlambda reactions (named by its
 * lambda_labels, when computed), qdd1..3, fd1..fdN, fp1..3, mp1..3, T, V
 * (N = nact, of the current model). */
typedef struct {
  prru_cli_out *out;
  const prru_load_schedule *loads;
  int reactions;
} prru_cli_csv;
/* The comment line and the header row. */
void prru_cli_csv_header(prru_cli_csv *c);
/* prru_sample_fn: writes one row; PRRU_EIO (non-zero: the run stops) on a
 * write error, whose errno stays in c->out->err: prru_simulate reports
 * the stop as PRRU_EINTERRUPTED, and the caller, seeing out->err, reports
 * an I/O error instead. */
int prru_cli_csv_row(const prru_sample *s, void *ctx);

#endif
