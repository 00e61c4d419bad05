/* The generated kernels against the hand-derived GSL reference at random
 * reachable states of whatever model the build uses (each output array to
 * 1e-12 relative to its own max-norm), the drives' kernels (actuator
 * rates, passive force, the passive force inside eom) included; the fused
 * kernels against the separate ones, h against the Christoffel symbols of
 * M by finite differences, limb 4 against limb 3 mirrored (four limbs,
 * spec section 12), and NaN on every output where q is unreachable or not
 * finite. */
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "prru_mechanism.h"
#include "prru_ref.h"
#include "testref.h"
#include "testutil.h"

#define PI 3.14159265358979323846
#define NSTATE 2000
#define NB PRRU_NBODY
#define NW (6 * PRRU_NBODY)
#define NL PRRU_NLAMBDA
#define NA PRRU_NACT
#define MARGIN 0.1 /* see margin() */

static prru_ref_params P;
static prru_ref_ws *W;

/* Worst relative error per output, over all states. */
enum {
  O_IK, O_JD, O_IKJD_D, O_IKJD_J, O_JAC, O_BT, O_MASS, O_BIAS, O_GRAV, O_DYN_M, O_DYN_H, O_DYN_G,
  O_EOM_M, O_EOM_B, O_EOM_QDD, O_PJ, O_POSE_R, O_POSE_P, O_IW, O_WB, O_EN, O_AR_DD, O_AR_DDB,
  O_PASSIVE, O_Q, O_COUNT
};
static const char *names[O_COUNT] = {
  "ik", "jd", "ik_jd d", "ik_jd Jd", "jacobians", "bias_terms", "mass", "bias", "gravity",
  "dynamics M", "dynamics h", "dynamics G", "eom M", "eom b", "eom qdd", "platform_jacobian",
  "poses R", "poses p", "inertia_world", "wrench_bias", "energy", "actuator_rates dd",
  "actuator_rates ddb", "passive", "reaction_basis"};
static double worst[O_COUNT], worst_near[O_COUNT], worst_near_raw[O_COUNT];
/* Margin of the state being compared (see margin()); below MARGIN its
 * errors are also kept scaled by (margin / MARGIN)^2. */
static double state_margin = 1.0;

/* The error of one output relative to its own max-norm, or to floor where
 * that is larger (an output that is a sum of large terms cancelling near 0
 * is only defined to the rounding of those terms). */
static void note_floor(int o, const double *kernel, const double *ref, int n, double floor)
{
  double e = tu_relerr(kernel, ref, n, floor);
  if (state_margin >= MARGIN) {
    if (!(e <= worst[o])) worst[o] = e; /* keeps NaN */
    return;
  }
  if (!(e <= worst_near_raw[o])) worst_near_raw[o] = e;
  const double es = e * (state_margin / MARGIN) * (state_margin / MARGIN);
  if (!(es <= worst_near[o])) worst_near[o] = es;
}

static void note(int o, const double *kernel, const double *ref, int n)
{
  note_floor(o, kernel, ref, n, 1e-300);
}

/* Every generated kernel's outputs at one state. */
typedef struct {
  double d[NA], Jd[3 * NA], d2[NA], Jd2[3 * NA], H[3 * NW], dm[NW], M[9], h[3], G[3], M2[9], h2[3], G2[3];
  double Me[9], be[3], JP[18], R[9 * NB], p[3 * NB], I[9 * NB], K[NW], E[2], dd[NA], ddb[NA];
  double Qp[3], Q[NW * NL], Qnz[PRRU_REACTION_BASIS_NNZ];
} kernel_outputs;

static void eval_all(const double q[3], const double qd[3], const double fd[NA],
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
  prru_actuator_rates(q, qd, o->dd, o->ddb);
  prru_passive(q, qd, o->Qp);
  prru_reaction_basis(q, o->Qnz);
  tu_reaction_basis_scatter(o->Qnz, o->Q);
}

/* M x = b by GSL's LU: the kernels' qdd, to compare with the reference's
 * forward dynamics (its own Cholesky of its own M and right-hand side). */
static void solve3(const double A[9], const double b[3], double x[3])
{
  double a[9], bb[3];
  int sign;
  memcpy(a, A, sizeof a);
  memcpy(bb, b, sizeof bb);
  gsl_matrix_view av = gsl_matrix_view_array(a, 3, 3);
  gsl_vector_view bv = gsl_vector_view_array(bb, 3), xv = gsl_vector_view_array(x, 3);
  gsl_permutation *perm = gsl_permutation_alloc(3);
  gsl_linalg_LU_decomp(&av.matrix, perm, &sign);
  gsl_linalg_LU_solve(&av.matrix, perm, &bv.vector, &xv.vector);
  gsl_permutation_free(perm);
}

