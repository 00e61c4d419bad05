/* Computed-torque tracking (prru_control.h) on any model: the plant's
 * dynamics through the runtime-parameter kernels at the model's numbers
 * are the constant kernels' forward dynamics; the controller's forces give
 * the plant exactly the commanded acceleration; with the exact model a
 * run that starts on a quintic reference stays on it (1e-9), and one that
 * starts off it follows the analytic critically damped error
 * e0 (1 + w t) e^(-w t); with heavier links the error stays bounded and
 * falls with the gains (as 1/w^2); a sampled controller with sensor noise
 * is deterministic per seed; force limits are reported as saturation and
 * never exceeded; a stroke limit stops the run; bad options are refused
 * with the option named. Each sample's slider speeds are J_d qd (1e-12),
 * the summary's max_dd their maxima and over_speed the samples over a
 * speed limit (counted here from J_d), the limit changing nothing else;
 * the gains of a bandwidth w are w^2, 2 w (the defaults w = 20); all-zero
 * LQR weights are the default ones. The time-varying LQR: on a pose held at rest its
 * Riccati recursion reaches the discrete algebraic Riccati equation's
 * solution to rounding, with a stable closed loop; on the exact plant it
 * tracks like computed torque at the same period (within the
 * zero-order-hold error), an initial offset decays, and a wrong gain (sign
 * or layout) is caught. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>

#include "testbuild.h"
#include "prru_control.h"
#include "prru_linearize.h"
#include "testutil.h"

/* Home (q = 0) to a tilted, raised pose and back: regular for any
 * buildable model (the design tests use the same neighbourhood). */
static const double WP[9] = {0, 0, 0, 0.1, -0.08, 0.02, 0, 0, 0};
static const double DUR[2] = {1.0, 1.0};

static prru_quintic ref;
static prru_model model;

static void plant_is_model(prru_data *d)
{
  double worst = 0, worst_ct = 0;
  prru_track_options o;
  prru_track_options_default(&model, &o);
  for (int k = 0; k < 200; k++) {
    double q[3] = {tu_uniform(-0.15, 0.15), tu_uniform(-0.12, 0.12), tu_uniform(-0.03, 0.03)};
    double qd[3] = {tu_uniform(-1, 1), tu_uniform(-1, 1), tu_uniform(-0.2, 0.2)};
    prru_loads l;
    memset(&l, 0, sizeof l);
    for (int i = 0; i < PRRU_NACT; i++) l.fd[i] = tu_uniform(-80, 80);
    double a[3], b[3];
    if (prru_forward_dynamics(&model, d, q, qd, &l, a) != PRRU_OK) continue;
    TU_TRUE(prru_plant_accel(&model, &prru_params_model, q, qd, l.fd, b) == PRRU_OK, "plant accel");
    worst = fmax(worst, tu_relerr(b, a, 3, 1.0));
    /* The controller's forces, unclipped, give the plant the commanded
     * acceleration qdd_ref + Kd (qd_ref - qd) + Kp (q_ref - q). */
    double qr[3] = {0.02, -0.01, 0.005}, qdr[3] = {0.1, 0.2, -0.05}, qddr[3] = {1, -2, 0.5};
    double fc[PRRU_NACT], f[PRRU_NACT], acc[3], want[3];
    int sat[PRRU_NACT];
    TU_TRUE(prru_computed_torque(&model, d, &o, qr, qdr, qddr, q, qd, fc, f, sat) == PRRU_OK,
            "computed torque");
    prru_plant_accel(&model, &prru_params_model, q, qd, f, acc);
    for (int i = 0; i < 3; i++)
      want[i] = qddr[i] + o.kd[i] * (qdr[i] - qd[i]) + o.kp[i] * (qr[i] - q[i]);
    worst_ct = fmax(worst_ct, tu_relerr(acc, want, 3, 1.0));
  }
  tu_check(worst <= 1e-12, "param plant = constant-kernel forward dynamics", worst, 1e-12);
  tu_check(worst_ct <= 1e-11, "computed torque gives the commanded acceleration", worst_ct, 1e-11);
}

static void exact_tracking(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  prru_track_summary s;
  char msg[512];
  int st = prru_track(&model, &ref, &o, &s, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK, msg);
  TU_TRUE(s.samples == 2001 && fabs(s.t_end - 2.0) < 1e-15, "2001 samples to t = 2");
  double m = fmax(s.max_e[0], fmax(s.max_e[1], s.max_e[2]));
  printf("exact model, continuous: max |e| = %.3e\n", m);
  tu_check(m <= 1e-9, "exact model tracks the quintic", m, 1e-9);
  TU_TRUE(s.any_saturated == 0, "no saturation without limits");
}

typedef struct {
  double e0[3], w, worst;
} decay_ctx;

static int decay_check(const prru_track_sample *s, void *p)
{
  decay_ctx *c = p;
  double t = s->t, f = (1 + c->w * t) * exp(-c->w * t);
  for (int i = 0; i < 3; i++) c->worst = fmax(c->worst, fabs(s->e[i] - c->e0[i] * f));
  return 0;
}

static void error_dynamics(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  decay_ctx c = {{0.01, -0.008, 0.002}, 20.0, 0.0};
  memcpy(o.q0_offset, c.e0, sizeof c.e0);
  o.on_sample = decay_check;
  o.ctx = &c;
  prru_track_summary s;
  char msg[512];
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_OK, msg);
  /* The comparison can fail: the same law with w 0.01 % off is far. */
  decay_ctx off = {{0.01, -0.008, 0.002}, 20.002, 0.0};
  o.ctx = &off;
  prru_track(&model, &ref, &o, &s, msg, sizeof msg);
  tu_check(off.worst > 1e-7, "a law with w 0.01 % off is detected", off.worst, 1e-7);
  printf("initial offset: worst deviation from e0 (1 + w t) exp(-w t): %.3e\n", c.worst);
  tu_check(c.worst <= 1e-9, "error follows the critically damped law", c.worst, 1e-9);
}

