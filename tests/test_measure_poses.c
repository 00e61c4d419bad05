/* Poses from measured sliders (prru_measure_poses, what `prru identify`
 * runs on slider columns and prru_measure_best_diff on simulated encoder
 * readings): along a smooth motion of the build's model the exact slider
 * positions give back the motion's poses; quantised readings are accepted
 * within the resolution and, with four sliders, refused without it (the
 * least-squares residual is then nonzero); a non-finite or unreachable
 * row is named with the forward kinematics' status.
 *
 * Bounds, derived from prru_forward_kinematics' documented tolerance:
 * the solver stops with a slider residual r <= 10 tol, tol = 100 u
 * max(L, |d|_inf) (u = DBL_EPSILON, L the length scale); the pose then
 * differs from the true one by at most |J_d^+|_1 r to first order (J_d^+
 * = J_d^-1 with three sliders), allowed twice that for the second order.
 * Quantisation to dres moves each slider by at most dres / 2, so the
 * least-squares residual (max norm) stays within dres. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"
#include "prru_measure.h"
#include "testutil.h"

#define N 200

static prru_data data;

/* A smooth motion about the home height: tilts of 0.1 rad, 5 % of L in
 * height, one period over the N rows. */
static void motion(double L, double q3, int i, double q[3])
{
  const double s = 2 * 3.14159265358979323846 * i / N;
  q[0] = 0.1 * sin(s), q[1] = 0.08 * sin(2 * s + 0.3), q[2] = q3 + 0.05 * L * sin(s + 1.1);
}

/* |J_d^+|_1 at q (J_d^-1 with three sliders): from J_d^T J_d. */
static double pinv_norm(const prru_model *m, const double q[3])
{
  double d[PRRU_NACT], Jd[PRRU_NACT * 3], JtJ[9] = {0}, inv[9], P[3 * PRRU_NACT];
  prru_model_ik_jd(m, q, d, Jd);
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++)
      for (int i = 0; i < PRRU_NACT; i++) JtJ[3 * r + c] += Jd[3 * i + r] * Jd[3 * i + c];
  tu_inverse3(JtJ, inv);
  for (int r = 0; r < 3; r++)
    for (int i = 0; i < PRRU_NACT; i++) {
      P[PRRU_NACT * r + i] = 0;
      for (int c = 0; c < 3; c++) P[PRRU_NACT * r + i] += inv[3 * r + c] * Jd[3 * i + c];
    }
  return tu_norm1(P, 3, PRRU_NACT);
}

int main(void)
{
  prru_model m;
  prru_model_default(&m);
  const double L = prru_length_scale(m.mech), u = DBL_EPSILON;
  /* The most regular height at q1 = q2 = 0 (every valid model assembles
   * there). */
  double q3 = 0, best = 0;
  for (int k = 1; k <= 400; k++) {
    double q[3] = {0, 0, -4 * L * k / 400}, rc;
    if (prru_check_regular(&m, &data, q, &rc) == PRRU_OK && rc > best) best = rc, q3 = q[2];
  }
  TU_TRUE(best > 0, "a regular home height");
  static double qt[3 * N], d[PRRU_NACT * N], q[3 * N], dq[PRRU_NACT * N];
  for (int i = 0; i < N; i++) {
    motion(L, q3, i, qt + 3 * i);
    TU_TRUE(prru_actuators(&m, &data, qt + 3 * i, d + PRRU_NACT * i) == PRRU_OK, "the motion is reachable");
  }
  int row;
  double res;
  char msg[300];

  /* Exact sliders: every pose back, within the solver's tolerance. */
  int st = prru_measure_poses(&m, N, d, INFINITY, q, &row, &res, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK && row == -1, "exact sliders: every row's pose");
  double worst = 0;
  for (int i = 0; i < N && st == PRRU_OK; i++) {
    const double tol = 100 * u * fmax(L, tu_norm_inf(d + PRRU_NACT * i, PRRU_NACT));
    const double bound = 2 * pinv_norm(&m, qt + 3 * i) * 10 * tol;
    double e = 0;
    for (int k = 0; k < 3; k++) e = fmax(e, fabs(q[3 * i + k] - qt[3 * i + k]));
    worst = fmax(worst, e / bound);
  }
  tu_check(worst <= 1, "exact sliders: |q - q_true| / (2 |J_d^+| 10 tol)", worst, 1);

  /* Quantised to dres: accepted with the resolution given; with four
   * sliders refused without it, the row and its residual named. */
  const double dres = 1e-5 * L;
  for (int i = 0; i < PRRU_NACT * N; i++) dq[i] = dres * nearbyint(d[i] / dres);
  st = prru_measure_poses(&m, N, dq, dres, q, &row, &res, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK && row == -1, "quantised sliders within the resolution");
  st = prru_measure_poses(&m, N, dq, 0, q, &row, &res, msg, sizeof msg);
  if (PRRU_NACT > 3)
    TU_TRUE(st == PRRU_EINPUT && row >= 0 && res > 0 && res <= dres && strstr(msg, "inconsistent"),
            "four quantised sliders without a resolution: refused, the row and residual named");
  else
    TU_TRUE(st == PRRU_OK, "three quantised sliders are always consistent");

  /* A non-finite and an unreachable row: the forward kinematics' status,
   * no residual. */
  d[PRRU_NACT * 7 + 1] = NAN;
  st = prru_measure_poses(&m, N, d, INFINITY, q, &row, &res, msg, sizeof msg);
  TU_TRUE(st == PRRU_EINPUT && row == 7 && isnan(res) && strstr(msg, "row 8"), "a NaN slider: row 8 named");
  d[PRRU_NACT * 7 + 1] = d[PRRU_NACT * 6 + 1];
  /* An unreachable slider: the solver fails, or (least squares over four
   * sliders) stops far from it, beyond any resolution. */
  d[PRRU_NACT * 3] += 10 * L;
  st = prru_measure_poses(&m, N, d, dres, q, &row, &res, msg, sizeof msg);
  TU_TRUE(row == 3 && strstr(msg, "row 4") &&
              ((st != PRRU_OK && st != PRRU_EINPUT && isnan(res)) || (st == PRRU_EINPUT && res > dres)),
          "an unreachable row: row 4 named");
  return tu_finish("test_measure_poses");
}
