/* Batched kernels (prru_batch_*, prru_param_batch_*) against their scalar
 * namesakes, state by state: ik_jd, mass, platform_jacobian and dme_terms
 * bit for bit; dynamics, eom, eom_solve and the derivative kernels
 * (eom_solve_derivs, inverse_derivs with three actuators; specialised
 * only: the model's parameter set has none), whose only difference from the
 * scalar kernels is the vector sin and cos (glibc's libmvec, at most 4 ulp),
 * within 1e-14 of the largest entry of the output array plus twice the
 * output's rounding sensitivity at that state: the largest change of the
 * scalar kernel's output when q1 or q2 moves by 8 ulp (which moves sin and
 * cos by more than libmvec's error). A fixed relative bound is wrong for
 * h, b and qdd: they are sums of qd-quadratic terms that cancel, by an
 * amount that depends on the model and the state (measured up to 4.8e-14
 * of the largest entry on the prototype model, 1.6e-14 on the paper's).
 * Compared at every state at least MARGIN from a singular boundary
 * (testref.h's ref_margin, as test_param_kernels: nearer, the kernels' own
 * conditioning grows without bound), and NaN exactly where the scalar
 * kernel gives NaN at every state. States are drawn over a box larger than
 * the workspace (some unreachable), for batch sizes that are and are not
 * multiples of the kernels' chunk, with the batch placed at an offset (no
 * alignment). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "prru_derivs.h"
#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_param_kernels.h"
#include "testparam.h"
#include "prru_ref.h"
#include "testref.h"
#include "testutil.h"

#define NMAX 203
#define TOL 1e-14
/* The angle perturbation, in units of DBL_EPSILON, and the factor on the
 * sensitivity it shows. */
#define PERTURB_EPS 8.0
#define SENS_FACTOR 2.0
#define MARGIN 0.1
enum { NA = PRRU_NACT };

/* Inputs, AoS (per state) and SoA (rows of n), at an offset into the
 * buffers so that the batch is not aligned. */
typedef struct {
  double q[NMAX][3], qd[NMAX][3], fd[NMAX][NA], fp[NMAX][3], mp[NMAX][3], qdd[NMAX][3];
} states;

static double soa_buf[6][NA * NMAX + 1];
static int compared[NMAX]; /* margin >= MARGIN */
static int nreach, nfar;

static void draw(states *s, int n)
{
  prru_ref_params r;
  prru_ref_params_default(&r);
  double L = 0;
  for (int i = 0; i < PRRU_NLIMB; i++) L = fmax(L, r.l1[i] + r.l2[i]);
  nreach = nfar = 0;
  for (int k = 0; k < n; k++) {
    s->q[k][0] = tu_uniform(-1.57, 1.57);
    s->q[k][1] = tu_uniform(-1.57, 1.57);
    s->q[k][2] = tu_uniform(-2 * L, 2 * L);
    const double margin = ref_margin(&r, s->q[k]);
    compared[k] = margin >= MARGIN;
    nreach += margin >= 0;
    nfar += compared[k];
    for (int i = 0; i < 3; i++) {
      s->qd[k][i] = tu_uniform(-2, 2);
      s->fp[k][i] = tu_uniform(-50, 50);
      s->mp[k][i] = tu_uniform(-5, 5);
      s->qdd[k][i] = tu_uniform(-10, 10);
    }
    for (int i = 0; i < NA; i++) s->fd[k][i] = tu_uniform(-100, 100);
  }
  if (n > 2) {
    s->q[n / 2][0] = NAN; /* a non-finite q gives NaN everywhere */
    s->q[n - 1][2] = INFINITY;
    compared[n / 2] = compared[n - 1] = 0;
  }
}

/* Row-major copy: x[i * n + k] = a[k][i]. */
static double *soa(int slot, const double *aos, int dim, int n)
{
  double *x = soa_buf[slot] + 1;
  for (int k = 0; k < n; k++)
    for (int i = 0; i < dim; i++) x[i * n + k] = aos[k * dim + i];
  return x;
}

/* Compares output array `name` (dim entries per state) of the batch, SoA,
 * with the scalar one, AoS: bit for bit when sens is NULL, else state k
 * within TOL of the array's largest entry plus SENS_FACTOR sens[k]. Returns
 * the worst difference relative to the largest entry. */
