/* Models loaded at run time (prru_model_load): every committed model file
 * and every valid file of the conformance corpus (tests/models/conformance,
 * which covers format 1 and 2, both topologies, extreme magnitudes and
 * reordered or re-spelt copies of the paper's model). Every file loads,
 * of either number of limbs whatever the build's model; its kernels are
 * the specialised ones
 * exactly when its numbers are the build's model's (the build's own file
 * and its re-spelt copies: the fast path survives a whitespace edit),
 * else the parameter ones. Either way forward dynamics, inverse dynamics
 * and the joint reactions agree with the GSL reference built from the
 * loaded numbers, at seeded random regular states with velocities and
 * loads, within the bounds of test_trust and test_reactions (derived from
 * the rounding unit and the state's conditioning, K u (kappa |qdd| +
 * |M^-1| S) and so on; see there); prru_power matches the kernels'
 * products and closes the work-energy balance. A refused file leaves
 * the model untouched. Loading takes well under 1 ms (timed,
 * printed). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "prru_control.h"
#include "prru_model_file.h"
#include "testref.h"
#include "testutil.h"

#define K 256.0     /* test_trust's u-multiple (forward and inverse dynamics) */
#define KR 1024.0   /* test_reactions' (the reactions, in u kappa(M_s)) */
#define STATES 40

static prru_data data;
static prru_ref_ws *W;
static int energy_checked; /* files whose work-energy balance was checked */
static int power_checked;  /* and with prru_power */

/* The most regular height of q = (0, 0, q3) on a grid down to 4 lengths
 * below the rails' top (every valid model assembles at q1 = q2 = 0);
 * 0 where none is regular. */
static int home_height(const prru_model *m, double L, double *q3)
{
  double best = 0;
  for (int k = 1; k <= 400; k++) {
    double q[3] = {0, 0, -4 * L * k / 400}, rc;
    if (prru_check_regular(m, &data, q, &rc) == PRRU_OK && rc > best) best = rc, *q3 = q[2];
  }
  return best > 0;
}

/* A regular state near the home height, the tilt range halved whenever
 * draws keep failing; 0 when none is found. */
static int random_state(const prru_model *m, const prru_ref_params *P, double L, double q3, double q[3],
                        double qd[3], prru_loads *l)
{
  double span = 1.0;
  for (int tries = 1; tries <= 2000; tries++) {
    q[0] = span * tu_uniform(-0.4, 0.4);
    q[1] = span * tu_uniform(-0.5, 0.4);
    q[2] = q3 + span * L * tu_uniform(-0.1, 0.1);
    if (prru_check_regular(m, &data, q, NULL) == PRRU_OK && ref_margin(P, q) >= 0.1) {
      for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
      for (int i = 0; i < m->mech->nact; i++) l->fd[i] = tu_uniform(-80, 80);
      for (int i = 0; i < 3; i++) l->fp[i] = tu_uniform(-40, 40), l->mp[i] = tu_uniform(-4, 4);
      return 1;
    }
    if (tries % 100 == 0) span *= 0.5;
  }
  return 0;
}

/* S: the size of the terms whose sum is b (test_trust). */
static double terms_scale(const prru_model *m, const double q[3], const double qd[3], const prru_loads *l,
                          const double h[3], const double G[3])
{
  double act[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3], JP[18], Qp[3], s[3] = {0, 0, 0};
  prru_model_ik_jd(m, q, act, Jd);
  prru_model_platform_jacobian(m, q, JP);
  prru_model_passive(m, q, qd, Qp);
  const double w[6] = {l->mp[0], l->mp[1], l->mp[2], l->fp[0], l->fp[1], l->fp[2]};
  for (int j = 0; j < 3; j++) {
    for (int i = 0; i < m->mech->nact; i++) s[j] += fabs(Jd[3 * i + j] * l->fd[i]);
    for (int i = 0; i < 6; i++) s[j] += fabs(JP[3 * i + j] * w[i]);
  }
  return tu_norm_inf(h, 3) + tu_norm_inf(G, 3) + tu_norm_inf(s, 3) + tu_norm_inf(Qp, 3);
}

typedef struct {
  double fd, id, rt, lam, energy, paths, power, balance;
  int states;
} worst;

/* gamma_n = n u / (1 - n u), u = DBL_EPSILON / 2: the bound on the
 * relative rounding of a chain of n floating-point operations. */
static double gamma_n(int n)
{
  const double u = DBL_EPSILON / 2;
  return n * u / (1 - n * u);
}

/* prru_power against the same powers summed the other way round from the
 * model's kernels: the loads' as qd . tau, tau = J_d^T fd + J_T,O'^T fp +
 * J_R,P^T mp the generalized force they exert (the virtual power that
 * the equations of motion use), the drives' as Q_p . qd from the last
 * term. Both sides are the same real sum of products f_i J_ik qd_k of the
 * same doubles, evaluated in different orders: each within gamma_n S of
 * the exact sum, S the sum of the products' magnitudes and n the most
 * operations any one product passes through (library: 1 product and 3
 * adds for J qd, 1 product by the load, 1 add of fp v + mp w, NACT + 3
 * adds into the total; here: 1 product, 1 add of the fp and mp terms,
 * NACT + 6 adds into tau, 1 product by qd, 3 adds; n = NACT + 12 covers
 * both), so they differ by at most 2 gamma_n S; the drives' sums (1
 * product, 3 adds) by 2 gamma_4 sum |Q_p,k qd_k|. S's own rounding is a
 * relative gamma_n: second order, left out. */
