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
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"
#include "prru_dme.h"
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
  if (st == PRRU_OK) st = prru_mode_status(st, D->Jd, home);
  if (st != PRRU_OK) return st;
  prru_dme r;
  st = prru_dme_eval(m, D, q, &r);
  *w = r.w_R;
  return st;
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

  TU_TRUE(kinds[0] > 0, "the grids have regular points");
  TU_TRUE(kinds[1] > 0, "the grids have singular points");
  TU_TRUE(kinds[2] > 0, "the grids have unreachable points");
  TU_TRUE(PRRU_NACT != 3 || kinds[3] > 0, "the grids reach the other assembly mode");
  free(D);
  return tu_finish("test_map_batch");
}
