/* The runtime-parameter kernels (prru_param_kernels.h) of whatever model
 * the build uses:
 *  - at prru_params_model they agree with the constant-folded kernels of
 *    the same name to 450 eps at 2000 random regular states around q = 0 and
 *    at 2000 anywhere in the reachable set at least 0.1 from a singular
 *    boundary (each output array norm-wise: max |param - const| /
 *    max |const|);
 *  - the parameters really flow: for random designs that perturb every
 *    member of prru_params (geometry, gravity vector, masses, centres of
 *    mass, full inertia tensors, drives), each kernel agrees with the
 *    hand-derived GSL reference given the same numbers (1e-12, as
 *    test_kernels), and the members the contract says are ignored (a[2],
 *    a[3]) are;
 *  - M, h and G are linear in the inertial parameters and G in gravity
 *    (all masses, inertias and armatures doubled: M, h, G doubled);
 *  - NaN on every output where q is unreachable or not finite. */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_param_kernels.h"
#include "testparam.h"
#include "prru_ref.h"
#include "testref.h"
#include "testsim.h"
#include "testutil.h"

#define NSTATE 2000
#define NA PRRU_NACT
#define NB PRRU_NBODY
#define NDESIGN 40
#define NDSTATE 50 /* states per design */
/* The param and constant kernels evaluate the same expressions, with the
 * model's numbers folded in at generation or read at run time: the same
 * operations in other orders, so each output differs by the rounding of
 * its terms, a few hundred eps of their size for sums of products ~100
 * operations deep (the dynamics'); each output is compared relative to
 * the size of its terms (note_all's floor). */
#define TOL_SAME (450 * DBL_EPSILON)
#define MARGIN 0.1  /* testref.h's ref_margin: states nearer a singular boundary are not compared */

/* Every param kernel's outputs (or every constant kernel's) at one state. */
typedef struct {
  double d[NA], Jd[3 * NA], d2[NA], Jd2[3 * NA], M[9], h[3], G[3], M2[9], h2[3], G2[3];
  double Me[9], be[3], JP[18], E[2], dd[NA], ddb[NA], Qp[3];
} outputs;

enum {
  O_IK, O_JD, O_IKJD_D, O_IKJD_J, O_MASS, O_BIAS, O_GRAV, O_DYN_M, O_DYN_H, O_DYN_G, O_EOM_M,
  O_EOM_B, O_PJ, O_EN, O_AR_DD, O_AR_DDB, O_PASSIVE, O_COUNT
};
static const char *names[O_COUNT] = {
  "ik", "jd", "ik_jd d", "ik_jd Jd", "mass", "bias", "gravity", "dynamics M", "dynamics h",
  "dynamics G", "eom M", "eom b", "platform_jacobian", "energy", "actuator_rates dd",
  "actuator_rates ddb", "passive"};

typedef struct {
  double q[3], qd[3], fd[NA], fp[3], mp[3];
} state;

static void eval_param(const prru_params *p, const state *s, outputs *o)
{
  prru_param_ik(tp_derived(p), s->q, o->d);
  prru_param_jd(tp_derived(p), s->q, o->Jd);
  prru_param_ik_jd(tp_derived(p), s->q, o->d2, o->Jd2);
  prru_param_mass(tp_derived(p), s->q, o->M);
  prru_param_bias(tp_derived(p), s->q, s->qd, o->h);
  prru_param_gravity(tp_derived(p), s->q, o->G);
  prru_param_dynamics(tp_derived(p), s->q, s->qd, o->M2, o->h2, o->G2);
  prru_param_eom(tp_derived(p), s->q, s->qd, s->fd, s->fp, s->mp, o->Me, o->be);
  prru_param_platform_jacobian(tp_derived(p), s->q, o->JP);
  prru_param_energy(tp_derived(p), s->q, s->qd, o->E);
  prru_param_actuator_rates(tp_derived(p), s->q, s->qd, o->dd, o->ddb);
  prru_param_passive(tp_derived(p), s->q, s->qd, o->Qp);
}