static double mismatch_max_error(double w, double period)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  for (int i = 0; i < 3; i++) {
    o.kp[i] = w * w;
    o.kd[i] = 2 * w;
  }
  o.control_period = period;
  prru_params_scale(&o.plant, "mass", 1.1);
  prru_track_summary s;
  char msg[512];
  int st = prru_track(&model, &ref, &o, &s, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK, msg);
  return fmax(s.max_e[0], fmax(s.max_e[1], s.max_e[2]));
}

static void mismatch(void)
{
  double e10 = mismatch_max_error(10, 0), e20 = mismatch_max_error(20, 0),
         e40 = mismatch_max_error(40, 0);
  printf("mass x 1.1: max |e| = %.3e (w = 10), %.3e (20), %.3e (40)\n", e10, e20, e40);
  /* Near the reference the error obeys e'' + Kd e' + Kp e = delta(t), the
   * plant's acceleration deficit under the model's feed-forward forces
   * (delta = qdd_ref - qdd_plant(q_ref, qd_ref, fd_ff)); for critically
   * damped gains the impulse response t e^(-w t) integrates to 1/w^2, so
   * |e| <= sup |delta| / w^2, here with a factor 2 for the plant's own
   * gain change (the commanded acceleration reaches a heavier plant
   * reduced) and for evaluating delta on the reference. Falls as 1/w^2
   * (a factor 4 per doubling; at least 3). */
  prru_track_options o;
  prru_track_options_default(&model, &o);
  prru_params plant = prru_params_model;
  prru_params_scale(&plant, "mass", 1.1);
  prru_data *d = malloc(sizeof *d);
  double sup = 0;
  for (int k = 0; k <= 2000; k++) {
    double qr[3], qdr[3], qddr[3], fc[PRRU_NACT], f[PRRU_NACT], a[3];
    int sat[PRRU_NACT];
    prru_quintic_eval(&ref, k * 1e-3, qr, qdr, qddr);
    prru_computed_torque(&model, d, &o, qr, qdr, qddr, qr, qdr, fc, f, sat);
    prru_plant_accel(&model, &plant, qr, qdr, f, a);
    for (int i = 0; i < 3; i++) sup = fmax(sup, fabs(qddr[i] - a[i]));
  }
  free(d);
  double bound10 = 2 * sup / 100;
  printf("mass x 1.1: sup |delta| = %.4g, bound at w = 10: %.3e\n", sup, bound10);
  tu_check(e10 <= bound10, "mismatch: error within 2 sup|delta| / w^2", e10, bound10);
  tu_check(e10 >= 0.1 * bound10, "mismatch: that bound not loose by 10x", e10, 0.1 * bound10);
  tu_check(e10 / e20 > 3 && e20 / e40 > 3, "mismatch: error falls with the gains",
           fmin(e10 / e20, e20 / e40), 3);
  double ez = mismatch_max_error(20, 1e-3);
  printf("mass x 1.1, 1 ms zero-order hold: max |e| = %.3e\n", ez);
  tu_check(ez < 2 * e20, "sampled 1 ms controller close to the continuous one", ez / e20, 2);
}

static void noise_deterministic(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  o.control_period = 1e-3;
  o.noise_q = 1e-5;
  o.noise_qd = 1e-3;
  o.seed = 42;
  prru_track_summary a, b, c;
  char msg[512];
  TU_TRUE(prru_track(&model, &ref, &o, &a, msg, sizeof msg) == PRRU_OK, msg);
  TU_TRUE(prru_track(&model, &ref, &o, &b, msg, sizeof msg) == PRRU_OK, msg);
  o.seed = 43;
  TU_TRUE(prru_track(&model, &ref, &o, &c, msg, sizeof msg) == PRRU_OK, msg);
  TU_TRUE(memcmp(a.rms_e, b.rms_e, sizeof a.rms_e) == 0 && memcmp(a.max_e, b.max_e, sizeof a.max_e) == 0,
          "same seed, same run");
  TU_TRUE(memcmp(a.rms_e, c.rms_e, sizeof a.rms_e) != 0, "another seed, another run");
  double m = fmax(a.max_e[0], fmax(a.max_e[1], a.max_e[2]));
  printf("noise 1e-5 / 1e-3, 1 ms: max |e| = %.3e\n", m);
  TU_TRUE(m > 1e-7 && m < 1e-3, "noise: error of the noise's order");
}

typedef struct {
  double lim, worst_excess;
  long flagged, over;
} sat_ctx;

static int sat_check(const prru_track_sample *s, void *p)
{
  sat_ctx *c = p;
  for (int i = 0; i < PRRU_NACT; i++) {
    c->worst_excess = fmax(c->worst_excess, fabs(s->fd[i]) - c->lim);
    c->flagged += s->saturated[i];
    c->over += fabs(s->fd_cmd[i]) > c->lim;
  }
  return 0;
}

static void saturation(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  prru_track_summary s;
  char msg[512];
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_OK, msg);
  double fmax_ff = 0;
  for (int i = 0; i < PRRU_NACT; i++) fmax_ff = fmax(fmax_ff, s.max_fd[i]);
  /* A limit at 95 % of the largest force the run needed. */
  sat_ctx c = {0.95 * fmax_ff, -INFINITY, 0, 0};
  for (int i = 0; i < PRRU_NACT; i++) o.f_max[i] = c.lim;
  o.on_sample = sat_check;
  o.ctx = &c;
  int st = prru_track(&model, &ref, &o, &s, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK, msg);
  long total = 0;
  for (int i = 0; i < PRRU_NACT; i++) total += s.saturated[i];
  printf("limit %.4g N: %ld saturated actuator-samples, %ld samples with any\n", c.lim, total,
         s.any_saturated);
  TU_TRUE(s.any_saturated > 0 && total == c.flagged && c.flagged == c.over,
          "saturation counted where the command exceeds the limit");
  TU_TRUE(c.worst_excess <= 0.0, "applied forces never exceed the limit");
}

