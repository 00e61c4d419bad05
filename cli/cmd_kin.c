/* prru ik, fk and id: kinematics both ways and inverse dynamics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru.h"

static const char ik_help[] =
    "usage: prru ik --q q1,q2,q3\n"
    "Prints JSON with model (name, file, sha256), q, the actuator displacements d\n"
    "(m, slider heights), J_d = dd/dq (actuators x q, row-major), its reciprocal\n"
    "condition number and whether J_d is singular there. Exit 1 when q is\n"
    "unreachable.\n";

int prru_cmd_ik(int argc, char **argv)
{
  const char *qs = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("ik", argc, argv, opts, 2)) return 2;
  if (help) {
    fputs(ik_help, stdout);
    return 0;
  }
  double q[PRRU_NQ];
  if (!qs) {
    prru_cli_error("ik", "--q is required (see 'prru ik --help')");
    return 2;
  }
  if (prru_cli_numbers("ik", "q", qs, q, PRRU_NQ)) return 2;
  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  double rcond;
  int st = prru_check_regular(&m, d, q, &rcond);
  if (st != PRRU_OK && st != PRRU_ESINGULAR) {
    prru_cli_error("ik", "q = (%.17g, %.17g, %.17g): %s", q[0], q[1], q[2], prru_strerror(st));
    free(d);
    return 1;
  }
  putchar('{');
  prru_cli_json_model(stdout);
  printf(",\n \"q\": ");
  prru_cli_json_array(stdout, q, PRRU_NQ, 1);
  printf(", \"d\": ");
  prru_cli_json_array(stdout, d->d, PRRU_NACT, 1);
  printf(", \"Jd\": ");
  prru_cli_json_array(stdout, d->Jd, PRRU_NACT * PRRU_NQ, 1);
  printf(", \"Jd_rcond\": ");
  prru_cli_json_number(stdout, rcond);
  printf(", \"singular\": %s}\n", st == PRRU_ESINGULAR ? "true" : "false");
  free(d);
  return ferror(stdout) ? 1 : 0;
}

/* %s: the --d names. */
static const char fk_help[] =
    "usage: prru fk --d %s [--seed q1,q2,q3]\n"
    "Solves d(q) = d for q by Newton's method (GSL hybridsj with J_d) from the\n"
    "seed (default: q1 = q2 = 0 and the height that matches the mean of d).\n"
    "Prints JSON with model (name, file, sha256), d, q and the residual\n"
    "max |d(q) - d| (m). Exit 1 when d is out of reach or the iteration meets a\n"
    "singularity.\n";

int prru_cmd_fk(int argc, char **argv)
{
  const char *ds = NULL, *seeds = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"d", 1, &ds, NULL}, {"seed", 1, &seeds, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("fk", argc, argv, opts, 3)) return 2;
  if (help) {
    char names[256];
    printf(fk_help, prru_cli_names(names, sizeof names, "d", PRRU_NACT, ","));
    return 0;
  }
  double act[PRRU_NACT], seed[PRRU_NQ], q[PRRU_NQ];
  if (!ds) {
    prru_cli_error("fk", "--d is required (see 'prru fk --help')");
    return 2;
  }
  if (prru_cli_numbers("fk", "d", ds, act, PRRU_NACT)) return 2;
  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  if (seeds) {
    if (prru_cli_numbers("fk", "seed", seeds, seed, PRRU_NQ)) { free(d); return 2; }
  } else {
    /* At q1 = q2 = 0 every d_i = q3 + d_i(0, 0, 0). */
    double zero[PRRU_NQ] = {0, 0, 0}, d0[PRRU_NACT], sum = 0.0;
    prru_ik(zero, d0);
    for (int i = 0; i < PRRU_NACT; i++) sum += act[i] - d0[i];
    seed[0] = seed[1] = 0.0;
    seed[2] = sum / PRRU_NACT;
  }
  int st = prru_forward_kinematics(&m, d, act, seed, q);
  if (st != PRRU_OK) {
    char dtext[64 * PRRU_NACT];
    size_t used = 0;
    for (int i = 0; i < PRRU_NACT; i++)
      used += (size_t)snprintf(dtext + used, sizeof dtext - used, "%s%.17g", i ? ", " : "", act[i]);
    prru_cli_error("fk", "d = (%s) from seed (%.6g, %.6g, %.6g): %s%s", dtext, seed[0], seed[1],
                   seed[2], prru_strerror(st),
                   st == PRRU_ENOCONV ? " (d out of reach, or a singularity near the path; try another --seed)" : "");
    free(d);
    return 1;
  }
  double dq[PRRU_NACT], res = 0;
  prru_ik(q, dq);
  for (int i = 0; i < PRRU_NACT; i++) res = fmax(res, fabs(dq[i] - act[i]));
  putchar('{');
  prru_cli_json_model(stdout);
  printf(",\n \"d\": ");
  prru_cli_json_array(stdout, act, PRRU_NACT, 1);
  printf(", \"q\": ");
  prru_cli_json_array(stdout, q, PRRU_NQ, 1);
  printf(", \"residual\": ");
  prru_cli_json_number(stdout, res);
  printf("}\n");
  free(d);
  return ferror(stdout) ? 1 : 0;
}