static void check_power_state(const prru_model *m, const double q[3], const double qd[3], const prru_loads *l,
                              worst *w, const char *file)
{
  const int na = m->mech->nact;
  double load, passive, act[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3], JP[18], Qp[3];
  prru_power(m, q, qd, l, &load, &passive);
  prru_model_ik_jd(m, q, act, Jd);
  prru_model_platform_jacobian(m, q, JP);
  prru_model_passive(m, q, qd, Qp);
  double load_t = 0, passive_t = 0, S = 0, Sp = 0;
  for (int k = 2; k >= 0; k--) {
    double tau = 0;
    for (int i = 0; i < 3; i++) {
      tau += JP[9 + 3 * i + k] * l->fp[i] + JP[3 * i + k] * l->mp[i];
      S += (fabs(JP[9 + 3 * i + k] * l->fp[i]) + fabs(JP[3 * i + k] * l->mp[i])) * fabs(qd[k]);
    }
    for (int i = na - 1; i >= 0; i--) {
      tau += Jd[3 * i + k] * l->fd[i];
      S += fabs(Jd[3 * i + k] * l->fd[i]) * fabs(qd[k]);
    }
    load_t += qd[k] * tau;
    passive_t += Qp[k] * qd[k];
    Sp += fabs(Qp[k] * qd[k]);
  }
  const double bl = 2 * gamma_n(na + 12) * S, bp = 2 * gamma_n(4) * Sp;
  const double el = fabs(load - load_t), ep = fabs(passive - passive_t);
  /* An exact 0 (a model without drives) has a zero bound: compared as such. */
  const double r = fmax(bl > 0 ? el / bl : el > 0, bp > 0 ? ep / bp : ep > 0);
  w->power = fmax(w->power, r);
  char what[700];
  snprintf(what, sizeof what, "%s: prru_power = qd . tau and Q_p . qd, within 2 gamma_n of the terms", file);
  tu_check(el <= bl && ep <= bp, what, r, 1.0);
}

/* One state: forward and inverse dynamics and the reactions against the
 * reference from the loaded numbers; refusals by the trust criterion skip. */
static void check_state(const prru_model *m, const prru_ref_params *P, const double q[3], const double qd[3],
                        const prru_loads *l, worst *w, const char *file, int reactions,
                        const prru_model *const alts[2])
{
  const int na = m->mech->nact;
  double qdd[3], qdd_ref[3], fd[PRRU_MAX_ACT], fd_ref[PRRU_MAX_ACT], lam[PRRU_MAX_LAMBDA], lam_ref[PRRU_MAX_LAMBDA];
  if (prru_forward_dynamics(m, &data, q, qd, l, qdd) != PRRU_OK) return;
  double M[9], h[3], G[3], Minv[9];
  prru_model_dynamics(m, q, qd, M, h, G);
  const double S = terms_scale(m, q, qd, l, h, G);
  tu_inverse3(M, Minv);
  const double u = DBL_EPSILON, nM = tu_norm1(M, 3, 3), nMi = tu_norm1(Minv, 3, 3), nq = tu_norm_inf(qdd, 3);
  char what[600];
  if (prru_ref_forward_dynamics(P, W, q, qd, l->fd, l->fp, l->mp, qdd_ref) != GSL_SUCCESS) {
    snprintf(what, sizeof what, "%s: the reference solves the forward dynamics", file);
    TU_TRUE(0, what);
    return;
  }
  double e = 0;
  for (int i = 0; i < 3; i++) e = fmax(e, fabs(qdd[i] - qdd_ref[i]));
  const double bfd = u * (nM * nMi * nq + nMi * S);
  w->fd = fmax(w->fd, e / bfd);
  snprintf(what, sizeof what, "%s: |qdd - qdd_ref| / (u (kappa |qdd| + |M^-1| S))", file);
  tu_check(e <= K * bfd, what, e / bfd, K);
  /* The specialised and the parameter path on the same numbers: each is
   * within K bfd of the exact qdd, so they differ by at most twice that;
   * likewise ID below. */
  double qdd_alt[3], fd_alt[PRRU_MAX_ACT];
  for (int a = 0; a < 2; a++)
    if (alts[a] && prru_forward_dynamics(alts[a], &data, q, qd, l, qdd_alt) == PRRU_OK) {
      double ea = 0;
      for (int i = 0; i < 3; i++) ea = fmax(ea, fabs(qdd[i] - qdd_alt[i]));
      w->paths = fmax(w->paths, ea / bfd);
      snprintf(what, sizeof what, "%s: two kernel tables (%s), |qdd - qdd_p| / (u (kappa |qdd| + |M^-1| S))",
               file, a ? "general" : "parameter");
      tu_check(ea <= 2 * K * bfd, what, ea / bfd, 2 * K);
    }

  /* Inverse dynamics at the same state and qdd, against the reference's
   * (minimum-norm with four actuators, as the runtime's). */
  if (prru_inverse_dynamics(m, &data, q, qd, qdd, l, fd) == PRRU_OK &&
      prru_ref_inverse_dynamics(P, W, q, qd, qdd, l->fp, l->mp, fd_ref) == GSL_SUCCESS) {
    const double nJ = tu_norm1(data.Jdpinv, 3, na);
    double r = 0;
    for (int i = 0; i < na; i++) r = fmax(r, fabs(fd[i] - fd_ref[i]));
    const double bid = u * nJ * (nM * nq + S);
    w->id = fmax(w->id, r / bid);
    snprintf(what, sizeof what, "%s: |fd - fd_ref| / (u |J_d^+| (|M| |qdd| + S))", file);
    tu_check(r <= K * bid, what, r / bid, K);
    for (int a = 0; a < 2; a++)
      if (alts[a] && prru_inverse_dynamics(alts[a], &data, q, qd, qdd, l, fd_alt) == PRRU_OK) {
        double ra = 0;
        for (int i = 0; i < na; i++) ra = fmax(ra, fabs(fd[i] - fd_alt[i]));
        w->paths = fmax(w->paths, ra / bid);
        snprintf(what, sizeof what, "%s: two kernel tables (%s), |fd - fd_p| / (u |J_d^+| (|M| |qdd| + S))",
                 file, a ? "general" : "parameter");
        tu_check(ra <= 2 * K * bid, what, ra / bid, 2 * K);
      }
    /* The round trip ID(FD(fd)) = fd, compared as generalised forces
     * J_d^T fd (with four actuators ID returns fd less its component along
     * the null vector of J_d^T, which J_d^T removes). Bound: qdd carries
     * FD's error, at most K bfd (above); ID maps it through |J_d^+| |M|
     * and adds its own K bid; J_d^T multiplies by |J_d^T|_1. */
    double d[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3], Q[3] = {0, 0, 0};
    prru_model_ik_jd(m, q, d, Jd);
    for (int i = 0; i < na; i++)
      for (int j = 0; j < 3; j++) Q[j] += Jd[3 * i + j] * (fd[i] - l->fd[i]);
    double nJt = 0; /* |J_d^T|_1: the largest row sum of J_d */
    for (int i = 0; i < na; i++)
      nJt = fmax(nJt, fabs(Jd[3 * i]) + fabs(Jd[3 * i + 1]) + fabs(Jd[3 * i + 2]));
    const double brt = nJt * (nJ * nM * bfd + bid);
    const double rt = tu_norm_inf(Q, 3);
    w->rt = fmax(w->rt, rt / brt);
    snprintf(what, sizeof what, "%s: |J_d^T (ID(FD(fd)) - fd)| / (|J_d^T| (|J_d^+| |M| bfd + bid))", file);
    tu_check(rt <= K * brt, what, rt / brt, K);
  }

  if (reactions && prru_reactions(m, &data, q, qd, l, lam) == PRRU_OK &&
      prru_ref_reactions(P, W, q, qd, l->fd, l->fp, l->mp, lam_ref) == GSL_SUCCESS) {
    const double kappa = 1.0 / prru_mass_rcond(m, data.M);
    const double er = tu_relerr(lam, lam_ref, m->mech->nlambda, 1.0) / (u * kappa);
    w->lam = fmax(w->lam, er);
    snprintf(what, sizeof what, "%s: reactions against the reference (in u kappa(M_s))", file);
    tu_check(er <= KR, what, er, KR);
  }
  w->states++;
}