/* A reachable q of the model: any q1, q2 of a half turn and any height
 * within twice the longest limb, rejected where the reference's inverse
 * kinematics has no solution. */
static double machine_size(void)
{
  double s = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) s = fmax(s, P.l1[i] + P.l2[i]);
  return s;
}

static int random_q(double q[3])
{
  const double L = machine_size();
  double d[NA];
  int tries = 0;
  do {
    q[0] = tu_uniform(-PI / 2, PI / 2);
    q[1] = tu_uniform(-PI / 2, PI / 2);
    q[2] = tu_uniform(-2 * L, 2 * L);
    tries++;
  } while (prru_ref_ik(&P, q, d) != GSL_SUCCESS);
  return tries - 1;
}

/* At margin m (testref.h) below MARGIN the inverse kinematics is
 * ill-conditioned: 1 - r^2 carries an absolute rounding error ~eps, so
 * both sides' d, J_d, Jd' qd, ... are only defined to ~eps / (1 - r^2),
 * whatever formulas compute them. So there the error is held to the same
 * 1e-12 after taking that factor out, i.e. scaled by (m / MARGIN)^2; at
 * m >= MARGIN it is held to 1e-12 as it is. */
static double margin(const double q[3]) { return ref_margin(&P, q); }

static void test_against_reference(void)
{
  int states = 0, skipped = 0, ref_fail = 0, nnear = 0;
  double fused = 0;
  static double Qr[NW * NL];
  while (states < NSTATE) {
    double q[3], qd[3], fd[NA], fp[3], mp[3];
    skipped += random_q(q);
    for (int i = 0; i < 3; i++) {
      qd[i] = tu_uniform(-1.15, 1.15); /* |qd| <= 2 */
      fd[i] = tu_uniform(-60, 60);
      fp[i] = tu_uniform(-30, 30);
      mp[i] = tu_uniform(-3, 3);
    }
    for (int i = 3; i < NA; i++) fd[i] = tu_uniform(-60, 60); /* limb 4 */
    /* Every third state slowly, where the drives' tanh(dd / v_s) is not
     * saturated. */
    if (states % 3 == 0)
      for (int i = 0; i < 3; i++) qd[i] *= 1e-3;
    states++;
    state_margin = margin(q);
    nnear += state_margin < MARGIN;
    double d_r[NA], Jd_r[3 * NA], H_r[3 * NW], dm_r[NW], M_r[9], h_r[3], G_r[3], R_r[9 * NB], p_r[3 * NB];
    double E_r[2], dd_r[NA], ddb_r[NA], Qp_r[3], qdd_r[3];
    int st = prru_ref_ik(&P, q, d_r) | prru_ref_jd(&P, q, Jd_r) | prru_ref_jacobians(&P, W, q, H_r) |
             prru_ref_bias_terms(&P, W, q, qd, dm_r) | prru_ref_poses(&P, q, R_r, p_r) |
             prru_ref_energy(&P, W, q, qd, E_r) | prru_ref_reaction_basis(&P, W, q, Qr) |
             prru_ref_actuator_rates(&P, q, qd, dd_r, ddb_r) | prru_ref_passive(&P, W, q, qd, Qp_r) |
             prru_ref_forward_dynamics(&P, W, q, qd, fd, fp, mp, qdd_r);
    /* Last: the workspace keeps this state's Phi and K for inertia_world
     * and wrench_bias. */
    st |= prru_ref_dynamics(&P, W, q, qd, M_r, h_r, G_r);
    if (st) { ref_fail++; continue; }
    double I_r[9 * NB], K_r[NW];
    for (int b = 0; b < NB; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) I_r[9 * b + 3 * i + j] = gsl_matrix_get(W->Phi, 3 * b + i, 3 * b + j);
    for (int i = 0; i < NW; i++) K_r[i] = gsl_vector_get(W->K, i);
    /* The platform Jacobian the kernel returns: J_R,P and the velocity
     * Jacobian of the tool point O' = (0, 0, q3) (spec section 1), which is
     * e3 e3^T whatever the platform's centre of mass. */
    double JP_r[18];
    memcpy(JP_r, H_r + 3 * 3 * prru_mech.platform, 9 * sizeof(double));
    memset(JP_r + 9, 0, 9 * sizeof(double));
    JP_r[17] = 1.0;
    /* b = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp + Qp - h from the
     * reference's pieces. */
    double b_r[3];
    for (int j = 0; j < 3; j++) {
      b_r[j] = G_r[j] - h_r[j] + Qp_r[j];
      for (int i = 0; i < NA; i++) b_r[j] += Jd_r[3 * i + j] * fd[i];
      for (int i = 0; i < 3; i++) b_r[j] += JP_r[9 + 3 * i + j] * fp[i] + JP_r[3 * i + j] * mp[i];
    }

    static kernel_outputs ko;
    eval_all(q, qd, fd, fp, mp, &ko);
    double qdd[3];
    solve3(ko.Me, ko.be, qdd);

    note(O_IK, ko.d, d_r, NA);
    note(O_JD, ko.Jd, Jd_r, 3 * NA);
    note(O_IKJD_D, ko.d2, d_r, NA);
    note(O_IKJD_J, ko.Jd2, Jd_r, 3 * NA);
    note(O_JAC, ko.H, H_r, 3 * NW);
    note(O_BT, ko.dm, dm_r, NW);
    note(O_MASS, ko.M, M_r, 9);
    note(O_BIAS, ko.h, h_r, 3);
    note(O_GRAV, ko.G, G_r, 3);
    note(O_DYN_M, ko.M2, M_r, 9);
    note(O_DYN_H, ko.h2, h_r, 3);
    note(O_DYN_G, ko.G2, G_r, 3);
    note(O_EOM_M, ko.Me, M_r, 9);
    note(O_EOM_B, ko.be, b_r, 3);
    note(O_EOM_QDD, qdd, qdd_r, 3);
    note(O_PJ, ko.JP, JP_r, 18);
    note(O_POSE_R, ko.R, R_r, 9 * NB);
    note(O_POSE_P, ko.p, p_r, 3 * NB);
    note(O_IW, ko.I, I_r, 9 * NB);
    note(O_WB, ko.K, K_r, NW);
    /* V = -sum m_b g . p_b is a sum of terms that cancel where the
     * machine's centre of mass crosses the level of {S}'s origin: its
     * scale is the size of those terms. */
    double Vterms = 0;
    for (int b = 0; b < NB; b++)
      for (int k = 0; k < 3; k++) Vterms += fabs(P.mass[b] * P.g[k] * p_r[3 * b + k]);
    note_floor(O_EN, ko.E, E_r, 2, Vterms);
    note(O_AR_DD, ko.dd, dd_r, NA);
    note(O_AR_DDB, ko.ddb, ddb_r, NA);
    note(O_PASSIVE, ko.Qp, Qp_r, 3);
    note(O_Q, ko.Q, Qr, NW * NL);

    /* Fused kernels against the separate ones. */
    double f[6] = {tu_relerr(ko.d2, ko.d, NA, 1e-300), tu_relerr(ko.Jd2, ko.Jd, 3 * NA, 1e-300),
                   tu_relerr(ko.M2, ko.M, 9, 1e-300), tu_relerr(ko.h2, ko.h, 3, 1e-300),
                   tu_relerr(ko.G2, ko.G, 3, 1e-300), tu_relerr(ko.Me, ko.M, 9, 1e-300)};
    for (int i = 0; i < 6; i++)
      if (!(f[i] <= fused)) fused = f[i];
  }
  tu_check(ref_fail == 0, "reference evaluates wherever its ik does", ref_fail, 0);
  printf("kernels vs reference, model %s: %d reachable states (%d unreachable skipped), %d of them"
         " within margin %.2g of a singular boundary\n", prru_mech.name, states, skipped, nnear, MARGIN);
  printf("  %-18s %-9s %s\n", "output", "worst", "near the boundary: scaled (raw)");
  for (int o = 0; o < O_COUNT; o++) {
    char what[96];
    snprintf(what, sizeof what, "kernel %s = reference", names[o]);
    tu_check(worst[o] <= 1e-12, what, worst[o], 1e-12);
    snprintf(what, sizeof what, "kernel %s = reference near the boundary, scaled", names[o]);
    tu_check(worst_near[o] <= 1e-12, what, worst_near[o], 1e-12);
    printf("  %-18s %.1e   %.1e (%.1e)\n", names[o], worst[o], worst_near[o], worst_near_raw[o]);
  }
  tu_check(fused <= 1e-15, "fused kernels (ik_jd, dynamics, eom) = separate ones", fused, 1e-15);
  printf("  fused vs separate  %.1e\n", fused);
}

