/* The closed-form derivatives of the dynamics (prru_linearize.h: the
 * generated prru_eom_solve_derivs and prru_inverse_derivs) against an
 * evaluation that shares no code with them: Richardson-extrapolated
 * central differences of the hand-written GSL reference (reference/,
 * prru_ref_forward_dynamics and prru_ref_inverse_dynamics), for the
 * build's model at a state at rest and at random states with velocities
 * and loads. With four actuators the minimum-norm fd's derivatives, and
 * with a fixed preload t those of fd + t n (n by GSL's QR of the
 * reference's J_d, here). Then identities that hold exactly: the inverse
 * of forward dynamics (dqdd/dfd dfd/dqdd = I, dqdd/dq + dqdd/dfd dfd/dq =
 * 0, the same for qd; with three actuators also the other order), J_d^T
 * dfd/dqdd = M, with four n . fd = t and n^T dfd/dqd = n^T dfd/dqdd = 0,
 * A and B's structure, and the zero-order hold (Ad, Bd) against the
 * exponential's Taylor series summed here.
 *
 * The bound, relative to each matrix's largest entry (tu_relerr):
 * 1e-9. The two sides' errors:
 *   - the reference's differences: central differences at h, h/2, h/4,
 *     h/8 extrapolated three times (Richardson), truncation O(h^8), with
 *     h = 0.005 m^2 rad for the angles (m the state's margin from the
 *     workspace boundary, ref_margin, at least MARGIN here: the functions
 *     vary on a length that shrinks like m^2 near it; 0.02 m^2 and more
 *     left truncation errors of 1e-9 and above on the paper model) and L
 *     times that for q3; the rounding of the reference (a few ulps of its
 *     terms) divided by h/8 and amplified ~3 by the extrapolation. The
 *     tableau's last correction (the error of the previous, less
 *     accurate extrapolant, so an over-estimate) is below 1e-9 of the
 *     block where the tableau converged (measured on the paper model: 4e-10
 *     at worst, while the two sides agree to 1.2e-11 at worst, which an
 *     error of either would not allow); at least 95 % of a model's blocks
 *     must be so resolved (every one on the committed models), the others
 *     are held to 1e-9 plus 4x that estimate (compare);
 *   - the kernel's: qdd's rounding (2e-10 relative at the trust limit
 *     mass_rcond_min = 1e-6, prru.h; ~1e-14 at these margins) times the
 *     few extra operations of a derivative: ~1e-13.
 * So 1e-9 leaves two orders of magnitude over the sum while a wrong term
 * (of order the block) fails by nine. The identities hold to rounding:
 * 1e-11 of the terms' magnitudes (products of two derivative blocks, each
 * accurate to ~1e-13 relative). */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "prru.h"
#include "prru_linearize.h"
#include "prru_model_file.h"
#include "prru_mechanism.h"
#include "prru_ref.h"
#include "testref.h"
#include "testutil.h"

#define PI 3.14159265358979323846
#define NA PRRU_NACT
#define LEVELS 4
#define MARGIN 0.3
#define BOUND 1e-9
#define REF_ACCURACY 1e-9
#define IDENTITY_BOUND 1e-11

static prru_ref_params P;
static prru_ref_ws *W;
static prru_model model;
static prru_data data;
static double length; /* the machine's scale (m): the mean link length */

typedef struct {
  double q[3], qd[3], fd[NA], fp[3], mp[3], qdd[3];
} state;

enum { V_Q, V_QD, V_FD, V_FP, V_MP, V_QDD };

static double *slot(state *s, int v)
{
  double *const slots[] = {s->q, s->qd, s->fd, s->fp, s->mp, s->qdd};
  return slots[v];
}

/* The preload t the reference's inverse dynamics adds along n (four
 * actuators; 0 with three). */
static double ref_preload;

/* n, the unit vector spanning null(J_d^T) with n_NACT > 0, from the
 * reference's J_d by GSL's Householder QR (the last column of Q): none of
 * the runtime's minors. */
static int ref_null(const double q[3], double n[NA])
{
  double jd[NA * 3], qm[NA * NA], rm[NA * 3], tau[3];
  if (prru_ref_jd(&P, q, jd)) return 1;
  gsl_matrix_view a = gsl_matrix_view_array(jd, NA, 3), qv = gsl_matrix_view_array(qm, NA, NA),
                  rv = gsl_matrix_view_array(rm, NA, 3);
  gsl_vector_view t = gsl_vector_view_array(tau, 3);
  if (gsl_linalg_QR_decomp(&a.matrix, &t.vector) ||
      gsl_linalg_QR_unpack(&a.matrix, &t.vector, &qv.matrix, &rv.matrix))
    return 1;
  const double sg = qm[NA * NA - 1] < 0 ? -1 : 1;
  for (int i = 0; i < NA; i++) n[i] = sg * qm[NA * i + NA - 1];
  return 0;
}

/* Forward dynamics' qdd (3), or inverse dynamics' fd (NA) plus the
 * preload's ref_preload n, by the reference. */
static int ref_eval(int inverse, const state *s, double *out)
{
  if (!inverse) return prru_ref_forward_dynamics(&P, W, s->q, s->qd, s->fd, s->fp, s->mp, out);
  if (prru_ref_inverse_dynamics(&P, W, s->q, s->qd, s->qdd, s->fp, s->mp, out)) return 1;
  if (ref_preload != 0) {
    double n[NA];
    if (NA == 3 || ref_null(s->q, n)) return 1;
    for (int i = 0; i < NA; i++) out[i] += ref_preload * n[i];
  }
  return 0;
}

/* d out / d (variable v, component k) by Richardson extrapolation of
 * central differences with steps h0 / 2^j; *est: the last correction's
 * size (its error estimate). */
static int richardson(int inverse, const state *s, int v, int k, double h0, int nout,
                      double *deriv, double *est)
{
  double T[LEVELS][LEVELS][NA];
  for (int lev = 0; lev < LEVELS; lev++) {
    const double h = ldexp(h0, -lev);
    state up = *s, dn = *s;
    slot(&up, v)[k] += h;
    slot(&dn, v)[k] -= h;
    double fu[NA], fdn[NA];
    if (ref_eval(inverse, &up, fu) || ref_eval(inverse, &dn, fdn)) return 1;
    for (int i = 0; i < nout; i++) T[lev][0][i] = (fu[i] - fdn[i]) / (2 * h);
    for (int j = 1; j <= lev; j++) {
      const double f = ldexp(1.0, 2 * j) - 1;
      for (int i = 0; i < nout; i++)
        T[lev][j][i] = T[lev][j - 1][i] + (T[lev][j - 1][i] - T[lev - 1][j - 1][i]) / f;
    }
  }
  *est = 0;
  for (int i = 0; i < nout; i++) {
    deriv[i] = T[LEVELS - 1][LEVELS - 1][i];
    *est = fmax(*est, fabs(deriv[i] - T[LEVELS - 2][LEVELS - 2][i]));
  }
  return 0;
}