static void eval_const(const state *s, outputs *o)
{
  prru_ik(s->q, o->d);
  prru_jd(s->q, o->Jd);
  prru_ik_jd(s->q, o->d2, o->Jd2);
  prru_mass(s->q, o->M);
  prru_bias(s->q, s->qd, o->h);
  prru_gravity(s->q, o->G);
  prru_dynamics(s->q, s->qd, o->M2, o->h2, o->G2);
  prru_eom(s->q, s->qd, s->fd, s->fp, s->mp, o->Me, o->be);
  prru_platform_jacobian(s->q, o->JP);
  prru_energy(s->q, s->qd, o->E);
  prru_actuator_rates(s->q, s->qd, o->dd, o->ddb);
  prru_passive(s->q, s->qd, o->Qp);
}

/* Pointer and length of output o in an outputs struct. */
static const double *out_array(const outputs *x, int o, int *n)
{
  const struct { const double *p; int n; } t[O_COUNT] = {
    {x->d, NA}, {x->Jd, 3 * NA}, {x->d2, NA}, {x->Jd2, 3 * NA}, {x->M, 9}, {x->h, 3}, {x->G, 3},
    {x->M2, 9}, {x->h2, 3}, {x->G2, 3}, {x->Me, 9}, {x->be, 3}, {x->JP, 18}, {x->E, 2},
    {x->dd, NA}, {x->ddb, NA}, {x->Qp, 3}};
  *n = t[o].n;
  return t[o].p;
}

/* Worst norm-wise relative error of every output of got against want.
 * floor[o] is the scale below which an output counts as 0 (1e-300 for all
 * but the potential energy and eom's b, sums of terms that cancel: their
 * scale is the size of those terms). NaN is kept as the worst. */
static void note_all(const outputs *got, const outputs *want, const double floor[O_COUNT],
                     double worst[O_COUNT])
{
  for (int o = 0; o < O_COUNT; o++) {
    int n;
    const double *a = out_array(got, o, &n), *b = out_array(want, o, &n);
    const double e = tu_relerr(a, b, n, floor[o]);
    if (!(e <= worst[o])) worst[o] = e;
  }
}

static void random_loads(state *s)
{
  for (int i = 0; i < NA; i++) s->fd[i] = tu_uniform(-60, 60);
  for (int i = 0; i < 3; i++) {
    s->fp[i] = tu_uniform(-30, 30);
    s->mp[i] = tu_uniform(-3, 3);
  }
}

/* sum_b |m_b g_k p_b,k|: the size of the terms of V. */
static double potential_terms(const double *mass, const double *g, const double *p)
{
  double s = 0;
  for (int b = 0; b < NB; b++)
    for (int k = 0; k < 3; k++) s += fabs(mass[b] * g[k] * p[3 * b + k]);
  return s;
}

/* max_i of the sum of the magnitudes of the terms of b_i = G_i + (J_d^T
 * fd)_i + (J_T,O'^T fp)_i + (J_R,P^T mp)_i + passive_i - h_i, from the
 * constant kernels' outputs w. b is what remains of forces that cancel (a
 * load that holds the platform up against gravity leaves b ~ 0): both
 * kernels round every term to ~eps of its own size, so b agrees to that
 * size, not to |b|'s. */
static double eom_b_terms(const outputs *w, const state *s)
{
  double scale = 0;
  for (int i = 0; i < 3; i++) {
    double t = fabs(w->G[i]) + fabs(w->h[i]) + fabs(w->Qp[i]);
    for (int j = 0; j < NA; j++) t += fabs(w->Jd[3 * j + i] * s->fd[j]);
    for (int k = 0; k < 3; k++)
      t += fabs(w->JP[3 * k + i] * s->mp[k]) + fabs(w->JP[3 * (3 + k) + i] * s->fp[k]);
    scale = fmax(scale, t);
  }
  return scale;
}

/* The size of the terms of h = H^T K (+ J_d^T K_arm Jd' qd) and of the
 * drives' passive forces J_d^T (-c dd - f tanh(dd / v_s)): each output is
 * a sum that can cancel (bodies' Coriolis forces against each other, one
 * limb's friction against another's), so it is compared relative to the
 * size of what it sums, not to its own (which can be any small part of
 * it: a random 4-limb model's h and passive differed by 1.2e-13 and
 * 4.2e-13 of their own size). */