/* h_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k: the bias forces
 * are the Christoffel form of M's derivatives (4th-order central FD; the
 * armature's J_d^T K J_d and J_d^T K Jd' qd are one more such pair). The
 * step is 1e-3 times the squared margin: near a singular boundary M varies
 * on a length that shrinks like the margin squared, and the step follows
 * it so that truncation stays ~1e-12 of h; states within 0.3 of the
 * boundary are left out (rounding ~eps / step would dominate there). */
static void test_christoffel(void)
{
  double worst_c = 0;
  int used = 0;
  while (used < 200) {
    double q[3], qd[3];
    random_q(q);
    const double m = margin(q);
    if (m < 0.3) continue;
    const double step = 1e-3 * m * m;
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
    used++;
    if (bad) { worst_c = NAN; continue; }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++) hc[i] += (dM[k][3 * i + j] - 0.5 * dM[i][3 * j + k]) * qd[j] * qd[k];
    prru_bias(q, qd, h);
    double e = tu_relerr(h, hc, 3, 1e-300);
    if (!(e <= worst_c)) worst_c = e;
  }
  tu_check(worst_c <= 1e-8, "h = Christoffel form of dM/dq (FD)", worst_c, 1e-8);
  printf("Christoffel consistency (%d states): %.1e\n", used, worst_c);
}

