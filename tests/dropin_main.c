/* Drop-in check of the generated kernels: this file and generated/ are all
 * that test_dropin.sh copies into an empty directory, so it may use nothing
 * but paper3prru_kernels.h, paper3prru_mechanism.h and the C library (no runtime, no
 * GSL, no testutil.h).
 * It must stay valid C99, C11 and C++ and warning-free under -Wconversion
 * -Wdouble-promotion, because a user's controller build may be any of those.
 * The expected values are the spec's section 10 public reference point,
 * computed independently of the generator. */
#include <math.h>
#include <stdio.h>

#include <string.h>

#include "paper3prru_kernels.h"
#include "paper3prru_mechanism.h"
#include "paper3prru_param_kernels.h"

static int failures = 0;
/* The model's numbers as the parameter kernels read them (derived once in
 * main, as a program does when it loads a model). */
static paper3prru_param_derived model_derived;

/* Every element within tol * max|want| of want; the scale is the array's,
 * not the element's, so exact zeros in J_d do not demand exact zeros. */
static void check_array(const char *what, const double *got, const double *want, int n,
                        double tol)
{
  double scale = 0.0, worst = 0.0;
  int i, worst_i = 0;
  for (i = 0; i < n; i++)
    if (fabs(want[i]) > scale) scale = fabs(want[i]);
  for (i = 0; i < n; i++) {
    double err = fabs(got[i] - want[i]);
    if (isnan(err)) err = HUGE_VAL; /* a NaN result must fail, not compare false */
    if (err > worst) {
      worst = err;
      worst_i = i;
    }
  }
  if (!(worst <= tol * scale)) {
    printf("FAIL %s[%d]: got %.17g want %.17g (error %.3g, limit %.3g)\n", what, worst_i,
           got[worst_i], want[worst_i], worst, tol * scale);
    failures++;
  } else {
    printf("ok   %-28s max error %.3g (relative %.3g)\n", what, worst, worst / scale);
  }
}

static void check_all_nan(const char *what, const double *got, int n)
{
  int i;
  for (i = 0; i < n; i++)
    if (!isnan(got[i])) {
      printf("FAIL %s[%d] = %.17g, want NaN\n", what, i, got[i]);
      failures++;
      return;
    }
  printf("ok   %-28s all %d NaN\n", what, n);
}

/* Fills every output of every kernel at (q, qd) and requires each element to
 * be NaN: the header promises misuse is visible, never a plausible number. */
