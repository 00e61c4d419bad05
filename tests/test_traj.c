/* Trajectories (prru_traj.h) on any model: the local polynomial
 * differentiation reproduces polynomials of its degree exactly (to the
 * rounding its noise gain predicts), on an analytic trajectory stays
 * within its own truncation bound (which is not loose by more than a
 * small factor) and converges at the order h^(p+1-k); bad data is refused
 * naming the row. Piecewise quintics: waypoint segments hit the waypoints
 * at rest with the textbook peak speed and acceleration, the Hermite
 * interpolation of any quintic's samples is that quintic, and q, qd, qdd
 * are continuous at the knots. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru_traj.h"
#include "testutil.h"

#define N_MAX 4001

static double T[N_MAX], Y[N_MAX], YS[N_MAX], YD[N_MAX], YDD[N_MAX];
static double TR[3 * N_MAX], GN[3 * N_MAX];

/* Times 0..(n-1) h with a deterministic jitter of up to 0.3 h (measured
 * time stamps), or exactly even. */
static void make_times(int n, double h, int jitter)
{
  for (int i = 0; i < n; i++) T[i] = i * h + (jitter && i > 0 && i < n - 1 ? tu_uniform(-0.3, 0.3) * h : 0.0);
}

static void polynomial_exact(int half, int degree)
{
  const int n = 301;
  const double h = 1e-3;
  make_times(n, h, 1);
  /* A polynomial of the fit's degree with O(1) coefficients, shifted so
   * that the values are O(1) on [0, 0.3]. */
  double c[PRRU_DIFF_MAX_DEGREE + 1];
  for (int k = 0; k <= degree; k++) c[k] = tu_uniform(-2, 2);
  double ymax = 0;
  for (int i = 0; i < n; i++) {
    double s = T[i] - 0.15, p = 0;
    for (int k = degree; k >= 0; k--) p = p * s + c[k];
    Y[i] = p;
    ymax = fmax(ymax, fabs(p));
  }
  prru_diff_options o = {half, degree};
  char msg[256];
  int st = prru_diff_signal(T, n, Y, 1, &o, YS, YD, YDD, TR, GN, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK, "polynomial: differentiates");
  /* Rounding: y carries relative errors of a few eps, the estimate sums
   * them with weights of 2-norm gain_k (1-norm at most sqrt(2m+1) times
   * that), so 100 eps ymax sqrt(2m+1) gain_k bounds it. */
  double worst[3] = {0, 0, 0};
  for (int i = 0; i < n; i++) {
    double s = T[i] - 0.15, v = 0, dv = 0, ddv = 0;
    for (int k = degree; k >= 0; k--) {
      ddv = ddv * s + 2 * dv;
      dv = dv * s + v;
      v = v * s + c[k];
    }
    const double est[3] = {YS[i], YD[i], YDD[i]}, ex[3] = {v, dv, ddv};
    for (int k = 0; k < 3; k++) {
      double bound = 100 * DBL_EPSILON * ymax * sqrt(2.0 * half + 1) * GN[3 * i + k];
      worst[k] = fmax(worst[k], fabs(est[k] - ex[k]) / bound);
    }
  }
  char what[128];
  for (int k = 0; k < 3; k++) {
    snprintf(what, sizeof what, "polynomial degree %d, m = %d: derivative %d / rounding bound",
             degree, half, k);
    tu_check(worst[k] <= 1.0, what, worst[k], 1.0);
  }
}

/* y = A sin(w t + phi): |y^(p+1)| <= A w^(p+1). */
static double sine_max_error(int n, double h, int k_order, const prru_diff_options *o,
                             double *ratio_to_bound, double *bound_max)
{
  const double A = 0.3, w = 7.0, phi = 0.4;
  make_times(n, h, 0);
  for (int i = 0; i < n; i++) Y[i] = A * sin(w * T[i] + phi);
  char msg[256];
  if (prru_diff_signal(T, n, Y, 1, o, YS, YD, YDD, TR, GN, msg, sizeof msg) != PRRU_OK) return NAN;
  double err = 0, ratio = 0, bmax = 0, dmax = A * pow(w, o->degree + 1);
  for (int i = 0; i < n; i++) {
    double ex = k_order == 0 ? A * sin(w * T[i] + phi)
                : k_order == 1 ? A * w * cos(w * T[i] + phi)
                               : -A * w * w * sin(w * T[i] + phi);
    double est = k_order == 0 ? YS[i] : k_order == 1 ? YD[i] : YDD[i];
    double e = fabs(est - ex);
    double bound = TR[3 * i + k_order] * dmax + 100 * DBL_EPSILON * A * 3 * GN[3 * i + k_order];
    err = fmax(err, e);
    ratio = fmax(ratio, e / bound);
    bmax = fmax(bmax, bound);
  }
  *ratio_to_bound = ratio;
  *bound_max = bmax;
  return err;
}

