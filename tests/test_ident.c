/* Regressor, base parameters and identification (prru_regressor.h,
 * prru_ident.h) of whatever model the build uses:
 *  - Y pi = M qdd + h - G - passive to 1e-12 at 500 random states, pi the
 *    model's standard parameters, against the constant dynamics kernels;
 *  - the same at 40 random parameter sets (masses, centres of mass, full
 *    inertia tensors, drives, all perturbed) against the runtime-parameter
 *    kernels given the same numbers: linearity in m, m c and I_O holds for
 *    every parameter, not only the model's zeros;
 *  - the runtime's conversion (prru_ident_standard) = the generator's exact
 *    one (prru_regressor_model), and prru_ident_body inverts it;
 *  - base parameters: Y pi = Y_base (B pi) to 1e-12 for random pi at states
 *    not used to find B; the number of base parameters is the same with
 *    twice the states and another seed; prru_base_to_standard gives B pi =
 *    beta;
 *  - identification from inverse-dynamics data along prru_excite's
 *    excitation (from the model, and from a perturbed model with the
 *    model as prior):
 *    noise-free, beta to 1e-9 relative; with Gaussian noise of known sigma
 *    on fd, every base parameter within 4 standard errors, the mean
 *    squared normalised error near 1 and the residual sigma near the
 *    noise's; an unreachable sample is named;
 *  - the excitation's defaults (prru_fourier_default,
 *    prru_excite_options_default, check samples 0 = 20 samples) and the
 *    rows of a run (prru_excite_rows) exactly, and at random runs: up to
 *    the end, none a dt past it. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testbuild.h"
#include "prru.h"
#include "prru_control.h"
#include "prru_ident.h"
#include "prru_kernels.h"
#include "prru_param_kernels.h"
#include "testparam.h"
#include "prru_regressor.h"
#include "testutil.h"

#define NSTATE 500
#define NDESIGN 40
#define NB PRRU_NBODY
#define NA PRRU_NACT

static prru_model model;
static prru_data data;
static unsigned long long state_seed = 12345;

static void random_state(double q[3], double qd[3], double qdd[3])
{
  int st = prru_ident_random_state(&model, &data, &state_seed, q, qd, qdd);
  if (st != PRRU_OK) {
    fprintf(stderr, "no random state\n");
    exit(1);
  }
}

static double vs_of(void)
{
  return prru_mech.coulomb_velocity > 0 ? prru_mech.coulomb_velocity : 1.0;
}

static void y_times(const double *Y, const double *pi, double out[3])
{
  for (int r = 0; r < 3; r++) {
    out[r] = 0;
    for (int j = 0; j < PRRU_NREG; j++) out[r] += Y[r * PRRU_NREG + j] * pi[j];
  }
}

static void check_model_params(void)
{
  double pi[PRRU_NREG];
  prru_ident_standard(&prru_mech, pi);
  TU_CLOSE(pi, prru_regressor_model, PRRU_NREG, 4e-16, "runtime standard parameters = generator's");
  double worst = 0;
  for (int b = 0; b < NB; b++) {
    double m, c[3], I[6];
    int st = prru_ident_body(pi + PRRU_NBODYPAR * b, &m, c, I);
    const double Im[6] = {prru_mech.inertia[b][0], prru_mech.inertia[b][4], prru_mech.inertia[b][8],
                          prru_mech.inertia[b][1], prru_mech.inertia[b][2], prru_mech.inertia[b][5]};
    TU_TRUE(st == PRRU_OK, "prru_ident_body accepts the model's bodies");
    double e = fabs(m - prru_mech.mass[b]) / prru_mech.mass[b];
    for (int k = 0; k < 3; k++) e = fmax(e, fabs(c[k] - prru_mech.com[b][k]) / 1.0);
    for (int k = 0; k < 6; k++) e = fmax(e, fabs(I[k] - Im[k]) / fabs(Im[0] + Im[1] + Im[2]));
    worst = fmax(worst, e);
  }
  tu_check(worst < 1e-13, "prru_ident_body inverts prru_ident_standard", worst, 1e-13);
  double bad[PRRU_NBODYPAR] = {0}, m, c[3], I[6];
  TU_TRUE(prru_ident_body(bad, &m, c, I) == PRRU_EINPUT, "a body of mass 0 is refused");
}

static void check_model_dynamics(void)
{
  double pi[PRRU_NREG], worst = 0, vs = vs_of();
  prru_ident_standard(&prru_mech, pi);
  for (int s = 0; s < NSTATE; s++) {
    double q[3], qd[3], qdd[3], Y[3 * PRRU_NREG], M[9], h[3], G[3], Qp[3], tau[3], yp[3];
    random_state(q, qd, qdd);
    prru_regressor(q, qd, qdd, &vs, Y);
    prru_dynamics(q, qd, M, h, G);
    prru_passive(q, qd, Qp);
    for (int i = 0; i < 3; i++)
      tau[i] = M[3 * i] * qdd[0] + M[3 * i + 1] * qdd[1] + M[3 * i + 2] * qdd[2] + h[i] - G[i] - Qp[i];
    y_times(Y, pi, yp);
    worst = fmax(worst, tu_relerr(yp, tau, 3, 1e-300));
  }
  printf("Y pi vs M qdd + h - G - passive, model's parameters, %d states: %.2e\n", NSTATE, worst);
  tu_check(worst <= 1e-12, "Y pi = dynamics at the model's parameters", worst, 1e-12);
}

/* A random parameter set: every inertial and drive number perturbed, in
 * the descriptor (for prru_ident_standard) and in prru_params alike. */
