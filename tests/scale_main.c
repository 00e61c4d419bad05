/* Built by test_scale.sh against kernels generated from a copy of the
 * model with every length multiplied by a factor s: prints, for fixed poses
 * q = (q1, q2, s q3), whether J_d is regular and its reciprocal condition
 * number, and checks FK(IK(q)) = q. A robot of any size must give the same
 * statuses and condition numbers (the tolerances are relative). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "prru.h"
#include "prru_kernels.h" /* the build's PRRU_NACT */

int main(int argc, char **argv)
{
  if (argc != 2) return 2;
  const double s = atof(argv[1]);
  prru_model m;
  prru_model_default(&m);
  prru_data *d = malloc(sizeof *d);
  int fails = 0;
  for (int i = 0; i < 9; i++) {
    for (int j = 0; j < 9; j++) {
      double q[3] = {-0.4 + 0.1 * i, -0.4 + 0.1 * j, -0.8 * s}, rc, act[PRRU_NACT], sol[3];
      int st = prru_check_regular(&m, d, q, &rc);
      printf("%d %.9e\n", st, rc);
      if (st != PRRU_OK) continue;
      prru_actuators(&m, d, q, act);
      double seed[3] = {q[0] + 0.02, q[1] - 0.02, q[2] + 0.02 * s};
      int fk = prru_forward_kinematics(&m, d, act, seed, sol);
      double e = fmax(fabs(sol[0] - q[0]), fmax(fabs(sol[1] - q[1]), fabs(sol[2] - q[2]) / s));
      if (fk != PRRU_OK || !(e <= 1e-12)) {
        fprintf(stderr, "FAIL FK(IK(q)) at q = (%g, %g, %g): status %d, error %.3g\n", q[0], q[1],
                q[2], fk, e);
        fails++;
      }
    }
  }
  free(d);
  return fails ? 1 : 0;
}
