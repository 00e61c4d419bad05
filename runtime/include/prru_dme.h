/* Dynamic manipulability of the 3-PRRU (paper section 5, spec section 8):
 * the rotational dynamic manipulability ellipse (DME), the translational
 * segment, the index w_R at one configuration, and w_R maps over (q1, q2).
 *
 * Quantities. With the actuator displacements d(q), J_d = dd/dq, the mass
 * matrix M(q) and the platform Jacobians (omega_P = J_R,P qd, v_P = J_T,P qd):
 *   Mt  = J_d^+T M J_d^+      inertia seen by the actuators: at rest (no
 *                             velocity terms, no gravity) F_d = Mt dd''
 *   JtR = J_R,P J_d^+         actuator accelerations -> platform angular
 *   JtT = J_T,P J_d^+         acceleration, and linear acceleration.
 * J_d^+ = (J_d^T J_d)^-1 J_d^T is J_d^-1 for the 3-PRRU (every formula
 * here is then the paper's section 5) and the pseudo-inverse for the
 * redundant 4-PRRU (spec section 12): J_d is 4x3, Mt 4x4 (the least-norm
 * drive forces J_d^+T M qdd, F_d = Mt dd'' for dd'' in range(J_d)), JtR
 * and JtT 3x4. N = nact below.
 * JtR has rank 2: the platform turns only about e1 and v (omega_P =
 * q1' e1 + q2' v, no parasitic motion), so its range is the plane
 * span{e1, v}. JtT has rank 1: O' moves only along e3.
 *
 * Rotational DME. An angular acceleration a in span{e1, v} needs at least
 * the actuator accelerations JtR^+ a and hence the forces B a, B = Mt JtR^+
 * (N x 3).
 * The ellipse is the set of a reachable with unit actuator-force norm:
 *     a in span{e1, v},  a^T B^T B a = a^T JtR^+T Mt^T Mt JtR^+ a <= 1.
 * (For a with a component normal to the plane, B a ignores it, so the 3-D
 * set is an unbounded cylinder; the DME is its section by the plane.)
 * With the SVD B = U S V^T, sigma_1 >= sigma_2 > 0 = sigma_3, the right
 * singular vectors V_1, V_2 span the plane and the ellipse is
 *     { t1 V_1 / sigma_1 + t2 V_2 / sigma_2 : t1^2 + t2^2 <= 1 },
 * i.e. its semi-axes are V_i (directions in {S}, unit, angular acceleration
 * per unit of force) with lengths 1/sigma_i in rad/s^2 per N (d in m, so
 * B maps rad/s^2 to N). The LEFT singular vectors U_i are the matching
 * actuator-force directions; they are not reported. Axis 0 (sigma_1) is the
 * minor semi-axis, axis 1 the major one, and
 *     w_R = sigma_1 / sigma_2 = (major semi-axis) / (minor semi-axis) >= 1,
 * 1 for a circle (isotropic), growing as the ellipse flattens.
 *
 * Translational DME: the same with JtT; one non-zero singular value
 * sigma_T, a segment of half-length 1/sigma_T (m/s^2 per N) along the unit
 * direction of range(JtT), which is +-e3 (reported with a positive z).
 *
 * Computation (no SVD routine needed): Q = [q_1 q_2], an orthonormal basis
 * of range(J_R,P) = range(JtR) (J_d^+ has full row rank) from J_R,P's
 * columns (Gram-Schmidt with pivoting); JtR = Q C with C = Q^T JtR (2xN,
 * full row rank), so JtR^+ = C^T (C C^T)^-1 Q^T and B = G Q^T with the
 * Nx2 G = Mt C^T (C C^T)^-1.
 * One exact Jacobi rotation of G's two columns makes them orthogonal:
 * their norms are sigma_1, sigma_2 (to rounding, without squaring the
 * condition number) and the rotation's columns, mapped by Q, are V_1, V_2.
 * tests/test_dme.c checks this against GSL SVDs built another way, and
 * tests/test_redundant.c the 4-PRRU's against GSL SVDs of M, J_d and J_R,P.
 *
 * Singular configurations: a q is PRRU_EUNREACHABLE when the inverse
 * kinematics has no solution (an acos argument outside [-1, 1]) and
 * PRRU_ESINGULAR when J_d's reciprocal 1-norm condition number
 * 1 / (|J|_1 |J^+|_1), J = J_d with its rotation columns divided by the
 * model's length scale (J^+ = J^-1 for three actuators; for four, J_d has
 * rank 3 far beyond the singularities of any three of its limbs), is below
 * m->jd_rcond_min (prru_check_regular;
 * the model's default 1e-8 flags numerical singularity only, pass a model
 * copy with a larger value for a practical-singularity band, see the
 * global index below), or, as a last guard, when a result is not finite.
 * w_R is not defined there: the outputs are NaN.
 *
 * Threading: the calls write only into their prru_data and outputs; use
 * one prru_data per thread. prru_dme_eval does not allocate. */