static void sine_bound_and_order(void)
{
  prru_diff_options o;
  prru_diff_options_default(&o);
  char what[160];
  for (int k = 0; k < 3; k++) {
    double ratio, bmax;
    double err = sine_max_error(1001, 1e-3, k, &o, &ratio, &bmax);
    snprintf(what, sizeof what, "sine, h = 1 ms, defaults: derivative %d error / stated bound", k);
    tu_check(ratio <= 1.0, what, ratio, 1.0);
    /* The bound is worth stating only if it is not loose: the largest
     * error reaches a fair part of it somewhere (ends included). */
    snprintf(what, sizeof what, "sine: derivative %d bound tight within 20x", k);
    tu_check(ratio >= 0.05, what, ratio, 0.05);
    printf("sine h = 1 ms m = %d p = %d: derivative %d max error %.3e, bound %.3e\n", o.half_width,
           o.degree, k, err, bmax);
  }
  /* Order: the second derivative's error falls as h^(p-1) = h^3, so
   * halving h divides it by 8 (interior and ends alike). */
  double r1, r2, b1, b2;
  double e1 = sine_max_error(1001, 2e-3, 2, &o, &r1, &b1);
  double e2 = sine_max_error(2001, 1e-3, 2, &o, &r2, &b2);
  double rate = log2(e1 / e2);
  tu_check(rate > 2.8 && rate < 3.2, "sine: qdd error order in h (3)", rate, 3.0);
}

/* On evenly spaced samples the defaults' truncation factors and noise
 * gains are the numbers prru_traj.h states (at 1 ms). */
static void stated_factor(void)
{
  prru_diff_options o;
  prru_diff_options_default(&o);
  make_times(101, 1e-3, 0);
  for (int i = 0; i < 101; i++) Y[i] = 0.0;
  char msg[256];
  TU_TRUE(prru_diff_signal(T, 101, Y, 1, &o, NULL, NULL, NULL, TR, GN, msg, sizeof msg) == PRRU_OK,
          "defaults on 101 samples");
  tu_check(fabs(TR[152] / 2.178e-9 - 1) < 1e-3, "stated interior trunc_2", TR[152], 2.178e-9);
  tu_check(fabs(GN[152] / 4.433e5 - 1) < 1e-3, "stated interior gain_2", GN[152], 4.433e5);
  tu_check(fabs(TR[2] / 2.702e-7 - 1) < 1e-3, "stated end trunc_2", TR[2], 2.702e-7);
  printf("defaults at h = 1 ms, interior: trunc = %.3e %.3e %.3e, gain = %.3e %.3e %.3e\n",
         TR[150], TR[151], TR[152], GN[150], GN[151], GN[152]);
  printf("defaults at h = 1 ms, first sample: trunc = %.3e %.3e %.3e, gain = %.3e %.3e %.3e\n",
         TR[0], TR[1], TR[2], GN[0], GN[1], GN[2]);
}