/* The work-energy balance on the loaded model (test_runtime's, there on
 * the build's own): along a motion under constant loads, d/dt (T + V) is
 * the power of the actuator forces and the drives' damping and friction,
 * P = fd . d' + Q_p . qd (gravity is in V). Classical RK4 carries (q, qd,
 * W) over half the model's time scale tau = sqrt(L / |g|) from a regular
 * state, with the actuator forces that hold it at rest plus a push, and
 * initial rates of 0.3 / tau (0.3 L / tau for q3): sizes 0.1x to 10x meet
 * the same problem in their own units. Bound, derived: RK4 is of order 4,
 * so the balance residual r_2n with 2n steps is (r_n - r_2n) / 15 of
 * truncation, allowed twice that, plus rounding of at most 4 u per stage
 * (16 u per step)
 * in the largest of |T|, |V|, |W|. A dynamics whose energy kernel
 * disagrees with its forward dynamics leaves a residual that does not
 * shrink with the step, and fails. check_energy returns 1 when checked,
 * 0 when the motion left the regular workspace (reported, not checked).
 * With library_power, the same balance with prru_power as dW/dt and a
 * platform force and moment as well (a tenth of the machine's weight W
 * and W L / 30 in each direction, held at the start like gravity): the
 * library's power against the energy kernel and the forward dynamics,
 * which share none of its code, with the same bound. */
static void work_rhs(const prru_model *m, const prru_loads *l, const double y[7], double f[7], int library_power)
{
  double d[PRRU_MAX_ACT], Jd[3 * PRRU_MAX_ACT], Qp[3], dd[PRRU_MAX_ACT], ddb[PRRU_MAX_ACT];
  memcpy(f, y + 3, 3 * sizeof f[0]);
  if (prru_forward_dynamics(m, &data, y, y + 3, l, f + 3) != PRRU_OK) f[3] = NAN;
  if (library_power) {
    double load, passive;
    prru_power(m, y, y + 3, l, &load, &passive);
    f[6] = load + passive;
    return;
  }
  prru_model_ik_jd(m, y, d, Jd);
  prru_model_passive(m, y, y + 3, Qp);
  prru_model_actuator_rates(m, y, y + 3, dd, ddb);
  double p = 0;
  for (int i = 0; i < 3; i++) p += Qp[i] * y[3 + i];
  for (int i = 0; i < m->mech->nact; i++) p += l->fd[i] * dd[i];
  f[6] = p;
}

static double balance_residual(const prru_model *m, const prru_loads *l, const double q0[3], const double qd0[3],
                               double t_end, int n, double *scale, int library_power)
{
  double y[7] = {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2], 0}, k1[7], k2[7], k3[7], k4[7], yt[7];
  const double h = t_end / n;
  for (int s = 0; s < n; s++) {
    work_rhs(m, l, y, k1, library_power);
    for (int j = 0; j < 7; j++) yt[j] = y[j] + 0.5 * h * k1[j];
    work_rhs(m, l, yt, k2, library_power);
    for (int j = 0; j < 7; j++) yt[j] = y[j] + 0.5 * h * k2[j];
    work_rhs(m, l, yt, k3, library_power);
    for (int j = 0; j < 7; j++) yt[j] = y[j] + h * k3[j];
    work_rhs(m, l, yt, k4, library_power);
    for (int j = 0; j < 7; j++) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    if (!isfinite(y[3])) return NAN;
  }
  double T0, V0, T1, V1;
  if (prru_energies(m, q0, qd0, &T0, &V0) != PRRU_OK || prru_energies(m, y, y + 3, &T1, &V1) != PRRU_OK) return NAN;
  *scale = fmax(fmax(fabs(T0), fabs(T1)), fmax(fmax(fabs(V0), fabs(V1)), fabs(y[6])));
  return T1 + V1 - T0 - V0 - y[6];
}

