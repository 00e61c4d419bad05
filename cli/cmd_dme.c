/* prru dme: the rotational dynamic manipulability ellipse and w_R at one
 * pose, as JSON. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "mapgrid.h"
#include "prru.h"
#include "prru_dme.h"

/* %s: the inverse of J_d and its explanation. */
static const char dme_help[] =
    "usage: prru dme --q q1,q2,q3 [--rcond-min R]\n"
    "Dynamic manipulability at the pose q (rad, rad, m), paper section 5: with\n"
    "Mt = J_d^%s M J_d^%s and JtR = J_R,P J_d^%s, the rotational ellipse is the\n"
    "set of platform angular accelerations a in span{e1, v} with\n"
    "|Mt JtR^+ a| <= 1 N; its semi-axes have lengths 1/sigma_i (rad/s^2 per N)\n"
    "along the right singular vectors of Mt JtR^+ (unit, in {S});\n"
    "w_R = sigma_1/sigma_2 (>= 1). The translational segment runs along z with\n"
    "half-length 1/sigma_T (m/s^2 per N).\n"
    "%s"
    "Prints JSON: model (name, file, sha256, ...), q, status (\"ok\", \"singular\",\n"
    "\"unreachable\" or \"out_of_stroke\"), w_R, Jd_rcond,\n"
    "sigma, semi_axes (minor, major), axis_directions, sigma_T,\n"
    "translational_half_length, translational_direction, Mt (%dx%d), JtR and\n"
    "JtT (3x%d). At a singular or unreachable pose the status says so and\n"
    "every quantity that is not defined there is null; that is still a valid\n"
    "answer (exit 0).\n"
    "J_d counts as singular when 1/(|J|_1 |J^%s|_1) < R, J = J_d with its\n"
    "rotation columns divided by the mean upper-link length (default R: the\n"
    "model's 1e-8).\n";

static const char dme_inverse_3[] =
    "J_d^-1 is the inverse of the 3x3 J_d (three actuators).\n";
static const char dme_inverse_redundant[] =
    "This model has %d actuators: J_d is %dx3 and J_d^+ = (J_d^T J_d)^-1 J_d^T,\n"
    "its pseudo-inverse (for three actuators J_d^-1), so that Mt maps actuator\n"
    "accelerations in range(J_d) to the least-norm drive forces.\n";

static void print_dme_help(void)
{
  const int nact = prru_cli_model()->mech->nact;
  char inv[sizeof dme_inverse_redundant + 32];
  const char *pinv = nact > 3 ? "+" : "-1", *pinvT = nact > 3 ? "+T" : "-T";
  if (nact > 3)
    snprintf(inv, sizeof inv, dme_inverse_redundant, nact, nact);
  else
    snprintf(inv, sizeof inv, "%s", dme_inverse_3);
  printf(dme_help, pinvT, pinv, pinv, inv, nact, nact, nact, pinv);
}

static void json_vec(FILE *f, const double *v, int n)
{
  prru_cli_json_array(f, v, n);
}

int prru_cmd_dme(int argc, char **argv)
{
  const char *qs = NULL, *rcs = NULL;
  int help = 0;
  prru_cli_option opts[] = {{"q", 1, &qs, NULL}, {"rcond-min", 1, &rcs, NULL}, {"help", 0, NULL, &help}};
  if (prru_cli_parse("dme", argc, argv, opts, 3)) return 2;
  if (help) {
    print_dme_help();
    return 0;
  }
  if (!qs) {
    prru_cli_error("dme", "--q is required (see 'prru dme --help')");
    return 2;
  }
  double q[3];
  if (prru_cli_numbers("dme", "q", qs, q, 3)) return 2;
  prru_model m = *prru_cli_model();
  const int nact = m.mech->nact;
  if (prru_cli_parse_rcond("dme", rcs, &m)) return 2;
  prru_data *d = malloc(sizeof *d);
  if (!d) return 1;
  prru_dme r;
  int st = prru_dme_eval(&m, d, q, &r);
  free(d);
  if (st == PRRU_EINPUT) { /* cannot happen after prru_cli_numbers; kept as a guard */
    prru_cli_error("dme", "q: %s", prru_strerror(st));
    return 2;
  }
  FILE *f = stdout;
  fputc('{', f);
  prru_cli_json_model(f);
  fputs(",\n \"q\": ", f);
  json_vec(f, q, 3);
  fprintf(f, ", \"status\": \"%s\", \"w_R\": ", prru_dme_status_name(st));
  prru_cli_json_number(f, r.w_R);
  fputs(", \"Jd_rcond\": ", f);
  prru_cli_json_number(f, st == PRRU_EUNREACHABLE || st == PRRU_ESTROKE ? NAN : r.jd_rcond);
  fputs(", \"sigma\": ", f);
  json_vec(f, r.sigma, 2);
  fputs(", \"semi_axes\": ", f);
  json_vec(f, r.semi_axis, 2);
  fputs(", \"axis_directions\": ", f);
  prru_cli_json_matrix(f, &r.axis_dir[0][0], 2, 3);
  fputs(", \"sigma_T\": ", f);
  prru_cli_json_number(f, r.sigma_T);
  fputs(", \"translational_half_length\": ", f);
  prru_cli_json_number(f, r.half_length_T);
  fputs(", \"translational_direction\": ", f);
  json_vec(f, r.dir_T, 3);
  fputs(", \"Mt\": ", f);
  prru_cli_json_matrix(f, r.Mt, nact, nact);
  fputs(", \"JtR\": ", f);
  prru_cli_json_matrix(f, r.JtR, 3, nact);
  fputs(", \"JtT\": ", f);
  prru_cli_json_matrix(f, r.JtT, 3, nact);
  fputs("}\n", f);
  return ferror(f) ? 1 : 0;
}