/* The reference's block d out / d v (nout x n, row-major); *est relative
 * to its largest entry. */
static double ref_hmin; /* the smallest step of the last ref_block */
static int ref_block(int inverse, const state *s, int v, int n, double h0, double *block,
                     double *est)
{
  const int nout = inverse ? NA : 3;
  double big = 1e-300, e = 0;
  ref_hmin = INFINITY;
  for (int k = 0; k < n; k++) {
    double col[NA], ek;
    const double h = (v == V_Q || v == V_QD || v == V_QDD) && k == 2 ? h0 * length : h0;
    if (richardson(inverse, s, v, k, h, nout, col, &ek)) return 1;
    /* Where the tableau has not converged (a function that bends on a
     * shorter length than the step assumes), the step a quarter, twice at
     * most, keeping the better column. */
    for (int shrink = 1; shrink <= 2 && ek > REF_ACCURACY * tu_norm_inf(col, nout); shrink++) {
      double c2[NA], e2;
      if (richardson(inverse, s, v, k, ldexp(h, -2 * shrink), nout, c2, &e2)) return 1;
      if (e2 < ek) memcpy(col, c2, sizeof col), ek = e2, ref_hmin = fmin(ref_hmin, ldexp(h, -2 * shrink));
    }
    ref_hmin = fmin(ref_hmin, h);
    e = fmax(e, ek);
    for (int i = 0; i < nout; i++) {
      block[n * i + k] = col[i];
      big = fmax(big, fabs(col[i]));
    }
  }
  *est = e / big;
  return 0;
}

static double worst[2][3 + 3], worst_est, worst_identity;
static int blocks_total, blocks_unresolved; /* of the model being checked */
static const char *const fwd_names[] = {"dqdd_dq", "dqdd_dqd", "dqdd_dfd", "dqdd_dfp", "dqdd_dmp"};
/* The last three: with a preload (four actuators). */
static const char *const inv_names[] = {"dfd_dq", "dfd_dqd", "dfd_dqdd",
                                        "dfd_dq (t)", "dfd_dqd (t)", "dfd_dqdd (t)"};

static void compare(int inverse, int b, const char *name, const double *kernel, const double *ref,
                    int n, double est)
{
  const double e = tu_relerr(kernel, ref, n, 1e-300);
  /* Where the reference resolves the block (est <= REF_ACCURACY) the two
   * agree within BOUND; where it does not (sharp Coulomb friction on
   * random models: dfd/dqd to 1.0e-9, the rates' steps limited by the
   * tanh's width below and by rounding above), within BOUND plus its
   * error, 4 est (check_boundary's rule), and the block is counted. */
  const double bound = est <= REF_ACCURACY ? BOUND : BOUND + 4 * est;
  char what[96];
  snprintf(what, sizeof what, "%s against the reference's Richardson differences", name);
  tu_check(e <= bound, what, e, bound);
  blocks_total++;
  blocks_unresolved += est > REF_ACCURACY;
  worst[inverse][b] = fmax(worst[inverse][b], e);
  worst_est = fmax(worst_est, est);
}

/* Steps: angles h = 0.005 m^2 (m the margin), q3 that times L; the rates
 * 0.05 (rad/s, L m/s); with Coulomb friction both shrink with the width
 * of its tanh, the rates' to 0.2 v_s / L (on random models a quarter of
 * that lost to rounding, the Coulomb terms f / v_s being large, and 1e-9
 * was exceeded; 0.2 left 2.6e-10 at worst over 20 of them); the loads
 * enter linearly (1 N, 1 N m). */
static double step_for(int v, double m)
{
  /* tanh(dd / v_s) bends on dd ~ v_s: in qd on v_s / L, in q (dd = J_d qd)
   * on v_s / (L |qd|), |qd| <= 1 here. */
  double coulomb = 1.0;
  for (int i = 0; i < NA; i++)
    if (P.coulomb[i] != 0) coulomb = fmin(coulomb, P.coulomb_velocity / length);
  if (v == V_Q) return 0.005 * m * m * fmin(1.0, 10 * coulomb);
  if (v == V_QD) return fmin(0.05, 0.2 * coulomb);
  return 1.0;
}

static void check_forward(state *s, double m)
{
  prru_loads l;
  memcpy(l.fd, s->fd, PRRU_NACT * sizeof(double)), memcpy(l.fp, s->fp, sizeof l.fp), memcpy(l.mp, s->mp, sizeof l.mp);
  prru_linearization o;
  const int st = prru_linearize(&model, &data, s->q, s->qd, &l, 0.0, &o);
  if (!TU_TRUE(st == PRRU_OK, "prru_linearize at a trusted state")) return;
  const double *blocks[] = {o.dqdd_dq, o.dqdd_dqd, o.dqdd_dfd, o.dqdd_dfp, o.dqdd_dmp};
  const int vars[] = {V_Q, V_QD, V_FD, V_FP, V_MP}, widths[] = {3, 3, NA, 3, 3};
  for (int b = 0; b < 5; b++) {
    double ref[3 * NA], est;
    if (!TU_TRUE(!ref_block(0, s, vars[b], widths[b], step_for(vars[b], m), ref, &est),
                 "reference forward dynamics near the state"))
      return;
    compare(0, b, fwd_names[b], blocks[b], ref, 3 * widths[b], est);
  }
  /* A = [0 I; Dq Dqd], B = [0; Dfd], exactly. */
  int structure = 1;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      structure &= o.A[6 * i + k] == 0 && o.A[6 * i + 3 + k] == (i == k);
      structure &= o.A[6 * (3 + i) + k] == o.dqdd_dq[3 * i + k];
      structure &= o.A[6 * (3 + i) + 3 + k] == o.dqdd_dqd[3 * i + k];
    }
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < NA; k++)
      structure &= o.B[NA * i + k] == 0 && o.B[NA * (3 + i) + k] == o.dqdd_dfd[NA * i + k];
  TU_TRUE(structure, "A = [0 I; dqdd_dq dqdd_dqd], B = [0; dqdd_dfd]");
  memcpy(s->qdd, o.qdd, sizeof o.qdd);
}

