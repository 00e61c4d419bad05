/* Independent validation of the generated dynamics against MuJoCo 2.2.2
 * (the role Adams/View plays in the paper).
 *
 * usage: validate_mujoco PRRU_MJCF.xml
 *
 * The MJCF (gen/prru_mjcf.py) is one open chain slide-hinge-hinge-U per
 * limb (three, or four for the redundant 4-PRRU of spec section 12) with
 * one platform copy per chain, copies 2..n welded to copy 1. MuJoCo
 * computes the tree
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
 *     [ M  J^T ] [ qacc ]   [ tau = qfrc_applied + qfrc_passive - qfrc_bias ]
 *     [ J   0  ] [ -f   ] = [ -J' qvel                                      ]
 * with M = mj_fullM(qM) (armature included), qfrc_applied = fd and the
 * Coulomb force on the slides plus J_O'^T (fp, mp) of platform copy 1 at O'
 * (mj_applyFT at its frame origin), J = the 6 (n_limb - 1) weld rows of
 * efc_J, and J' qvel by a
 * fourth-order central difference of efc_J along qvel,
 *     J' v ~ (8 (J(q+hv) - J(q-hv)) - (J(q+2hv) - J(q-2hv))) / (12 h) v,
 * h = 1e-3 s: truncation ~h^4 |J^(5)| and rounding ~eps |J| / h are both
 * ~1e-13 here. (MuJoCo 2.2.2 exposes no J'; a row transformation of J, as in
 * its quaternion-based weld rows, leaves J' v on the constraint manifold
 * unchanged because J v = 0 there.)
 * With four limbs the 18 weld rows on 20 tree DOF have rank 17, not 18:
 * chains 3 and 4 both keep their copy's O' in the plane y = 0, so the welds
 * of copies 3 and 4 to copy 1 both hold copy 1's O' there: one row says
 * what another already does, and the KKT matrix is singular (f is not
 * unique; qacc is). So the system is
 * solved for qacc alone, for J of any rank: an SVD of J gives its numerical
 * rank r (singular values above RANK_TOL sigma_1; r must be NV - 3, the
 * closed mechanism's 3 DOF, which for three limbs is NC: nothing dropped),
 * a basis N of null(J) (the last NV - r right singular vectors) and the
 * minimum-norm a_p = J^+ (-J'v); then
 *     qacc = a_p + N (N^T M N)^-1 N^T (tau - M a_p),
 * the unique acceleration with J qacc = -J'v (least squares: the part of
 * -J'v outside range(J), which a redundant row's difference quotient could
 * leave, is reported and checked) and N^T (M qacc - tau) = 0 (no work of the
 * constraint forces along the free motions).
 * From qacc: d'' = qacc of the slides,
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
 * accelerations differ from the rigid ones by ~1e-4..2e-2 on the committed
 * models, and by more on others (a bound measured on some models is no
 * bound). That difference is the soft welds', whatever it is: so level 2a
 * checks that mj_forward's qacc is the minimiser of the cost above, built
 * here from MuJoCo's own M, tau, J, R (efc_R: solimp) and aref (efc_aref:
 * solref and the state), to the rounding of the solve (soft_model_check),
 * and reports its distance to the rigid accelerations. The cost is
 * strictly convex for any J (R > 0), so the redundant weld row of four
 * limbs needs nothing special: MuJoCo 2.2.2's Newton solver converges in
 * one iteration as for three limbs, splits the force along e2 evenly
 * between the two rows that carry it (equal R: the R-weighted minimum
 * norm), and the accelerations stay in the same band. Along a trajectory the
 * stiff stabilisation (time constant tc = 2e-4 s, b ~ 1e4 /s, k ~ 2.5e7 /s^2)
 * keeps r and J v near 0 and q stays within ~1e-7 of ours on the paper's
 * model; the loops' give is ~tc^2 times their accelerations, which a violent
 * run (the 4-limb model's) raises to ~6e-6. The run is repeated with the
 * welds twice as stiff (tc and dt halved): the difference to ours falls 4x,
 * and the extrapolation (4 q(tc/2) - q(tc)) / 3 to rigid welds agrees with
 * ours to ~1e-11 (3 limbs) .. 4e-8 (4 limbs): the remaining difference is
 * MuJoCo's soft welds, not the dynamics. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
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
 * (measured <= 5e-14 on the paper's model, models/prototype_example and the
 * 4-limb models/4prru; the issue asks for ~1e-9, 1e-11 leaves room for
 * other MuJoCo builds and still catches a 1e-7 kg error in one link's mass,
 * which shows as 7e-8). Level 2b bounds are ~2-4x the values measured with
 * MuJoCo 2.2.2: the trajectory as written on
 * models/4prru, whose run is the most violent (fd_4 = 0: the platform falls
 * and tilts to q2 = -1.13 rad in 0.48 s; 6.2e-6, the paper's model 1.2e-7,
 * the prototype's damped drives 1.5e-9), and extrapolated to rigid welds
 * on models/4prru (4.3e-8; the 3-limb models ~3e-11). */
