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
 * with the option named. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru_control.h"
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
  prru_track_options_default(&o);
  for (int k = 0; k < 200; k++) {
    double q[3] = {tu_uniform(-0.15, 0.15), tu_uniform(-0.12, 0.12), tu_uniform(-0.03, 0.03)};
    double qd[3] = {tu_uniform(-1, 1), tu_uniform(-1, 1), tu_uniform(-0.2, 0.2)};
    prru_loads l;
    memset(&l, 0, sizeof l);
    for (int i = 0; i < PRRU_NACT; i++) l.fd[i] = tu_uniform(-80, 80);
    double a[3], b[3];
    if (prru_forward_dynamics(&model, d, q, qd, &l, a) != PRRU_OK) continue;
    TU_TRUE(prru_plant_accel(&prru_params_model, q, qd, l.fd, b) == PRRU_OK, "plant accel");
    worst = fmax(worst, tu_relerr(b, a, 3, 1.0));
    /* The controller's forces, unclipped, give the plant the commanded
     * acceleration qdd_ref + Kd (qd_ref - qd) + Kp (q_ref - q). */
    double qr[3] = {0.02, -0.01, 0.005}, qdr[3] = {0.1, 0.2, -0.05}, qddr[3] = {1, -2, 0.5};
    double fc[PRRU_NACT], f[PRRU_NACT], acc[3], want[3];
    int sat[PRRU_NACT];
    TU_TRUE(prru_computed_torque(&model, d, &o, qr, qdr, qddr, q, qd, fc, f, sat) == PRRU_OK,
            "computed torque");
    prru_plant_accel(&prru_params_model, q, qd, f, acc);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
  prru_params plant = prru_params_model;
  prru_params_scale(&plant, "mass", 1.1);
  prru_data *d = malloc(sizeof *d);
  double sup = 0;
  for (int k = 0; k <= 2000; k++) {
    double qr[3], qdr[3], qddr[3], fc[PRRU_NACT], f[PRRU_NACT], a[3];
    int sat[PRRU_NACT];
    prru_quintic_eval(&ref, k * 1e-3, qr, qdr, qddr);
    prru_computed_torque(&model, d, &o, qr, qdr, qddr, qr, qdr, fc, f, sat);
    prru_plant_accel(&plant, qr, qdr, f, a);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
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
  prru_track_options_default(&o);
  o.kp[1] = -1;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT && strstr(msg, "kp"),
          "negative kp refused");
  prru_track_options_default(&o);
  o.f_max[0] = 0;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "force limit of actuator 1"),
          "zero force limit refused");
  prru_track_options_default(&o);
  o.d_min[2] = 0.1;
  o.d_max[2] = 0.1;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "stroke of slider 3"),
          "empty stroke refused");
  prru_track_options_default(&o);
  o.noise_q = 1e-6;
  TU_TRUE(prru_track(&model, &ref, &o, &s, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "control period"),
          "noise with a continuous controller refused");
  TU_TRUE(prru_params_scale(&o.plant, "masses", 1.1) == PRRU_EINPUT &&
              prru_params_scale(&o.plant, "mass", 0) == PRRU_EINPUT &&
              prru_params_scale(&o.plant, "mass", NAN) == PRRU_EINPUT,
          "unknown mismatch key or bad factor refused");
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
  prru_quintic_free(&ref);
  return tu_finish("test_control");
}
