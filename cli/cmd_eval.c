/* prru eval: every dynamics quantity at one state, as JSON. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "prru.h"

/* %s: the --fd names; %d: the model's reaction coordinates (nlambda). */
static const char eval_help[] =
    "usage: prru eval --q q1,q2,q3 [--qd qd1,qd2,qd3] [--fd %s]\n"
    "                 [--fp fx,fy,fz] [--mp mx,my,mz]\n"
    "Prints JSON with model (name, file, sha256, ... of the model computed with),\n"
    "q, qd, M (3x3), h, G, passive (the drives' damping and friction as\n"
    "generalized forces; zero for a model without them), d, Jd (one row per\n"
    "actuator, one column per coordinate; every matrix is a list of rows),\n"
    "qdd (under the given actuator forces fd (N), platform force fp (N) and\n"
    "moment mp (N m) at O', in {S}: M qdd + h = G + Jd^T fd + J_T,P^T fp +\n"
    "J_R,P^T mp + passive) and lambda (the %d joint reaction coordinates: force\n"
    "(N) and moment (N m) components of what each joint's proximal body exerts\n"
    "on the distal one, named in lambda_labels as JOINT_COMPONENT, e.g. %s).\n"
    "Velocities and loads default to 0. Exit 1 when q is unreachable or\n"
    "out_of_stroke (a slider beyond the model's actuators.stroke), J_d is\n"
    "singular there, or q is too near the workspace boundary to trust the\n"
    "dynamics (the mass matrix's rcond below 1e-6), 2 on bad arguments.\n"
    "%s";

/* The part of the help that only a model with redundant actuators has. */
static const char eval_help_redundant[] =
    "This model has %d actuators for 3 coordinates (redundant actuation):\n"
    "  actuator_null: n, the unit vector with J_d^T n = 0 and n_%d > 0 (an\n"
    "    actuator-force pattern in equilibrium by itself: fd and fd + t n move\n"
    "    the robot identically);\n"
    "  preload: fd . n (N), the internal preload contained in the given fd;\n"
    "  reaction_null: z (unit, in lambda_labels order), the one pattern of\n"
    "    joint reactions that loads no body and moves nothing: a lateral force\n"
    "    along e2 around the loop rail 3 -> limb 3 -> platform -> limb 4 ->\n"
    "    rail 4 -> ground. Rigid-body dynamics cannot tell how much of it the\n"
    "    joints carry (that depends on their compliance and fit): every\n"
    "    lambda + s z satisfies the equations of motion equally, and lambda is\n"
    "    the solution of least Euclidean norm (lambda . z = 0, coordinates in\n"
    "    N and N m as they stand).\n";

/* Reads the --q/--qd/--fd/--fp/--mp family shared by eval-like commands:
 * n numbers, all 0 when the option is absent. */
static int read_vec(const char *cmd, const char *name, const char *text, double *out, int n)
{
  if (!text) {
    for (int i = 0; i < n; i++) out[i] = 0.0;
    return 0;
  }
  return prru_cli_numbers(cmd, name, text, out, n);
}

static void member(const char *sep, const char *name, const double *v, int n)
{
  printf("%s\"%s\": ", sep, name);
  prru_cli_json_array(stdout, v, n);
}

/* A rows x cols row-major matrix as nested row arrays. */
static void member_matrix(const char *sep, const char *name, const double *v, int rows, int cols)
{
  printf("%s\"%s\": ", sep, name);
  prru_cli_json_matrix(stdout, v, rows, cols);
}