static int check_energy(const prru_model *m, const double q0[3], double L, const char *file, double *ratio,
                        int library_power)
{
  const double g = sqrt(m->mech->gravity[0] * m->mech->gravity[0] + m->mech->gravity[1] * m->mech->gravity[1] +
                        m->mech->gravity[2] * m->mech->gravity[2]);
  const double tau = sqrt(L / g), zero[3] = {0, 0, 0};
  const double qd0[3] = {0.3 / tau, -0.2 / tau, 0.3 * L / tau};
  prru_loads l;
  memset(&l, 0, sizeof l);
  if (library_power) {
    double weight = 0;
    for (int b = 0; b < m->mech->nbody; b++) weight += m->mech->mass[b] * g;
    for (int i = 0; i < 3; i++) {
      l.fp[i] = 0.1 * weight * (i == 1 ? -1 : 1);
      l.mp[i] = weight * L / 30 * (i == 2 ? -1 : 1);
    }
  }
  if (prru_inverse_dynamics(m, &data, q0, zero, zero, &l, l.fd) != PRRU_OK) return 0;
  for (int i = 0; i < m->mech->nact; i++) l.fd[i] *= 1.0 + 0.05 * (i + 1); /* a push: the forces do work */
  const int n = 200;
  double s1 = 0, s2 = 0;
  const double r1 = balance_residual(m, &l, q0, qd0, 0.5 * tau, n, &s1, library_power);
  const double r2 = balance_residual(m, &l, q0, qd0, 0.5 * tau, 2 * n, &s2, library_power);
  if (!isfinite(r1) || !isfinite(r2)) {
    printf("%s: %s not checked: the motion left the regular workspace\n", file,
           library_power ? "prru_power's energy balance" : "energy balance");
    return 0;
  }
  const double bound = 2 * fabs(r1 - r2) / 15 + 16 * DBL_EPSILON * 2 * n * s2;
  *ratio = fabs(r2) / bound;
  char what[600];
  snprintf(what, sizeof what, "%s: work-energy balance%s |r_2n| / (2 |r_n - r_2n| / 15 + 16 u 2n max(T, V, W))", file,
           library_power ? " with prru_power and platform loads" : "");
  tu_check(fabs(r2) <= bound, what, *ratio, 1.0);
  return 1;
}

/* Whether the file's numbers are the build's model's, decided here by the
 * generator's descriptor of the build (prru_mech) against the loader's
 * spec, member by member. */
static int numbers_are_built(const prru_model_spec *s)
{
  const prru_mechanism *me = &prru_mech;
  if (s->nlimb != me->nlimb || memcmp(s->gravity, me->gravity, sizeof s->gravity) != 0) return 0;
  for (int i = 0; i < me->nlimb; i++)
    if (s->limb[i].b != me->b[i] || s->limb[i].l1 != me->l1[i] || s->limb[i].l2 != me->l2[i] ||
        s->limb[i].a != me->a[i] || s->armature[i] != me->armature[i] || s->damping[i] != me->damping[i] ||
        s->coulomb[i] != me->coulomb[i])
      return 0;
  for (int b = 0; b < me->nbody; b++) {
    const double *I = me->inertia[b], *J = s->inertia[b];
    if (s->mass[b] != me->mass[b] || memcmp(s->com[b], me->com[b], sizeof s->com[b]) != 0 || J[0] != I[0] ||
        J[1] != I[4] || J[2] != I[8] || J[3] != I[1] || J[4] != I[2] || J[5] != I[5])
      return 0;
  }
  return s->coulomb_velocity == me->coulomb_velocity;
}