/* max |add + sign X Y| (X r x c, Y c x k; add NULL: -I, r = k) relative
 * to max (|add| + |X| |Y|)_ij. */
static double identity_error(const double *X, const double *Y, const double *add, int sign, int r,
                             int c, int k)
{
  double e = 0, scale = 1e-300;
  for (int i = 0; i < r; i++)
    for (int j = 0; j < k; j++) {
      double s = add ? add[k * i + j] : -(i == j), t = add ? fabs(add[k * i + j]) : 1;
      for (int l = 0; l < c; l++) {
        s += sign * X[c * i + l] * Y[k * l + j];
        t += fabs(X[c * i + l] * Y[k * l + j]);
      }
      e = fmax(e, fabs(s));
      scale = fmax(scale, t);
    }
  return e / scale;
}

static void check_identity(double e, const char *what)
{
  tu_check(e <= IDENTITY_BOUND, what, e, IDENTITY_BOUND);
  worst_identity = fmax(worst_identity, e);
}

/* Inverse dynamics' derivatives at qdd = FD(q, qd, fd) (s->qdd) with the
 * preload t held fixed (four actuators; t = 0 is
 * prru_inverse_dynamics_derivs), against the reference, and the
 * identities of FD(ID) = qdd (and with three actuators ID(FD) = fd). */
static void check_inverse(state *s, double m, double t)
{
  prru_loads l;
  memcpy(l.fp, s->fp, sizeof l.fp), memcpy(l.mp, s->mp, sizeof l.mp);
  double fd[NA], Dq[3 * NA], Dqd[3 * NA], Dqdd[3 * NA], f0[NA];
  int st = t == 0 ? prru_inverse_dynamics_derivs(&model, &data, s->q, s->qd, s->qdd, &l, fd, Dq, Dqd, Dqdd)
                  : prru_inverse_dynamics_preload_derivs(&model, &data, s->q, s->qd, s->qdd, &l, t, fd,
                                                         Dq, Dqd, Dqdd);
  if (!TU_TRUE(st == PRRU_OK, "prru_inverse_dynamics_derivs at a trusted state")) return;
  /* The same fd as inverse dynamics, to the bit. */
  TU_TRUE(prru_inverse_dynamics_preload(&model, &data, s->q, s->qd, s->qdd, &l, t, f0) == PRRU_OK &&
              !memcmp(f0, fd, sizeof fd),
          "inverse derivatives' fd = prru_inverse_dynamics_preload's");
  /* Relative to the forces' size, at least the platform's weight. */
  const double floor = prru_mech.total_mass * 9.81;
  ref_preload = t;
#if NA == 3
  const double e_id = tu_relerr(fd, s->fd, NA, floor);
  tu_check(e_id <= 1e-11, "ID(FD(fd)) = fd", e_id, 1e-11);
#else
  /* The reference's minimum-norm forces plus t n: the same solution by
   * other arithmetic (GSL's QR of J_d^T J_d's system, J_d to ~1e-15 with
   * rcond >= ~1e-3 at these margins): 1e-11 as above. */
  double fr[NA], n[NA];
  if (!TU_TRUE(!ref_eval(1, s, fr) && !ref_null(s->q, n), "reference inverse dynamics")) return;
  const double e_id = tu_relerr(fd, fr, NA, floor);
  tu_check(e_id <= 1e-11, "fd = the reference's minimum-norm fd + t n", e_id, 1e-11);
  /* fd's component along n is the preload's: n . fd = t, to the rounding
   * of the terms |n_i fd_i|. */
  double nf = -t, nfs = fabs(t);
  for (int i = 0; i < NA; i++) nf += n[i] * fd[i], nfs += fabs(n[i] * fd[i]);
  check_identity(fabs(nf) / fmax(nfs, floor), "n . fd = t");
  /* And constant in qd and qdd: n^T dfd/dqd = n^T dfd/dqdd = 0. */
  double nD[6] = {0}, nDs = 1e-300;
  for (int k = 0; k < 3; k++)
    for (int i = 0; i < NA; i++) {
      nD[k] += n[i] * Dqd[3 * i + k], nD[3 + k] += n[i] * Dqdd[3 * i + k];
      nDs = fmax(nDs, fmax(fabs(n[i] * Dqd[3 * i + k]), fabs(n[i] * Dqdd[3 * i + k])));
    }
  check_identity(tu_norm_inf(nD, 6) / nDs, "n^T dfd/dqd = n^T dfd/dqdd = 0");
#endif
  const double *blocks[] = {Dq, Dqd, Dqdd};
  const int vars[] = {V_Q, V_QD, V_QDD}, b0 = t == 0 ? 0 : 3;
  for (int b = 0; b < 3; b++) {
    double ref[3 * NA], est;
    /* fd is J_d^+T (M qdd - J_T,O'^T fp - J_R,P^T mp) + t n, none of it
     * depending on qd, plus J_d^+T (h - G - passive): dfd/dqd is that of
     * the reference at qdd = fp = mp = 0 and t = 0, whose differences
     * round on the scale of G and h alone (with the large random forces
     * in, their rounding, ~eps |fd| / h, reached 2e-9 of a small dfd/dqd
     * on random four-limb models). */
    state z = *s;
    if (vars[b] == V_QD) {
      memset(z.qdd, 0, sizeof z.qdd), memset(z.fp, 0, sizeof z.fp), memset(z.mp, 0, sizeof z.mp);
      ref_preload = 0;
    }
    if (!TU_TRUE(!ref_block(1, &z, vars[b], 3, step_for(vars[b], m), ref, &est),
                 "reference inverse dynamics near the state"))
      return;
    ref_preload = t;
    compare(1, b0 + b, inv_names[b0 + b], blocks[b], ref, 3 * NA, est);
  }
  ref_preload = 0;
  /* J_d^T dfd/dqdd = M (J_d^T fd = M qdd - b), J_d and M the reference's. */
  double jd[3 * NA], jdt[3 * NA], M[9];
  if (!TU_TRUE(!prru_ref_jd(&P, s->q, jd) && !prru_ref_mass(&P, W, s->q, M), "reference J_d, M"))
    return;
  for (int i = 0; i < NA; i++)
    for (int k = 0; k < 3; k++) jdt[NA * k + i] = jd[3 * i + k];
  check_identity(identity_error(jdt, Dqdd, M, -1, 3, NA, 3), "J_d^T dfd/dqdd = M");
  memcpy(l.fd, fd, PRRU_NACT * sizeof(double));
  prru_linearization o;
  if (!TU_TRUE(prru_linearize(&model, &data, s->q, s->qd, &l, 0.0, &o) == PRRU_OK, "linearize"))
    return;
  /* qdd(q, qd, fd(q, qd, qdd)) = qdd: dqdd/dfd dfd/dqdd = I, and
   * dqdd/dq + dqdd/dfd dfd/dq = 0 (the same for qd). */
  check_identity(identity_error(o.dqdd_dfd, Dqdd, NULL, 1, 3, NA, 3), "dqdd/dfd dfd/dqdd = I");
  check_identity(identity_error(o.dqdd_dfd, Dq, o.dqdd_dq, 1, 3, NA, 3),
                 "dqdd/dq + dqdd/dfd dfd/dq = 0");
  check_identity(identity_error(o.dqdd_dfd, Dqd, o.dqdd_dqd, 1, 3, NA, 3),
                 "dqdd/dqd + dqdd/dfd dfd/dqd = 0");
#if NA == 3
  /* fd(q, qd, qdd(q, qd, fd)) = fd: dfd/dqdd dqdd/dfd = I, and
   * dfd/dq + dfd/dqdd dqdd/dq = 0 (the same for qd). */
  check_identity(identity_error(Dqdd, o.dqdd_dfd, NULL, 1, 3, 3, 3), "dfd/dqdd dqdd/dfd = I");
  check_identity(identity_error(Dqdd, o.dqdd_dq, Dq, 1, 3, 3, 3), "dfd/dq + dfd/dqdd dqdd/dq = 0");
  check_identity(identity_error(Dqdd, o.dqdd_dqd, Dqd, 1, 3, 3, 3),
                 "dfd/dqd + dfd/dqdd dqdd/dqd = 0");
#endif
}

