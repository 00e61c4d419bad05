/* The reference library on the paper's model only: the spec's public
 * reference point (section 10), the paper's total mass, d and w_R at the
 * home pose, the mirror symmetry of its geometry about the plane y = 0, and
 * poses the paper's geometry cannot reach. Model-generic properties of the
 * reference are in test_reference.c. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_mechanism.h"
#include "prru_ref.h"
#include "testutil.h"

static prru_ref_params P;
static prru_ref_ws *W;

/* ---- spec section 10 ---- */
static void test_reference_point(void)
{
  static const double M_ref[9] = {
      0.45906598061227876, 0.0034180053946637732, -0.067202143647255787,
      0.0034180053946637732, 0.17775860212149512, -0.75886870659132982,
      -0.067202143647255787, -0.75886870659132982, 12.39};
  static const double h_ref[3] = {-0.0026294266343440007, 0.0043554318154298796, -0.061280218724993618};
  static const double G_ref[3] = {0.6592530291795793, 7.4445020116609459, -121.54590000000001};
  static const double d_ref[3] = {-0.61587356199245987, -0.56196351700317267, -0.63523945236562458};
  static const double Jd_ref[9] = {-0.280316341384197, 0, 1, 0.2569859078659369, 0, 1,
                                   -0.004724475401913745, -0.2418333257655752, 1};
  const double q[3] = {0.1, 0.2, -0.8}, qd[3] = {0.3, -0.4, 0.5};
  double M[9], h[3], G[3], d[3], Jd[9];
  TU_TRUE(prru_ref_dynamics(&P, W, q, qd, M, h, G) == GSL_SUCCESS, "reference point: dynamics status");
  TU_TRUE(prru_ref_ik(&P, q, d) == GSL_SUCCESS, "reference point: ik status");
  TU_TRUE(prru_ref_jd(&P, q, Jd) == GSL_SUCCESS, "reference point: jd status");
  TU_CLOSE(M, M_ref, 9, 1e-12, "reference point M");
  TU_CLOSE(h, h_ref, 3, 1e-12, "reference point h");
  TU_CLOSE(G, G_ref, 3, 1e-12, "reference point G");
  TU_CLOSE(d, d_ref, 3, 1e-12, "reference point d");
  TU_CLOSE(Jd, Jd_ref, 9, 1e-12, "reference point J_d");
  printf("reference point: M %.1e h %.1e G %.1e d %.1e J_d %.1e\n", tu_relerr(M, M_ref, 9, 1e-300),
         tu_relerr(h, h_ref, 3, 1e-300), tu_relerr(G, G_ref, 3, 1e-300), tu_relerr(d, d_ref, 3, 1e-300),
         tu_relerr(Jd, Jd_ref, 9, 1e-300));
  /* M33 is the machine's total mass (Table 1: 12.39 kg): q3 moves every
   * body rigidly in z, and the paper has no drive armature. */
  tu_check(fabs(M[8] - 12.39) <= 1e-13 * 12.39, "M33 = total mass 12.39", fabs(M[8] - 12.39),
           1e-13 * 12.39);
  tu_check(fabs(prru_mech.total_mass - 12.39) <= 1e-13 * 12.39, "descriptor total mass 12.39",
           fabs(prru_mech.total_mass - 12.39), 1e-13 * 12.39);

  /* The paper has no drives: the passive force is zero, not just small. */
  double Qp[3];
  TU_TRUE(prru_ref_passive(&P, W, q, qd, Qp) == GSL_SUCCESS && Qp[0] == 0 && Qp[1] == 0 && Qp[2] == 0,
          "paper model: no drive damping or friction");

  const double q0[3] = {0, 0, 0};
  const double d0[3] = {0.2116601048851672, 0.2116601048851672, 0.2116601048851672};
  double wr;
  prru_ref_ik(&P, q0, d);
  TU_CLOSE(d, d0, 3, 1e-15, "d at q = 0");
  TU_TRUE(prru_ref_w_r(&P, W, q0, &wr) == GSL_SUCCESS, "w_R(0) status");
  tu_check(fabs(wr - 1.80468) <= 5e-6, "w_R(0) = 1.80468 (5 digits)", fabs(wr - 1.80468), 5e-6);
  printf("reference point: w_R(0) = %.10f\n", wr);
}

/* The paper's geometry is mirror-symmetric about the plane y = 0 (limbs 1
 * and 2 equal, limb 3 in the plane): q1 -> -q1 swaps d_1 and d_2, keeps
 * d_3, and leaves w_R unchanged (the paper's fig. 7). */
static void test_mirror_symmetry(void)
{
  double e_d = 0, e_w = 0;
  for (int n = 0; n < 200; n++) {
    double q[3] = {tu_uniform(-0.4, 0.4), tu_uniform(-0.6, 0.4), tu_uniform(-1.0, 0.2)};
    double qm[3] = {-q[0], q[1], q[2]};
    double d[3], dm[3], a, b;
    if (prru_ref_ik(&P, q, d) || prru_ref_ik(&P, qm, dm)) continue;
    const double dswap[3] = {dm[1], dm[0], dm[2]};
    e_d = fmax(e_d, tu_relerr(d, dswap, 3, 1e-300));
    if (prru_ref_w_r(&P, W, q, &a) || prru_ref_w_r(&P, W, qm, &b)) continue;
    e_w = fmax(e_w, fabs(a - b) / a);
  }
  tu_check(e_d <= 1e-15, "d(q1) = d(-q1) with d_1, d_2 swapped", e_d, 1e-15);
  tu_check(e_w <= 1e-12, "w_R(q1) = w_R(-q1)", e_w, 1e-12);
  printf("mirror symmetry: d %.1e, w_R %.1e\n", e_d, e_w);
}

/* Poses the paper's geometry cannot reach: at q1 = 1.4 limbs 1, 2 need
 * (b12 - (a + l2) cos q1) / l1 = 1.36 > 1; at q2 = 1.2 limb 3 needs
 * (l2 cos q2 - b3) / l1 = -1.02 < -1. */
static void test_unreachable(void)
{
  const double bad[2][3] = {{1.4, 0, -0.8}, {0, 1.2, -0.8}};
  const double qd[3] = {0.1, 0.2, 0.3};
  for (int k = 0; k < 2; k++) {
    double d[3], M[9], dd[3], ddb[3], wr;
    int ok = prru_ref_ik(&P, bad[k], d) == GSL_EDOM && isnan(d[0]) &&
             prru_ref_mass(&P, W, bad[k], M) == GSL_EDOM && isnan(M[0]) &&
             prru_ref_actuator_rates(&P, bad[k], qd, dd, ddb) == GSL_EDOM && isnan(ddb[0]) &&
             prru_ref_w_r(&P, W, bad[k], &wr) == GSL_EDOM && isnan(wr);
    char what[80];
    snprintf(what, sizeof what, "paper geometry cannot reach q = (%g, %g, %g)", bad[k][0], bad[k][1],
             bad[k][2]);
    TU_TRUE(ok, what);
  }
}

int main(void)
{
  prru_ref_params_default(&P);
  W = prru_ref_alloc();
  if (!W) { fprintf(stderr, "prru_ref_alloc failed\n"); return 1; }
  test_reference_point();
  test_mirror_symmetry();
  test_unreachable();
  prru_ref_free(W);
  return tu_finish("paper_reference");
}
