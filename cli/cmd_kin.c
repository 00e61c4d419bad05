/* prru ik, fk and id: kinematics both ways and inverse dynamics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru.h"

static const char ik_help[] =
    "usage: prru ik --q q1,q2,q3\n"
    "Prints JSON with the actuator displacements d (m, slider heights) and J_d =\n"
    "dd/dq. Exit 1 when q is unreachable.\n";

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
  double q[3];
  if (!qs) {
    prru_cli_error("ik", "--q is required (see 'prru ik --help')");
    return 2;
  }
  if (prru_cli_numbers("ik", "q", qs, q, 3)) return 2;
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
  printf("{\"q\": ");
  prru_cli_json_array(stdout, q, 3, 1);
  printf(", \"d\": ");
  prru_cli_json_array(stdout, d->d, 3, 1);
  printf(", \"Jd\": ");
  prru_cli_json_array(stdout, d->Jd, 9, 1);
  printf(", \"Jd_rcond\": ");
  prru_cli_json_number(stdout, rcond);
  printf(", \"singular\": %s}\n", st == PRRU_ESINGULAR ? "true" : "false");
  free(d);
  return ferror(stdout) ? 1 : 0;
}

static const char fk_help[] =
    "usage: prru fk --d d1,d2,d3 [--seed q1,q2,q3]\n"
    "Solves d(q) = d for q by Newton's method (GSL hybridsj with J_d) from the\n"
    "seed (default: q1 = q2 = 0 and the height that matches the mean of d).\n"
    "Prints JSON with q and the residual. Exit 1 when d is out of reach or the\n"
    "iteration meets a singularity.\n";

int prru_cmd_fk(int argc, char **argv)
{
  const char *ds = NULL, *seeds = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"d", 1, &ds, NULL}, {"seed", 1, &seeds, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("fk", argc, argv, opts, 3)) return 2;
  if (help) {
    fputs(fk_help, stdout);
    return 0;
  }
  double act[3], seed[3], q[3];
  if (!ds) {
    prru_cli_error("fk", "--d is required (see 'prru fk --help')");
    return 2;
  }
  if (prru_cli_numbers("fk", "d", ds, act, 3)) return 2;
  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  if (seeds) {
    if (prru_cli_numbers("fk", "seed", seeds, seed, 3)) { free(d); return 2; }
  } else {
    /* At q1 = q2 = 0 every d_i = q3 + d_i(0, 0, 0). */
    double zero[3] = {0, 0, 0}, d0[3];
    prru_ik(zero, d0);
    seed[0] = seed[1] = 0.0;
    seed[2] = (act[0] + act[1] + act[2] - d0[0] - d0[1] - d0[2]) / 3.0;
  }
  int st = prru_forward_kinematics(&m, d, act, seed, q);
  if (st != PRRU_OK) {
    prru_cli_error("fk", "d = (%.17g, %.17g, %.17g) from seed (%.6g, %.6g, %.6g): %s%s", act[0],
                   act[1], act[2], seed[0], seed[1], seed[2], prru_strerror(st),
                   st == PRRU_ENOCONV ? " (d out of reach, or a singularity near the path; try another --seed)" : "");
    free(d);
    return 1;
  }
  double dq[3], res = 0;
  prru_ik(q, dq);
  for (int i = 0; i < 3; i++) res = fmax(res, fabs(dq[i] - act[i]));
  printf("{\"d\": ");
  prru_cli_json_array(stdout, act, 3, 1);
  printf(", \"q\": ");
  prru_cli_json_array(stdout, q, 3, 1);
  printf(", \"residual\": ");
  prru_cli_json_number(stdout, res);
  printf("}\n");
  free(d);
  return ferror(stdout) ? 1 : 0;
}

static const char id_help[] =
    "usage: prru id --traj FILE.csv [--out FILE.csv]\n"
    "Inverse dynamics along a trajectory: FILE has a header row and columns\n"
    "t, q1..q3, qd1..qd3, qdd1..qdd3 (any order, other columns ignored) and\n"
    "optionally fp1..fp3, mp1..mp3 (platform loads, default 0); `prru simulate`\n"
    "output qualifies. Writes t,fd1,fd2,fd3 (N) to --out or stdout. A row where\n"
    "the pose is unreachable or J_d singular stops with exit 1; the rows before\n"
    "it are kept. An unreadable or malformed FILE exits 2.\n";

int prru_cmd_id(int argc, char **argv)
{
  const char *traj = NULL, *out = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"traj", 1, &traj, NULL}, {"out", 1, &out, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("id", argc, argv, opts, 3)) return 2;
  if (help) {
    fputs(id_help, stdout);
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
  FILE *f = out ? fopen(out, "w") : stdout;
  if (!f) {
    prru_cli_error("id", "--out %s: cannot open for writing", out);
    prru_table_free(&t);
    return 1;
  }
  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  st = d ? PRRU_OK : PRRU_ENOMEM;
  fprintf(f, "t,fd1,fd2,fd3\n");
  for (int i = 0; st == PRRU_OK && i < t.nrows; i++) {
    const double *row = t.data + (size_t)i * (size_t)t.ncols;
    double v[16], fd[3];
    for (int k = 0; k < 16; k++) v[k] = col[k] < 0 ? 0.0 : row[col[k]];
    prru_loads l;
    memset(&l, 0, sizeof l);
    memcpy(l.fp, v + 10, sizeof l.fp);
    memcpy(l.mp, v + 13, sizeof l.mp);
    st = prru_inverse_dynamics(&m, d, v + 1, v + 4, v + 7, &l, fd);
    if (st != PRRU_OK) {
      prru_cli_error("id", "%s: data row %d (t = %g): %s; %d rows written", traj, i + 1, v[0],
                     prru_strerror(st), i);
      break;
    }
    fprintf(f, "%.17g,%.17g,%.17g,%.17g\n", v[0], fd[0], fd[1], fd[2]);
  }
  int bad_io = ferror(f) != 0;
  if (f != stdout) bad_io |= fclose(f) != 0;
  if (bad_io && st == PRRU_OK) {
    prru_cli_error("id", "%s: write error", out ? out : "stdout");
    st = PRRU_EIO;
  }
  free(d);
  prru_table_free(&t);
  return st == PRRU_OK ? 0 : prru_cli_exit_for(st);
}
