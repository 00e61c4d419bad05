/* Runtime properties that hold for any valid model: the work-energy
 * balance (with the drives' dissipation), inverse of the forward dynamics,
 * FK(IK) and its seed, tolerance and residual, reactions (H^T Q = 0,
 * platform Newton-Euler, machine force balance, agreement with the dense
 * reference), the integrators against an independent RK4, clean stops,
 * bounded integrator work (tolerance floor,
 * step budget, interrupts inside a step), msbdf at the workspace boundary,
 * parsing. The paper's scenario is checked in paper_runtime.c.
 * Models with 3 or 4 actuators (spec section 12): sizes follow PRRU_NACT;
 * with a redundant actuator ID(FD(fd)) is fd less its component along the
 * actuator null vector and FD(ID(qdd)) = qdd, limb 4's U-joint moment axis
 * is w x x4 (x4 = -R_L4 e1), FK refuses sliders no pose reproduces, and
 * the simulations' constant loads are built from the model's static
 * actuator forces. test_redundant.c checks the redundancy itself. */
#define _XOPEN_SOURCE 700 /* setitimer, sigaction, clock_gettime, write, _exit */
#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "testbuild.h"
#include "prru.h"
#include "prru_ref.h"
#include "testsim.h"
#include "testutil.h"

static prru_model model;
static prru_data data;

static void random_state(double q[3], double qd[3]) { ts_random_state(&model, &data, q, qd); }