static void sum_floors(const state *s, const outputs *w, double floor[O_COUNT])
{
  static double H[6 * NB * 3], K[6 * NB];
  prru_jacobians(s->q, H);
  prru_wrench_bias(s->q, s->qd, K);
  double fh = 0, fp = 0;
  for (int j = 0; j < 3; j++) {
    double th = 0, tp = 0;
    for (int i = 0; i < 6 * NB; i++) th += fabs(H[3 * i + j] * K[i]);
    for (int a = 0; a < NA; a++) {
      const double J = fabs(w->Jd[3 * a + j]);
      th += J * fabs(prru_mech.armature[a] * w->ddb[a]);
      tp += J * (fabs(prru_mech.damping[a] * w->dd[a]) + fabs(prru_mech.coulomb[a]));
    }
    fh = fmax(fh, th);
    fp = fmax(fp, tp);
  }
  /* 1e-300 as elsewhere: a model without drives has passive = 0 exactly. */
  floor[O_BIAS] = floor[O_DYN_H] = fmax(fh, 1e-300);
  floor[O_PASSIVE] = fmax(fp, 1e-300);
}

/* prru_params_model against the constant kernels, and that it holds the
 * descriptor's numbers. */
static void test_model_params(void)
{
  const prru_params *p = &prru_params_model;
  int same = 1;
  for (int i = 0; i < PRRU_NLIMB; i++)
    same &= p->b[i] == prru_mech.b[i] && p->l1[i] == prru_mech.l1[i] &&
            p->l2[i] == prru_mech.l2[i] && (i >= 2 || p->a[i] == prru_mech.a[i]);
  for (int b = 0; b < NB; b++) {
    same &= p->mass[b] == prru_mech.mass[b];
    for (int k = 0; k < 3; k++) same &= p->com[b][k] == prru_mech.com[b][k];
    const double *I = prru_mech.inertia[b];
    const double six[6] = {I[0], I[4], I[8], I[1], I[2], I[5]};
    for (int k = 0; k < 6; k++) same &= p->inertia[b][k] == six[k];
  }
  for (int i = 0; i < NA; i++)
    same &= p->armature[i] == prru_mech.armature[i] && p->damping[i] == prru_mech.damping[i] &&
            p->coulomb[i] == prru_mech.coulomb[i];
  for (int k = 0; k < 3; k++) same &= p->gravity[k] == prru_mech.gravity[k];
  same &= p->coulomb_velocity > 0;
  TU_TRUE(same, "prru_params_model holds the descriptor's numbers (coulomb_velocity > 0)");

  prru_model model;
  prru_data data;
  prru_model_default(&model);
  double worst[O_COUNT] = {0};
  int id_fails = 0;
  for (int n = 0; n < NSTATE; n++) {
    state s;
    ts_random_state(&model, &data, s.q, s.qd);
    /* Every third state slowly, where tanh(dd / v_s) is not saturated. */
    if (n % 3 == 0)
      for (int i = 0; i < 3; i++) s.qd[i] *= 1e-3;
    random_loads(&s);
    /* Every fifth state the drives hold the motion: fd from the inverse
     * dynamics for qdd = 0, so eom's b is 0 up to the rounding of its
     * terms (all cancellation). */
    if (n % 5 == 4) {
      prru_loads l;
      const double zero[3] = {0, 0, 0};
      memset(&l, 0, sizeof l);
      memcpy(l.fp, s.fp, sizeof l.fp);
      memcpy(l.mp, s.mp, sizeof l.mp);
      id_fails += prru_inverse_dynamics(&model, &data, s.q, s.qd, zero, &l, s.fd) != PRRU_OK;
    }
    static outputs got, want;
    eval_param(p, &s, &got);
    eval_const(&s, &want);
    double R[9 * NB], pos[3 * NB], floor[O_COUNT];
    prru_poses(s.q, R, pos);
    for (int o = 0; o < O_COUNT; o++) floor[o] = 1e-300;
    floor[O_EN] = potential_terms(prru_mech.mass, prru_mech.gravity, pos);
    floor[O_EOM_B] = eom_b_terms(&want, &s);
    sum_floors(&s, &want, floor);
    note_all(&got, &want, floor, worst);
  }
  TU_TRUE(id_fails == 0, "inverse dynamics for qdd = 0 (the states where eom's b cancels)");
  printf("param kernels at prru_params_model vs constant kernels, model %s, %d regular states:\n",
         prru_mech.name, NSTATE);
  for (int o = 0; o < O_COUNT; o++) {
    char what[96];
    snprintf(what, sizeof what, "param %s = constant %s at prru_params_model", names[o], names[o]);
    tu_check(worst[o] <= TOL_SAME, what, worst[o], TOL_SAME);
    printf("  %-18s %.1e\n", names[o], worst[o]);
  }
}