static void stroke(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  /* Slider 1's extreme height on the reference away from its start (the
   * start is home, where it may already be at one extreme), moved 1 mm
   * inwards. */
  double dmax = -INFINITY, dmin = INFINITY, d0 = 0, q[3], d[PRRU_NACT];
  for (int k = 0; k <= 2000; k++) {
    prru_quintic_eval(&ref, k * 1e-3, q, NULL, NULL);
    prru_ik(q, d);
    if (k == 0) d0 = d[0];
    dmax = fmax(dmax, d[0]);
    dmin = fmin(dmin, d[0]);
  }
  if (dmax - d0 > d0 - dmin)
    o.d_max[0] = dmax - 1e-3;
  else
    o.d_min[0] = dmin + 1e-3;
  prru_track_summary s;
  char msg[512];
  int st = prru_track(&model, &ref, &o, &s, msg, sizeof msg);
  TU_TRUE(st == PRRU_EUNREACHABLE && strstr(msg, "slider 1") && strstr(msg, "stroke") &&
              s.samples > 0 && s.samples < 2001,
          "stroke limit stops the run, samples before it kept");
  printf("stroke: %s (%ld samples)\n", msg, s.samples);
}

/* A slider that leaves its stroke only between two samples: continuous
 * control (the plant follows the reference), samples 0.3 s apart (the waypoints, where the sliders
 * turn, lie between them), the
 * stroke 1e-7 m inside slider 1's highest or lowest point on the
 * reference, whichever lies between samples with every sample inside. The
 * run stops at an integration step between the samples, near that point. */
static void stroke_between_samples(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  o.control_period = 0.0;
  const double dt = 0.3;
  o.dt_out = dt;
  const double t1 = prru_quintic_t_end(&ref);
  double q[3], d[PRRU_NACT], hi = -INFINITY, lo = INFINITY, t_hi = 0, t_lo = 0;
  double hi_samples = -INFINITY, lo_samples = INFINITY;
  for (long k = 0; k * 1e-5 <= t1; k++) { /* 10 us apart */
    double t = k * 1e-5;
    prru_quintic_eval(&ref, t, q, NULL, NULL);
    prru_ik(q, d);
    if (d[0] > hi) hi = d[0], t_hi = t;
    if (d[0] < lo) lo = d[0], t_lo = t;
    if (k % 30000 == 0 || k * 1e-5 + 1e-5 > t1) { /* the samples, the last at t1 */
      hi_samples = fmax(hi_samples, d[0]);
      lo_samples = fmin(lo_samples, d[0]);
    }
  }
  double t_x = -1;
  if (fmod(t_hi, dt) > 0.01 && fmod(t_hi, dt) < dt - 0.01 && hi_samples < hi - 1e-7) {
    o.d_max[0] = hi - 1e-7;
    t_x = t_hi;
  } else if (fmod(t_lo, dt) > 0.01 && fmod(t_lo, dt) < dt - 0.01 && lo_samples > lo + 1e-7) {
    o.d_min[0] = lo + 1e-7;
    t_x = t_lo;
  }
  TU_TRUE(t_x > 0, "slider 1 has an extreme between samples on this reference");
  if (!(t_x > 0)) return;
  prru_track_summary s;
  char msg[512];
  int st = prru_track(&model, &ref, &o, &s, msg, sizeof msg);
  const char *p = strstr(msg, "t = ");
  double t_stop = p ? atof(p + 4) : -1;
  printf("stroke between samples: extreme at t = %.6f s; %s (%ld samples)\n", t_x, msg,
         s.samples);
  TU_TRUE(st == PRRU_EUNREACHABLE && strstr(msg, "between samples") && strstr(msg, "slider 1") &&
              fabs(t_stop - t_x) < 0.01 && s.samples == (long)floor(t_stop / dt) + 1,
          "a stroke left between two samples stops the run there, samples before it kept");
}

static void refusals(void)
{
  prru_track_options o;
  prru_track_summary s;
  char msg[512];
  prru_track_options_default(&model, &o);
  o.kp[1] = -1;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "kp"),
          "negative kp refused");
  prru_track_options_default(&model, &o);
  o.f_max[0] = 0;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "force limit of actuator 1"),
          "zero force limit refused");
  prru_track_options_default(&model, &o);
  o.d_min[2] = 0.1;
  o.d_max[2] = 0.1;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "stroke of slider 3"),
          "empty stroke refused");
  prru_track_options_default(&model, &o);
  o.noise_q = 1e-6;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "control period"),
          "noise with a continuous controller refused");
  TU_TRUE(prru_params_scale(&o.plant, "masses", 1.1) == PRRU_EINPUT &&
              prru_params_scale(&o.plant, "mass", 0) == PRRU_EINPUT &&
              prru_params_scale(&o.plant, "mass", NAN) == PRRU_EINPUT,
          "unknown mismatch key or bad factor refused");
}

/* ---- slider speeds, the option checks, the bandwidth rule ---- */

typedef struct {
  double speed_max[PRRU_NACT], max_dd[PRRU_NACT], max_size[PRRU_NACT], worst;
  long over, samples;
} speed_ctx;

/* The slider speeds J_d(q) qd from the model's J_d (not the rates kernel
 * the library uses), their maxima and the samples over a limit. worst:
 * max_i |dd_i - dd'_i| / (u sum_k |J_d,ik qd_k|). Bound, derived: each
 * kernel's J_d entries are a few dozen roundings from the exact ones
 * (sin, cos, sqrt and products of the model's lengths), each within u of
 * the row's magnitude, and the three-term sum adds 3 u of it: 256 u of
 * sum_k |J_d,ik qd_k| (test_model_load's K for two kernel paths) covers
 * both sides with room, while a wrong speed is off by its whole size. */