static void random_design(prru_mechanism *me, prru_params *p)
{
  *me = prru_mech;
  *p = prru_params_model;
  for (int b = 0; b < NB; b++) {
    p->mass[b] = me->mass[b] = prru_mech.mass[b] * tu_uniform(0.5, 1.5);
    for (int k = 0; k < 3; k++) p->com[b][k] = me->com[b][k] = tu_uniform(-0.03, 0.03);
    const double base = prru_mech.inertia[b][0] + prru_mech.inertia[b][4] + prru_mech.inertia[b][8];
    double t[6];
    for (int k = 0; k < 3; k++) t[k] = base * tu_uniform(0.2, 0.5);
    for (int k = 3; k < 6; k++) t[k] = base * tu_uniform(-0.05, 0.05);
    const int at[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    for (int k = 0; k < 6; k++) {
      p->inertia[b][k] = t[k];
      me->inertia[b][3 * at[k][0] + at[k][1]] = me->inertia[b][3 * at[k][1] + at[k][0]] = t[k];
    }
  }
  for (int i = 0; i < NA; i++) {
    p->armature[i] = me->armature[i] = tu_uniform(0, 0.5);
    p->damping[i] = me->damping[i] = tu_uniform(0, 30);
    p->coulomb[i] = me->coulomb[i] = tu_uniform(0, 5);
  }
  p->coulomb_velocity = me->coulomb_velocity = tu_uniform(0.002, 0.05);
}

static void check_random_designs(void)
{
  double worst = 0;
  for (int k = 0; k < NDESIGN; k++) {
    prru_mechanism me;
    prru_params p;
    double pi[PRRU_NREG];
    random_design(&me, &p);
    prru_ident_standard(&me, pi);
    for (int s = 0; s < 20; s++) {
      double q[3], qd[3], qdd[3], Y[3 * PRRU_NREG], M[9], h[3], G[3], Qp[3], tau[3], yp[3];
      random_state(q, qd, qdd);
      prru_regressor(q, qd, qdd, &p.coulomb_velocity, Y);
      prru_param_dynamics(tp_derived(&p), q, qd, M, h, G);
      prru_param_passive(tp_derived(&p), q, qd, Qp);
      for (int i = 0; i < 3; i++)
        tau[i] = M[3 * i] * qdd[0] + M[3 * i + 1] * qdd[1] + M[3 * i + 2] * qdd[2] + h[i] - G[i] - Qp[i];
      y_times(Y, pi, yp);
      worst = fmax(worst, tu_relerr(yp, tau, 3, 1e-300));
    }
  }
  printf("Y pi vs runtime-parameter dynamics, %d random parameter sets x 20 states: %.2e\n", NDESIGN, worst);
  tu_check(worst <= 1e-12, "Y pi = dynamics for random parameters", worst, 1e-12);
  double q[3] = {NAN, 0, 0}, qd[3] = {0}, qdd[3] = {0}, Y[3 * PRRU_NREG], vs = 1;
  prru_regressor(q, qd, qdd, &vs, Y);
  int all_nan = 1;
  for (int j = 0; j < 3 * PRRU_NREG; j++) all_nan &= isnan(Y[j]);
  TU_TRUE(all_nan, "regressor: NaN q gives NaN everywhere");
}

static void check_base(prru_base *b)
{
  const double vs = vs_of();
  TU_TRUE(prru_base_compute(&model, vs, 0, 1, b) == PRRU_OK, "base parameters computed");
  prru_base *b2 = malloc(sizeof *b2);
  TU_TRUE(b2 && prru_base_compute(&model, vs, 2 * PRRU_BASE_STATES, 7, b2) == PRRU_OK,
          "base parameters with twice the states");
  printf("base parameters: %d of %d (pivot gap %.1e kept / %.1e dropped); %d with %d states, seed 7\n",
         b->nbase, PRRU_NREG, b->last_kept, b->first_dropped, b2->nbase, b2->nstates);
  TU_TRUE(b2->nbase == b->nbase, "the number of base parameters does not change with more states");
  TU_TRUE(b->nreg == PRRU_NREG && b->nbody == PRRU_NBODY && b->nact == PRRU_NACT,
          "the base holds the model's counts");
  int names_same = prru_base_param_name(b, -1) == NULL && prru_base_param_name(b, PRRU_NREG) == NULL;
  for (int j = 0; j < PRRU_NREG; j++) {
    const char *nm = prru_base_param_name(b, j);
    names_same &= nm && strcmp(nm, prru_regressor_names[j]) == 0;
  }
  TU_TRUE(names_same, "prru_base_param_name: the generated regressor's column names");
  tu_check(b->first_dropped < 1e-12 && b->last_kept > 1e-6, "a clear gap at the rank cut",
           b->first_dropped, 1e-12);
  free(b2);
  double worst = 0, worst_std = 0;
  for (int k = 0; k < 20; k++) {
    double pi[PRRU_NREG], beta[PRRU_NREG], pi2[PRRU_NREG], beta2[PRRU_NREG];
    for (int j = 0; j < PRRU_NREG; j++) pi[j] = tu_uniform(-1, 1);
    prru_base_params(b, pi, beta);
    for (int s = 0; s < 10; s++) {
      double q[3], qd[3], qdd[3], Y[3 * PRRU_NREG], Yb[3 * PRRU_NREG], yp[3], yb[3];
      random_state(q, qd, qdd);
      prru_regressor(q, qd, qdd, &vs, Y);
      prru_base_regressor(b, Y, 3, Yb);
      y_times(Y, pi, yp);
      for (int r = 0; r < 3; r++) {
        yb[r] = 0;
        for (int i = 0; i < b->nbase; i++) yb[r] += Yb[r * b->nbase + i] * beta[i];
      }
      worst = fmax(worst, tu_relerr(yb, yp, 3, 1e-300));
    }
    double pi0[PRRU_NREG];
    for (int j = 0; j < PRRU_NREG; j++) pi0[j] = tu_uniform(-1, 1);
    prru_base_to_standard(b, beta, pi0, pi2);
    prru_base_params(b, pi2, beta2);
    worst_std = fmax(worst_std, tu_relerr(beta2, beta, b->nbase, 1e-300));
  }
  printf("Y pi vs Y_base beta, random pi at fresh states: %.2e; B(base_to_standard(beta)) vs beta: %.2e\n",
         worst, worst_std);
  tu_check(worst <= 1e-12, "Y pi = Y_base B pi", worst, 1e-12);
  tu_check(worst_std <= 1e-12, "B pi' = beta for pi' = prru_base_to_standard(beta)", worst_std, 1e-12);
}

static double gauss(void)
{
  double u = tu_uniform(1e-300, 1), v = tu_uniform(0, 1);
  return sqrt(-2 * log(u)) * cos(2 * 3.14159265358979323846 * v);
}

/* n samples of an excitation, fd by inverse dynamics (+ noise sigma). */
/* n samples of an excitation with fd from the dynamics of *truth (the
 * runtime-parameter kernels; the model's own numbers when NULL), plus
 * Gaussian noise sigma. */
static const prru_params *truth;
/* The optimised excitation of check_excite (a hand-made one until then). */
static prru_fourier excitation;

static void hand_excitation(void)
{
  prru_fourier *f = &excitation;
  memset(f, 0, sizeof *f);
  f->period = 4;
  f->harmonics = 4;
  const double L = prru_mech.l1[0];
  for (int l = 0; l < 4; l++) {
    f->a[0][l] = 0.05 / (l + 1), f->b[0][l] = 0.03 * (l % 2 ? 1 : -1) / (l + 1);
    f->a[1][l] = -0.04 / (l + 1), f->b[1][l] = 0.05 / (l + 1.5);
    f->a[2][l] = 0.04 * L / (l + 1), f->b[2][l] = -0.03 * L / (l + 1);
  }
}

static int make_data(int n, double sigma, double *q, double *qd, double *qdd, double *fd)
{
  const prru_fourier f = excitation;
  const prru_params *p = truth ? truth : &prru_params_model;
  for (int s = 0; s < n; s++) {
    double *x = q + 3 * s, *v = qd + 3 * s, *a = qdd + 3 * s, M[9], h[3], G[3], Qp[3], tau[3];
    prru_fourier_eval(&f, f.period * s / n, x, v, a);
    if (prru_check_regular(&model, &data, x, NULL) != PRRU_OK) return 1;
    prru_param_dynamics(tp_derived(p), x, v, M, h, G);
    prru_param_passive(tp_derived(p), x, v, Qp);
    for (int i = 0; i < 3; i++) tau[i] = M[3 * i] * a[0] + M[3 * i + 1] * a[1] + M[3 * i + 2] * a[2] + h[i] - G[i] - Qp[i];
    /* J_d^T fd = tau, fd = J_d^+T tau. */
    for (int i = 0; i < NA; i++) {
      fd[NA * s + i] = sigma * gauss();
      for (int k = 0; k < 3; k++) fd[NA * s + i] += data.Jdpinv[k * NA + i] * tau[k];
    }
  }
  return 0;
}

/* The standard parameters of a parameter set (the mechanism's layout). */
static void standard_of(const prru_params *p, double pi[PRRU_NREG])
{
  prru_mechanism me = prru_mech;
  memcpy(me.mass, p->mass, sizeof me.mass);
  memcpy(me.com, p->com, sizeof me.com);
  const int at[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < NB; k++)
    for (int e = 0; e < 6; e++)
      me.inertia[k][3 * at[e][0] + at[e][1]] = me.inertia[k][3 * at[e][1] + at[e][0]] = p->inertia[k][e];
  memcpy(me.armature, p->armature, sizeof me.armature);
  memcpy(me.damping, p->damping, sizeof me.damping);
  memcpy(me.coulomb, p->coulomb, sizeof me.coulomb);
  prru_ident_standard(&me, pi);
}

static void check_identify(const prru_base *b)
{
  enum { N = 2000 };
  double *q = malloc(sizeof(double) * 3 * N), *qd = malloc(sizeof(double) * 3 * N);
  double *qdd = malloc(sizeof(double) * 3 * N), *fd = malloc(sizeof(double) * NA * N);
  prru_ident_result *r = malloc(sizeof *r);
  double pi[PRRU_NREG], beta[PRRU_NREG];
  if (truth)
    standard_of(truth, pi);
  else
    prru_ident_standard(&prru_mech, pi);
  prru_base_params(b, pi, beta);
  if (!TU_TRUE(q && qd && qdd && fd && r && !make_data(N, 0, q, qd, qdd, fd), "excitation data")) return;
  int bad = -2;
  int st = prru_identify(&model, b, N, q, qd, qdd, fd, r, &bad);
  TU_TRUE(st == PRRU_OK, "noise-free identification runs");
  /* Relative to |beta_i|, or for a parameter near 0 (exact zeros come
   * out of B as rounding-level values) to u_i = rms(y) / rms(X_i), the
   * value at which it alone would give forces of the data's size. */
  double *A = malloc(sizeof(double) * NA * PRRU_NREG), colsq[PRRU_NREG] = {0}, ysq = 0, y[NA];
  for (int s = 0; s < N && A; s++) {
    prru_ident_rows(&model, &data, b, q + 3 * s, qd + 3 * s, qdd + 3 * s, fd + NA * s, A, y);
    for (int i = 0; i < NA; i++) {
      ysq += y[i] * y[i];
      for (int j = 0; j < b->nbase; j++) colsq[j] += A[i * b->nbase + j] * A[i * b->nbase + j];
    }
  }
  free(A);
  double e = 0;
  for (int i = 0; i < b->nbase; i++)
    e = fmax(e, fabs(r->beta[i] - beta[i]) / fmax(fabs(beta[i]), sqrt(ysq / colsq[i])));
  printf("noise-free: %d samples, cond %.3g, worst relative error of a base parameter %.2e, "
         "sigma %.2e N\n", N, r->cond, e, r->sigma);
  tu_check(e <= 1e-9, "noise-free identification recovers beta", e, 1e-9);

  const double sigma = 0.5;
  make_data(N, sigma, q, qd, qdd, fd);
  st = prru_identify(&model, b, N, q, qd, qdd, fd, r, &bad);
  TU_TRUE(st == PRRU_OK, "noisy identification runs");
  /* Each error alone against its standard error, and all together: the
   * errors are correlated (strongly, along the regressor's weakest
   * direction), so the joint statistic is |X (beta^ - beta)|^2 / s^2,
   * chi-squared with nbase degrees of freedom: mean 1 per parameter,
   * standard deviation sqrt(2 / nbase). */
  double worst = 0, chi = 0, dbeta[PRRU_NREG];
  for (int i = 0; i < b->nbase; i++) {
    dbeta[i] = r->beta[i] - beta[i];
    worst = fmax(worst, fabs(dbeta[i] / r->se[i]));
  }
  A = malloc(sizeof(double) * NA * PRRU_NREG);
  for (int s = 0; s < N && A; s++) {
    prru_ident_rows(&model, &data, b, q + 3 * s, qd + 3 * s, qdd + 3 * s, fd + NA * s, A, y);
    for (int i = 0; i < NA; i++) {
      double v = 0;
      for (int j = 0; j < b->nbase; j++) v += A[i * b->nbase + j] * dbeta[j];
      chi += v * v;
    }
  }
  free(A);
  chi /= r->sigma * r->sigma * b->nbase;
  const double sd = sqrt(2.0 / b->nbase);
  printf("noise sigma %.2f N: estimated %.4f N, worst |error| / se %.2f, |X error|^2 / (s^2 nbase) %.3f "
         "(expected 1 +- %.2f)\n", sigma, r->sigma, worst, chi, sd);
  tu_check(worst <= 4, "every base parameter within 4 standard errors", worst, 4);
  tu_check(fabs(chi - 1) < 4 * sd, "joint error chi-squared as the noise predicts (4 sd)", chi, 1);
  tu_check(fabs(r->sigma / sigma - 1) < 0.05, "residual sigma = noise sigma (5 %)", r->sigma / sigma, 1);

  q[3 * 17] = 2.5; /* q1 far outside the workspace */
  st = prru_identify(&model, b, N, q, qd, qdd, fd, r, &bad);
  TU_TRUE(st != PRRU_OK && bad == 17, "an unreachable sample is refused and named");
  TU_TRUE(prru_identify(&model, b, 3, q, qd, qdd, fd, r, &bad) == PRRU_EINPUT, "too few samples refused");
  free(q), free(qd), free(qdd), free(fd), free(r);
}

static void check_excite(const prru_base *b)
{
  prru_excite_options o;
  prru_excite_options_default(&o);
  o.max_evals = 400;
  o.samples = 60;
  o.check_samples = 600;
  prru_fourier f;
  memset(&f, 0, sizeof f);
  f.period = 5, f.harmonics = 3;
  prru_excite_result r;
  char msg[256];
  int st = prru_excite(&model, b, &o, NULL, &f, &r, msg, sizeof msg);
  if (!TU_TRUE(st == PRRU_OK, "prru_excite finds a trajectory")) {
    fprintf(stderr, "%s\n", msg);
    return;
  }
  printf("excitation: cond %.4g from %.4g in %d evaluations, worst rcond %.3g\n", r.cond, r.cond_start, r.evals,
         r.rcond_worst);
  excitation = f;
  TU_TRUE(r.cond <= r.cond_start, "the optimiser does not make the condition worse");
  /* Strokes: the sliders of the result stay within a band around home. */
  prru_excite_options os = o;
  double d0[NA], dmin = INFINITY, dmax = -INFINITY;
  const double q0[3] = {0, 0, 0};
  prru_actuators(&model, &data, q0, d0);
  for (int i = 0; i < NA; i++) os.d_min[i] = d0[i] - 0.02, os.d_max[i] = d0[i] + 0.02;
  prru_fourier fs;
  memset(&fs, 0, sizeof fs);
  fs.period = 5, fs.harmonics = 3;
  st = prru_excite(&model, b, &os, NULL, &fs, &r, msg, sizeof msg);
  for (int s = 0; st == PRRU_OK && s < 5000; s++) {
    double q[3], dd[NA];
    prru_fourier_eval(&fs, fs.period * s / 5000, q, NULL, NULL);
    prru_actuators(&model, &data, q, dd);
    for (int i = 0; i < NA; i++) dmin = fmin(dmin, dd[i] - d0[i]), dmax = fmax(dmax, dd[i] - d0[i]);
  }
  printf("excitation within +-20 mm strokes: sliders from %.4g to %.4g m about home\n", dmin, dmax);
  TU_TRUE(st == PRRU_OK && dmin >= -0.02 && dmax <= 0.02, "excitation within the strokes");
  double peak[NA], rw, tb;
  TU_TRUE(prru_excite_check(&model, &f, &o, 5000, peak, &rw, &tb) == PRRU_OK && rw >= o.rcond_min,
          "the trajectory passes a denser check");
  prru_fourier f2;
  memset(&f2, 0, sizeof f2);
  f2.period = 5, f2.harmonics = 3;
  prru_excite_result r2;
  prru_excite(&model, b, &o, NULL, &f2, &r2, msg, sizeof msg);
  TU_TRUE(memcmp(&f, &f2, sizeof f) == 0, "deterministic");
  f2.centre[0] = 3.0;
  TU_TRUE(prru_excite(&model, b, &o, NULL, &f2, &r2, msg, sizeof msg) == PRRU_EINPUT &&
              strstr(msg, "centre") != NULL,
          "an unreachable centre is refused by name");
}

/* The defaults prru excite and the binding take from the library, and the
 * rows of a run: n = floor(T N / dt (1 + 1e-12)) + 1, exactly. */
static void check_excite_defaults(const prru_base *b)
{
  prru_fourier f;
  memset(&f, 0xff, sizeof f);
  prru_fourier_default(&f);
  int zero = f.centre[0] == 0 && f.centre[1] == 0 && f.centre[2] == 0;
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < PRRU_EXCITE_MAX_HARMONICS; l++) zero &= f.a[k][l] == 0 && f.b[k][l] == 0;
  TU_TRUE(f.period == 10 && f.harmonics == 5 && zero, "Fourier default: 10 s, 5 harmonics, all 0");
  prru_excite_options o;
  prru_excite_options_default(&o);
  TU_TRUE(o.dt == 0.01 && o.periods == 1 && o.samples == 100 && o.check_samples == 0 && o.max_evals == 3000 &&
              o.seed == 1,
          "excite defaults: rows every 0.01 s over 1 period, check samples follow samples");
  TU_TRUE(prru_excite_rows(&f, &o) == 1001, "default run: 1001 rows");
  f.period = 0.3, o.dt = 0.1; /* 0.3 / 0.1 = 2.9999999999999996 */
  TU_TRUE(prru_excite_rows(&f, &o) == 4, "the end's row kept against rounding");
  f.period = 8, o.periods = 3, o.dt = 0.007;
  TU_TRUE(prru_excite_rows(&f, &o) == 3429, "8 s x 3 every 7 ms: 3429 rows");
  o.dt = 24;
  TU_TRUE(prru_excite_rows(&f, &o) == 2, "dt = the run: its two ends");
  const double bad_dt[] = {24.000001, 0, -0.01, NAN, INFINITY, 1e-15};
  int refused = 1;
  for (int k = 0; k < 6; k++) {
    o.dt = bad_dt[k];
    refused &= prru_excite_rows(&f, &o) == 0;
  }
  o.dt = 0.01, o.periods = 0;
  refused &= prru_excite_rows(&f, &o) == 0;
  o.periods = 1, f.period = -1;
  refused &= prru_excite_rows(&f, &o) == 0;
  TU_TRUE(refused, "no rows without a run (dt past its end, not > 0, > 1e15 rows; bad period or periods)");
  /* Random runs: the last row at the end or less than dt before it. */
  int held = 1;
  for (int k = 0; k < 1000; k++) {
    f.period = tu_uniform(0.01, 20), o.periods = 1 + (int)tu_uniform(0, 5), o.dt = tu_uniform(1e-4, 0.5);
    const double run = f.period * o.periods;
    long n = prru_excite_rows(&f, &o);
    held &= o.dt > run ? n == 0 : n >= 2 && (n - 1) * o.dt <= run * (1 + 1e-12) && n * o.dt > run;
  }
  TU_TRUE(held, "rows up to the run's end, none a dt past it");
  /* check_samples 0 is 20 samples: the same excitation as giving them. */
  prru_excite_options_default(&o);
  o.max_evals = 60;
  o.samples = 40;
  prru_excite_options o20 = o;
  o20.check_samples = 800;
  prru_fourier f0, f20;
  prru_fourier_default(&f0);
  f0.period = 5, f0.harmonics = 3;
  f20 = f0;
  prru_excite_result r0, r20;
  char msg[256];
  int st0 = prru_excite(&model, b, &o, NULL, &f0, &r0, msg, sizeof msg);
  int st20 = prru_excite(&model, b, &o20, NULL, &f20, &r20, msg, sizeof msg);
  TU_TRUE(st0 == st20 && memcmp(&f0, &f20, sizeof f0) == 0 && memcmp(&r0, &r20, sizeof r0) == 0,
          "check samples 0 = 20 times samples");
  o.check_samples = -1;
  TU_TRUE(prru_excite(&model, b, &o, NULL, &f0, &r0, msg, sizeof msg) == PRRU_EINPUT, "negative check samples refused");
}

