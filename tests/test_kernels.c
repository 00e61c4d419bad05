/* The generated kernels against the hand-derived GSL reference at random
 * reachable states (each output array to 1e-12 relative to its own
 * max-norm), the fused kernels against the separate ones, h against the
 * Christoffel symbols of M by finite differences, and NaN on every output
 * where q is unreachable or not finite. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_kernels.h"
#include "prru_ref.h"
#include "testutil.h"

#define NSTATE 2000
#define NL PRRU_NLAMBDA

static prru_ref_params P;
static prru_ref_ws *W;

/* Worst relative error per output, over all states. */
enum {
  O_IK, O_JD, O_IKJD_D, O_IKJD_J, O_JAC, O_BT, O_MASS, O_BIAS, O_GRAV, O_DYN_M, O_DYN_H, O_DYN_G,
  O_EOM_M, O_EOM_B, O_PJ, O_POSE_R, O_POSE_P, O_IW, O_WB, O_EN, O_Q, O_COUNT
};
static const char *names[O_COUNT] = {
  "ik", "jd", "ik_jd d", "ik_jd Jd", "jacobians", "bias_terms", "mass", "bias", "gravity",
  "dynamics M", "dynamics h", "dynamics G", "eom M", "eom b", "platform_jacobian", "poses R",
  "poses p", "inertia_world", "wrench_bias", "energy", "reaction_basis"};
static double worst[O_COUNT];

static void note(int o, const double *kernel, const double *ref, int n)
{
  double e = tu_relerr(kernel, ref, n, 1e-300);
  if (!(e <= worst[o])) worst[o] = e; /* keeps NaN */
}

/* Every generated kernel's outputs at one state. */
typedef struct {
  double d[3], Jd[9], d2[3], Jd2[9], H[180], dm[60], M[9], h[3], G[3], M2[9], h2[3], G2[3];
  double Me[9], be[3], JP[18], R[90], p[30], I[90], K[60], E[2], Q[60 * NL];
} kernel_outputs;

static void eval_all(const double q[3], const double qd[3], const double fd[3],
                     const double fp[3], const double mp[3], kernel_outputs *o)
{
  prru_ik(q, o->d);
  prru_jd(q, o->Jd);
  prru_ik_jd(q, o->d2, o->Jd2);
  prru_jacobians(q, o->H);
  prru_bias_terms(q, qd, o->dm);
  prru_mass(q, o->M);
  prru_bias(q, qd, o->h);
  prru_gravity(q, o->G);
  prru_dynamics(q, qd, o->M2, o->h2, o->G2);
  prru_eom(q, qd, fd, fp, mp, o->Me, o->be);
  prru_platform_jacobian(q, o->JP);
  prru_poses(q, o->R, o->p);
  prru_inertia_world(q, o->I);
  prru_wrench_bias(q, qd, o->K);
  prru_energy(q, qd, o->E);
  prru_reaction_basis(q, o->Q);
}

