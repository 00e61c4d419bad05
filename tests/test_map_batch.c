/* The map's batched evaluation (prru_batch_dme_terms, then prru_dme_batch:
 * w_R and the status of a block of points with selects for branches)
 * against the scalar path point by point: prru_check_regular, the mode
 * classification (prru_mode_status against prru_map_home_mode) and
 * prru_dme_eval. The contract is bit for bit: every w_R the same double
 * (memcmp, so NaN exactly where the scalar path gives NaN) and every status
 * the same. Grids: the paper's fig. 7 rectangle, grids crossing the
 * singular band (at the default tolerance and at a wide one), reaching
 * unreachable poses and the other assembly mode, at other heights q3, and
 * of sizes that are not multiples of the map's block of points (and one
 * smaller than it), with one and two threads. Every kind of status must
 * occur somewhere, so no branch of the batched code goes untested. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"
#include "prru_dme.h"
#include "prru_kernels.h"
#include "testutil.h"

#define PI 3.14159265358979323846

static prru_data *D;
static long kinds[4]; /* ok, singular, unreachable, other mode */

/* The scalar path at point (i, j) of g: the status prru_map_eval documents
 * and prru_dme_eval's w_R (NaN where the status is not ok). */
static int scalar_point(const prru_model *m, const prru_map_grid *g, int home, int i, int j,
                        double *w)
{
  const double q[3] = {prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i),
                       prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j), g->q3};
  double rc;
  *w = NAN;
  int st = prru_check_regular(m, D, q, &rc);
  if (st == PRRU_OK) st = prru_mode_status(st, D->Jd, m->mech->nact, home);
  if (st != PRRU_OK) return st;
  prru_dme r;
  st = prru_dme_eval(m, D, q, &r);
  *w = r.w_R;
  return st;
}

/* --precision float (prru_map_options.precision): the statuses are the
 * scalar path's exactly (they are decided in double), and w_R agrees with
 * double's within a bound that follows from where float's error enters.
 * The float kernels' outputs carry a relative error of a few FLT_EPSILON
 * (within 16 FLT_EPSILON of the sum of their terms' magnitudes,
 * test_float_kernels.c), e = 16 FLT_EPSILON in J_d, M and J_P. w_R = sa /
 * sb is the ratio of the singular values of G = Mt C^T S^-1, which takes
 * J_d^-1 twice (Mt = J^-T M J^-1, C = Q^T J_R,P J^-1): a relative error e
 * of J_d moves J_d^-1 by kappa e, kappa = 1 / rcond(J_d) (1-norm, rotation
 * columns in units of L), so G moves by about 2 kappa e of |G| = sa; that
 * moves sb by as much absolutely, i.e. by 2 kappa e w_R relatively (w_R =
 * sa / sb is the conditioning sb enters with). So per point
 *   |w_f - w| / w <= 2 kappa e (1 + w) <= 64 FLT_EPSILON w / rcond
 * (w >= 1). Measured: at most 3.8 FLT_EPSILON w / rcond over these grids;
 * where rcond >= 1e-2 the error still grows with w_R (6.7e-5 at w_R = 20):
 * the target of 1e-5 there holds only for w_R up to a few
 * (printed below), since an M rounded to float (2 FLT_EPSILON relative
 * alone) is amplified by w_R / rcond. */
#define W_BOUND(rc, w) (64.0 * FLT_EPSILON * (w) / (rc))
static double float_worst_rel, float_worst_scaled, w_first_over = INFINITY;
static long n_good, n_good_within; /* points with rcond >= 1e-2; of them within 1e-5 */

static void check_float(const char *what, const prru_model *m, prru_map_grid g)
{
  const long n = (long)g.n1 * g.n2;
  double *w = malloc((size_t)n * sizeof *w);
  unsigned char *st = malloc((size_t)n);
  const int home = prru_map_home_mode(m, &g);
  prru_map_options o;
  prru_map_options_default(&o);
  o.precision = PRRU_PRECISION_FLOAT;
  memset(st, 0xAA, (size_t)n);
  TU_TRUE(prru_map_eval(m, &g, &o, w, st, NULL) == PRRU_OK, "float map runs");
  long bad_st = 0, bad_w = 0, first = 0;
  for (int i = 0; i < g.n1; i++)
    for (int j = 0; j < g.n2; j++) {
      const long k = (long)i * g.n2 + j;
      double ws, rc;
      const int ss = scalar_point(m, &g, home, i, j, &ws);
      const double q[3] = {prru_map_axis(g.q1_lo, g.q1_hi, g.n1, i),
                           prru_map_axis(g.q2_lo, g.q2_hi, g.n2, j), g.q3};
      prru_check_regular(m, D, q, &rc);
      bad_st += ss != st[k];
      if (ss != st[k] && first++ == 0)
        fprintf(stderr, "%s, float: point (%d, %d): status %d vs scalar %d\n", what, i, j, st[k], ss);
      if (ss != PRRU_OK) {
        bad_w += !isnan(w[k]);
        continue;
      }
      const double e = fabs(w[k] - ws) / ws;
      if (e > W_BOUND(rc, ws)) bad_w++;
      if (e * rc / FLT_EPSILON / ws > float_worst_scaled) float_worst_scaled = e * rc / FLT_EPSILON / ws;
      if (rc >= 1e-2) {
        n_good++;
        n_good_within += e <= 1e-5;
        float_worst_rel = e > float_worst_rel ? e : float_worst_rel;
        if (e > 1e-5 && ws < w_first_over) w_first_over = ws;
      }
    }
  char msg[160];
  snprintf(msg, sizeof msg, "%s, float: statuses the scalar path's (points differing)", what);
  tu_check(bad_st == 0, msg, (double)bad_st, 0.0);
  snprintf(msg, sizeof msg, "%s, float: w_R within 64 FLT_EPSILON w_R / rcond (points beyond)", what);
  tu_check(bad_w == 0, msg, (double)bad_w, 0.0);
  free(w);
  free(st);
}

