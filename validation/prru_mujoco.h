/* State transfer between the runtime and the MJCF of gen/prru_mjcf.py,
 * shared by validate_mujoco and bench_mujoco.
 *
 * The layout comes from the generated descriptor prru_mech (body indices
 * and names, joint names, sizes), never from literals: per limb i the MJCF
 * has the bodies slider, upper and lower link (prru_mech's names) and a
 * platform copy "platform<i>", and the joints P<i> (slide), A<i>, B<i>
 * (hinges) and the U joint's two hinges C<i>a, C<i>b.
 *
 * For (q, qd) the body poses and velocities come from our kernels
 * (prru_poses, prru_jacobians: rotations R_b and centres of mass p_b). A
 * MuJoCo body frame is the frame origin of the spec's pose functions,
 * origin_b = p_b - R_b com_b, and its <inertial> sits at com_b, so MuJoCo's
 * xmat and xipos are our R_b and p_b. Every MuJoCo joint coordinate is the
 * relative rotation (or slide) between the two bodies it joins, measured
 * from the model's reference pose (body_quat/body_pos), and every joint
 * velocity is the relative angular (or linear) velocity along the joint
 * axis. set_state reports how well MuJoCo then reproduces our poses, body
 * velocities and closed loops. */
#ifndef PRRU_MUJOCO_H
#define PRRU_MUJOCO_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "prru.h"
#include "prru_kernels.h"
#include "prru_mechanism.h"

/* Sizes of the MJCF, from the descriptor: per limb five tree DOF (slide,
 * two hinges, the U joint's two hinges) and one platform copy; the copies
 * 2..n are welded to copy 1 (6 rows each). For n = 3 the 12 rows are
 * independent and the closed mechanism has 15 - 12 = PRRU_NQ DOF; for the
 * redundant n = 4 one of the 18 rows repeats another (limbs 3 and 4 both
 * hold O' in the plane y = 0): rank 17, and again 20 - 17 = PRRU_NQ DOF. */
#define NLIMB PRRU_NLIMB
#define NJL 5 /* joints per limb: slide, A, B, C a, C b */
#define NV (NJL * NLIMB)
#define NC (6 * (NLIMB - 1))
#define NBODY_MJ (4 * NLIMB) /* S, U, L and a platform copy per limb */

typedef struct {
  int S[NLIMB], U[NLIMB], L[NLIMB], P[NLIMB]; /* MuJoCo body ids */
  int jnt[NLIMB][NJL];                        /* slide, A, B, Ca, Cb */
  int slide_dof[NLIMB];
  double coulomb[NLIMB][2];                   /* f (N), v_s (m/s) from the MJCF */
} mjmap;

static inline int lookup(const mjModel *m, int type, const char *name, const char *what)
{
  int id = mj_name2id(m, type, name);
  if (id < 0) fprintf(stderr, "validate_mujoco: the MJCF has no %s named '%s'\n", what, name);
  return id;
}

/* Name of the descriptor's joint of type t ('P', 'R', 'U') whose distal
 * body is `distal` (the slide, A, B joints; C: distal is the platform, so
 * it is found by limb). */
static inline const char *mech_joint(char t, int limb, int distal)
{
  for (int j = 0; j < prru_mech.njoint; j++) {
    const prru_joint_info *ji = &prru_mech.joint[j];
    if (ji->type == t && ji->limb == limb && (distal < 0 || ji->distal == distal))
      return ji->name;
  }
  return "?";
}