static double compare(const char *kernel, const char *name, const double *batch,
                      const double *scalar, const double *sens, int dim, int n, int *nan_ok)
{
  double worst = 0, x[64];
  int within = 1;
  for (int k = 0; k < n; k++) {
    const double *ref = scalar + k * dim;
    int any_nan = 0;
    for (int i = 0; i < dim; i++) {
      x[i] = batch[i * n + k];
      if (isnan(ref[i]) != isnan(x[i])) *nan_ok = 0;
      any_nan |= isnan(ref[i]);
    }
    if (any_nan || !compared[k]) continue;
    double err = 0, scale = 1e-300;
    for (int i = 0; i < dim; i++) {
      double e = fabs(x[i] - ref[i]);
      if (!(e <= err)) err = e; /* NaN propagates as a failure */
      scale = fmax(scale, fabs(ref[i]));
    }
    const double bound = sens ? TOL * scale + SENS_FACTOR * sens[k] : 0.0;
    if (!(err <= bound)) within = 0;
    if (!(err / scale <= worst)) worst = err / scale;
  }
  char what[200];
  if (sens)
    snprintf(what, sizeof what, "%s: %s within %.0e + %.0f x its sensitivity to %.0f ulp of q1, q2 "
             "of the scalar kernel (n = %d)", kernel, name, TOL, SENS_FACTOR, PERTURB_EPS, n);
  else
    snprintf(what, sizeof what, "%s: %s bit for bit the scalar kernel's (n = %d)", kernel, name, n);
  tu_check(within, what, worst, sens ? TOL : 0.0);
  return worst;
}

/* The vector-trig kernels' outputs at one state, the scalar way. */
typedef struct {
  double M[9], h[3], G[3], b[3], qdd[3], minors[3];
} trig_outs;

static void scalar_trig(const prru_params *p, const states *s, int k, const double q[3], trig_outs *o)
{
  double M[9], b[3];
  if (p) {
    prru_param_dynamics(tp_derived(p), q, s->qd[k], o->M, o->h, o->G);
    prru_param_eom(tp_derived(p), q, s->qd[k], s->fd[k], s->fp[k], s->mp[k], M, o->b);
    memset(o->qdd, 0, sizeof o->qdd);
    memset(o->minors, 0, sizeof o->minors);
  } else {
    prru_dynamics(q, s->qd[k], o->M, o->h, o->G);
    prru_eom_solve(q, s->qd[k], s->fd[k], s->fp[k], s->mp[k], M, b, o->qdd, o->minors);
    prru_eom(q, s->qd[k], s->fd[k], s->fp[k], s->mp[k], M, o->b);
  }
}