/* The status of the scalar path at (q1, q2, q3). */
static int status_at(const prru_model *m, int home, double q1, double q2, double q3)
{
  double w;
  const prru_map_grid g = {q1, q1 + 1, q2, q2 + 1, q3, 2, 2};
  return scalar_point(m, &g, home, 0, 0, &w);
}

/* Float's statuses where they are hardest to get right: along q2 rows at
 * several q1, wherever the scalar status changes between samples (ok |
 * singular at rcond_min, singular | unreachable, ok | other mode at a small
 * rcond_min, ok | out of stroke), the change is bisected down to adjacent
 * doubles and a 2 x 2 map put on the two sides (q2 = lo and hi, the
 * thresholds' values within an ulp): float's own numbers there are on
 * either side by chance, so these statuses come from the decision in
 * double. Returns the number of boundaries checked. */
static int check_float_boundaries(const char *what, const prru_model *m, double q3)
{
  prru_map_grid g0 = {-1.55, 1.55, -1.55, 1.55, q3, 2, 2};
  const int home = prru_map_home_mode(m, &g0);
  int found = 0;
  for (int r = 0; r < 9; r++) {
    const double q1 = -1.2 + 0.3 * r;
    double prev_q2 = -1.55;
    int prev = status_at(m, home, q1, prev_q2, q3);
    for (int s = 1; s <= 120; s++) {
      const double q2 = -1.55 + 3.1 * s / 120;
      const int st = status_at(m, home, q1, q2, q3);
      if (st != prev) {
        double lo = prev_q2, hi = q2;
        for (int it = 0; it < 80 && nextafter(lo, hi) < hi; it++) {
          const double mid = lo + (hi - lo) / 2;
          if (status_at(m, home, q1, mid, q3) == prev) lo = mid;
          else hi = mid;
        }
        char name[160];
        snprintf(name, sizeof name, "%s boundary %d -> %d at q1 %.2f", what, prev, st, q1);
        check_float(name, m, (prru_map_grid){q1, nextafter(q1, 2.0), lo, hi, q3, 2, 2});
        found++;
      }
      prev = st;
      prev_q2 = q2;
    }
  }
  return found;
}

static void count(int st)
{
  kinds[st == PRRU_OK ? 0 : st == PRRU_ESINGULAR ? 1 : st == PRRU_EUNREACHABLE ? 2 : 3]++;
}

/* One grid, nthreads 1 and 2: every point's bits and status. */
static void check_grid(const char *what, const prru_model *m, prru_map_grid g)
{
  const long n = (long)g.n1 * g.n2;
  double *w = malloc((size_t)n * sizeof *w);
  unsigned char *st = malloc((size_t)n);
  const int home = prru_map_home_mode(m, &g);
  long bad_w = 0, bad_st = 0, first_bad = -1, local[4] = {0, 0, 0, 0};
  for (int nt = 1; nt <= 2; nt++) {
    prru_map_options o;
    prru_map_options_default(&o);
    o.nthreads = nt;
    memset(w, 0, (size_t)n * sizeof *w);
    memset(st, 0xAA, (size_t)n);
    int rc = prru_map_eval(m, &g, &o, w, st, NULL);
    char msg[160];
    snprintf(msg, sizeof msg, "%s: map runs (%d thread%s)", what, nt, nt > 1 ? "s" : "");
    TU_TRUE(rc == PRRU_OK, msg);
    for (int i = 0; i < g.n1; i++)
      for (int j = 0; j < g.n2; j++) {
        const long k = (long)i * g.n2 + j;
        double ws;
        const int ss = scalar_point(m, &g, home, i, j, &ws);
        const int wrong_w = memcmp(&ws, &w[k], sizeof ws) != 0, wrong_st = ss != st[k];
        bad_w += wrong_w;
        bad_st += wrong_st;
        if ((wrong_w || wrong_st) && first_bad < 0) {
          first_bad = k;
          fprintf(stderr, "%s, %d thread(s): point (%d, %d): status %d vs scalar %d, w_R %.17g vs %.17g\n",
                  what, nt, i, j, st[k], ss, w[k], ws);
        }
        if (nt == 1) {
          count(ss);
          local[ss == PRRU_OK ? 0 : ss == PRRU_ESINGULAR ? 1 : ss == PRRU_EUNREACHABLE ? 2 : 3]++;
        }
      }
  }
  printf("%-44s %4d x %-4d ok %6ld singular %6ld unreachable %6ld other mode %6ld\n", what, g.n1,
         g.n2, local[0], local[1], local[2], local[3]);
  check_float(what, m, g);
  char msg[160];
  snprintf(msg, sizeof msg, "%s: w_R bit for bit the scalar path's (points differing)", what);
  tu_check(bad_w == 0, msg, (double)bad_w, 0.0);
  snprintf(msg, sizeof msg, "%s: statuses the scalar path's (points differing)", what);
  tu_check(bad_st == 0, msg, (double)bad_st, 0.0);
  free(w);
  free(st);
}