static int speed_check(const prru_track_sample *s, void *p)
{
  speed_ctx *c = p;
  double d[PRRU_NACT], Jd[PRRU_NACT * 3], dd[PRRU_NACT];
  prru_model_ik_jd(&model, s->q, d, Jd);
  int over = 0;
  for (int i = 0; i < PRRU_NACT; i++) {
    dd[i] = Jd[3 * i] * s->qd[0] + Jd[3 * i + 1] * s->qd[1] + Jd[3 * i + 2] * s->qd[2];
    c->max_dd[i] = fmax(c->max_dd[i], fabs(dd[i]));
    over |= fabs(dd[i]) > c->speed_max[i];
    const double size =
        fabs(Jd[3 * i] * s->qd[0]) + fabs(Jd[3 * i + 1] * s->qd[1]) + fabs(Jd[3 * i + 2] * s->qd[2]);
    c->max_size[i] = fmax(c->max_size[i], size);
    c->worst = fmax(c->worst, size > 0 ? fabs(s->dd[i] - dd[i]) / (DBL_EPSILON * size)
                                       : (s->dd[i] == 0 ? 0 : INFINITY));
  }
  c->over += over;
  c->samples++;
  return 0;
}

static void slider_speeds(void)
{
  prru_track_options o;
  prru_track_options_default(&model, &o);
  /* Off the reference and a heavier plant: the speeds are the plant's
   * state's, not the reference's. */
  prru_params_scale(&o.plant, "mass", 1.2);
  o.q0_offset[0] = 0.01;
  speed_ctx c;
  memset(&c, 0, sizeof c);
  for (int i = 0; i < PRRU_NACT; i++) c.speed_max[i] = o.speed_max[i];
  o.on_sample = speed_check;
  o.ctx = &c;
  prru_track_summary s;
  char msg[512];
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_OK, msg);
  tu_check(c.worst <= 256, "sample dd = J_d qd, in u sum_k |J_d,ik qd_k|", c.worst, 256);
  printf("slider speeds: %.2f u of |J_d| |qd| at worst\n", c.worst);
  /* The maxima of two sequences that differ sample by sample by at most
   * 256 u of that sample's size differ by at most 256 u of the largest
   * size. */
  int same = 1;
  for (int i = 0; i < PRRU_NACT; i++)
    same &= fabs(s.max_dd[i] - c.max_dd[i]) <= 256 * DBL_EPSILON * c.max_size[i];
  TU_TRUE(same, "max_dd = max over the samples of |J_d qd|");
  TU_TRUE(s.over_speed == 0 && c.over == 0, "no speed limit: nothing over it");
  /* Limits at half of each slider's peak speed: counted where any slider
   * is over its own, and reported, not enforced (the same run). */
  prru_track_summary s2;
  memset(&c, 0, sizeof c);
  for (int i = 0; i < PRRU_NACT; i++) o.speed_max[i] = c.speed_max[i] = 0.5 * s.max_dd[i];
  TU_TRUE(prru_track(&model, &ref, &o, &s2, msg, sizeof msg) == PRRU_OK, msg);
  printf("speed limits at half the peaks: %ld of %ld samples over\n", s2.over_speed, s2.samples);
  TU_TRUE(s2.over_speed == c.over && c.samples == s2.samples && s2.over_speed > 0 &&
              s2.over_speed < s2.samples,
          "over_speed counts the samples with a slider over its limit");
  TU_TRUE(memcmp(s2.max_dd, s.max_dd, PRRU_NACT * sizeof(double)) == 0 && memcmp(s2.max_e, s.max_e, sizeof s.max_e) == 0,
          "a speed limit changes nothing in the run");
  o.speed_max[1] = 0;
  TU_TRUE(prru_track_options_check(&model, &o, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "speed limit of actuator 2"),
          "zero speed limit refused");
}

