/* Independent validation of the generated dynamics against MuJoCo 2.2.2
 * (the role Adams/View plays in the paper).
 *
 * usage: validate_mujoco PRRU_MJCF.xml
 *
 * The MJCF (gen/prru_mjcf.py) is three open chains slide-hinge-hinge-U with
 * one platform copy per chain, welded together. MuJoCo computes the tree
 * dynamics of that model by its own algorithms (CRB mass matrix, RNE bias
 * forces, weld Jacobians); nothing is shared with our kernels except the
 * model file's numbers. Every size and index comes from the generated
 * descriptor prru_mech (prru_mujoco.h), so this runs for any model file,
 * format 1 or 2: per-limb geometry, a gravity vector, centres of mass off
 * the body frames, full inertia tensors (principal moments and axes,
 * which gen/prru_mjcf.py computes to rounding: MuJoCo 2.2.2's own
 * fullinertia diagonalisation is off by up to ~1e-8), the drives' armature
 * and viscous damping (MuJoCo's slide-joint armature and damping, i.e. qM
 * and qfrc_passive) and their smoothed Coulomb force -f tanh(v / v_s),
 * which MuJoCo has no law for: the MJCF carries (f, v_s) as custom data
 * and this test applies the force through qfrc_applied on the slide dof,
 * at MuJoCo's slide velocity.
 *
 * State transfer (prru_mujoco.h): MuJoCo's joint coordinates and velocities
 * follow from our poses and body velocities; before any comparison MuJoCo's
 * forward kinematics must reproduce all our poses and body velocities and
 * the weld residuals efc_pos and efc_vel = J qvel must vanish.
 *
 * Level 1 (exact). Rigid constrained dynamics from MuJoCo's tree terms:
 *     [ M  J^T ] [ qacc ]   [ qfrc_applied + qfrc_passive - qfrc_bias ]
 *     [ J   0  ] [ -f   ] = [ -J' qvel                                ]
 * with M = mj_fullM(qM) (armature included), qfrc_applied = fd and the
 * Coulomb force on the slides plus J_O'^T (fp, mp) of platform copy 1 at O'
 * (mj_applyFT at its frame origin), J = the 6 (n_limb - 1) weld rows of
 * efc_J, and J' qvel by a
 * fourth-order central difference of efc_J along qvel,
 *     J' v ~ (8 (J(q+hv) - J(q-hv)) - (J(q+2hv) - J(q-2hv))) / (12 h) v,
 * h = 1e-3 s: truncation ~h^4 |J^(5)| and rounding ~eps |J| / h are both
 * ~1e-13 here. (MuJoCo 2.2.2 exposes no J'; a row transformation of J, as in
 * its quaternion-based weld rows, leaves J' v on the constraint manifold
 * unchanged because J v = 0 there.) From qacc: d'' = qacc of the slides,
 * the platform's angular acceleration from mj_rnePostConstraint (cacc).
 * Compared with prru_forward_dynamics: d'' = J_d qdd + J_d' qd,
 * omega_P' = J_R,P qdd + delta_P, to 1e-11 relative. Every third state
 * has slow sliders (|d'| ~ v_s), where the Coulomb force is not saturated.
 *
 * Level 2 (MuJoCo as users run it). mj_forward's qacc and a 1 s run of the
 * paper's scenario (its initial state and loads, on this model) with
 * mj_step (RK4, dt = 1e-4, loads and Coulomb force through mjcb_control so
 * every RK4 stage sees them at its own time and velocity). MuJoCo's equality
 * constraints are soft: its solver minimises
 *     1/2 (a - a0)^T M (a - a0) + 1/2 (J a - aref)^T R^-1 (J a - aref),
 * R = (1 - d)/d diag(J M^-1 J^T), impedance d <= 0.9999 (the MJCF uses that
 * cap), and aref = -b J v - k r has no J' v term. So J a is neither -J' v
 * (missing at states with velocity) nor exactly aref (the compliance R,
 * which on the ill-conditioned J M^-1 J^T of light platform copies on heavy
 * chains is felt most by the platform's rotation): mj_forward's
 * accelerations differ from the rigid ones by ~1e-4..2e-2. Along a
 * trajectory the stiff stabilisation (time constant 2e-4 s, b ~ 1e4 /s,
 * k ~ 2.5e7 /s^2) keeps r and J v near 0 and q stays within ~1e-7 of ours
 * (paper's model). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_linalg.h>
#include <mujoco/mujoco.h>

#include "prru.h"
#include "prru_mujoco.h"
#include "testutil.h"

#define NSTATES 24

/* A reachable centre for every model file: at q1 = q2 = 0 the limbs close
 * at every height (prrugen rejects a model that does not assemble there);
 * -0.8 m is the paper's working height. States are sampled around it and
 * kept where J_d is regular. */