/* ---- physically consistent identification ---- */

/* 0 when the body's inertia about its centre of mass is physical: m > 0
 * and 0.5 tr(I_c) E - I_c (its second moment) positive definite by its
 * leading minors, which holds the triangle inequalities. For drawing
 * truths (well inside, so the determinants are not near rounding). */
static int body_consistent(double m, const double I[6])
{
  const double t = 0.5 * (I[0] + I[1] + I[2]);
  const double S[9] = {t - I[0], -I[3], -I[4], -I[3], t - I[1], -I[5], -I[4], -I[5], t - I[2]};
  const double m2 = S[0] * S[4] - S[1] * S[3];
  const double m3 = S[0] * (S[4] * S[8] - S[5] * S[7]) - S[1] * (S[3] * S[8] - S[5] * S[6]) +
                    S[2] * (S[3] * S[7] - S[4] * S[6]);
  return m > 0 && S[0] > 0 && m2 > 0 && m3 > 0 ? 0 : 1;
}

/* 0 when pi is physically consistent: every body's pseudo-inertia
 * [[S, m c], [m c^T, m]] (S = 0.5 tr(I_O) E - I_O), formed from pi
 * directly, has a Cholesky factor, and every drive coefficient is >= 0.
 * Not through m, c, I_c: an identified body may lie near the boundary (a
 * rod), where I_c's determinants are at the level of the conversion's
 * rounding; the model files' validators decide exactly. */
