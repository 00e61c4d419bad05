/* w_R and the map's status over a block of poses, in structure-of-arrays
 * layout, bit for bit what the scalar path gives pose by pose:
 * prru_jd_regular (prru_rcond3's arithmetic with three actuators, the
 * Householder QR of rcond_pinv with more), prru_mode_status and
 * prru_dme_from. Every IEEE operation is the scalar
 * code's, in its order; its branches (pivots, early failures) are selects,
 * so each stage is a loop over the poses that the build may vectorise
 * (PRRU_BATCH_LOOP, PRRU_BATCH_TARGETS: the batched kernels' options,
 * which never contract to FMA or reassociate). Lanes that fail early run
 * on through the later stages on meaningless numbers (no traps: the
 * results are discarded by the status). Only what w_R and the status need
 * is computed: no directions, semi-axes or dir_T.
 *
 * Locals of a loop marked omp simd must not have their address taken
 * (GCC turns them into per-lane arrays it does not vectorise), so the
 * stages keep per-lane values in scalars or in the workspace's rows, and
 * small loops over matrix entries are unrolled inside the loop over
 * poses.
 *
 * The stages are written once over the type and the number of actuators
 * (dme_batch_stages.h) and instantiated for three and four actuators
 * (dme_batch_types.inc), each in double (prru_dme_batch, as above) and float
 * (prru_dme_batch_f, the maps' --precision float: not bit for bit, it
 * says which statuses it is sure of). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "internal.h"
#include "prru_dme.h"

#ifndef PRRU_BATCH_LOOP
#define PRRU_BATCH_LOOP
#endif
#ifndef PRRU_BATCH_TARGETS
#define PRRU_BATCH_TARGETS
#endif

#define CH PRRU_DME_BATCH_CHUNK

/* One instance per number of actuators N and type: the loops over
 * matrix entries keep constant bounds, unrolled inside the loops over
 * poses. */
#define STAGE_NAME_(name, type, n) name##_##type##n
#define STAGE_NAME(name, type, n) STAGE_NAME_(name, type, n)
#define N 3
#include "dme_batch_types.inc"
#undef N
#define N 4
#include "dme_batch_types.inc"
#undef N

PRRU_BATCH_TARGETS
void prru_dme_batch(int nact, int n, const double *d, const double *Jd, const double *M, const double *JP,
                    double L, double rcond_min, int home, prru_dme_batch_ws *ws, double *w_R,
                    unsigned char *status, double *rcond, unsigned char *other)
{
  for (int o = 0; o < n; o += CH) {
    const int m = n - o < CH ? n - o : CH;
    if (nact == 3) {
      regular3_d3(n, o, m, d, Jd, L, rcond_min, home, ws);
      transformed_d3(n, o, m, M, JP, ws);
      range_basis_d3(n, o, m, JP, ws);
      singular_values_d3(m, ws);
    } else {
      regular_qr_d4(n, o, m, d, Jd, L, rcond_min, home, ws);
      transformed_d4(n, o, m, M, JP, ws);
      range_basis_d4(n, o, m, JP, ws);
      singular_values_d4(m, ws);
    }
    for (int k = 0; k < m; k++) {
      const int pre = (int)ws->pre[k];
      const int st = pre != PRRU_OK ? pre : ws->ok[k] != 0.0 ? PRRU_OK : PRRU_ESINGULAR;
      w_R[o + k] = st == PRRU_OK ? ws->w[k] : NAN;
      status[o + k] = (unsigned char)st;
      if (rcond) rcond[o + k] = ws->rcond[k];
      if (other) other[o + k] = (unsigned char)(ws->other[k] != 0.0);
    }
  }
}

/* The float path's margins, relative to FLT_EPSILON (u). The float
 * kernels' entries of J_d are within 16 u of the sum of their terms'
 * magnitudes (tests/test_float_kernels.c), a few times |J_d|; rcond =
 * 1/(|J|_1 |J^-1|_1) is within a factor 3 (the order) of J's relative
 * distance to the singular matrices, so a relative perturbation e of J
 * moves rcond by at most about 3 e, and the adjugate, determinant and
 * norms in float add a few u more. RC_MARGIN = 1024 u (1.2e-4) covers
 * 3 x 16 u x a term sum up to 20 |J| with room to spare. The same margin
 * covers the mode (det J_d's sign): flipping it takes a perturbation
 * that makes J singular, i.e. of relative size rcond; and the reach: at
 * the reach boundary an IK acos argument reaches +-1, where its
 * derivative, and so J_d, is unbounded (rcond -> 0). The DME's own tests
 * (det S > 0, sb > 0, tests/test_map_batch.c's bound) take J_d^-1, whose
 * relative error is kappa = 1/rcond times J_d's: their relative margins
 * (ws->gap) must exceed RC_MARGIN / rcond. */
#define RC_MARGIN (1024.0 * FLT_EPSILON)

PRRU_BATCH_TARGETS
void prru_dme_batch_f(int nact, int n, const float *d, const float *Jd, const float *M, const float *JP,
                      double L, double rcond_min, int home, prru_dme_batch_wsf *ws, double *w_R,
                      unsigned char *status, unsigned char *sure)
{
  const float Lf = (float)L, rf = (float)rcond_min;
  for (int o = 0; o < n; o += CH) {
    const int m = n - o < CH ? n - o : CH;
    if (nact == 3) {
      regular3_f3(n, o, m, d, Jd, Lf, rf, home, ws);
      transformed_f3(n, o, m, M, JP, ws);
      range_basis_f3(n, o, m, JP, ws);
      singular_values_f3(m, ws);
    } else {
      regular_qr_f4(n, o, m, d, Jd, Lf, rf, home, ws);
      transformed_f4(n, o, m, M, JP, ws);
      range_basis_f4(n, o, m, JP, ws);
      singular_values_f4(m, ws);
    }
    for (int k = 0; k < m; k++) {
      const int pre = (int)ws->pre[k];
      const int st = pre != PRRU_OK ? pre : ws->ok[k] != 0 ? PRRU_OK : PRRU_ESINGULAR;
      const double rc = ws->rcond[k];
      w_R[o + k] = st == PRRU_OK ? (double)ws->w[k] : NAN;
      status[o + k] = (unsigned char)st;
      sure[o + k] = st == PRRU_OK && rc - RC_MARGIN >= rcond_min &&
                    (double)ws->gap[k] * rc >= RC_MARGIN;
    }
  }
}