#define TOL_EXACT 1e-11
#define TOL_STATE 1e-12     /* poses (m, rotation entries), velocities */
/* 1 s run, max |q_mj - q_ours| (rad, m): the 3-limb bound as before; the
 * redundant model's soft welds cost it (see above). */
#define TOL_TRAJ_Q (PRRU_NACT > 3 ? 2e-5 : 5e-7)
#define TOL_TRAJ_RIGID 2e-7 /* the same, extrapolated to rigid welds */
#define MJ_DT 1e-4          /* mj_step's step, s (the MJCF's timestep) */
/* Numerical rank of the weld rows: singular values below RANK_TOL sigma_1
 * count as 0. The redundant row of the 4-limb model gives ~1e-16 sigma_1,
 * the smallest genuine one is ~1e-2 sigma_1 at the sampled states: the
 * threshold sits far from both, and the rank must come out NV - NQ. */
#define RANK_TOL 1e-9

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

typedef struct {
  int rank;            /* numerical rank of the weld rows J */
  double kept, dropped; /* smallest kept, largest dropped singular value / largest */
  double residual;      /* |N^T (M qacc - tau)| / |tau| */
  double inconsistency; /* |J qacc + J'v| / (|J| |qacc| + |J'v|): the part of -J'v outside range(J) */
} rigid_info;

/* Rigid accelerations from MuJoCo's tree terms at the state in d (after
 * mj_forward): qacc (NV), for weld rows J of any rank (see top):
 * SVD of J (padded with zero rows to NV x NV, so that V is a full basis),
 * rank r where sigma > RANK_TOL sigma_1, N = the last NV - r columns of V
 * (a basis of null(J)), the minimum-norm solution a_p = J^+ (-J'v) and
 * qacc = a_p + N (N^T M N)^-1 N^T (tau - M a_p). */