static int pi_consistent(const double *pi)
{
  for (int k = 0; k < NB; k++) {
    const double *p = pi + PRRU_NBODYPAR * k, h = 0.5 * (p[4] + p[5] + p[6]);
    const double J[4][4] = {{h - p[4], -p[7], -p[8], p[1]}, {-p[7], h - p[5], -p[9], p[2]},
                            {-p[8], -p[9], h - p[6], p[3]}, {p[1], p[2], p[3], p[0]}};
    double L[4][4] = {{0}};
    for (int j = 0; j < 4; j++) {
      double d = J[j][j];
      for (int i = 0; i < j; i++) d -= L[j][i] * L[j][i];
      if (!(d > 0)) return 1;
      L[j][j] = sqrt(d);
      for (int i = j + 1; i < 4; i++) {
        double s = J[i][j];
        for (int l = 0; l < j; l++) s -= L[i][l] * L[j][l];
        L[i][j] = s / L[j][j];
      }
    }
  }
  for (int j = PRRU_NBODYPAR * NB; j < PRRU_NREG; j++)
    if (!(pi[j] >= 0)) return 1;
  return 0;
}

/* A consistent truth near the model: masses x U(0.9, 1.1), every inertia
 * entry about the centre +-20 % (products by 20 % of the body's mean
 * moment), the centre of mass moved by up to 20 % of the body's radius of
 * gyration per axis, drives x U(0.7, 1.3); redrawn until consistent. */