static void option_checks(void)
{
  prru_track_options o, d;
  char msg[512] = "stale";
  prru_track_options_default(&model, &o);
  TU_TRUE(prru_track_options_check(&model, &o, msg, sizeof msg) == PRRU_OK && msg[0] == '\0', "defaults pass");
  /* The bandwidth rule: the defaults are w = 20; bad w leaves o alone. */
  prru_track_options_default(&model, &d);
  TU_TRUE(prru_track_gains_bandwidth(20.0, &o) == PRRU_OK && memcmp(&o, &d, sizeof o) == 0,
          "default gains = bandwidth 20 rad/s");
  TU_TRUE(memcmp(&d.plant, &prru_params_model, sizeof d.plant) == 0,
          "the default plant is the model's numbers");
  /* Only the model's actuators' entries are checked: one past them may
   * hold anything. */
  if (model.mech->nact < PRRU_MAX_ACT) {
    d.f_max[PRRU_MAX_ACT - 1] = 0;
    d.d_min[PRRU_MAX_ACT - 1] = d.d_max[PRRU_MAX_ACT - 1] = NAN;
    TU_TRUE(prru_track_options_check(&model, &d, msg, sizeof msg) == PRRU_OK, "entries past nact not read");
  }
  TU_TRUE(prru_track_gains_bandwidth(7.0, &o) == PRRU_OK && o.kp[0] == 49.0 && o.kp[2] == 49.0 &&
              o.kd[0] == 14.0 && o.kd[1] == 14.0,
          "bandwidth 7: kp = 49, kd = 14");
  const double bad[] = {0.0, -1.0, NAN, INFINITY, 1e200};
  int refused = 1;
  for (int k = 0; k < 5; k++) refused &= prru_track_gains_bandwidth(bad[k], &o) == PRRU_EINPUT && o.kp[1] == 49.0;
  TU_TRUE(refused, "bandwidth not > 0 or with infinite gains refused, gains kept");
  /* The names a front end replaces (prru_control.h). */
  prru_track_options_default(&model, &o);
  o.noise_qd = 1e-3;
  TU_TRUE(prru_track_options_check(&model, &o, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "sensor noise needs control period > 0"),
          "noise needs a control period");
  prru_track_options_default(&model, &o);
  o.controller = PRRU_TRACK_LQR;
  TU_TRUE(prru_track_options_check(&model, &o, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "controller PRRU_TRACK_LQR needs control period > 0"),
          "LQR needs a control period");
  o.control_period = 1e-2;
  o.rel_tol = 1e-15;
  TU_TRUE(prru_track_options_check(&model, &o, msg, sizeof msg) == PRRU_EINPUT &&
              strncmp(msg, "rel_tol: ", 9) == 0,
          "tolerance below PRRU_TOL_MIN refused");
  /* One rule for all-zero weights: the defaults, Q and R alike. */
  o.rel_tol = 1e-12;
  TU_TRUE(prru_track_options_check(&model, &o, msg, sizeof msg) == PRRU_OK && msg[0] == '\0',
          "LQR weights all 0 accepted");
  prru_lqr_schedule sch;
  double q[6], r[PRRU_NACT];
  TU_TRUE(prru_lqr_default_weights(&model, &ref, o.control_period, q, r, msg, sizeof msg) == PRRU_OK, msg);
  TU_TRUE(prru_lqr_schedule_build(&model, &ref, &o, &sch, msg, sizeof msg) == PRRU_OK, msg);
  TU_TRUE(memcmp(sch.q, q, sizeof q) == 0 && memcmp(sch.r, r, sizeof r) == 0,
          "all-zero weights are prru_lqr_default_weights'");
  TU_TRUE(sch.nact == model.mech->nact, "the schedule records the model's actuators");
  prru_lqr_schedule_free(&sch);
}

/* ---- LQR ---- */

static double frob(const double *a, int n)
{
  double s = 0;
  for (int i = 0; i < n; i++) s += a[i] * a[i];
  return sqrt(s);
}

/* C = A^T B (A: r x m, B: r x c, row-major), or A B when trans is 0
 * (A: m x r). */
static void matmul(int trans, const double *A, const double *B, int m, int r, int c, double *C)
{
  for (int i = 0; i < m; i++)
    for (int j = 0; j < c; j++) {
      double s = 0;
      for (int k = 0; k < r; k++) s += (trans ? A[k * m + i] : A[i * r + k]) * B[k * c + j];
      C[i * c + j] = s;
    }
}

/* A reference holding pose q at rest over span seconds. */
static void hold_reference(prru_quintic *tr, const double q[3], double span)
{
  double t[2] = {0, span}, qq[6], z[6] = {0};
  memcpy(qq, q, 3 * sizeof *q);
  memcpy(qq + 3, q, 3 * sizeof *q);
  char msg[256];
  TU_TRUE(prru_quintic_samples(tr, 2, t, qq, z, z, msg, sizeof msg) == PRRU_OK, msg);
}

/* The DARE residual at the schedule's P_0 relative to its rounding bound
 * (see lqr_stationary), and the spectral radius of A - B K_0. */
static void dare_check(const prru_lqr_schedule *s, const double A[36], const double B[6 * PRRU_NACT],
                       double *ratio, double *rho)
{
  enum { N = PRRU_NACT };
  const double *P = s->P0, *K = s->K;
  double PA[36], PB[6 * N], S[N * N], BtPA[N * 6], X[N * 6], AtPA[36], AtPB[6 * N], R[36];
  matmul(0, P, A, 6, 6, 6, PA);
  matmul(0, P, B, 6, 6, N, PB);
  matmul(1, B, PB, N, 6, N, S);
  for (int i = 0; i < N; i++) S[i * N + i] += s->r[i];
  matmul(1, B, PA, N, 6, 6, BtPA);
  matmul(1, A, PA, 6, 6, 6, AtPA);
  matmul(1, A, PB, 6, 6, N, AtPB);
  /* The condition of S (2-norm, from its eigenvalues), before the solve
   * overwrites it. */
  double Sc[N * N], ev[N];
  memcpy(Sc, S, sizeof Sc);
  gsl_matrix_view sc = gsl_matrix_view_array(Sc, N, N);
  gsl_vector_view evv = gsl_vector_view_array(ev, N);
  gsl_eigen_symm_workspace *ws = gsl_eigen_symm_alloc(N);
  gsl_eigen_symm(&sc.matrix, &evv.vector, ws);
  gsl_eigen_symm_free(ws);
  double emin = INFINITY, emax = 0;
  for (int i = 0; i < N; i++) emin = fmin(emin, ev[i]), emax = fmax(emax, ev[i]);
  gsl_matrix_view sv = gsl_matrix_view_array(S, N, N), bv = gsl_matrix_view_array(BtPA, N, 6),
                  xv = gsl_matrix_view_array(X, N, 6);
  gsl_linalg_cholesky_decomp1(&sv.matrix);
  gsl_linalg_cholesky_solve_mat(&sv.matrix, &bv.matrix, &xv.matrix);
  double BX[36]; /* A^T P B S^-1 B^T P A */
  matmul(0, AtPB, X, 6, N, 6, BX);
  double Q[36] = {0};
  for (int i = 0; i < 6; i++) Q[i * 6 + i] = s->q[i];
  for (int i = 0; i < 36; i++) R[i] = Q[i] + AtPA[i] - BX[i] - P[i];
  double ABK[36], BK[36];
  matmul(0, B, K, 6, N, 6, BK);
  for (int i = 0; i < 36; i++) ABK[i] = A[i] - BK[i];
  double ev_re[6], ev_im[6];
  gsl_matrix_view abk = gsl_matrix_view_array(ABK, 6, 6);
  gsl_vector_complex *eval = gsl_vector_complex_alloc(6);
  gsl_eigen_nonsymm_workspace *wn = gsl_eigen_nonsymm_alloc(6);
  gsl_eigen_nonsymm(&abk.matrix, eval, wn);
  *rho = 0;
  for (int i = 0; i < 6; i++) {
    ev_re[i] = GSL_REAL(gsl_vector_complex_get(eval, i));
    ev_im[i] = GSL_IMAG(gsl_vector_complex_get(eval, i));
    *rho = fmax(*rho, hypot(ev_re[i], ev_im[i]));
  }
  gsl_eigen_nonsymm_free(wn);
  gsl_vector_complex_free(eval);
  /* Rounding of one Riccati step (6 x 6 and 6 x NACT products, sums of
   * at most 6 terms, two chained: gamma_12 = 12 u each; the Cholesky
   * solve's relative error kappa(S) u in K, carried by A^T P B), in the
   * recursion and again in this evaluation, 32 u for both; a contracting
   * recursion gathers up to 1 / (1 - rho^2) steps' rounding at its fixed
   * point (each step multiplies an earlier error by about rho^2). The
   * residual seen is far below this (1e-5 of it on the paper's model):
   * this evaluation repeats the recursion's operations on nearly the same
   * numbers, so most of its rounding repeats too; an unconverged P is
   * 1e3 and more above it (checked below). */
  const double u = 0x1p-53;
  double nA = frob(A, 36), nB = frob(B, 6 * N), nP = frob(P, 36), nK = frob(K, 6 * N);
  double bound = 32 * u * (frob(Q, 36) + nA * nA * nP + nA * nP * nB * nK * (emax / emin)) /
                 (1 - *rho * *rho);
  *ratio = frob(R, 36) / bound;
}