static int rigid_solve(const mjModel *m, mjData *d, mjData *scratch, double qacc[NV],
                       rigid_info *info)
{
  double M[NV * NV], J[NC * NV], jv[NC], tau[NV];
  double A[NV * NV], V[NV * NV], S[NV], work[NV];
  if (!weld_jacobian(m, d, J) || !jdot_v(m, d, scratch, jv)) return 0;
  mj_fullM(m, M, d->qM);
  for (int k = 0; k < NV; k++) tau[k] = d->qfrc_applied[k] + d->qfrc_passive[k] - d->qfrc_bias[k];
  memset(A, 0, sizeof A);
  memcpy(A, J, sizeof J);
  gsl_matrix_view Av = gsl_matrix_view_array(A, NV, NV), Vv = gsl_matrix_view_array(V, NV, NV);
  gsl_vector_view Sv = gsl_vector_view_array(S, NV);
  gsl_vector_view Wv = gsl_vector_view_array(work, NV);
  if (gsl_linalg_SV_decomp(&Av.matrix, &Vv.matrix, &Sv.vector, &Wv.vector) != 0 || !(S[0] > 0))
    return 0;
  /* GSL sorts the singular values in decreasing order */
  int r = 0;
  while (r < NV && S[r] > RANK_TOL * S[0]) r++;
  info->rank = r;
  info->kept = S[r - 1] / S[0];
  info->dropped = r < NC ? S[r] / S[0] : 0.0; /* S[NC..NV) are the padding's 0 */
  if (r > NC || NV - r != PRRU_NQ) return 0; /* the closed mechanism has NQ DOF */
  /* a_p = V_r S_r^-1 U_r^T (-J'v); U = A now (its first NC rows: J's part) */
  double ap[NV], c[NV];
  memset(ap, 0, sizeof ap);
  for (int i = 0; i < r; i++) {
    double s = 0;
    for (int k = 0; k < NC; k++) s -= A[NV * k + i] * jv[k];
    c[i] = s / S[i];
    for (int j = 0; j < NV; j++) ap[j] += V[NV * j + i] * c[i];
  }
  /* null-space part: (N^T M N) z = N^T (tau - M a_p), N = V[:, r..NV) */
  enum { NN = PRRU_NQ };
  double MN[NV * NN], B[NN * NN], rhs[NN], z[NN], g[NV];
  for (int j = 0; j < NV; j++) {
    double s = tau[j];
    for (int k = 0; k < NV; k++) s -= M[NV * j + k] * ap[k];
    g[j] = s;
    for (int b = 0; b < NN; b++) {
      double t = 0;
      for (int k = 0; k < NV; k++) t += M[NV * j + k] * V[NV * k + r + b];
      MN[NN * j + b] = t;
    }
  }
  for (int a = 0; a < NN; a++) {
    double s = 0;
    for (int j = 0; j < NV; j++) s += V[NV * j + r + a] * g[j];
    rhs[a] = s;
    for (int b = 0; b < NN; b++) {
      double t = 0;
      for (int j = 0; j < NV; j++) t += V[NV * j + r + a] * MN[NN * j + b];
      B[NN * a + b] = t;
    }
  }
  gsl_matrix_view Bv = gsl_matrix_view_array(B, NN, NN);
  gsl_vector_view rv = gsl_vector_view_array(rhs, NN), zv = gsl_vector_view_array(z, NN);
  if (gsl_linalg_cholesky_decomp1(&Bv.matrix) != 0 ||
      gsl_linalg_cholesky_solve(&Bv.matrix, &rv.vector, &zv.vector) != 0)
    return 0;
  for (int j = 0; j < NV; j++) {
    qacc[j] = ap[j];
    for (int b = 0; b < NN; b++) qacc[j] += V[NV * j + r + b] * z[b];
  }
  /* residuals: the dynamics along the free motions, and the part of -J'v
   * that no acceleration reaches (J N = 0, so J qacc = J a_p): rounding
   * for three limbs; with a redundant row, the difference quotient's
   * disagreement between the two rows that say the same */
  double taun = 1e-300, nres = 0, jvn = 1e-300, incons = 0;
  for (int j = 0; j < NV; j++) taun = fmax(taun, fabs(tau[j]));
  for (int b = 0; b < NN; b++) {
    double s = 0;
    for (int j = 0; j < NV; j++) {
      double mq = -tau[j];
      for (int k = 0; k < NV; k++) mq += M[NV * j + k] * qacc[k];
      s += V[NV * j + r + b] * mq;
    }
    nres = fmax(nres, fabs(s));
  }
  for (int k = 0; k < NC; k++) {
    double s = jv[k], t = fabs(jv[k]);
    for (int j = 0; j < NV; j++) {
      s += J[NV * k + j] * qacc[j];
      t += fabs(J[NV * k + j] * qacc[j]);
    }
    jvn = fmax(jvn, t); /* the row's scale: at slow states J'v is ~0 */
    incons = fmax(incons, fabs(s));
  }
  info->residual = nres / taun;
  info->inconsistency = incons / jvn;
  return 1;
}

/* MuJoCo's soft model at the state in d (after mj_forward): the minimiser
 * of its stated cost (see top),
 *     qacc = a0 + M^-1 J^T f,  f = -(A + R)^-1 (J a0 - aref),
 *     a0 = M^-1 tau,  A = J M^-1 J^T,
 * from MuJoCo's own M, tau, weld rows J and their efc_R and efc_aref (the
 * solref/solimp of the MJCF and the step). This is the acceleration MuJoCo
 * must return whatever the softness costs; its distance to the rigid one
 * is the soft welds' error, and is reported, not bounded. cond receives the
 * 2-norm condition number of the cost's Hessian M + J^T R^-1 J, which
 * bounds the rounding of both solvers (MuJoCo's Newton step on it, this
 * Schur complement). */
