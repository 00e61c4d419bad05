/* Three models' kernels in one program (tests/test_two_models.sh): the
 * paper's as paper3prru, the prototype's as proto and the 4-limb model's
 * as prru4, each with its constant kernels, descriptor, regressor and
 * parameter kernels (the topology kernels prru_p3_*, prru_p4_*, shared).
 * Each model's constant dynamics must equal its parameter kernels at its
 * own numbers (the same derivation, folded or not: within 1e-12 of the
 * largest entry, the bound of tests/test_param_kernels.c), and the three
 * must differ from one another (no model's symbol shadowed another's). */
#include <math.h>
#include <stdio.h>

#include "paper3prru_kernels.h"
#include "paper3prru_mechanism.h"
#include "paper3prru_param_kernels.h"
#include "proto_kernels.h"
#include "proto_mechanism.h"
#include "proto_param_kernels.h"
#include "prru4_kernels.h"
#include "prru4_mechanism.h"
#include "prru4_param_kernels.h"

static int failures;

static double relerr(const double *a, const double *b, int n)
{
  double e = 0, s = 1e-300;
  for (int i = 0; i < n; i++) {
    e = fmax(e, fabs(a[i] - b[i]));
    s = fmax(s, fabs(b[i]));
  }
  return e / s;
}

static void check(const char *what, double e, double bound)
{
  const int ok = e <= bound;
  failures += !ok;
  printf("%s %s: %.2e (bound %.0e)\n", ok ? "ok  " : "FAIL", what, e, bound);
}

int main(void)
{
  const double q[3] = {0.1, -0.2, 0.05}, qd[3] = {0.3, -0.1, 0.2};
  double M[3][9], h[3][3], G[3][3], Mp[9], hp[3], Gp[3];
  /* Each model's numbers as its parameter kernels read them. */
  static paper3prru_param_derived paper_d;
  static proto_param_derived proto_d;
  static prru4_param_derived prru4_d;
  paper3prru_param_derive(&paper3prru_params_model, &paper_d);
  proto_param_derive(&proto_params_model, &proto_d);
  prru4_param_derive(&prru4_params_model, &prru4_d);
  paper3prru_dynamics(q, qd, M[0], h[0], G[0]);
  paper3prru_param_dynamics(&paper_d, q, qd, Mp, hp, Gp);
  check("paper3prru: constant = parameter kernels (M)", relerr(M[0], Mp, 9), 1e-12);
  check("paper3prru: constant = parameter kernels (h)", relerr(h[0], hp, 3), 1e-12);
  proto_dynamics(q, qd, M[1], h[1], G[1]);
  proto_param_dynamics(&proto_d, q, qd, Mp, hp, Gp);
  check("proto: constant = parameter kernels (M)", relerr(M[1], Mp, 9), 1e-12);
  check("proto: constant = parameter kernels (h)", relerr(h[1], hp, 3), 1e-12);
  prru4_dynamics(q, qd, M[2], h[2], G[2]);
  prru4_param_dynamics(&prru4_d, q, qd, Mp, hp, Gp);
  check("prru4: constant = parameter kernels (M)", relerr(M[2], Mp, 9), 1e-12);
  check("prru4: constant = parameter kernels (h)", relerr(h[2], hp, 3), 1e-12);
  /* Distinct models give distinct numbers (a shadowed symbol would not). */
  check("paper3prru and proto differ", relerr(M[0], M[1], 9) > 1e-6 ? 0 : 1, 0);
  check("paper3prru and prru4 differ", relerr(M[0], M[2], 9) > 1e-6 ? 0 : 1, 0);
  check("descriptors: 3, 3 and 4 actuators",
        paper3prru_mech.nact == 3 && proto_mech.nact == 3 && prru4_mech.nact == 4 ? 0 : 1, 0);
  return failures != 0;
}