static void lqr_stationary(void)
{
  /* The raised, tilted pose of the move, held 2 s with a 2 ms period: 1000
   * ticks; the recursion contracts by rho^2 ~ exp(-2 w Tc) = 0.92 per
   * tick (w 20 rad/s), so P_n = Q is forgotten to exp(-80) at tick 0. */
  const double q[3] = {0.1, -0.08, 0.02}, period = 2e-3;
  prru_quintic hold;
  hold_reference(&hold, q, 2.0);
  prru_track_options o;
  prru_track_options_default(&model, &o);
  o.controller = PRRU_TRACK_LQR;
  o.control_period = period;
  prru_lqr_schedule s;
  char msg[512];
  TU_TRUE(prru_lqr_schedule_build(&model, &hold, &o, &s, msg, sizeof msg) == PRRU_OK, msg);
  TU_TRUE(s.n == 1001, "1001 ticks over 2 s at 2 ms");
  prru_data *d = malloc(sizeof *d);
  prru_linearization *lin = malloc(sizeof *lin);
  prru_loads l;
  memset(&l, 0, sizeof l);
  memcpy(l.fd, s.u_ff, PRRU_NACT * sizeof(double));
  double qd0[3] = {0, 0, 0};
  TU_TRUE(prru_linearize(&model, d, q, qd0, &l, period, lin) == PRRU_OK, "linearise the held pose");
  double ratio, rho;
  dare_check(&s, lin->Ad, lin->Bd, &ratio, &rho);
  /* The recursion forgets P_n = Q like rho^2 a tick: where the slowest
   * closed-loop mode is slow (a damped prototype: rho 0.997 at 2 ms, not
   * the 0.96 of a critically damped 20 rad/s), hold the pose long enough
   * for rho^(2 n) < 1e-16 (at most 60 s) and check that schedule. */
  if (rho < 1 && pow(rho, 2.0 * (double)(s.n - 1)) > 1e-16) {
    const double ticks = ceil(log(1e-16) / (2 * log(rho)));
    prru_lqr_schedule_free(&s);
    prru_quintic_free(&hold);
    hold_reference(&hold, q, fmin(ticks, 30000) * period);
    TU_TRUE(prru_lqr_schedule_build(&model, &hold, &o, &s, msg, sizeof msg) == PRRU_OK, msg);
    dare_check(&s, lin->Ad, lin->Bd, &ratio, &rho);
  }
  printf("LQR on a held pose (%ld ticks): DARE residual at P_0 = %.3g of its rounding bound; spectral "
         "radius of A - B K_0 = %.6f (exp(-w Tc) = %.6f)\n", s.n, ratio, rho, exp(-20 * period));
  tu_check(ratio <= 1, "Riccati recursion converged to the DARE solution (rounding)", ratio, 1);
  tu_check(rho < 1, "closed loop A - B K_0 stable", rho, 1);
  /* The check can fail: 20 ticks before the end the recursion is still
   * far from the stationary solution. */
  prru_quintic brief;
  hold_reference(&brief, q, 19 * period);
  prru_lqr_schedule b;
  TU_TRUE(prru_lqr_schedule_build(&model, &brief, &o, &b, msg, sizeof msg) == PRRU_OK, msg);
  double ratio_b, rho_b;
  dare_check(&b, lin->Ad, lin->Bd, &ratio_b, &rho_b);
  tu_check(ratio_b > 1e3, "a 20-tick recursion is detected as not converged", ratio_b, 1e3);
  prru_lqr_schedule_free(&b);
  prru_quintic_free(&brief);
  prru_lqr_schedule_free(&s);
  prru_quintic_free(&hold);
  free(d);
  free(lin);
}

typedef struct {
  double tmin, worst;
} late_ctx;

static int late_error(const prru_track_sample *s, void *p)
{
  late_ctx *c = p;
  if (s->t >= c->tmin)
    for (int i = 0; i < 3; i++) c->worst = fmax(c->worst, fabs(s->e[i]));
  return 0;
}

