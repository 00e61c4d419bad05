/* The trust criterion at the workspace boundary (prru_model.mass_rcond_min):
 * along seeded random rays from the home pose to the edge of reach, every
 * state is either refused (PRRU_ESINGULAR or PRRU_EUNREACHABLE, never a
 * finite number with status PRRU_OK) or its forward dynamics agrees with the
 * GSL reference and round-trips through inverse dynamics, ID(FD(fd)) = fd,
 * within bounds derived from the state's own scales and conditioning:
 *
 *   FD:  |qdd - qdd_ref| <= K u (kappa_1(M) |qdd| + |M^-1|_1 S)
 *   ID:  |ID(FD(fd)) - fd_r| <= K u |J_d^+|_1 (|M|_1 |qdd| + S)
 *
 * u = DBL_EPSILON; S = |h| + |G| + |J_d^T| |fd| + |J_P^T| |(fp, mp)| +
 * |passive| (infinity norms), the size of the terms whose sum is b;
 * fd_r is fd less its preload (fd . n) n with four actuators (inverse
 * dynamics returns the preload-free solution). M's and b's entries carry
 * a few ulp of their terms each; the solve multiplies the first by
 * kappa(M) and the second by |M^-1|; inverse dynamics maps both through
 * J_d^+. K = 256 covers the few hundred roundings of two kernels (or
 * kernel and reference) per output (measured on the paper model: at most
 * 48 for FD and 11 for the round trip, at every distance from the edge).
 * Without the criterion the same walk gave qdd of the wrong sign at
 * rcond(M_s) = 5e-13 with status OK. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "testref.h"
#include "testsim.h"

static prru_model model;
static prru_data data;
static prru_ref_params P;
static prru_ref_ws *W;

#define K 256.0

/* S: the size of the terms whose sum is b (see the header). */
static double terms_scale(const double q[3], const double qd[3], const prru_loads *l,
                          const double h[3], const double G[3])
{
  double act[PRRU_NACT], Jd[PRRU_NACT * 3], JP[18], Qp[3], s[3] = {0, 0, 0};
  prru_ik_jd(q, act, Jd);
  prru_platform_jacobian(q, JP);
  prru_passive(q, qd, Qp);
  const double w[6] = {l->mp[0], l->mp[1], l->mp[2], l->fp[0], l->fp[1], l->fp[2]};
  for (int j = 0; j < 3; j++) {
    for (int i = 0; i < PRRU_NACT; i++) s[j] += fabs(Jd[3 * i + j] * l->fd[i]);
    for (int i = 0; i < 6; i++) s[j] += fabs(JP[3 * i + j] * w[i]);
  }
  return tu_norm_inf(h, 3) + tu_norm_inf(G, 3) + tu_norm_inf(s, 3) + tu_norm_inf(Qp, 3);
}

static int refused(int st) { return st == PRRU_ESINGULAR || st == PRRU_EUNREACHABLE; }

/* One state: refused, or the two bounds of the header hold. Counts the
 * states accepted in *accepted. */
static void check_state(const double q[3], const double qd[3], const prru_loads *l,
                        double *worst_fd, double *worst_rt, int *accepted, const char *where)
{
  double qdd[3], qdd_ref[3], fd[PRRU_NACT];
  int st = prru_forward_dynamics(&model, &data, q, qd, l, qdd);
  if (st != PRRU_OK) {
    char what[320];
    snprintf(what, sizeof what, "%s: forward dynamics refused (status %d), not failed otherwise",
             where, st);
    TU_TRUE(refused(st), what);
    /* The reactions stand on the forward dynamics: refused alike. */
    double lambda[PRRU_NLAMBDA];
    TU_TRUE(prru_reactions(&model, &data, q, qd, l, lambda) == st, "reactions refused alike");
    return;
  }
  (*accepted)++;
  double M[9], Minv[9], h[3], G[3];
  prru_dynamics(q, qd, M, h, G);
  const double S = terms_scale(q, qd, l, h, G);
  /* M^-1 by the adjugate: M is well conditioned enough here (the
   * criterion holds) for its own rounding not to matter to the bound. */
  tu_inverse3(M, Minv);
  const double nM = tu_norm1(M, 3, 3), nMi = tu_norm1(Minv, 3, 3), nq = tu_norm_inf(qdd, 3);
  const double u = DBL_EPSILON;

  TU_TRUE(prru_ref_forward_dynamics(&P, W, q, qd, l->fd, l->fp, l->mp, qdd_ref) == GSL_SUCCESS,
          "the reference solves where the kernel does");
  double e = 0;
  for (int i = 0; i < 3; i++) e = fmax(e, fabs(qdd[i] - qdd_ref[i]));
  const double bfd = u * (nM * nMi * nq + nMi * S);
  if (e / bfd > *worst_fd) *worst_fd = e / bfd;
  char what[320];
  snprintf(what, sizeof what, "%s: |qdd - qdd_ref| / (u (kappa |qdd| + |M^-1| S))", where);
  tu_check(e <= K * bfd, what, e / bfd, K);

  st = prru_inverse_dynamics(&model, &data, q, qd, qdd, l, fd);
  if (st != PRRU_OK) { /* its own half of the criterion (prru_stretch) */
    snprintf(what, sizeof what, "%s: inverse dynamics refused (status %d), not failed", where, st);
    TU_TRUE(st == PRRU_ESINGULAR, what);
    return;
  }
  double fr[PRRU_NACT];
  memcpy(fr, l->fd, sizeof fr);
  if (PRRU_NPRELOAD > 0) {
    double n[PRRU_NACT], t = 0;
    TU_TRUE(prru_actuator_null(&model, &data, q, n) == PRRU_OK, "actuator null vector");
    for (int i = 0; i < PRRU_NACT; i++) t += fr[i] * n[i];
    for (int i = 0; i < PRRU_NACT; i++) fr[i] -= t * n[i];
  }
  const double nJ = tu_norm1(data.Jdpinv, 3, PRRU_NACT);
  double r = 0;
  for (int i = 0; i < PRRU_NACT; i++) r = fmax(r, fabs(fd[i] - fr[i]));
  const double brt = u * nJ * (nM * nq + S);
  if (r / brt > *worst_rt) *worst_rt = r / brt;
  snprintf(what, sizeof what, "%s: |ID(FD(fd)) - fd| / (u |J_d^+| (|M| |qdd| + S))", where);
  tu_check(r <= K * brt, what, r / brt, K);
}

