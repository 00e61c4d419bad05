/* The topology kernels (prru_p3_kernels.h, prru_p4_kernels.h), both of
 * which every build carries whatever its model:
 *  - the build's own topology: every kernel at prru_params_model (mapped
 *    into prru_params3/4) agrees with the constant kernel of the same name
 *    at 1000 regular states, within a bound derived per output beside
 *    `bound` below from the rounding unit and the size of the terms;
 *  - both topologies: the batched kernels agree with the scalar ones state
 *    by state (tests/test_batch.c's rule), the own at the model's numbers,
 *    the other at its reference model's (prru_p<n>_params_reference);
 *  - across topologies: the four-limb kernels with a massless fourth limb
 *    (no mass, inertia or drive) are the three-limb kernels of limbs 1-3:
 *    d, J_d, M, h, G, b, qdd, energy, J_P, passive forces, poses, the
 *    generalized force of inverse_terms and the reactions of limbs 1 and 2
 *    (limb 4, along e2 through O' like limb 3, only shares limb 3's
 *    constraint force).
 * The GSL reference (reference/) is compiled for the build's topology
 * only, so the other topology's set meets it in the build of that topology
 * (`make test MODEL=models/4prru.json` for prru_p4_*), where it is the own
 * set and equals the constant kernels, which test_kernels checks against the
 * reference. */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_p3_kernels.h"
#include "prru_p4_kernels.h"
#include "prru_param_kernels.h"
#include "testsim.h"
#include "testutil.h"

#define NSTATE 1000
#define NMAX 203
/* The topology and constant kernels evaluate the same expressions, with
 * the model's numbers folded in at generation or read at run time (and
 * simplifications the model's zeros allow taken or not): the same
 * operations in other orders, so each output differs by the rounding of
 * its terms, a few hundred eps of their size for the dynamics' sums of
 * products ~100 operations deep (test_param_kernels.c's rule). */
#define TOL_SAME (450 * DBL_EPSILON)
#define TOL_BATCH 1e-14
#define PERTURB_EPS 8.0
#define SENS_FACTOR 2.0
#define MARGIN 0.1

typedef struct {
  double q[NMAX][3], qd[NMAX][3], fd[NMAX][4], fp[NMAX][3], mp[NMAX][3];
  int compared[NMAX];
} tt_states;

static double soa_buf[5][4 * NMAX + 1];

/* Rows of n (x[i n + k] = component i of state k) from per-state rows of
 * `stride` doubles, at an offset (no alignment). */
static double *tt_soa(int slot, const double *aos, int stride, int dim, int n)
{
  double *x = soa_buf[slot] + 1;
  for (int k = 0; k < n; k++)
    for (int i = 0; i < dim; i++) x[i * n + k] = aos[k * stride + i];
  return x;
}