static int soft_solve(const mjModel *m, const mjData *d, double qacc[NV], double *cond)
{
  double M[NV * NV], J[NC * NV], R[NC], aref[NC], tau[NV], MJt[NV * NC], A[NC * NC], c[NC];
  double Hs[NV * NV], ev[NV];
  if (!weld_jacobian(m, d, J)) return 0;
  for (int r = 0, row = 0; r < d->nefc; r++)
    if (d->efc_type[r] == mjCNSTR_EQUALITY && row < NC) {
      R[row] = d->efc_R[r];
      aref[row++] = d->efc_aref[r];
    }
  mj_fullM(m, M, d->qM);
  for (int k = 0; k < NV; k++) tau[k] = d->qfrc_applied[k] + d->qfrc_passive[k] - d->qfrc_bias[k];
  /* the Hessian's spectrum, before M is factorised */
  for (int i = 0; i < NV; i++)
    for (int j = 0; j < NV; j++) {
      double s = M[NV * i + j];
      for (int r = 0; r < NC; r++) s += J[NV * r + i] * J[NV * r + j] / R[r];
      Hs[NV * i + j] = s;
    }
  gsl_matrix_view Hv = gsl_matrix_view_array(Hs, NV, NV);
  gsl_vector_view ew = gsl_vector_view_array(ev, NV);
  gsl_eigen_symm_workspace *ws = gsl_eigen_symm_alloc(NV);
  int bad = gsl_eigen_symm(&Hv.matrix, &ew.vector, ws);
  gsl_eigen_symm_free(ws);
  double lo = INFINITY, hi = 0;
  for (int i = 0; i < NV; i++) {
    lo = fmin(lo, ev[i]);
    hi = fmax(hi, ev[i]);
  }
  if (bad || !(lo > 0)) return 0;
  *cond = hi / lo;
  /* a0 = M^-1 tau, M^-1 J^T */
  gsl_matrix_view Mv = gsl_matrix_view_array(M, NV, NV);
  if (gsl_linalg_cholesky_decomp1(&Mv.matrix) != 0) return 0;
  gsl_vector_view a0 = gsl_vector_view_array(qacc, NV);
  memcpy(qacc, tau, sizeof tau);
  gsl_linalg_cholesky_svx(&Mv.matrix, &a0.vector);
  for (int r = 0; r < NC; r++) {
    double col[NV];
    memcpy(col, J + NV * r, sizeof col);
    gsl_vector_view cv = gsl_vector_view_array(col, NV);
    gsl_linalg_cholesky_svx(&Mv.matrix, &cv.vector);
    for (int k = 0; k < NV; k++) MJt[NC * k + r] = col[k];
  }
  /* (A + R) f = -(J a0 - aref) */
  for (int r = 0; r < NC; r++) {
    double s = -aref[r];
    for (int k = 0; k < NV; k++) s += J[NV * r + k] * qacc[k];
    c[r] = -s;
    for (int t = 0; t < NC; t++) {
      double a = 0;
      for (int k = 0; k < NV; k++) a += J[NV * r + k] * MJt[NC * k + t];
      A[NC * r + t] = a + (r == t ? R[r] : 0.0);
    }
  }
  gsl_matrix_view Av = gsl_matrix_view_array(A, NC, NC);
  gsl_vector_view cv = gsl_vector_view_array(c, NC);
  if (gsl_linalg_cholesky_decomp1(&Av.matrix) != 0 ||
      gsl_linalg_cholesky_svx(&Av.matrix, &cv.vector) != 0)
    return 0;
  for (int k = 0; k < NV; k++)
    for (int r = 0; r < NC; r++) qacc[k] += MJt[NC * k + r] * c[r];
  return 1;
}

typedef struct {
  double worst;    /* max |qacc_mj - qacc_soft| / max |qacc_soft| */
  double ratio;    /* max of that over its bound */
  double cond;     /* largest condition number of the Hessian seen */
  int failed;      /* states where the soft solve failed */
} soft_stats;

/* mj_forward's qacc in d against soft_solve's. Both solve the same
 * quadratic cost from the same terms, so they differ by rounding only:
 * a backward-stable solve of an NV-dimensional system perturbs its
 * solution by ~NV eps cond relative (cond: the Hessian's condition
 * number); the bound is 4x that for the two solvers together. MuJoCo's
 * Newton solver lands on the minimiser of this quadratic cost in one
 * step, so its iteration tolerance adds nothing (checked here). */