int main(void)
{
  prru_model m;
  prru_model_default(&m);
  D = malloc(sizeof *D);
  double h = 0; /* the model's length scale: its mean upper-link length */
  for (int i = 0; i < PRRU_NLIMB; i++) h += m.mech->l1[i] / PRRU_NLIMB;
  prru_model wide = m;
  wide.jd_rcond_min = 0.05; /* a wide singular band */

  /* fig. 7's rectangle; the map's block is 128 points, so 67 < block and
   * 131, 257 are one and two blocks and a few points. */
  check_grid("fig. 7 rectangle", &m, (prru_map_grid){-PI / 6, PI / 6, -PI / 4, PI / 4, 0.0, 61, 67});
  check_grid("fig. 7 rectangle, wide band", &wide,
             (prru_map_grid){-PI / 6, PI / 6, -PI / 4, PI / 4, 0.0, 37, 131});
  /* Across the singular locus into the other assembly mode and out of
   * reach: the whole square of rotations the kernels take. */
  check_grid("beyond reach, default tolerance", &m, (prru_map_grid){-1.55, 1.55, -1.55, 1.55, 0.0, 53, 257});
  check_grid("beyond reach, wide band", &wide, (prru_map_grid){-1.55, 1.55, -1.55, 1.55, 0.0, 41, 129});
  check_grid("beyond reach, raised platform", &m,
             (prru_map_grid){-1.2, 1.2, -1.3, 1.3, 0.3 * h, 29, 200});
  check_grid("beyond reach, lowered platform", &wide,
             (prru_map_grid){-1.2, 1.2, -1.3, 1.3, -0.3 * h, 31, 127});
  /* Small grids: n2 of 2 and 3 points, a single partial block. */
  check_grid("2 x 2", &m, (prru_map_grid){-0.5, 0.7, -0.9, 1.1, 0.0, 2, 2});
  check_grid("3 x 3 across everything", &wide, (prru_map_grid){-1.5, 1.5, -1.5, 1.5, 0.0, 3, 3});

  /* Float's statuses at the thresholds themselves. */
  prru_model small = m;
  small.jd_rcond_min = 1e-8; /* ok next to the other mode's locus */
  prru_mechanism stroke_mech = *m.mech;
  prru_model stroke = m;
  {
    double d0[PRRU_NACT], J0[3 * PRRU_NACT];
    prru_ik_jd((const double[3]){0.0, 0.0, 0.0}, d0, J0);
    for (int i = 0; i < PRRU_NACT; i++) stroke_mech.d_max[i] = d0[i] + 0.02 * h;
    stroke.mech = &stroke_mech;
  }
  int nb = check_float_boundaries("default tolerance", &m, 0.0);
  nb += check_float_boundaries("wide band", &wide, 0.0);
  nb += check_float_boundaries("numerical tolerance", &small, 0.0);
  nb += check_float_boundaries("stroke", &stroke, 0.0);
  printf("float: statuses checked at %d status boundaries (2 x 2 maps on adjacent doubles)\n", nb);
  TU_TRUE(nb > 50, "the boundary scan finds the thresholds");
  printf("float: where rcond >= 1e-2, largest |w_f - w| / w %.3g, %ld of %ld points within 1e-5, the "
         "smallest w_R beyond it %.3g; largest |w_f - w| / w rcond / (FLT_EPSILON w): %.3g (bound 64)\n",
         float_worst_rel, n_good_within, n_good, w_first_over, float_worst_scaled);
  TU_TRUE(kinds[0] > 0, "the grids have regular points");
  TU_TRUE(kinds[1] > 0, "the grids have singular points");
  TU_TRUE(kinds[2] > 0, "the grids have unreachable points");
  TU_TRUE(PRRU_NACT != 3 || kinds[3] > 0, "the grids reach the other assembly mode");
  free(D);
  return tu_finish("test_map_batch");
}