static void refusals(void)
{
  prru_diff_options o;
  prru_diff_options_default(&o);
  char msg[256] = "";
  make_times(20, 1e-3, 0);
  for (int i = 0; i < 20; i++) Y[i] = i;
  T[7] = T[6];
  TU_TRUE(prru_diff_signal(T, 20, Y, 1, &o, YS, YD, YDD, NULL, NULL, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "row 8") && strstr(msg, "does not increase"),
          "repeated time refused naming row 8");
  make_times(20, 1e-3, 0);
  Y[12] = NAN;
  TU_TRUE(prru_diff_signal(T, 20, Y, 1, &o, YS, YD, YDD, NULL, NULL, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "row 13"),
          "NaN refused naming row 13");
  Y[12] = 12;
  TU_TRUE(prru_diff_signal(T, 8, Y, 1, &o, YS, YD, YDD, NULL, NULL, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "at least 9"),
          "too few rows refused");
  prru_diff_options bad = {2, 5};
  TU_TRUE(prru_diff_signal(T, 20, Y, 1, &bad, YS, YD, YDD, NULL, NULL, msg, sizeof msg) == PRRU_EINPUT,
          "degree above 2m refused");
  prru_diff_options bad2 = {3, 1};
  TU_TRUE(prru_diff_signal(T, 20, Y, 1, &bad2, YS, YD, YDD, NULL, NULL, msg, sizeof msg) == PRRU_EINPUT,
          "degree 1 refused (no second derivative)");
}

static void quintic_waypoints(void)
{
  const double wp[9] = {0, 0, 0, 0.1, -0.08, 0.02, -0.05, 0.03, -0.01};
  const double dur[2] = {0.8, 1.3};
  prru_quintic tr;
  char msg[256];
  TU_TRUE(prru_quintic_waypoints(&tr, 3, wp, dur, 0.5, msg, sizeof msg) == PRRU_OK, "waypoints");
  double q[3], qd[3], qdd[3];
  for (int k = 0; k < 3; k++) {
    prru_quintic_eval(&tr, tr.t[k], q, qd, qdd);
    /* Every knot exactly: u = 0 of its segment, the last one stored
     * (u = 1 would sum the coefficients, rounding to a few ulps of dq). */
    TU_CLOSE(q, wp + 3 * k, 3, 0.0, "waypoint reached");
    TU_TRUE(fabs(qd[0]) + fabs(qd[1]) + fabs(qd[2]) == 0.0 &&
                fabs(qdd[0]) + fabs(qdd[1]) + fabs(qdd[2]) == 0.0,
            "at rest at the waypoint");
  }
  /* Mid-segment: halfway, peak speed 1.875 dq / T; peak acceleration
   * 10 / sqrt(3) dq / T^2 at u = (3 - sqrt 3) / 6. */
  double e[3], peak[3];
  prru_quintic_eval(&tr, 0.5 + 0.4, q, qd, qdd);
  for (int c = 0; c < 3; c++) {
    e[c] = 0.5 * (wp[c] + wp[3 + c]);
    peak[c] = 1.875 * (wp[3 + c] - wp[c]) / 0.8;
  }
  TU_CLOSE(q, e, 3, 1e-15, "quintic: halfway at half time");
  TU_CLOSE(qd, peak, 3, 1e-14, "quintic: peak speed 1.875 dq/T");
  double u = (3 - sqrt(3.0)) / 6;
  prru_quintic_eval(&tr, 1.3 + u * 1.3, q, qd, qdd);
  for (int c = 0; c < 3; c++) peak[c] = 10 / sqrt(3.0) * (wp[6 + c] - wp[3 + c]) / (1.3 * 1.3);
  TU_CLOSE(qdd, peak, 3, 1e-13, "quintic: peak acceleration 10/sqrt(3) dq/T^2");
  TU_TRUE(prru_quintic_eval(&tr, 0.4999, q, qd, qdd) == PRRU_EINPUT &&
              prru_quintic_eval(&tr, 2.6001, q, qd, qdd) == PRRU_EINPUT &&
              prru_quintic_eval(&tr, NAN, q, qd, qdd) == PRRU_EINPUT,
          "outside the span refused");
  prru_quintic_free(&tr);
  const double bad_dur[2] = {0.8, 0.0};
  TU_TRUE(prru_quintic_waypoints(&tr, 3, wp, bad_dur, 0, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "duration 2"),
          "zero duration refused by number");
  const double nan_wp[6] = {0, 0, 0, 0.1, NAN, 0};
  TU_TRUE(prru_quintic_waypoints(&tr, 2, nan_wp, dur, 0, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "waypoint 2"),
          "NaN waypoint refused by number");
  TU_TRUE(prru_quintic_waypoints(&tr, 1, wp, dur, 0, msg, sizeof msg) == PRRU_EINPUT,
          "one waypoint refused");
}