/* [Ad Bd; 0 I] = exp(Z), Z = [A B; 0 0] dt, against its Taylor series
 * summed here: of Z / 2^k with |Z / 2^k|_inf <= 1/2 (30 terms leave
 * 2^-30 / 30! ~ 1e-42), then squared k times. */
static void check_hold(const state *s)
{
  enum { S = 6 + NA };
  prru_loads l;
  memcpy(l.fd, s->fd, PRRU_NACT * sizeof(double)), memcpy(l.fp, s->fp, sizeof l.fp), memcpy(l.mp, s->mp, sizeof l.mp);
  const double dts[] = {1e-3, 2e-2, 0.5};
  for (int t = 0; t < 3; t++) {
    prru_linearization o;
    if (!TU_TRUE(prru_linearize(&model, &data, s->q, s->qd, &l, dts[t], &o) == PRRU_OK,
                 "linearize with dt"))
      return;
    double Z[S * S] = {0}, term[S * S] = {0}, sum[S * S] = {0}, next[S * S], zn = 0;
    for (int i = 0; i < 6; i++) {
      for (int k = 0; k < 6; k++) Z[S * i + k] = o.A[6 * i + k] * dts[t];
      for (int k = 0; k < NA; k++) Z[S * i + 6 + k] = o.B[NA * i + k] * dts[t];
    }
    for (int i = 0; i < S; i++) {
      double r = 0;
      for (int k = 0; k < S; k++) r += fabs(Z[S * i + k]);
      zn = fmax(zn, r);
    }
    int squarings = 0, sq0;
    for (; zn > 0.5; zn /= 2) squarings++;
    sq0 = squarings;
    for (int i = 0; i < S * S; i++) Z[i] = ldexp(Z[i], -squarings);
    for (int i = 0; i < S; i++) term[S * i + i] = sum[S * i + i] = 1;
    for (int n = 1; n <= 30; n++) {
      for (int i = 0; i < S; i++)
        for (int j = 0; j < S; j++) {
          double x = 0;
          for (int k = 0; k < S; k++) x += term[S * i + k] * Z[S * k + j];
          next[S * i + j] = x / n;
        }
      memcpy(term, next, sizeof term);
      for (int i = 0; i < S * S; i++) sum[i] += term[i];
    }
    for (; squarings > 0; squarings--) {
      for (int i = 0; i < S; i++)
        for (int j = 0; j < S; j++) {
          double x = 0;
          for (int k = 0; k < S; k++) x += sum[S * i + k] * sum[S * k + j];
          next[S * i + j] = x;
        }
      memcpy(sum, next, sizeof sum);
    }
    double Ad[36], Bd[6 * NA];
    for (int i = 0; i < 6; i++) {
      for (int k = 0; k < 6; k++) Ad[6 * i + k] = sum[S * i + k];
      for (int k = 0; k < NA; k++) Bd[NA * i + k] = sum[S * i + 6 + k];
    }
    /* GSL_PREC_DOUBLE and the series: a few ulps of the exponential's
     * largest entry (Ad's, at least 1: Bd, of order B dt, is relative to
     * it too), the rounding of each squaring doubling it on either side
     * (measured 1e-15 without squaring, 4e-13 after ten): 1e-14 2^k. */
    const double tol = ldexp(1e-14, sq0), big = fmax(1.0, tu_norm_inf(Ad, 36));
    double e = tu_relerr(o.Ad, Ad, 36, big);
    tu_check(e <= tol, "Ad against the exponential's Taylor series", e, tol);
    e = tu_relerr(o.Bd, Bd, 6 * NA, big);
    tu_check(e <= tol, "Bd against the exponential's Taylor series", e, tol);
  }
}

static int trusted_state(state *s, double *m)
{
  prru_loads l;
  memcpy(l.fd, s->fd, PRRU_NACT * sizeof(double)), memcpy(l.fp, s->fp, sizeof l.fp), memcpy(l.mp, s->mp, sizeof l.mp);
  double qdd[3];
  *m = ref_margin(&P, s->q);
  return *m >= MARGIN && prru_forward_dynamics(&model, &data, s->q, s->qd, &l, qdd) == PRRU_OK;
}

static int random_state(state *s, double *m)
{
  for (long tries = 0; tries < 100000; tries++) {
    memset(s, 0, sizeof *s);
    s->q[0] = tu_uniform(-PI / 4, PI / 4);
    s->q[1] = tu_uniform(-PI / 4, PI / 4);
    s->q[2] = tu_uniform(-2 * length, 2 * length);
    for (int i = 0; i < 3; i++) {
      s->qd[i] = tu_uniform(-1, 1) * (i == 2 ? length : 1);
      s->fp[i] = tu_uniform(-30, 30);
      s->mp[i] = tu_uniform(-3, 3);
    }
    for (int i = 0; i < NA; i++) s->fd[i] = tu_uniform(-60, 60);
    if (trusted_state(s, m)) return 1;
  }
  return 0;
}

