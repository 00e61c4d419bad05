/* The paper's claims about w_R (section 5, fig. 7) and the spec's facts of
 * its geometry, for the paper's model only: w_R(0, 0) = 1.80468, symmetry
 * in q1 (the model is symmetric about the plane y = 0), w_R falling toward 1
 * with |q1|, and the singular locus near |q1| = 0.29 rad at q2 = -pi/4. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru_dme.h"
#include "testutil.h"

#define PI 3.14159265358979323846

static prru_model M;
static prru_data *D;

static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

static double det3(const double a[9])
{
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

static void test_claims(void)
{
  prru_dme r, s;
  double q0[3] = {0, 0, 0};
  prru_dme_eval(&M, D, q0, &r);
  printf("w_R(0, 0) = %.6f\n", r.w_R);
  tu_check(fabs(r.w_R - 1.80468) < 5e-6, "w_R(0, 0) = 1.80468 (spec)", fabs(r.w_R - 1.80468), 5e-6);
  double worst = 0;
  for (int k = 0; k < 300; k++) {
    double q[3] = {tu_uniform(0, PI / 6), tu_uniform(-PI / 4, PI / 6), tu_uniform(-0.8, 0.1)};
    double qm[3] = {-q[0], q[1], q[2]};
    int a = prru_dme_eval(&M, D, q, &r), b = prru_dme_eval(&M, D, qm, &s);
    TU_TRUE(a == b, "status symmetric in q1");
    if (a != PRRU_OK) continue;
    if (rel(s.w_R, r.w_R) > worst) worst = rel(s.w_R, r.w_R);
  }
  tu_check(worst <= 1e-12, "w_R(-q1, q2) = w_R(q1, q2)", worst, 1e-12);
  /* At q2 = 0 (q3 = 0) w_R falls monotonically from its value at q1 = 0. */
  double prev = INFINITY;
  int mono = 1;
  for (int i = 0; i <= 200; i++) {
    double q[3] = {PI / 6 * i / 200.0, 0, 0};
    prru_dme_eval(&M, D, q, &r);
    if (!(r.w_R < prev && r.w_R > 1.0)) mono = 0;
    prev = r.w_R;
  }
  TU_TRUE(mono, "w_R strictly decreasing in |q1| at q2 = 0 and > 1");
  prru_dme_eval(&M, D, (const double[3]){PI / 6, 0, 0}, &r);
  prru_dme_eval(&M, D, q0, &s);
  TU_TRUE(r.w_R - 1.0 < 0.8 * (s.w_R - 1.0), "w_R(pi/6, 0) - 1 well below w_R(0, 0) - 1");
  TU_TRUE(prru_dme_eval(&M, D, (const double[3]){0, 2.0, 0}, &r) == PRRU_EUNREACHABLE,
          "q2 = 2 rad is out of reach");
}

static void test_locus(void)
{
  /* det J_d changes sign on q2 = -pi/4 between q1 = 0.2 and 0.4. */
  double lo = 0.2, hi = 0.4, Jd[9];
  prru_jd((const double[3]){lo, -PI / 4, 0}, Jd);
  double slo = det3(Jd);
  prru_jd((const double[3]){hi, -PI / 4, 0}, Jd);
  TU_TRUE(slo * det3(Jd) < 0, "det J_d changes sign on q2 = -pi/4 between q1 = 0.2 and 0.4");
  for (int i = 0; i < 200; i++) {
    double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    prru_jd((const double[3]){mid, -PI / 4, 0}, Jd);
    if (det3(Jd) * slo > 0) lo = mid; else hi = mid;
  }
  printf("singular locus at q2 = -pi/4: |q1| = %.6f\n", lo);
  TU_TRUE(fabs(lo - 0.29) < 0.02, "singular locus at |q1| about 0.29 rad for q2 = -pi/4 (spec)");
  prru_dme r;
  double qn[3] = {lo - 1e-4, -PI / 4, 0};
  TU_TRUE(prru_dme_eval(&M, D, qn, &r) == PRRU_OK && r.w_R > 100, "near the locus: regular, w_R > 100");
}

static void test_map(void)
{
  prru_model m3 = M;
  m3.jd_rcond_min = 1e-3;
  prru_map_grid g = {-PI / 6, PI / 6, -PI / 4, 1.2, 0.0, 57, 43};
  long n = (long)g.n1 * g.n2;
  double *w = malloc(n * sizeof(double));
  unsigned char *st = malloc(n);
  prru_map_options o;
  prru_map_options_default(&o);
  prru_map_summary sum;
  TU_TRUE(prru_map_eval(&m3, &g, &o, w, st, &sum) == PRRU_OK, "map runs");
  int sym = 1;
  double worst = 0;
  for (int i = 0; i < g.n1; i++)
    for (int j = 0; j < g.n2; j++) {
      long k = (long)i * g.n2 + j, km = (long)(g.n1 - 1 - i) * g.n2 + j;
      if (st[k] != st[km]) sym = 0;
      if (st[k] == PRRU_OK && rel(w[km], w[k]) > worst) worst = rel(w[km], w[k]);
    }
  TU_TRUE(sym, "map statuses symmetric in q1");
  tu_check(worst <= 1e-12, "map symmetric in q1", worst, 1e-12);
  TU_TRUE(sum.n_singular > 0 && sum.n_unreachable > 0 && sum.n_ok > 0,
          "the grid has ok, singular and unreachable points");
  free(w);
  free(st);
}

int main(void)
{
  prru_model_default(&M);
  D = malloc(sizeof *D);
  test_claims();
  test_locus();
  test_map();
  free(D);
  return tu_finish("paper_dme");
}