static double maxdiff(const double *a, const double *b, int n)
{
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* Per state, the largest change of each vector-trig output when q1 or q2
 * moves by PERTURB_EPS ulp either way. */
typedef struct {
  double M[NMAX], h[NMAX], G[NMAX], b[NMAX], qdd[NMAX], minors[NMAX];
} sensitivity;

static void rounding_sensitivity(const prru_params *p, const states *s, int n, sensitivity *sv)
{
  for (int k = 0; k < n; k++) {
    trig_outs o0, o1;
    sv->M[k] = sv->h[k] = sv->G[k] = sv->b[k] = sv->qdd[k] = sv->minors[k] = 0;
    if (!compared[k]) continue;
    scalar_trig(p, s, k, s->q[k], &o0);
    for (int j = 0; j < 2; j++)
      for (int sign = -1; sign <= 1; sign += 2) {
        double q[3] = {s->q[k][0], s->q[k][1], s->q[k][2]};
        q[j] += sign * PERTURB_EPS * DBL_EPSILON * fmax(1.0, fabs(q[j]));
        scalar_trig(p, s, k, q, &o1);
        sv->M[k] = fmax(sv->M[k], maxdiff(o1.M, o0.M, 9));
        sv->h[k] = fmax(sv->h[k], maxdiff(o1.h, o0.h, 3));
        sv->G[k] = fmax(sv->G[k], maxdiff(o1.G, o0.G, 3));
        sv->b[k] = fmax(sv->b[k], maxdiff(o1.b, o0.b, 3));
        sv->qdd[k] = fmax(sv->qdd[k], maxdiff(o1.qdd, o0.qdd, 3));
        sv->minors[k] = fmax(sv->minors[k], maxdiff(o1.minors, o0.minors, 3));
      }
  }
}

/* The derivative kernels (specialised only: the model's parameter set has
 * none; the topology's are checked through prru_linearize_batch,
 * test_derivs): every output array against the scalar kernel's under the
 * vector-trig rule, each with its own sensitivity. One state's outputs,
 * the arrays in the kernel's argument order. */
enum { D_NDERIV = 9 + 9 + 3 * NA + 9 + 9 };
static const char *const fwd_arrays[] = {"M", "b", "qdd", "minors", "Dq", "Dqd", "Dfd", "Dfp", "Dmp"};
static const int fwd_dims[] = {9, 3, 3, 3, 9, 9, 3 * NA, 9, 9};
#define NFWD 9
#define FWD_SIZE (9 + 3 + 3 + 3 + D_NDERIV)
#if PRRU_NACT == 3
static const char *const inv_arrays[] = {"d", "Jd", "Jdinv", "fd", "Dq", "Dqd", "Dqdd"};
static const int inv_dims[] = {3, 9, 9, 3, 9, 9, 9};
#define NINV 7
#define INV_SIZE (3 + 9 + 9 + 3 + 27)
#else
#define NINV 0
#define INV_SIZE 0
#endif
#define DMAX (FWD_SIZE > INV_SIZE ? FWD_SIZE : INV_SIZE)

static void scalar_derivs(int inverse, const states *s, int k, const double q[3], const double qd[3],
                          double *o)
{
  double *x[9];
  const int *dims = fwd_dims;
#if PRRU_NACT == 3
  if (inverse) dims = inv_dims;
#endif
  x[0] = o;
  for (int a = 1; a < (inverse ? NINV : NFWD); a++) x[a] = x[a - 1] + dims[a - 1];
  if (!inverse)
    prru_eom_solve_derivs(q, qd, s->fd[k], s->fp[k], s->mp[k], x[0], x[1], x[2], x[3], x[4],
                          x[5], x[6], x[7], x[8]);
#if PRRU_NACT == 3
  else
    prru_inverse_derivs(q, qd, s->qdd[k], s->fp[k], s->mp[k], x[0], x[1], x[2], x[3], x[4],
                        x[5], x[6]);
#endif
}

static double want_d[NMAX][DMAX], sens_d[9][NMAX], got_d[DMAX * NMAX];

/* The vector tanh's share in Dqd (tu_tanh_share). */
static double tanh_share(int inverse, const double q[3])
{
  double f = 0, Jd[3 * NA], M[9];
  for (int i = 0; i < NA; i++) f = fmax(f, prru_mech.coulomb[i]);
  prru_jd(q, Jd);
  prru_mass(q, M);
  return tu_tanh_share(Jd, NA, inverse ? NULL : M, f, prru_mech.coulomb_velocity);
}

static double check_derivs_of(int inverse, const states *s, int n, const double *q, const double *qd,
                              const double *fd, const double *fp, const double *mp, const double *qdd,
                              int *nan_ok)
{
  const int na = inverse ? NINV : NFWD, size = inverse ? INV_SIZE : FWD_SIZE;
  const int *dims = fwd_dims;
  const char *const *names = fwd_arrays;
  const char *kernel = inverse ? "batch_inverse_derivs" : "batch_eom_solve_derivs";
#if PRRU_NACT == 3
  if (inverse) dims = inv_dims, names = inv_arrays;
#endif
  for (int k = 0; k < n; k++) {
    scalar_derivs(inverse, s, k, s->q[k], s->qd[k], want_d[k]);
    for (int a = 0; a < na; a++) sens_d[a][k] = 0;
    if (!compared[k]) continue;
    /* With Coulomb friction the vector tanh differs too: its arguments
     * are the slider rates J_d qd / v_s, so qd's components are perturbed
     * as well, by PERTURB_EPS of their own ulps (test_derivs.c's rule for
     * prru_linearize_batch). */
    for (int j = 0; j < 5; j++)
      for (int sign = -1; sign <= 1; sign += 2) {
        double qp[3] = {s->q[k][0], s->q[k][1], s->q[k][2]}, o1[DMAX];
        double qdp[3] = {s->qd[k][0], s->qd[k][1], s->qd[k][2]};
        if (j < 2)
          qp[j] += sign * PERTURB_EPS * DBL_EPSILON * fmax(1.0, fabs(qp[j]));
        else
          qdp[j - 2] += sign * PERTURB_EPS * DBL_EPSILON * fabs(qdp[j - 2]);
        scalar_derivs(inverse, s, k, qp, qdp, o1);
        for (int a = 0, at = 0; a < na; at += dims[a], a++)
          sens_d[a][k] = fmax(sens_d[a][k], maxdiff(o1 + at, want_d[k] + at, dims[a]));
      }
    sens_d[5][k] += tanh_share(inverse, s->q[k]) / SENS_FACTOR; /* Dqd, index 5 in both */
  }
  double *x[9];
  x[0] = got_d;
  for (int a = 1; a < na; a++) x[a] = x[a - 1] + dims[a - 1] * n;
  if (!inverse)
    prru_batch_eom_solve_derivs(n, q, qd, fd, fp, mp, x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7],
                                x[8]);
#if PRRU_NACT == 3
  else
    prru_batch_inverse_derivs(n, q, qd, qdd, fp, mp, x[0], x[1], x[2], x[3], x[4], x[5], x[6]);
#else
  (void)qdd;
#endif
  double worst = 0;
  static double scal[NMAX * DMAX];
  for (int a = 0, at = 0; a < na; at += dims[a], a++) {
    for (int k = 0; k < n; k++)
      for (int i = 0; i < dims[a]; i++) scal[k * dims[a] + i] = want_d[k][at + i];
    const double e = compare(kernel, names[a], x[a], scal, sens_d[a], dims[a], n, nan_ok);
    if (e > worst) worst = e;
  }
  (void)size;
  return worst;
}

