/* Drop-in check of the single-precision controller kernels
 * (gen/prru_gen.py --precision float) linked beside the double ones: this
 * file, generated/ and the float set are all test_dropin.sh compiles, under
 * the same strict flags (no double promotion, no float conversion), as
 * C99, C11 and C++. Both headers in one translation unit and both sets in
 * one program: no symbol, macro or type clashes. The agreement checked
 * here is a smoke test (1e-4 of each array's largest entry, at the spec's
 * section 10 point); tests/test_float_kernels.c holds every output to its
 * derived bound over the workspace. */
#include <math.h>
#include <stdio.h>

#include "paper3prru_f_kernels.h"
#include "paper3prru_kernels.h"

static int failures = 0;

static void check(const char *what, const float *got, const double *want, int n)
{
  double scale = 0.0, worst = 0.0;
  int i;
  for (i = 0; i < n; i++)
    if (fabs(want[i]) > scale) scale = fabs(want[i]);
  for (i = 0; i < n; i++) {
    double err = fabs((double)got[i] - want[i]);
    if (isnan(err)) err = HUGE_VAL;
    if (err > worst) worst = err;
  }
  if (!(worst <= 1e-4 * scale)) {
    printf("FAIL %s: error %.3g, limit %.3g\n", what, worst, 1e-4 * scale);
    failures++;
  } else {
    printf("ok   %-24s relative error %.3g\n", what, worst / scale);
  }
}

static void check_nan(const char *what, const float *got, int n)
{
  int i;
  for (i = 0; i < n; i++)
    if (!isnan(got[i])) {
      printf("FAIL %s[%d] = %.9g, want NaN\n", what, i, (double)got[i]);
      failures++;
      return;
    }
  printf("ok   %-24s all %d NaN\n", what, n);
}

int main(void)
{
  const double load[3] = {1.0, -2.0, 3.0};
  const float qf[3] = {0.1f, 0.2f, -0.8f}, qdf[3] = {0.3f, -0.4f, 0.5f},
              qddf[3] = {0.5f, -0.2f, 1.0f}, loadf[3] = {1.0f, -2.0f, 3.0f};
  double qr[3], qdr[3], qddr[3];
  double d[3], Jd[9], M[9], h[3], G[3], b[3], x[3], minors[3], Jdinv[9], fd[3];
  float df[3], Jdf[9], Mf[9], hf[3], Gf[3], bf[3], xf[3], minorsf[3], Jdinvf[9], fdf[3];
  int i;

  /* Both get the same float-rounded inputs. */
  for (i = 0; i < 3; i++) {
    qr[i] = (double)qf[i];
    qdr[i] = (double)qdf[i];
    qddr[i] = (double)qddf[i];
  }
  paper3prru_ik_jd(qr, d, Jd);
  paper3prru_f_ik_jd(qf, df, Jdf);
  check("ik_jd d", df, d, 3);
  check("ik_jd Jd", Jdf, Jd, 9);
  paper3prru_dynamics(qr, qdr, M, h, G);
  paper3prru_f_dynamics(qf, qdf, Mf, hf, Gf);
  check("dynamics M", Mf, M, 9);
  check("dynamics h", hf, h, 3);
  check("dynamics G", Gf, G, 3);
  paper3prru_eom_solve(qr, qdr, load, load, load, M, b, x, minors);
  paper3prru_f_eom_solve(qf, qdf, loadf, loadf, loadf, Mf, bf, xf, minorsf);
  check("eom_solve b", bf, b, 3);
  check("eom_solve qdd", xf, x, 3);
  check("eom_solve minors", minorsf, minors, 3);
  paper3prru_inverse_terms(qr, qdr, qddr, load, load, d, Jd, Jdinv, fd);
  paper3prru_f_inverse_terms(qf, qdf, qddf, loadf, loadf, df, Jdf, Jdinvf, fdf);
  check("inverse_terms Jdinv", Jdinvf, Jdinv, 9);
  check("inverse_terms fd", fdf, fd, 3);
  if (PAPER3PRRU_F_NQ != PAPER3PRRU_NQ || PAPER3PRRU_F_ARITH_INVERSE_TERMS != PAPER3PRRU_ARITH_INVERSE_TERMS) {
    printf("FAIL the float set's sizes or operation counts differ from the double set's\n");
    failures++;
  }

  {
    /* Unreachable (limbs 1 and 2 out of reach) and non-finite q. */
    const float bad[3][3] = {{1.5f, 0.0f, 0.0f}, {0.1f, NAN, -0.8f}, {0.1f, 0.2f, INFINITY}};
    for (i = 0; i < 3; i++) {
      paper3prru_f_inverse_terms(bad[i], qdf, qddf, loadf, loadf, df, Jdf, Jdinvf, fdf);
      check_nan("inverse_terms fd", fdf, 3);
      paper3prru_f_eom_solve(bad[i], qdf, loadf, loadf, loadf, Mf, bf, xf, minorsf);
      check_nan("eom_solve qdd", xf, 3);
      paper3prru_f_dynamics(bad[i], qdf, Mf, hf, Gf);
      check_nan("dynamics M", Mf, 9);
    }
  }

  if (failures) {
    printf("%d check(s) failed\n", failures);
    return 1;
  }
  printf("all float drop-in checks passed\n");
  return 0;
}
