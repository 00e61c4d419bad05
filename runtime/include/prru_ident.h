/* Inertial-parameter identification: standard and base parameters, least
 * squares from measured motion and actuator forces, and periodic excitation
 * trajectories.
 *
 * The standard parameters pi (nreg = 10 nbody + 3 nact of them, order and units in
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

#ifdef __cplusplus
extern "C" {
#endif

#define PRRU_NBODYPAR 10        /* m, m c (3), I_O (6) per body */
#define PRRU_BASE_RTOL 1e-9     /* relative pivot size of a base column */
#define PRRU_BASE_STATES 200    /* random states of prru_base_compute */

/* The standard parameters of a mechanism descriptor: pi (10 me->nbody +
 * 3 me->nact values) from its mass, com, inertia (about the centre) and
 * drives. */
PRRU_API void prru_ident_standard(const prru_mechanism *me, double pi[]);
/* One body's mass, centre of mass and inertia about the centre (Ixx Iyy
 * Izz Ixy Ixz Iyz, as in model files) from its 10 standard parameters:
 * PRRU_EINPUT when m <= 0 or a value is not finite. */
PRRU_API int prru_ident_body(const double pib[PRRU_NBODYPAR], double *mass, double com[3],
                             double inertia[6]);

/* The role of a standard parameter in the base parameters. */
enum { PRRU_PAR_BASE = 0, PRRU_PAR_COMBINED = 1, PRRU_PAR_NONE = 2 };