static const double Q_CENTRE[3] = {0.0, 0.0, -0.8};
static const double Q_SPREAD[3] = {0.3, 0.4, 0.2};

/* Bounds. Level 1 is exact up to rounding and the J' v difference quotient
 * (measured <= 5e-14 on the paper's model and on models/prototype_example;
 * the issue asks for ~1e-9, 1e-11 leaves room for other MuJoCo builds and
 * still catches a 1e-7 kg error in one link's mass, which shows as 7e-8).
 * Level 2 bounds are ~2-4x the values measured with MuJoCo 2.2.2 on the
 * paper's model (the prototype's damped drives keep it ~100x closer on the
 * trajectory). */
#define TOL_EXACT 1e-11
#define TOL_STATE 1e-12     /* poses (m, rotation entries), velocities */
#define TOL_SOFT_ACC 5e-2   /* mj_forward qacc vs rigid, relative */
#define TOL_TRAJ_Q 5e-7     /* 1 s run, max |q_mj - q_ours| (rad, m) */

/* The NC weld rows of efc_J as a dense NC x NV matrix (MuJoCo picks a dense
 * or sparse layout by model size). */
static int weld_jacobian(const mjModel *m, const mjData *d, double *J)
{
  int row = 0;
  memset(J, 0, sizeof(double) * NC * NV);
  for (int r = 0; r < d->nefc; r++) {
    if (d->efc_type[r] != mjCNSTR_EQUALITY) continue;
    if (row == NC) return 0;
    if (mj_isSparse(m)) {
      int adr = d->efc_J_rowadr[r];
      for (int k = 0; k < d->efc_J_rownnz[r]; k++)
        J[NV * row + d->efc_J_colind[adr + k]] = d->efc_J[adr + k];
    } else {
      memcpy(J + NV * row, d->efc_J + NV * r, sizeof(double) * NV);
    }
    row++;
  }
  return row == NC;
}

/* J' qvel by the fourth-order central difference along qvel (see top). */
static int jdot_v(const mjModel *m, const mjData *d, mjData *scratch, double *out)
{
  static const double coef[4] = {8.0, -8.0, -1.0, 1.0};
  static const double step[4] = {1.0, -1.0, 2.0, -2.0};
  const double h = 1e-3;
  double J[NC * NV];
  memset(out, 0, sizeof(double) * NC);
  for (int s = 0; s < 4; s++) {
    for (int k = 0; k < NV; k++) scratch->qpos[k] = d->qpos[k] + step[s] * h * d->qvel[k];
    mj_fwdPosition(m, scratch);
    if (!weld_jacobian(m, scratch, J)) return 0;
    for (int r = 0; r < NC; r++) {
      double jv = 0;
      for (int k = 0; k < NV; k++) jv += J[NV * r + k] * d->qvel[k];
      out[r] += coef[s] * jv / (12.0 * h);
    }
  }
  return 1;
}

/* Rigid accelerations from MuJoCo's tree terms at the state in d (after
 * mj_forward): qacc (NV), and the slide and platform outputs. */
