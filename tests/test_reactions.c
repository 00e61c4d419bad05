/* The closed-form joint reactions (prru_joint_reactions, used by
 * prru_reactions) against the dense reference, eq. 31 with GSL
 * (reference/ref_reactions.c: Q and Phi formed, Cholesky for three limbs,
 * the SVD's least-norm solution for four), at 2000 regular states with
 * velocities and loads, relative to the largest coordinate (at least 1):
 * within K u kappa_1(M_s) (u = DBL_EPSILON, M_s the scaled mass matrix of
 * prru_mass_rcond): both sides stand on their own solve of the forward
 * dynamics, whose qdd carries u kappa(M) of rounding into every inertial
 * force, and K = 1024 covers the few hundred roundings of each side's
 * chain of joint equations (measured on the paper model: 157 u kappa at
 * random states, 236 on the grid; a random valid model's 1.9e-12 broke the
 * old fixed 1e-12, a bound measured on the committed models). For the
 * redundant 4-PRRU also the null direction against the reference's SVD
 * (same sign convention up to the reference's, which signs the largest
 * component) and lambda . z = 0. Then the statuses: unreachable, NaN,
 * overflow, and lambda untouched on failure. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "prru.h"
#include "prru_ref.h"
#include "testsim.h"
#include "testutil.h"

#define NL PRRU_NLAMBDA
#define NA PRRU_NACT

static prru_model model;
static prru_data data;

#if PRRU_NREACTION_NULL == 1
static double dot(const double *a, const double *b, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

static double maxabs(const double *a, int n)
{
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i]));
  return m;
}
#endif

static void test_against_reference(void)
{
  prru_ref_params rp;
  prru_ref_params_default(&rp);
  prru_ref_ws *w = prru_ref_alloc();
  double e_lam = 0, e_z = 0, e_lz = 0, e_kernel = 0;
  int n = 0, ok = 1;
  for (int k = 0; k < 2000; k++) {
    double q[3], qd[3], qdd[3], lam[NL], ref[NL], direct[NL];
    prru_loads l;
    ts_random_state(&model, &data, q, qd);
    for (int i = 0; i < 3; i++) qd[i] *= 2.0;
    ts_random_loads(&l);
    if (prru_reactions(&model, &data, q, qd, &l, lam) != PRRU_OK ||
        prru_ref_reactions(&rp, w, q, qd, l.fd, l.fp, l.mp, ref) != 0) {
      ok = 0;
      continue;
    }
    n++;
    const double kappa = 1.0 / prru_mass_rcond(&model, data.M);
    e_lam = fmax(e_lam, tu_relerr(lam, ref, NL, 1.0) / (DBL_EPSILON * kappa));
    /* The kernel itself at the forward dynamics' qdd is what the runtime
     * returns, bit for bit. */
    memcpy(qdd, data.qdd, sizeof qdd);
#if PRRU_NREACTION_NULL == 0
    prru_joint_reactions(q, qd, qdd, l.fd, l.fp, l.mp, direct);
#else
    double zk[NL];
    prru_joint_reactions(q, qd, qdd, l.fd, l.fp, l.mp, direct, zk);
#endif
    for (int i = 0; i < NL; i++) e_kernel = fmax(e_kernel, fabs(direct[i] - lam[i]));
#if PRRU_NREACTION_NULL == 1
    double z[NL], zr[NL];
    int nullity = -1;
    if (prru_reaction_null(&model, &data, q, z) != PRRU_OK ||
        prru_ref_reaction_null(&rp, w, q, zr, &nullity) != 0 || nullity != 1) {
      ok = 0;
      continue;
    }
    double sg = dot(z, zr, NL) < 0 ? -1.0 : 1.0;
    for (int i = 0; i < NL; i++) e_z = fmax(e_z, fabs(z[i] - sg * zr[i]));
    e_lz = fmax(e_lz, fabs(dot(lam, z, NL)) / maxabs(lam, NL));
    for (int i = 0; i < NL; i++) e_kernel = fmax(e_kernel, fabs(data.lambda_null[i] - z[i]));