static void soft_model_check(const mjModel *m, const mjData *d, soft_stats *st)
{
  double qs[NV], cond;
  if (!soft_solve(m, d, qs, &cond)) {
    st->failed++;
    return;
  }
  const double bound = 4.0 * NV * DBL_EPSILON * cond;
  const double e = tu_relerr(d->qacc, qs, NV, 1e-300);
  st->worst = fmax(st->worst, e);
  st->ratio = fmax(st->ratio, e / bound);
  st->cond = fmax(st->cond, cond);
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


/* Level 2b: the scenario with mj_step (RK4), the welds' time constant
 * (solref[0]) scaled by `stiff` and the step MJ_DT with it (MuJoCo raises a
 * time constant below 2 dt to 2 dt); q of platform copy 1 at nsamp samples
 * dt_out apart into qm (3 nsamp), and how far the copies drift apart. */
static int mj_run(mjModel *m, mjData *d, const mjmap *mp, const prru_scenario *sc,
                  double dt_out, int nsamp, double stiff, double *qm, double *spread)
{
  double solref[NLIMB - 1] = {0};
  state_residuals sr;
  if (m->neq != NLIMB - 1) return 0;
  for (int e = 0; e < m->neq; e++) {
    solref[e] = m->eq_solref[mjNREF * e];
    m->eq_solref[mjNREF * e] *= stiff;
  }
  mj_resetData(m, d);
  m->opt.timestep = MJ_DT * stiff;
  m->opt.integrator = mjINT_RK4;
  int per_sample = (int)floor(dt_out / m->opt.timestep + 0.5);
  int ok = set_state(m, d, mp, sc->q0, sc->qd0, &sr);
  d->time = 0;
  mjcb_control = apply_loads;
  *spread = 0;
  for (int k = 0; ok && k < nsamp; k++) {
    if (k > 0) {
      for (int s = 0; s < per_sample; s++) mj_step(m, d);
      mj_kinematics(m, d); /* mj_step leaves the poses of the step's start */
    }
    platform_q(d, mp->P[0], qm + 3 * k);
    for (int c = 1; c < NLIMB; c++) {
      double qc[3];
      platform_q(d, mp->P[c], qc);
      for (int j = 0; j < 3; j++) *spread = fmax(*spread, fabs(qc[j] - qm[3 * k + j]));
    }
  }
  mjcb_control = NULL;
  for (int e = 0; e < m->neq; e++) m->eq_solref[mjNREF * e] = solref[e];
  m->opt.timestep = MJ_DT;
  return ok;
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
  double worst_incons = 0, min_kept = 1, max_dropped = 0;
  int rank = -1, rank_varies = 0;
  double worst_dd = 0, worst_w = 0, soft_dd = 0, soft_w = 0, rest_dd = 0, rest_w = 0;
  soft_stats soft = {0, 0, 0, 0};
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

    /* level 2a: MuJoCo's own (soft) accelerations at this state, and the
     * soft model's minimiser from MuJoCo's terms */
    double dd_soft[NLIMB], w_soft[NLIMB][3];
    mj_outputs(m, d, &mp, dd_soft, w_soft);
    soft_model_check(m, d, &soft);

    /* level 1 */
    double qacc[NV], dd_mj[NLIMB], w_mj[NLIMB][3], dd_ours[PRRU_NACT], w_ours[3];
    rigid_info ri = {-1, 0, 0, 0, 0};
    if (!TU_TRUE(rigid_solve(m, d, scratch, qacc, &ri), "rigid KKT solve (rank NV - NQ)")) {
      fprintf(stderr, "  weld rows of rank %d (sigma_r/sigma_1 %.1e, next %.1e), expected %d\n",
              ri.rank, ri.kept, ri.dropped, NV - PRRU_NQ);
      continue;
    }
    rank_varies |= rank >= 0 && ri.rank != rank;
    rank = ri.rank;
    worst_kkt = fmax(worst_kkt, ri.residual);
    worst_incons = fmax(worst_incons, ri.inconsistency);
    min_kept = fmin(min_kept, ri.kept);
    max_dropped = fmax(max_dropped, ri.dropped);
    tu_check(ri.residual <= TOL_EXACT, "level 1: dynamics residual along null(J)", ri.residual,
             TOL_EXACT);
    tu_check(ri.inconsistency <= TOL_EXACT, "level 1: J qacc + J'v (redundant rows agree)",
             ri.inconsistency, TOL_EXACT);
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
      soft_model_check(m, d, &soft);
      rest_dd = fmax(rest_dd, tu_relerr(dd_soft, dd_ours, NLIMB, 1e-300));
      rest_w = fmax(rest_w, tu_relerr(w_soft[0], w_ours, 3, 1e-300));
    }
    n++;
  }
  TU_TRUE(n == NSTATES, "enough regular states sampled");
  tu_check(worst_copy <= TOL_EXACT, "rigid qacc: the platform copies agree", worst_copy,
           TOL_EXACT);
  TU_TRUE(!rank_varies, "the weld rows have the same rank at every state");
  tu_check(soft.failed == 0, "level 2: the soft model's minimiser (regular Hessian)", soft.failed, 0);
  tu_check(soft.ratio <= 1, "level 2: mj_forward qacc = the soft model's minimiser (error / bound)",
           soft.ratio, 1);
  printf("state transfer (%d states): poses/velocities %.1e, weld efc_pos %.1e, J qvel %.1e\n",
         n, worst_state, worst_weld, worst_wvel);
  char dropped[64] = "none dropped";
  if (rank >= 0 && rank < NC) snprintf(dropped, sizeof dropped, "largest dropped %.1e", max_dropped);
  printf("level 1, rigid KKT from MuJoCo's M, qfrc_bias, efc_J, J'v:\n"
         "  %d weld rows of rank %d = %d tree DOF - %d (%d redundant; singular values / largest:"
         " smallest kept %.1e, %s);\n"
         "  residual along null(J) %.1e, J qacc + J'v %.1e (the rows' J'v agree to that)\n"
         "  max relative difference vs prru_forward_dynamics: d'' %.2e, platform alpha %.2e"
         " (bound %.0e); copies agree to %.1e\n",
         NC, rank, NV, NV - rank, NC - rank, min_kept, dropped, worst_kkt, worst_incons,
         worst_dd, worst_w, TOL_EXACT, worst_copy);
  printf("level 2, mj_forward = the soft model's minimiser from MuJoCo's M, tau, J, efc_R, efc_aref:\n"
         "  %.1e relative (%.2g of its bound 4 NV eps cond, Hessian cond <= %.1e);\n"
         "  the soft welds' error, mj_forward vs rigid: d'' %.2e, platform alpha %.2e;\n"
         "  same states at rest (no J'v, impedance only): d'' %.2e, platform alpha %.2e\n",
         soft.worst, soft.ratio, soft.cond, soft_dd, soft_w, rest_dd, rest_w);

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
    g_schedule = &sc.loads;
    g_map = &mp;
    /* the MJCF as written, then its welds twice as stiff (time constant
     * and step halved) */
    double *qm1 = malloc(sizeof(double) * 3 * (size_t)nsamp);
    double *qm2 = malloc(sizeof(double) * 3 * (size_t)nsamp);
    double spread1 = 0, spread2 = 0, tc = m->eq_solref[0];
    int ran = TU_TRUE(mj_run(m, d, &mp, &sc, sc.opt.dt_out, nsamp, 1.0, qm1, &spread1) &&
                          mj_run(m, d, &mp, &sc, sc.opt.dt_out, nsamp, 0.5, qm2, &spread2),
                      "initial state transfer");
    double dq[3] = {0, 0, 0}, dq2 = 0, dqx = 0;
    for (int k = 0; ran && k < nsamp; k++)
      for (int c = 0; c < 3; c++) {
        double ours = tr.q[3 * k + c];
        dq[c] = fmax(dq[c], fabs(qm1[3 * k + c] - ours));
        dq2 = fmax(dq2, fabs(qm2[3 * k + c] - ours));
        dqx = fmax(dqx, fabs((4 * qm2[3 * k + c] - qm1[3 * k + c]) / 3 - ours));
      }
    double worst = fmax(dq[0], fmax(dq[1], dq[2]));
    printf("level 2, paper scenario from %s, mj_step RK4 dt = %g vs prru_simulate (%s, tol %g):\n"
           "  max |q_mj - q_ours| over %d samples (%g s): q1 %.2e rad, q2 %.2e rad, q3 %.2e m"
           " (bound %.0e); platform copies drift apart by %.1e;\n"
           "  welds twice as stiff (time constant %g s, dt %g): %.2e (%.1fx less), copies %.1e;"
           " extrapolated to rigid welds: %.2e (bound %.0e)\n",
           start, MJ_DT, prru_stepper_name(sc.opt.stepper), sc.opt.rel_tol, nsamp,
           tr.t[nsamp - 1], dq[0], dq[1], dq[2], TOL_TRAJ_Q, spread1, tc / 2, MJ_DT / 2, dq2,
           worst / dq2, spread2, dqx, TOL_TRAJ_RIGID);
    tu_check(worst <= TOL_TRAJ_Q, "level 2: trajectory q", worst, TOL_TRAJ_Q);
    tu_check(dqx <= TOL_TRAJ_RIGID, "level 2: trajectory q, extrapolated to rigid welds", dqx,
             TOL_TRAJ_RIGID);
    free(qm1);
    free(qm2);
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