static void check_nan_everywhere(const char *label, const double q[3], const double qd[3])
{
  static double H[180], dm[60], JP[18], R[90], p[30], I[90], K[60], Q[PAPER3PRRU_REACTION_BASIS_NNZ];
  double d[3], Jd[9], M[9], h[3], G[3], b[3], E[2], dd[3], ddb[3], Qp[3];
  const double f[3] = {1.0, 2.0, 3.0};
  char name[96];
#define NAN_CHECK(kernel_call, arr, n)                       \
  do {                                                      \
    kernel_call;                                            \
    snprintf(name, sizeof name, "%s %s", label, #arr);      \
    check_all_nan(name, arr, n);                            \
  } while (0)
  NAN_CHECK(paper3prru_ik(q, d), d, 3);
  NAN_CHECK(paper3prru_jd(q, Jd), Jd, 9);
  NAN_CHECK(paper3prru_ik_jd(q, d, Jd), d, 3);
  check_all_nan("  ik_jd Jd", Jd, 9);
  NAN_CHECK(paper3prru_jacobians(q, H), H, 180);
  NAN_CHECK(paper3prru_bias_terms(q, qd, dm), dm, 60);
  NAN_CHECK(paper3prru_mass(q, M), M, 9);
  NAN_CHECK(paper3prru_bias(q, qd, h), h, 3);
  NAN_CHECK(paper3prru_gravity(q, G), G, 3);
  NAN_CHECK(paper3prru_eom(q, qd, f, f, f, M, b), b, 3);
  check_all_nan("  eom M", M, 9);
  NAN_CHECK(paper3prru_platform_jacobian(q, JP), JP, 18);
  NAN_CHECK(paper3prru_poses(q, R, p), R, 90);
  check_all_nan("  poses p", p, 30);
  NAN_CHECK(paper3prru_inertia_world(q, I), I, 90);
  NAN_CHECK(paper3prru_wrench_bias(q, qd, K), K, 60);
  NAN_CHECK(paper3prru_energy(q, qd, E), E, 2);
  NAN_CHECK(paper3prru_reaction_basis(q, Q), Q, PAPER3PRRU_REACTION_BASIS_NNZ);
  NAN_CHECK(paper3prru_actuator_rates(q, qd, dd, ddb), dd, 3);
  check_all_nan("  actuator_rates ddb", ddb, 3);
  NAN_CHECK(paper3prru_passive(q, qd, Qp), Qp, 3);
  NAN_CHECK(paper3prru_dynamics(q, qd, M, h, G), M, 9);
  check_all_nan("  dynamics h", h, 3);
  check_all_nan("  dynamics G", G, 3);
  NAN_CHECK(paper3prru_param_dynamics(&model_derived, q, qd, M, h, G), M, 9);
  check_all_nan("  param_dynamics h", h, 3);
  check_all_nan("  param_dynamics G", G, 3);
  NAN_CHECK(paper3prru_param_eom(&model_derived, q, qd, f, f, f, M, b), b, 3);
  check_all_nan("  param_eom M", M, 9);
#undef NAN_CHECK
}

int main(void)
{
  const double q[3] = {0.1, 0.2, -0.8}, qd[3] = {0.3, -0.4, 0.5};
  /* Spec section 10. */
  const double M_ref[9] = {0.45906598061227876,   0.0034180053946637732, -0.067202143647255787,
                           0.0034180053946637732, 0.17775860212149512,   -0.75886870659132982,
                           -0.067202143647255787, -0.75886870659132982,  12.39};
  const double h_ref[3] = {-0.0026294266343440007, 0.0043554318154298796,
                           -0.061280218724993618};
  const double G_ref[3] = {0.6592530291795793, 7.4445020116609459, -121.54590000000001};
  const double d_ref[3] = {-0.61587356199245987, -0.56196351700317267, -0.63523945236562458};
  const double Jd_ref[9] = {-0.280316341384197,    0.0, 1.0, 0.2569859078659369,   0.0,
                            1.0, -0.004724475401913745, -0.2418333257655752, 1.0};
  const double d0_ref[3] = {0.2116601048851672, 0.2116601048851672, 0.2116601048851672};
  const double q0[3] = {0.0, 0.0, 0.0};
  const double zero[3] = {0.0, 0.0, 0.0};
  double M[9], h[3], G[3], d[3], Jd[9], b[3], b_ref[3];
  int i;

  paper3prru_param_derive(&paper3prru_params_model, &model_derived);
  paper3prru_mass(q, M);
  check_array("paper3prru_mass M", M, M_ref, 9, 1e-12);
  paper3prru_bias(q, qd, h);
  check_array("paper3prru_bias h", h, h_ref, 3, 1e-12);
  paper3prru_gravity(q, G);
  check_array("paper3prru_gravity G", G, G_ref, 3, 1e-12);
  paper3prru_ik(q, d);
  check_array("paper3prru_ik d", d, d_ref, 3, 1e-12);
  paper3prru_jd(q, Jd);
  check_array("paper3prru_jd J_d", Jd, Jd_ref, 9, 1e-12);
  paper3prru_ik_jd(q, d, Jd);
  check_array("paper3prru_ik_jd d", d, d_ref, 3, 1e-12);
  check_array("paper3prru_ik_jd J_d", Jd, Jd_ref, 9, 1e-12);
  paper3prru_dynamics(q, qd, M, h, G);
  check_array("paper3prru_dynamics M", M, M_ref, 9, 1e-12);
  check_array("paper3prru_dynamics h", h, h_ref, 3, 1e-12);
  check_array("paper3prru_dynamics G", G, G_ref, 3, 1e-12);
  /* With no loads, M qdd = G - h. */
  paper3prru_eom(q, qd, zero, zero, zero, M, b);
  for (i = 0; i < 3; i++) b_ref[i] = G_ref[i] - h_ref[i];
  check_array("paper3prru_eom M", M, M_ref, 9, 1e-12);
  check_array("paper3prru_eom b (no loads)", b, b_ref, 3, 1e-12);
  paper3prru_ik(q0, d);
  check_array("paper3prru_ik d at q = 0", d, d0_ref, 3, 1e-12);
  /* The runtime-parameter kernels with the model's own numbers. */
  paper3prru_param_dynamics(&model_derived, q, qd, M, h, G);
  check_array("paper3prru_param_dynamics M", M, M_ref, 9, 1e-12);
  check_array("paper3prru_param_dynamics h", h, h_ref, 3, 1e-12);
  check_array("paper3prru_param_dynamics G", G, G_ref, 3, 1e-12);
  paper3prru_param_ik_jd(&model_derived, q, d, Jd);
  check_array("paper3prru_param_ik_jd d", d, d_ref, 3, 1e-12);
  check_array("paper3prru_param_ik_jd J_d", Jd, Jd_ref, 9, 1e-12);
  /* The descriptor describes these kernels: the paper's model, its sizes. */
  if (!(paper3prru_mech.total_mass == M_ref[8]) || strcmp(paper3prru_mech.name, "paper3prru") != 0 ||
      paper3prru_mech.nlambda != PAPER3PRRU_NLAMBDA || paper3prru_mech.nbody != PAPER3PRRU_NBODY ||
      paper3prru_mech.joint[PAPER3PRRU_NJOINT - 1].lambda_offset + paper3prru_mech.joint[PAPER3PRRU_NJOINT - 1].lambda_count !=
          PAPER3PRRU_NLAMBDA) {
    printf("FAIL descriptor: total mass %.17g (M33 %.17g), name %s, nlambda %d\n",
           paper3prru_mech.total_mass, M_ref[8], paper3prru_mech.name, paper3prru_mech.nlambda);
    failures++;
  } else {
    printf("ok   descriptor of model %s (sha256 %.12s...)\n", paper3prru_mech.name, paper3prru_mech.sha256);
  }

  {
    /* Tilting the platform 1.5 rad about e1 takes limbs 1 and 2 out of
     * reach (acos argument > 1); NaN/inf in q must poison every output. */
    const double unreachable[3] = {1.5, 0.0, 0.0};
    const double nan_q[3] = {0.1, (double)NAN, -0.8};
    const double inf_q[3] = {0.1, 0.2, HUGE_VAL};
    check_nan_everywhere("unreachable", unreachable, qd);
    check_nan_everywhere("NaN q", nan_q, qd);
    check_nan_everywhere("inf q", inf_q, qd);
  }

  if (failures) {
    printf("%d check(s) failed\n", failures);
    return 1;
  }
  printf("all drop-in checks passed\n");
  return 0;
}
