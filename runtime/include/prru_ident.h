/* Inertial-parameter identification: standard and base parameters, least
 * squares from measured motion and actuator forces, and periodic excitation
 * trajectories.
 *
 * The standard parameters pi (PRRU_NREG, order and units in
 * prru_regressor.h) are per body m, m c (c the centre of mass in the body
 * frame) and the inertia I_O about the body-frame origin, then per actuator
 * the armature, damping and Coulomb force. With no platform loads the
 * actuator forces satisfy J_d^T fd = Y(q, qd, qdd) pi (prru_regressor).
 *
 * Base parameters. Many standard parameters never move an actuator (a
 * slider's inertia) or only in fixed combinations (a link's mass with its
 * first moment and the sliders'); only base parameters beta = B pi can be
 * identified. B comes from a column-pivoted Householder QR (GSL) of Y
 * stacked over random reachable states (deterministic seed) with its
 * columns scaled to unit norm: the first nbase pivots are the base columns,
 * the rest are combinations of them, Y_rest = Y_base K, and
 * beta = pi_base + K pi_rest, so Y pi = Y_base beta for every pi. A pivot
 * counts when |R_ii| > PRRU_BASE_RTOL |R_00|; the gap between the last
 * kept and the first dropped pivot (typically 1e-3 against 1e-15) is
 * reported so that the decision can be judged.
 *
 * Least squares. Each sample gives, with J_d^+ = (J_d^T J_d)^-1 J_d^T,
 * the rows J_d^+T Y_base beta = J_d^+T J_d^T fd: for three actuators
 * exactly fd = J_d^-T Y_base beta, so residuals are actuator forces (N) and
 * white noise on fd is white noise on the rows; with four, the part of fd
 * that no motion reveals (the preload, along null(J_d^T)) is projected
 * out. Solved with gsl_multifit_linear; standard errors from the residual
 * variance s^2 = |r|^2 / (3 n - nbase) (3 independent rows per sample) and
 * (X^T X)^-1. */
#ifndef PRRU_IDENT_H
#define PRRU_IDENT_H

#include "prru.h"
#include "prru_regressor.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PRRU_NBODYPAR 10        /* m, m c (3), I_O (6) per body */
#define PRRU_BASE_RTOL 1e-9     /* relative pivot size of a base column */
#define PRRU_BASE_STATES 200    /* random states of prru_base_compute */

/* The standard parameters of a mechanism descriptor: pi from its mass,
 * com, inertia (about the centre) and drives. */
void prru_ident_standard(const prru_mechanism *me, double pi[PRRU_NREG]);
/* One body's mass, centre of mass and inertia about the centre (Ixx Iyy
 * Izz Ixy Ixz Iyz, as in model files) from its 10 standard parameters:
 * PRRU_EINPUT when m <= 0 or a value is not finite. */
int prru_ident_body(const double pib[PRRU_NBODYPAR], double *mass, double com[3],
                    double inertia[6]);

/* The role of a standard parameter in the base parameters. */
enum { PRRU_PAR_BASE = 0, PRRU_PAR_COMBINED = 1, PRRU_PAR_NONE = 2 };

typedef struct {
  int nbase;                      /* number of base parameters */
  int col[PRRU_NREG];             /* col[i], i < nbase: base parameter i's own standard one */
  int role[PRRU_NREG];            /* per standard parameter */
  double B[PRRU_NREG * PRRU_NREG];/* rows i < nbase: beta_i = sum_j B[i][j] pi_j */
  double vs;                      /* Coulomb smoothing velocity Y was evaluated with (m/s) */
  double last_kept, first_dropped;/* |R_ii| / |R_00| on either side of the cut */
  int nstates;
  unsigned long seed;
} prru_base;

/* A random reachable, regular state (q in |q1|, |q2| <= 0.3 rad, |q3| <=
 * 0.2 L about (0, 0, 0), in the assembly mode of q = 0; qd, qdd uniform in
 * +-1 rad/s, +-L/s and +-4 rad/s^2, +-4 L/s^2) from the generator state
 * *s (xorshift64*, deterministic). PRRU_ENOCONV when 1000 draws found no
 * regular pose. */
int prru_ident_random_state(const prru_model *m, prru_data *d, unsigned long long *s,
                            double q[3], double qd[3], double qdd[3]);

/* Base parameters from nstates random states (PRRU_BASE_STATES when <= 0)
 * drawn with seed; vs > 0 the Coulomb smoothing velocity. Allocates (a
 * set-up call). PRRU_EINPUT for vs <= 0, PRRU_ENOMEM, PRRU_ENOCONV. */
int prru_base_compute(const prru_model *m, double vs, int nstates, unsigned long seed,
                      prru_base *b);
/* beta = B pi (nbase values). */
void prru_base_params(const prru_base *b, const double pi[PRRU_NREG], double beta[PRRU_NREG]);
/* The base columns of rows x PRRU_NREG Y: Yb (rows x nbase). */
void prru_base_regressor(const prru_base *b, const double *Y, int rows, double *Yb);
/* A standard parameter vector with B pi = beta: pi0 (a prior, e.g. the
 * model's) with each base parameter's own standard parameter replaced so
 * that the combination equals beta (the others keep pi0's values). */
void prru_base_to_standard(const prru_base *b, const double beta[PRRU_NREG],
                           const double pi0[PRRU_NREG], double pi[PRRU_NREG]);