/* %s: the output's columns. */
static const char id_help[] =
    "usage: prru id --traj FILE.csv [--out FILE.csv|-]\n"
    "Inverse dynamics along a trajectory: FILE has a header row and columns\n"
    "t, q1..q3, qd1..qd3, qdd1..qdd3 (any order, other columns ignored) and\n"
    "optionally fp1..fp3, mp1..mp3 (platform loads, default 0); lines starting\n"
    "with '#' are skipped, so `prru simulate` output qualifies. Writes the model\n"
    "line (# prru ... model ...) and t,%s (N) to --out or stdout (also\n"
    "--out -); --out FILE keeps its old contents until the first row is ready\n"
    "(it is built as FILE.partial-XXXXXX and renamed). A row where the pose is\n"
    "unreachable or J_d singular stops with exit 1, SIGINT/SIGTERM/SIGHUP with\n"
    "exit 130/143/129; the rows before it are kept. A write error exits 1 with\n"
    "the reason; an unreadable or malformed FILE exits 2.\n";

int prru_cmd_id(int argc, char **argv)
{
  const char *traj = NULL, *out = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"traj", 1, &traj, NULL}, {"out", 1, &out, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("id", argc, argv, opts, 3)) return 2;
  char fd_names[256];
  prru_cli_names(fd_names, sizeof fd_names, "fd", PRRU_NACT, ",");
  if (help) {
    printf(id_help, fd_names);
    return 0;
  }
  if (!traj) {
    prru_cli_error("id", "--traj is required (see 'prru id --help')");
    return 2;
  }
  static const char *const need[10] = {"t", "q1", "q2", "q3", "qd1", "qd2", "qd3", "qdd1", "qdd2", "qdd3"};
  static const char *const opt[6] = {"fp1", "fp2", "fp3", "mp1", "mp2", "mp3"};
  char msg[512];
  prru_table t;
  int st = prru_table_read(&t, traj, msg, sizeof msg);
  if (st != PRRU_OK) {
    prru_cli_error("id", "--traj %s", msg);
    return 2;
  }
  int col[16];
  for (int k = 0; k < 10; k++)
    if ((col[k] = prru_table_column(&t, need[k])) < 0) {
      prru_cli_error("id", "--traj %s: missing column '%s' (need t, q1..3, qd1..3, qdd1..3)", traj, need[k]);
      prru_table_free(&t);
      return 2;
    }
  for (int k = 0; k < 6; k++) col[10 + k] = prru_table_column(&t, opt[k]);
  prru_cli_catch_signals();
  prru_cli_out o;
  if (prru_cli_out_open(&o, "id", out)) {
    prru_table_free(&t);
    return 1;
  }
  const char *name = o.name;
  int in_place = o.tmp_path == NULL;
  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  st = d ? PRRU_OK : PRRU_ENOMEM;
  prru_cli_out_comment(&o);
  prru_cli_out_printf(&o, "t,%s\n", fd_names);
  prru_cli_out_line(&o);
  char why[700] = "";
  for (int i = 0; st == PRRU_OK && !o.err && i < t.nrows; i++) {
    if (prru_cli_interrupted) {
      st = PRRU_EINTERRUPTED;
      snprintf(why, sizeof why, "interrupted (%s) before data row %d", prru_cli_signal_name(), i + 1);
      break;
    }
    const double *row = t.data + (size_t)i * (size_t)t.ncols;
    double v[16], fd[PRRU_NACT];
    for (int k = 0; k < 16; k++) v[k] = col[k] < 0 ? 0.0 : row[col[k]];
    prru_loads l;
    memset(&l, 0, sizeof l);
    memcpy(l.fp, v + 10, sizeof l.fp);
    memcpy(l.mp, v + 13, sizeof l.mp);
    st = prru_inverse_dynamics(&m, d, v + 1, v + 4, v + 7, &l, fd);
    if (st != PRRU_OK) {
      snprintf(why, sizeof why, "%s: data row %d (t = %g): %s", traj, i + 1, v[0], prru_strerror(st));
      break;
    }
    prru_cli_out_printf(&o, "%.17g", v[0]);
    prru_cli_out_numbers(&o, fd, PRRU_NACT);
    prru_cli_out_printf(&o, "\n");
    prru_cli_out_row(&o);
  }
  long rows = o.rows;
  int io = o.err != 0;
  free(d);
  prru_table_free(&t);
  /* The rows before a stop are kept; nothing (and the old file) when the
   * first row already failed or the output could not be written. */
  if (prru_cli_out_close(&o, !io && (rows > 0 || st == PRRU_OK))) return 1;
  if (st != PRRU_OK) {
    if (rows > 0)
      prru_cli_error("id", "%s; %ld rows written to %s", why, rows, name);
    else
      prru_cli_error("id", "%s; nothing written%s%s%s", why, in_place ? "" : ", ",
                     in_place ? "" : name, in_place ? "" : " is not changed");
  }
  return st == PRRU_OK ? 0 : prru_cli_exit_for(st);
}