static int all_finite(const double *v, int n)
{
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

static double dot_n(const double *a, const double *b, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* A pose out of reach: q1 raised until the inverse kinematics fails. */
static void unreachable_pose(double q[3])
{
  q[0] = 0.0, q[1] = 0.0, q[2] = -0.8;
  double d[PRRU_NACT];
  do {
    q[0] += 0.01;
    prru_ik(q, d);
  } while (all_finite(d, PRRU_NACT) && q[0] < 3.2);
}

/* Every actuator force, fp and mp; the draws for the first three
 * actuators come in the order they always did, so a 3-limb model sees the
 * same loads as before redundant actuators existed. */
static void random_loads(prru_loads *l)
{
  for (int i = 0; i < 3; i++) {
    l->fd[i] = tu_uniform(-60, 60);
    l->fp[i] = tu_uniform(-30, 30);
    l->mp[i] = tu_uniform(-3, 3);
  }
  for (int i = 3; i < PRRU_NACT; i++) l->fd[i] = tu_uniform(-60, 60);
}

static void mat3vec(const double *A, int stride, const double x[3], double y[3])
{
  for (int i = 0; i < 3; i++)
    y[i] = A[i * stride] * x[0] + A[i * stride + 1] * x[1] + A[i * stride + 2] * x[2];
}

/* ---- forward/inverse dynamics, FK ---- */
/* ID(FD(fd)) = fd for three actuators. With redundant ones (spec section
 * 12) every fd + t n (n = prru_actuator_null: J_d^T n = 0) moves the robot
 * alike and ID returns the one of least norm, so it must return fd's
 * projection fd - (fd . n) n off the null direction, and FD(ID(qdd)) must
 * give qdd back. */
static void test_inverse_of_forward(void)
{
  double worst = 0, worst_ref = 0, worst_fdid = 0;
  for (int k = 0; k < 500; k++) {
    double q[3], qd[3], qdd[3], fd[PRRU_NACT], want[PRRU_NACT];
    prru_loads l;
    random_state(q, qd);
    random_loads(&l);
    if (prru_forward_dynamics(&model, &data, q, qd, &l, qdd) != PRRU_OK) { TU_TRUE(0, "fd status"); continue; }
    if (prru_inverse_dynamics(&model, &data, q, qd, qdd, &l, fd) != PRRU_OK) { TU_TRUE(0, "id status"); continue; }
    memcpy(want, l.fd, sizeof want);
    if (PRRU_NPRELOAD > 0) {
      double n[PRRU_NACT];
      if (!TU_TRUE(prru_actuator_null(&model, &data, q, n) == PRRU_OK, "actuator null vector status"))
        continue;
      const double t = dot_n(l.fd, n, PRRU_NACT);
      for (int i = 0; i < PRRU_NACT; i++) want[i] -= t * n[i];
      prru_loads li = l;
      double a[3];
      memcpy(li.fd, fd, sizeof fd);
      if (TU_TRUE(prru_forward_dynamics(&model, &data, q, qd, &li, a) == PRRU_OK, "FD(ID) status"))
        worst_fdid = fmax(worst_fdid, tu_relerr(a, qdd, 3, 1.0));
    }
    worst = fmax(worst, tu_relerr(fd, want, PRRU_NACT, 1.0));
    /* The runtime's unrolled solve against GSL in the reference. */
    static prru_ref_params p;
    static prru_ref_ws *w;
    if (!w) { prru_ref_params_default(&p); w = prru_ref_alloc(); }
    double qdd_ref[3];
    prru_ref_forward_dynamics(&p, w, q, qd, l.fd, l.fp, l.mp, qdd_ref);
    worst_ref = fmax(worst_ref, tu_relerr(qdd, qdd_ref, 3, 1e-3));
  }
  if (PRRU_NPRELOAD == 0) {
    printf("ID(FD) %.1e, FD vs reference solve %.1e\n", worst, worst_ref);
    tu_check(worst <= 1e-10, "inverse dynamics of forward dynamics returns fd", worst, 1e-10);
  } else {
    printf("ID(FD) vs fd - (fd . n) n %.1e, FD(ID(qdd)) %.1e, FD vs reference solve %.1e\n", worst,
           worst_fdid, worst_ref);
    tu_check(worst <= 1e-10, "inverse dynamics of forward dynamics returns fd less its preload along n",
             worst, 1e-10);
    tu_check(worst_fdid <= 1e-10, "forward dynamics of inverse dynamics returns qdd", worst_fdid, 1e-10);
  }
  tu_check(worst_ref <= 1e-10, "forward dynamics agrees with the reference's GSL solve", worst_ref, 1e-10);
}

static void test_fk(void)
{
  double worst = 0;
  int fails = 0;
  for (int k = 0; k < 300; k++) {
    double q[3], qd[3], act[PRRU_NACT], seed[3], sol[3];
    random_state(q, qd);
    prru_ik(q, act);
    for (int i = 0; i < 3; i++) seed[i] = q[i] + tu_uniform(-0.05, 0.05);
    if (prru_forward_kinematics(&model, &data, act, seed, sol) != PRRU_OK) { fails++; continue; }
    worst = fmax(worst, tu_relerr(sol, q, 3, 1.0));
  }
  tu_check(fails == 0, "FK converges from a nearby seed", fails, 0);
  printf("FK(IK(q)) %.1e\n", worst);
  tu_check(worst <= 1e-12, "FK(IK(q)) = q", worst, 1e-12);
  /* Out of reach: sliders far apart vertically (limb 1 2 m above limb 2;
   * any further slider at 0). */
  double act[PRRU_NACT] = {1.0, -1.0, 0.0}, seed[3] = {0, 0, -0.2}, sol[3];
  TU_TRUE(prru_forward_kinematics(&model, &data, act, seed, sol) == PRRU_ENOCONV,
          "FK of an unreachable d fails with PRRU_ENOCONV");
  if (PRRU_NPRELOAD > 0) {
    /* Every slider within reach, but no pose puts all of them there: the
     * sliders of a reachable pose with the last one moved by 1 cm. */
    const double q[3] = {0.1, -0.05, -0.8};
    prru_ik(q, act);
    act[PRRU_NACT - 1] += 0.01;
    for (int i = 0; i < 3; i++) seed[i] = q[i];
    TU_TRUE(prru_forward_kinematics(&model, &data, act, seed, sol) == PRRU_ENOCONV,
            "FK of sliders no pose reproduces fails with PRRU_ENOCONV");
  }
  double bad[PRRU_NACT] = {NAN, 0, 0};
  TU_TRUE(prru_forward_kinematics(&model, &data, bad, seed, sol) == PRRU_EINPUT, "FK of NaN d");
}

/* The pieces prru fk and Model.fk use around the solvers.
 * prru_fk_tolerance: its documented rule, 1000 DBL_EPSILON max(L, |act|),
 * exactly (the same operations on the same doubles), on sliders shorter
 * than L and with one far down its rail.
 * prru_fk_default_seed, at level and tilted regular poses q with act =
 * d(q): (0, 0, h), regular; at a level pose it reproduces act within the
 * tolerance (d_i = q3 + d_i(0, 0, 0) up to the kernel's rounding, far
 * below 1000 ulps); prru_forward_kinematics and its least-squares
 * variant converge from it to q. Bound on q: the answer's residual r is
 * at most tol, and q_sol - q = J_d^+ (d(q_sol) - d(q)) to first order,
 * so |q_sol,i - q_i| <= sum_j |J_d^+_ij| tol; allowed twice that for the
 * kernel's own rounding of d at both points (tens of operations: well
 * under tol / 2, 500 ulps of the scale) and the second-order term.
 * prru_fk_residual: bit for bit the least-squares solver's residual at
 * its answer (the same kernel and operations); against the GSL
 * reference's d_ref(q) with act = d_ref + delta (delta ~ 1e-4 L, so the
 * norm is what is checked), |res - res_ref| <= max_i |d_i - d_ref_i| +
 * u / (1 - u) (res + res_ref): max_i |x_i| moves by at most
 * max_i |x_i - y_i| (triangle inequality), and each side rounds its
 * differences once (u = DBL_EPSILON / 2); NaN out of reach or for NaN
 * sliders. */
static void test_fk_helpers(void)
{
  const double L = prru_length_scale(model.mech), u = DBL_EPSILON / 2;
  double small[PRRU_NACT], big[PRRU_NACT];
  for (int i = 0; i < PRRU_NACT; i++) small[i] = big[i] = 0.25 * L * (i % 2 ? -1 : 1);
  big[PRRU_NACT - 1] = -40 * L;
  TU_TRUE(prru_fk_tolerance(&model, small) == 1000 * DBL_EPSILON * L &&
              prru_fk_tolerance(&model, big) == 1000 * DBL_EPSILON * fabs(big[PRRU_NACT - 1]),
          "prru_fk_tolerance = 1000 eps max(L, |act|_inf)");
  static const double poses[5][3] = {
      {0, 0, -0.8}, {0, 0, -0.65}, {0.1, 0.2, -0.8}, {-0.15, 0.1, -0.7}, {0.2, -0.25, -0.9}};
  prru_ref_params P;
  prru_ref_params_default(&P);
  int checked = 0;
  double worst_q = 0, worst_res = 0;
  for (int p = 0; p < 5; p++) {
    const double *q = poses[p];
    if (prru_check_regular(&model, &data, q, NULL) != PRRU_OK) continue;
    double act[PRRU_NACT], rows[3] = {0, 0, 0}, seed[3], sol[3], fit[3], res_fit = NAN;
    memcpy(act, data.d, sizeof act);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < PRRU_NACT; j++) rows[i] += fabs(data.Jdpinv[PRRU_NACT * i + j]);
    const double tol = prru_fk_tolerance(&model, act);
    prru_fk_default_seed(&model, act, seed);
    char what[200];
    snprintf(what, sizeof what, "pose %d: the default seed is (0, 0, h) and regular", p);
    TU_TRUE(seed[0] == 0 && seed[1] == 0 && prru_check_regular(&model, &data, seed, NULL) == PRRU_OK, what);
    if (q[0] == 0 && q[1] == 0) {
      const double r = prru_fk_residual(&model, seed, act);
      snprintf(what, sizeof what, "pose %d (level): the default seed reproduces the sliders within tol", p);
      tu_check(r <= tol, what, r, tol);
    }
    snprintf(what, sizeof what, "pose %d: Newton and least squares converge from the default seed", p);
    if (!TU_TRUE(prru_forward_kinematics(&model, &data, act, seed, sol) == PRRU_OK &&
                     prru_forward_kinematics_lsq(&model, &data, act, seed, fit, &res_fit) == PRRU_OK,
                 what))
      continue;
    for (int i = 0; i < 3; i++) {
      worst_q = fmax(worst_q, fabs(sol[i] - q[i]) / (2 * rows[i] * tol));
      worst_q = fmax(worst_q, fabs(fit[i] - q[i]) / (2 * rows[i] * tol));
    }
    const double r_sol = prru_fk_residual(&model, sol, act);
    snprintf(what, sizeof what, "pose %d: FK's residual within tol, the least-squares one bit for bit", p);
    TU_TRUE(r_sol <= tol && res_fit <= tol && res_fit == prru_fk_residual(&model, fit, act), what);
    /* Against the reference's d. */
    double d_ref[PRRU_NACT], off[PRRU_NACT], dk = 0, res_ref = 0;
    if (!TU_TRUE(prru_ref_ik(&P, q, d_ref) == GSL_SUCCESS, "reference ik")) continue;
    for (int i = 0; i < PRRU_NACT; i++) {
      off[i] = d_ref[i] + 1e-4 * L * (i + 1) * (i % 2 ? -1 : 1);
      dk = fmax(dk, fabs(act[i] - d_ref[i]));
      res_ref = fmax(res_ref, fabs(d_ref[i] - off[i]));
    }
    const double res = prru_fk_residual(&model, q, off);
    const double bound = dk + u / (1 - u) * (res + res_ref);
    worst_res = fmax(worst_res, fabs(res - res_ref) / bound);
    snprintf(what, sizeof what, "pose %d: prru_fk_residual = max |d_ref - act| within the rounding", p);
    tu_check(fabs(res - res_ref) <= bound, what, fabs(res - res_ref) / bound, 1.0);
    checked++;
  }
  printf("FK from the default seed at %d poses: q within %.2g of its bound; residual vs reference %.2g of its bound\n",
         checked, worst_q, worst_res);
  tu_check(worst_q <= 1.0, "FK from the default seed: |q_sol - q| <= 2 |J_d^+| tol", worst_q, 1.0);
  TU_TRUE(checked >= 4, "FK helpers checked at 4 or more regular poses");
  double far[3], bad[PRRU_NACT];
  unreachable_pose(far);
  memcpy(bad, small, sizeof bad);
  bad[0] = NAN;
  TU_TRUE(isnan(prru_fk_residual(&model, far, small)) && isnan(prru_fk_residual(&model, poses[0], bad)),
          "prru_fk_residual: NaN out of reach and for NaN sliders");
}

static void test_bad_input(void)
{
  double q[3] = {0.1, 0.2, -0.8}, qd[3] = {0, 0, 0}, qdd[3], fd[PRRU_NACT];
  prru_loads l;
  memset(&l, 0, sizeof l);
  double far[3];
  unreachable_pose(far);
  TU_TRUE(prru_forward_dynamics(&model, &data, far, qd, &l, qdd) == PRRU_EUNREACHABLE, "FD unreachable q");
  double T, V, huge_qd[3] = {1e200, 0, 0};
  TU_TRUE(prru_energies(&model, far, qd, &T, &V) == PRRU_EUNREACHABLE, "energies at an unreachable q");
  TU_TRUE(prru_energies(&model, q, huge_qd, &T, &V) == PRRU_EINPUT,
          "energies overflowing at a reachable q: bad input, not unreachable");
  double nanq[3] = {NAN, 0, -0.8};
  TU_TRUE(prru_forward_dynamics(&model, &data, nanq, qd, &l, qdd) == PRRU_EINPUT, "FD NaN q");
  double infqd[3] = {0, INFINITY, 0};
  TU_TRUE(prru_forward_dynamics(&model, &data, q, infqd, &l, qdd) == PRRU_EINPUT, "FD infinite qd");
  l.fd[1] = NAN;
  TU_TRUE(prru_forward_dynamics(&model, &data, q, qd, &l, qdd) == PRRU_EINPUT, "FD NaN force");
  l.fd[1] = 0;
  TU_TRUE(prru_inverse_dynamics(&model, &data, far, qd, qd, &l, fd) == PRRU_EUNREACHABLE, "ID unreachable");
  /* J_d singular: limb 3's upper link horizontal makes d_3 stationary; find
   * the q3 where rcond vanishes along q1 = q2 = 0 is not needed: a state with
   * rcond just below the model tolerance is built by raising the tolerance. */
  prru_model strict = model;
  strict.jd_rcond_min = 0.5;
  TU_TRUE(prru_inverse_dynamics(&strict, &data, q, qd, qd, &l, fd) == PRRU_ESINGULAR,
          "ID reports a singular J_d below the tolerance");
  TU_TRUE(strcmp(prru_strerror(PRRU_ESINGULAR), prru_strerror(PRRU_EUNREACHABLE)) != 0, "distinct messages");
}

/* Every input component of forward and inverse dynamics, made NaN, +inf
 * or -inf at a regular state and at a singular one (J_d below a raised
 * tolerance), must give PRRU_EINPUT, and the outputs stay untouched: the
 * runtime tests most inputs only through the kernels' outputs
 * (PRRU_UNSEEN_FINITE_*), so this holds only if the generator's analysis
 * of which inputs reach them is right. */
static void test_every_bad_input(void)
{
  static const double bad[3] = {NAN, INFINITY, -INFINITY};
  enum { NIN = 12 + PRRU_NACT + 3 };
  prru_model strict = model;
  strict.jd_rcond_min = 0.5;
  int fails = 0, n = 0;
  for (int s = 0; s < 2; s++) {
    const prru_model *m = s ? &strict : &model;
    double q[3], qd[3], qdd[3];
    prru_loads l;
    random_state(q, qd);
    random_loads(&l);
    for (int i = 0; i < 3; i++) qdd[i] = tu_uniform(-2, 2);
    double out[PRRU_NACT], fd0[PRRU_NACT];
    TU_TRUE(prru_forward_dynamics(m, &data, q, qd, &l, out) == PRRU_OK, "FD at the base state");
    TU_TRUE(prru_inverse_dynamics(m, &data, q, qd, qdd, &l, fd0) == (s ? PRRU_ESINGULAR : PRRU_OK),
            "ID at the base state");
    for (int k = 0; k < NIN; k++) {
      /* input k: q, qd, qdd, fd, fp, mp in that order */
      double *v = k < 3 ? &q[k] : k < 6 ? &qd[k - 3] : k < 9 ? &qdd[k - 6]
                  : k < 9 + PRRU_NACT ? &l.fd[k - 9] : k < 12 + PRRU_NACT ? &l.fp[k - 9 - PRRU_NACT]
                  : &l.mp[k - 12 - PRRU_NACT];
      const double saved = *v;
      for (int b = 0; b < 3; b++) {
        *v = bad[b];
        double o[PRRU_NACT] = {7, 7, 7};
        int ok = 1;
        if (k < 6 || k >= 9) { /* forward dynamics has no qdd */
          ok &= prru_forward_dynamics(m, &data, q, qd, &l, o) == PRRU_EINPUT;
          n++;
        }
        if (k < 9 || k >= 9 + PRRU_NACT) { /* inverse dynamics has no fd */
          ok &= prru_inverse_dynamics(m, &data, q, qd, qdd, &l, o) == PRRU_EINPUT;
          n++;
        }
        ok &= o[0] == 7 && o[1] == 7 && o[2] == 7;
        if (!ok) {
          fails++;
          printf("  input %d = %g (%s state): not PRRU_EINPUT, or output written\n", k, bad[b],
                 s ? "singular" : "regular");
        }
      }
      *v = saved;
    }
  }
  printf("forward and inverse dynamics: %d calls with one non-finite input, %d wrong\n", n, fails);
  TU_TRUE(fails == 0, "every non-finite input is PRRU_EINPUT");
}

/* ---- reactions ---- */
/* Joint j's lambda coordinates. */
static const double *joint_lambda(const double *lam, int j)
{
  return lam + prru_mech.joint[j].lambda_offset;
}

static void test_reactions(void)
{
  const prru_mechanism *me = &prru_mech;
  static double H[3 * PRRU_NH], dm[PRRU_NH], Q[PRRU_NH * PRRU_NLAMBDA], R[9 * PRRU_NBODY],
      p[3 * PRRU_NBODY], I[9 * PRRU_NBODY];
  const int T0 = 3 * PRRU_NBODY; /* first translational row */
  const double mP = me->mass[me->platform], *g = me->gravity;
  prru_ref_params rp;
  prru_ref_params_default(&rp);
  prru_ref_ws *w = prru_ref_alloc();
  double e_ref = 0, e_force = 0, e_moment = 0, e_machine = 0, e_htq = 0;
  for (int k = 0; k < 200; k++) {
    double q[3], qd[3], lam[PRRU_NLAMBDA], lam_ref[PRRU_NLAMBDA], qdd[3];
    prru_loads l;
    random_state(q, qd);
    random_loads(&l);
    if (prru_reactions(&model, &data, q, qd, &l, lam) != PRRU_OK) { TU_TRUE(0, "reactions status"); continue; }
    prru_ref_reactions(&rp, w, q, qd, l.fd, l.fp, l.mp, lam_ref);
    e_ref = fmax(e_ref, tu_relerr(lam, lam_ref, PRRU_NLAMBDA, 1.0));
    prru_forward_dynamics(&model, &data, q, qd, &l, qdd);
    prru_jacobians(q, H);
    prru_bias_terms(q, qd, dm);
    tu_reaction_basis_dense(q, Q);
    prru_poses(q, R, p);
    prru_inertia_world(q, I);
    /* H^T Q = 0, relative to |H| |Q| (Frobenius). */
    double nh = 0, nq = 0, mx = 0;
    for (int i = 0; i < 3 * PRRU_NH; i++) nh += H[i] * H[i];
    for (int i = 0; i < PRRU_NH * PRRU_NLAMBDA; i++) nq += Q[i] * Q[i];
    for (int a = 0; a < 3; a++)
      for (int c = 0; c < PRRU_NLAMBDA; c++) {
        double s = 0;
        for (int r = 0; r < PRRU_NH; r++) s += H[3 * r + a] * Q[PRRU_NLAMBDA * r + c];
        mx = fmax(mx, fabs(s));
      }
    e_htq = fmax(e_htq, mx / sqrt(nh * nq));
    /* Platform: U-joint wrenches (distal body: +), loads at O', gravity;
     * moments about the platform's centre p. */
    const double *pp = p + 3 * me->platform, *RP = R + 9 * me->platform;
    double acc[3], alpha[3], om[3], Iom[3], gyro[3];
    mat3vec(H + 3 * (T0 + 3 * me->platform), 3, qdd, acc); /* J_T,P qdd */
    mat3vec(H + 9 * me->platform, 3, qdd, alpha);          /* J_R,P qdd */
    mat3vec(H + 9 * me->platform, 3, qd, om);
    for (int i = 0; i < 3; i++) {
      acc[i] += dm[T0 + 3 * me->platform + i];
      alpha[i] += dm[3 * me->platform + i];
    }
    mat3vec(I + 9 * me->platform, 3, om, Iom);
    tu_cross(om, Iom, gyro);
    double o_p[3] = {-pp[0], -pp[1], q[2] - pp[2]}, lever[3]; /* O' - p */
    tu_cross(o_p, l.fp, lever);
    double f[3], mo[3], mscale = 0, fscale = 0;
    for (int i = 0; i < 3; i++) {
      f[i] = l.fp[i] + mP * g[i];
      mo[i] = l.mp[i] + lever[i];
      mscale = fmax(mscale, fmax(fabs(l.mp[i]), fabs(lever[i])));
    }
    double u[3] = {RP[0], RP[3], RP[6]}, v[3] = {RP[1], RP[4], RP[7]}, wv[3] = {RP[2], RP[5], RP[8]};
    for (int j = 0; j < PRRU_NJOINT; j++) {
      const prru_joint_info *jt = &me->joint[j];
      if (jt->type != 'U') continue;
      /* C_1, C_2 at O' -+ a v; limb 3's (and limb 4's) at O'; moment axis
       * u for limbs 1, 2, w x x3 for limb 3 (x3 = R_L3 e1: the lower link's
       * long axis) and w x x4 for limb 4, whose lower link points the
       * other way (x4 = -R_L4 e1, spec section 12). */
      const double *fj = joint_lambda(lam, j), *RL = R + 9 * me->lower[jt->limb];
      double s = jt->limb == 0 ? -1 : 1, c[3], r[3], rxf[3], axis[3];
      for (int i = 0; i < 3; i++)
        c[i] = (i == 2 ? q[2] : 0.0) + (jt->limb < 2 ? s * me->a[jt->limb] * v[i] : 0.0);
      if (jt->limb < 2) {
        memcpy(axis, u, sizeof axis);
      } else {
        const double sx = jt->limb == 3 ? -1.0 : 1.0;
        double x3[3] = {sx * RL[0], sx * RL[3], sx * RL[6]};
        tu_cross(wv, x3, axis);
        double nn = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
        for (int i = 0; i < 3; i++) axis[i] /= nn;
      }
      for (int i = 0; i < 3; i++) r[i] = c[i] - pp[i];
      tu_cross(r, fj, rxf);
      for (int i = 0; i < 3; i++) {
        f[i] += fj[i];
        mo[i] += rxf[i] + fj[3] * axis[i];
        /* Relative to the largest term summed, not to the (smaller) net. */
        mscale = fmax(mscale, fmax(fabs(rxf[i]), fabs(fj[3])));
        fscale = fmax(fscale, fabs(fj[i]));
      }
    }
    double ma[3], rhs_m[3];
    for (int i = 0; i < 3; i++) {
      ma[i] = mP * acc[i];
      rhs_m[i] = I[9 * me->platform + 3 * i] * alpha[0] + I[9 * me->platform + 3 * i + 1] * alpha[1] +
                 I[9 * me->platform + 3 * i + 2] * alpha[2] + gyro[i];
      fscale = fmax(fscale, fmax(fabs(ma[i]), fabs(mP * g[i])));
      mscale = fmax(mscale, fabs(rhs_m[i]));
    }
    e_force = fmax(e_force, tu_relerr(f, ma, 3, fscale));
    e_moment = fmax(e_moment, tu_relerr(mo, rhs_m, 3, mscale));
    /* Whole machine, horizontal: sum m_b a_b = fp + gravity + rail forces
     * on the sliders (the P joints' first two coordinates). */
    double lhs[2] = {0, 0}, ext[2] = {l.fp[0] + me->total_mass * g[0], l.fp[1] + me->total_mass * g[1]};
    for (int b = 0; b < PRRU_NBODY; b++) {
      double ab[3];
      mat3vec(H + 3 * (T0 + 3 * b), 3, qdd, ab);
      for (int i = 0; i < 2; i++) lhs[i] += me->mass[b] * (ab[i] + dm[T0 + 3 * b + i]);
    }
    for (int j = 0; j < PRRU_NJOINT; j++)
      if (me->joint[j].type == 'P')
        for (int i = 0; i < 2; i++) ext[i] += joint_lambda(lam, j)[i];
    e_machine = fmax(e_machine, tu_relerr(ext, lhs, 2, fmax(50.0, fmax(fabs(lhs[0]), fabs(lhs[1])))));
  }
  prru_ref_free(w);
  printf("reactions: H^T Q %.1e, vs dense reference %.1e, platform force %.1e, moment %.1e, "
         "machine horizontal force %.1e\n", e_htq, e_ref, e_force, e_moment, e_machine);
  tu_check(e_htq <= 1e-12, "H^T Q = 0 relative to |H||Q|", e_htq, 1e-12);
  tu_check(e_ref <= 1e-10, "fast reactions = dense reference eq. 31", e_ref, 1e-10);
  tu_check(e_force <= 1e-10, "platform force balance (Newton)", e_force, 1e-10);
  tu_check(e_moment <= 1e-10, "platform moment balance (Euler)", e_moment, 1e-10);
  tu_check(e_machine <= 1e-10, "machine horizontal force balance", e_machine, 1e-10);
}

/* ---- simulation ---- */
/* The state (q, qd) and W, the work done on the machine by the actuator
 * forces, the platform loads (at O') and the drives' damping and friction
 * (gravity is in V): d/dt (T + V) = dW/dt along every trajectory. */
static void work_rhs(const prru_loads *l, const double y[7], double f[7])
{
  double Jd[3 * PRRU_NACT], JP[18], Qp[3];
  memcpy(f, y + 3, 3 * sizeof f[0]);
  if (prru_forward_dynamics(&model, &data, y, y + 3, l, f + 3) != PRRU_OK) f[3] = NAN;
  prru_jd(y, Jd);
  prru_platform_jacobian(y, JP);
  prru_passive(y, y + 3, Qp);
  double p = 0;
  for (int i = 0; i < 3; i++) {
    double w = 0, v = 0;
    for (int j = 0; j < 3; j++) {
      w += JP[3 * i + j] * y[3 + j];
      v += JP[9 + 3 * i + j] * y[3 + j];
    }
    p += l->fp[i] * v + l->mp[i] * w + Qp[i] * y[3 + i];
  }
  for (int i = 0; i < PRRU_NACT; i++) {
    double dd = 0;
    for (int j = 0; j < 3; j++) dd += Jd[3 * i + j] * y[3 + j];
    p += l->fd[i] * dd;
  }
  f[6] = p;
}

/* Constant loads for a run from q0: fp and mp as given in l, the actuator
 * forces that hold q0 at rest under them and gravity (inverse dynamics at
 * qd = qdd = 0) plus delta (N, actuators 1-3; an actuator beyond the third
 * gets delta_3, as limb 4 mirrors limb 3). Taken from the model, so that
 * every model, also the heavier 4-PRRU, stays in its workspace over the
 * tests' horizons (they drift it through a fraction of a radian). For the
 * paper's model these are within 0.5 N of the fixed forces the tests used
 * before. */
static void loads_near_rest(const double q0[3], const double delta[3], prru_loads *l)
{
  const double zero[3] = {0, 0, 0};
  TU_TRUE(prru_inverse_dynamics(&model, &data, q0, zero, zero, l, l->fd) == PRRU_OK,
          "static actuator forces at the start pose");
  for (int i = 0; i < PRRU_NACT; i++) l->fd[i] += delta[i < 3 ? i : 2];
}

/* Classical RK4 on (q, qd, W) with n steps to t_end. */
static void rk4_work(const prru_loads *l, double y[7], double t_end, int n)
{
  double k1[7], k2[7], k3[7], k4[7], yt[7], h = t_end / n;
  for (int s = 0; s < n; s++) {
    work_rhs(l, y, k1);
    for (int j = 0; j < 7; j++) yt[j] = y[j] + 0.5 * h * k1[j];
    work_rhs(l, yt, k2);
    for (int j = 0; j < 7; j++) yt[j] = y[j] + 0.5 * h * k2[j];
    work_rhs(l, yt, k3);
    for (int j = 0; j < 7; j++) yt[j] = y[j] + h * k3[j];
    work_rhs(l, yt, k4);
    for (int j = 0; j < 7; j++) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
  }
}

static void test_energy(void)
{
  const double q0[3] = {0.05, 0.1, -0.8}, qd0[3] = {0.8, -0.6, 0.4};
  prru_loads cases[2];
  memset(cases, 0, sizeof cases);
  /* Free motion, then constant actuator forces and platform loads. */
  cases[1].fp[0] = 4, cases[1].fp[2] = -10, cases[1].mp[1] = 0.5;
  loads_near_rest(q0, (const double[3]){6, -5, -3}, &cases[1]);
  const char *what[2] = {"free motion", "constant loads"};
  for (int c = 0; c < 2; c++) {
    const double t_end = 0.5;
    double y[7] = {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2], 0.0}, T0, V0, T1, V1;
    prru_energies(&model, q0, qd0, &T0, &V0);
    rk4_work(&cases[c], y, t_end, 5000);
    prru_energies(&model, y, y + 3, &T1, &V1);
    double dE = T1 + V1 - T0 - V0, scale = fmax(fabs(y[6]), fmax(fabs(T1), fabs(V1)));
    double e = fabs(dE - y[6]) / scale;
    printf("%s: dE %.9f J, work of loads and drives %.9f J, residual %.1e relative\n", what[c], dE,
           y[6], e);
    tu_check(e <= 1e-9, "change of T + V = work of the loads and the drives' damping and friction", e,
             1e-9);
    /* The runtime's integrator on the same problem. */
    char msg[300];
    prru_load_schedule ls;
    prru_schedule_constant(&ls, &cases[c]);
    keep k;
    int st = run_sim(&model, q0, qd0, &ls, PRRU_RK8PD, 1e-12, t_end, &k, msg);
    e = tu_relerr(k.last.q, y, 3, 1.0);
    printf("%s: prru_simulate vs RK4 q(%.1f s) %.1e, qd %.1e\n", what[c], t_end, e,
           tu_relerr(k.last.qd, y + 3, 3, 1.0));
    TU_TRUE(st == PRRU_OK, "prru_simulate runs");
    tu_check(e <= 1e-9, "prru_simulate q = RK4 on the runtime dynamics", e, 1e-9);
    e = tu_relerr(k.last.qd, y + 3, 3, 1.0);
    tu_check(e <= 1e-8, "prru_simulate qd = RK4 on the runtime dynamics", e, 1e-8);
  }
}