static int rigid_solve(const mjModel *m, mjData *d, mjData *scratch, double qacc[NV],
                       double *kkt_residual)
{
  enum { N = NV + NC };
  double A[N * N], rhs[N], M[NV * NV], J[NC * NV], jv[NC], tau[NV];
  if (!weld_jacobian(m, d, J) || !jdot_v(m, d, scratch, jv)) return 0;
  mj_fullM(m, M, d->qM);
  for (int k = 0; k < NV; k++) tau[k] = d->qfrc_applied[k] + d->qfrc_passive[k] - d->qfrc_bias[k];
  memset(A, 0, sizeof A);
  for (int i = 0; i < NV; i++) {
    for (int j = 0; j < NV; j++) A[N * i + j] = M[NV * i + j];
    rhs[i] = tau[i];
  }
  for (int r = 0; r < NC; r++) {
    for (int j = 0; j < NV; j++) {
      A[N * (NV + r) + j] = J[NV * r + j];
      A[N * j + NV + r] = J[NV * r + j];
    }
    rhs[NV + r] = -jv[r];
  }
  double Acopy[N * N], x[N];
  memcpy(Acopy, A, sizeof A);
  gsl_matrix_view Av = gsl_matrix_view_array(Acopy, N, N);
  gsl_vector_view bv = gsl_vector_view_array(rhs, N), xv = gsl_vector_view_array(x, N);
  gsl_permutation *perm = gsl_permutation_alloc(N);
  int sgn, st = gsl_linalg_LU_decomp(&Av.matrix, perm, &sgn);
  if (st == 0) st = gsl_linalg_LU_solve(&Av.matrix, perm, &bv.vector, &xv.vector);
  gsl_permutation_free(perm);
  if (st != 0) return 0;
  /* residual of the linear solve, relative to |rhs| */
  double rmax = 0, bmax = 1e-300;
  for (int i = 0; i < N; i++) {
    double s = -rhs[i];
    for (int j = 0; j < N; j++) s += A[N * i + j] * x[j];
    rmax = fmax(rmax, fabs(s));
    bmax = fmax(bmax, fabs(rhs[i]));
  }
  *kkt_residual = rmax / bmax;
  memcpy(qacc, x, sizeof(double) * NV);
  return 1;
}

/* d'' (slides) and the angular acceleration of each platform copy for the
 * qacc in d->qacc (MuJoCo's forward recursion, cacc). */
static void mj_outputs(const mjModel *m, mjData *d, const mjmap *mp, double dd[NLIMB],
                       double wdot[NLIMB][3])
{
  double acc6[6];
  mj_rnePostConstraint(m, d);
  for (int i = 0; i < NLIMB; i++) {
    dd[i] = d->qacc[mp->slide_dof[i]];
    mj_objectAcceleration(m, d, mjOBJ_BODY, mp->P[i], acc6, 0);
    memcpy(wdot[i], acc6, sizeof wdot[i]);
  }
}

/* Ours: d'' = J_d qdd + J_d' qd, omega_P' = J_R,P qdd + delta_P. */
static int our_outputs(const prru_model *pm, prru_data *pd, const double q[3],
                       const double qd[3], const prru_loads *l, double dd[PRRU_NACT],
                       double wdot[3])
{
  double qdd[3], H[3 * PRRU_NH], dm[PRRU_NH], act[PRRU_NACT], Jd[3 * PRRU_NACT];
  double ddot[PRRU_NACT], ddb[PRRU_NACT];
  if (prru_forward_dynamics(pm, pd, q, qd, l, qdd) != PRRU_OK) return 0;
  prru_jacobians(q, H);
  prru_bias_terms(q, qd, dm);
  prru_ik_jd(q, act, Jd);
  prru_actuator_rates(q, qd, ddot, ddb);
  for (int i = 0; i < PRRU_NACT; i++)
    dd[i] = Jd[3 * i] * qdd[0] + Jd[3 * i + 1] * qdd[1] + Jd[3 * i + 2] * qdd[2] + ddb[i];
  for (int k = 0; k < 3; k++) {
    int r = 3 * prru_mech.platform + k;
    wdot[k] = H[3 * r] * qdd[0] + H[3 * r + 1] * qdd[1] + H[3 * r + 2] * qdd[2] + dm[r];
  }
  return 1;
}