/* The largest acceleration a held force lacks over one tick: the
 * feed-forward forces (inverse dynamics along the reference, drives'
 * damping and Coulomb friction included) change by dfd over a period,
 * which the plant turns into dqdd/dfd dfd (prru_linearize at the
 * reference). Without drives that is the reference's jerk times the
 * period; with them the friction's rate adds (Coulomb's f / v_s times the
 * sliders' acceleration, steep for a small v_s). Every 0.1 ms of the
 * reference. */
static double hold_deficit(double period)
{
  prru_data *d = malloc(sizeof *d);
  prru_linearization *lin = malloc(sizeof *lin);
  prru_loads l;
  memset(&l, 0, sizeof l);
  double worst = 0, t_end = ref.t[ref.n - 1];
  for (double t = ref.t[0]; t + period <= t_end; t += 1e-4) {
    double q0[3], qd0[3], a0[3], q1[3], qd1[3], a1[3], f0[PRRU_NACT], f1[PRRU_NACT], dq[3];
    prru_quintic_eval(&ref, t, q0, qd0, a0);
    prru_quintic_eval(&ref, t + period, q1, qd1, a1);
    if (prru_inverse_dynamics(&model, d, q0, qd0, a0, &l, f0) != PRRU_OK ||
        prru_inverse_dynamics(&model, d, q1, qd1, a1, &l, f1) != PRRU_OK)
      continue;
    memcpy(l.fd, f0, PRRU_NACT * sizeof(double));
    if (prru_linearize(&model, d, q0, qd0, &l, 0.0, lin) != PRRU_OK) continue;
    memset(l.fd, 0, sizeof l.fd);
    for (int i = 0; i < 3; i++) {
      dq[i] = 0;
      for (int k = 0; k < PRRU_NACT; k++) dq[i] += lin->dqdd_dfd[PRRU_NACT * i + k] * (f1[k] - f0[k]);
      worst = fmax(worst, fabs(dq[i]));
    }
  }
  free(d);
  free(lin);
  return worst;
}

static double max3(const double v[3])
{
  return fmax(v[0], fmax(v[1], v[2]));
}

static void lqr_tracking(void)
{
  const double period = 1e-3, w = 20;
  prru_track_options o;
  prru_track_options_default(&model, &o);
  o.control_period = period;
  prru_track_summary ct, lqr;
  char msg[512];
  TU_TRUE(prru_track(&model, &ref, &o, &ct, msg, sizeof msg) == PRRU_OK, msg);
  o.controller = PRRU_TRACK_LQR;
  TU_TRUE(prru_track(&model, &ref, &o, &lqr, msg, sizeof msg) == PRRU_OK, msg);
  TU_TRUE(lqr.samples == ct.samples && lqr.samples == 2001, "LQR: one sample per tick");
  /* Exact plant, started on the reference: the only error is the hold's.
   * The held force lags the needed one by half a tick on average, an
   * acceleration deficit of about a / 2 (a: hold_deficit, the change over
   * a tick; jerk Tc without drives), which a loop critically damped at w
   * turns into at most a / (2 w^2) (the impulse response t e^(-w t)
   * integrates to 1 / w^2); a factor 2 for the transient and the LQR's
   * coupled, not exactly critically damped, gains: a / w^2 for either
   * controller. */
  double a = hold_deficit(period), bound = a / (w * w);
  double ect = max3(ct.max_e), elqr = max3(lqr.max_e);
  printf("exact plant, %g ms hold: max |e| computed torque %.3e, LQR %.3e (bound a / w^2 = "
         "%.3e, a = %.4g rad/s^2 lacking over a tick)\n", period * 1e3, ect, elqr, bound, a);
  tu_check(ect <= bound, "computed torque within the hold's error", ect, bound);
  tu_check(elqr <= bound, "LQR within the hold's error", elqr, bound);
  tu_check(fabs(elqr - ect) <= bound, "LQR tracks as computed torque does", fabs(elqr - ect), bound);
  double fct = 0, flqr = 0;
  for (int i = 0; i < PRRU_NACT; i++) fct = fmax(fct, ct.max_fd[i]), flqr = fmax(flqr, lqr.max_fd[i]);
  printf("  peak force: computed torque %.6g N, LQR %.6g N\n", fct, flqr);
  TU_TRUE(fabs(flqr - fct) <= 1e-3 * fct, "the same feed-forward forces (to 0.1 %)");
  /* The cost of the schedule (reported, not checked: the machine's). */
  prru_lqr_schedule sch;
  clock_t c0 = clock();
  TU_TRUE(prru_lqr_schedule_build(&model, &ref, &o, &sch, msg, sizeof msg) == PRRU_OK, msg);
  double per_tick = (double)(clock() - c0) / CLOCKS_PER_SEC / (double)sch.n;
  printf("  LQR schedule: %ld ticks, %.1f us per tick\n", sch.n, per_tick * 1e6);
  /* The closed loop's slowest mode at the start: rho, the spectral radius
   * of A - B K_0 (the zero-order-hold pair at the reference's start). */
  double rho = 0, unused, q0[3], qd0[3];
  prru_quintic_eval(&ref, ref.t[0], q0, qd0, NULL);
  prru_data *dd = malloc(sizeof *dd);
  prru_linearization *lin = malloc(sizeof *lin);
  prru_loads l0;
  memset(&l0, 0, sizeof l0);
  memcpy(l0.fd, sch.u_ff, sizeof l0.fd);
  if (TU_TRUE(prru_linearize(&model, dd, q0, qd0, &l0, period, lin) == PRRU_OK, "linearise the start"))
    dare_check(&sch, lin->Ad, lin->Bd, &unused, &rho);
  free(dd);
  free(lin);
  prru_lqr_schedule_free(&sch);
  /* Started off the reference: the error decays. By 0.4 s (w t = 8) a
   * critically damped loop keeps (1 + w t) e^(-w t) = 3e-3 of the offset;
   * allow 1e-2 (coupling, discrete gains), or where the LQR's slowest mode
   * is slower (a damped prototype), 10 rho^(0.4 s / Tc) (10: the coupled
   * loop's transient), plus the hold's error. */
  const double e0[3] = {0.01, -0.008, 0.002};
  memcpy(o.q0_offset, e0, sizeof e0);
  late_ctx c = {0.4, 0};
  o.on_sample = late_error;
  o.ctx = &c;
  int st = prru_track(&model, &ref, &o, &lqr, msg, sizeof msg);
  TU_TRUE(st == PRRU_OK, msg);
  double late_bound = fmax(1e-2, 10 * pow(rho, 0.4 / period)) * max3(e0) + bound;
  printf("LQR from a %g offset: max |e| after 0.4 s = %.3e (bound %.3e)\n", max3(e0), c.worst,
         late_bound);
  tu_check(st == PRRU_OK && c.worst <= late_bound, "LQR: an initial offset decays", c.worst, late_bound);
  tu_check(lqr.max_e[0] >= 0.99 * e0[0], "the offset was there", lqr.max_e[0], 0.99 * e0[0]);
}