/* Independent integration: classical RK4 on the reference's forward
 * dynamics (GSL assembly, hand-derived Jacobians), fixed step, against the
 * runtime's three kinds of stepper. */
static void ref_rhs(prru_ref_params *p, prru_ref_ws *w, const prru_loads *l, const double y[6],
                    double f[6])
{
  memcpy(f, y + 3, 3 * sizeof f[0]);
  prru_ref_forward_dynamics(p, w, y, y + 3, l->fd, l->fp, l->mp, f + 3);
}

static void test_steppers(void)
{
  char msg[300];
  const double q0[3] = {0.1, -0.05, -0.8}, qd0[3] = {-0.3, 0.2, 0.1}, t_end = 0.4;
  prru_loads l;
  memset(&l, 0, sizeof l);
  l.fp[1] = 5;
  loads_near_rest(q0, (const double[3]){-4, -11, -2}, &l);
  prru_load_schedule ls;
  prru_schedule_constant(&ls, &l);
  keep a, b, c;
  int sa = run_sim(&model, q0, qd0, &ls, PRRU_RK8PD, 1e-12, t_end, &a, msg);
  int sb = run_sim(&model, q0, qd0, &ls, PRRU_RKCK, 1e-12, t_end, &b, msg);
  int sc = run_sim(&model, q0, qd0, &ls, PRRU_MSBDF, 1e-11, t_end, &c, msg);
  TU_TRUE(sa == PRRU_OK && sb == PRRU_OK && sc == PRRU_OK, "three steppers run");
  double e = tu_relerr(a.last.q, b.last.q, 3, 1.0), e2 = tu_relerr(a.last.q, c.last.q, 3, 1.0);
  printf("q(%.1f s): rk8pd vs rkck %.1e, vs msbdf %.1e\n", t_end, e, e2);
  tu_check(e <= 1e-8, "rk8pd and rkck agree", e, 1e-8);
  tu_check(e2 <= 1e-6, "rk8pd and msbdf agree", e2, 1e-6);
  prru_ref_params p;
  prru_ref_params_default(&p);
  prru_ref_ws *w = prru_ref_alloc();
  double y[6] = {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2]}, k1[6], k2[6], k3[6], k4[6], yt[6];
  const int n = 4000;
  const double h = t_end / n;
  for (int i = 0; i < n; i++) {
    ref_rhs(&p, w, &l, y, k1);
    for (int j = 0; j < 6; j++) yt[j] = y[j] + 0.5 * h * k1[j];
    ref_rhs(&p, w, &l, yt, k2);
    for (int j = 0; j < 6; j++) yt[j] = y[j] + 0.5 * h * k2[j];
    ref_rhs(&p, w, &l, yt, k3);
    for (int j = 0; j < 6; j++) yt[j] = y[j] + h * k3[j];
    ref_rhs(&p, w, &l, yt, k4);
    for (int j = 0; j < 6; j++) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
  }
  e = tu_relerr(a.last.q, y, 3, 1.0);
  printf("q(%.1f s) vs RK4 on the reference dynamics: %.1e\n", t_end, e);
  tu_check(e <= 1e-9, "q = RK4 on the reference dynamics", e, 1e-9);
  e = tu_relerr(a.last.qd, y + 3, 3, 1.0);
  tu_check(e <= 1e-8, "qd = RK4 on the reference dynamics", e, 1e-8);
  prru_ref_free(w);
}