/* The same over the whole reachable set: q1, q2 anywhere in a half turn,
 * any height within twice the longest limb, at least MARGIN from a
 * singular boundary (nearer, both sides are only defined to ~eps / margin^2
 * and neither is the better answer), each state's difference times
 * margin^2 against TOL_SAME. */
static void test_model_params_wide(void)
{
  prru_ref_params r;
  prru_ref_params_default(&r);
  double L = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) L = fmax(L, r.l1[i] + r.l2[i]);
  double worst[O_COUNT] = {0};
  for (int n = 0; n < NSTATE; n++) {
    state s;
    double margin;
    do {
      s.q[0] = tu_uniform(-1.57, 1.57);
      s.q[1] = tu_uniform(-1.57, 1.57);
      s.q[2] = tu_uniform(-2 * L, 2 * L);
    } while (!((margin = ref_margin(&r, s.q)) >= MARGIN));
    for (int i = 0; i < 3; i++) s.qd[i] = tu_uniform(-1.15, 1.15) * (n % 3 ? 1 : 1e-3);
    random_loads(&s);
    static outputs got, want;
    eval_param(&prru_params_model, &s, &got);
    eval_const(&s, &want);
    double R[9 * NB], pos[3 * NB], floor[O_COUNT];
    prru_poses(s.q, R, pos);
    for (int o = 0; o < O_COUNT; o++) floor[o] = 1e-300;
    floor[O_EN] = potential_terms(prru_mech.mass, prru_mech.gravity, pos);
    floor[O_EOM_B] = eom_b_terms(&want, &s);
    sum_floors(&s, &want, floor);
    /* Near a boundary an upper link's sin alpha rounds to u / sin^2
     * alpha of itself and every output built on it with it (J_d ~ 1 / sin,
     * its rate ~ 1 / sin^3): each state's difference in units of
     * 1 / margin^2 (a random 4-limb model's h and passive differed by
     * 1.2e-13 of their terms at margin 0.1, 0.012 u / margin^2). */
    double here[O_COUNT] = {0};
    note_all(&got, &want, floor, here);
    for (int o = 0; o < O_COUNT; o++) worst[o] = fmax(worst[o], here[o] * margin * margin);
  }
  printf("the same at %d reachable states anywhere (margin >= %.2g):\n", NSTATE, MARGIN);
  for (int o = 0; o < O_COUNT; o++) {
    char what[128];
    snprintf(what, sizeof what, "param %s = constant %s at prru_params_model, whole workspace (x margin^2)",
             names[o], names[o]);
    tu_check(worst[o] <= TOL_SAME, what, worst[o], TOL_SAME);
    printf("  %-18s %.1e\n", names[o], worst[o]);
  }
}

/* A design near the model's: every length within 3 %, U-joint offsets of
 * limbs 1, 2 within 3 %, a gravity vector tilted up to ~0.3 rad, masses
 * and principal moments within 30 %, centres of mass up to 1 cm off,
 * inertia tensors turned by a random rotation (products of inertia),
 * drives from none to a prototype's. The ignored a[2], a[3] get garbage. */
