/* Helpers shared inside the runtime, not part of its API. */
#ifndef PRRU_INTERNAL_H
#define PRRU_INTERNAL_H
#include <math.h>
#include <stddef.h>

#include "prru.h"
/* The build's model (its sizes PRRU_N*, descriptor and parameter
 * kernels): the runtime's own, never its public headers'. */
#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_param_kernels.h"
#include "prru_regressor.h"

/* The build's model fits the public structs (prru_sizes.h). */
typedef char prru_build_fits_public_structs[(PRRU_NACT <= PRRU_MAX_ACT && PRRU_NLIMB <= PRRU_MAX_LIMB &&
                                             PRRU_NBODY <= PRRU_MAX_BODY && PRRU_NJOINT <= PRRU_MAX_JOINT &&
                                             PRRU_NLAMBDA <= PRRU_MAX_LAMBDA)
                                                ? 1
                                                : -1];
/* The build's specialised kernel table (kernels.c); the parameter
 * kernels of both topologies are topology.h's. */
extern const prru_kernel_table prru_kernels_specialised;
#include "params_derive.h" /* prru_params_derive */
#include "topology.h"
/* A model's kernel K with its parameters: K(m, ik)(m->kernel_params, ...). */
#define KERNEL(m, k) ((m)->kernels->k)

/* prru_forward_dynamics's trust test on eom_solve's outputs, left in d
 * (M, b, qdd) with minors: PRRU_OK where qdd is trusted, else the status
 * the forward step returns. unseen_finite: the kernel's
 * PRRU_UNSEEN_FINITE_* test of the inputs its outputs do not witness. */
int prru_forward_verdict(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                         const prru_loads *l, const double minors[3], int unseen_finite);
/* prru_inverse_dynamics's test (three actuators) of inverse_terms's
 * outputs: d, J_d and J_d^-1 in d (d->d, d->Jd, d->Jdpinv), fd. */
int prru_inverse3_status(const prru_model *m, const prru_data *d, const double fd[3]);
/* prru_inverse_dynamics's test (four actuators) of inverse_terms's
 * outputs d and J_d (d->d, d->Jd; d->Jdpinv = J_d^+ where regular), and
 * the minimum-norm fd = J_d^+T tau into f. */
int prru_inverse4_status(const prru_model *m, prru_data *d, const double tau[3], double f[4]);
/* prru_actuator_null's n from a regular four-actuator J_d: PRRU_OK or
 * PRRU_ESINGULAR. */
int prru_null_from_jd(const prru_model *m, const double Jd[4 * 3], double n[4]);
/* The status of a failed inverse test st once the inputs are examined:
 * PRRU_EINPUT where one is not finite, else st. */
int prru_inverse_failure(int st, const double q[3], const double qd[3], const double qdd[3],
                         const prru_loads *l);

/* C99 has no M_PI. */
#define PRRU_PI 3.14159265358979323846

/* m without a stroke, in out (with its descriptor copied into *mech): for
 * what depends on the model's numbers alone (the base parameters), never
 * on how far the sliders may travel. */
static inline void prru_model_unbounded(const prru_model *m, prru_model *out, prru_mechanism *mech)
{
  *mech = *m->mech;
  for (int i = 0; i < mech->nact; i++) mech->d_min[i] = -INFINITY, mech->d_max[i] = INFINITY;
  *out = *m;
  out->mech = mech;
}

/* A screw drive's motor radians per metre of slider travel, 2 pi gear /
 * lead, as these double operations in this order: the generator
 * (model.drive_ratio) computes the same bits, and so every conversion
 * between the rail and the motor agrees with it. */
static inline double prru_drive_ratio(double lead, double gear)
{
  return 2.0 * PRRU_PI * gear / lead;
}

