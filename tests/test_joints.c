/* Joint centres from the poses (prru_body_origin, prru_limb_joints: what
 * prru view and prru animate draw), against the mechanism's own lengths
 * and the inverse kinematics, at seeded random regular poses of the
 * build's model: each upper link spans l1 (A_i to B_i) and each lower link
 * l2 (B_i to C_i), A_i stands at the slider height d_i of prru_actuators,
 * and C_i sits on the platform a_i from its frame origin O' (C3, C4 at O'
 * itself).
 *
 * Bound: each point is a few roundings (a 3x3 product and sums) of
 * numbers no larger than S = max(L, the largest coordinate), so within
 * 16 u S of the exact point; a distance then within 64 u S (four
 * points' errors and the square root's), the rule used for all. */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "prru.h"
#include "testutil.h"

#define POSES 50

static prru_data data;

static double dist(const double a[3], const double b[3])
{
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

int main(void)
{
  prru_model m;
  prru_model_default(&m);
  const prru_mechanism *me = m.mech;
  const double L = prru_length_scale(me), u = DBL_EPSILON;
  double q3 = 0, best = 0;
  for (int k = 1; k <= 400; k++) {
    double q[3] = {0, 0, -4 * L * k / 400}, rc;
    if (prru_check_regular(&m, &data, q, &rc) == PRRU_OK && rc > best) best = rc, q3 = q[2];
  }
  TU_TRUE(best > 0, "a regular home height");
  tu_rng_state = 20261127;
  double worst = 0;
  int n = 0;
  for (int tries = 0; tries < 20 * POSES && n < POSES; tries++) {
    const double q[3] = {tu_uniform(-0.3, 0.3), tu_uniform(-0.3, 0.3), q3 + L * tu_uniform(-0.1, 0.1)};
    double rc, d[PRRU_NACT], R[9 * PRRU_NBODY], pos[3 * PRRU_NBODY], O[3];
    if (prru_check_regular(&m, &data, q, &rc) != PRRU_OK || prru_actuators(&m, &data, q, d) != PRRU_OK) continue;
    n++;
    prru_model_poses(&m, q, R, pos);
    prru_body_origin(&m, R, pos, me->platform, O);
    double S = L;
    for (int k = 0; k < 3 * PRRU_NBODY; k++) S = fmax(S, fabs(pos[k]));
    for (int i = 0; i < PRRU_NLIMB; i++) {
      double A[3], B[3], C[3];
      prru_limb_joints(&m, R, pos, i, A, B, C);
      const double a = i < 2 ? me->a[i] : 0.0;
      const double e[4] = {fabs(dist(A, B) - me->l1[i]), fabs(dist(B, C) - me->l2[i]), fabs(A[2] - d[i]),
                           fabs(dist(C, O) - a)};
      for (int k = 0; k < 4; k++) worst = fmax(worst, e[k] / (64 * u * S));
    }
  }
  TU_TRUE(n == POSES, "enough regular random poses");
  tu_check(worst <= 1, "|l1|, |l2|, A_z = d_i, |C_i - O'| = a_i, in 64 u S", worst, 1);
  return tu_finish("test_joints");
}