static void consistent_truth(prru_params *p)
{
  *p = prru_params_model;
  for (int b = 0; b < NB; b++) {
    const double *I0 = prru_params_model.inertia[b], m0 = prru_params_model.mass[b];
    const double mean = (I0[0] + I0[1] + I0[2]) / 3, rho = sqrt(1.5 * mean / m0);
    do {
      p->mass[b] = m0 * tu_uniform(0.9, 1.1);
      for (int k = 0; k < 3; k++) p->inertia[b][k] = I0[k] * tu_uniform(0.8, 1.2);
      for (int k = 3; k < 6; k++) p->inertia[b][k] = I0[k] + 0.2 * mean * tu_uniform(-1, 1);
    } while (body_consistent(p->mass[b], p->inertia[b]));
    for (int k = 0; k < 3; k++) p->com[b][k] = prru_params_model.com[b][k] + 0.2 * rho * tu_uniform(-1, 1);
  }
  for (int i = 0; i < NA; i++) {
    p->armature[i] *= tu_uniform(0.7, 1.3);
    p->damping[i] *= tu_uniform(0.7, 1.3);
    p->coulomb[i] *= tu_uniform(0.7, 1.3);
  }
}

/* A truth's drives, where the model has none: armature up to 0.3 slider
 * masses, damping up to 3 N s/m per kg of slider, Coulomb up to 0.5 N per
 * kg (the prior's 0 is then off by the whole value). A truth with every
 * drive coefficient > 0 lies inside the consistent set, so some consistent
 * pi has the estimate's base parameters (noise-free): the exact path. */
static void add_drives(prru_params *p)
{
  for (int i = 0; i < NA; i++) {
    const double ms = p->mass[prru_mech.slider[i]];
    if (p->armature[i] == 0) p->armature[i] = 0.3 * ms * tu_uniform(0.2, 1);
    if (p->damping[i] == 0) p->damping[i] = 3 * ms * tu_uniform(0.2, 1);
    if (p->coulomb[i] == 0) p->coulomb[i] = 0.5 * ms * tu_uniform(0.2, 1);
  }
}


/* RMS over held-out states (random ones, not the excitation's) of the
 * forces Y_base beta_a and of Y_base (beta_a - beta_b): J_d^T fd units. */
static void held_out(const prru_base *b, const double *ba, const double *bb, double *rms, double *err)
{
  double s = 0, e = 0, vs = b->vs;
  for (int k = 0; k < 200; k++) {
    double q[3], qd[3], qdd[3], Y[3 * PRRU_NREG], Yb[3 * PRRU_NREG];
    random_state(q, qd, qdd);
    prru_regressor(q, qd, qdd, &vs, Y);
    prru_base_regressor(b, Y, 3, Yb);
    for (int r = 0; r < 3; r++) {
      double fa = 0, fe = 0;
      for (int i = 0; i < b->nbase; i++) fa += Yb[r * b->nbase + i] * ba[i], fe += Yb[r * b->nbase + i] * (ba[i] - bb[i]);
      s += fa * fa, e += fe * fe;
    }
  }
  *rms = sqrt(s / 600), *err = sqrt(e / 600);
}