static int same_bits(const double *a, const double *b, int n)
{
  return memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

/* prru_model_file_text of a loaded model's own numbers reads back as the
 * same numbers, bit for bit (%.17g round-trips a double), with the
 * file's drive keys; a description with bytes that are not UTF-8 and
 * quotes comes back as prru_description made it; numbers that do not
 * make a model (a mass of 0, a bad name) are refused with the loader's
 * message and no text. */
static void check_written(const char *path, const prru_model *m, const prru_model_spec *spec)
{
  prru_params p;
  prru_model_params(m, &p);
  char *text = NULL, msg[1024], what[1400], desc[PRRU_DESCRIPTION_SIZE];
  static const char hostile[] = "round trip \"quoted\" \\ \377\376 */ <&>";
  int st = prru_model_file_text(m, &p, spec->name, hostile, &text, msg, sizeof msg);
  snprintf(what, sizeof what, "%s: written back (%s)", path, st ? msg : "ok");
  if (!TU_TRUE(st == PRRU_OK && text, what)) return;
  prru_model_spec *s2 = malloc(sizeof *s2);
  st = s2 ? prru_model_file_parse(text, strlen(text), "written", s2, msg, sizeof msg) : PRRU_ENOMEM;
  snprintf(what, sizeof what, "%s: the written text parses (%s)", path, st ? msg : "ok");
  if (TU_TRUE(st == PRRU_OK, what)) {
    int same = same_bits(s2->gravity, spec->gravity, 3) && s2->keys == spec->keys &&
               strcmp(s2->description, prru_description(desc, sizeof desc, hostile)) == 0;
    for (int i = 0; i < spec->nlimb; i++)
      same &= same_bits(&s2->limb[i].b, &spec->limb[i].b, 1) && same_bits(&s2->limb[i].l1, &spec->limb[i].l1, 1) &&
              same_bits(&s2->limb[i].l2, &spec->limb[i].l2, 1) && same_bits(&s2->limb[i].a, &spec->limb[i].a, 1);
    same &= same_bits(s2->mass, spec->mass, spec->nbody);
    for (int k = 0; k < spec->nbody; k++)
      same &= same_bits(s2->com[k], spec->com[k], 3) && same_bits(s2->inertia[k], spec->inertia[k], 6);
    same &= same_bits(s2->armature, spec->armature, spec->nlimb) && same_bits(s2->damping, spec->damping, spec->nlimb) &&
            same_bits(s2->coulomb, spec->coulomb, spec->nlimb) && same_bits(s2->d_min, spec->d_min, spec->nlimb) &&
            same_bits(s2->d_max, spec->d_max, spec->nlimb) && same_bits(s2->force_max, spec->force_max, spec->nlimb) &&
            same_bits(s2->speed_max, spec->speed_max, spec->nlimb);
    /* Without Coulomb friction the file has no coulomb_velocity; the
     * parameters carry 1 m/s (prru_model_params), which is written. */
    same &= spec->coulomb_velocity == 0 || s2->coulomb_velocity == spec->coulomb_velocity;
    snprintf(what, sizeof what, "%s: written and read back: the same numbers, drive keys and description", path);
    TU_TRUE(same, what);
  }
  /* Numbers no short decimal holds (an identified model's): each body's
   * mass and inertia, and each drive's damping and Coulomb force, times
   * 1 + 1/3000 (divided by it where that would pass a file's 1e6 bound;
   * a body's inertia scaled as one keeps it consistent) read back exactly. */
  prru_params odd = p;
  const double f = 1 + 1.0 / 3000;
  const int nb = m->mech->nbody, na = m->mech->nact;
  for (int k = 0; k < nb; k++) {
    double big = odd.mass[k];
    for (int e = 0; e < 6; e++) big = fmax(big, fabs(odd.inertia[k][e]));
    const double g = big * f <= 1e6 ? f : 1 / f;
    odd.mass[k] *= g;
    for (int e = 0; e < 6; e++) odd.inertia[k][e] *= g;
  }
  for (int i = 0; i < na; i++) {
    odd.damping[i] *= odd.damping[i] * f <= 1e6 ? f : 1 / f;
    odd.coulomb[i] *= odd.coulomb[i] * f <= 1e6 ? f : 1 / f;
  }
  free(text);
  st = prru_model_file_text(m, &odd, spec->name, "", &text, msg, sizeof msg);
  if (st == PRRU_OK) st = prru_model_file_parse(text, strlen(text), "written", s2, msg, sizeof msg);
  snprintf(what, sizeof what, "%s: numbers of 17 digits written and read back exactly (%s)", path, st ? msg : "ok");
  if (TU_TRUE(st == PRRU_OK, what)) {
    int same = same_bits(s2->mass, odd.mass, nb) && same_bits(s2->damping, odd.damping, na) &&
               same_bits(s2->coulomb, odd.coulomb, na);
    for (int k = 0; k < nb; k++) same &= same_bits(s2->inertia[k], odd.inertia[k], 6);
    TU_TRUE(same, what);
  }
  free(s2);
  free(text);
  prru_params bad = p;
  bad.mass[nb - 1] = 0;
  st = prru_model_file_text(m, &bad, spec->name, "", &text, msg, sizeof msg);
  snprintf(what, sizeof what, "%s: a slider of mass 0 is refused with the loader's message (%s)", path, msg);
  TU_TRUE(st == PRRU_EINPUT && text == NULL && strstr(msg, "mass: must be positive"), what);
  st = prru_model_file_text(m, &p, "Bad-Name", "", &text, msg, sizeof msg);
  snprintf(what, sizeof what, "%s: a name that is no identifier is refused (%s)", path, msg);
  TU_TRUE(st == PRRU_EINPUT && text == NULL && strstr(msg, "Bad-Name"), what);
}

/* Model names (spec 11) and the names identify and optimize derive: cut
 * to fit 16 characters with their suffix, valid whenever the base is. */
static void check_names(void)
{
  static const char *const good[] = {"a", "paper3prru", "p_1", "abcdefghijklmnop"};
  static const char *const bad[] = {"", "Paper", "3prru", "_x", "a-b", "abcdefghijklmnopq", "a b", "\303\251"};
  for (int i = 0; i < 4; i++) TU_TRUE(prru_model_name_valid(good[i]), good[i]);
  for (int i = 0; i < 8; i++) TU_TRUE(!prru_model_name_valid(bad[i]), bad[i]);
  char out[PRRU_MODEL_NAME_MAX + 1];
  prru_model_name_derive("abcdefghijklmnop", "_id", out);
  TU_TRUE(strcmp(out, "abcdefghijklm_id") == 0 && prru_model_name_valid(out), "a 16-character base cut for _id");
  prru_model_name_derive("paper3prru", "_opt", out);
  TU_TRUE(strcmp(out, "paper3prru_opt") == 0, "a short base kept whole");
  prru_model_name_derive("abcdefghijklmnop", "_opt", out);
  TU_TRUE(strlen(out) == PRRU_MODEL_NAME_MAX && prru_model_name_valid(out), "a 16-character base cut for _opt");
}

/* The loader's descriptor of the build's own model file has the
 * generator's layout (prru_topology_layout: sizes, bodies, joints, lambda
 * labels), member by member. */
static void check_layout(const char *path)
{
  prru_model m;
  char msg[1024];
  prru_model_default(&m);
  if (!TU_TRUE(prru_model_load(&m, path, msg, sizeof msg) == PRRU_OK, "the build's model file loads")) return;
  const prru_mechanism *a = m.mech, *g = &prru_mech;
  int ok = a->nq == g->nq && a->nact == g->nact && a->nlimb == g->nlimb && a->nbody == g->nbody &&
           a->nlambda == g->nlambda && a->njoint == g->njoint && a->platform == g->platform;
  for (int b = 0; ok && b < g->nbody; b++)
    ok = strcmp(a->body_names[b], g->body_names[b]) == 0 && a->body_limb[b] == g->body_limb[b];
  for (int i = 0; ok && i < g->nlimb; i++)
    ok = a->lower[i] == g->lower[i] && a->upper[i] == g->upper[i] && a->slider[i] == g->slider[i];
  for (int j = 0; ok && j < g->njoint; j++) {
    const prru_joint_info *x = &a->joint[j], *y = &g->joint[j];
    ok = strcmp(x->name, y->name) == 0 && x->type == y->type && x->limb == y->limb && x->proximal == y->proximal &&
         x->distal == y->distal && x->lambda_offset == y->lambda_offset && x->lambda_count == y->lambda_count;
  }
  for (int r = 0; ok && r < g->nlambda; r++) ok = strcmp(a->lambda_labels[r], g->lambda_labels[r]) == 0;
  TU_TRUE(ok, "the loaded descriptor's layout (sizes, bodies, joints, lambda labels) is the generator's");
  prru_model_free(&m);
}

static void check_file(const char *path, int *loaded, int *other, int *specialised, int reactions)
{
  prru_model_spec spec;
  char msg[1024], what[1200];
  if (prru_model_file_read(path, &spec, msg, sizeof msg) != PRRU_OK) {
    snprintf(what, sizeof what, "%s: a valid file reads: %s", path, msg);
    TU_TRUE(0, what);
    return;
  }
  prru_model m;
  prru_model_default(&m);
  m.jd_rcond_min = 0.5; /* untouched on failure: checked below */
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  const int st = prru_model_load(&m, path, msg, sizeof msg);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  const double ms = 1e3 * (double)(t1.tv_sec - t0.tv_sec) + 1e-6 * (double)(t1.tv_nsec - t0.tv_nsec);
  /* Every build evaluates both topologies: a file of the other one is
   * checked like the rest (against the reference in its own topology). */
  *other += spec.nlimb != prru_mech.nlimb;
  snprintf(what, sizeof what, "%s: loads", path);
  if (!TU_TRUE(st == PRRU_OK, what)) return;
  (*loaded)++;
  check_written(path, &m, &spec);
  const int built = numbers_are_built(&spec);
  *specialised += built;
  snprintf(what, sizeof what, "%s: %s kernels", path, built ? "specialised" : "parameter");
  TU_TRUE(strcmp(m.kernels->path, built ? "specialised" : "parameter") == 0 && (m.kernel_params == NULL) == built,
          what);
  snprintf(what, sizeof what, "%s: the descriptor holds the file's name, path and sha256", path);
  TU_TRUE(strcmp(m.mech->name, spec.name) == 0 && strcmp(m.mech->model_file, path) == 0 &&
              strcmp(m.mech->sha256, spec.sha256) == 0 && m.mech->format == spec.format,
          what);
  prru_ref_params P;
  ref_params_of(m.mech, &P);
  const double L = prru_length_scale(m.mech);
  double q3 = 0;
  worst w = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  /* The build's own numbers: the same file again, on the parameter
   * kernels, compared state by state with the specialised path. */
  /* And the general parameter kernels where the model's own path is
   * their simple variant (a model with none of its numbers: exactly the
   * zeros the variant drops). The simple variant is chosen exactly when
   * every centre of mass, product of inertia and drive number is 0 and
   * gravity is along z. */
  prru_model alt, general;
  prru_model_default(&alt);
  prru_model_default(&general);
  const int two_paths = built && prru_model_load(&alt, path, msg, sizeof msg) == PRRU_OK &&
                        prru_model_use_parameter_kernels(&alt) == PRRU_OK &&
                        strcmp(alt.kernels->path, "parameter") == 0;
  if (built) {
    snprintf(what, sizeof what, "%s: a second copy switched to the parameter kernels", path);
    TU_TRUE(two_paths, what);
  }
  const prru_model *paramd = built ? &alt : &m;
  const prru_mechanism *me = m.mech;
  int simple = me->gravity[0] == 0 && me->gravity[1] == 0;
  for (int b = 0; b < me->nbody; b++) /* inertia: 3x3 row-major, products off the diagonal */
    simple &= !me->com[b][0] && !me->com[b][1] && !me->com[b][2] && !me->inertia[b][1] && !me->inertia[b][2] &&
              !me->inertia[b][5];
  for (int i = 0; i < me->nact; i++) simple &= !me->armature[i] && !me->damping[i] && !me->coulomb[i];
  prru_model probe;
  prru_model_default(&probe);
  const int loaded_general = paramd->own && prru_model_load(&probe, path, msg, sizeof msg) == PRRU_OK &&
                             prru_model_use_general_kernels(&probe) == PRRU_OK;
  snprintf(what, sizeof what, "%s: the parameter kernels are the simple variant exactly when its numbers are %s", path,
           simple ? "simple" : "not");
  TU_TRUE(loaded_general && (paramd->kernels->dynamics != probe.kernels->dynamics) == simple, what);
  if (loaded_general && simple) general = probe;
  else prru_model_free(&probe);
  const prru_model *alts[2] = {two_paths ? &alt : NULL, simple && general.own ? &general : NULL};
  if (!home_height(&m, L, &q3)) {
    printf("%s: SKIPPED the dynamics: no regular pose at q1 = q2 = 0\n", path);
  } else {
    for (int k = 0; k < STATES; k++) {
      double q[3], qd[3];
      prru_loads l;
      if (!random_state(&m, &P, L, q3, q, qd, &l)) break;
      check_state(&m, &P, q, qd, &l, &w, path, reactions, alts);
      check_power_state(&m, q, qd, &l, &w, path);
    }
    printf("home %s 0,0,%.17g\n", path, q3); /* the CLI check of test_random_loaded.sh starts there */
    const double q0[3] = {0.05, -0.05, q3};
    energy_checked += check_energy(&m, q0, L, path, &w.energy, 0);
    power_checked += check_energy(&m, q0, L, path, &w.balance, 1);
  }
  printf("%-60s %s, %.3f ms to load; %d states: FD %.1f, ID %.1f, ID(FD) %.1f u-bounds, reactions %.1f u kappa%s; "
         "energy %.2g of its bound; prru_power %.2g of its bound, in the balance %.2g\n",
         path, m.kernels->path, ms, w.states, w.fd, w.id, w.rt, w.lam, reactions ? "" : " (not compared: see main)",
         w.energy, w.power, w.balance);
  if (alts[0] || alts[1])
    printf("  against the other kernel tables (%s%s): %.2f u-bounds (FD, ID)\n", alts[0] ? "parameter " : "",
           alts[1] ? "general" : "", w.paths);
  prru_model_free(&alt);
  prru_model_free(&general);
  snprintf(what, sizeof what, "%s: dynamics compared at regular states", path);
  TU_TRUE(w.states >= STATES / 2, what);
  prru_model_free(&m);
  TU_TRUE(m.own == NULL && m.mech == &prru_mech, "prru_model_free leaves the default model");
}

/* The drives (spec 13) of a loaded model: the descriptor and the accessor
 * hold the loader's numbers; prru_model_motor_units inverts the file's
 * torque_max and reproduces the spec's conversions written another way.
 * Tolerance: each side is a few correctly rounded operations on the same
 * doubles (tau = f / (2 pi gear / lead) against f lead / (2 pi gear):
 * 3 roundings each, plus the 1 of 2 pi and the file's torque_max -> f
 * conversion), so they agree to 8 u of the result. */
static void check_drives(const char *src)
{
  const double tol = 8 * DBL_EPSILON, twopi = 2 * 3.14159265358979323846;
  char path[2100], msg[1024], what[2300];
  const char *files[2] = {"models/prototype_drives.json",
                          "tests/models/conformance/valid/f2_drives_motor_forms.json"};
  for (int k = 0; k < 2; k++) {
    prru_model_spec s;
    prru_model m;
    prru_limits lim;
    prru_model_default(&m);
    snprintf(path, sizeof path, "%s/%s", src, files[k]);
    if (!TU_TRUE(prru_model_file_read(path, &s, msg, sizeof msg) == PRRU_OK &&
                     prru_model_load(&m, path, msg, sizeof msg) == PRRU_OK,
                 path))
      continue;
    prru_model_limits(&m, &lim);
    int same = 1, conv = 1;
    double f[PRRU_MAX_ACT], tau[PRRU_MAX_ACT], cur[PRRU_MAX_ACT];
    for (int i = 0; i < m.mech->nact; i++) {
      same &= lim.force_max[i] == s.force_max[i] && lim.speed_max[i] == s.speed_max[i] &&
              lim.d_min[i] == s.d_min[i] && lim.d_max[i] == s.d_max[i] && m.mech->lead[i] == s.lead[i] &&
              m.mech->gear[i] == s.gear[i] && m.mech->torque_constant[i] == s.torque_constant[i];
      const double lead = s.lead[i], gear = s.gear[i], w = twopi * gear / lead;
      /* the file's forms: torque_max, motor_speed_max (rev/min), rotor_inertia */
      conv &= fabs(lim.force_max[i] - s.torque_max[i] * twopi * gear / lead) <= tol * lim.force_max[i];
      conv &= fabs(lim.speed_max[i] - s.motor_speed_max[i] * lead / (60 * gear)) <= tol * lim.speed_max[i];
      conv &= fabs(m.mech->armature[i] - s.rotor_inertia[i] * w * w) <= tol * m.mech->armature[i];
      f[i] = lim.force_max[i];
    }
    snprintf(what, sizeof what, "%s: descriptor and prru_model_limits hold the loader's drives", path);
    TU_TRUE(same && prru_model_has_lead(&m), what);
    snprintf(what, sizeof what, "%s: rail limits and armature from torque_max, motor_speed_max, rotor_inertia",
             path);
    TU_TRUE(conv, what);
    int back = prru_model_motor_units(&m, f, tau, cur) == PRRU_OK;
    for (int i = 0; i < m.mech->nact; i++)
      back &= fabs(tau[i] - s.torque_max[i]) <= tol * s.torque_max[i] &&
              fabs(cur[i] - s.torque_max[i] / s.torque_constant[i]) <= tol * cur[i];
    snprintf(what, sizeof what, "%s: motor units of force_max give torque_max and its current", path);
    TU_TRUE(back, what);
    prru_model_free(&m);
  }
  /* No drive keys: no limits, no lead, motor units refused. */
  prru_model m;
  prru_limits lim;
  prru_model_default(&m);
  snprintf(path, sizeof path, "%s/models/prototype_example.json", src);
  if (TU_TRUE(prru_model_load(&m, path, msg, sizeof msg) == PRRU_OK, path)) {
    prru_model_limits(&m, &lim);
    int none = 1;
    double f[PRRU_MAX_ACT] = {0}, tau[PRRU_MAX_ACT], cur[PRRU_MAX_ACT];
    for (int i = 0; i < m.mech->nact; i++) {
      none &= isinf(lim.force_max[i]) && lim.force_max[i] > 0 && isinf(lim.speed_max[i]) &&
              lim.speed_max[i] > 0 && isinf(lim.d_min[i]) && lim.d_min[i] < 0 && isinf(lim.d_max[i]) &&
              lim.d_max[i] > 0 && m.mech->gear[i] == 1 && m.mech->lead[i] == 0;
      tau[i] = cur[i] = 7;
    }
    TU_TRUE(none, "a model without drive keys: every limit none, gear 1, no lead");
    TU_TRUE(!prru_model_has_lead(&m) && prru_model_motor_units(&m, f, tau, cur) == PRRU_EINPUT && tau[0] == 7 &&
                cur[0] == 7,
            "motor units without a lead: PRRU_EINPUT, outputs untouched");
    prru_model_free(&m);
  }
  prru_model_default(&m);
  prru_model_limits(&m, &lim);
  TU_TRUE(isinf(lim.force_max[0]) && isinf(lim.d_min[m.mech->nact - 1]) && lim.d_min[m.mech->nact - 1] < 0,
          "the build's paper model (generated descriptor): no limits");
}

static int by_name(const struct dirent **a, const struct dirent **b) { return strcmp((*a)->d_name, (*b)->d_name); }
static int json_file(const struct dirent *e)
{
  const size_t n = strlen(e->d_name);
  return n > 5 && strcmp(e->d_name + n - 5, ".json") == 0;
}

static void check_dir(const char *dir, int *loaded, int *other, int *specialised, int reactions)
{
  struct dirent **list;
  const int n = scandir(dir, &list, json_file, by_name);
  char what[600];
  snprintf(what, sizeof what, "%s holds model files", dir);
  TU_TRUE(n > 0, what);
  for (int i = 0; i < n; i++) {
    char path[2400];
    snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
    check_file(path, loaded, other, specialised, reactions);
    free(list[i]);
  }
  if (n > 0) free(list);
}

/* test_model_load FILE...: only the given files (tests/test_random_loaded.sh
 * passes random valid models of the build's topology), each of which must
 * load, evaluate on the parameter kernels and pass every check above,
 * reactions and the energy balance included. */
static int check_given(int n, char **files)
{
  int loaded = 0, other = 0, specialised = 0;
  for (int i = 0; i < n; i++) {
    const int before = tu_failures, energy_before = energy_checked, power_before = power_checked;
    check_file(files[i], &loaded, &other, &specialised, 1);
    char what[600];
    snprintf(what, sizeof what, "%s: the work-energy balance checked", files[i]);
    TU_TRUE(energy_checked == energy_before + 1, what);
    snprintf(what, sizeof what, "%s: the work-energy balance with prru_power checked", files[i]);
    TU_TRUE(power_checked == power_before + 1, what);
    if (tu_failures != before) printf("FAILED: %s\n", files[i]);
  }
  printf("%d of them with another number of limbs than the build's model\n", other);
  TU_TRUE(loaded == n && specialised == 0, "every file loaded, on the parameter kernels");
  prru_ref_free(W);
  return tu_finish("test_model_load");
}

int main(int argc, char **argv)
{
  const char *src = getenv("PRRU_SOURCE_DIR"), *built = getenv("PRRU_MODEL");
  W = prru_ref_alloc();
  tu_rng_state = 20261126;
  if (argc > 1) return check_given(argc - 1, argv + 1);
  if (!TU_TRUE(src && built, "PRRU_SOURCE_DIR and PRRU_MODEL set (ctest sets them)")) return tu_finish("test_model_load");
  int loaded = 0, other = 0, specialised = 0;
  char dir[2048];
  check_names();
  check_layout(built);
  check_file(built, &loaded, &other, &specialised, 1);
  TU_TRUE(specialised == 1, "the build's own model file: specialised kernels");
  snprintf(dir, sizeof dir, "%s/models", src);
  check_dir(dir, &loaded, &other, &specialised, 1);
  /* The corpus's reactions are not compared: test_reactions' bound
   * K u kappa(M_s) presumes that the dense reference's own solve (Q^T
   * Phi^-1 Q) is conditioned like M, which fails for its deliberately
   * extreme files (a 1e6 kg platform with gram-scale moments of inertia:
   * 1e11 u kappa; a planar body on the triangle inequality's bound: 1.6e3). */
  snprintf(dir, sizeof dir, "%s/tests/models/conformance/valid", src);
  printf("conformance corpus: forward and inverse dynamics against the reference (reactions not compared)\n");
  check_dir(dir, &loaded, &other, &specialised, 0);
  printf("%d files loaded (%d with the build's numbers: specialised), %d of the other topology\n", loaded,
         specialised, other);
  /* models/ and the corpus hold 3-limb files of other numbers than any
   * build's and 4-limb ones (4prru.json, two in the corpus): whatever
   * the build's model, files of both topologies go through the parameter
   * kernels. */
  TU_TRUE(loaded - specialised >= 4 && other >= 1, "files of both topologies evaluated by the parameter kernels");

  /* Refusals: an unreadable path, a file the generator refuses. */
  prru_model m;
  prru_model_default(&m);
  char msg[1024];
  TU_TRUE(prru_model_use_parameter_kernels(&m) == PRRU_EINPUT && m.kernel_params == NULL &&
              strcmp(m.kernels->path, "specialised") == 0,
          "the built-in model has no parameter set: switching it is refused, the model untouched");
  TU_TRUE(prru_model_load(&m, "/nonexistent/model.json", msg, sizeof msg) == PRRU_EIO &&
              strstr(msg, "/nonexistent/model.json") && m.own == NULL,
          "a missing file: PRRU_EIO naming it, the model untouched");
  snprintf(dir, sizeof dir, "%s/tests/models/conformance/invalid", src);
  struct dirent **list;
  const int n = scandir(dir, &list, json_file, by_name);
  int refused = 0;
  for (int i = 0; i < n; i++) {
    char path[2400];
    snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
    refused += prru_model_load(&m, path, msg, sizeof msg) == PRRU_EPARSE && m.own == NULL && strstr(msg, path);
    free(list[i]);
  }
  if (n > 0) free(list);
  printf("%d of %d invalid files refused with their name\n", refused, n);
  TU_TRUE(n > 20 && refused == n, "every invalid file refused (PRRU_EPARSE, named, model untouched)");
  check_drives(src);
  prru_ref_free(W);
  return tu_finish("test_model_load");
}