/* ---- Near the workspace boundary ----
 * As an upper link turns horizontal, M grows like 1/m^2 in one direction
 * (m: ref_margin) and the dynamics stop being trusted at prru_mass_rcond(M)
 * < mass_rcond_min (prru_forward_dynamics). Between MARGIN and that limit
 * the kernel is checked at states of margins spread log-uniformly down
 * to BOUNDARY_MIN, wherever forward dynamics is trusted. There the
 * reference's differences, not the kernel, limit the comparison: the
 * functions bend on a length ~m^2 (the steps shrink with it) while the
 * reference's own rounding grows with M's conditioning. So the bound is
 * the sum of the two sides' errors, each derived at the state:
 *   - the kernel's: BOUND, as away from the boundary (its rounding, u
 *     times the conditioning, stays below it: 2e-10 relative for qdd at
 *     the trust limit, prru.h);
 *   - the spread between that tableau and a second from half the step
 *     (the first's error where it is not yet asymptotic);
 *   - the reference's truncation and the part of its rounding that the
 *     noise below misses (rounding at the steps' own offsets, where the
 *     state's evaluation differs most): 4 est, est the tableau's last
 *     correction. With independent rounding per evaluation, est = |T33 -
 *     T22| is a sample of that rounding about as large as T33's own (rms
 *     weights 13.9 and 11.7 noise / h); the maximum over a block's
 *     columns and outputs has not been found below a third of the error
 *     (measured 1 / 2.5 at worst over the committed models);
 *   - the reference's rounding: noise (ref_noise, measured at the state)
 *     enters
 *     each difference at step h' as noise / h'; the extrapolated entry
 *     weighs the four levels h, h/2, h/4, h/8 so that its rounding is at
 *     most sum_j |w_j| 2^j noise / h = 13.5 noise / h (w: the tableau's
 *     weights, -3.5e-4, 0.030, -0.47, 1.44), doubled because noise is
 *     sampled rather than bounded: 27 noise / h, relative to the block's
 *     largest entry.
 * The bound grows with the conditioning through noise and est: to a few
 * 1e-6 at the trust limit on the committed models, so a wrong term (of
 * order the block) fails by five orders. Where sharp Coulomb friction
 * (a small coulomb_velocity: the steps in q shrink with it, step_for)
 * meets the boundary the reference resolves less (1e-3 seen on random
 * models); a bound that grew to the block's size would test nothing, so
 * at least half of the blocks must be resolved to BOUNDARY_CEILING, and
 * the count is printed. */
#define BOUNDARY_MIN 0.003
#define NOISE_TRIALS 8
#define BOUNDARY_CEILING 1e-5

/* The reference forward dynamics' rounding noise at s when variable v
 * moves, as it does in the differences of its block (the other inputs
 * stay, and so does their rounding): over NOISE_TRIALS random directions
 * d moving v, the largest |qdd(s + d) + qdd(s - d) - 2 qdd(s)| / 2. The
 * second difference cancels the outputs' first-order change (their true
 * dependence, huge near the boundary), so what is left is the rounding
 * of the three evaluations plus a curvature term of order d^2: for the
 * forces, on which qdd depends linearly, that term is 0 and d is as long
 * as the steps (up to h each way: the rounding the differences meet);
 * for q and qd, d moves each component by up to 4 ulps (angles and rates
 * of angles about 1, lengths about L where the input is 0) and the
 * curvature term is negligible. */
static double ref_noise(const state *s, int v, double h)
{
  double base[3], noise = 0;
  if (ref_eval(0, s, base)) return INFINITY;
  const int n = v == V_FD ? NA : 3;
  for (int t = 0; t < NOISE_TRIALS; t++) {
    state up = *s, dn = *s;
    for (int k = 0; k < n; k++) {
      const double x = slot(&up, v)[k];
      const double unit = (v == V_Q || v == V_QD) && k == 2 ? length : 1.0;
      const double dx = v == V_FD ? tu_uniform(-h, h) : tu_uniform(-4, 4) * DBL_EPSILON * fmax(fabs(x), unit);
      slot(&up, v)[k] = x + dx;
      slot(&dn, v)[k] = x - dx;
    }
    double fu[3], fdn[3];
    if (ref_eval(0, &up, fu) || ref_eval(0, &dn, fdn)) return INFINITY;
    for (int i = 0; i < 3; i++) noise = fmax(noise, fabs(fu[i] + fdn[i] - 2 * base[i]) / 2);
  }
  return noise;
}

/* A trusted state of margin within a factor 1.25 of target, with rates
 * and loads as random_state's; 0 when none is found. */
static int state_at_margin(state *s, double target, double *m)
{
  for (long tries = 0; tries < 2000000; tries++) {
    memset(s, 0, sizeof *s);
    s->q[0] = tu_uniform(-PI / 2, PI / 2);
    s->q[1] = tu_uniform(-PI / 2, PI / 2);
    s->q[2] = tu_uniform(-3 * length, 3 * length);
    const double mm = ref_margin(&P, s->q);
    if (mm < target / 1.25 || mm > target * 1.25) continue;
    for (int i = 0; i < 3; i++) {
      s->qd[i] = tu_uniform(-1, 1) * (i == 2 ? length : 1);
      s->fp[i] = tu_uniform(-30, 30);
      s->mp[i] = tu_uniform(-3, 3);
    }
    for (int i = 0; i < NA; i++) s->fd[i] = tu_uniform(-60, 60);
    prru_loads l;
    memcpy(l.fd, s->fd, PRRU_NACT * sizeof(double)), memcpy(l.fp, s->fp, sizeof l.fp), memcpy(l.mp, s->mp, sizeof l.mp);
    double qdd[3];
    if (prru_forward_dynamics(&model, &data, s->q, s->qd, &l, qdd) == PRRU_OK) {
      *m = mm;
      return 1;
    }
  }
  return 0;
}