static void test_stops(void)
{
  char msg[300];
  /* Limb 1 driven up and limb 2 down tilt the platform about x until a
   * limb stretches out: the run must stop with a status, keeping its
   * samples. */
  double q0[3] = {0, 0, -0.8}, qd0[3] = {0, 0, 0};
  prru_loads l;
  memset(&l, 0, sizeof l);
  l.fd[0] = 200; l.fd[1] = -100; l.fd[2] = 0;
  prru_load_schedule ls;
  prru_schedule_constant(&ls, &l);
  keep k;
  memset(&k, 0, sizeof k);
  int st = run_sim(&model, q0, qd0, &ls, PRRU_RK8PD, 1e-10, 2.0, &k, msg);
  TU_TRUE(st == PRRU_EUNREACHABLE || st == PRRU_ESINGULAR, "run into the boundary stops with a status");
  TU_TRUE(k.n > 1 && k.last.t < 2.0, "samples before the stop are kept");
  TU_TRUE(strstr(msg, "stopped at t =") != NULL, "the message says when it stopped");
  TU_TRUE(isfinite(k.last.q[0]) && isfinite(k.last.T), "the last kept sample is finite");
  /* A consumer that asks to stop after 5 samples. */
  prru_sim_options o;
  prru_sim_options_default(&o);
  o.loads = &ls;
  o.on_sample = keep_sample;
  memset(&k, 0, sizeof k);
  k.stop_after = 5;
  o.ctx = &k;
  double t_stop;
  st = prru_simulate(&model, q0, qd0, &o, &t_stop, msg, 300);
  TU_TRUE(st == PRRU_EINTERRUPTED && k.n == 5, "a consumer can stop the run");
  /* Bad options. */
  prru_sim_options_default(&o);
  o.dt_out = -1;
  TU_TRUE(prru_simulate(&model, q0, qd0, &o, &t_stop, msg, 300) == PRRU_EINPUT, "negative dt refused");
}

