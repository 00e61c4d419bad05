/* Batched kernels (prru_batch_*, prru_param_batch_*) against their scalar
 * namesakes, state by state: ik_jd, mass, platform_jacobian and dme_terms
 * bit for bit, dynamics, eom and eom_solve within 1e-14 of the scalar
 * kernel's (h, b, qdd: 2e-14, see TOL_BIAS), relative to the largest entry of
 * that output array at that state (the only difference the build allows is
 * the vector sin and cos, within a few ulp), at every state at least MARGIN from a singular
 * boundary (testref.h's ref_margin, as test_param_kernels: nearer, the
 * kernels' own conditioning grows without bound), and NaN exactly where the
 * scalar kernel gives NaN at every state. States are drawn over a box
 * larger than the workspace (some unreachable), for batch sizes that are
 * and are not multiples of the kernels' chunk, with the batch placed at an
 * offset (no alignment). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_param_kernels.h"
#include "prru_ref.h"
#include "testref.h"
#include "testutil.h"

#define NMAX 203
#define TOL 1e-14
/* h, b and qdd (dynamics, eom, eom_solve): sums of qd-quadratic terms that cancel, so the
 * vector sin and cos's few ulp show up to 1.6e-14 of the largest entry in
 * the runtime-parameter kernels (measured over these states); the constant
 * kernels stay within TOL. */
#define TOL_BIAS 2e-14
#define MARGIN 0.1
enum { NA = PRRU_NACT };

/* Inputs, AoS (per state) and SoA (rows of n), at an offset into the
 * buffers so that the batch is not aligned. */
typedef struct {
  double q[NMAX][3], qd[NMAX][3], fd[NMAX][NA], fp[NMAX][3], mp[NMAX][3];
} states;

static double soa_buf[5][NA * NMAX + 1];
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
 * with the scalar one, AoS. Returns the worst relative difference. */
static double compare(const char *kernel, const char *name, const double *batch,
                      const double *scalar, int dim, int n, int *nan_ok)
{
  /* The kinematic kernels keep the scalar sin and cos: bit for bit. */
  const int exact = strstr(kernel, "dynamics") == NULL && strstr(kernel, "eom") == NULL;
  const int bias = strcmp(name, "h") == 0 || strcmp(name, "b") == 0 || strcmp(name, "qdd") == 0;
  const double tol = exact ? 0.0 : bias ? TOL_BIAS : TOL;
  double worst = 0, x[64];
  for (int k = 0; k < n; k++) {
    const double *ref = scalar + k * dim;
    int any_nan = 0;
    for (int i = 0; i < dim; i++) {
      x[i] = batch[i * n + k];
      if (isnan(ref[i]) != isnan(x[i])) *nan_ok = 0;
      any_nan |= isnan(ref[i]);
    }
    if (any_nan || !compared[k]) continue;
    double e = tu_relerr(x, ref, dim, 1e-300);
    if (!(e <= worst)) worst = e;
  }
  char what[160];
  snprintf(what, sizeof what, "%s: %s within %.0e of the scalar kernel (n = %d)%s", kernel, name,
           tol, n, exact ? ", bit for bit" : "");
  tu_check(worst <= tol, what, worst, tol);
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
#define CMP(kern, name, arr, scal, dim)                               \
  snprintf(k, sizeof k, "%s_%s", pre, kern);                          \
  e = compare(k, name, arr, &want.scal[0][0], dim, n, nan_ok);        \
  if (e > worst) worst = e
  /* ik_jd */
  for (int i = 0; i < n; i++) {
    if (p) prru_param_ik_jd(p, s->q[i], want.d[i], want.Jd[i]);
    else prru_ik_jd(s->q[i], want.d[i], want.Jd[i]);
  }
  if (p) prru_param_batch_ik_jd(p, n, q, got[0], got[1]);
  else prru_batch_ik_jd(n, q, got[0], got[1]);
  CMP("ik_jd", "d", got[0], d, NA);
  CMP("ik_jd", "Jd", got[1], Jd, 3 * NA);
  /* mass, platform_jacobian, dme_terms */
  for (int i = 0; i < n; i++) {
    if (p) {
      prru_param_mass(p, s->q[i], want.M[i]);
      prru_param_platform_jacobian(p, s->q[i], want.JP[i]);
    } else {
      prru_mass(s->q[i], want.M[i]);
      prru_platform_jacobian(s->q[i], want.JP[i]);
    }
  }
  if (p) prru_param_batch_mass(p, n, q, got[2]);
  else prru_batch_mass(n, q, got[2]);
  CMP("mass", "M", got[2], M, 9);
  if (p) prru_param_batch_platform_jacobian(p, n, q, got[3]);
  else prru_batch_platform_jacobian(n, q, got[3]);
  CMP("platform_jacobian", "JP", got[3], JP, 18);
  if (p) prru_param_batch_dme_terms(p, n, q, got[0], got[1], got[2], got[3]);
  else prru_batch_dme_terms(n, q, got[0], got[1], got[2], got[3]);
  CMP("dme_terms", "d", got[0], d, NA);
  CMP("dme_terms", "Jd", got[1], Jd, 3 * NA);
  CMP("dme_terms", "M", got[2], M, 9);
  CMP("dme_terms", "JP", got[3], JP, 18);
  /* dynamics */
  for (int i = 0; i < n; i++) {
    if (p) prru_param_dynamics(p, s->q[i], s->qd[i], want.M[i], want.h[i], want.G[i]);
    else prru_dynamics(s->q[i], s->qd[i], want.M[i], want.h[i], want.G[i]);
  }
  if (p) prru_param_batch_dynamics(p, n, q, qd, got[2], got[4], got[5]);
  else prru_batch_dynamics(n, q, qd, got[2], got[4], got[5]);
  CMP("dynamics", "M", got[2], M, 9);
  CMP("dynamics", "h", got[4], h, 3);
  CMP("dynamics", "G", got[5], G, 3);
  /* eom */
  for (int i = 0; i < n; i++) {
    if (p) prru_param_eom(p, s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want.M[i], want.b[i]);
    else prru_eom(s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want.M[i], want.b[i]);
  }
  if (p) prru_param_batch_eom(p, n, q, qd, fd, fp, mp, got[2], got[6]);
  else prru_batch_eom(n, q, qd, fd, fp, mp, got[2], got[6]);
  CMP("eom", "M", got[2], M, 9);
  CMP("eom", "b", got[6], b, 3);
  /* eom_solve (constant kernels only): the forward-dynamics step */
  if (!p) {
    for (int i = 0; i < n; i++)
      prru_eom_solve(s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want.M[i], want.b[i],
                     want.qdd[i], want.minors[i]);
    prru_batch_eom_solve(n, q, qd, fd, fp, mp, got[2], got[6], got[7], got[4]);
    CMP("eom_solve", "M", got[2], M, 9);
    CMP("eom_solve", "b", got[6], b, 3);
    CMP("eom_solve", "qdd", got[7], qdd, 3);
    CMP("eom_solve", "minors", got[4], minors, 3);
  }
#undef CMP
  (void)got_store;
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
  printf("batched vs scalar kernels: worst relative difference %.2e (bound %.0e, h, b, qdd %.0e); last batch: "
         "%d of %d states reachable, %d compared (margin >= %.2g)\n",
         worst, TOL, TOL_BIAS, nreach, NMAX, nfar, MARGIN);
  return tu_finish("test_batch");
}