static double tt_maxdiff(const double *a, const double *b, int n)
{
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* Batch output (SoA) against the scalar one (AoS), test_batch.c's rule:
 * bit for bit when sens is NULL, else state k within TOL_BATCH of the
 * largest entry plus SENS_FACTOR sens[k]; NaN exactly where the scalar
 * kernel's. Returns the worst difference relative to the largest entry. */
static double tt_compare(const char *kernel, const char *name, const double *batch,
                         const double *scalar, const double *sens, int dim, int n,
                         const int *compared, int *nan_ok)
{
  double worst = 0;
  int within = 1;
  for (int k = 0; k < n; k++) {
    const double *ref = scalar + k * dim;
    int any_nan = 0;
    for (int i = 0; i < dim; i++) {
      if (isnan(ref[i]) != isnan(batch[i * n + k])) *nan_ok = 0;
      any_nan |= isnan(ref[i]);
    }
    if (any_nan || !compared[k]) continue;
    double err = 0, scale = 1e-300;
    for (int i = 0; i < dim; i++) {
      const double e = fabs(batch[i * n + k] - ref[i]);
      if (!(e <= err)) err = e;
      scale = fmax(scale, fabs(ref[i]));
    }
    const double bound = sens ? TOL_BATCH * scale + SENS_FACTOR * sens[k] : 0.0;
    if (!(err <= bound)) within = 0;
    if (!(err / scale <= worst)) worst = err / scale;
  }
  char what[200];
  snprintf(what, sizeof what, "%s: %s %s the scalar kernel's (n = %d)", kernel, name,
           sens ? "within the rounding of" : "bit for bit", n);
  tu_check(within, what, worst, sens ? TOL_BATCH : 0.0);
  return worst;
}

#define TT_N 3
#include "testtopo.h"
#undef TT_N
#define TT_N 4
#include "testtopo.h"
#undef TT_N

/* ---- the build's own topology against the constant kernels ---------- */
#define NA PRRU_NACT
#define NB PRRU_NBODY
#define NL PRRU_NLAMBDA
#if NA == 3
typedef prru_params3 own_params;
typedef prru_p3_derived own_derived;
#define OWN(name) prru_p3_##name
#define OWN_NNZ PRRU_P3_REACTION_BASIS_NNZ
#else
typedef prru_params4 own_params;
typedef prru_p4_derived own_derived;
#define OWN(name) prru_p4_##name
#define OWN_NNZ PRRU_P4_REACTION_BASIS_NNZ
#endif

/* prru_params_model (the public prru_params, arrays of the maxima) in the
 * topology's struct: the first PRRU_NLIMB, PRRU_NBODY and PRRU_NACT
 * entries of each member. */
static void own_from_model(own_params *o)
{
  const prru_params *p = &prru_params_model;
  for (int i = 0; i < PRRU_NLIMB; i++) o->b[i] = p->b[i], o->l1[i] = p->l1[i], o->l2[i] = p->l2[i], o->a[i] = p->a[i];
  memcpy(o->gravity, p->gravity, sizeof o->gravity);
  for (int k = 0; k < NB; k++) {
    o->mass[k] = p->mass[k];
    memcpy(o->com[k], p->com[k], sizeof o->com[k]);
    memcpy(o->inertia[k], p->inertia[k], sizeof o->inertia[k]);
  }
  for (int i = 0; i < NA; i++) o->armature[i] = p->armature[i], o->damping[i] = p->damping[i], o->coulomb[i] = p->coulomb[i];
  o->coulomb_velocity = p->coulomb_velocity;
}

/* Every output of every kernel at one state. inverse_terms: X = J_d^-1 and
 * y = fd (three limbs), y = tau (four). */
typedef struct {
  double d[NA], Jd[3 * NA], d2[NA], Jd2[3 * NA], H[18 * NB], dm[6 * NB], M[9], h[3], G[3];
  double M2[9], h2[3], G2[3], Me[9], be[3], JP[18], R[9 * NB], pos[3 * NB], I[9 * NB];
  double K[6 * NB], E[2], dd[NA], ddb[NA], Qp[3], Q[6 * NB * NL], Ms[9], bs[3], qdd[3];
  double minors[3], di[NA], Jdi[3 * NA], X[9], y[NA], lam[NL], z[NL], zn[NL];
} outs;

typedef struct {
  double q[3], qd[3], fd[NA], fp[3], mp[3], qdd[3];
} state;

static void scatter(const double *nz, const int *index, int nnz, double *Q)
{
  memset(Q, 0, sizeof(double) * 6 * NB * NL);
  for (int k = 0; k < nnz; k++) Q[index[k]] = nz[k];
}

static void eval_own(const own_derived *p, const state *s, outs *o)
{
  static double nz[6 * NB * NL];
  OWN(ik)(p, s->q, o->d);
  OWN(jd)(p, s->q, o->Jd);
  OWN(ik_jd)(p, s->q, o->d2, o->Jd2);
  OWN(jacobians)(p, s->q, o->H);
  OWN(bias_terms)(p, s->q, s->qd, o->dm);
  OWN(mass)(p, s->q, o->M);
  OWN(bias)(p, s->q, s->qd, o->h);
  OWN(gravity)(p, s->q, o->G);
  OWN(dynamics)(p, s->q, s->qd, o->M2, o->h2, o->G2);
  OWN(eom)(p, s->q, s->qd, s->fd, s->fp, s->mp, o->Me, o->be);
  OWN(platform_jacobian)(p, s->q, o->JP);
  OWN(poses)(p, s->q, o->R, o->pos);
  OWN(inertia_world)(p, s->q, o->I);
  OWN(wrench_bias)(p, s->q, s->qd, o->K);
  OWN(energy)(p, s->q, s->qd, o->E);
  OWN(actuator_rates)(p, s->q, s->qd, o->dd, o->ddb);
  OWN(passive)(p, s->q, s->qd, o->Qp);
  OWN(reaction_basis)(p, s->q, nz);
  scatter(nz, OWN(reaction_basis_index), OWN_NNZ, o->Q);
  OWN(eom_solve)(p, s->q, s->qd, s->fd, s->fp, s->mp, o->Ms, o->bs, o->qdd, o->minors);
#if NA == 3
  OWN(inverse_terms)(p, s->q, s->qd, s->qdd, s->fp, s->mp, o->di, o->Jdi, o->X, o->y);
  OWN(joint_reactions)(p, s->q, s->qd, s->qdd, s->fd, s->fp, s->mp, o->lam);
#else
  OWN(inverse_terms)(p, s->q, s->qd, s->qdd, s->fp, s->mp, o->di, o->Jdi, o->y);
  OWN(joint_reactions)(p, s->q, s->qd, s->qdd, s->fd, s->fp, s->mp, o->lam, o->z);
  OWN(reaction_nullspace)(p, s->q, o->zn);
#endif
}

static void eval_const(const state *s, outs *o)
{
  static double nz[6 * NB * NL];
  prru_ik(s->q, o->d);
  prru_jd(s->q, o->Jd);
  prru_ik_jd(s->q, o->d2, o->Jd2);
  prru_jacobians(s->q, o->H);
  prru_bias_terms(s->q, s->qd, o->dm);
  prru_mass(s->q, o->M);
  prru_bias(s->q, s->qd, o->h);
  prru_gravity(s->q, o->G);
  prru_dynamics(s->q, s->qd, o->M2, o->h2, o->G2);
  prru_eom(s->q, s->qd, s->fd, s->fp, s->mp, o->Me, o->be);
  prru_platform_jacobian(s->q, o->JP);
  prru_poses(s->q, o->R, o->pos);
  prru_inertia_world(s->q, o->I);
  prru_wrench_bias(s->q, s->qd, o->K);
  prru_energy(s->q, s->qd, o->E);
  prru_actuator_rates(s->q, s->qd, o->dd, o->ddb);
  prru_passive(s->q, s->qd, o->Qp);
  prru_reaction_basis(s->q, nz);
  scatter(nz, prru_reaction_basis_index, PRRU_REACTION_BASIS_NNZ, o->Q);
  prru_eom_solve(s->q, s->qd, s->fd, s->fp, s->mp, o->Ms, o->bs, o->qdd, o->minors);
#if NA == 3
  prru_inverse_terms(s->q, s->qd, s->qdd, s->fp, s->mp, o->di, o->Jdi, o->X, o->y);
  prru_joint_reactions(s->q, s->qd, s->qdd, s->fd, s->fp, s->mp, o->lam);
#else
  prru_inverse_terms(s->q, s->qd, s->qdd, s->fp, s->mp, o->di, o->Jdi, o->y);
  prru_joint_reactions(s->q, s->qd, s->qdd, s->fd, s->fp, s->mp, o->lam, o->z);
  prru_reaction_nullspace(s->q, o->zn);
#endif
}

static double maxabs(const double *x, int n)
{
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(x[i]));
  return m;
}