static double check_derivs(const states *s, int n, const double *q, const double *qd, const double *fd,
                           const double *fp, const double *mp, const double *qdd, int *nan_ok)
{
  double worst = check_derivs_of(0, s, n, q, qd, fd, fp, mp, qdd, nan_ok);
#if PRRU_NACT == 3
  worst = fmax(worst, check_derivs_of(1, s, n, q, qd, fd, fp, mp, qdd, nan_ok));
#endif
  return worst;
}

typedef struct {
  double d[NMAX][NA], Jd[NMAX][NA * 3], M[NMAX][9], h[NMAX][3], G[NMAX][3], b[NMAX][3],
      JP[NMAX][18], qdd[NMAX][3], minors[NMAX][3];
} outs;

static outs want, got_store;
static double got[8][NA * 18 * NMAX];

static double run(const prru_params *p, const states *s, int n, int *nan_ok)
{
  const double *q = soa(0, &s->q[0][0], 3, n), *qd = soa(1, &s->qd[0][0], 3, n),
               *fd = soa(2, &s->fd[0][0], NA, n), *fp = soa(3, &s->fp[0][0], 3, n),
               *mp = soa(4, &s->mp[0][0], 3, n);
  double worst = 0, e;
  const char *pre = p ? "param_batch" : "batch";
  char k[64];
#define CMP(kern, name, arr, scal, dim)                                \
  snprintf(k, sizeof k, "%s_%s", pre, kern);                           \
  e = compare(k, name, arr, &want.scal[0][0], NULL, dim, n, nan_ok);   \
  if (e > worst) worst = e
#define CMP_TRIG(kern, name, arr, scal, dim)                           \
  snprintf(k, sizeof k, "%s_%s", pre, kern);                           \
  e = compare(k, name, arr, &want.scal[0][0], sens.scal, dim, n, nan_ok); \
  if (e > worst) worst = e
  /* ik_jd */
  for (int i = 0; i < n; i++) {
    if (p) prru_param_ik_jd(tp_derived(p), s->q[i], want.d[i], want.Jd[i]);
    else prru_ik_jd(s->q[i], want.d[i], want.Jd[i]);
  }
  if (p) prru_param_batch_ik_jd(tp_derived(p), n, q, got[0], got[1]);
  else prru_batch_ik_jd(n, q, got[0], got[1]);
  CMP("ik_jd", "d", got[0], d, NA);
  CMP("ik_jd", "Jd", got[1], Jd, 3 * NA);
  /* mass, platform_jacobian, dme_terms */
  for (int i = 0; i < n; i++) {
    if (p) {
      prru_param_mass(tp_derived(p), s->q[i], want.M[i]);
      prru_param_platform_jacobian(tp_derived(p), s->q[i], want.JP[i]);
    } else {
      prru_mass(s->q[i], want.M[i]);
      prru_platform_jacobian(s->q[i], want.JP[i]);
    }
  }
  if (p) prru_param_batch_mass(tp_derived(p), n, q, got[2]);
  else prru_batch_mass(n, q, got[2]);
  CMP("mass", "M", got[2], M, 9);
  if (p) prru_param_batch_platform_jacobian(tp_derived(p), n, q, got[3]);
  else prru_batch_platform_jacobian(n, q, got[3]);
  CMP("platform_jacobian", "JP", got[3], JP, 18);
  if (p) prru_param_batch_dme_terms(tp_derived(p), n, q, got[0], got[1], got[2], got[3]);
  else prru_batch_dme_terms(n, q, got[0], got[1], got[2], got[3]);
  CMP("dme_terms", "d", got[0], d, NA);
  CMP("dme_terms", "Jd", got[1], Jd, 3 * NA);
  CMP("dme_terms", "M", got[2], M, 9);
  CMP("dme_terms", "JP", got[3], JP, 18);
  /* dynamics, eom, eom_solve: vector sin and cos */
  static sensitivity sens;
  rounding_sensitivity(p, s, n, &sens);
  for (int i = 0; i < n; i++) {
    if (p) prru_param_dynamics(tp_derived(p), s->q[i], s->qd[i], want.M[i], want.h[i], want.G[i]);
    else prru_dynamics(s->q[i], s->qd[i], want.M[i], want.h[i], want.G[i]);
  }
  if (p) prru_param_batch_dynamics(tp_derived(p), n, q, qd, got[2], got[4], got[5]);
  else prru_batch_dynamics(n, q, qd, got[2], got[4], got[5]);
  CMP_TRIG("dynamics", "M", got[2], M, 9);
  CMP_TRIG("dynamics", "h", got[4], h, 3);
  CMP_TRIG("dynamics", "G", got[5], G, 3);
  /* eom */
  for (int i = 0; i < n; i++) {
    if (p) prru_param_eom(tp_derived(p), s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want.M[i], want.b[i]);
    else prru_eom(s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want.M[i], want.b[i]);
  }
  if (p) prru_param_batch_eom(tp_derived(p), n, q, qd, fd, fp, mp, got[2], got[6]);
  else prru_batch_eom(n, q, qd, fd, fp, mp, got[2], got[6]);
  CMP_TRIG("eom", "M", got[2], M, 9);
  CMP_TRIG("eom", "b", got[6], b, 3);
  /* eom_solve (constant kernels only): the forward-dynamics step */
  if (!p) {
    for (int i = 0; i < n; i++)
      prru_eom_solve(s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want.M[i], want.b[i],
                     want.qdd[i], want.minors[i]);
    prru_batch_eom_solve(n, q, qd, fd, fp, mp, got[2], got[6], got[7], got[4]);
    CMP_TRIG("eom_solve", "M", got[2], M, 9);
    CMP_TRIG("eom_solve", "b", got[6], b, 3);
    CMP_TRIG("eom_solve", "qdd", got[7], qdd, 3);
    CMP_TRIG("eom_solve", "minors", got[4], minors, 3);
  }
#undef CMP
#undef CMP_TRIG
  (void)got_store;
  if (!p) {
    e = check_derivs(s, n, q, qd, fd, fp, mp, soa(5, &s->qdd[0][0], 3, n), nan_ok);
    if (e > worst) worst = e;
  }
  return worst;
}

static states st;

int main(void)
{
  static const int sizes[] = {1, 7, 32, 33, 64, 100, NMAX};
  double worst = 0, e;
  int nan_ok = 1;
  for (size_t t = 0; t < sizeof sizes / sizeof sizes[0]; t++) {
    int n = sizes[t];
    draw(&st, n);
    e = run(NULL, &st, n, &nan_ok);
    if (e > worst) worst = e;
    e = run(&prru_params_model, &st, n, &nan_ok);
    if (e > worst) worst = e;
  }
  TU_TRUE(nan_ok, "NaN exactly where the scalar kernels give NaN");
  TU_TRUE(nfar > NMAX / 10 && nreach < NMAX - 10, "both reachable and unreachable states drawn");
  printf("batched vs scalar kernels: worst difference %.2e of the largest entry (bound %.0e + %.0f x the "
         "sensitivity to %.0f ulp of q1, q2); last batch: %d of %d states reachable, %d compared (margin "
         ">= %.2g)\n",
         worst, TOL, SENS_FACTOR, PERTURB_EPS, nreach, NMAX, nfar, MARGIN);
  return tu_finish("test_batch");
}