/* ---- bounded work, interrupts, the boundary (issue 16, items 3, 4, 6) ---- */
static const double q_mid[3] = {0.1, -0.05, -0.8}; /* as in test_steppers */

static double wall_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A hang is a failure: while armed, SIGALRM after `seconds` of wall time
 * ends the test with FAIL and the name of what hung. */
static const char *watchdog_what = "";
static void on_watchdog(int sig)
{
  (void)sig;
  static const char head[] = "FAIL did not finish in time (hang): ";
  ssize_t r = write(2, head, sizeof head - 1);
  r = write(2, watchdog_what, strlen(watchdog_what));
  r = write(2, "\n", 1);
  (void)r;
  _exit(1);
}

static void watchdog(int seconds, const char *what)
{
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_watchdog;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGALRM, &sa, NULL);
  watchdog_what = what ? what : "";
  struct itimerval it;
  memset(&it, 0, sizeof it);
  it.it_value.tv_sec = seconds; /* 0 disarms */
  setitimer(ITIMER_REAL, &it, NULL);
}

/* Loads that hold q at rest (inverse dynamics at qd = qdd = 0) plus, from
 * t_from on, fd_1 alternating between -amp and +amp every tau (a table,
 * linear in between): the integrator has to resolve every kink, so an
 * interval costs many steps while the state hardly moves. amp scales with
 * the model's static forces. */
static void busy_loads(prru_load_schedule *s, const double q[3], double t_from, double t_end,
                       double tau)
{
  const int R = PRRU_NACT + 7;
  const double zero[3] = {0, 0, 0};
  prru_loads eq;
  memset(&eq, 0, sizeof eq);
  TU_TRUE(prru_inverse_dynamics(&model, &data, q, zero, zero, &eq, eq.fd) == PRRU_OK,
          "static actuator forces");
  double amp = 1.0;
  for (int i = 0; i < PRRU_NACT; i++) amp = fmax(amp, 0.5 * fabs(eq.fd[i]));
  prru_schedule_constant(s, &eq);
  int n = (int)((t_end - t_from) / tau) + 2;
  s->rows = calloc((size_t)n * R, sizeof(double));
  if (!s->rows) { TU_TRUE(0, "out of memory"); return; }
  s->kind = PRRU_LOAD_TABLE;
  s->nact = model.mech->nact;
  s->nrows = n;
  for (int i = 0; i < n; i++) {
    s->rows[R * i] = t_from + i * tau;
    s->rows[R * i + 1] = i == 0 ? 0.0 : i % 2 ? amp : -amp;
  }
}