static void random_design(prru_params *p)
{
  *p = prru_params_model;
  for (int i = 0; i < PRRU_NLIMB; i++) {
    p->b[i] *= 1 + tu_uniform(-0.03, 0.03);
    p->l1[i] *= 1 + tu_uniform(-0.03, 0.03);
    p->l2[i] *= 1 + tu_uniform(-0.03, 0.03);
    p->a[i] = i < 2 ? p->a[i] * (1 + tu_uniform(-0.03, 0.03)) : 1e3;
  }
  const double g = 9.81;
  p->gravity[0] = g * tu_uniform(-0.3, 0.3);
  p->gravity[1] = g * tu_uniform(-0.3, 0.3);
  p->gravity[2] = -g * tu_uniform(0.9, 1.1);
  for (int b = 0; b < NB; b++) {
    p->mass[b] *= 1 + tu_uniform(-0.3, 0.3);
    for (int k = 0; k < 3; k++) p->com[b][k] = tu_uniform(-0.01, 0.01);
    /* R diag(I) R^T with R a rotation by a random angle about a random
     * axis: a physically possible tensor with products of inertia. */
    double I[3];
    for (int k = 0; k < 3; k++) I[k] = prru_mech.inertia[b][4 * k] * (1 + tu_uniform(-0.3, 0.3));
    for (int k = 0; k < 3; k++) /* keep the triangle inequality */
      if (I[(k + 1) % 3] + I[(k + 2) % 3] < I[k]) I[k] = 0.99 * (I[(k + 1) % 3] + I[(k + 2) % 3]);
    double u[3] = {tu_uniform(-1, 1), tu_uniform(-1, 1), tu_uniform(-1, 1)};
    const double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int k = 0; k < 3; k++) u[k] /= un;
    const double th = tu_uniform(-1, 1), c = cos(th), s = sin(th);
    double R[3][3];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) R[i][j] = (i == j ? c : 0) + (1 - c) * u[i] * u[j];
    R[0][1] -= s * u[2], R[0][2] += s * u[1], R[1][0] += s * u[2];
    R[1][2] -= s * u[0], R[2][0] -= s * u[1], R[2][1] += s * u[0];
    double T[3][3];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        T[i][j] = 0;
        for (int k = 0; k < 3; k++) T[i][j] += R[i][k] * I[k] * R[j][k];
      }
    const double six[6] = {T[0][0], T[1][1], T[2][2], T[0][1], T[0][2], T[1][2]};
    memcpy(p->inertia[b], six, sizeof six);
  }
  for (int i = 0; i < NA; i++) {
    p->armature[i] = tu_uniform(0, 0.3);
    p->damping[i] = tu_uniform(0, 25);
    p->coulomb[i] = tu_uniform(0, 4);
  }
  p->coulomb_velocity = tu_uniform(0.002, 0.02);
}

/* The same design as the reference's parameters (the param kernels are
 * the build's topology). */
static void to_ref(const prru_params *p, prru_ref_params *r)
{
  memset(r, 0, sizeof *r);
  r->nlimb = PRRU_NLIMB;
  for (int k = 0; k < 3; k++) r->g[k] = p->gravity[k];
  for (int i = 0; i < PRRU_NLIMB; i++) {
    r->b[i] = p->b[i];
    r->l1[i] = p->l1[i];
    r->l2[i] = p->l2[i];
    r->a[i] = i < 2 ? p->a[i] : 0.0;
  }
  for (int b = 0; b < NB; b++) {
    r->mass[b] = p->mass[b];
    for (int k = 0; k < 3; k++) r->com[b][k] = p->com[b][k];
    const double *t = p->inertia[b];
    const double full[9] = {t[0], t[3], t[4], t[3], t[1], t[5], t[4], t[5], t[2]};
    memcpy(r->inertia[b], full, sizeof full);
  }
  for (int i = 0; i < NA; i++) {
    r->armature[i] = p->armature[i];
    r->damping[i] = p->damping[i];
    r->coulomb[i] = p->coulomb[i];
  }
  r->coulomb_velocity = p->coulomb_velocity;
}

/* A reachable state of design r at least MARGIN from a singular
 * boundary: q1, q2 within +-0.5 rad, q3 anywhere within the longest limb. */
static void design_state(const prru_ref_params *r, state *s)
{
  double L = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) L = fmax(L, r->l1[i] + r->l2[i]);
  do {
    s->q[0] = tu_uniform(-0.5, 0.5);
    s->q[1] = tu_uniform(-0.5, 0.5);
    s->q[2] = tu_uniform(-L, L);
  } while (!(ref_margin(r, s->q) >= MARGIN));
  for (int i = 0; i < 3; i++) s->qd[i] = tu_uniform(-1.15, 1.15);
  random_loads(s);
}