static void check_boundary(const char *name, int nstates)
{
  double worst_ratio = 0, worst_bound = 0, lowest = 1;
  int n = 0, resolved = 0, blocks_checked = 0;
  for (int k = 0; k < nstates; k++) {
    state s;
    double m;
    const double target = MARGIN * pow(BOUNDARY_MIN / MARGIN, (k + 1.0) / nstates);
    if (!state_at_margin(&s, target, &m)) continue;
    prru_loads l;
    memcpy(l.fd, s.fd, PRRU_NACT * sizeof(double)), memcpy(l.fp, s.fp, sizeof l.fp), memcpy(l.mp, s.mp, sizeof l.mp);
    prru_linearization o;
    if (!TU_TRUE(prru_linearize(&model, &data, s.q, s.qd, &l, 0.0, &o) == PRRU_OK,
                 "prru_linearize where forward dynamics is trusted"))
      continue;
    const double *blocks[] = {o.dqdd_dq, o.dqdd_dqd, o.dqdd_dfd};
    const int vars[] = {V_Q, V_QD, V_FD}, widths[] = {3, 3, NA};
    for (int b = 0; b < 3; b++) {
      double ref[3 * NA], est;
      if (!TU_TRUE(!ref_block(0, &s, vars[b], widths[b], step_for(vars[b], m), ref, &est),
                   "reference forward dynamics near a boundary state"))
        continue;
      const double big = fmax(tu_norm_inf(ref, 3 * widths[b]), 1e-300), noise = ref_noise(&s, vars[b], step_for(vars[b], m));
      const double hmin = ref_hmin;
      /* A second tableau from half the step: near the boundary the first
       * may not be in its asymptotic regime, where est understates its
       * error (a random 4-limb model: 6x at margin 0.0025); the two
       * tableaux' difference measures that. */
      double ref2[3 * NA], est2;
      if (!TU_TRUE(!ref_block(0, &s, vars[b], widths[b], step_for(vars[b], m) / 2, ref2, &est2),
                   "reference forward dynamics near a boundary state (half step)"))
        continue;
      const double spread = tu_relerr(ref2, ref, 3 * widths[b], big);
      const double bound = BOUND + 4 * fmax(est, est2) + spread + 27 * noise / (fmin(hmin, ref_hmin) * big);
      const double e = tu_relerr(blocks[b], ref, 3 * widths[b], 1e-300);
      char what[160];
      snprintf(what, sizeof what, "%s: %s at margin %.3g against the reference (bound: both sides' errors)",
               name, fwd_names[b], m);
      tu_check(e <= bound, what, e, bound);
      resolved += bound <= BOUNDARY_CEILING;
      blocks_checked++;
      worst_ratio = fmax(worst_ratio, e / bound);
      worst_bound = fmax(worst_bound, bound);
    }
    lowest = fmin(lowest, m);
    n++;
  }
  char what[200];
  snprintf(what, sizeof what, "%s: trusted states near the boundary (margin below %g)", name, MARGIN / 10);
  TU_TRUE(n >= nstates / 2 && lowest < MARGIN / 10, what);
  snprintf(what, sizeof what, "%s: blocks near the boundary that the reference resolves to %g", name,
           BOUNDARY_CEILING);
  TU_TRUE(2 * resolved >= blocks_checked, what);
  printf("  near the boundary: %d states down to margin %.2g, worst error / bound %.2f, largest bound %.1e, "
         "%d of %d blocks resolved to %g\n",
         n, lowest, worst_ratio, worst_bound, resolved, blocks_checked, BOUNDARY_CEILING);
}

/* prru_linearize_batch against prru_linearize, state by state, over
 * NBATCH states (two of its chunks of 32 and part of a third) drawn over a
 * box wider than the workspace, with non-finite inputs and states just
 * inside the reach boundary (PRRU_ESINGULAR: the mass matrix's rcond far
 * below mass_rcond_min there) mixed in. Statuses must be equal, failures
 * all zeros. Trusted states: every array of the linearisation (dt > 0: Ad
 * and Bd too) under test_batch.c's rule for the batched kernels, whose
 * vector sin and cos (within 4 ulp) are the only difference: within
 * BATCH_TOL of the array's largest entry plus BATCH_SENS times the largest
 * change of prru_linearize's array when q1 or q2 moves by BATCH_PERTURB
 * ulp (more than libmvec's error) either way, or a component of qd by as
 * many of its ulps: with Coulomb friction the vector tanh differs too, and
 * its arguments are the slider rates J_d qd / v_s, on which dqdd/dqd
 * depends through tanh' / v_s, steep where v_s is small (the prototype
 * models: 4e-14 of dqdd_dqd's largest entry against a bound of 1e-14 plus
 * q's sensitivity alone). */
#define NBATCH 75
#define BATCH_TOL 1e-14
#define BATCH_PERTURB 8.0
#define BATCH_SENS 2.0
#define BATCH_DT 1e-3

static const struct {
  const char *name;
  size_t at;
  int n;
} lin_arrays[] = {
  {"qdd", offsetof(prru_linearization, qdd), 3},
  {"dqdd_dq", offsetof(prru_linearization, dqdd_dq), 9},
  {"dqdd_dqd", offsetof(prru_linearization, dqdd_dqd), 9},
  {"dqdd_dfd", offsetof(prru_linearization, dqdd_dfd), 3 * NA},
  {"dqdd_dfp", offsetof(prru_linearization, dqdd_dfp), 9},
  {"dqdd_dmp", offsetof(prru_linearization, dqdd_dmp), 9},
  {"A", offsetof(prru_linearization, A), 36},
  {"B", offsetof(prru_linearization, B), 6 * NA},
  {"Ad", offsetof(prru_linearization, Ad), 36},
  {"Bd", offsetof(prru_linearization, Bd), 6 * NA},
};
#define NLIN ((int)(sizeof lin_arrays / sizeof lin_arrays[0]))

static const double *lin_array(const prru_linearization *o, int a)
{
  return (const double *)(const void *)((const char *)o + lin_arrays[a].at);
}

static double bq[NBATCH][3], bqd[NBATCH][3];
static prru_loads bl[NBATCH];
static prru_linearization lin_one[NBATCH], lin_many[NBATCH];
static int st_one[NBATCH], st_many[NBATCH];

/* A state just inside the reach from q (reachable) along q1 towards
 * +-pi/2: the boundary by bisection, then 1e-10 rad back: PRRU_ESINGULAR
 * (on the paper model from 1e-8 to 1e-14 rad back, the mass matrix's
 * rcond below mass_rcond_min; trusted from 1e-6), and 1e-10 rad is a
 * million ulps of sin and cos from the reach. 0 if no boundary that way. */
static int near_boundary(double q[3], double to)
{
  double lo = q[0], hi = to, x[3] = {to, q[1], q[2]};
  prru_loads none = {{0}, {0, 0, 0}, {0, 0, 0}};
  prru_linearization o;
  const double qd[3] = {0, 0, 0};
  if (prru_linearize(&model, &data, x, qd, &none, 0.0, &o) != PRRU_EUNREACHABLE) return 0;
  for (int i = 0; i < 200 && fabs(hi - lo) > 4 * DBL_EPSILON; i++) {
    x[0] = 0.5 * (lo + hi);
    if (prru_linearize(&model, &data, x, qd, &none, 0.0, &o) == PRRU_EUNREACHABLE)
      hi = x[0];
    else
      lo = x[0];
  }
  q[0] = lo - copysign(1e-10, to);
  return 1;
}