/* Item 4: tolerances below PRRU_TOL_MIN are refused at once (1e-25 used
 * to run for ever with every stepper); at the floor every stepper runs. */
static void test_tolerances(void)
{
  char msg[300];
  const double qd0[3] = {0.2, -0.1, 0.05};
  for (int stp = PRRU_RK8PD; stp <= PRRU_MSBDF; stp++) {
    prru_sim_options o;
    prru_sim_options_default(&o);
    o.stepper = (prru_stepper)stp;
    o.t_end = 0.05, o.dt_out = 0.01;
    keep k;
    memset(&k, 0, sizeof k);
    o.on_sample = keep_sample, o.ctx = &k;
    double t_stop, t0 = wall_now();
    o.abs_tol = o.rel_tol = 1e-25;
    int st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
    TU_TRUE(st == PRRU_EINPUT && strstr(msg, "rel_tol") && k.n == 0, "rel_tol 1e-25 refused");
    o.rel_tol = 1e-10;
    st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
    TU_TRUE(st == PRRU_EINPUT && strstr(msg, "abs_tol") && k.n == 0, "abs_tol 1e-25 refused");
    o.abs_tol = 1e-10, o.rel_tol = 0.5 * PRRU_TOL_MIN;
    TU_TRUE(prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300) == PRRU_EINPUT,
            "rel_tol just below the floor refused");
    o.abs_tol = o.rel_tol = PRRU_TOL_MIN;
    st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
    printf("%s at tolerance %.2g: %.3f s, %s\n", prru_stepper_name(o.stepper), PRRU_TOL_MIN,
           wall_now() - t0, st == PRRU_OK ? "completes" : msg);
    TU_TRUE(st == PRRU_OK && k.n == 6, "a run at the tolerance floor completes");
  }
  prru_sim_options o;
  prru_sim_options_default(&o);
  double t_stop;
  o.stepper = PRRU_MSBDF, o.abs_tol = 0;
  TU_TRUE(prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300) == PRRU_EINPUT &&
              strstr(msg, "abs_tol"), "msbdf with abs_tol = 0 refused");
  prru_sim_options_default(&o);
  o.max_steps = -1;
  TU_TRUE(prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300) == PRRU_EINPUT &&
              strstr(msg, "max_steps"), "negative max_steps refused");
  /* prru_sim_options_check names the member at fault (the CLI turns it
   * into its option) and starts its message with it. */
  const struct { double *v; double bad; const char *name; } cases[] = {
      {&o.t_end, -1, "t_end"}, {&o.dt_out, 0, "dt_out"}, {&o.abs_tol, NAN, "abs_tol"},
      {&o.rel_tol, -1e-3, "rel_tol"}, {&o.h0, INFINITY, "h0"}};
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    prru_sim_options_default(&o);
    *cases[c].v = cases[c].bad;
    const char *field = "none";
    const int st = prru_sim_options_check(&o, &field, msg, 300);
    TU_TRUE(st == PRRU_EINPUT && field && strcmp(field, cases[c].name) == 0 &&
                strncmp(msg, cases[c].name, strlen(cases[c].name)) == 0,
            "prru_sim_options_check names the member");
  }
  prru_sim_options_default(&o);
  const char *field = "none";
  TU_TRUE(prru_sim_options_check(&o, &field, NULL, 0) == PRRU_OK && field == NULL,
          "prru_sim_options_check: the defaults pass");
}

/* Item 4: the step budget ends a run that needs too many steps between two
 * samples with PRRU_ENOCONV, keeping every sample delivered. */
static void test_step_budget(void)
{
  char msg[300];
  const double qd0[3] = {0, 0, 0};
  prru_load_schedule ls;
  busy_loads(&ls, q_mid, 0.05, 0.1, 1e-4); /* quiet up to 0.05 s, then 100 kinks per 10 ms */
  prru_sim_options o;
  prru_sim_options_default(&o);
  o.t_end = 0.1, o.dt_out = 0.01, o.loads = &ls;
  keep k;
  memset(&k, 0, sizeof k);
  o.on_sample = keep_sample, o.ctx = &k;
  double t_stop = -1, t0 = wall_now();
  o.max_steps = 50;
  int st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
  printf("budget of 50 steps: %s (%ld samples, %.3f s)\n", msg, k.n, wall_now() - t0);
  TU_TRUE(st == PRRU_ENOCONV && strstr(msg, "step budget of 50 steps exhausted at t ="),
          "a run beyond its step budget stops with PRRU_ENOCONV and says so");
  TU_TRUE(k.n >= 5 && k.n < 11 && t_stop == k.last.t && k.last.t >= 0.04 - 1e-12,
          "the samples before the budget ran out are kept");
  /* The default budget is per output interval and generous. */
  memset(&k, 0, sizeof k);
  o.max_steps = 0;
  t0 = wall_now();
  st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
  printf("default budget: %s, %ld samples, %.3f s\n", st == PRRU_OK ? "completes" : msg, k.n,
         wall_now() - t0);
  TU_TRUE(st == PRRU_OK && k.n == 11, "the same run completes with the default budget");
  prru_schedule_free(&ls);
  /* From rest with h0 = 1e-4 s a 10 ms interval takes at least 4 steps
   * (a step grows at most 5x): a budget of 1 stops in the first one. */
  prru_sim_options_default(&o);
  o.t_end = 0.1, o.dt_out = 0.01, o.max_steps = 1;
  memset(&k, 0, sizeof k);
  o.on_sample = keep_sample, o.ctx = &k;
  st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
  TU_TRUE(st == PRRU_ENOCONV && k.n == 1 && t_stop == 0 && strstr(msg, "step budget of 1 steps"),
          "a budget of 1 step stops in the first interval, keeping the sample at t = 0");
}

/* Item 3: the interrupt flag is polled inside the right-hand side, so it
 * stops a run in the middle of one long interval (it was only polled
 * between samples). A CPU-time timer (SIGVTALRM: SIGALRM is the watchdog's)
 * raises it 30 ms into a 0.5 s interval that takes several tenths of a
 * second to integrate. */
static volatile sig_atomic_t test_interrupt_flag;
static void on_test_alarm(int sig)
{
  (void)sig;
  test_interrupt_flag = 1;
}

static void test_interrupt_in_step(void)
{
  char msg[300];
  const double qd0[3] = {0, 0, 0};
  prru_load_schedule ls;
  busy_loads(&ls, q_mid, 0.0, 0.5, 1e-4);
  prru_sim_options o;
  prru_sim_options_default(&o);
  o.t_end = o.dt_out = 0.5;
  o.loads = &ls, o.max_steps = 10000000;
  keep k;
  memset(&k, 0, sizeof k);
  o.on_sample = keep_sample, o.ctx = &k;
  test_interrupt_flag = 0;
  o.interrupt = &test_interrupt_flag;
  struct sigaction sa, old;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_test_alarm;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGVTALRM, &sa, &old);
  struct itimerval it, off;
  memset(&it, 0, sizeof it);
  memset(&off, 0, sizeof off);
  it.it_value.tv_usec = 30000;
  double t_stop = -1, t0 = wall_now();
  setitimer(ITIMER_VIRTUAL, &it, NULL);
  int st = prru_simulate(&model, q_mid, qd0, &o, &t_stop, msg, 300);
  double wall = wall_now() - t0;
  setitimer(ITIMER_VIRTUAL, &off, NULL);
  sigaction(SIGVTALRM, &old, NULL);
  printf("interrupt 30 ms into one 0.5 s interval: stopped after %.3f s: %s\n", wall, msg);
  TU_TRUE(st == PRRU_EINTERRUPTED, "an interrupt during an interval stops the run");
  TU_TRUE(k.n == 1 && t_stop == 0 && strstr(msg, "interrupted at t = 0 s (during the step"),
          "it stops inside the interval, reporting the last sample (t = 0), which stays delivered");
  prru_schedule_free(&ls);
}

/* Item 6: near the workspace boundary msbdf's finite-difference Jacobian
 * probed outside and stopped the run at t = 0, where rk8pd completes. The
 * boundary (of the states whose dynamics are trusted: prru_forward_dynamics
 * succeeds at rest) is found by bisection along q1 and q2 (both signs)
 * from (0, 0, -0.8); the run starts 1e-9 inside, well within a difference
 * step. Wherever rk8pd completes, msbdf must complete and agree. */