/* The reference's outputs of every param kernel at state s. */
static int eval_ref(const prru_ref_params *r, prru_ref_ws *w, const state *s, outputs *o,
                    double pos[3 * NB])
{
  double R[9 * NB], qdd[3];
  int st = prru_ref_ik(r, s->q, o->d) | prru_ref_jd(r, s->q, o->Jd) |
           prru_ref_poses(r, s->q, R, pos) | prru_ref_energy(r, w, s->q, s->qd, o->E) |
           prru_ref_actuator_rates(r, s->q, s->qd, o->dd, o->ddb) |
           prru_ref_passive(r, w, s->q, s->qd, o->Qp) |
           prru_ref_forward_dynamics(r, w, s->q, s->qd, s->fd, s->fp, s->mp, qdd) |
           prru_ref_dynamics(r, w, s->q, s->qd, o->M, o->h, o->G);
  memcpy(o->d2, o->d, sizeof o->d);
  memcpy(o->Jd2, o->Jd, sizeof o->Jd);
  memcpy(o->M2, o->M, sizeof o->M);
  memcpy(o->Me, o->M, sizeof o->M);
  memcpy(o->h2, o->h, sizeof o->h);
  memcpy(o->G2, o->G, sizeof o->G);
  /* J_R,P from H (world frame), and J_T of the tool point O' = (0, 0, q3). */
  memcpy(o->JP, gsl_matrix_const_ptr(w->H, 0, 0), 9 * sizeof(double));
  memset(o->JP + 9, 0, 9 * sizeof(double));
  o->JP[17] = 1.0;
  /* b = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp + Qp - h. */
  for (int j = 0; j < 3; j++) {
    o->be[j] = o->G[j] - o->h[j] + o->Qp[j];
    for (int i = 0; i < NA; i++) o->be[j] += o->Jd[3 * i + j] * s->fd[i];
    for (int i = 0; i < 3; i++) o->be[j] += o->JP[9 + 3 * i + j] * s->fp[i] + o->JP[3 * i + j] * s->mp[i];
  }
  return st;
}

static void test_designs(void)
{
  prru_ref_ws *w = prru_ref_alloc();
  if (!w) {
    TU_TRUE(0, "prru_ref_alloc");
    return;
  }
  double worst[O_COUNT] = {0}, moved = HUGE_VAL;
  int ref_fail = 0;
  for (int k = 0; k < NDESIGN; k++) {
    prru_params p;
    prru_ref_params r;
    random_design(&p);
    to_ref(&p, &r);
    for (int n = 0; n < NDSTATE; n++) {
      state s;
      design_state(&r, &s);
      if (n % 3 == 0)
        for (int i = 0; i < 3; i++) s.qd[i] *= 1e-3;
      static outputs got, want, model_out;
      double pos[3 * NB], floor[O_COUNT];
      if (eval_ref(&r, w, &s, &want, pos) != GSL_SUCCESS) {
        ref_fail++;
        continue;
      }
      eval_param(&p, &s, &got);
      for (int o = 0; o < O_COUNT; o++) floor[o] = 1e-300;
      floor[O_EN] = potential_terms(r.mass, r.g, pos);
      note_all(&got, &want, floor, worst);
      /* The design's M is not the model's: the test can tell them apart. */
      prru_param_dynamics(tp_derived(&prru_params_model), s.q, s.qd, model_out.M, model_out.h, model_out.G);
      const double e = tu_relerr(model_out.M, want.M, 9, 1e-300);
      if (!(e >= moved)) moved = e;
    }
  }
  prru_ref_free(w);
  tu_check(ref_fail == 0, "reference evaluates at every design state", ref_fail, 0);
  printf("param kernels vs reference at %d random designs x %d states (margin >= %.2g):\n", NDESIGN,
         NDSTATE, MARGIN);
  for (int o = 0; o < O_COUNT; o++) {
    char what[96];
    snprintf(what, sizeof what, "param %s = reference at a random design", names[o]);
    tu_check(worst[o] <= 1e-12, what, worst[o], 1e-12);
    printf("  %-18s %.1e\n", names[o], worst[o]);
  }
  /* ... by far more than the tolerance above (the prototype's armature
   * dominates its M, so its designs move M least, ~3e-4). */
  tu_check(moved >= 1e-6, "the designs' M differ from the model's (smallest relative change)", moved, 1e-6);
  printf("  smallest |M(design) - M(model)| / |M(design)|: %.1e\n", moved);
}

/* Doubling every mass, inertia and armature doubles M, h and G; doubling
 * gravity doubles G only. Exact up to rounding (the kernels are linear in
 * these parameters, multiplication by 2 is exact, sums reassociate not). */