static void check_consistent(const prru_base *b)
{
  enum { N = 1000, TRIALS = 10, NOISY = 40 };
  double *q = malloc(sizeof(double) * 3 * N), *qd = malloc(sizeof(double) * 3 * N);
  double *qdd = malloc(sizeof(double) * 3 * N), *fd = malloc(sizeof(double) * NA * N);
  prru_ident_result *r = malloc(sizeof *r);
  prru_consistent_result *c = malloc(sizeof *c);
  if (!TU_TRUE(q && qd && qdd && fd && r && c, "memory")) return;
  prru_consistent_options o;
  prru_consistent_options_default(&o);
  double pi0[PRRU_NREG], pi[PRRU_NREG], pit[PRRU_NREG], bt[PRRU_NREG];
  prru_ident_standard(&prru_mech, pi0);
  prru_params p;
  truth = &p;
  tu_rng_state = 4242;
  /* Noise-free: the truth's base parameters to 1e-8 of each one's
   * resolution (the report's column) and held-out forces to 1e-8 of their
   * RMS. The fit's own floor: d^2 <= lambda |pi* - pi0|_w^2 with sigma_w
   * = 1e-8 rms(y), i.e. |R e| <= 1e-3 |pi* - pi0|_w 1e-8 rms(y), far
   * below both bounds for prior distances of order 1. */
  double worst = 0, worst_f = 0, worst_d2 = 0;
  int fails = 0, inconsistent = 0, iters = 0, exact = 0;
  int with_drives = 0;
  for (int k = 0; k < TRIALS; k++) {
    consistent_truth(&p);
    /* Every other truth with drives of its own. */
    if (k % 2) add_drives(&p), with_drives++;
    p.coulomb_velocity = b->vs;
    standard_of(&p, pit);
    prru_base_params(b, pit, bt);
    int bad;
    if (make_data(N, 0, q, qd, qdd, fd) || prru_identify(&model, b, N, q, qd, qdd, fd, r, &bad) != PRRU_OK) {
      fails++;
      continue;
    }
    const int st = prru_ident_consistent(&model, b, r, pi0, &o, pi, c);
    fails += st != PRRU_OK;
    inconsistent += pi_consistent(pi);
    iters = iters > c->newton ? iters : c->newton;
    exact += c->how == PRRU_CONSISTENT_EXACT && k % 2;
    for (int i = 0; i < b->nbase; i++) worst = fmax(worst, fabs(c->beta[i] - bt[i]) / r->scale[i]);
    double rms, err;
    held_out(b, c->beta, bt, &rms, &err);
    worst_f = fmax(worst_f, err / rms);
    worst_d2 = fmax(worst_d2, c->d2);
  }
  printf("consistent, noise-free, %d consistent truths: %d refused, %d inconsistent, %d with the estimate's own "
         "base parameters; worst base error %.2e of the resolution, held-out force error %.2e of the RMS, "
         "d^2 %.2e; up to %d Newton steps\n", TRIALS, fails, inconsistent, exact, worst, worst_f, worst_d2, iters);
  TU_TRUE(fails == 0, "every noise-free consistent truth gives a model");
  TU_TRUE(exact == with_drives, "a truth inside the consistent set: the estimate's own base parameters");
  TU_TRUE(inconsistent == 0, "the returned parameters are physically consistent");
  tu_check(worst <= 1e-8, "base parameters within 1e-8 of their resolution", worst, 1e-8);
  tu_check(worst_f <= 1e-8, "held-out forces within 1e-8 of their RMS", worst_f, 1e-8);

  /* A flipped force sign: every base parameter negated, masses too. */
  for (int s = 0; s < N * NA; s++) fd[s] = -fd[s];
  int bad;
  prru_identify(&model, b, N, q, qd, qdd, fd, r, &bad);
  const int st = prru_ident_consistent(&model, b, r, pi0, &o, pi, c);
  printf("flipped force signs: status %d, d^2 %.3g against the quantile %.3g\n", st, c->d2, c->d2_max);
  TU_TRUE(st == PRRU_ESINGULAR && c->d2 > c->d2_max, "flipped force signs refused: d^2 above the quantile");
  TU_TRUE(pi_consistent(pi) == 0, "even then the nearest set found is consistent");

  /* Noise on the forces only, sigma 0.5 N: NOISY trials. Per trial the
   * residual chi^2 = |r|^2 / sigma^2 = dof s^2 / sigma^2 is chi^2(dof):
   * within 4 sd, sqrt(2 dof), of dof. Pairs (trial, base parameter) whose
   * model's base parameter lies within 3 se of the truth's: >= 95 % (the
   * least-squares estimate alone gives 99.7 %). */
  const double sigma = 0.5;
  int within = 0, pairs = 0, refused = 0, chi_bad = 0;
  double chi_worst = 0;
  for (int k = 0; k < NOISY; k++) {
    consistent_truth(&p);
    if (k % 2) add_drives(&p);
    p.coulomb_velocity = b->vs;
    standard_of(&p, pit);
    prru_base_params(b, pit, bt);
    if (make_data(N, sigma, q, qd, qdd, fd) || prru_identify(&model, b, N, q, qd, qdd, fd, r, &bad) != PRRU_OK) {
      refused++;
      continue;
    }
    const double chi = r->dof * r->sigma * r->sigma / (sigma * sigma), z = (chi - r->dof) / sqrt(2.0 * r->dof);
    chi_worst = fmax(chi_worst, fabs(z));
    chi_bad += fabs(z) > 4;
    const int cs = prru_ident_consistent(&model, b, r, pi0, &o, pi, c);
    if (cs != PRRU_OK || pi_consistent(pi))
      printf("  trial %d: status %d, d^2 %.4g, consistent %d\n", k, cs, c->d2, !pi_consistent(pi));
    if (cs != PRRU_OK || pi_consistent(pi)) {
      refused++;
      continue;
    }
    for (int i = 0; i < b->nbase; i++, pairs++) within += fabs(c->beta[i] - bt[i]) <= 3 * r->se[i];
  }
  printf("consistent, noise %.1f N, %d trials: %d refused; %d of %d (trial, base parameter) pairs within 3 se "
         "(%.1f %%); worst chi^2 deviation %.2f sd\n", sigma, NOISY, refused, within, pairs,
         100.0 * within / (pairs ? pairs : 1), chi_worst);
  tu_check(within >= 0.95 * pairs && pairs > 0, "95 % of the pairs within 3 se", within, 0.95 * pairs);
  TU_TRUE(chi_bad == 0, "each trial's chi^2 within 4 sd of its degrees of freedom");
  truth = NULL;
  free(q), free(qd), free(qdd), free(fd), free(r), free(c);
}