int main(int argc, char **argv)
{
  if (argc != 2) {
    fprintf(stderr, "usage: validate_mujoco PRRU_MJCF.xml\n");
    return 2;
  }
  char err[1000] = "";
  mjModel *m = mj_loadXML(argv[1], NULL, err, sizeof err);
  if (!m) {
    fprintf(stderr, "validate_mujoco: %s: cannot load: %s\n", argv[1], err);
    return 2;
  }
  mjmap mp;
  if (!build_map(m, &mp)) return 2;
  mjData *d = mj_makeData(m), *scratch = mj_makeData(m);
  prru_model pm;
  prru_data *pd = malloc(sizeof *pd);
  prru_model_default(&pm);
  int ver = mj_version(), drives = 0;
  for (int i = 0; i < PRRU_NACT; i++)
    drives |= prru_mech.armature[i] != 0 || prru_mech.damping[i] != 0 || prru_mech.coulomb[i] != 0;
  printf("MuJoCo %d.%d.%d, model %s: %d bodies, %d tree DOF, %d weld rows;\n"
         "  kernels of %s (%s, format %d)%s\n", ver / 100, ver / 10 % 10, ver % 10, argv[1],
         m->nbody - 1, m->nv, NC, prru_mech.model_file, prru_mech.name, prru_mech.format,
         drives ? ", drives with armature, damping, Coulomb" : "");

  /* ---- level 1 and level 2a at random reachable states ---- */
  double worst_state = 0, worst_weld = 0, worst_wvel = 0, worst_kkt = 0, worst_copy = 0;
  double worst_dd = 0, worst_w = 0, soft_dd = 0, soft_w = 0, rest_dd = 0, rest_w = 0;
  int n = 0, tries = 0;
  while (n < NSTATES && tries++ < 100 * NSTATES) {
    double q[3], rc;
    for (int k = 0; k < 3; k++) q[k] = Q_CENTRE[k] + tu_uniform(-Q_SPREAD[k], Q_SPREAD[k]);
    if (prru_check_regular(&pm, pd, q, &rc) != PRRU_OK || rc < 1e-3) continue;
    double qd[3] = {tu_uniform(-1, 1), tu_uniform(-1, 1), tu_uniform(-0.5, 0.5)};
    if (n % 3 == 2) /* slow sliders: the Coulomb force's smooth part */
      for (int k = 0; k < 3; k++) qd[k] *= 1e-2;
    prru_loads l;
    for (int i = 0; i < PRRU_NACT; i++) l.fd[i] = tu_uniform(0, 120);
    for (int k = 0; k < 3; k++) l.fp[k] = tu_uniform(-50, 50);
    for (int k = 0; k < 3; k++) l.mp[k] = tu_uniform(-5, 5);
    state_residuals sr;
    mju_zero(d->qfrc_applied, NV);
    mju_zero(d->xfrc_applied, 6 * m->nbody);
    if (!TU_TRUE(set_state(m, d, &mp, q, qd, &sr), "state transfer")) continue;
    worst_state = fmax(worst_state, fmax(fmax(sr.pose, sr.vel), sr.ujoint));
    worst_weld = fmax(worst_weld, sr.weld_pos);
    worst_wvel = fmax(worst_wvel, sr.weld_vel);
    tu_check(sr.pose <= TOL_STATE, "MuJoCo poses vs prru_poses", sr.pose, TOL_STATE);
    tu_check(sr.vel <= TOL_STATE, "MuJoCo body velocities vs ours", sr.vel, TOL_STATE);
    tu_check(sr.ujoint <= TOL_STATE, "U-joint velocity fit", sr.ujoint, TOL_STATE);
    tu_check(sr.weld_pos <= TOL_STATE, "weld residual efc_pos", sr.weld_pos, TOL_STATE);
    tu_check(sr.weld_vel <= TOL_STATE, "weld velocity J qvel", sr.weld_vel, TOL_STATE);
    /* the loads at this state (Coulomb at MuJoCo's slide velocities) */
    mj_load_forces(m, d, &mp, &l, d->qfrc_applied);
    mj_forward(m, d);

    /* level 2a: MuJoCo's own (soft) accelerations at this state */
    double dd_soft[NLIMB], w_soft[NLIMB][3];
    mj_outputs(m, d, &mp, dd_soft, w_soft);

    /* level 1 */
    double qacc[NV], kkt, dd_mj[NLIMB], w_mj[NLIMB][3], dd_ours[PRRU_NACT], w_ours[3];
    if (!TU_TRUE(rigid_solve(m, d, scratch, qacc, &kkt), "rigid KKT solve")) continue;
    worst_kkt = fmax(worst_kkt, kkt);
    mju_copy(d->qacc, qacc, NV);
    mj_outputs(m, d, &mp, dd_mj, w_mj);
    if (!TU_TRUE(our_outputs(&pm, pd, q, qd, &l, dd_ours, w_ours), "prru_forward_dynamics"))
      continue;
    double e_dd = tu_relerr(dd_mj, dd_ours, NLIMB, 1e-300);
    double e_w = tu_relerr(w_mj[0], w_ours, 3, 1e-300);
    for (int c = 1; c < NLIMB; c++)
      worst_copy = fmax(worst_copy, tu_relerr(w_mj[c], w_mj[0], 3, 1e-300));
    worst_dd = fmax(worst_dd, e_dd);
    worst_w = fmax(worst_w, e_w);
    tu_check(e_dd <= TOL_EXACT, "level 1: d'' MuJoCo-rigid vs ours", e_dd, TOL_EXACT);
    tu_check(e_w <= TOL_EXACT, "level 1: platform angular acceleration", e_w, TOL_EXACT);
    soft_dd = fmax(soft_dd, tu_relerr(dd_soft, dd_ours, NLIMB, 1e-300));
    soft_w = fmax(soft_w, tu_relerr(w_soft[0], w_ours, 3, 1e-300));
    /* The same state at rest separates the two causes: with qd = 0 there
     * is no J'v, and what remains is the impedance's compliance. */
    static const double rest[3] = {0, 0, 0};
    if (set_state(m, d, &mp, q, rest, &sr) && our_outputs(&pm, pd, q, rest, &l, dd_ours, w_ours)) {
      mj_load_forces(m, d, &mp, &l, d->qfrc_applied);
      mj_forward(m, d);
      mj_outputs(m, d, &mp, dd_soft, w_soft);
      rest_dd = fmax(rest_dd, tu_relerr(dd_soft, dd_ours, NLIMB, 1e-300));
      rest_w = fmax(rest_w, tu_relerr(w_soft[0], w_ours, 3, 1e-300));
    }
    n++;
  }
  TU_TRUE(n == NSTATES, "enough regular states sampled");
  tu_check(worst_copy <= TOL_EXACT, "rigid qacc: the platform copies agree", worst_copy,
           TOL_EXACT);
  tu_check(soft_dd <= TOL_SOFT_ACC, "level 2: mj_forward d'' vs rigid", soft_dd, TOL_SOFT_ACC);
  tu_check(soft_w <= TOL_SOFT_ACC, "level 2: mj_forward angular acc. vs rigid", soft_w,
           TOL_SOFT_ACC);
  tu_check(rest_dd <= TOL_SOFT_ACC, "level 2: mj_forward d'' at rest", rest_dd, TOL_SOFT_ACC);
  tu_check(rest_w <= TOL_SOFT_ACC, "level 2: mj_forward angular acc. at rest", rest_w,
           TOL_SOFT_ACC);
  printf("state transfer (%d states): poses/velocities %.1e, weld efc_pos %.1e, J qvel %.1e\n",
         n, worst_state, worst_weld, worst_wvel);
  printf("level 1, rigid KKT from MuJoCo's M, qfrc_bias, efc_J, J'v (solve residual %.1e):\n"
         "  max relative difference vs prru_forward_dynamics: d'' %.2e, platform alpha %.2e"
         " (bound %.0e); copies agree to %.1e\n",
         worst_kkt, worst_dd, worst_w, TOL_EXACT, worst_copy);
  printf("level 2, mj_forward (soft welds) vs rigid: d'' %.2e, platform alpha %.2e (bound %.0e);\n"
         "  same states at rest (no J'v, impedance only): d'' %.2e, platform alpha %.2e\n",
         soft_dd, soft_w, TOL_SOFT_ACC, rest_dd, rest_w);

  /* ---- level 2b: the paper's 1 s run, mj_step RK4 dt = 1e-4 vs prru_simulate ----
   * The paper's scenario (initial state, loads, 1 s) on this model. A model
   * whose workspace does not hold the paper's q(0) starts at rest from
   * Q_CENTRE instead, and a run that leaves the workspace is compared over
   * the samples prru_simulate delivered (at least a tenth of the run). */
  prru_scenario sc;
  prru_scenario_paper(&sc);
  const char *start = "the paper's q(0)";
  if (prru_check_regular(&pm, pd, sc.q0, NULL) != PRRU_OK) {
    memcpy(sc.q0, Q_CENTRE, sizeof sc.q0);
    memset(sc.qd0, 0, sizeof sc.qd0);
    start = "the centre at rest";
  }
  trajectory tr = {0, 0, NULL, NULL};
  int nsamp = (int)floor(sc.opt.t_end / sc.opt.dt_out + 0.5) + 1;
  tr.cap = nsamp;
  tr.t = malloc(sizeof(double) * (size_t)nsamp);
  tr.q = malloc(sizeof(double) * 3 * (size_t)nsamp);
  sc.opt.loads = &sc.loads; /* a scenario's options do not point into it */
  sc.opt.on_sample = record_sample;
  sc.opt.ctx = &tr;
  double t_stop;
  char msg[256] = "";
  int st = prru_simulate(&pm, sc.q0, sc.qd0, &sc.opt, &t_stop, msg, sizeof msg);
  int left = st == PRRU_EUNREACHABLE || st == PRRU_ESINGULAR; /* left the workspace */
  if (!TU_TRUE((st == PRRU_OK && tr.n == nsamp) || (left && tr.n >= nsamp / 10),
               "prru_simulate of the paper scenario")) {
    fprintf(stderr, "prru_simulate: %s (%s), %d of %d samples\n", prru_strerror(st), msg, tr.n,
            nsamp);
  } else {
    if (left) printf("prru_simulate left the workspace at t = %g s: %s\n", t_stop, msg);
    nsamp = tr.n;
    const double dt = 1e-4;
    int per_sample = (int)floor(sc.opt.dt_out / dt + 0.5);
    state_residuals sr;
    mj_resetData(m, d);
    m->opt.timestep = dt;
    m->opt.integrator = mjINT_RK4;
    g_schedule = &sc.loads;
    g_map = &mp;
    TU_TRUE(set_state(m, d, &mp, sc.q0, sc.qd0, &sr), "initial state transfer");
    d->time = 0;
    mjcb_control = apply_loads;
    double dq[3] = {0, 0, 0}, spread = 0, qm[3];
    for (int k = 0; k < nsamp; k++) {
      if (k > 0) {
        for (int s = 0; s < per_sample; s++) mj_step(m, d);
        mj_kinematics(m, d); /* mj_step leaves the poses of the step's start */
      }
      platform_q(d, mp.P[0], qm);
      for (int c = 0; c < 3; c++) dq[c] = fmax(dq[c], fabs(qm[c] - tr.q[3 * k + c]));
      for (int c = 1; c < NLIMB; c++) {
        double qc[3];
        platform_q(d, mp.P[c], qc);
        for (int j = 0; j < 3; j++) spread = fmax(spread, fabs(qc[j] - qm[j]));
      }
    }
    mjcb_control = NULL;
    double worst = fmax(dq[0], fmax(dq[1], dq[2]));
    printf("level 2, paper scenario from %s, mj_step RK4 dt = %g vs prru_simulate (%s, tol %g):\n"
           "  max |q_mj - q_ours| over %d samples (%g s): q1 %.2e rad, q2 %.2e rad, q3 %.2e m"
           " (bound %.0e); platform copies drift apart by %.1e\n",
           start, dt, prru_stepper_name(sc.opt.stepper), sc.opt.rel_tol, nsamp,
           tr.t[nsamp - 1], dq[0], dq[1], dq[2], TOL_TRAJ_Q, spread);
    tu_check(worst <= TOL_TRAJ_Q, "level 2: trajectory q", worst, TOL_TRAJ_Q);
  }
  free(tr.t);
  free(tr.q);
  prru_scenario_free(&sc);
  free(pd);
  mj_deleteData(scratch);
  mj_deleteData(d);
  mj_deleteModel(m);
  return tu_finish("validate_mujoco");
}