/* ||A^-1||_inf of a regular 3x3 (adjugate; only a size, for a bound). */
static double inv_norm3(const double A[9])
{
  double c[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[3 * j + i] = A[3 * ((i + 1) % 3) + (j + 1) % 3] * A[3 * ((i + 2) % 3) + (j + 2) % 3] -
                     A[3 * ((i + 1) % 3) + (j + 2) % 3] * A[3 * ((i + 2) % 3) + (j + 1) % 3];
  const double det = A[0] * c[0] + A[1] * c[3] + A[2] * c[6];
  double n = 0;
  for (int i = 0; i < 3; i++) n = fmax(n, (fabs(c[3 * i]) + fabs(c[3 * i + 1]) + fabs(c[3 * i + 2])) / fabs(det));
  return n;
}

/* sum_b |m_b g_k p_b,k|: the size of the terms of V. */
static double potential_terms(const double *mass, const double *g, const double *pos, int nb)
{
  double s = 0;
  for (int b = 0; b < nb; b++)
    for (int k = 0; k < 3; k++) s += fabs(mass[b] * g[k] * pos[3 * b + k]);
  return s;
}

/* max_i of the magnitudes of the terms of b_i = G_i + (J_d^T fd)_i +
 * (J_T,O'^T fp)_i + (J_R,P^T mp)_i + passive_i - h_i (test_param_kernels'
 * eom_b_terms): b is what remains of forces that may cancel. */
static double b_terms(const double *G, const double *h, const double *Qp, const double *Jd,
                      const double *JP, const double *fd, int na, const double *fp,
                      const double *mp)
{
  double scale = 0;
  for (int i = 0; i < 3; i++) {
    double t = fabs(G[i]) + fabs(h[i]) + fabs(Qp[i]);
    for (int j = 0; j < na; j++) t += fd ? fabs(Jd[3 * j + i] * fd[j]) : 0.0;
    for (int k = 0; k < 3; k++)
      t += fabs(JP[3 * k + i] * mp[k]) + fabs(JP[3 * (3 + k) + i] * fp[k]);
    scale = fmax(scale, t);
  }
  return scale;
}

/* The bound of a solve's result x of A x = r, when A's entries may differ
 * by TOL_SAME max|A| and r's by TOL_SAME rterms (first-order perturbation,
 * ||dA||_inf <= 3 max|dA_ij|), twice for the two sides' own rounding. */
static double solve_bound(double ainv, double amax, double xmax, double rterms)
{
  return 2 * TOL_SAME * ainv * (3 * amax * xmax + rterms);
}

enum { SAME, SAME_V, SAME_B, QDD, MINORS, JDINV, FD, TAU };
typedef struct {
  const char *name;
  size_t off;
  int n, rule;
} field;
#define FIELD(name, member, rule) {name, offsetof(outs, member), (int)(sizeof((outs *)0)->member / sizeof(double)), rule}
static const field fields[] = {
  FIELD("ik d", d, SAME), FIELD("jd", Jd, SAME), FIELD("ik_jd d", d2, SAME), FIELD("ik_jd Jd", Jd2, SAME),
  FIELD("jacobians", H, SAME), FIELD("bias_terms", dm, SAME), FIELD("mass", M, SAME),
  FIELD("bias", h, SAME), FIELD("gravity", G, SAME), FIELD("dynamics M", M2, SAME),
  FIELD("dynamics h", h2, SAME), FIELD("dynamics G", G2, SAME), FIELD("eom M", Me, SAME),
  FIELD("eom b", be, SAME_B), FIELD("platform_jacobian", JP, SAME), FIELD("poses R", R, SAME),
  FIELD("poses p", pos, SAME), FIELD("inertia_world", I, SAME), FIELD("wrench_bias", K, SAME),
  FIELD("energy", E, SAME_V), FIELD("actuator_rates dd", dd, SAME),
  FIELD("actuator_rates ddb", ddb, SAME), FIELD("passive", Qp, SAME),
  FIELD("reaction_basis", Q, SAME), FIELD("eom_solve M", Ms, SAME), FIELD("eom_solve b", bs, SAME_B),
  FIELD("eom_solve qdd", qdd, QDD), FIELD("eom_solve minors", minors, MINORS),
  FIELD("inverse_terms d", di, SAME), FIELD("inverse_terms Jd", Jdi, SAME),
#if NA == 3
  FIELD("inverse_terms Jdinv", X, JDINV), FIELD("inverse_terms fd", y, FD),
#else
  FIELD("inverse_terms tau", y, TAU), FIELD("joint_reactions z", z, SAME),
  FIELD("reaction_nullspace", zn, SAME),
#endif
  /* lambda: straight-line sums of the body wrenches and loads at the given
   * qdd, like M: the same rule (relative to its largest entry, the
   * constraint forces that carry those wrenches). */
  FIELD("joint_reactions", lam, SAME),
};
#define NFIELD ((int)(sizeof fields / sizeof fields[0]))

/* The largest |own - const| of field f allowed at this state, from the
 * constant kernels' outputs w. */
static double bound(const field *f, const outs *w, const state *s, const double *got, double *err)
{
  const double *want = (const double *)((const char *)w + f->off);
  *err = tt_maxdiff(got, want, f->n);
  const double mM = maxabs(w->M, 9), nq = maxabs(w->qdd, 3);
  const double B = b_terms(w->G, w->h, w->Qp, w->Jd, w->JP, s->fd, NA, s->fp, s->mp);
  /* tau = M qdd - b(fd = 0): M's and b's terms. */
  const double B0 = b_terms(w->G, w->h, w->Qp, w->Jd, w->JP, NULL, NA, s->fp, s->mp);
  switch (f->rule) {
  case SAME_V: /* relative to the size of V's terms too */
    return TOL_SAME * fmax(maxabs(want, f->n), potential_terms(prru_mech.mass, prru_mech.gravity, w->pos, NB));
  case SAME_B: /* b to the size of its terms */
    return TOL_SAME * fmax(maxabs(want, f->n), B);
  case QDD: /* M qdd = b */
    return solve_bound(inv_norm3(w->M), mM, nq, B);
  case MINORS: { /* minor k: a sum of k! products of k entries of M: k k! TOL_SAME max|M|^k */
    const double c[3] = {1, 4, 18};
    double r = 0;
    for (int k = 0; k < 3; k++)
      r = fmax(r, fabs(got[k] - want[k]) / (c[k] * TOL_SAME * pow(mM, k + 1)));
    *err = r * TOL_SAME;
    return TOL_SAME;
  }
#if NA == 3
  case JDINV: { /* d(J^-1) = -J^-1 dJ J^-1 */
    const double ni = inv_norm3(w->Jd);
    return 2 * 3 * TOL_SAME * maxabs(w->Jd, 9) * ni * ni;
  }
  case FD: { /* J_d^T fd = tau: ||J_d^-T||_inf = ||J_d^-1||_1 */
    double JT[9];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) JT[3 * i + j] = w->Jd[3 * j + i];
    return solve_bound(inv_norm3(JT), maxabs(w->Jd, 9), maxabs(w->y, 3), 3 * mM * maxabs(s->qdd, 3) + B0);
  }
#endif
  case TAU:
    return 2 * TOL_SAME * (3 * mM * maxabs(s->qdd, 3) + B0);
  default:
    return TOL_SAME * fmax(maxabs(want, f->n), 1e-300);
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

static void test_own_topology(void)
{
  own_params p;
  own_from_model(&p);
  static own_derived dp;
  OWN(derive)(&p, &dp);
  prru_model model;
  prru_data data;
  prru_model_default(&model);
  double ratio[NFIELD] = {0};
  int id_fails = 0;
  for (int n = 0; n < NSTATE; n++) {
    state s;
    ts_random_state(&model, &data, s.q, s.qd);
    if (n % 3 == 0) /* slowly, where tanh(dd / v_s) is not saturated */
      for (int i = 0; i < 3; i++) s.qd[i] *= 1e-3;
    random_loads(&s);
    if (n % 5 == 4) { /* the drives hold the motion: b cancels */
      prru_loads l;
      const double zero[3] = {0, 0, 0};
      memset(&l, 0, sizeof l);
      memcpy(l.fp, s.fp, sizeof l.fp);
      memcpy(l.mp, s.mp, sizeof l.mp);
      id_fails += prru_inverse_dynamics(&model, &data, s.q, s.qd, zero, &l, s.fd) != PRRU_OK;
    }
    /* The accelerations of the motion, for inverse_terms and the reactions. */
    double M[9], b[3], minors[3];
    prru_eom_solve(s.q, s.qd, s.fd, s.fp, s.mp, M, b, s.qdd, minors);
    static outs got, want;
    eval_own(&dp, &s, &got);
    eval_const(&s, &want);
    for (int k = 0; k < NFIELD; k++) {
      double err;
      const double *g = (const double *)((const char *)&got + fields[k].off);
      const double bnd = bound(&fields[k], &want, &s, g, &err);
      const double r = err / bnd;
      if (!(r <= ratio[k])) ratio[k] = r;
    }
  }
  TU_TRUE(id_fails == 0, "inverse dynamics for qdd = 0 (the states where b cancels)");
  printf("prru_p%d_* at prru_params_model vs the constant kernels, model %s, %d states, largest "
         "difference as a fraction of its bound:\n", NA, prru_mech.name, NSTATE);
  for (int k = 0; k < NFIELD; k++) {
    char what[128];
    snprintf(what, sizeof what, "prru_p%d %s = constant %s (fraction of the derived bound)", NA,
             fields[k].name, fields[k].name);
    tu_check(ratio[k] <= 1.0, what, ratio[k], 1.0);
    printf("  %-22s %.1e\n", fields[k].name, ratio[k]);
  }
}

/* ---- both topologies: batched against scalar -------------------------- */
static void test_batches(void)
{
  static const int sizes[] = {1, 7, 32, 33, 100, NMAX};
  static tt_states st;
  prru_params3 p3;
  prru_params4 p4;
  double worst = 0;
  int nan_ok = 1, compared = 0;
#if NA == 3
  own_from_model(&p3);
  p4 = prru_p4_params_reference;
#else
  own_from_model(&p4);
  p3 = prru_p3_params_reference;
#endif
  static prru_p3_derived d3;
  static prru_p4_derived d4;
  prru_p3_derive(&p3, &d3);
  prru_p4_derive(&p4, &d4);
  for (size_t t = 0; t < sizeof sizes / sizeof sizes[0]; t++) {
    const int n = sizes[t];
    draw3(&d3, &st, n);
    for (int k = 0; k < n; k++) compared += st.compared[k];
    worst = fmax(worst, check_batch3(&d3, &st, n, &nan_ok));
    draw4(&d4, &st, n);
    for (int k = 0; k < n; k++) compared += st.compared[k];
    worst = fmax(worst, check_batch4(&d4, &st, n, &nan_ok));
  }
  TU_TRUE(nan_ok, "batched topology kernels: NaN exactly where the scalar ones give NaN");
  TU_TRUE(compared > 100, "batched topology kernels: regular states compared");
  printf("prru_p3_batch_* (%s), prru_p4_batch_* (%s) vs scalar: worst %.2e of the largest entry, "
         "%d states compared\n", NA == 3 ? "model" : "reference", NA == 4 ? "model" : "reference",
         worst, compared);
}

/* ---- across topologies: a massless fourth limb ------------------------ */
/* Body j of the three-limb machine in the four-limb order. */
static int body4(int j)
{
  return j == 0 ? 0 : j <= 3 ? j : j <= 6 ? j + 1 : j + 2;
}

static void test_massless_fourth_limb(void)
{
  prru_params4 p4 = prru_p4_params_reference;
  prru_params3 p3;
  for (int j = 4; j <= 12; j += 4) {
    p4.mass[j] = 0;
    memset(p4.com[j], 0, sizeof p4.com[j]);
    memset(p4.inertia[j], 0, sizeof p4.inertia[j]);
  }
  p4.armature[3] = p4.damping[3] = p4.coulomb[3] = 0;
  for (int i = 0; i < 3; i++) {
    p3.b[i] = p4.b[i], p3.l1[i] = p4.l1[i], p3.l2[i] = p4.l2[i], p3.a[i] = p4.a[i];
    p3.armature[i] = p4.armature[i], p3.damping[i] = p4.damping[i], p3.coulomb[i] = p4.coulomb[i];
  }
  memcpy(p3.gravity, p4.gravity, sizeof p3.gravity);
  p3.coulomb_velocity = p4.coulomb_velocity;
  for (int j = 0; j < 10; j++) {
    p3.mass[j] = p4.mass[body4(j)];
    memcpy(p3.com[j], p4.com[body4(j)], sizeof p3.com[j]);
    memcpy(p3.inertia[j], p4.inertia[body4(j)], sizeof p3.inertia[j]);
  }
  static prru_p3_derived dp3;
  static prru_p4_derived dp4;
  prru_p3_derive(&p3, &dp3);
  prru_p4_derive(&p4, &dp4);
  /* lambda coordinates of limbs 1 and 2, by label. */
  int pair[2][PRRU_P3_NLAMBDA], npair = 0;
  for (int i = 0; i < PRRU_P3_NLAMBDA; i++) {
    const char *l = prru_p3_lambda_labels[i];
    if (l[1] != '1' && l[1] != '2') continue;
    for (int k = 0; k < PRRU_P4_NLAMBDA; k++)
      if (strcmp(l, prru_p4_lambda_labels[k]) == 0) pair[0][npair] = i, pair[1][npair++] = k;
  }
  TU_TRUE(npair == 2 * 19, "the 19 reaction coordinates of limbs 1 and 2 are named alike in both sets");
  enum { X_D, X_JD, X_M, X_H, X_G, X_B, X_QDD, X_E, X_JP, X_QP, X_R, X_P, X_TAU, X_LAM, X_N };
  static const char *xname[X_N] = {"ik d", "jd", "mass", "bias", "gravity", "eom b", "eom_solve qdd",
                                   "energy", "platform_jacobian", "passive", "poses R", "poses p",
                                   "inverse_terms tau", "joint_reactions (limbs 1, 2)"};
  double ratio[X_N] = {0};
  int n = 0;
  for (int tries = 0; n < 300 && tries < 30000; tries++) {
    double q[3] = {tu_uniform(-0.4, 0.4), tu_uniform(-0.5, 0.4), tu_uniform(-1.0, -0.5)};
    if (!(margin3(&dp3, q) >= MARGIN && margin4(&dp4, q) >= MARGIN)) continue;
    n++;
    double qd[3], fd[4] = {0, 0, 0, 0}, fp[3], mp[3];
    for (int i = 0; i < 3; i++) {
      qd[i] = tu_uniform(-1, 1) * (n % 3 ? 1 : 1e-3);
      fd[i] = tu_uniform(-60, 60);
      fp[i] = tu_uniform(-30, 30);
      mp[i] = tu_uniform(-3, 3);
    }
    /* a: the three-limb side (the reference), c: the four-limb one. */
    double d3[3], J3[9], M3[9], h3[3], G3[3], Me[9], b3[3], q3dd[3], mi[3], E3[2], JP3[18], Qp3[3];
    double R3[90], P3[30], di[3], Ji[9], Jinv[9], fd3[3], lam3[57];
    double d4[4], J4[12], M4[9], h4[3], G4[3], b4[3], q4dd[3], E4[2], JP4[18], Qp4[3], R4[117],
        P4[39], di4[4], Ji4[12], tau4[3], lam4[76], z4[76];
    prru_p3_ik_jd(&dp3, q, d3, J3);
    prru_p3_dynamics(&dp3, q, qd, M3, h3, G3);
    prru_p3_eom_solve(&dp3, q, qd, fd, fp, mp, Me, b3, q3dd, mi);
    prru_p3_energy(&dp3, q, qd, E3);
    prru_p3_platform_jacobian(&dp3, q, JP3);
    prru_p3_passive(&dp3, q, qd, Qp3);
    prru_p3_poses(&dp3, q, R3, P3);
    prru_p3_inverse_terms(&dp3, q, qd, q3dd, fp, mp, di, Ji, Jinv, fd3);
    prru_p3_joint_reactions(&dp3, q, qd, q3dd, fd, fp, mp, lam3);
    prru_p4_ik_jd(&dp4, q, d4, J4);
    prru_p4_dynamics(&dp4, q, qd, M4, h4, G4);
    prru_p4_eom_solve(&dp4, q, qd, fd, fp, mp, Me, b4, q4dd, mi);
    prru_p4_energy(&dp4, q, qd, E4);
    prru_p4_platform_jacobian(&dp4, q, JP4);
    prru_p4_passive(&dp4, q, qd, Qp4);
    prru_p4_poses(&dp4, q, R4, P4);
    prru_p4_inverse_terms(&dp4, q, qd, q3dd, fp, mp, di4, Ji4, tau4);
    prru_p4_joint_reactions(&dp4, q, qd, q3dd, fd, fp, mp, lam4, z4);
    double R4s[90], P4s[30], tau3[3], l3[38], l4[38];
    for (int j = 0; j < 10; j++) {
      memcpy(R4s + 9 * j, R4 + 9 * body4(j), 9 * sizeof(double));
      memcpy(P4s + 3 * j, P4 + 3 * body4(j), 3 * sizeof(double));
    }
    for (int i = 0; i < 3; i++) tau3[i] = J3[i] * fd3[0] + J3[3 + i] * fd3[1] + J3[6 + i] * fd3[2];
    for (int k = 0; k < npair; k++) l3[k] = lam3[pair[0][k]], l4[k] = lam4[pair[1][k]];
    /* The bounds of test_own_topology's rules, from the three-limb side. */
    const double B = b_terms(G3, h3, Qp3, J3, JP3, fd, 3, fp, mp);
    const double B0 = b_terms(G3, h3, Qp3, J3, JP3, NULL, 3, fp, mp);
    const double mM = maxabs(M3, 9), V = potential_terms(p3.mass, p3.gravity, P3, 10);
    const struct { const double *a, *c; int n; double bnd; } x[X_N] = {
      {d3, d4, 3, TOL_SAME * maxabs(d3, 3)},
      {J3, J4, 9, TOL_SAME * maxabs(J3, 9)},
      {M3, M4, 9, TOL_SAME * mM},
      {h3, h4, 3, TOL_SAME * maxabs(h3, 3)},
      {G3, G4, 3, TOL_SAME * maxabs(G3, 3)},
      {b3, b4, 3, TOL_SAME * fmax(maxabs(b3, 3), B)},
      {q3dd, q4dd, 3, solve_bound(inv_norm3(M3), mM, maxabs(q3dd, 3), B)},
      {E3, E4, 2, TOL_SAME * fmax(maxabs(E3, 2), V)},
      {JP3, JP4, 18, TOL_SAME * maxabs(JP3, 18)},
      {Qp3, Qp4, 3, TOL_SAME * fmax(maxabs(Qp3, 3), 1e-300)},
      {R3, R4s, 90, TOL_SAME * maxabs(R3, 90)},
      {P3, P4s, 30, TOL_SAME * maxabs(P3, 30)},
      /* tau from fd3 = J_d^-T tau and back: the solve's bound besides */
      {tau3, tau4, 3, 2 * TOL_SAME * (3 * mM * maxabs(q3dd, 3) + B0) +
                          solve_bound(1.0, maxabs(J3, 9), maxabs(fd3, 3), 0)},
      {l3, l4, npair, TOL_SAME * maxabs(l3, npair)},
    };
    for (int k = 0; k < X_N; k++) {
      const double r = tt_maxdiff(x[k].a, x[k].c, x[k].n) / x[k].bnd;
      if (!(r <= ratio[k])) ratio[k] = r;
    }
  }
  TU_TRUE(n == 300, "300 regular states of both machines");
  printf("prru_p4_* with a massless fourth limb vs prru_p3_* (limbs 1-3 of %s), %d states, "
         "fraction of the bound:\n", "the 4-limb reference model", n);
  for (int k = 0; k < X_N; k++) {
    char what[128];
    snprintf(what, sizeof what, "massless fourth limb: prru_p4 %s = prru_p3 %s", xname[k], xname[k]);
    tu_check(ratio[k] <= 1.0, what, ratio[k], 1.0);
    printf("  %-30s %.1e\n", xname[k], ratio[k]);
  }
}

int main(void)
{
  test_own_topology();
  test_batches();
  test_massless_fourth_limb();
  return tu_finish("test_topology_kernels");
}