/* Whether v[0..n) are all finite. */
static inline int prru_finite_n(const double *v, int n)
{
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* Complete unrolling of a loop over matrix entries (GCC and Clang): the
 * batched maps need it before the vectoriser sees the loop over poses;
 * with four actuators, inverse dynamics (J_d^+ by a Householder QR) takes
 * 216 ns a call unrolled against 298. */
#if defined(__GNUC__)
#define PRRU_UNROLLED _Pragma("GCC unroll 16")
#else
#define PRRU_UNROLLED
#endif

/* For the buffers the batched kernels work on: 64-byte aligned, each row
 * (of a multiple of 8 doubles) starts on a cache line, and no AVX-512
 * access splits one (unaligned, the batched loops ran up to 1.5x slower). */
#if defined(__GNUC__)
#define PRRU_ALIGN64 __attribute__((aligned(64)))
#else
#define PRRU_ALIGN64
#endif

/* Failure paths: kept out of line, so that the fast path they branch
 * from saves no registers for them. */
#if defined(__GNUC__)
#define PRRU_COLD __attribute__((cold, noinline))
#else
#define PRRU_COLD
#endif

/* Formats msg (if non-NULL) and returns status. */
int prru_fail(char *msg, int msglen, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* Reads a whole file (at most 256 MiB); NULL with msg on failure. */
char *prru_read_file(const char *path, size_t *len, char *msg, int msglen);
/* 1 / (|A|_1 |A^-1|_1) of a 3x3 matrix via its adjugate (no pivoting:
 * callers only invert J_d, whose conditioning this is); 0 when the
 * determinant is 0 or not finite. Fills inv = A^-1 when non-NULL and the
 * determinant is usable. */
double prru_rcond3(const double a[9], double inv[9]);
/* Turns GSL's abort-on-error handler off, once per process: every runtime
 * call checks GSL's status codes itself. Thread-safe. */
void prru_gsl_init(void);
/* Poses per pass of prru_dme_batch's stages: its workspace (about 16 kB
 * with three actuators, the rows it touches) stays in the first-level
 * cache. */
#define PRRU_DME_BATCH_CHUNK 32
/* The workspace of one type T (double: prru_dme_batch_ws, float:
 * prru_dme_batch_wsf), for either number of actuators: rows of the
 * largest (prru_sizes.h), W, V, beta and e only for the Householder QR of
 * a four-actuator J_d. */
#define PRRU_DME_BATCH_WS(T)                                                                     \
  struct {                                                                                       \
    T inv[3 * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK], tmp[3 * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK],  \
        JtR[3 * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK], JtT[3 * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK],\
        Mt[PRRU_MAX_ACT * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK],                                   \
        c0[PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK], c1[PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK],          \
        g0[PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK], g1[PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK];          \
    T pre[PRRU_DME_BATCH_CHUNK], rcond[PRRU_DME_BATCH_CHUNK], other[PRRU_DME_BATCH_CHUNK],       \
        ok[PRRU_DME_BATCH_CHUNK], w[PRRU_DME_BATCH_CHUNK], gap[PRRU_DME_BATCH_CHUNK];            \
    T W[3 * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK], V[3 * PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK],      \
        beta[3][PRRU_DME_BATCH_CHUNK], e[PRRU_MAX_ACT][PRRU_DME_BATCH_CHUNK];                    \
  }
typedef PRRU_DME_BATCH_WS(double) prru_dme_batch_ws;
typedef PRRU_DME_BATCH_WS(float) prru_dme_batch_wsf;
/* w_R and the status of n poses of a model with nact actuators (3 or 4)
 * from their kernel outputs in SoA layout
 * (entry i of pose k at [i * n + k], as prru_batch_dme_terms gives d, J_d,
 * M and [J_R,P; J_T,P]): at every pose bit for bit what prru_jd_regular
 * (length scale L, tolerance rcond_min), prru_mode_status (home) and
 * prru_dme_from give, w_R NaN where the status is not PRRU_OK (unreachable
 * where a slider is not finite). rcond (prru_jd_regular's, 0 where
 * unreachable) and other (prru_jd_other_mode at a reachable pose) may be
 * NULL. No allocation: ws is scratch. */
void prru_dme_batch(int nact, int n, const double *d, const double *Jd, const double *M, const double *JP,
                    double L, double rcond_min, int home, prru_dme_batch_ws *ws, double *w_R,
                    unsigned char *status, double *rcond, unsigned char *other);
/* prru_dme_batch on float kernel outputs (prru_f_batch_dme_terms), in
 * float: w_R (within 64 FLT_EPSILON w_R / rcond(J_d) relative of the
 * double path's: tests/test_map_batch.c) and the status as float sees it; sure[k]
 * is 1 where that status is certain to be the double path's: PRRU_OK with
 * rcond and the DME's tests clear of their thresholds by more than float's
 * error (dme_batch.c). Elsewhere the caller decides the status in double
 * (prru_dme_batch on the double kernels' outputs). */
void prru_dme_batch_f(int nact, int n, const float *d, const float *Jd, const float *M, const float *JP,
                      double L, double rcond_min, int home, prru_dme_batch_wsf *ws, double *w_R,
                      unsigned char *status, unsigned char *sure);
#endif