#ifndef PRRU_DME_H
#define PRRU_DME_H

#include <signal.h>

#include "prru.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  int status;             /* PRRU_OK, PRRU_EUNREACHABLE, PRRU_ESINGULAR, PRRU_EINPUT */
  double jd_rcond;        /* reciprocal 1-norm condition number of J_d, 1 / (|J|_1 |J^+|_1)
                             with the model's length scale (0 if unreachable) */
  double w_R;             /* sigma[0] / sigma[1]; NaN unless status == PRRU_OK */
  double sigma[2];        /* non-zero singular values of Mt JtR^+, sigma[0] >= sigma[1] (N s^2/rad) */
  double semi_axis[2];    /* 1 / sigma[i]: semi_axis[0] minor, semi_axis[1] major (rad/s^2 per N) */
  double axis_dir[2][3];  /* unit direction of semi-axis i in {S}, in span{e1, v}; sign: the
                             component of largest magnitude is positive */
  double sigma_T;         /* the non-zero singular value of Mt JtT^+ (N s^2/m) */
  double half_length_T;   /* 1 / sigma_T: half-length of the translational segment (m/s^2 per N) */
  double dir_T[3];        /* its unit direction in {S} (e3) */
  /* Row-major, as defined above: Mt N x N, JtR and JtT 3 x N (N = nact). */
  double Mt[PRRU_MAX_ACT * PRRU_MAX_ACT], JtR[3 * PRRU_MAX_ACT], JtT[3 * PRRU_MAX_ACT];
} prru_dme;

/* A regular pose of the other assembly mode: det J_d has the opposite sign
 * to the home pose's. det J_d changes sign only through det J_d = 0, so
 * such a pose is cut off from home by the singular locus: the robot
 * assembled at home cannot reach it without crossing a singularity. The
 * status prru_map_eval gives it (w_R is NaN there, it is not ok); only
 * with three actuators (a square J_d; with more, J_d has no sign). */
#define PRRU_DME_OTHER_MODE 0xFE

/* "ok", "singular", "unreachable", "out_of_stroke" (PRRU_ESTROKE),
 * "other_mode" (PRRU_DME_OTHER_MODE) or "invalid" (PRRU_EINPUT and any
 * other code). */
PRRU_API const char *prru_dme_status_name(int status);

/* The assembly mode of a pose from its slider positions d and J_d (nact
 * actuators): the
 * sign of det J_d (prru_jd_det_sign), or 0 when it cannot be told (a
 * slider unreachable, det J_d = 0, more than three actuators); with home
 * 0 no pose is in "the other" mode. */
PRRU_API int prru_assembly_mode(const double d[], const double Jd[], int nact);
/* 1 when home != 0 and det J_d's sign is not home (a pose beyond the
 * singular locus, or on it), else 0. */
PRRU_API int prru_jd_other_mode(const double Jd[], int nact, int home);
/* A reachable pose's status from its regularity status (prru_jd_regular):
 * PRRU_DME_OTHER_MODE when it is PRRU_OK but prru_jd_other_mode, else
 * regular_status. The one classification of the map and the design
 * optimiser. */
PRRU_API int prru_mode_status(int regular_status, const double Jd[], int nact, int home);

/* Fills out at q (uses d->d, d->Jd, d->M as workspace) and returns
 * out->status. At a non-OK status every double of out except jd_rcond is
 * NaN. */