static int trusted_at_rest(const double q[3])
{
  prru_loads none;
  memset(&none, 0, sizeof none);
  const double qd[3] = {0, 0, 0};
  double qdd[3];
  return prru_forward_dynamics(&model, &data, q, qd, &none, qdd) == PRRU_OK;
}

static void test_msbdf_boundary(void)
{
  char msg[300];
  const double qd0[3] = {0, 0, 0};
  prru_loads zero;
  memset(&zero, 0, sizeof zero);
  prru_load_schedule ls;
  prru_schedule_constant(&ls, &zero);
  int cases = 0;
  for (int axis = 0; axis < 2; axis++)
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      double q[3] = {0, 0, -0.8}, lo = 0, hi = 0.01;
      for (;;) { /* bracket */
        q[axis] = sgn * hi;
        if (!trusted_at_rest(q) || hi > 3.2) break;
        lo = hi, hi *= 1.5;
      }
      if (hi > 3.2) continue;
      for (int i = 0; i < 80; i++) {
        double mid = 0.5 * (lo + hi);
        q[axis] = sgn * mid;
        if (trusted_at_rest(q)) lo = mid; else hi = mid;
      }
      q[axis] = sgn * (lo - 1e-9);
      if (!trusted_at_rest(q)) continue;
      keep a, b;
      int sa = run_sim(&model, q, qd0, &ls, PRRU_RK8PD, 1e-10, 0.05, &a, msg);
      if (sa != PRRU_OK) continue;
      int sb = run_sim(&model, q, qd0, &ls, PRRU_MSBDF, 1e-10, 0.05, &b, msg);
      double e = sb == PRRU_OK ? tu_relerr(b.last.q, a.last.q, 3, 1.0) : INFINITY;
      printf("q%d = %+.9f (boundary %+.9f): rk8pd completes, msbdf %s, |q| difference %.1e\n",
             axis + 1, q[axis], sgn * lo, sb == PRRU_OK ? "completes" : msg, e);
      TU_TRUE(sb == PRRU_OK && b.n == a.n, "msbdf runs from next to the boundary where rk8pd does");
      tu_check(e <= 1e-6, "msbdf agrees with rk8pd there", e, 1e-6);
      cases++;
    }
  TU_TRUE(cases > 0, "some start next to the boundary where rk8pd completes");
}

/* ---- schedules, scenarios, parsing ---- */
/* "t,fd1,...,fdn". */
static void csv_fd_header(char *buf, size_t len, int n)
{
  size_t k = (size_t)snprintf(buf, len, "t");
  for (int i = 1; i <= n && k < len; i++) k += (size_t)snprintf(buf + k, len - k, ",fd%d", i);
}

/* item (at most 7 characters) repeated n times, at most 8 ("" for n <= 0);
 * one of four static buffers in turn, so up to four results live at once. */
static const char *csv_repeat(const char *item, int n)
{
  static char bufs[4][64];
  static int next;
  char *b = bufs[next++ % 4];
  b[0] = '\0';
  for (int i = 0; i < n && i < 8; i++) strcat(b, item);
  return b;
}

/* ",1,2,...,n". */
static const char *csv_count(int n)
{
  static char bufs[4][64];
  static int next;
  char *b = bufs[next++ % 4];
  size_t k = 0;
  b[0] = '\0';
  for (int i = 1; i <= n && k < sizeof bufs[0]; i++) k += (size_t)snprintf(b + k, sizeof bufs[0] - k, ",%d", i);
  return b;
}