static inline int build_map(const mjModel *m, mjmap *mp)
{
  char name[64];
  int ok = 1;
  if (m->nq != NV || m->nv != NV || m->neq != NLIMB - 1 || m->nbody - 1 != NBODY_MJ) {
    fprintf(stderr, "validate_mujoco: expected %d bodies, %d hinge/slide joints and %d welds "
                    "(%d limbs), got nbody=%d nq=%d nv=%d neq=%d\n", NBODY_MJ, NV, NLIMB - 1,
            NLIMB, m->nbody - 1, m->nq, m->nv, m->neq);
    return 0;
  }
  for (int i = 0; i < NLIMB; i++) {
    const char *jname[NJL] = {mech_joint('P', i, prru_mech.slider[i]),
                              mech_joint('R', i, prru_mech.upper[i]),
                              mech_joint('R', i, prru_mech.lower[i]), NULL, NULL};
    const char *cname = mech_joint('U', i, -1);
    ok &= (mp->S[i] = lookup(m, mjOBJ_BODY, prru_mech.body_names[prru_mech.slider[i]],
                             "body")) >= 0;
    ok &= (mp->U[i] = lookup(m, mjOBJ_BODY, prru_mech.body_names[prru_mech.upper[i]],
                             "body")) >= 0;
    ok &= (mp->L[i] = lookup(m, mjOBJ_BODY, prru_mech.body_names[prru_mech.lower[i]],
                             "body")) >= 0;
    snprintf(name, sizeof name, "platform%d", i + 1);
    ok &= (mp->P[i] = lookup(m, mjOBJ_BODY, name, "body")) >= 0;
    for (int k = 0; k < NJL; k++) {
      if (k < 3)
        snprintf(name, sizeof name, "%s", jname[k]);
      else
        snprintf(name, sizeof name, "%s%c", cname, k == 3 ? 'a' : 'b');
      ok &= (mp->jnt[i][k] = lookup(m, mjOBJ_JOINT, name, "joint")) >= 0;
    }
    if (!ok) return 0;
    mp->slide_dof[i] = m->jnt_dofadr[mp->jnt[i][0]];
    /* the drive's Coulomb law, which MuJoCo does not model (see the MJCF) */
    snprintf(name, sizeof name, "%s_coulomb", jname[0]);
    int id = lookup(m, mjOBJ_NUMERIC, name, "custom numeric");
    if (id < 0 || m->numeric_size[id] != 2) return 0;
    mp->coulomb[i][0] = m->numeric_data[m->numeric_adr[id]];
    mp->coulomb[i][1] = m->numeric_data[m->numeric_adr[id] + 1];
    if (mp->coulomb[i][0] != 0 && !(mp->coulomb[i][1] > 0)) {
      fprintf(stderr, "validate_mujoco: %s: Coulomb force without a smoothing velocity\n", name);
      return 0;
    }
  }
  return ok;
}

/* ---- small 3-vector / 3x3 helpers (row-major) ---- */
static inline double dot3(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void cross3(double *r, const double *a, const double *b)
{
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}

/* r = a^T b */
static inline void mulTN(double *r, const double *a, const double *b)
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) r[3 * i + j] = a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j];
}