/* Issue 30 item 1: a first segment of 1e-300 s gave inf and NaN rows.
 * Every segment, the first one included, is refused when rounding loses
 * it: its knot time does not move, or its square (dividing the
 * accelerations) is below DBL_MIN, where it no longer carries the rounding
 * unit's relative accuracy: the bound sqrt(DBL_MIN) = 1.49e-154 s is
 * checked on both sides. A short segment that is kept ends exactly at
 * rest on its waypoint. */
static void quintic_durations_rounding(void)
{
  const double wp[9] = {0, 0, 0, 0.1, 0, 0, 0.2, 0, 0};
  prru_quintic tr;
  char msg[256];
  const double tiny[1] = {1e-300}, below[1] = {1e-154}, above[1] = {2e-154};
  TU_TRUE(prru_quintic_waypoints(&tr, 2, wp, tiny, 0.0, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "duration 1") && strstr(msg, "lost to rounding"),
          "first duration 1e-300 s refused");
  TU_TRUE(prru_quintic_waypoints(&tr, 2, wp, below, 0.0, msg, sizeof msg) == PRRU_EINPUT,
          "first duration 1e-154 s (square below DBL_MIN) refused");
  TU_TRUE(prru_quintic_waypoints(&tr, 2, wp, above, 0.0, msg, sizeof msg) == PRRU_OK,
          "first duration 2e-154 s (square above DBL_MIN) kept");
  if (tr.n) prru_quintic_free(&tr);
  const double later[2] = {1.0, 1e-16};
  TU_TRUE(prru_quintic_waypoints(&tr, 3, wp, later, 0.0, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "duration 2"),
          "later duration below the rounding unit of its start refused");
  const double short_dur[1] = {1e-12};
  TU_TRUE(prru_quintic_waypoints(&tr, 2, wp, short_dur, 0.0, msg, sizeof msg) == PRRU_OK,
          "duration 1e-12 s kept");
  double q[3], qd[3], qdd[3];
  prru_quintic_eval(&tr, prru_quintic_t_end(&tr), q, qd, qdd);
  TU_CLOSE(q, wp + 3, 3, 0.0, "short segment: ends on its waypoint");
  TU_TRUE(qd[0] == 0.0 && qd[1] == 0.0 && qd[2] == 0.0 && qdd[0] == 0.0 && qdd[1] == 0.0 &&
              qdd[2] == 0.0,
          "short segment: ends at rest");
  prru_quintic_eval(&tr, 0.5e-12, q, qd, qdd);
  int finite = 1;
  for (int c = 0; c < 3; c++) finite &= isfinite(q[c]) && isfinite(qd[c]) && isfinite(qdd[c]);
  TU_TRUE(finite, "short segment: finite inside");
  prru_quintic_free(&tr);
}