static void draw_batch(void)
{
  for (int k = 0; k < NBATCH; k++) {
    bq[k][0] = tu_uniform(-PI / 2, PI / 2);
    bq[k][1] = tu_uniform(-PI / 2, PI / 2);
    bq[k][2] = tu_uniform(-2 * length, 2 * length);
    for (int i = 0; i < 3; i++) {
      bqd[k][i] = tu_uniform(-1, 1) * (i == 2 ? length : 1);
      bl[k].fp[i] = tu_uniform(-30, 30);
      bl[k].mp[i] = tu_uniform(-3, 3);
    }
    for (int i = 0; i < NA; i++) bl[k].fd[i] = tu_uniform(-60, 60);
    /* Every fifth state trusted for sure (the box alone gave as few as 6
     * of 75 on a prototype). */
    state t;
    double mt;
    if (k % 5 == 2 && random_state(&t, &mt)) {
      memcpy(bq[k], t.q, sizeof t.q), memcpy(bqd[k], t.qd, sizeof t.qd);
      memcpy(bl[k].fd, t.fd, PRRU_NACT * sizeof(double)), memcpy(bl[k].fp, t.fp, sizeof t.fp), memcpy(bl[k].mp, t.mp, sizeof t.mp);
    }
  }
  bq[5][0] = NAN, bqd[40][1] = INFINITY, bl[41].fd[0] = NAN;
  /* Just inside the reach, from reachable states at small angles. */
  static const int edge[] = {10, 33, 64, 74};
  for (int e = 0; e < 4; e++) {
    double *q = bq[edge[e]], mm;
    state s;
    memset(&s, 0, sizeof s);
    for (int tries = 0; tries < 1000; tries++) {
      s.q[0] = q[0] = tu_uniform(-PI / 8, PI / 8);
      s.q[1] = q[1] = tu_uniform(-PI / 8, PI / 8);
      s.q[2] = q[2] = tu_uniform(-length, length);
      if (trusted_state(&s, &mm) && near_boundary(q, tu_uniform(-1, 1) < 0 ? -PI / 2 : PI / 2)) break;
    }
  }
}

/* The vector tanh's share in dqdd/dqd (tu_tanh_share, testutil.h). */
static double tanh_bound(const double q[3])
{
  const prru_mechanism *mech = model.mech;
  double f = 0, Jd[3 * NA], M[9];
  for (int i = 0; i < NA; i++) f = fmax(f, mech->coulomb[i]);
  model.kernels->jd(model.kernel_params, q, Jd);
  model.kernels->mass(model.kernel_params, q, M);
  return tu_tanh_share(Jd, NA, M, f, mech->coulomb_velocity);
}

static void check_batch(const char *name)
{
  char what[400];
  int count[16] = {0};
  draw_batch();
  for (int k = 0; k < NBATCH; k++)
    st_one[k] = prru_linearize(&model, &data, bq[k], bqd[k], &bl[k], BATCH_DT, &lin_one[k]);
  int first = PRRU_OK;
  for (int k = 0; k < NBATCH && first == PRRU_OK; k++) first = st_one[k];
  memset(lin_many, 0x55, sizeof lin_many);
  const int ret = prru_linearize_batch(&model, NBATCH, &bq[0][0], &bqd[0][0], bl, BATCH_DT, lin_many, st_many);
  snprintf(what, sizeof what, "%s: prru_linearize_batch returns the first failing state's status", name);
  TU_TRUE(ret == first, what);
  int same = 1, zeros = 1;
  double worst_batch = 0;
  static const prru_linearization zero;
  for (int k = 0; k < NBATCH; k++) {
    same &= st_many[k] == st_one[k];
    count[st_one[k] & 15]++;
    if (st_one[k] != PRRU_OK) {
      zeros &= !memcmp(&lin_many[k], &zero, sizeof zero);
      continue;
    }
    double sens[NLIN] = {0};
    for (int j = 0; j < 5; j++)
      for (int sign = -1; sign <= 1; sign += 2) {
        double q[3] = {bq[k][0], bq[k][1], bq[k][2]}, qd[3] = {bqd[k][0], bqd[k][1], bqd[k][2]};
        prru_linearization o;
        if (j < 2)
          q[j] += sign * BATCH_PERTURB * DBL_EPSILON * fmax(1.0, fabs(q[j]));
        else
          qd[j - 2] += sign * BATCH_PERTURB * DBL_EPSILON * fabs(qd[j - 2]);
        if (prru_linearize(&model, &data, q, qd, &bl[k], BATCH_DT, &o) != PRRU_OK) continue;
        for (int a = 0; a < NLIN; a++)
          for (int i = 0; i < lin_arrays[a].n; i++)
            sens[a] = fmax(sens[a], fabs(lin_array(&o, a)[i] - lin_array(&lin_one[k], a)[i]));
      }
    const double tanh_err = tanh_bound(bq[k]);
    for (int a = 0; a < NLIN; a++) {
      const double *x = lin_array(&lin_many[k], a), *y = lin_array(&lin_one[k], a);
      double err = 0, scale = 1e-300;
      for (int i = 0; i < lin_arrays[a].n; i++) {
        const double e = fabs(x[i] - y[i]);
        if (!(e <= err)) err = e;
        scale = fmax(scale, fabs(y[i]));
      }
      snprintf(what, sizeof what, "%s: batched %s of state %d within %.0e + %.0f x its sensitivity to %.0f "
               "ulp of q1, q2", name, lin_arrays[a].name, k, BATCH_TOL, BATCH_SENS, BATCH_PERTURB);
      tu_check(err <= BATCH_TOL * scale + BATCH_SENS * sens[a] + tanh_err, what, err / scale, BATCH_TOL);
      worst_batch = fmax(worst_batch, err / scale);
    }
    snprintf(what, sizeof what, "%s: batched dt of state %d", name, k);
    TU_TRUE(lin_many[k].dt == BATCH_DT, what);
  }
  snprintf(what, sizeof what, "%s: prru_linearize_batch's statuses are prru_linearize's", name);
  TU_TRUE(same, what);
  snprintf(what, sizeof what, "%s: a failed state's batched linearisation is all zeros", name);
  TU_TRUE(zeros, what);
  snprintf(what, sizeof what, "%s: the batch mixes trusted (%d), unreachable (%d), singular (%d), "
           "out-of-stroke (%d) and non-finite (%d) states", name, count[PRRU_OK], count[PRRU_EUNREACHABLE],
           count[PRRU_ESINGULAR], count[PRRU_ESTROKE], count[PRRU_EINPUT]);
  TU_TRUE(count[PRRU_OK] >= NBATCH / 10 && count[PRRU_EUNREACHABLE] > 0 && count[PRRU_ESINGULAR] >= 3 &&
              count[PRRU_EINPUT] >= 3,
          what);
  printf("  batched linearisation: worst difference %.2e of an array's largest entry; %s\n", worst_batch, what);
  /* Arguments: every state PRRU_EINPUT and zeroed for a bad dt; n = 0. */
  TU_TRUE(prru_linearize_batch(&model, 3, &bq[0][0], &bqd[0][0], bl, -1.0, lin_many, st_many) == PRRU_EINPUT &&
              st_many[0] == PRRU_EINPUT && st_many[2] == PRRU_EINPUT &&
              !memcmp(&lin_many[2], &zero, sizeof zero),
          "prru_linearize_batch: dt < 0 fails every state");
  TU_TRUE(prru_linearize_batch(&model, 0, NULL, NULL, NULL, 0.0, NULL, NULL) == PRRU_OK,
          "prru_linearize_batch: no states, PRRU_OK");
}