/* Limb 4 mirrors limb 3 (spec section 12): where the descriptor gives
 * limbs 3 and 4 the same b, l1 and l2, the kernels' d_4(q1, q2, q3) =
 * d_3(q1, -q2, q3) and the other way round, and J_d's rows 3 and 4 follow
 * with the q2 column negated (reflection in the plane x = 0). */
static void test_mirror(void)
{
  if (PRRU_NLIMB != 4) return;
  const int l3 = 2, l4 = PRRU_NLIMB - 1;
  if (!(prru_mech.b[l4] == prru_mech.b[l3] && prru_mech.l1[l4] == prru_mech.l1[l3] &&
        prru_mech.l2[l4] == prru_mech.l2[l3])) {
    printf("mirror: limbs 3 and 4 differ in b, l1 or l2; not checked\n");
    return;
  }
  double e_d = 0, e_j = 0;
  for (int n = 0; n < 500; n++) {
    double q[3], d[NA], dm[NA], J[3 * NA], Jm[3 * NA];
    random_q(q);
    const double qm[3] = {q[0], -q[1], q[2]};
    prru_ik_jd(q, d, J);
    prru_ik_jd(qm, dm, Jm);
    const double a[2] = {d[l4], d[l3]}, b[2] = {dm[l3], dm[l4]};
    const double ja[6] = {J[3 * l4], J[3 * l4 + 1], J[3 * l4 + 2], J[3 * l3], J[3 * l3 + 1], J[3 * l3 + 2]};
    const double jb[6] = {Jm[3 * l3], -Jm[3 * l3 + 1], Jm[3 * l3 + 2], Jm[3 * l4], -Jm[3 * l4 + 1], Jm[3 * l4 + 2]};
    const double ed = tu_relerr(a, b, 2, 1e-300), ej = tu_relerr(ja, jb, 6, 1e-300);
    if (!(ed <= e_d)) e_d = ed; /* keeps NaN */
    if (!(ej <= e_j)) e_j = ej;
  }
  tu_check(e_d <= 1e-15, "kernel d_4(q1, q2, q3) = d_3(q1, -q2, q3) and d_3 = d_4 mirrored", e_d, 1e-15);
  tu_check(e_j <= 1e-15, "kernel J_d rows 3, 4 mirror each other (q2 column negated)", e_j, 1e-15);
  printf("mirror (500 states): d %.1e, J_d %.1e\n", e_d, e_j);
}

static int all_nan(const double *x, int n)
{
  for (int i = 0; i < n; i++)
    if (!isnan(x[i])) return 0;
  return 1;
}

/* The first q along q = t e_axis, t in (0, pi], that the model cannot
 * reach (by the reference's inverse kinematics): q1 takes limbs 1, 2 past
 * their reach (limb 3 keeps gamma = 0 at q2 = 0), q2 takes limb 3 (limbs
 * 1, 2 keep q1 = 0). q = 0 is reachable in every valid model; one that
 * reaches a whole half turn has no such q and returns 0. */
static int unreachable_along(int axis, double q[3])
{
  double d[NA];
  for (int k = 1; k <= 3142; k++) {
    q[0] = q[1] = 0;
    q[2] = -0.5;
    q[axis] = 1e-3 * k;
    if (prru_ref_ik(&P, q, d) == GSL_EDOM) return 1;
  }
  return 0;
}