/* The Hermite interpolation of samples of one quintic P is P. */
static void hermite_reproduces_quintic(void)
{
  double c[3][6];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 6; k++) c[i][k] = tu_uniform(-1, 1);
  const int n = 5;
  double t[5] = {-0.2, 0.1, 0.15, 0.6, 1.0}, q[15], qd[15], qdd[15];
  for (int j = 0; j < n; j++)
    for (int i = 0; i < 3; i++) {
      double v = 0, dv = 0, ddv = 0;
      for (int k = 5; k >= 0; k--) {
        ddv = ddv * t[j] + 2 * dv;
        dv = dv * t[j] + v;
        v = v * t[j] + c[i][k];
      }
      q[3 * j + i] = v;
      qd[3 * j + i] = dv;
      qdd[3 * j + i] = ddv;
    }
  prru_quintic tr;
  char msg[256];
  TU_TRUE(prru_quintic_samples(&tr, n, t, q, qd, qdd, msg, sizeof msg) == PRRU_OK, "samples");
  double worst = 0;
  for (int s = 0; s <= 120; s++) {
    double ts = -0.2 + 1.2 * s / 120.0, a[3], ad[3], add[3], ex[9];
    prru_quintic_eval(&tr, ts, a, ad, add);
    for (int i = 0; i < 3; i++) {
      double v = 0, dv = 0, ddv = 0;
      for (int k = 5; k >= 0; k--) {
        ddv = ddv * ts + 2 * dv;
        dv = dv * ts + v;
        v = v * ts + c[i][k];
      }
      ex[i] = v;
      ex[3 + i] = dv;
      ex[6 + i] = ddv;
    }
    double got[9] = {a[0], a[1], a[2], ad[0], ad[1], ad[2], add[0], add[1], add[2]};
    worst = fmax(worst, tu_relerr(got, ex, 9, 1.0));
  }
  tu_check(worst <= 1e-12, "Hermite quintic of a quintic's samples is the quintic", worst, 1e-12);
  prru_quintic_free(&tr);
  /* Continuity at a knot of a general table: q, qd, qdd from both sides. */
  for (int j = 0; j < 15; j++) {
    q[j] = tu_uniform(-0.1, 0.1);
    qd[j] = tu_uniform(-1, 1);
    qdd[j] = tu_uniform(-5, 5);
  }
  TU_TRUE(prru_quintic_samples(&tr, n, t, q, qd, qdd, msg, sizeof msg) == PRRU_OK, "table");
  double l[9], r[9];
  prru_quintic_eval(&tr, nextafter(0.6, 0), l, l + 3, l + 6);
  prru_quintic_eval(&tr, 0.6, r, r + 3, r + 6);
  double at[9] = {q[9], q[10], q[11], qd[9], qd[10], qd[11], qdd[9], qdd[10], qdd[11]};
  tu_check(tu_relerr(r, at, 9, 1.0) <= 1e-14, "knot values matched", tu_relerr(r, at, 9, 1.0), 1e-14);
  tu_check(tu_relerr(l, at, 9, 1.0) <= 1e-12, "continuous at the knot (left limit)",
           tu_relerr(l, at, 9, 1.0), 1e-12);
  prru_quintic_free(&tr);
  t[2] = t[1];
  TU_TRUE(prru_quintic_samples(&tr, n, t, q, qd, qdd, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "point 3"),
          "table with a repeated time refused naming point 3");
}

/* Differentiating the samples of a quintic waypoint trajectory: q(t) at
 * 1 ms from the quintic, derivatives against the quintic's own, within
 * the stated bound (the quintic's 6th derivative is 0 inside a segment,
 * its 5th is constant: degree 5 is exact away from the knots). */
static void differentiate_quintic(void)
{
  const double wp[9] = {0, 0, 0, 0.1, -0.08, 0.02, 0, 0, 0};
  const double dur[2] = {1.0, 1.0};
  prru_quintic tr;
  char msg[256];
  prru_quintic_waypoints(&tr, 3, wp, dur, 0, msg, sizeof msg);
  const int n = 2001;
  static double q[3 * 2001], qd[3 * 2001], qdd[3 * 2001], ex[3 * 2001], exd[3 * 2001];
  for (int i = 0; i < n; i++) {
    T[i] = i * 1e-3;
    prru_quintic_eval(&tr, T[i], q + 3 * i, ex + 3 * i, exd + 3 * i);
  }
  prru_diff_options o = {4, 5};
  TU_TRUE(prru_diff_signal(T, n, q, 3, &o, NULL, qd, qdd, TR, GN, msg, sizeof msg) == PRRU_OK,
          "differentiate 3 columns");
  double wqd = 0, wqdd = 0;
  for (int i = 0; i < n; i++) {
    if (abs(i - 1000) <= 4) continue; /* windows across the middle knot */
    for (int c = 0; c < 3; c++) {
      wqd = fmax(wqd, fabs(qd[3 * i + c] - ex[3 * i + c]));
      wqdd = fmax(wqdd, fabs(qdd[3 * i + c] - exd[3 * i + c]));
    }
  }
  /* Exact to rounding: 1e-4 rad/s^2 of rounding noise would be
   * eps * 0.1 * gain_2 (~1e6 / s^2 at 1 ms): about 2e-11 . */
  tu_check(wqd <= 1e-11, "quintic samples: qd exact (degree 5) away from the knot", wqd, 1e-11);
  tu_check(wqdd <= 1e-8, "quintic samples: qdd exact (degree 5) away from the knot", wqdd, 1e-8);
  prru_quintic_free(&tr);
}

/* prru_path_side: a sign change of det J_d between regular samples is a
 * crossing; a singular sample (det 0) neither records nor crosses; with
 * four actuators (no determinant) nothing is ever crossed. */