/* Hovering (at rest, the drives holding the robot against gravity:
 * unloaded it falls as one rigid body and every derivative is 0), then
 * random states with rates and loads, on model (P its numbers). */
static void check_model(const char *name, int nstates, int nboundary)
{
  memset(worst, 0, sizeof worst);
  worst_est = worst_identity = 0;
  blocks_total = blocks_unresolved = 0;
  length = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) length += (P.l1[i] + P.l2[i]) / (2 * PRRU_NLIMB);
  state s;
  double m = 0;
  int n = 0, hover = 0;
  memset(&s, 0, sizeof s);
  prru_loads none = {{0}, {0, 0, 0}, {0, 0, 0}};
  for (int tries = 0; tries < 2000 && !hover; tries++) {
    s.q[2] = tu_uniform(-2 * length, 2 * length);
    hover = prru_inverse_dynamics(&model, &data, s.q, s.qd, s.qdd, &none, s.fd) == PRRU_OK &&
            trusted_state(&s, &m);
  }
  char what[300];
  snprintf(what, sizeof what, "%s: a hovering state with margin >= %g", name, MARGIN);
  TU_TRUE(hover, what);
  for (int k = 0; k < nstates; k++) {
    if (k > 0 || !hover) {
      snprintf(what, sizeof what, "%s: a random trusted state with margin >= %g", name, MARGIN);
      if (!TU_TRUE(random_state(&s, &m), what)) break;
    }
    check_forward(&s, m);
    check_inverse(&s, m, 0.0);
    /* A preload of twice the robot's weight: dn/dq of the order of the
     * minimum-norm part's derivatives. */
    if (NA == 4) check_inverse(&s, m, 2 * prru_mech.total_mass * 9.81);
    if (k < 3) check_hold(&s);
    n++;
  }
  printf("%s (%s kernels), %d states:\n", name, model.kernels->path, n);
  for (int b = 0; b < 5; b++) printf("  %-9s worst relative error %.2e\n", fwd_names[b], worst[0][b]);
  for (int b = 0; b < (NA == 3 ? 3 : 6); b++)
    printf("  %-12s worst relative error %.2e\n", inv_names[b], worst[1][b]);
  printf("  identities worst %.2e\n", worst_identity);
  printf("  reference differences' worst error estimate %.2e, %d of %d blocks not resolved to %g\n", worst_est,
         blocks_unresolved, blocks_total, REF_ACCURACY);
  /* Nearly every block is checked to 1e-9 (all on the committed models). */
  snprintf(what, sizeof what, "%s: blocks the reference resolves to %g (at least 95 %%)", name, REF_ACCURACY);
  TU_TRUE(20 * blocks_unresolved <= blocks_total, what);
  check_boundary(name, nboundary);
  check_batch(name);
}

/* A model file loaded at run time: 0 when it is of the other topology
 * (refused by the build: not this test's business). */
static int check_file(const char *path, int nstates, int must_load)
{
  char msg[1024];
  const int st = prru_model_load(&model, path, msg, sizeof msg);
  if (st != PRRU_OK) {
    if (must_load) tu_check(0, msg, 0, 0);
    return 0;
  }
  /* This test's checks are sized by the build's model (NA, ...): a file
   * of the other topology is test_model_load's and cross_build.py's. */
  if (model.mech->nlimb != PRRU_NLIMB) {
    printf("%s: %d limbs, not this test's (its checks have the build's sizes)\n", path, model.mech->nlimb);
    prru_model_free(&model);
    if (must_load) tu_check(0, "a model of the build's number of limbs", 0, 0);
    return 0;
  }
  ref_params_of(model.mech, &P);
  check_model(path, nstates, nstates);
  prru_model_free(&model);
  return 1;
}

/* No arguments: the build's model (specialised kernels), then every
 * committed model file of the build's number of limbs loaded at run time
 * (the parameter kernels where its numbers differ). Arguments: those
 * model files (test_random_loaded.sh: random valid models). */
int main(int argc, char **argv)
{
  gsl_set_error_handler_off();
  W = prru_ref_alloc();
  if (argc > 1) {
    for (int i = 1; i < argc; i++) {
      const int before = tu_failures;
      check_file(argv[i], 6, 1);
      if (tu_failures != before) printf("FAILED: %s\n", argv[i]);
    }
  } else {
    prru_ref_params_default(&P);
    prru_model_default(&model);
    check_model("the build's model", 21, 16);
    const char *src = getenv("PRRU_SOURCE_DIR");
    static const char *const files[] = {"3prru_paper.json", "prototype_drives.json",
                                        "prototype_example.json", "4prru.json"};
    int loaded = 0;
    for (int i = 0; src && i < 4; i++) {
      char path[2048];
      snprintf(path, sizeof path, "%s/models/%s", src, files[i]);
      loaded += check_file(path, 8, 0);
    }
    TU_TRUE(loaded >= (PRRU_NLIMB == 3 ? 3 : 1), "the committed models of the build's limbs (PRRU_SOURCE_DIR)");
  }
  prru_ref_free(W);
  return tu_finish("test_derivs");
}