static void test_against_reference(void)
{
  int states = 0, skipped = 0, ref_fail = 0;
  double fused = 0;
  static double Qr[60 * NL];
  while (states < NSTATE) {
    double q[3] = {tu_uniform(-0.5, 0.5), tu_uniform(-0.6, 0.5), tu_uniform(-1.0, 0.2)};
    double qd[3], fd[3], fp[3], mp[3];
    for (int i = 0; i < 3; i++) {
      qd[i] = tu_uniform(-1.15, 1.15); /* |qd| <= 2 */
      fd[i] = tu_uniform(-60, 60);
      fp[i] = tu_uniform(-30, 30);
      mp[i] = tu_uniform(-3, 3);
    }
    double d_r[3], Jd_r[9], H_r[180], dm_r[60], M_r[9], h_r[3], G_r[3], R_r[90], p_r[30], E_r[2];
    if (prru_ref_ik(&P, q, d_r) == GSL_EDOM) { skipped++; continue; }
    states++;
    int st = prru_ref_jd(&P, q, Jd_r) | prru_ref_jacobians(&P, W, q, H_r) |
             prru_ref_bias_terms(&P, W, q, qd, dm_r) | prru_ref_poses(&P, q, R_r, p_r) |
             prru_ref_energy(&P, W, q, qd, E_r) | prru_ref_reaction_basis(&P, W, q, Qr);
    /* Last: the workspace keeps this state's Phi and K for inertia_world
     * and wrench_bias. */
    st |= prru_ref_dynamics(&P, W, q, qd, M_r, h_r, G_r);
    if (st) { ref_fail++; continue; }
    double I_r[90], K_r[60];
    for (int b = 0; b < PRRU_NBODY; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) I_r[9 * b + 3 * i + j] = gsl_matrix_get(W->Phi, 3 * b + i, 3 * b + j);
    for (int i = 0; i < 60; i++) K_r[i] = gsl_vector_get(W->K, i);
    /* b = G + J_d^T fd + J_T,P^T fp + J_R,P^T mp - h from the reference. */
    double b_r[3], JP_r[18];
    for (int j = 0; j < 3; j++) {
      b_r[j] = G_r[j] - h_r[j];
      for (int i = 0; i < 3; i++)
        b_r[j] += Jd_r[3 * i + j] * fd[i] + H_r[3 * (30 + i) + j] * fp[i] + H_r[3 * i + j] * mp[i];
    }
    memcpy(JP_r, H_r, 9 * sizeof(double));
    memcpy(JP_r + 9, H_r + 90, 9 * sizeof(double));

    static kernel_outputs ko;
    eval_all(q, qd, fd, fp, mp, &ko);
    double *d = ko.d, *Jd = ko.Jd, *d2 = ko.d2, *Jd2 = ko.Jd2, *H = ko.H, *dm = ko.dm, *M = ko.M,
           *h = ko.h, *G = ko.G, *M2 = ko.M2, *h2 = ko.h2, *G2 = ko.G2, *Me = ko.Me, *be = ko.be,
           *JP = ko.JP, *R = ko.R, *p = ko.p, *I = ko.I, *K = ko.K, *E = ko.E, *Q = ko.Q;

    note(O_IK, d, d_r, 3);
    note(O_JD, Jd, Jd_r, 9);
    note(O_IKJD_D, d2, d_r, 3);
    note(O_IKJD_J, Jd2, Jd_r, 9);
    note(O_JAC, H, H_r, 180);
    note(O_BT, dm, dm_r, 60);
    note(O_MASS, M, M_r, 9);
    note(O_BIAS, h, h_r, 3);
    note(O_GRAV, G, G_r, 3);
    note(O_DYN_M, M2, M_r, 9);
    note(O_DYN_H, h2, h_r, 3);
    note(O_DYN_G, G2, G_r, 3);
    note(O_EOM_M, Me, M_r, 9);
    note(O_EOM_B, be, b_r, 3);
    note(O_PJ, JP, JP_r, 18);
    note(O_POSE_R, R, R_r, 90);
    note(O_POSE_P, p, p_r, 30);
    note(O_IW, I, I_r, 90);
    note(O_WB, K, K_r, 60);
    note(O_EN, E, E_r, 2);
    note(O_Q, Q, Qr, 60 * NL);

    /* Fused kernels against the separate ones. */
    double f[6] = {tu_relerr(d2, d, 3, 1e-300), tu_relerr(Jd2, Jd, 9, 1e-300),
                   tu_relerr(M2, M, 9, 1e-300), tu_relerr(h2, h, 3, 1e-300),
                   tu_relerr(G2, G, 3, 1e-300), tu_relerr(Me, M, 9, 1e-300)};
    for (int i = 0; i < 6; i++)
      if (!(f[i] <= fused)) fused = f[i];
  }
  tu_check(ref_fail == 0, "reference evaluates wherever ik does", ref_fail, 0);
  printf("kernels vs reference: %d reachable states (%d unreachable skipped)\n", states, skipped);
  for (int o = 0; o < O_COUNT; o++) {
    char what[80];
    snprintf(what, sizeof what, "kernel %s = reference", names[o]);
    tu_check(worst[o] <= 1e-12, what, worst[o], 1e-12);
    printf("  %-18s %.1e\n", names[o], worst[o]);
  }
  tu_check(fused <= 1e-15, "fused kernels (ik_jd, dynamics, eom) = separate ones", fused, 1e-15);
  printf("  fused vs separate  %.1e\n", fused);
}

/* h_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k: the bias forces
 * are the Christoffel form of M's derivatives (4th-order central FD). */
