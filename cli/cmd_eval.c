/* prru eval: every dynamics quantity at one state, as JSON. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru.h"

static const char eval_help[] =
    "usage: prru eval --q q1,q2,q3 [--qd qd1,qd2,qd3] [--fd f1,f2,f3]\n"
    "                 [--fp fx,fy,fz] [--mp mx,my,mz]\n"
    "Prints JSON with q, qd, M (3x3), h, G, d, Jd (3x3), qdd (under the given\n"
    "actuator forces fd (N), platform force fp (N) and moment mp (N m) at O', in\n"
    "{S}) and lambda (the 57 joint reaction coordinates, order lambda_labels).\n"
    "Velocities and loads default to 0. Exit 1 when q is unreachable or J_d is\n"
    "singular there, 2 on bad arguments.\n";

/* Reads the --q/--qd/--fd/--fp/--mp family shared by eval-like commands. */
static int read_vec(const char *cmd, const char *name, const char *text, double out[3])
{
  if (!text) {
    out[0] = out[1] = out[2] = 0.0;
    return 0;
  }
  return prru_cli_numbers(cmd, name, text, out, 3);
}

int prru_cmd_eval(int argc, char **argv)
{
  const char *qs = NULL, *qds = NULL, *fds = NULL, *fps = NULL, *mps = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL},   {"qd", 1, &qds, NULL}, {"fd", 1, &fds, NULL},
                            {"fp", 1, &fps, NULL}, {"mp", 1, &mps, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("eval", argc, argv, opts, 6)) return 2;
  if (help) {
    fputs(eval_help, stdout);
    return 0;
  }
  if (!qs) {
    prru_cli_error("eval", "--q is required (see 'prru eval --help')");
    return 2;
  }
  double q[3], qd[3];
  prru_loads l;
  if (read_vec("eval", "q", qs, q) || read_vec("eval", "qd", qds, qd) ||
      read_vec("eval", "fd", fds, l.fd) || read_vec("eval", "fp", fps, l.fp) ||
      read_vec("eval", "mp", mps, l.mp))
    return 2;

  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  double rcond, M[9], h[3], G[3], lambda[PRRU_NLAMBDA], qdd[3];
  int st = prru_check_regular(&m, d, q, &rcond);
  if (st == PRRU_OK) st = prru_reactions(&m, d, q, qd, &l, lambda);
  if (st != PRRU_OK) {
    prru_cli_error("eval", "q = (%.17g, %.17g, %.17g): %s%s", q[0], q[1], q[2], prru_strerror(st),
                   st == PRRU_ESINGULAR ? " (rcond below 1e-8)" : "");
    free(d);
    return prru_cli_exit_for(st);
  }
  memcpy(qdd, d->qdd, sizeof qdd);
  prru_dynamics(q, qd, M, h, G);
  double act[3], Jd[9];
  prru_ik_jd(q, act, Jd);
  const char *const *labels = prru_mech.lambda_labels;

  printf("{\"q\": ");
  prru_cli_json_array(stdout, q, 3, 1);
  printf(", \"qd\": ");
  prru_cli_json_array(stdout, qd, 3, 1);
  printf(",\n \"M\": ");
  prru_cli_json_array(stdout, M, 9, 1);
  printf(",\n \"h\": ");
  prru_cli_json_array(stdout, h, 3, 1);
  printf(", \"G\": ");
  prru_cli_json_array(stdout, G, 3, 1);
  printf(",\n \"d\": ");
  prru_cli_json_array(stdout, act, 3, 1);
  printf(", \"Jd\": ");
  prru_cli_json_array(stdout, Jd, 9, 1);
  printf(", \"Jd_rcond\": ");
  prru_cli_json_number(stdout, rcond);
  printf(",\n \"fd\": ");
  prru_cli_json_array(stdout, l.fd, 3, 1);
  printf(", \"fp\": ");
  prru_cli_json_array(stdout, l.fp, 3, 1);
  printf(", \"mp\": ");
  prru_cli_json_array(stdout, l.mp, 3, 1);
  printf(",\n \"qdd\": ");
  prru_cli_json_array(stdout, qdd, 3, 1);
  printf(",\n \"lambda\": ");
  prru_cli_json_array(stdout, lambda, PRRU_NLAMBDA, 1);
  printf(",\n \"lambda_labels\": [");
  for (int i = 0; i < PRRU_NLAMBDA; i++) printf("%s\"%s\"", i ? ", " : "", labels[i]);
  printf("]}\n");
  free(d);
  return ferror(stdout) ? 1 : 0;
}
