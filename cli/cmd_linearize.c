/* prru linearize: the closed-form derivatives of forward dynamics at one
 * state and the state-space pair (A, B), with --dt the zero-order-hold
 * discrete pair, as JSON. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "prru.h"
#include "prru_linearize.h"

/* %s: the --fd names; %d, %d: the model's actuators (B's and dqdd_dfd's columns). */
static const char linearize_help[] =
    "usage: prru linearize --q q1,q2,q3 --qd qd1,qd2,qd3 --fd %s\n"
    "                      [--fp fx,fy,fz] [--mp mx,my,mz] [--dt DT]\n"
    "Linearises the equations of motion at one state, from the closed-form\n"
    "derivatives the generator derived (one evaluation with qdd). Prints JSON\n"
    "with model (name, file, sha256, ... of the model computed with), q, qd,\n"
    "fd, fp, mp, qdd, and, each a list of rows (row i is qdd_i, column k the\n"
    "k-th variable): dqdd_dq (3x3), dqdd_dqd (3x3), dqdd_dfd (3x%d), dqdd_dfp\n"
    "and dqdd_dmp (3x3), and the state-space pair of x' = A x + B u with\n"
    "x = (q, qd), u = fd: A (6x6) = [0 I; dqdd_dq dqdd_dqd] and B (6x%d) =\n"
    "[0; dqdd_dfd]. With --dt DT (s, > 0): dt, and Ad, Bd of the zero-order\n"
    "hold x_{k+1} = Ad x_k + Bd u_k ([Ad Bd; 0 I] = exp([A B; 0 0] DT)).\n"
    "fp (N) acts at O' and mp (N m) on the platform, in {S}; fp and mp default\n"
    "to 0. Exit 1 where forward dynamics is not trusted (q unreachable,\n"
    "out_of_stroke, on or too near the workspace boundary: the same test as\n"
    "eval and simulate), 2 on bad arguments.\n";

static void member_matrix(const char *sep, const char *name, const double *v, int rows, int cols)
{
  printf("%s\"%s\": ", sep, name);
  prru_cli_json_matrix(stdout, v, rows, cols);
}

static void member(const char *sep, const char *name, const double *v, int n)
{
  printf("%s\"%s\": ", sep, name);
  prru_cli_json_array(stdout, v, n);
}

static void print_linearization(const double q[3], const double qd[3], const prru_loads *l,
                                const prru_linearization *o)
{
  const int nact = prru_cli_model()->mech->nact;
  printf("{");
  prru_cli_json_model(stdout);
  member(",\n ", "q", q, 3);
  member(", ", "qd", qd, 3);
  member(",\n ", "fd", l->fd, nact);
  member(", ", "fp", l->fp, 3);
  member(", ", "mp", l->mp, 3);
  member(",\n ", "qdd", o->qdd, 3);
  member_matrix(",\n ", "dqdd_dq", o->dqdd_dq, 3, 3);
  member_matrix(",\n ", "dqdd_dqd", o->dqdd_dqd, 3, 3);
  member_matrix(",\n ", "dqdd_dfd", o->dqdd_dfd, 3, nact);
  member_matrix(",\n ", "dqdd_dfp", o->dqdd_dfp, 3, 3);
  member_matrix(",\n ", "dqdd_dmp", o->dqdd_dmp, 3, 3);
  member_matrix(",\n ", "A", o->A, 6, 6);
  member_matrix(",\n ", "B", o->B, 6, nact);
  if (o->dt > 0) {
    printf(",\n \"dt\": ");
    prru_cli_json_number(stdout, o->dt);
    member_matrix(",\n ", "Ad", o->Ad, 6, 6);
    member_matrix(",\n ", "Bd", o->Bd, 6, nact);
  }
  printf("}\n");
}

int prru_cmd_linearize(int argc, char **argv)
{
  const char *qs = NULL, *qds = NULL, *fds = NULL, *fps = NULL, *mps = NULL, *dts = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL},   {"qd", 1, &qds, NULL}, {"fd", 1, &fds, NULL},
                            {"fp", 1, &fps, NULL}, {"mp", 1, &mps, NULL}, {"dt", 1, &dts, NULL},
                            {"help", 0, NULL, &help}};
  if (prru_cli_parse("linearize", argc, argv, opts, 7)) return 2;
  const int nact = prru_cli_model()->mech->nact;
  if (help) {
    char fd_names[256];
    printf(linearize_help, prru_cli_names(fd_names, sizeof fd_names, "f", nact, ","), nact, nact);
    return 0;
  }
  if (!qs || !qds || !fds) {
    prru_cli_error("linearize", "--q, --qd and --fd are required (see 'prru linearize --help')");
    return 2;
  }
  double q[3], qd[3], dt = 0.0;
  prru_loads l = {{0}, {0, 0, 0}, {0, 0, 0}};
  if (prru_cli_numbers("linearize", "q", qs, q, 3) || prru_cli_numbers("linearize", "qd", qds, qd, 3) ||
      prru_cli_numbers("linearize", "fd", fds, l.fd, nact) ||
      (fps && prru_cli_numbers("linearize", "fp", fps, l.fp, 3)) ||
      (mps && prru_cli_numbers("linearize", "mp", mps, l.mp, 3)) ||
      (dts && prru_cli_number("linearize", "dt", dts, &dt)))
    return 2;
  if (dts && !(dt > 0)) {
    prru_cli_error("linearize", "--dt %s: the hold period must be > 0 s", dts);
    return 2;
  }
  const prru_model m = *prru_cli_model();
  char why[400];
  if (!prru_linearize_available(&m)) {
    prru_linearize_why(&m, NULL, q, qd, &l, dt, NULL, why, sizeof why);
    prru_cli_error("linearize", "%s", why);
    return 2;
  }
  prru_data *d = malloc(sizeof *d);
  prru_linearization *o = malloc(sizeof *o);
  int rc = 1;
  if (d && o) {
    const int st = prru_linearize_why(&m, d, q, qd, &l, dt, o, why, sizeof why);
    if (st != PRRU_OK) {
      prru_cli_error("linearize", "%s", why);
      rc = prru_cli_exit_for(st);
    } else {
      print_linearization(q, qd, &l, o);
      rc = ferror(stdout) ? 1 : 0;
    }
  }
  free(d), free(o);
  return rc;
}