PRRU_API int prru_dme_eval(const prru_model *m, prru_data *d, const double q[3], prru_dme *out);

/* The one computation of the DME behind prru_dme_eval, from its
 * ingredients at a pose already found regular: M (3x3), J_d^+ (3 x N, as
 * prru_jd_regular leaves it) and the platform Jacobian [J_R,P; J_T,P]
 * (6x3, row-major, as prru_platform_jacobian). prru_map_eval and the
 * design optimiser (prru_design.h) evaluate blocks of points with a
 * batched copy of it that gives the same bits at every point (its
 * operations in the same order, its branches as selects), so w_R has one
 * definition. Returns out->status (PRRU_ESINGULAR when a result is not
 * finite); out->jd_rcond is left as it is. */
PRRU_API int prru_dme_from(const double M[9], const double Jdpinv[], int nact, const double JP[18],
                           prru_dme *out);

/* ---- Maps over a rectangle of (q1, q2) at fixed q3 ---- */

/* n1 values q1_i = (q1_lo (n1-1-i) + q1_hi i) / (n1-1), i = 0..n1-1 (the
 * form keeps a grid symmetric about 0 exactly symmetric), the same for q2;
 * n1, n2 >= 2, lo < hi, all finite. */
typedef struct {
  double q1_lo, q1_hi;
  double q2_lo, q2_hi;
  double q3;
  int n1, n2;
} prru_map_grid;

/* Grid point i of an axis. */
PRRU_API double prru_map_axis(double lo, double hi, int n, int i);

/* The global index (the paper's "overall distance between the w_R surface
 * and the plane w_R = 1"), defined over the grid points:
 *   index = (1 / n_ok) sum over the status-OK points of (w_R - 1),
 * the mean height of the surface above the plane on the regular part of the
 * rectangle (on a uniform grid, the area-weighted mean to O(h)); NaN when
 * n_ok = 0. It must be read together with
 *   singular_fraction = (n_singular + n_unreachable) / (n1 n2),
 * the share of the rectangle where w_R is undefined: a design can only look
 * better by losing workspace if that fraction grows. Smaller index = more
 * isotropic rotational dynamics.
 *
 * The tolerance matters. Near the locus det J_d = 0, w_R grows like
 * 1/distance, whose integral over a plane region diverges (logarithmically):
 * when the rectangle crosses the locus (fig. 7's corners do) and the
 * tolerance is the numerical one (jd_rcond_min = 1e-8), the index is
 * dominated by the few grid points that happen to fall nearest the locus
 * and changes erratically with the resolution (1.10, 1.00, 1.44, 1.29 at
 * 121^2, 201^2, 401^2, 1001^2 for fig. 7). For design comparison, map with
 * a practical-singularity tolerance (a model copy with e.g. jd_rcond_min =
 * 4e-3, cond_1 > 250): the band around the locus is then singular,
 * counted in singular_fraction, and the index converges (0.818, 0.815,
 * 0.812, 0.811 at 121^2, 201^2, 401^2, 801^2 for fig. 7). index_log, the
 * mean of ln w_R over the OK points, stays
 * finite either way (the logarithm of 1/distance is integrable).
 * The sums run over the points in grid order after all threads finish, so
 * the result does not depend on threading. */
typedef struct {
  long n_points, n_ok, n_singular, n_unreachable;
  long n_other_mode; /* of n_singular: regular, but in the other assembly mode */
  double index;             /* mean of w_R - 1 over the OK points */
  double index_log;         /* mean of ln w_R over the OK points */
  double singular_fraction;
  double w_min, w_max;      /* over the OK points (NaN when none) */
  double w_min_q[2], w_max_q[2]; /* (q1, q2) of the first point reaching them */
} prru_map_summary;

/* Called from the calling thread with the number of grid points done so
 * far; a non-zero return stops the map (PRRU_EINTERRUPTED). */
typedef int (*prru_map_progress_fn)(long done, long total, void *ctx);