#endif
  }
  prru_ref_free(w);
  printf("closed form vs dense reference at %d states: lambda %.1f u kappa(M_s)", n, e_lam);
  if (PRRU_NREACTION_NULL) printf(", z %.1e, lambda . z / |lambda| %.1e", e_z, e_lz);
  printf("; kernel vs prru_reactions %.1e\n", e_kernel);
  TU_TRUE(ok && n == 2000, "every state solved by both");
  tu_check(e_lam <= 1024, "closed-form lambda = dense eq. 31 (in u kappa(M_s))", e_lam, 1024);
  tu_check(e_kernel == 0, "prru_reactions = prru_joint_reactions at its qdd", e_kernel, 0);
  if (PRRU_NREACTION_NULL) {
    tu_check(e_z <= 1e-12, "closed-form z = the reference's SVD null vector", e_z, 1e-12);
    tu_check(e_lz <= 1e-13, "lambda . z = 0 (least norm)", e_lz, 1e-13);
  }
}

/* Over a grid reaching further out than the random states (every regular
 * pose of the test_redundant spectrum grid and beyond), both solve, and
 * agree. */
static void test_grid(void)
{
  prru_ref_params rp;
  prru_ref_params_default(&rp);
  prru_ref_ws *w = prru_ref_alloc();
  int regular = 0, solved = 0;
  double e = 0;
  for (int i = 0; i < 25; i++)
    for (int j = 0; j < 25; j++)
      for (int h = 0; h < 2; h++) {
        double q[3] = {-0.8 + 1.6 * i / 24, -1.0 + 1.7 * j / 24, h ? -0.6 : -0.85};
        double qd[3] = {0.4, -0.3, 0.2}, lam[NL], ref[NL];
        if (prru_check_regular(&model, &data, q, NULL) != PRRU_OK) continue;
        prru_loads l;
        ts_random_loads(&l);
        /* Poses the trust criterion refuses (too near the edge of reach:
         * prru_model.mass_rcond_min) do not count as regular. */
        double qdd[3];
        if (prru_forward_dynamics(&model, &data, q, qd, &l, qdd) == PRRU_ESINGULAR) continue;
        regular++;
        if (prru_reactions(&model, &data, q, qd, &l, lam) != PRRU_OK) continue;
        if (prru_ref_reactions(&rp, w, q, qd, l.fd, l.fp, l.mp, ref) != 0) continue;
        solved++;
        const double kappa = 1.0 / prru_mass_rcond(&model, data.M);
        e = fmax(e, tu_relerr(lam, ref, NL, 1.0) / (DBL_EPSILON * kappa));
      }
  prru_ref_free(w);
  printf("grid: %d regular poses, %d solved by both, worst %.1f u kappa(M_s)\n", regular, solved, e);
  TU_TRUE(regular > 400 && solved == regular, "every regular grid pose solved");
  tu_check(e <= 1024, "closed form = dense reference over the grid (in u kappa(M_s))", e, 1024);
}

static void test_statuses(void)
{
  double q[3] = {0, 0, -0.8}, qd[3] = {0, 0, 0}, lam[NL], before[NL], act[NA];
  prru_loads l;
  memset(&l, 0, sizeof l);
  for (int i = 0; i < NL; i++) lam[i] = before[i] = 1.0 + i;
  /* Tilting the platform about e1 until a limb cannot reach it. */
  double far[3] = {0, 0, -0.8};
  while (far[0] < 3 && prru_actuators(&model, &data, far, act) == PRRU_OK) far[0] += 0.01;
  TU_TRUE(prru_actuators(&model, &data, far, act) == PRRU_EUNREACHABLE, "an unreachable tilt");
  TU_TRUE(prru_reactions(&model, &data, far, qd, &l, lam) == PRRU_EUNREACHABLE,
          "unreachable q: PRRU_EUNREACHABLE");
  double nanq[3] = {NAN, 0, -0.8};
  TU_TRUE(prru_reactions(&model, &data, nanq, qd, &l, lam) == PRRU_EINPUT, "NaN q: PRRU_EINPUT");
  prru_loads huge = l;
  huge.fp[0] = 1e307;
  huge.fp[1] = -1e307;
  huge.mp[2] = 1e307;
  int st = prru_reactions(&model, &data, q, qd, &huge, lam);
  TU_TRUE(st == PRRU_EINPUT, "overflowing loads: PRRU_EINPUT");
  TU_TRUE(memcmp(lam, before, sizeof lam) == 0, "lambda untouched on failure");
  TU_TRUE(prru_reactions(&model, &data, q, qd, &l, lam) == PRRU_OK, "rest pose solves");
}

int main(void)
{
  prru_model_default(&model);
  test_against_reference();
  test_grid();
  test_statuses();
  return tu_finish("test_reactions");
}
