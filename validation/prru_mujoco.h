/* State transfer between the runtime and the MJCF of gen/prru_mjcf.py,
 * shared by validate_mujoco and bench_mujoco.
 *
 * For (q, qd) the body poses and velocities come from our kernels
 * (prru_poses, prru_jacobians); every MuJoCo joint coordinate is the
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

#define NV 15
#define NC 12

/* Our body order: P L1 L2 L3 U1 U2 U3 S1 S2 S3. */
enum { OB_P = 0, OB_L = 1, OB_U = 4, OB_S = 7 };

typedef struct {
  int S[3], U[3], L[3], P[3];     /* MuJoCo body ids */
  int jnt[3][5];                  /* slide, A, B, Ca, Cb */
} mjmap;

static const char *const joint_fmt[5] = {"P%d", "A%d", "B%d", "C%da", "C%db"};

static inline int lookup(const mjModel *m, int type, const char *name, const char *what)
{
  int id = mj_name2id(m, type, name);
  if (id < 0) fprintf(stderr, "validate_mujoco: the MJCF has no %s named '%s'\n", what, name);
  return id;
}

static inline int build_map(const mjModel *m, mjmap *mp)
{
  char name[32];
  int ok = 1;
  if (m->nq != NV || m->nv != NV || m->neq != 2) {
    fprintf(stderr, "validate_mujoco: expected 15 hinge/slide joints and 2 welds, got nq=%d "
                    "nv=%d neq=%d\n", m->nq, m->nv, m->neq);
    return 0;
  }
  for (int i = 0; i < 3; i++) {
    snprintf(name, sizeof name, "S%d", i + 1);
    ok &= (mp->S[i] = lookup(m, mjOBJ_BODY, name, "body")) >= 0;
    snprintf(name, sizeof name, "U%d", i + 1);
    ok &= (mp->U[i] = lookup(m, mjOBJ_BODY, name, "body")) >= 0;
    snprintf(name, sizeof name, "L%d", i + 1);
    ok &= (mp->L[i] = lookup(m, mjOBJ_BODY, name, "body")) >= 0;
    snprintf(name, sizeof name, "platform%d", i + 1);
    ok &= (mp->P[i] = lookup(m, mjOBJ_BODY, name, "body")) >= 0;
    for (int k = 0; k < 5; k++) {
      snprintf(name, sizeof name, joint_fmt[k], i + 1);
      ok &= (mp->jnt[i][k] = lookup(m, mjOBJ_JOINT, name, "joint")) >= 0;
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

/* Sets d->qpos, d->qvel from our (q, qd), runs mj_forward (with whatever
 * loads d holds) and measures how well MuJoCo reproduces our state. */
static inline int set_state(const mjModel *m, mjData *d, const mjmap *mp, const double q[3],
                     const double qd[3], state_residuals *res)
{
  double R[90], p[30], H[180], w[30], v[30];
  prru_poses(q, R, p);
  prru_jacobians(q, H);
  for (int r = 0; r < 60; r++) {
    double s = H[3 * r] * qd[0] + H[3 * r + 1] * qd[1] + H[3 * r + 2] * qd[2];
    if (r < 30) w[r] = s; else v[r - 30] = s;
  }
  for (int i = 0; i < 30; i++)
    if (!isfinite(p[i]) || !isfinite(w[i]) || !isfinite(v[i])) return 0;
  const double *RP = R + 9 * OB_P;
  for (int i = 0; i < 3; i++) {
    int bS = OB_S + i, bU = OB_U + i, bL = OB_L + i;
    const int *jn = mp->jnt[i];
    double X[9], Y[9], Ra[9], Rs0[9], ax[3], t1, t2;
    /* slide: along its world axis from the reference position */
    mju_quat2Mat(Rs0, m->body_quat + 4 * mp->S[i]);
    rotvec(ax, Rs0, m->jnt_axis + 3 * jn[0]);
    double dp[3] = {p[3 * bS] - m->body_pos[3 * mp->S[i]], p[3 * bS + 1] - m->body_pos[3 * mp->S[i] + 1],
                    p[3 * bS + 2] - m->body_pos[3 * mp->S[i] + 2]};
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
  for (int i = 0; i < 3; i++) {
    int bS = OB_S + i, bU = OB_U + i, bL = OB_L + i;
    const int *jn = mp->jnt[i];
    double rel[3];
    d->qvel[m->jnt_dofadr[jn[0]]] = dot3(v + 3 * bS, d->xaxis + 3 * jn[0]);
    for (int k = 0; k < 3; k++) rel[k] = w[3 * bU + k] - w[3 * bS + k];
    d->qvel[m->jnt_dofadr[jn[1]]] = dot3(rel, d->xaxis + 3 * jn[1]);
    for (int k = 0; k < 3; k++) rel[k] = w[3 * bL + k] - w[3 * bU + k];
    d->qvel[m->jnt_dofadr[jn[2]]] = dot3(rel, d->xaxis + 3 * jn[2]);
    /* omega_P - omega_L = t1' a1 + t2' a2: least squares (normal equations) */
    for (int k = 0; k < 3; k++) rel[k] = w[3 * OB_P + k] - w[3 * bL + k];
    const double *a1 = d->xaxis + 3 * jn[3], *a2 = d->xaxis + 3 * jn[4];
    double g11 = dot3(a1, a1), g12 = dot3(a1, a2), g22 = dot3(a2, a2);
    double r1 = dot3(a1, rel), r2 = dot3(a2, rel), det = g11 * g22 - g12 * g12;
    double t1 = (g22 * r1 - g12 * r2) / det, t2 = (g11 * r2 - g12 * r1) / det;
    d->qvel[m->jnt_dofadr[jn[3]]] = t1;
    d->qvel[m->jnt_dofadr[jn[4]]] = t2;
    for (int k = 0; k < 3; k++) res->ujoint = fmax(res->ujoint, fabs(rel[k] - t1 * a1[k] - t2 * a2[k]));
  }
  mj_forward(m, d);
  /* MuJoCo's poses and body velocities vs ours */
  res->pose = res->vel = 0;
  for (int i = 0; i < 12; i++) {
    int limb = i % 3, kind = i / 3; /* S, U, L, platform copy */
    int mb = (kind == 0 ? mp->S : kind == 1 ? mp->U : kind == 2 ? mp->L : mp->P)[limb];
    int ob = kind == 0 ? OB_S + limb : kind == 1 ? OB_U + limb : kind == 2 ? OB_L + limb : OB_P;
    double vel6[6];
    for (int k = 0; k < 3; k++) res->pose = fmax(res->pose, fabs(d->xpos[3 * mb + k] - p[3 * ob + k]));
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

/* ---- level 2: the paper's scenario with mj_step ---- */
static const prru_load_schedule *g_schedule;
static int g_slide_dof[3], g_platform;

/* mjcb_control runs at every RK4 stage with d->time at that stage. */
static inline void apply_loads(const mjModel *m, mjData *d)
{
  prru_loads l;
  (void)m;
  prru_schedule_eval(g_schedule, d->time, &l);
  mju_zero(d->qfrc_applied, NV);
  for (int i = 0; i < 3; i++) d->qfrc_applied[g_slide_dof[i]] = l.fd[i];
  mju_zero(d->xfrc_applied + 6 * g_platform, 6);
  mju_copy3(d->xfrc_applied + 6 * g_platform, l.fp);
  mju_copy3(d->xfrc_applied + 6 * g_platform + 3, l.mp);
}

/* q of a platform copy: R_P = Rx(q1) Ry(q2), p_P = (0, 0, q3). */
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