/* The arithmetic of w_R in the maps and the optimiser. PRRU_PRECISION_FLOAT
 * runs the single-precision batched kernels (prru_f_batch_dme_terms, 8
 * poses a vector with AVX2) and the w_R stage in float: w_R within
 * 64 FLT_EPSILON w_R / rcond(J_d) relative of double's (where rcond >=
 * 1e-2, within 1e-5 but where w_R is large: up to 7e-5 measured at w_R
 * 20; tests/test_map_batch.c), and every status (ok,
 * singular, unreachable, out of stroke, other mode) the double path's: a
 * pose whose float result is not clearly ok (docs/performance.md, "Single
 * precision") is evaluated again in double. Only the build's model has
 * float kernels (prru_precision_available). */
enum { PRRU_PRECISION_DOUBLE = 0, PRRU_PRECISION_FLOAT = 1 };

/* "double" or "float" (NULL for another value). */
PRRU_API const char *prru_precision_name(int precision);
/* The precision named s ("double", "float"), -1 for any other text. */
PRRU_API int prru_precision_parse(const char *s);
/* PRRU_OK if m can be evaluated in this precision; PRRU_EINPUT for an
 * unknown precision or float on a model with the run-time parameter
 * kernels (a model file of other numbers than the build's: only the
 * build's model has float batched kernels). */
PRRU_API int prru_precision_available(const prru_model *m, int precision);

typedef struct {
  int nthreads;                      /* >= 1; the calling thread is one of them */
  prru_map_progress_fn progress; void *ctx; /* may be NULL */
  volatile sig_atomic_t *interrupt;  /* polled per grid row; non-zero stops (may be NULL) */
  int precision;                     /* PRRU_PRECISION_DOUBLE (default) or _FLOAT */
} prru_map_options;

/* nthreads = 2, no progress, no interrupt, double. */
PRRU_API void prru_map_options_default(prru_map_options *o);

/* PRRU_OK, or PRRU_EINPUT when the grid is invalid (see prru_map_grid). */
PRRU_API int prru_map_check(const prru_map_grid *g);

/* The model's assembly mode at the grid's home pose (0, 0, q3):
 * prru_assembly_mode there, 0 when not told (no point of the map is then
 * in the other mode). */
PRRU_API int prru_map_home_mode(const prru_model *m, const prru_map_grid *g);

/* Evaluates w_R at every grid point: index k = i n2 + j for (q1_i, q2_j)
 * (q1 outer). status[k] is PRRU_OK, PRRU_EUNREACHABLE, PRRU_ESTROKE (a
 * slider outside the model's stroke: prru_stroke_actuator, tested before
 * the regularity as prru_check_regular does), PRRU_ESINGULAR or
 * PRRU_DME_OTHER_MODE (the regular poses whose assembly mode is not
 * prru_map_home_mode's); w_R[k] is NaN where status[k] != PRRU_OK. The
 * summary counts PRRU_ESTROKE in n_unreachable (the stroke ends bound the
 * workspace).
 * Allocates one batch workspace per thread (not per point). status may be
 * NULL if not needed; sum may be NULL. Returns PRRU_OK, PRRU_EINPUT (bad grid or options,
 * or a precision m does not have: prru_precision_available),
 * PRRU_ENOMEM, or PRRU_EINTERRUPTED (outputs partly filled, sum not set). */
PRRU_API int prru_map_eval(const prru_model *m, const prru_map_grid *g, const prru_map_options *o,
                           double *w_R, unsigned char *status, prru_map_summary *sum);

/* Only the q1 rows row_begin .. row_end - 1 of the grid (a shard of a map
 * split across processes): w_R[k] and status[k] for k = (i - row_begin) n2
 * + j, the same values prru_map_eval gives those points. No summary (it
 * needs the whole grid: prru_map_summarize on the joined rows). PRRU_OK,
 * PRRU_EINPUT (bad grid, options or rows), PRRU_ENOMEM,
 * PRRU_EINTERRUPTED. prru_map_eval is this for every row. */
PRRU_API int prru_map_eval_rows(const prru_model *m, const prru_map_grid *g, int row_begin, int row_end,
                                const prru_map_options *o, double *w_R, unsigned char *status);

/* The summary of an already computed map (used by prru_map_eval):
 * PRRU_DME_OTHER_MODE counts in n_singular and in n_other_mode. */
PRRU_API void prru_map_summarize(const prru_map_grid *g, const double *w_R, const unsigned char *status,
                                 prru_map_summary *sum);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_DME_H */