/* A gain of the wrong sign or layout does not decay an offset: the law
 * must read K_k as NACT x 6 row-major, with u = u_ff - K dx. */
static void lqr_wrong_gain(void)
{
  const double q[3] = {0.1, -0.08, 0.02};
  prru_quintic hold;
  hold_reference(&hold, q, 1.0);
  prru_track_options o;
  prru_track_options_default(&model, &o);
  o.controller = PRRU_TRACK_LQR;
  o.control_period = 1e-3;
  prru_lqr_schedule s;
  char msg[512];
  TU_TRUE(prru_lqr_schedule_build(&model, &hold, &o, &s, msg, sizeof msg) == PRRU_OK, msg);
  /* One tick of the law on a state 1 mm / 1 mrad off in q1: the force
   * change is -K column 1 (row-major NACT x 6). */
  double x[6], fc[PRRU_NACT], f[PRRU_NACT];
  int sat[PRRU_NACT];
  memcpy(x, s.x_ref, sizeof x);
  x[0] += 1e-3;
  TU_TRUE(prru_lqr_control(&s, 0, &o, x, fc, f, sat) == PRRU_OK, "LQR law");
  double worst = 0;
  for (int i = 0; i < PRRU_NACT; i++)
    worst = fmax(worst, fabs((fc[i] - s.u_ff[i]) - (-s.K[6 * i] * 1e-3)) / fabs(s.K[6 * i] * 1e-3));
  tu_check(worst <= 1e-9, "LQR law: u = u_ff - K (x - x_ref)", worst, 1e-9);
  TU_TRUE(prru_lqr_control(&s, s.n, &o, x, fc, f, sat) == PRRU_EINPUT, "tick out of range refused");
  prru_lqr_schedule_free(&s);
  prru_quintic_free(&hold);
}

static void lqr_refusals(void)
{
  prru_track_options o;
  prru_track_summary s;
  char msg[512];
  prru_track_options_default(&model, &o);
  o.controller = PRRU_TRACK_LQR;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "control period"),
          "LQR without a control period refused");
  o.control_period = 1e-3;
  o.lqr_q[4] = -1;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "lqr_q: weight 5"),
          "negative Q refused");
  o.lqr_q[4] = NAN;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "lqr_q"),
          "NaN Q refused");
  o.lqr_q[4] = 0;
  for (int i = 0; i < PRRU_NACT; i++) o.lqr_r[i] = 1e-4;
  o.lqr_r[PRRU_NACT - 1] = 0;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "lqr_r: weight"),
          "zero R (not all) refused");
  o.lqr_r[PRRU_NACT - 1] = INFINITY;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "lqr_r"),
          "infinite R refused");
  o.controller = 7;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "controller"),
          "unknown controller refused");
  /* A reference that leaves the workspace: the schedule fails at the
   * first tick whose pose has no dynamics, naming its time. */
  prru_track_options_default(&model, &o);
  o.controller = PRRU_TRACK_LQR;
  o.control_period = 1e-2;
  const double wp[6] = {0, 0, 0, 1.5, 0, 0};
  const double dur[1] = {1};
  prru_quintic far;
  TU_TRUE(prru_quintic_waypoints(&far, 2, wp, dur, 0.0, msg, sizeof msg) == PRRU_OK, msg);
  int st = prru_track(&model, &far, &o, &s, msg, sizeof msg);
  printf("LQR on a reference out of the workspace: %s\n", msg);
  TU_TRUE((st == PRRU_EUNREACHABLE || st == PRRU_ESINGULAR) && strstr(msg, "LQR schedule: tick") &&
              strstr(msg, "t = ") && s.samples == 0,
          "a tick the model cannot linearise fails the run, named");
  prru_quintic_free(&far);
}

int main(void)
{
  prru_model_default(&model);
  char msg[256];
  if (prru_quintic_waypoints(&ref, 3, WP, DUR, 0.0, msg, sizeof msg) != PRRU_OK) {
    fprintf(stderr, "%s\n", msg);
    return 1;
  }
  prru_data *d = malloc(sizeof *d);
  plant_is_model(d);
  free(d);
  exact_tracking();
  error_dynamics();
  mismatch();
  noise_deterministic();
  saturation();
  stroke();
  stroke_between_samples();
  refusals();
  slider_speeds();
  option_checks();
  lqr_stationary();
  lqr_tracking();
  lqr_wrong_gain();
  lqr_refusals();
  prru_quintic_free(&ref);
  return tu_finish("test_control");
}