static void test_nan_outputs(void)
{
  double bad[6][3] = {{NAN, 0, -0.8}, {0, INFINITY, -0.8}, {0, 0, -INFINITY}, {0, 0, NAN}};
  int nbad = 4;
  for (int axis = 0; axis < 2; axis++)
    if (unreachable_along(axis, bad[nbad])) nbad++;
    else printf("no unreachable q along q%d in (0, pi]\n", axis + 1);
  const double qd[3] = {0.1, -0.2, 0.3}, f3[4] = {1, 2, 3, 4}; /* f3[0..NA-1]: fd */
  for (int c = 0; c < nbad; c++) {
    const double *q = bad[c];
    static kernel_outputs ko;
    eval_all(q, qd, f3, f3, f3, &ko);
    const struct { const char *name; const double *x; int n; } out[] = {
      {"ik", ko.d, NA}, {"jd", ko.Jd, 3 * NA}, {"ik_jd d", ko.d2, NA}, {"ik_jd Jd", ko.Jd2, 3 * NA},
      {"jacobians", ko.H, 3 * NW}, {"bias_terms", ko.dm, NW}, {"mass", ko.M, 9}, {"bias", ko.h, 3},
      {"gravity", ko.G, 3}, {"dynamics M", ko.M2, 9}, {"dynamics h", ko.h2, 3},
      {"dynamics G", ko.G2, 3}, {"eom M", ko.Me, 9}, {"eom b", ko.be, 3},
      {"platform_jacobian", ko.JP, 18}, {"poses R", ko.R, 9 * NB}, {"poses p", ko.p, 3 * NB},
      {"inertia_world", ko.I, 9 * NB}, {"wrench_bias", ko.K, NW}, {"energy", ko.E, 2},
      {"actuator_rates dd", ko.dd, NA}, {"actuator_rates ddb", ko.ddb, NA}, {"passive", ko.Qp, 3},
      {"reaction_basis", ko.Qnz, PRRU_REACTION_BASIS_NNZ}};
    for (size_t o = 0; o < sizeof out / sizeof out[0]; o++) {
      char what[112];
      snprintf(what, sizeof what, "q (%g, %g, %g): %s all NaN", q[0], q[1], q[2], out[o].name);
      TU_TRUE(all_nan(out[o].x, out[o].n), what);
    }
  }
  printf("NaN outputs checked at %d unreachable or non-finite q\n", nbad);
}

/* prru_reaction_basis returns the entries of Q that are not identically
 * zero (the comparison with the reference, through the dense Q, shows the
 * others are zero): its index table is strictly increasing inside the dense
 * 6 NBODY x NLAMBDA matrix, and every entry it keeps is nonzero at some
 * state, so the output holds no padding. */
static void test_reaction_basis_pattern(void)
{
  int increasing = 1;
  for (int k = 0; k < PRRU_REACTION_BASIS_NNZ; k++) {
    const int at = prru_reaction_basis_index[k];
    increasing &= at >= 0 && at < NW * NL && (k == 0 || at > prru_reaction_basis_index[k - 1]);
  }
  TU_TRUE(increasing, "reaction_basis index table increasing, inside 6 NBODY x NLAMBDA");
  static int seen[PRRU_REACTION_BASIS_NNZ];
  for (int s = 0, found = 0; s < 200 && found < 20; s++) {
    double q[3], nz[PRRU_REACTION_BASIS_NNZ];
    random_q(q);
    if (ref_margin(&P, q) < MARGIN) continue;
    found++;
    prru_reaction_basis(q, nz);
    for (int k = 0; k < PRRU_REACTION_BASIS_NNZ; k++) seen[k] |= nz[k] != 0.0;
  }
  int zero = 0;
  for (int k = 0; k < PRRU_REACTION_BASIS_NNZ; k++) zero += !seen[k];
  char what[96];
  snprintf(what, sizeof what, "reaction_basis: %d kept entries zero at every state", zero);
  TU_TRUE(zero == 0, what);
  printf("reaction_basis: %d of %d entries of Q kept\n", PRRU_REACTION_BASIS_NNZ, NW * NL);
}

int main(void)
{
  prru_ref_params_default(&P);
  W = prru_ref_alloc();
  if (!W) { fprintf(stderr, "prru_ref_alloc failed\n"); return 1; }
  test_against_reference();
  test_christoffel();
  test_mirror();
  test_nan_outputs();
  test_reaction_basis_pattern();
  prru_ref_free(W);
  return tu_finish("test_kernels");
}