/* Observation rows of one sample: A (PRRU_NACT x nbase) = J_d^+T Y_base
 * and y (PRRU_NACT) = J_d^+T J_d^T fd. The status of prru_check_regular
 * (unreachable or singular poses give no rows). */
int prru_ident_rows(const prru_model *m, prru_data *d, const prru_base *b, const double q[3],
                    const double qd[3], const double qdd[3], const double fd[PRRU_NACT],
                    double *A, double y[PRRU_NACT]);

typedef struct {
  int nsamples, nrows, dof;   /* dof = 3 nsamples - nbase */
  double beta[PRRU_NREG];     /* the estimate, nbase values */
  double se[PRRU_NREG];       /* standard errors */
  /* Resolution: rms(y) / rms(X_i), the value at which parameter i alone
   * would give forces of the data's RMS size; an estimate within 1e-9 of
   * it of a bound is at the bound to rounding. */
  double scale[PRRU_NREG];
  double sigma;               /* residual standard deviation s (N) */
  double rms[PRRU_NACT];      /* residual RMS per row of a sample (N) */
  double cond;                /* 2-norm condition number of the column-scaled X */
} prru_ident_result;

/* Least squares of the base parameters from n samples (q, qd, qdd, fd:
 * row-major n x 3 and n x PRRU_NACT). PRRU_EINPUT when n is too small
 * (3 n <= nbase), or with *bad the 0-based sample and its status
 * (PRRU_EUNREACHABLE, PRRU_ESINGULAR, PRRU_EINPUT for non-finite values)
 * when a sample gives no rows; PRRU_ESINGULAR when the stacked regressor
 * is rank deficient (the motion does not excite every base parameter);
 * PRRU_ENOMEM. Allocates. */
int prru_identify(const prru_model *m, const prru_base *b, int n, const double *q, const double *qd,
                  const double *qdd, const double *fd, prru_ident_result *r, int *bad);

/* ---- Periodic excitation ----
 * q_k(t) = c_k + sum_{l=1..L} (a_kl sin(l w t) + b_kl cos(l w t)),
 * w = 2 pi / period: q, qd and qdd are analytic and periodic. */
#define PRRU_EXCITE_MAX_HARMONICS 8

typedef struct {
  double period;                /* s */
  int harmonics;                /* L, 1..PRRU_EXCITE_MAX_HARMONICS */
  double centre[3];
  double a[3][PRRU_EXCITE_MAX_HARMONICS], b[3][PRRU_EXCITE_MAX_HARMONICS];
} prru_fourier;

void prru_fourier_eval(const prru_fourier *f, double t, double q[3], double qd[3], double qdd[3]);

typedef struct {
  double fd_max[PRRU_NACT];  /* |fd_i| limit (N), > 0 */
  double d_min[PRRU_NACT], d_max[PRRU_NACT]; /* slider strokes (m), -inf/+inf by default */
  double rcond_min;          /* regularity along the path (prru_check_regular's rcond) */
  double amplitude_max[3];   /* |q_k - c_k| bound of the start and of each coordinate's sum of |a|, |b| */
  int samples;               /* points per period the objective stacks (>= nbase/3 + 1) */
  int check_samples;         /* points per period of the final feasibility check */
  int max_evals;             /* Nelder-Mead budget */
  unsigned long seed;
} prru_excite_options;

/* fd_max 500 N each, no stroke limits, rcond_min 1e-2, amplitude 0.25 rad, 0.25 rad, 0.1 L,
 * 100 samples, 2000 check samples, 3000 evaluations, seed 1. */
void prru_excite_options_default(prru_excite_options *o);

typedef struct {
  double cond;          /* condition number of the column-scaled stacked base regressor */
  double cond_start;    /* the same for the starting coefficients (inf: infeasible start) */
  double fd_peak[PRRU_NACT];
  double rcond_worst;
  int evals;
  int shrunk;           /* times the motion was scaled by 0.95 to pass the dense check */
} prru_excite_result;

/* Optimises f's coefficients (period, harmonics and centre given) for the
 * smallest condition number of the stacked base regressor under the
 * model m (inverse dynamics with no platform loads), subject to every
 * checked point being reachable, regular (rcond >= rcond_min), in the
 * assembly mode of the centre and within the force and stroke limits. Deterministic
 * (seeded start, GSL nmsimplex2). PRRU_EINPUT for bad options or centre
 * (msg says which), PRRU_ENOCONV when no feasible trajectory was found,
 * PRRU_EINTERRUPTED when *stop became non-zero. Allocates. */
int prru_excite(const prru_model *m, const prru_base *b, const prru_excite_options *o,
                volatile sig_atomic_t *stop, prru_fourier *f, prru_excite_result *r, char *msg,
                int msglen);

/* The excitation's feasibility at n points per period: 0 and the peak
 * forces and worst rcond, or the first failing point's status
 * (PRRU_EUNREACHABLE, PRRU_ESINGULAR, or PRRU_EINPUT for a force or
 * stroke limit)
 * with *t_bad its time. */
int prru_excite_check(const prru_model *m, const prru_fourier *f, const prru_excite_options *o,
                      int n, double fd_peak[PRRU_NACT], double *rcond_worst, double *t_bad);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_IDENT_H */