/* prru_ident_model_params: the model's own standard parameters give its
 * numbers back (to the rounding of m c / m and I_O -> I_c: a few u of
 * each body's scale); a body shrunk to 1e-3 of the file's floor (mass
 * and moments times 1e-12) comes back raised to the floor and still
 * consistent, and its model file loads; a negative damping is named. */
static void check_model_params_of_pi(const prru_base *b)
{
  double pi[PRRU_NREG];
  prru_ident_standard(model.mech, pi);
  prru_params p, ref;
  char why[300], *text = NULL;
  prru_model_params(&model, &ref);
  int st = prru_ident_model_params(&model, b, pi, &p, why, sizeof why);
  double err = 0;
  for (int k = 0; k < PRRU_NBODY; k++) {
    double scale = ref.mass[k];
    for (int e = 0; e < 3; e++) scale = fmax(scale, ref.inertia[k][e]);
    err = fmax(err, fabs(p.mass[k] - ref.mass[k]) / scale);
    for (int e = 0; e < 6; e++) err = fmax(err, fabs(p.inertia[k][e] - ref.inertia[k][e]) / scale);
  }
  tu_check(st == PRRU_OK && err <= 64 * DBL_EPSILON, "prru_ident_model_params of the model's own pi: its numbers",
           err, 64 * DBL_EPSILON);
  const int k = PRRU_NBODY - 1;
  for (int j = 0; j < PRRU_NBODYPAR; j++) pi[PRRU_NBODYPAR * k + j] *= 1e-12;
  st = prru_ident_model_params(&model, b, pi, &p, why, sizeof why);
  TU_TRUE(st == PRRU_OK && p.mass[k] == 1e-9 && p.inertia[k][0] == 1e-9 && p.inertia[k][1] == 1e-9 &&
              p.inertia[k][2] == 1e-9,
          "a body below the file's floor is raised to 1e-9 kg and 1e-9 kg m^2");
  st = prru_model_file_text(&model, &p, "floor", "", &text, why, sizeof why);
  TU_TRUE(st == PRRU_OK, "its model file loads");
  free(text);
  prru_ident_standard(model.mech, pi);
  pi[PRRU_NBODYPAR * PRRU_NBODY + PRRU_NACT] = -1; /* damping1 */
  st = prru_ident_model_params(&model, b, pi, &p, why, sizeof why);
  TU_TRUE(st == PRRU_EINPUT && strstr(why, "damping1 = -1 is negative"), "a negative damping is named");
}

/* A model of another geometry, loaded at run time, is identified without
 * a build of its own: the topology's regressor (geometry and gravity
 * read at run time) satisfies Y pi = M qdd + h - G - passive of the loaded
 * model, and its identification from its own exact inverse dynamics at
 * random states returns its base parameters. Tolerances: Y pi is a
 * straight-line program of PRRU_P<n>_ARITH_REGRESSOR operations, so its
 * forward error is at most that many u times the magnitude of the terms
 * (|M qdd| + |h| + |G| + |passive|, each a sum of products of the same
 * parameters); the fit's errors, for exact data, are rounding amplified
 * by the regressor's conditioning, and the bound is 1e-8 of each
 * base parameter's resolution (the report's column). */
#if PRRU_NLIMB == 3
#include "prru_p3_kernels.h"
#define ARITH_REGRESSOR PRRU_P3_ARITH_REGRESSOR
static const char *const other_geometry[] = {"models/prototype_example.json",
                                             "tests/models/conformance/valid/random_3.json"};
#else
#include "prru_p4_kernels.h"
#define ARITH_REGRESSOR PRRU_P4_ARITH_REGRESSOR
static const char *const other_geometry[] = {"tests/models/conformance/valid/random_1.json",
                                             "tests/models/conformance/valid/random_2.json"};
#endif

static void check_other_geometry(const char *src, const char *file)
{
  char path[4096], msg[1024], what[4400];
  snprintf(path, sizeof path, "%s/%s", src, file);
  prru_model m;
  prru_model_default(&m);
  if (!TU_TRUE(prru_model_load(&m, path, msg, sizeof msg) == PRRU_OK, path)) return;
  if (prru_model_is_built(&m, 1)) {
    printf("%s: SKIPPED: its geometry and gravity are the build's\n", file);
    prru_model_free(&m);
    return;
  }
  prru_data *d = malloc(sizeof *d);
  double pi[PRRU_NREG], worst = 0;
  const double vs = prru_ident_default_vs(&m);
  prru_ident_standard(m.mech, pi);
  unsigned long long seed = 777;
  enum { N = 200 };
  double *q = malloc(sizeof(double) * 3 * N * 3), *qd = q + 3 * N, *qdd = qd + 3 * N;
  double *fd = malloc(sizeof(double) * PRRU_NACT * N);
  int n = 0;
  for (int s = 0; s < N; s++) {
    double Y[3 * PRRU_NREG], M[9], h[3], G[3], Qp[3], tau[3], yp[3], scale = 0;
    if (prru_ident_random_state(&m, d, &seed, q + 3 * n, qd + 3 * n, qdd + 3 * n) != PRRU_OK) break;
    const double *x = q + 3 * n, *v = qd + 3 * n, *a = qdd + 3 * n;
    prru_model_regressor(&m, x, v, a, vs, Y);
    prru_model_dynamics(&m, x, v, M, h, G);
    prru_model_passive(&m, x, v, Qp);
    for (int i = 0; i < 3; i++) {
      const double Ma = M[3 * i] * a[0] + M[3 * i + 1] * a[1] + M[3 * i + 2] * a[2];
      tau[i] = Ma + h[i] - G[i] - Qp[i];
      scale = fmax(scale, fabs(M[3 * i]) * fabs(a[0]) + fabs(M[3 * i + 1]) * fabs(a[1]) +
                              fabs(M[3 * i + 2]) * fabs(a[2]) + fabs(h[i]) + fabs(G[i]) + fabs(Qp[i]));
    }
    y_times(Y, pi, yp);
    for (int i = 0; i < 3; i++) worst = fmax(worst, fabs(yp[i] - tau[i]) / scale);
    static const prru_loads none;
    if (prru_inverse_dynamics(&m, d, x, v, a, &none, fd + PRRU_NACT * n) == PRRU_OK) n++;
  }
  const double bound = ARITH_REGRESSOR * DBL_EPSILON;
  printf("%s (parameter kernels): Y pi vs its dynamics over %d states: %.2e of the terms (bound %.2e)\n", file, n,
         worst, bound);
  snprintf(what, sizeof what, "%s (parameter kernels): Y pi = its dynamics (%d states)", file, n);
  tu_check(worst <= bound, what, worst, bound);
  prru_base *b = malloc(sizeof *b);
  prru_ident_result *r = malloc(sizeof *r);
  int bad = -1, st = prru_base_compute(&m, vs, 0, 1, b);
  if (st == PRRU_OK) st = prru_identify(&m, b, n, q, qd, qdd, fd, r, &bad);
  snprintf(what, sizeof what, "%s: identified without a build of its own (status %d)", file, st);
  if (TU_TRUE(st == PRRU_OK && n >= N / 2, what)) {
    double beta_true[PRRU_NREG], err = 0;
    prru_base_params(b, pi, beta_true);
    for (int i = 0; i < b->nbase; i++) err = fmax(err, fabs(r->beta[i] - beta_true[i]) / r->scale[i]);
    snprintf(what, sizeof what, "%s: base parameters within 1e-8 of their resolution (%d of them)", file, b->nbase);
    printf("%s: %d base parameters identified from its exact forces: %.2e of their resolution\n", file, b->nbase,
           err);
    tu_check(err <= 1e-8, what, err, 1e-8);
  }
  free(b), free(r), free(q), free(fd), free(d);
  prru_model_free(&m);
}