static inline void rotvec(double *r, const double *R, const double *v)
{
  for (int i = 0; i < 3; i++) r[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
}

/* Angle of X = Rot(a, theta) about the unit axis a: sin from the skew part,
 * cos from the trace, so no acos/asin loses accuracy near 0 or pi/2. */
static inline double hinge_angle(const double *X, const double *a)
{
  double w[3] = {0.5 * (X[7] - X[5]), 0.5 * (X[2] - X[6]), 0.5 * (X[3] - X[1])};
  return atan2(dot3(w, a), 0.5 * (X[0] + X[4] + X[8] - 1.0));
}

static inline void axis_rot(double *R, const double *a, double theta)
{
  double qu[4];
  mju_axisAngle2Quat(qu, a, theta);
  mju_quat2Mat(R, qu);
}

/* Rotation of the child in the parent at the reference pose, Rbq, and
 * X = Rbq^T R_parent^T R_child = the product of the child's joint rotations. */
static inline void joint_rotation(const mjModel *m, int child, const double *Rparent,
                           const double *Rchild, double *X)
{
  double Rbq[9], rel[9];
  mju_quat2Mat(Rbq, m->body_quat + 4 * child);
  mulTN(rel, Rparent, Rchild);
  mulTN(X, Rbq, rel);
}

typedef struct {
  double pose, vel, weld_pos, weld_vel, ujoint;  /* residuals */
} state_residuals;

/* The drive's smoothed Coulomb force at slide velocity v (MJCF custom data). */
static inline double coulomb_force(const mjmap *mp, int limb, double v)
{
  double f = mp->coulomb[limb][0];
  return f != 0 ? -f * tanh(v / mp->coulomb[limb][1]) : 0.0;
}

/* The loads as MuJoCo's generalized applied force at the state in d
 * (kinematics and qvel current): fd along each slide plus the drive's
 * Coulomb force at the slide velocity, and (fp, mp) on platform copy 1 at
 * its frame origin O' (xpos; xfrc_applied would act at the centre of mass
 * xipos, which is not O' when the platform's com is offset). Armature and
 * damping are MuJoCo's own (qM, qfrc_passive). */
static inline void mj_load_forces(const mjModel *m, mjData *d, const mjmap *mp,
                                  const prru_loads *l, double *qfrc)
{
  mju_zero(qfrc, m->nv);
  for (int i = 0; i < NLIMB; i++) {
    int dof = mp->slide_dof[i];
    qfrc[dof] += l->fd[i] + coulomb_force(mp, i, d->qvel[dof]);
  }
  mj_applyFT(m, d, l->fp, l->mp, d->xpos + 3 * mp->P[0], mp->P[0], qfrc);
}

/* Sets d->qpos, d->qvel from our (q, qd), runs mj_forward (with whatever
 * loads d holds) and measures how well MuJoCo reproduces our state. */
static inline int set_state(const mjModel *m, mjData *d, const mjmap *mp, const double q[3],
                     const double qd[3], state_residuals *res)
{
  enum { NB = PRRU_NBODY };
  double R[9 * NB], p[3 * NB], H[3 * PRRU_NH], w[3 * NB], v[3 * NB], o[3 * NB];
  const int bP = prru_mech.platform;
  prru_poses(q, R, p);
  prru_jacobians(q, H);
  for (int r = 0; r < PRRU_NH; r++) {
    double s = H[3 * r] * qd[0] + H[3 * r + 1] * qd[1] + H[3 * r + 2] * qd[2];
    if (r < 3 * NB) w[r] = s; else v[r - 3 * NB] = s;
  }
  /* frame origins: o_b = p_b - R_b com_b */
  for (int b = 0; b < NB; b++) {
    double rc[3];
    rotvec(rc, R + 9 * b, prru_mech.com[b]);
    for (int k = 0; k < 3; k++) o[3 * b + k] = p[3 * b + k] - rc[k];
  }
  for (int i = 0; i < 3 * NB; i++)
    if (!isfinite(o[i]) || !isfinite(w[i]) || !isfinite(v[i])) return 0;
  const double *RP = R + 9 * bP;
  for (int i = 0; i < NLIMB; i++) {
    int bS = prru_mech.slider[i], bU = prru_mech.upper[i], bL = prru_mech.lower[i];
    const int *jn = mp->jnt[i];
    double X[9], Y[9], Ra[9], Rs0[9], ax[3], t1, t2;
    /* slide: the slider's frame origin along its world axis from the
     * reference position */
    mju_quat2Mat(Rs0, m->body_quat + 4 * mp->S[i]);
    rotvec(ax, Rs0, m->jnt_axis + 3 * jn[0]);
    double dp[3] = {o[3 * bS] - m->body_pos[3 * mp->S[i]], o[3 * bS + 1] - m->body_pos[3 * mp->S[i] + 1],
                    o[3 * bS + 2] - m->body_pos[3 * mp->S[i] + 2]};
    d->qpos[m->jnt_qposadr[jn[0]]] = dot3(dp, ax);
    joint_rotation(m, mp->U[i], R + 9 * bS, R + 9 * bU, X);
    d->qpos[m->jnt_qposadr[jn[1]]] = hinge_angle(X, m->jnt_axis + 3 * jn[1]);
    joint_rotation(m, mp->L[i], R + 9 * bU, R + 9 * bL, X);
    d->qpos[m->jnt_qposadr[jn[2]]] = hinge_angle(X, m->jnt_axis + 3 * jn[2]);
    /* U joint: X = Rot(a1, t1) Rot(a2, t2), a1 _|_ a2, so X a2 = Rot(a1, t1) a2
     * = cos t1 a2 + sin t1 (a1 x a2). */
    const double *a1 = m->jnt_axis + 3 * jn[3], *a2 = m->jnt_axis + 3 * jn[4];
    double Xa2[3], n[3];
    joint_rotation(m, mp->P[i], R + 9 * bL, RP, X);
    rotvec(Xa2, X, a2);
    cross3(n, a1, a2);
    t1 = atan2(dot3(n, Xa2), dot3(a2, Xa2));
    axis_rot(Ra, a1, t1);
    mulTN(Y, Ra, X);
    t2 = hinge_angle(Y, a2);
    d->qpos[m->jnt_qposadr[jn[3]]] = t1;
    d->qpos[m->jnt_qposadr[jn[4]]] = t2;
  }
  mj_kinematics(m, d);
  /* velocities along the (now posed) joint axes */
  res->ujoint = 0;
  for (int i = 0; i < NLIMB; i++) {
    int bS = prru_mech.slider[i], bU = prru_mech.upper[i], bL = prru_mech.lower[i];
    const int *jn = mp->jnt[i];
    double rel[3], arm[3], wxr[3];
    /* the slider frame origin's velocity: v_S - w_S x (p_S - o_S) */
    for (int k = 0; k < 3; k++) arm[k] = p[3 * bS + k] - o[3 * bS + k];
    cross3(wxr, w + 3 * bS, arm);
    for (int k = 0; k < 3; k++) rel[k] = v[3 * bS + k] - wxr[k];
    d->qvel[m->jnt_dofadr[jn[0]]] = dot3(rel, d->xaxis + 3 * jn[0]);
    for (int k = 0; k < 3; k++) rel[k] = w[3 * bU + k] - w[3 * bS + k];
    d->qvel[m->jnt_dofadr[jn[1]]] = dot3(rel, d->xaxis + 3 * jn[1]);
    for (int k = 0; k < 3; k++) rel[k] = w[3 * bL + k] - w[3 * bU + k];
    d->qvel[m->jnt_dofadr[jn[2]]] = dot3(rel, d->xaxis + 3 * jn[2]);
    /* omega_P - omega_L = t1' a1 + t2' a2: least squares (normal equations) */
    for (int k = 0; k < 3; k++) rel[k] = w[3 * bP + k] - w[3 * bL + k];
    const double *a1 = d->xaxis + 3 * jn[3], *a2 = d->xaxis + 3 * jn[4];
    double g11 = dot3(a1, a1), g12 = dot3(a1, a2), g22 = dot3(a2, a2);
    double r1 = dot3(a1, rel), r2 = dot3(a2, rel), det = g11 * g22 - g12 * g12;
    double t1 = (g22 * r1 - g12 * r2) / det, t2 = (g11 * r2 - g12 * r1) / det;
    d->qvel[m->jnt_dofadr[jn[3]]] = t1;
    d->qvel[m->jnt_dofadr[jn[4]]] = t2;
    for (int k = 0; k < 3; k++) res->ujoint = fmax(res->ujoint, fabs(rel[k] - t1 * a1[k] - t2 * a2[k]));
  }
  mj_forward(m, d);
  /* MuJoCo's poses (frame rotation xmat, centre of mass xipos) and body
   * velocities (mjOBJ_BODY: at the centre of mass) vs ours */
  res->pose = res->vel = 0;
  for (int i = 0; i < NBODY_MJ; i++) {
    int limb = i % NLIMB, kind = i / NLIMB; /* S, U, L, platform copy */
    int mb = (kind == 0 ? mp->S : kind == 1 ? mp->U : kind == 2 ? mp->L : mp->P)[limb];
    int ob = kind == 0   ? prru_mech.slider[limb]
             : kind == 1 ? prru_mech.upper[limb]
             : kind == 2 ? prru_mech.lower[limb]
                         : bP;
    double vel6[6];
    for (int k = 0; k < 3; k++) res->pose = fmax(res->pose, fabs(d->xipos[3 * mb + k] - p[3 * ob + k]));
    for (int k = 0; k < 9; k++) res->pose = fmax(res->pose, fabs(d->xmat[9 * mb + k] - R[9 * ob + k]));
    mj_objectVelocity(m, d, mjOBJ_BODY, mb, vel6, 0);
    for (int k = 0; k < 3; k++) {
      res->vel = fmax(res->vel, fabs(vel6[k] - w[3 * ob + k]));
      res->vel = fmax(res->vel, fabs(vel6[3 + k] - v[3 * ob + k]));
    }
  }
  res->weld_pos = res->weld_vel = 0;
  for (int r = 0; r < d->nefc; r++)
    if (d->efc_type[r] == mjCNSTR_EQUALITY) {
      res->weld_pos = fmax(res->weld_pos, fabs(d->efc_pos[r]));
      res->weld_vel = fmax(res->weld_vel, fabs(d->efc_vel[r]));
    }
  return 1;
}

/* ---- level 2: a scenario with mj_step ---- */
static const prru_load_schedule *g_schedule;
static const mjmap *g_map;

/* mjcb_control runs at every RK4 stage with d->time, the poses and qvel of
 * that stage. */
static inline void apply_loads(const mjModel *m, mjData *d)
{
  prru_loads l;
  prru_schedule_eval(g_schedule, d->time, &l);
  mju_zero(d->xfrc_applied, 6 * m->nbody);
  mj_load_forces(m, d, g_map, &l, d->qfrc_applied);
}

/* q of a platform copy from its frame: R_P = Rx(q1) Ry(q2), p_P = (0, 0, q3)
 * at the frame origin O' (xpos). */
static inline void platform_q(const mjData *d, int body, double q[3])
{
  const double *R = d->xmat + 9 * body;
  q[0] = atan2(R[7], R[4]);
  q[1] = atan2(R[2], hypot(R[0], R[1]));
  q[2] = d->xpos[3 * body + 2];
}

typedef struct {
  int n, cap;
  double *t, *q;
} trajectory;

static inline int record_sample(const prru_sample *s, void *ctx)
{
  trajectory *tr = ctx;
  if (tr->n == tr->cap) return 1;
  tr->t[tr->n] = s->t;
  memcpy(tr->q + 3 * tr->n, s->q, sizeof s->q);
  tr->n++;
  return 0;
}

#endif