int main(void)
{
  prru_model_default(&model);
  prru_ref_params_default(&P);
  W = prru_ref_alloc();
  double worst_fd = 0, worst_rt = 0;
  int accepted = 0, states = 0, rays = 0;
  for (int ray = 0; ray < 48; ray++) {
    const double q0[3] = {0, 0, tu_uniform(-1.0, -0.5)};
    double dir[3] = {tu_uniform(-1, 1), tu_uniform(-1, 1), 0};
    double qd[3];
    prru_loads l;
    for (int i = 0; i < 3; i++) qd[i] = tu_uniform(-1, 1);
    ts_random_loads(&l);
    /* The edge of reach along the ray (reachability does not depend on
     * q3): bracket, then bisect to the last double. */
    double lo = 0, hi = 0.05, q[3];
    for (;;) {
      for (int i = 0; i < 3; i++) q[i] = q0[i] + hi * dir[i];
      if (prru_check_reachable(&model, &data, q) != PRRU_OK || hi > 8) break;
      lo = hi, hi *= 1.5;
    }
    if (hi > 8) continue; /* a ray that never leaves (cannot happen for q1, q2 in a box) */
    for (int it = 0; it < 200 && hi - lo > 0; it++) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      for (int i = 0; i < 3; i++) q[i] = q0[i] + mid * dir[i];
      if (prru_check_reachable(&model, &data, q) == PRRU_OK) lo = mid; else hi = mid;
    }
    rays++;
    char where[160];
    for (double gap = 0.3; gap > 1e-17; gap /= 3) {
      for (int i = 0; i < 3; i++) q[i] = q0[i] + lo * (1 - gap) * dir[i];
      snprintf(where, sizeof where, "ray %d, gap %.1e", ray, gap);
      const int before = accepted;
      check_state(q, qd, &l, &worst_fd, &worst_rt, &accepted, where);
      states++;
      /* Well inside (rcond(M_s) of order gap / 10, far above the
       * tolerance) every state is accepted. */
      if (gap >= 0.01) TU_TRUE(accepted == before + 1, "well inside the edge: accepted");
    }
    /* At the edge itself every dynamics call is refused. */
    for (int i = 0; i < 3; i++) q[i] = q0[i] + lo * dir[i];
    double qdd[3], fd[PRRU_NACT];
    snprintf(where, sizeof where, "ray %d: the last reachable pose is refused", ray);
    TU_TRUE(refused(prru_forward_dynamics(&model, &data, q, qd, &l, qdd)), where);
    const double zero[3] = {0, 0, 0};
    TU_TRUE(refused(prru_inverse_dynamics(&model, &data, q, qd, zero, &l, fd)), where);
  }
  printf("%d rays, %d states, %d accepted; worst FD error %.3g and round trip %.3g of their "
         "bounds' u-multiples (K = %g)\n",
         rays, states, accepted, worst_fd, worst_rt, K);
  TU_TRUE(rays >= 40, "most rays reach an edge");
  prru_ref_free(W);
  return tu_finish("test_trust");
}