/* prru_identify_model, the procedure identify and the Python binding
 * share: on the model's own noise-free motion the estimate's base
 * parameters are the prior's, so the consistent set is the prior itself
 * (the exact case; nearest the prior) and the written model's masses are
 * the model's to the 1e-9 the consistent fit's margin allows (relative;
 * the file's 17 digits add nothing); each failing stage stops with its
 * stage, sample and reason. */
static void check_identify_model(const prru_base *b)
{
  enum { N = 400 };
  double *q = malloc(sizeof(double) * 3 * N), *qd = malloc(sizeof(double) * 3 * N);
  double *qdd = malloc(sizeof(double) * 3 * N), *fd = malloc(sizeof(double) * NA * N);
  prru_identification *r = malloc(sizeof *r);
  if (!TU_TRUE(q && qd && qdd && fd && r && !make_data(N, 0, q, qd, qdd, fd), "excitation data")) return;
  int st = prru_identify_model(&model, b, N, q, qd, qdd, fd, "ident_test", "a \"test\"", r);
  TU_TRUE(st == PRRU_OK && r->stage == PRRU_IDENTIFY_DONE && r->text && r->bad == -1,
          "identify_model: noise-free data give a model");
  char path[] = "test_ident_model.json";
  FILE *f = r->text ? fopen(path, "w") : NULL;
  if (f) fputs(r->text, f), fclose(f);
  prru_model m;
  char msg[512] = "";
  if (TU_TRUE(f && prru_model_load(&m, path, msg, sizeof msg) == PRRU_OK, "identify_model: its text loads")) {
    double e = 0;
    for (int k = 0; k < PRRU_NBODY; k++)
      e = fmax(e, fabs(m.mech->mass[k] - prru_mech.mass[k]) / prru_mech.mass[k]);
    tu_check(e <= 1e-6, "identify_model: the prior's masses come back", e, 1e-6);
    TU_TRUE(strcmp(m.mech->name, "ident_test") == 0, "identify_model: named");
    prru_model_free(&m);
  }
  remove(path);
  free(r->text);

  q[3 * 17] = 2.5; /* q1 far outside the workspace */
  st = prru_identify_model(&model, b, N, q, qd, qdd, fd, "x", "", r);
  TU_TRUE(st == PRRU_EUNREACHABLE && r->stage == PRRU_IDENTIFY_FIT && r->bad == 17 && !r->text &&
          strncmp(r->msg, "sample 18: ", 11) == 0, "identify_model: an unreachable sample is named");
  st = prru_identify_model(&model, b, 3, q, qd, qdd, fd, "x", "", r);
  TU_TRUE(st == PRRU_EINPUT && r->stage == PRRU_IDENTIFY_FIT && strstr(r->msg, "fewer than"),
          "identify_model: too few samples");
  prru_base *other = malloc(sizeof *other);
  if (other) { /* a base of the other topology's counts */
    *other = *b;
    other->nact = NA == 3 ? 4 : 3, other->nbody = NB == 10 ? 13 : 10;
    other->nreg = PRRU_NBODYPAR * other->nbody + 3 * other->nact;
    st = prru_identify_model(&model, other, N, q, qd, qdd, fd, "x", "", r);
    TU_TRUE(st == PRRU_EINPUT && r->stage == PRRU_IDENTIFY_FIT && strstr(r->msg, "computed for a model of"),
            "identify_model: a base of another topology is refused");
    prru_ident_result *fit = malloc(sizeof *fit);
    TU_TRUE(fit && prru_identify(&model, other, N, q, qd, qdd, fd, fit, NULL) == PRRU_EINPUT,
            "identify: a base of another topology is refused");
    free(fit), free(other);
  }
  make_data(N, 0, q, qd, qdd, fd);
  for (int i = 0; i < NA * N; i++) fd[i] = -fd[i]; /* a sign convention flipped */
  st = prru_identify_model(&model, b, N, q, qd, qdd, fd, "x", "", r);
  TU_TRUE(st == PRRU_ESINGULAR && r->stage == PRRU_IDENTIFY_PHYSICS && !r->text &&
          r->consistent.d2 > r->consistent.d2_max && strstr(r->msg, "the data contradict physics") == r->msg,
          "identify_model: flipped forces contradict physics, with the nearest consistent set");
  printf("flipped forces: %s\n", r->msg);
  free(q), free(qd), free(qdd), free(fd), free(r);
}

int main(void)
{
  prru_model_default(&model);
  check_model_params();
  check_model_dynamics();
  check_random_designs();
  prru_base *b = malloc(sizeof *b);
  if (!b) return 1;
  check_base(b);
  hand_excitation();
  check_excite(b);
  check_excite_defaults(b);
  check_identify(b);
  check_identify_model(b);
  check_model_params_of_pi(b);
  const char *src = getenv("PRRU_SOURCE_DIR");
  if (TU_TRUE(src != NULL, "PRRU_SOURCE_DIR set (ctest sets it)"))
    for (size_t k = 0; k < sizeof other_geometry / sizeof *other_geometry; k++) check_other_geometry(src, other_geometry[k]);
  /* A truth other than the model (the prior): every inertial and drive
   * number perturbed, Coulomb smoothing as in the base parameters. */
  prru_mechanism me;
  prru_params p;
  tu_rng_state = 99;
  random_design(&me, &p);
  p.coulomb_velocity = b->vs;
  truth = &p;
  printf("-- data from a perturbed model, the built one as the prior:\n");
  check_identify(b);
  truth = NULL;
  check_consistent(b);
  free(b);
  return tu_finish("test_ident");
}