static void test_linearity(void)
{
  prru_model model;
  prru_data data;
  prru_model_default(&model);
  prru_params p2 = prru_params_model, pg = prru_params_model;
  for (int b = 0; b < NB; b++) {
    p2.mass[b] *= 2;
    for (int k = 0; k < 6; k++) p2.inertia[b][k] *= 2;
  }
  for (int i = 0; i < NA; i++) p2.armature[i] *= 2;
  for (int k = 0; k < 3; k++) pg.gravity[k] *= 2;
  double worst = 0, worst_g = 0;
  for (int n = 0; n < 200; n++) {
    double q[3], qd[3], M[9], h[3], G[3], M2[9], h2[3], G2[3], Mg[9], hg[3], Gg[3];
    ts_random_state(&model, &data, q, qd);
    prru_param_dynamics(tp_derived(&prru_params_model), q, qd, M, h, G);
    prru_param_dynamics(tp_derived(&p2), q, qd, M2, h2, G2);
    prru_param_dynamics(tp_derived(&pg), q, qd, Mg, hg, Gg);
    for (int i = 0; i < 9; i++) M[i] *= 2;
    for (int i = 0; i < 3; i++) h[i] *= 2, G[i] *= 2;
    const double e[4] = {tu_relerr(M2, M, 9, 1e-300), tu_relerr(h2, h, 3, 1e-300),
                         tu_relerr(G2, G, 3, 1e-300), 0};
    for (int i = 0; i < 3; i++)
      if (!(e[i] <= worst)) worst = e[i];
    /* Gravity doubled: G doubled (G above is already x2), M and h as before. */
    for (int i = 0; i < 9; i++) M[i] *= 0.5;
    for (int i = 0; i < 3; i++) h[i] *= 0.5;
    const double eg[3] = {tu_relerr(Gg, G, 3, 1e-300), tu_relerr(Mg, M, 9, 1e-300),
                          tu_relerr(hg, h, 3, 1e-300)};
    for (int i = 0; i < 3; i++)
      if (!(eg[i] <= worst_g)) worst_g = eg[i];
  }
  tu_check(worst <= 1e-14, "masses, inertias, armatures x2: M, h, G x2", worst, 1e-14);
  tu_check(worst_g <= 1e-14, "gravity x2: G x2, M and h unchanged", worst_g, 1e-14);
  printf("linearity in the inertial parameters %.1e, in gravity %.1e\n", worst, worst_g);
}

static int all_nan(const double *x, int n)
{
  for (int i = 0; i < n; i++)
    if (!isnan(x[i])) return 0;
  return 1;
}

/* Non-finite q, and q = (0, 0, -0.8) for a design whose rails are 10
 * machine sizes away (no limb reaches them): every output NaN. */
static void test_nan(void)
{
  double L = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) L = fmax(L, prru_mech.l1[i] + prru_mech.l2[i]);
  const double inf = HUGE_VAL;
  const double bad[][3] = {{NAN, 0, -0.8}, {0, inf, -0.8}, {0, 0, -inf}, {0, 0, NAN}, {0, 0, -0.8}};
  const int nbad = (int)(sizeof bad / sizeof bad[0]);
  prru_params far = prru_params_model;
  for (int i = 0; i < PRRU_NLIMB; i++) far.b[i] += 10 * L;
  for (int c = 0; c < nbad; c++) {
    state s;
    memcpy(s.q, bad[c], sizeof s.q);
    for (int i = 0; i < 3; i++) s.qd[i] = 0.1 * (i + 1);
    random_loads(&s);
    static outputs o;
    eval_param(c == nbad - 1 ? &far : &prru_params_model, &s, &o);
    for (int k = 0; k < O_COUNT; k++) {
      int n;
      const double *x = out_array(&o, k, &n);
      char what[128];
      snprintf(what, sizeof what, "q (%g, %g, %g)%s: param %s all NaN", s.q[0], s.q[1], s.q[2],
               c == nbad - 1 ? " of a design with far rails" : "", names[k]);
      TU_TRUE(all_nan(x, n), what);
    }
  }
  printf("NaN outputs checked at %d unreachable or non-finite q\n", nbad);
}

int main(void)
{
  gsl_set_error_handler_off();
  test_model_params();
  test_model_params_wide();
  test_designs();
  test_linearity();
  test_nan();
  return tu_finish("test_param_kernels");
}