static void test_parsing(void)
{
  double v[3];
  TU_TRUE(prru_parse_list("1, -2.5e-1,3", v, 3) == PRRU_OK && v[1] == -0.25, "list parses");
  const char *bad[] = {"1,2", "1,2,3,4", "1,,3", "1,2,x", "nan,0,0", "1,inf,2", "1e999,0,0",
                       "0x10,0,0", "", " ", "1,2,3,", ",1,2", "1 2,3,4"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
    TU_TRUE(prru_parse_list(bad[i], v, 3) == PRRU_EPARSE, bad[i]);
  char msg[300];
  prru_load_schedule s;
  /* The tables have one fd column per actuator (t,fd1..fdN, N =
   * PRRU_NACT): the texts are built for the model. Actuators beyond the
   * third run from 5 N to 7 N. */
  char fdh[128], fdh1[128], csv[512];
  csv_fd_header(fdh, sizeof fdh, PRRU_NACT);
  csv_fd_header(fdh1, sizeof fdh1, PRRU_NACT - 1);
  snprintf(csv, sizeof csv, "%s,fp3\n0,0,10,20%s,1\n1,10,10,0%s,3\n", fdh,
           csv_repeat(",5", PRRU_NACT - 3), csv_repeat(",7", PRRU_NACT - 3));
  TU_TRUE(prru_schedule_parse_csv(&model, &s, csv, strlen(csv), "mem", msg, 300) == PRRU_OK, "load table parses");
  prru_loads l;
  prru_schedule_eval(&s, 0.25, &l);
  int extra_ok = 1;
  for (int i = 3; i < PRRU_NACT; i++) extra_ok &= fabs(l.fd[i] - 5.5) < 1e-15;
  TU_TRUE(fabs(l.fd[0] - 2.5) < 1e-15 && fabs(l.fd[2] - 15) < 1e-14 && fabs(l.fp[2] - 1.5) < 1e-15 &&
              extra_ok,
          "linear interpolation");
  prru_schedule_eval(&s, 7, &l);
  TU_TRUE(l.fd[0] == 10 && l.fp[2] == 3 && l.fd[PRRU_NACT - 1] == (PRRU_NACT > 3 ? 7 : 0),
          "held after the last row");
  prru_schedule_free(&s);
  /* "0,1,2,..,N" (N numbers after t); the header's missing column. */
  char row[80], row_short[80], missing[64], t_missing[512], t_short[512], t_dup[512], t_zz[512],
      t_nan[512], t_none[512], t_twice[512];
  snprintf(row, sizeof row, "0%s", csv_count(PRRU_NACT));
  snprintf(row_short, sizeof row_short, "0%s", csv_count(PRRU_NACT - 1));
  snprintf(missing, sizeof missing, "missing column 'fd%d'", PRRU_NACT);
  snprintf(t_missing, sizeof t_missing, "%s\n%s\n", fdh1, row_short);
  snprintf(t_short, sizeof t_short, "%s\n%s\n", fdh, row_short);
  snprintf(t_dup, sizeof t_dup, "%s\n%s\n%s\n", fdh, row, row);
  snprintf(t_zz, sizeof t_zz, "%s,zz\n%s,%d\n", fdh, row, PRRU_NACT + 1);
  snprintf(t_nan, sizeof t_nan, "%s\n0,1,nan%s\n", fdh, csv_count(PRRU_NACT) + 4);
  snprintf(t_none, sizeof t_none, "%s\n", fdh);
  snprintf(t_twice, sizeof t_twice, "t,t%s\n%s\n", fdh + 5, row); /* t,t,fd2,.. */
  const struct { const char *text, *needle; } bad_csv[] = {
      {t_missing, missing},
      {t_short, "mem:2"},
      {t_dup, "does not increase"},
      {t_zz, "unknown column 'zz'"},
      {t_nan, "not a finite number"},
      {t_none, "no data rows"},
      {"", "no header"},
      {t_twice, "appears twice"},
  };
  for (size_t i = 0; i < sizeof bad_csv / sizeof bad_csv[0]; i++) {
    int st = prru_schedule_parse_csv(&model, &s, bad_csv[i].text, strlen(bad_csv[i].text), "mem", msg, 300);
    TU_TRUE(st == PRRU_EPARSE && strstr(msg, bad_csv[i].needle), bad_csv[i].needle);
    if (!(st == PRRU_EPARSE && strstr(msg, bad_csv[i].needle))) fprintf(stderr, "  got: %s\n", msg);
  }
  prru_scenario sc;
  char ok[512];
  snprintf(ok, sizeof ok,
           "# test\nq0 = 0, 0.5, -0.8\nfd = 50,40,25%s\nharmonic = 50, 12.566370614359172\n"
           "t_end = 0.5\ndt = 0.01\nstepper = rkck\n", csv_repeat(",25", PRRU_NACT - 3));
  TU_TRUE(prru_scenario_parse(&model, &sc, ok, strlen(ok), "mem", NULL, msg, 300) == PRRU_OK &&
              sc.q0[1] == 0.5 && sc.opt.stepper == PRRU_RKCK && sc.loads.kind == PRRU_LOAD_HARMONIC &&
              sc.loads.base.fd[PRRU_NACT - 1] == 25,
          "scenario parses");
  prru_scenario_free(&sc);
  /* fd takes exactly one number per actuator. */
  char fd_short[128];
  snprintf(fd_short, sizeof fd_short, "fd = 1%s\n", csv_repeat(",1", PRRU_NACT - 2));
  TU_TRUE(prru_scenario_parse(&model, &sc, fd_short, strlen(fd_short), "mem", NULL, msg, 300) == PRRU_EPARSE &&
              strstr(msg, "mem:1: fd"),
          "scenario fd with one number fewer than the actuators refused");
  const char *budget = "max_steps = 500\natol = 0\nrtol = 2.3e-14\n";
  TU_TRUE(prru_scenario_parse(&model, &sc, budget, strlen(budget), "mem", NULL, msg, 300) == PRRU_OK &&
              sc.opt.max_steps == 500 && sc.opt.rel_tol == 2.3e-14,
          "scenario max_steps and a tolerance at the floor parse");
  prru_scenario_free(&sc);
  /* Angles and every other number as on the command line: multiples of pi
   * are the same doubles as the arithmetic written out in C. */
  const double pi = 3.14159265358979323846;
  const char *with_pi = "q0 = 0, pi/6, -pi/4\nqd0 = -2*pi/3, 0.5pi, +pi\n"
                        "harmonic = 50, 4pi\nt_end = pi/4\n";
  int st_pi = prru_scenario_parse(&model, &sc, with_pi, strlen(with_pi), "mem", NULL, msg, 300);
  TU_TRUE(st_pi == PRRU_OK &&
              sc.q0[0] == 0 && sc.q0[1] == pi / 6 && sc.q0[2] == -(pi / 4) &&
              sc.qd0[0] == -(2 * pi / 3) && sc.qd0[1] == 0.5 * pi && sc.qd0[2] == pi &&
              sc.loads.omega == 4 * pi && sc.opt.t_end == pi / 4,
          "scenario values in multiples of pi parse as on the command line");
  if (st_pi != PRRU_OK) fprintf(stderr, "  got: %s\n", msg);
  prru_scenario_free(&sc);
  const struct { const char *text, *needle; } bad_sc[] = {
      {"q0 = 0, pi/0, 0\n", "mem:1: q0: expected 3 comma-separated finite numbers (decimal, or multiples of pi"},
      {"qd0 = 0, 0, pi/-2\n", "mem:1: qd0"},
      {"q0 = 0, 2 pi, 0\n", "mem:1: q0"},
      {"t_end = -pi\n", "mem:1: t_end"},
      {"q0 = 1,2\n", "mem:1: q0"},
      {"speed = 3\n", "unknown key 'speed'"},
      {"t_end = -1\n", "t_end"},
      {"stepper = euler\n", "stepper"},
      {"q0 = 0,0,-0.8\nq0 = 0,0,-0.7\n", "given twice"},
      {"junk\n", "expected 'key = value'"},
      {"loads = x.csv\n", "not allowed"},
      {"dt = 2\n", "larger than t_end"},
      {"atol = 1e-25\n", "mem:1: atol: 1e-25 is below"},
      {"rtol = 1e-16\n", "mem:1: rtol"},
      {"max_steps = -3\n", "mem:1: max_steps"},
      {"max_steps = 2.5\n", "mem:1: max_steps"},
  };
  for (size_t i = 0; i < sizeof bad_sc / sizeof bad_sc[0]; i++) {
    int st = prru_scenario_parse(&model, &sc, bad_sc[i].text, strlen(bad_sc[i].text), "mem", NULL, msg, 300);
    TU_TRUE(st == PRRU_EPARSE && strstr(msg, bad_sc[i].needle), bad_sc[i].needle);
    if (!(st == PRRU_EPARSE && strstr(msg, bad_sc[i].needle))) fprintf(stderr, "  got: %s\n", msg);
  }
}

/* Code points of s if it is all well-formed UTF-8, -1 otherwise. */
static long utf8_count(const char *s)
{
  long k = 0;
  for (size_t n; *s; s += n, k++)
    if ((n = prru_utf8_char(s)) == 0) return -1;
  return k;
}

/* prru_description's result must pass the generator's rule for any text
 * (gen/prrugen/model.py): UTF-8, one line of at most 400 characters
 * without a star-slash. */
static int valid_description(const char *d)
{
  long k = utf8_count(d);
  if (k < 0 || k > PRRU_DESCRIPTION_MAX || strstr(d, "*" "/")) return 0;
  for (const unsigned char *c = (const unsigned char *)d; *c; c++)
    if (*c < 0x20 || *c == 0x7f) return 0;
  return 1;
}

static void test_description(void)
{
  char out[PRRU_DESCRIPTION_SIZE], text[3000];
  TU_TRUE(strcmp(prru_description(out, sizeof out, "plain \xc3\xa9 \xe2\x98\x83 ?\?/ \"q\" \\"),
                 "plain \xc3\xa9 \xe2\x98\x83 ?\?/ \"q\" \\") == 0,
          "description: printable text and well-formed UTF-8 kept");
  TU_TRUE(strcmp(prru_description(out, sizeof out, "a*/b**//\n\t\x7f\xc2\x85"), "a*|b**|/????") == 0,
          "description: star-slash broken, control characters replaced");
  /* Malformed: a lone continuation byte, an overlong '/', a surrogate, a
   * code point beyond U+10FFFF, a truncated sequence at the end. */
  TU_TRUE(strcmp(prru_description(out, sizeof out, "\x80|\xc0\xaf|\xed\xa0\x80|\xf4\x90\x80\x80|\xe2\x98"),
                 "?|??|???|????|??") == 0,
          "description: every byte of a malformed sequence replaced");
  /* Over 400 characters: start and end kept around "...", 400 in all. */
  memset(text, 'a', 1000);
  strcpy(text + 1000, "/data.csv");
  prru_description(out, sizeof out, text);
  TU_TRUE(utf8_count(out) == PRRU_DESCRIPTION_MAX && strncmp(out, "aaaa", 4) == 0 && strstr(out, "a...a") &&
              strcmp(out + strlen(out) - 9, "/data.csv") == 0,
          "description: a long text shortened in its middle to 400 characters");
  /* 4-byte characters, star-slashes across the cut, any byte: still valid. */
  static const char *pieces[] = {"\xf0\x9f\x98\x80", "*", "/", "\xff", "\xe2\x98", "\n", "x"};
  unsigned long seed = 1;
  for (int round = 0; round < 200; round++) {
    size_t n = 0, len = (size_t)(round * 13 % 700);
    for (size_t i = 0; i < len; i++) {
      seed = seed * 6364136223846793005UL + 1442695040888963407UL;
      const unsigned r = (unsigned)(seed >> 33);
      if (round % 2) /* any byte but NUL */
        text[n++] = (char)(1 + r % 255);
      else
        for (const char *p = pieces[r % 7]; *p; p++) text[n++] = *p;
    }
    text[n] = '\0';
    if (!valid_description(prru_description(out, sizeof out, text)))
      TU_TRUE(0, "description: valid for any text");
  }
  TU_TRUE(valid_description(prru_description(out, 8, "\xf0\x9f\x98\x80\xf0\x9f\x98\x80")) && strlen(out) == 4,
          "description: a short buffer cut between characters");
}

int main(void)
{
  prru_model_default(&model);
  test_description();
  test_inverse_of_forward();
  test_fk();
  test_fk_helpers();
  test_bad_input();
  test_every_bad_input();
  test_reactions();
  test_energy();
  test_steppers();
  test_stops();
  /* Release builds take well under a second for these four. */
  watchdog(60, "tolerance floor (a tolerance of 1e-25 used to run for ever)");
  test_tolerances();
  watchdog(60, "step budget");
  test_step_budget();
  watchdog(60, "interrupt inside an interval");
  test_interrupt_in_step();
  watchdog(60, "msbdf next to the workspace boundary");
  test_msbdf_boundary();
  watchdog(0, NULL);
  test_parsing();
  return tu_finish("test_runtime");
}