int prru_cmd_eval(int argc, char **argv)
{
  const char *qs = NULL, *qds = NULL, *fds = NULL, *fps = NULL, *mps = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL},   {"qd", 1, &qds, NULL}, {"fd", 1, &fds, NULL},
                            {"fp", 1, &fps, NULL}, {"mp", 1, &mps, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("eval", argc, argv, opts, 6)) return 2;
  const prru_mechanism *me = prru_cli_model()->mech;
  const int nact = me->nact;
  if (help) {
    char fd_names[256];
    char redundant[sizeof eval_help_redundant + 32] = "";
    if (nact > 3) snprintf(redundant, sizeof redundant, eval_help_redundant, nact, nact);
    printf(eval_help, prru_cli_names(fd_names, sizeof fd_names, "f", nact, ","), me->nlambda,
           me->lambda_labels[0], redundant);
    return 0;
  }
  if (!qs) {
    prru_cli_error("eval", "--q is required (see 'prru eval --help')");
    return 2;
  }
  double q[3], qd[3];
  prru_loads l;
  if (read_vec("eval", "q", qs, q, 3) || read_vec("eval", "qd", qds, qd, 3) ||
      read_vec("eval", "fd", fds, l.fd, nact) || read_vec("eval", "fp", fps, l.fp, 3) ||
      read_vec("eval", "mp", mps, l.mp, 3))
    return 2;

  const prru_model m = *prru_cli_model();
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  double rcond, M[9], h[3], G[3], passive[3];
  double lambda[PRRU_MAX_LAMBDA], qdd[3];
  char qtext[128];
  int st = prru_check_regular(&m, d, q, &rcond);
  if (st != PRRU_OK) {
    char why[200];
    if (st == PRRU_ESINGULAR)
      prru_cli_error("eval", "q = %s: J_d is singular there (rcond %.3g below jd_rcond_min %.3g)",
                     prru_cli_vec(qtext, sizeof qtext, q, 3), rcond, m.jd_rcond_min);
    else if (st == PRRU_ESTROKE && prru_stroke_why(&m, d->d, why, sizeof why) == PRRU_ESTROKE)
      prru_cli_error("eval", "q = %s: out_of_stroke: %s", prru_cli_vec(qtext, sizeof qtext, q, 3), why);
    else
      prru_cli_error("eval", "q = %s: %s", prru_cli_vec(qtext, sizeof qtext, q, 3), prru_strerror(st));
    free(d);
    return prru_cli_exit_for(st);
  }
  st = prru_reactions(&m, d, q, qd, &l, lambda);
  if (st != PRRU_OK) {
    /* The library's diagnosis of the state; where the forward dynamics
     * are fine, the reactions themselves failed. */
    char why[320];
    if (prru_forward_dynamics_why(&m, d, q, qd, &l, why, sizeof why) == PRRU_OK)
      snprintf(why, sizeof why, "%s",
               st == PRRU_ESINGULAR ? "the joints cannot carry the loads there (a constraint "
                                      "singularity)"
                                    : "the reactions overflow: the velocities or loads are too "
                                      "large");
    prru_cli_error("eval", "%s", why);
    free(d);
    return prru_cli_exit_for(st);
  }
  memcpy(qdd, d->qdd, sizeof qdd);
  /* Redundant actuation: the actuator null vector n and the reaction null
   * vector z (left in d->lambda_null by prru_reactions). */
  double n[PRRU_MAX_ACT], z[PRRU_MAX_LAMBDA], preload = 0.0;
  const int npreload = prru_cli_npreload(&m), nreaction_null = prru_cli_nreaction_null(&m);
  if (npreload > 0) {
    memcpy(z, d->lambda_null, sizeof z);
    st = prru_actuator_null(&m, d, q, n);
    if (st != PRRU_OK) {
      prru_cli_error("eval", "q = %s: actuator null vector: %s", prru_cli_vec(qtext, sizeof qtext, q, 3),
                     prru_strerror(st));
      free(d);
      return prru_cli_exit_for(st);
    }
    for (int i = 0; i < nact; i++) preload += l.fd[i] * n[i];
  }
  prru_model_dynamics(&m, q, qd, M, h, G);
  prru_model_passive(&m, q, qd, passive);
  double act[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3];
  prru_model_ik_jd(&m, q, act, Jd);
  const char *const *labels = m.mech->lambda_labels;

  printf("{");
  prru_cli_json_model(stdout);
  member(",\n ", "q", q, 3);
  member(", ", "qd", qd, 3);
  member_matrix(",\n ", "M", M, 3, 3);
  member(",\n ", "h", h, 3);
  member(", ", "G", G, 3);
  member(", ", "passive", passive, 3);
  member(",\n ", "d", act, nact);
  member_matrix(", ", "Jd", Jd, nact, 3);
  printf(", \"Jd_rcond\": ");
  prru_cli_json_number(stdout, rcond);
  member(",\n ", "fd", l.fd, nact);
  member(", ", "fp", l.fp, 3);
  member(", ", "mp", l.mp, 3);
  member(",\n ", "qdd", qdd, 3);
  if (npreload > 0) {
    member(",\n ", "actuator_null", n, nact);
    printf(", \"preload\": ");
    prru_cli_json_number(stdout, preload);
  }
  member(",\n ", "lambda", lambda, me->nlambda);
  if (nreaction_null > 0) member(",\n ", "reaction_null", z, me->nlambda);
  printf(",\n \"lambda_labels\": [");
  for (int i = 0; i < me->nlambda; i++) {
    if (i) fputs(", ", stdout);
    prru_cli_json_string(stdout, labels[i]);
  }
  printf("]}\n");
  free(d);
  return ferror(stdout) ? 1 : 0;
}