typedef struct {
  int nbase;                      /* number of base parameters */
  /* The counts of the model it was computed for (prru_base_compute):
   * nreg = 10 nbody + 3 nact standard parameters, the length of pi and
   * the row stride of B. The functions taking a model and a base refuse
   * a base of another topology (PRRU_EINPUT). */
  int nreg, nbody, nact;
  int col[PRRU_MAX_REG];             /* col[i], i < nbase: base parameter i's own standard one */
  int role[PRRU_MAX_REG];            /* per standard parameter */
  double B[PRRU_MAX_REG * PRRU_MAX_REG];/* rows i < nbase: beta_i = sum_j B[i][j] pi_j (row stride nreg) */
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
PRRU_API int prru_ident_random_state(const prru_model *m, prru_data *d, unsigned long long *s,
                                     double q[3], double qd[3], double qdd[3]);

/* The regressor Y (3 x nreg, row-major; prru_regressor.h's columns)
 * of model m at (q, qd, qdd) with Coulomb smoothing velocity vs: the
 * build's specialised kernel for the build's own numbers, the topology's
 * (geometry and gravity read at run time) for a loaded model, so that a
 * model of any geometry is identified without a build of its own. */
PRRU_API void prru_model_regressor(const prru_model *m, const double q[3], const double qd[3], const double qdd[3], double vs,
                                   double *Y);

/* The Coulomb smoothing velocity identification evaluates the regressor
 * with unless told otherwise: the model's, else 1 mm/s (m/s). */
PRRU_API double prru_ident_default_vs(const prru_model *m);

/* Base parameters of m from nstates random states (PRRU_BASE_STATES when
 * <= 0, at least nreg / 3) drawn with seed; vs > 0 the Coulomb smoothing
 * velocity. Allocates (a set-up call). PRRU_EINPUT for vs <= 0,
 * PRRU_ENOMEM, PRRU_ENOCONV. */
PRRU_API int prru_base_compute(const prru_model *m, double vs, int nstates, unsigned long seed,
                               prru_base *b);
/* beta = B pi (nbase values; pi b->nreg values). */
PRRU_API void prru_base_params(const prru_base *b, const double pi[], double beta[]);
/* The base columns of rows x nreg Y (nreg b's): Yb (rows x nbase). */
PRRU_API void prru_base_regressor(const prru_base *b, const double *Y, int rows, double *Yb);
/* A standard parameter vector with B pi = beta: pi0 (a prior, e.g. the
 * model's) with each base parameter's own standard parameter replaced so
 * that the combination equals beta (the others keep pi0's values). */
PRRU_API void prru_base_to_standard(const prru_base *b, const double beta[],
                                    const double pi0[], double pi[]);
/* The name of standard parameter j (0 <= j < b->nreg) of the model b was
 * computed for, as prru_regressor.h names the columns: "P.m", "P.mcx",
 * ..., "S3.Iyz", "armature1", ..., "coulomb3" for three limbs (bodies P,
 * L1.., U1.., S1..); NULL for another j. */
PRRU_API const char *prru_base_param_name(const prru_base *b, int j);

/* Observation rows of one sample: A (nact x nbase) = J_d^+T Y_base
 * and y (nact) = J_d^+T J_d^T fd. The status of prru_check_regular
 * (unreachable or singular poses give no rows); PRRU_EINPUT for a
 * non-finite qd, qdd or fd, or b of another topology than m's. */
PRRU_API int prru_ident_rows(const prru_model *m, prru_data *d, const prru_base *b, const double q[3],
                             const double qd[3], const double qdd[3], const double fd[],
                             double *A, double y[]);

typedef struct {
  int nsamples, nrows, dof;   /* dof = 3 nsamples - nbase */
  double beta[PRRU_MAX_REG];     /* the estimate, nbase values */
  double se[PRRU_MAX_REG];       /* standard errors */
  /* Resolution: rms(y) / rms(X_i), the value at which parameter i alone
   * would give forces of the data's RMS size; an estimate within 1e-9 of
   * it of a bound is at the bound to rounding. */
  double scale[PRRU_MAX_REG];
  double sigma;               /* residual standard deviation s (N) */
  double rms[PRRU_MAX_ACT];      /* residual RMS per row of a sample (N) */
  double cond;                /* 2-norm condition number of the column-scaled X */
  double yrms;                /* RMS of the rows' forces y (N) */
  /* The residuals' variance inflation f >= 1: sigma^2 (R^T R)^-1 is the
   * covariance for white residuals; residuals correlated in time (the
   * truncation error of differentiated q, slow drifts) make the estimate
   * vary more, by about f = 1 + 2 sum_k (1 - k / (L + 1)) rho_k over
   * hac_lags = L sample lags (Newey-West), 1 where they are white or
   * anticorrelated. prru_ident_consistent judges with it. */
  double inflation;
  int hac_lags;
  /* X = Q R (R: nbase x nbase upper triangular, row stride the base's
   * nreg), so that |X beta - y|^2 = |X beta^ - y|^2 + |R (beta - beta^)|^2:
   * the covariance of beta^ is s^2 (R^T R)^-1. */
  double R[PRRU_MAX_REG * PRRU_MAX_REG];
} prru_ident_result;

/* Least squares of the base parameters from n samples (q, qd, qdd, fd:
 * row-major n x 3 and n x nact). PRRU_EINPUT when n is too small
 * (3 n <= nbase) or b is of another topology than m's, or with *bad the
 * 0-based sample and its status (PRRU_EUNREACHABLE, PRRU_ESINGULAR,
 * PRRU_EINPUT for non-finite values) when a sample gives no rows; PRRU_ESINGULAR when the stacked regressor
 * is rank deficient (the motion does not excite every base parameter);
 * PRRU_ENOMEM. Allocates. */
PRRU_API int prru_identify(const prru_model *m, const prru_base *b, int n, const double *q, const double *qd,
                           const double *qdd, const double *fd, prru_ident_result *r, int *bad);

/* ---- Physically consistent parameters ----
 * The least-squares estimate beta^ may belong to no physical robot: a
 * slider's mass change, loaded onto its armature, makes that negative.
 * prru_ident_consistent returns standard parameters pi that are
 * physically consistent and whose base parameters B pi agree with beta^:
 *   - consistent: each body's pseudo-inertia
 *       J(pi_b) = [[S, m c], [m c^T, m]], S = tr(I_O)/2 E - I_O = int r r^T dm,
 *     positive definite (Wensing, Kim and Slotine, IEEE RA-L 3(1), 2018:
 *     equivalent to a positive mass, an inertia about the centre of mass
 *     that is positive definite and meets the triangle inequalities), with
 *     a margin: T_b^-1 J T_b^-T >= eps I, T_b T_b^T the prior body's
 *     pseudo-inertia (regularised by 1e-6 tr(S_c)/3 on its S block so that
 *     a planar prior body qualifies); armature, damping and Coulomb >= 0
 *     (>= 1e-12 w_k, w_k below, so that rounding cannot make them negative);
 *   - exact where possible: when some consistent pi has B pi = beta^
 *     (a phase-I problem decides it), pi is the one nearest the prior pi0,
 *     and its base parameters are the estimate's to rounding;
 *   - otherwise within the covariance: pi minimises
 *       d^2 + mu |pi - pi0|_W^2,  d^2 = |R (B pi - beta^)|^2 / sigma_w^2,
 *     the squared Mahalanobis distance of B pi to beta^ under the
 *     covariance sigma_w^2 (R^T R)^-1, sigma_w = max(s sqrt(inflation),
 *     sigma_floor yrms) (data exact to sigma_floor of their RMS are treated
 *     as that exact);
 *     mu small, so the prior moves B pi by at most sqrt(mu) |pi* - pi0|_W
 *     standard deviations (pi* any consistent set); then, at those base
 *     parameters, the consistent pi nearest the prior (the directions no
 *     motion reveals, as in the exact case). When d^2 exceeds the chi^2 quantile of
 *     nbase degrees of freedom at 1 - alpha, no physical robot explains
 *     the data within their noise: the data contradict physics (a force
 *     sign, a gear ratio, a unit).
 * The norm to the prior is |pi - pi0|_W^2 = sum_b |T_b^-1 (J(pi_b) -
 * J(pi0_b)) T_b^-T|_F^2 + sum_k ((x_k - x0_k) / w_k)^2 over the drive
 * coefficients x_k, with w_k = max(|x0_k|, the limb's slider mass m_s,
 * m_s / tau, m_s g) for armature, damping and Coulomb (tau = sqrt(L / g),
 * L the length scale; g 9.81 m/s^2 where the model has no gravity): the
 * pseudo-inertia part is the same for a body of any size or shape and
 * invariant to rotations of its frame.
 * Each problem is convex (linear matrix inequalities) and solved by a
 * log-barrier interior-point method (Boyd and Vandenberghe, Convex
 * Optimization, ch. 11) with damped Newton steps; the same formulation as
 * the semidefinite programs of Wensing et al. and of Lee, Wensing and
 * Park (IEEE T-RO 36(2), 2020), without an SDP library. */
typedef struct {
  double mu;           /* prior weight within the covariance, > 0 */
  double alpha;        /* refusal level of the chi^2 test, in (0, 1) */
  double sigma_floor;  /* sigma_w >= sigma_floor yrms, >= 0 */
  double eps;          /* the pseudo-inertia margin, in [0, 1e-3] */
  int max_newton;      /* Newton steps in all, > 0 */
} prru_consistent_options;

/* mu 1e-6, alpha 1e-3, sigma_floor 1e-8, eps 1e-9, 5000 Newton steps. */
PRRU_API void prru_consistent_options_default(prru_consistent_options *o);

enum { PRRU_CONSISTENT_EXACT = 0, PRRU_CONSISTENT_COVARIANCE = 1 };

typedef struct {
  int how;                   /* PRRU_CONSISTENT_EXACT or _COVARIANCE */
  double beta[PRRU_MAX_REG];    /* B pi, nbase values */
  double t[PRRU_MAX_REG];       /* (B pi - beta^)_i / (sigma_w sqrt(C_ii)), C = (R^T R)^-1 */
  double w[PRRU_MAX_REG];       /* drive weights w_k at the drive parameters, else 0 */
  double d2, d2_max;         /* d^2 and the chi^2 quantile */
  double sigma_w;            /* N */
  double prior_dist;         /* |pi - pi0|_W */
  double margin;             /* smallest eigenvalue of T_b^-1 J T_b^-T over the bodies */
  int newton;                /* Newton steps taken */
} prru_consistent_result;

/* Consistent standard parameters pi from the fit r (prru_identify) and
 * the prior pi0 (the model's, prru_ident_standard). PRRU_OK with pi and c
 * filled; PRRU_ESINGULAR (pi and c filled: the consistent set nearest the
 * estimate) when d^2 > d2_max, the data contradicting physics; PRRU_EINPUT
 * for bad options, b of another topology than m's or a prior with a mass
 * <= 0, a non-finite value or a negative drive coefficient; PRRU_ENOCONV
 * when the Newton budget runs out; PRRU_ENOMEM. Allocates. */
PRRU_API int prru_ident_consistent(const prru_model *m, const prru_base *b, const prru_ident_result *r,
                                   const double pi0[], const prru_consistent_options *o,
                                   double pi[], prru_consistent_result *c);

/* Standard parameters pi (e.g. prru_ident_consistent's) as the numbers of
 * a model file: m's geometry and gravity (the regressor's), each body's
 * mass, centre of mass and inertia about it, the drives, b's Coulomb
 * smoothing velocity. A mass or principal moment below 1e-9 (a body on
 * the consistent set's margin) is raised to 1e-9 kg or kg m^2, which a
 * model file can hold and which keeps the body consistent. PRRU_EINPUT
 * with why naming the body or drive that is not physical (a mass <= 0,
 * an inertia not positive definite, a negative drive coefficient; never
 * for prru_ident_consistent's output), or b of another topology than m's.
 * prru_model_file_text writes p. */
PRRU_API int prru_ident_model_params(const prru_model *m, const prru_base *b, const double pi[], prru_params *p,
                                     char *why, int len);

/* ---- The whole identification ----
 * What prru identify and prru.Model.identify do, in one call: the least
 * squares of the base parameters (prru_identify), the physically
 * consistent standard parameters nearest the model's own (the prior,
 * prru_ident_consistent with the default options), those as a model's
 * numbers (prru_ident_model_params) and the identified model file's text
 * (prru_model_file_text, read back by the loader before it is returned:
 * nothing is handed over that cannot be loaded). Large (two nreg x nreg
 * matrices): allocate it. */
enum {
  PRRU_IDENTIFY_FIT = 0,        /* stopped at the least squares (bad, fit.cond) */
  PRRU_IDENTIFY_CONSISTENT = 1, /* no consistent fit: a prior not physical, no convergence */
  PRRU_IDENTIFY_PHYSICS = 2,    /* the data contradict physics (consistent: the nearest set) */
  PRRU_IDENTIFY_MODEL = 3,      /* the parameters make no model file (an internal error) */
  PRRU_IDENTIFY_DONE = 4
};

typedef struct {
  int stage;                         /* how far it got: PRRU_IDENTIFY_* */
  int bad;                           /* the 0-based sample that gave no rows, else -1 */
  prru_ident_result fit;             /* from stage PRRU_IDENTIFY_CONSISTENT on */
  prru_consistent_options options;   /* prru_consistent_options_default */
  prru_consistent_result consistent; /* from stage PRRU_IDENTIFY_PHYSICS on */
  double pi0[PRRU_MAX_REG];             /* the prior: the model's standard parameters */
  double prior[PRRU_MAX_REG];           /* its base parameters, nbase values */
  double pi[PRRU_MAX_REG];              /* the consistent standard parameters */
  char *text;                        /* the model file on PRRU_OK, to free(); else NULL */
  char msg[1024];                    /* why it stopped, without the data's name */
} prru_identification;

/* Identifies m's parameters from n samples (as prru_identify) and writes
 * the model named name, described by description (prru_model_file_text's
 * rules). PRRU_OK with stage PRRU_IDENTIFY_DONE and out->text; otherwise
 * the first failing step's status with out->stage and out->msg:
 * PRRU_EINPUT for b of another topology than m's, prru_identify's (with
 * out->bad for a sample that gives no rows), prru_ident_consistent's
 * PRRU_EINPUT or PRRU_ENOCONV, PRRU_ESINGULAR when the data contradict
 * physics (the consistent result is filled: a report can show it),
 * PRRU_EINPUT when the parameters make no model file (never for a
 * consistent result), PRRU_ENOMEM. Allocates. */
PRRU_API int prru_identify_model(const prru_model *m, const prru_base *b, int n, const double *q, const double *qd,
                                 const double *qdd, const double *fd, const char *name, const char *description,
                                 prru_identification *out);

/* The k base parameters whose consistent value is furthest from the
 * estimate, in standard errors: "#3 P.m at 4.1 se, ..." (1-based index,
 * its regressor column's name, prru_base_param_name). */
PRRU_API void prru_consistent_worst(const prru_base *b, const prru_consistent_result *c, int k, char *buf, int len);

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

PRRU_API void prru_fourier_eval(const prru_fourier *f, double t, double q[3], double qd[3], double qdd[3]);
/* Period 10 s, 5 harmonics, centre 0, every coefficient 0: prru excite's
 * series before its options and the optimisation. */
PRRU_API void prru_fourier_default(prru_fourier *f);

typedef struct {
  double fd_max[PRRU_MAX_ACT];  /* |fd_i| limit (N), > 0 */
  double d_min[PRRU_MAX_ACT], d_max[PRRU_MAX_ACT]; /* slider strokes (m), -inf/+inf by default */
  double rcond_min;          /* regularity along the path (prru_check_regular's rcond) */
  double amplitude_max[3];   /* |q_k - c_k| bound of the start and of each coordinate's sum of |a|, |b| */
  int samples;               /* points per period the objective stacks (>= nbase/3 + 1) */
  int check_samples;         /* points per period of the final feasibility check; 0: 20 samples */
  int max_evals;             /* Nelder-Mead budget */
  unsigned long seed;
  double speed_max[PRRU_MAX_ACT]; /* |d_i'| limit (m/s), INFINITY: none */
  /* The rows a run writes of the result (prru_excite_rows): every dt
   * seconds over periods periods. prru_excite does not read them. */
  double dt;
  int periods;
} prru_excite_options;

/* fd_max 500 N each, no stroke or speed limits, rcond_min 1e-2, amplitude 0.25 rad, 0.25 rad, 0.1 L,
 * 100 samples, check samples 0 (20 times samples, whatever samples becomes), 3000 evaluations,
 * seed 1; rows every 0.01 s over 1 period. All PRRU_MAX_ACT entries, so that the options suit a
 * model of either number of actuators. */
PRRU_API void prru_excite_options_default(prru_excite_options *o);
/* A run's limits (prru_limits_for_run) into o: the force bounds where
 * finite (an excitation needs one: o's, 500 N by default, where the run
 * has none), the speed limits and the strokes; all PRRU_MAX_ACT
 * entries, as lim holds them. */
PRRU_API void prru_excite_options_limits(prru_excite_options *o, const prru_limits *lim);
/* The rows t_i = i o->dt, i = 0..n-1, of a run of o->periods periods of
 * f: n = floor(periods period / dt (1 + 1e-12)) + 1, the last row at the
 * run's end or less than dt before it (the factor keeps the end's row
 * that rounding would push past it). 0 where there is no such run: dt not
 * finite and > 0, or longer than the run (period x periods); period not
 * finite and > 0; periods < 1; n above 1e15. */
PRRU_API long prru_excite_rows(const prru_fourier *f, const prru_excite_options *o);

typedef struct {
  double cond;          /* condition number of the column-scaled stacked base regressor */
  double cond_start;    /* the same for the starting coefficients (inf: infeasible start) */
  double fd_peak[PRRU_MAX_ACT];
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
 * or b of another topology than m's (msg says which), PRRU_ENOCONV when
 * no feasible trajectory was found, PRRU_EINTERRUPTED when *stop became
 * non-zero. Allocates. */
PRRU_API int prru_excite(const prru_model *m, const prru_base *b, const prru_excite_options *o,
                         volatile sig_atomic_t *stop, prru_fourier *f, prru_excite_result *r, char *msg,
                         int msglen);

/* The excitation's feasibility at n points per period: 0 and the peak
 * forces and worst rcond, or the first failing point's status
 * (PRRU_EUNREACHABLE, PRRU_ESTROKE beyond the model's stroke,
 * PRRU_ESINGULAR, or PRRU_EINPUT for a force, speed or stroke limit)
 * with *t_bad its time. */
PRRU_API int prru_excite_check(const prru_model *m, const prru_fourier *f, const prru_excite_options *o,
                               int n, double fd_peak[], double *rcond_worst, double *t_bad);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_IDENT_H */