static void test_christoffel(void)
{
  const double step = 1e-3;
  double worst_c = 0;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], d[3];
    do {
      q[0] = tu_uniform(-0.5, 0.5);
      q[1] = tu_uniform(-0.5, 0.5);
      q[2] = tu_uniform(-1.0, -0.5);
      prru_ik(q, d);
    } while (isnan(d[0] + d[1] + d[2]));
    for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
    double dM[3][9], h[3], hc[3] = {0, 0, 0};
    int bad = 0;
    for (int k = 0; k < 3; k++) {
      static const double off[4] = {2, 1, -1, -2}, wgt[4] = {-1, 8, -8, 1};
      memset(dM[k], 0, sizeof dM[k]);
      for (int s = 0; s < 4; s++) {
        double qs[3] = {q[0], q[1], q[2]}, M[9];
        qs[k] += off[s] * step;
        prru_mass(qs, M);
        for (int i = 0; i < 9; i++) {
          if (isnan(M[i])) bad = 1;
          dM[k][i] += wgt[s] * M[i] / (12 * step);
        }
      }
    }
    if (bad) continue;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++) hc[i] += (dM[k][3 * i + j] - 0.5 * dM[i][3 * j + k]) * qd[j] * qd[k];
    prru_bias(q, qd, h);
    double e = tu_relerr(h, hc, 3, 1e-300);
    if (!(e <= worst_c)) worst_c = e;
  }
  tu_check(worst_c <= 1e-8, "h = Christoffel form of dM/dq (FD)", worst_c, 1e-8);
  printf("Christoffel consistency (200 states): %.1e\n", worst_c);
}

static int all_nan(const double *x, int n)
{
  for (int i = 0; i < n; i++)
    if (!isnan(x[i])) return 0;
  return 1;
}

static void test_nan_outputs(void)
{
  const double bad[6][3] = {{1.4, 0, -0.8}, {0, 1.2, -0.8}, {NAN, 0, -0.8},
                            {0, INFINITY, -0.8}, {0, 0, -INFINITY}, {0, 0, NAN}};
  const double qd[3] = {0.1, -0.2, 0.3}, f3[3] = {1, 2, 3};
  for (int c = 0; c < 6; c++) {
    const double *q = bad[c];
    static kernel_outputs ko;
    eval_all(q, qd, f3, f3, f3, &ko);
    double *d = ko.d, *Jd = ko.Jd, *d2 = ko.d2, *Jd2 = ko.Jd2, *H = ko.H, *dm = ko.dm, *M = ko.M,
           *h = ko.h, *G = ko.G, *M2 = ko.M2, *h2 = ko.h2, *G2 = ko.G2, *Me = ko.Me, *be = ko.be,
           *JP = ko.JP, *R = ko.R, *p = ko.p, *I = ko.I, *K = ko.K, *E = ko.E, *Q = ko.Q;
    const struct { const char *name; const double *x; int n; } out[] = {
      {"ik", d, 3}, {"jd", Jd, 9}, {"ik_jd d", d2, 3}, {"ik_jd Jd", Jd2, 9}, {"jacobians", H, 180},
      {"bias_terms", dm, 60}, {"mass", M, 9}, {"bias", h, 3}, {"gravity", G, 3},
      {"dynamics M", M2, 9}, {"dynamics h", h2, 3}, {"dynamics G", G2, 3}, {"eom M", Me, 9},
      {"eom b", be, 3}, {"platform_jacobian", JP, 18}, {"poses R", R, 90}, {"poses p", p, 30},
      {"inertia_world", I, 90}, {"wrench_bias", K, 60}, {"energy", E, 2},
      {"reaction_basis", Q, 60 * NL}};
    for (size_t o = 0; o < sizeof out / sizeof out[0]; o++) {
      char what[96];
      snprintf(what, sizeof what, "q #%d (%g, %g, %g): %s all NaN", c, q[0], q[1], q[2], out[o].name);
      TU_TRUE(all_nan(out[o].x, out[o].n), what);
    }
  }
}

int main(void)
{
  prru_ref_params_default(&P);
  W = prru_ref_alloc();
  if (!W) { fprintf(stderr, "prru_ref_alloc failed\n"); return 1; }
  test_against_reference();
  test_christoffel();
  test_nan_outputs();
  prru_ref_free(W);
  return tu_finish("test_kernels");
}