static void path_side(void)
{
  double Jp[PRRU_NACT * 3], Jn[PRRU_NACT * 3], J0[PRRU_NACT * 3];
  memset(Jp, 0, sizeof Jp);
  for (int i = 0; i < 3; i++) Jp[4 * i] = 1; /* rows 1..3 the identity */
  memcpy(Jn, Jp, sizeof Jn);
  Jn[0] = -1;
  memcpy(J0, Jp, sizeof J0);
  J0[0] = 0;
  prru_path_side s;
  prru_path_side_init(&s);
  const int square = PRRU_NACT == 3;
  TU_TRUE(!prru_path_side_crossed(&s, J0, PRRU_NACT), "path side: a singular first sample records nothing");
  TU_TRUE(!prru_path_side_crossed(&s, Jp, PRRU_NACT) && s.sign == (square ? 1 : 0), "path side: the first sign");
  TU_TRUE(!prru_path_side_crossed(&s, J0, PRRU_NACT) && !prru_path_side_crossed(&s, Jp, PRRU_NACT), "path side: the same side");
  TU_TRUE(prru_path_side_crossed(&s, Jn, PRRU_NACT) == square, "path side: the other side is a crossing (three actuators)");
  TU_TRUE(s.sign == (square ? 1 : 0), "path side: a crossing keeps the sign before it");
}

/* The rows of a sampled motion (prru_row_count, prru_row_time): every dt
 * from t0 and t1 itself, a remainder of rounding's size merged into the
 * last row, at least two rows, and no run of more than 1e8 steps. */
static void row_times(void)
{
  TU_TRUE(prru_row_count(0, 1, 0.25) == 5 && prru_row_time(0, 1, 0.25, 3, 5) == 0.75 &&
              prru_row_time(0, 1, 0.25, 4, 5) == 1.0,
          "rows: 1 s every 0.25 s is 0, 0.25, 0.5, 0.75, 1");
  /* 0.3 / 0.1 is 2.9999999999999996 in double: three steps, not four. */
  TU_TRUE(prru_row_count(0, 0.3, 0.1) == 4 && prru_row_time(0, 0.3, 0.1, 3, 4) == 0.3,
          "rows: a quotient a rounding below a whole number");
  TU_TRUE(prru_row_count(0, 1, 0.3) == 5 && prru_row_time(0, 1, 0.3, 3, 5) == 0.3 * 3 &&
              prru_row_time(0, 1, 0.3, 4, 5) == 1.0,
          "rows: a remainder gets the end's row");
  TU_TRUE(prru_row_count(2, 2.001, 1) == 2 && prru_row_time(2, 2.001, 1, 1, 2) == 2.001,
          "rows: a span below dt still has both ends");
  TU_TRUE(prru_row_count(0, 1, 0) == 0 && prru_row_count(0, 1, -1) == 0 && prru_row_count(0, 1, NAN) == 0 &&
              prru_row_count(0, 1e9, 1) == 0 && prru_row_count(0, 1e8, 1) == 100000001,
          "rows: dt not > 0 or more than 1e8 steps refused, 1e8 steps allowed");
  /* Every row before the end within the span, the last at t1, steps of dt. */
  tu_rng_state = 7;
  int ok = 1;
  for (int i = 0; i < 1000; i++) {
    const double t0 = tu_uniform(-5, 5), t1 = t0 + tu_uniform(1e-3, 10), dt = tu_uniform(1e-3, 1);
    const long n = prru_row_count(t0, t1, dt);
    ok &= n >= 2 && prru_row_time(t0, t1, dt, n - 1, n) == t1 && prru_row_time(t0, t1, dt, n - 2, n) < t1 &&
          t1 - prru_row_time(t0, t1, dt, n - 2, n) <= dt * (1 + 1e-9);
  }
  TU_TRUE(ok, "rows: the last at t1, the one before within dt of it");
}

int main(void)
{
  row_times();
  path_side();
  polynomial_exact(4, 4);
  polynomial_exact(3, 2);
  polynomial_exact(6, 5);
  polynomial_exact(2, 4);
  sine_bound_and_order();
  stated_factor();
  refusals();
  quintic_waypoints();
  quintic_durations_rounding();
  hermite_reproduces_quintic();
  differentiate_quintic();
  return tu_finish("test_traj");
}
