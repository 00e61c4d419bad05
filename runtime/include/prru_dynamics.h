/* prru runtime, the core: models (built in or loaded from a model file),
 * kinematics, forward and inverse dynamics and the joint reactions of the
 * 3-PRRU over the generated kernels and GSL. prru.h includes it with
 * prru_sim.h (loads, simulation, scenarios) and prru_io.h (tables, number
 * parsing, text for model files).
 *
 * Model (constant, prru_model) vs Data (per-call workspace, prru_data), as in
 * MuJoCo: a prru_model is filled once from the generated model constants;
 * a prru_data is plain storage the calls write into, so nothing allocates in
 * the hot paths and one prru_data per thread makes every call re-entrant.
 *
 * The mechanism itself (sizes, bodies, joints, the model's numbers) is the
 * generated descriptor prru_mech (prru_mechanism.h); prru_model points at it
 * and adds only the runtime's own settings, so nothing here can disagree
 * with the kernels.
 *
 * GSL: every GSL status is checked here, so the first call that uses GSL
 * turns GSL's abort-on-error handler off, once per process
 * (gsl_set_error_handler_off); the runtime never changes it per call.
 *
 * Every function returns a prru_status; PRRU_OK is 0. Arrays are row-major,
 * body order prru_mech.body_names, lambda order prru_mech.lambda_labels.
 * An array argument declared [] has the model's size (its descriptor
 * m->mech): nact values per actuator (d, fd, dd), J_d nact x 3 and its
 * inverse 3 x nact, nlambda reaction coordinates, rotations 9 nbody and
 * positions 3 nbody; a struct's arrays have room for the largest model
 * (prru_sizes.h). */
#ifndef PRRU_DYNAMICS_H
#define PRRU_DYNAMICS_H

#include <float.h>
#include <signal.h>
#include <stddef.h>

#include "prru_descriptor.h"

/* The public API: libprru.so is built with hidden visibility, so that
 * only what the headers declare with PRRU_API (and the generated
 * kernels, the drop-in API) is exported; helpers shared between the
 * library's own files stay inside it. */
#if defined(__GNUC__) || defined(__clang__)
#define PRRU_API __attribute__((visibility("default")))
#else
#define PRRU_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  PRRU_OK = 0,
  PRRU_EINPUT = 1,       /* an argument is NaN/inf or out of its range */
  PRRU_EUNREACHABLE = 2, /* q outside the inverse kinematics' domain */
  PRRU_ESINGULAR = 3,    /* J_d singular to the model's tolerance */
  PRRU_ENOCONV = 4,      /* an iteration or the integrator failed */
  PRRU_EINTERRUPTED = 5, /* stopped on request (SIGINT) */
  PRRU_EIO = 6,          /* a file could not be read or written */
  PRRU_ENOMEM = 7,
  PRRU_EPARSE = 8,       /* malformed number, list, CSV or scenario */
  PRRU_ESTROKE = 9       /* a slider outside its stroke (the model's
                            actuators.stroke, spec 13): the stroke ends
                            bound the workspace like the reach does */
} prru_status;

/* A short, stable description of a status code. */
PRRU_API const char *prru_strerror(int status);
/* sizeof the public struct named name ("prru_data", "prru_mechanism",
 * ...; every struct a binding mirrors), 0 for a name that is not one:
 * bindings check their mirrors against it (python/prru/_lib.py). The
 * sizes are the same for every model and build (prru_sizes.h). */
PRRU_API size_t prru_struct_size(const char *name);

/* The code a model evaluates with. MuJoCo's Model holds its numbers; a
 * prru_model also chooses its kernels: the specialised set, constant-folded
 * from the build's model file (prru_kernels.h), or the parameter set of
 * the model's topology (prru_p3_kernels.h or prru_p4_kernels.h), which
 * reads the numbers of a model file loaded at run time (prru_model_load).
 * Each entry has the arguments and outputs of the prru_kernels.h kernel of
 * its name after p, the table's parameters (kernel_params of the model;
 * ignored by the specialised set); arrays of the model's sizes (m->mech:
 * nact, nbody, nlambda). The unseen_* entries are the generated finiteness witnesses
 * (PRRU_UNSEEN_FINITE_*) of the same set. */
typedef struct prru_kernel_table {
  const char *path; /* "specialised" or "parameter" */
  void (*ik)(const void *p, const double q[3], double d[]);
  void (*jd)(const void *p, const double q[3], double Jd[]);
  void (*ik_jd)(const void *p, const double q[3], double d[], double Jd[]);
  void (*mass)(const void *p, const double q[3], double M[9]);
  void (*dynamics)(const void *p, const double q[3], const double qd[3], double M[9], double h[3],
                   double G[3]);
  void (*eom)(const void *p, const double q[3], const double qd[3], const double fd[],
              const double fp[3], const double mp[3], double M[9], double b[3]);
  void (*eom_solve)(const void *p, const double q[3], const double qd[3], const double fd[],
                    const double fp[3], const double mp[3], double M[9], double b[3], double qdd[3],
                    double minors[3]);
  int (*unseen_finite_eom_solve)(const double q[3], const double qd[3], const double fd[],
                                 const double fp[3], const double mp[3]);
  /* Three actuators: d, J_d, J_d^-1 and fd = J_d^-T tau (out, 3 values);
   * four: d, J_d and tau (out, 3 values), Jdinv unused. */
  void (*inverse_terms)(const void *p, const double q[3], const double qd[3], const double qdd[3],
                        const double fp[3], const double mp[3], double d[],
                        double Jd[], double Jdinv[], double out[3]);
  int (*unseen_finite_inverse_terms)(const double q[3], const double qd[3], const double qdd[3],
                                     const double fp[3], const double mp[3]);
  /* z (the null vector of Q) only with four actuators; NULL otherwise. */
  void (*joint_reactions)(const void *p, const double q[3], const double qd[3], const double qdd[3],
                          const double fd[], const double fp[3], const double mp[3],
                          double lambda[], double z[]);
  void (*platform_jacobian)(const void *p, const double q[3], double JP[18]);
  void (*poses)(const void *p, const double q[3], double R[], double pos[]);
  void (*energy)(const void *p, const double q[3], const double qd[3], double E[2]);
  void (*actuator_rates)(const void *p, const double q[3], const double qd[3], double dd[],
                         double ddb[]);
  void (*passive)(const void *p, const double q[3], const double qd[3], double Qp[3]);
  void (*batch_dme_terms)(const void *p, int n, const double *q, double *d, double *Jd, double *M,
                          double *JP);
  /* The identification regressor Y (3 x nreg, nreg = 10 nbody + 3 nact:
   * prru_regressor.h) at the Coulomb smoothing velocity vs. */
  void (*regressor)(const void *p, const double q[3], const double qd[3], const double qdd[3], double vs,
                    double *Y);
  /* The closed-form derivatives (prru_linearize.h): eom_solve's outputs,
   * then dqdd/dq, dqdd/dqd (3x3), dqdd/dfd (3 x nact), dqdd/dfp,
   * dqdd/dmp (3x3), row-major, row i = qdd_i. */
  void (*eom_solve_derivs)(const void *p, const double q[3], const double qd[3],
                           const double fd[], const double fp[3], const double mp[3],
                           double M[9], double b[3], double qdd[3], double minors[3], double Dq[9],
                           double Dqd[9], double Dfd[], double Dfp[9], double Dmp[9]);
  int (*unseen_finite_eom_solve_derivs)(const double q[3], const double qd[3],
                                        const double fd[], const double fp[3],
                                        const double mp[3]);
  /* inverse_terms's outputs, then three 3x3 blocks, row-major, row i =
   * out_i: with three actuators dfd/dq, dfd/dqd, dfd/dqdd (DJd unused);
   * with four dtau/dq, dtau/dqd, dtau/dqdd (= M) and DJd = dJ_d/dq, block
   * k (nact x 3, row-major) dJ_d/dq_k, Jdinv unused. */
  void (*inverse_derivs)(const void *p, const double q[3], const double qd[3], const double qdd[3],
                         const double fp[3], const double mp[3], double d[],
                         double Jd[], double Jdinv[], double out[3],
                         double Dq[9], double Dqd[9], double Dqdd[9], double DJd[]);
  int (*unseen_finite_inverse_derivs)(const double q[3], const double qd[3], const double qdd[3],
                                      const double fp[3], const double mp[3]);
  /* eom_solve_derivs batched (prru_batch_eom_solve_derivs in
   * prru_kernels.h: n states, every array in rows of n). */
  void (*batch_eom_solve_derivs)(const void *p, int n, const double *q, const double *qd,
                                 const double *fd, const double *fp, const double *mp, double *M,
                                 double *b, double *qdd, double *minors, double *Dq, double *Dqd,
                                 double *Dfd, double *Dfp, double *Dmp);
  /* The unit null vector z of the reactions' Q (nlambda values, its sign
   * the kernel's) with four actuators; NULL with three (Q has none). */
  void (*reaction_nullspace)(const void *p, const double q[3], double z[]);
} prru_kernel_table;

typedef struct {
  /* The descriptor: &prru_mech (the build's model), or a loaded model's
   * own copy (prru_model_load): names, sizes and numbers. */
  const prru_mechanism *mech;
  /* J_d counts as singular when the reciprocal condition number
   * 1 / (|J|_1 |J^-1|_1) of J = J_d diag(1/L, 1/L, 1) is below this
   * (default 1e-8); L, the mean upper-link length, measures rotations as arc
   * lengths at the robot's own scale, so the test means the same for a
   * robot of any size. With four actuators J is 4x3 and J^-1 is
   * J^+ = (J^T J)^-1 J^T (prru_check_regular). */
  double jd_rcond_min;
  /* The trust criterion of the dynamics (docs/model.md section 4): forward
   * dynamics, the reactions and inverse dynamics return PRRU_ESINGULAR
   * where the mass matrix is too ill-conditioned for a result worth
   * having: near the workspace boundary, where an upper link turns
   * horizontal and its slider moves without bound per unit of platform
   * motion, M grows like 1/sin^2 of that link's angle in one direction
   * only, and the rounding of those huge terms swamps the rest (measured:
   * qdd off by 1e-8 relative at rcond(M_s) = 5e-8, of the wrong sign at
   * 1e-13). Forward dynamics (and so the reactions and every simulated
   * state) test prru_mass_rcond(M) >= mass_rcond_min; inverse dynamics,
   * whose kernel never forms M, tests the cause instead:
   * prru_stretch(J_d)^2 mass_rcond_min <= 1 (M_s's conditioning is
   * c / stretch^2 with c of order 1: 0.2 to 5 over the paper model's
   * workspace). Default 1e-6: qdd and fd then agree with the GSL reference
   * to 2e-10 relative, and ID(FD(fd)) returns fd to 1e-7 of its terms. */
  double mass_rcond_min;
  const prru_kernel_table *kernels; /* the code (see prru_kernel_table) */
  const void *kernel_params;        /* its numbers, derived (prru_param_derived;
                                       NULL: specialised) */
  void *own;                        /* a loaded model's storage, else NULL */
} prru_model;

/* The mechanism the kernels were generated from, default settings,
 * specialised kernels. */
PRRU_API void prru_model_default(prru_model *m);
/* Reads the model file at path (format 1 or 2, spec sections 11-13; the
 * generator's validation and messages, prru_model_file.h) into m with
 * default settings. Its kernels: the specialised set when every number
 * equals the build's model's (names and descriptions aside: the same
 * robot, so a whitespace or comment edit keeps the fast path), else the
 * parameter set of the file's topology (3 or 4 limbs: every build has
 * both, whatever its own model). PRRU_OK; PRRU_EIO or PRRU_EPARSE with
 * msg "path: key: reason"; PRRU_ENOMEM. m is untouched on
 * failure: nothing is computed with a partly loaded model. Allocates: prru_model_free (m must
 * not hold a loaded model already: free it first). */
PRRU_API int prru_model_load(prru_model *m, const char *path, char *msg, int msglen);
/* Switches a loaded model to the parameter kernels even where its numbers
 * are the build's: to measure what the fast path saves (bench/) and to
 * check both paths against each other (test_model_load). The parameter
 * kernels a loaded model gets: their simple structural variant where its
 * numbers have exactly no centre-of-mass offset, product of inertia or
 * drive and gravity along z (the paper's model), else the general ones.
 * PRRU_EINPUT for a model not loaded from a file (prru_model_default's has
 * no parameter set of its own); PRRU_ENOMEM. */
PRRU_API int prru_model_use_parameter_kernels(prru_model *m);
/* The same with the general parameter kernels whatever the structure: to
 * compare the variant with them (test_model_load, bench/). */
PRRU_API int prru_model_use_general_kernels(prru_model *m);
/* Frees a loaded model's storage (nothing for prru_model_default's);
 * then m is prru_model_default's. */
PRRU_API void prru_model_free(prru_model *m);
/* A mechanism's length scale (m): the mean upper-link length. Tolerances
 * on lengths, the conditioning of J_d and of M, and the drawings' sizes
 * are relative to it, so that they mean the same for a robot of any size. */
PRRU_API double prru_length_scale(const prru_mechanism *me);
/* Whether m's numbers are the build's model's: the kernels that exist only
 * for it (the identification regressor, prru_regressor.h) apply. The
 * inertial and drive numbers may differ when only_geometry is non-zero
 * (the regressor depends on geometry and gravity alone). */
PRRU_API int prru_model_is_built(const prru_model *m, int only_geometry);
/* m's kernels of the same names (prru_kernel_table), for callers that
 * need a kernel's raw outputs (NaN where q is unreachable, no status):
 * the CLI and the Python binding. */
PRRU_API void prru_model_ik_jd(const prru_model *m, const double q[3], double d[], double Jd[]);
PRRU_API void prru_model_dynamics(const prru_model *m, const double q[3], const double qd[3], double M[9], double h[3],
                                  double G[3]);
PRRU_API void prru_model_passive(const prru_model *m, const double q[3], const double qd[3], double Qp[3]);
PRRU_API void prru_model_platform_jacobian(const prru_model *m, const double q[3], double JP[18]);
PRRU_API void prru_model_poses(const prru_model *m, const double q[3], double R[], double pos[]);
/* From the poses (R, pos) of prru_model_poses, which place each body's
 * centre of mass: the origin of body b's frame, pos_b - R_b com_b (they
 * differ for a model with offset centres), and the joint centres of limb
 * i (0-based): A_i, the slider's frame origin, then B_i and C_i from the
 * link frames' origins, which are the links' midpoints (docs/model.md
 * section 4). What drawings and animations place their segments on. */
PRRU_API void prru_body_origin(const prru_model *m, const double R[], const double pos[],
                               int b, double o[3]);
PRRU_API void prru_limb_joints(const prru_model *m, const double R[], const double pos[],
                               int i, double A[3], double B[3], double C[3]);
PRRU_API void prru_model_actuator_rates(const prru_model *m, const double q[3], const double qd[3], double dd[],
                                        double ddb[]);
/* "model NAME (FILE, sha256 HEX, KERNELS kernels)": the identity every
 * output states (KERNELS "specialised" or "parameter"); buf holds at least
 * len bytes, truncated with a NUL. FILE as given at load (any bytes; a
 * caller writing it where newlines or quotes matter escapes it). */
PRRU_API void prru_model_identity(const prru_model *m, char *buf, size_t len);

/* The drives' limits (spec section 13), per actuator, as every command
 * that plans, tracks, excites or optimises applies them: a rail force
 * |f_i| <= force_max[i] (N), a slider speed |d_i'| <= speed_max[i] (m/s)
 * and the stroke d_min[i] <= d_i <= d_max[i] (m). No limit is INFINITY
 * (-INFINITY for d_min). */
typedef struct {
  double force_max[PRRU_MAX_ACT];
  double speed_max[PRRU_MAX_ACT];
  double d_min[PRRU_MAX_ACT], d_max[PRRU_MAX_ACT];
} prru_limits;
/* The section 13 keys a model file gives, as bits (prru_mechanism.drive_keys,
 * prru_model_spec.keys): bit k for the k-th key of this list. */
enum {
  PRRU_DRIVE_LEAD = 1 << 0,
  PRRU_DRIVE_GEAR = 1 << 1,
  PRRU_DRIVE_ROTOR_INERTIA = 1 << 2,
  PRRU_DRIVE_TORQUE_CONSTANT = 1 << 3,
  PRRU_DRIVE_STROKE = 1 << 4,
  PRRU_DRIVE_FORCE_MAX = 1 << 5,
  PRRU_DRIVE_TORQUE_MAX = 1 << 6,
  PRRU_DRIVE_SPEED_MAX = 1 << 7,
  PRRU_DRIVE_MOTOR_SPEED_MAX = 1 << 8
};

/* Every limit off. */
PRRU_API void prru_limits_none(prru_limits *l);
/* The model's own limits (its file's actuators keys, spec 13, in rail
 * units: torque_max and motor_speed_max converted through the lead and
 * gear); none where the file sets none. */
PRRU_API void prru_model_limits(const prru_model *m, prru_limits *out);
/* Motor radians per metre of slider i's travel, 2 pi gear_i / lead_i
 * (rad/m; the reflected armature of a rotor inertia J_r is J_r times its
 * square), NaN without a lead or for i outside 0..nact-1. */
PRRU_API double prru_model_drive_ratio(const prru_model *m, int i);
/* Whether every actuator has a screw lead (the file's actuators.lead):
 * only then do rail quantities convert to the motor. */
PRRU_API int prru_model_has_lead(const prru_model *m);
/* Rail forces f (N) to the ideal motor torques tau_i = f_i lead_i /
 * (2 pi gear_i) (N m) and, where current is non-NULL, the motor currents
 * tau_i / k_t,i (A; NaN for an actuator without torque_constant). tau
 * may be NULL. PRRU_EINPUT (outputs untouched) when an actuator has no
 * lead (prru_model_has_lead); else PRRU_OK. */
PRRU_API int prru_model_motor_units(const prru_model *m, const double f[], double tau[],
                                    double current[]);
/* A run's overrides of the model's limits, as given on a command line
 * (--no-limits, --force-max, --speed-max, --stroke); NULL text: not given. */
typedef struct {
  int none;              /* drop every limit of the model first (--no-limits) */
  const char *force_max; /* "F" for every actuator or "F1,..,FN" (N, > 0) */
  const char *speed_max; /* likewise, m/s */
  const char *stroke;    /* "LO,HI" (or "LO:HI") for every slider, or
                            "LO1,HI1,..,LON,HIN" (m, LO < HI) */
} prru_limit_args;
/* The limits a run applies: the model's (prru_model_limits), all none if
 * a->none, then each limit given in a replaces that kind for every
 * actuator. PRRU_OK; PRRU_EINPUT with msg naming the option
 * ("--force-max: ...") and out untouched. a may be NULL (the model's). */
PRRU_API int prru_limits_for_run(const prru_model *m, const prru_limit_args *a, prru_limits *out, char *msg,
                                 int msglen);
/* One line for a run's header: "force_max F N, speed_max V m/s, stroke
 * [LO, HI] m" (one value when every actuator has the same, else a list
 * per actuator of m; "none" for a kind that is off), into buf (len bytes). */
PRRU_API void prru_limits_describe(const prru_model *m, const prru_limits *l, char *buf, size_t len);
/* out: src with l's limits in a descriptor of its own (the stroke then
 * bounds every reachability test of out, prru_stroke_actuator); src's
 * numbers, kernels and settings otherwise. Allocates: prru_model_free(out)
 * (src may be freed first). PRRU_OK or PRRU_ENOMEM (out untouched). */
PRRU_API int prru_model_with_limits(prru_model *out, const prru_model *src, const prru_limits *l);

typedef struct {
  double fd[PRRU_MAX_ACT]; /* actuator forces along +e3 on the sliders (N) */
  double fp[3]; /* force on the platform at O', {S} (N) */
  double mp[3]; /* moment on the platform, {S} (N m) */
} prru_loads;

/* Per-call workspace and last results. */
typedef struct {
  double d[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3]; /* actuators, J_d (NACT x 3) */
  /* J_d^+ = (J_d^T J_d)^-1 J_d^T (3 x NACT), the left inverse of J_d
   * (J_d^+ J_d = I): J_d^-1 for three actuators. */
  double Jdpinv[3 * PRRU_MAX_ACT];
  double M[9], b[3];              /* M qdd = b (prru_eom) */
  double qdd[3];
  double r[PRRU_MAX_LAMBDA];         /* the last prru_reactions' lambda */
  /* The unit null vector z of Q at the last prru_reactions (see
   * prru_reaction_null); all 0 with three limbs (nlambda - 6 nbody + 3 = 0: no such z). */
  double lambda_null[PRRU_MAX_LAMBDA];
} prru_data;

/* PRRU_OK, PRRU_EINPUT (non-finite q), PRRU_EUNREACHABLE or PRRU_ESTROKE
 * (a slider outside its stroke, prru_stroke_actuator); fills d->d. */
PRRU_API int prru_check_reachable(const prru_model *m, prru_data *d, const double q[3]);
/* The first actuator (0-based) whose displacement d_i lies outside the
 * model's stroke [d_min_i, d_max_i] (m->mech, ends included), -1 when
 * none does (NaN d_i: none; unreachability is tested apart). Every
 * reachability test of the library applies it: prru_check_reachable,
 * prru_check_regular, the dynamics, prru_simulate, the maps. */
PRRU_API int prru_stroke_actuator(const prru_model *m, const double d[]);
/* At a q whose sliders are at d: PRRU_ESTROKE and msg "slider I at d = X m
 * is outside its stroke [D_MIN, D_MAX] m" (I 1-based), else PRRU_OK and
 * msg "". */
PRRU_API int prru_stroke_why(const prru_model *m, const double d[], char *msg, int msglen);
/* Reachable and J_d regular (full column rank 3); fills d->d, d->Jd,
 * d->Jdpinv (when regular); *rcond if non-NULL: 1 / (|J|_1 |J^+|_1) for
 * J = J_d diag(1/L, 1/L, 1) (see prru_model), which for three actuators is
 * 1 / (|J|_1 |J^-1|_1). J^+ comes from a Householder QR of J for four. */
PRRU_API int prru_check_regular(const prru_model *m, prru_data *d, const double q[3], double *rcond);
/* (prru_check_regular: PRRU_ESTROKE before the regularity test, as
 * prru_check_reachable.) */
/* The regularity test of prru_check_regular on a given J_d (finite, nact
 * x 3), for a mechanism of length scale L (m) and tolerance rcond_min:
 * PRRU_OK and Jdpinv = J_d^+ (3 x nact), or PRRU_ESINGULAR; *rcond as
 * there; PRRU_EINPUT for nact other than 3 or 4. prru_check_regular is
 * this with the model's L and jd_rcond_min; the design optimiser calls it
 * with a candidate design's own L, so both judge regularity alike. */
PRRU_API int prru_jd_regular(const double Jd[], int nact, double L, double rcond_min,
                             double Jdpinv[], double *rcond);
/* The reciprocal 1-norm condition number 1 / (|M_s|_1 |M_s^-1|_1) of
 * M_s = D^-1 M D^-1, D = diag(L, L, 1) with L the model's length scale (the
 * mass matrix with rotations measured as arc lengths at the robot's scale,
 * so that its entries share one unit, kg): in (0, 1], 0 where M (a
 * prru_dynamics or prru_data.M output) is not positive definite or not
 * finite. The quantity forward dynamics tests against mass_rcond_min. */
PRRU_API double prru_mass_rcond(const prru_model *m, const double M[9]);
/* How far J_d's rows are from the workspace boundary: the largest 1-norm
 * of a row of J_d diag(1/L, 1/L, 1), metres of slider travel per metre of
 * platform motion (1 to 3 in the middle of the workspace, without bound
 * as an upper link turns horizontal); NaN propagates. The quantity
 * inverse dynamics tests: stretch^2 mass_rcond_min <= 1. */
PRRU_API double prru_stretch(const prru_model *m, const double Jd[]);
/* With three actuators (nact, J_d's rows), the sign (+1 or -1) of det
 * J_d, 0 where it is 0; always 0 with more actuators (J_d has no determinant, and a path meets
 * a rank deficiency of J_d only by exception). det J_d changes sign only
 * through det J_d = 0, so two regular poses of opposite signs lie on
 * either side of the singular locus: the assembly mode (prru_dme.h) and
 * the crossing test of sampled paths (prru traj, prru track) rest on it. */
PRRU_API int prru_jd_det_sign(const double Jd[], int nact);

/* Actuator displacements (inverse kinematics). */
PRRU_API int prru_actuators(const prru_model *m, prru_data *d, const double q[3], double act[]);
/* q with d(q) = act from seed: three actuators, Newton's method
 * (gsl_multiroot, hybridsj with J_d; allocates: a set-up call); four,
 * Gauss-Newton with J_d^+ and step halving (prru_forward_kinematics_lsq,
 * no allocation). The residual max_i |d_i(q) - act_i| must reach
 * tol = 100 DBL_EPSILON max(L, |act|_inf) (L the model's length scale;
 * 10 tol, prru_fk_tolerance, is accepted where the iteration stalls a few
 * ulps short).
 * PRRU_ENOCONV when act is out of reach, the iteration meets a
 * singularity, or, with four actuators, act is inconsistent beyond 10 tol:
 * no pose reproduces all four sliders (the fourth is not where the other
 * three put it; measured or rounded slider positions: use
 * prru_forward_kinematics_lsq and judge its residual). PRRU_ESINGULAR when
 * the solution has a singular J_d. */
PRRU_API int prru_forward_kinematics(const prru_model *m, prru_data *d, const double act[],
                                     const double seed[3], double q[3]);
/* Least squares: Gauss-Newton from seed to a q minimizing |d(q) - act|_2
 * (with four actuators act need not be consistent: measured sliders), and
 * *residual = max_i |d_i(q) - act_i| (m) there. PRRU_OK once the iteration
 * is stationary, whatever the residual: the caller judges it (for
 * consistent act it is at the tolerance of prru_forward_kinematics);
 * PRRU_ENOCONV when it does not settle within 200 iterations or leaves
 * the workspace, PRRU_ESINGULAR at a singular J_d. */
PRRU_API int prru_forward_kinematics_lsq(const prru_model *m, prru_data *d, const double act[],
                                         const double seed[3], double q[3], double *residual);
/* The residual (m) prru_forward_kinematics accepts for act and a caller
 * holds a least-squares fit to before calling the sliders consistent:
 * 1000 DBL_EPSILON max(L, |act|_inf), ten times the iteration's target
 * (above). Relative, so that it means the same for a robot of any size
 * and for sliders far down their rails. */
PRRU_API double prru_fk_tolerance(const prru_model *m, const double act[]);
/* The seed the forward kinematics starts from when the caller has none:
 * q0 = (0, 0, h) with h the mean of act_i - d_i(0, 0, 0). At q1 = q2 = 0
 * every slider is the platform height plus a constant, d_i = q3 +
 * d_i(0, 0, 0), so h solves the sliders of a level pose exactly and is
 * the level pose nearest to those of a tilted one. NaN in act gives a NaN
 * q0[2]. */
PRRU_API void prru_fk_default_seed(const prru_model *m, const double act[], double q0[3]);
/* max_i |d_i(q) - act_i| (m), the residual prru_forward_kinematics_lsq
 * reports and prru_fk_tolerance bounds, for any q (a Newton solution's,
 * whose solver does not return it); NaN where q is out of reach or an
 * input is NaN. */
PRRU_API double prru_fk_residual(const prru_model *m, const double q[3], const double act[]);
/* qdd from M qdd = G + J_d^T fd + J_T,P^T fp + J_R,P^T mp - h, solved
 * inside the generated prru_eom_solve; PRRU_ESINGULAR unless M is positive
 * definite (three nested principal minors positive) and
 * prru_mass_rcond(M) >= m->mass_rcond_min (the trust criterion: too near
 * the workspace boundary, d->M still holds M). PRRU_EINPUT for a NaN
 * or infinite input; d->M, d->b and d->qdd may then hold what the kernel
 * made of it, qdd is untouched. */
PRRU_API int prru_forward_dynamics(const prru_model *m, prru_data *d, const double q[3],
                                   const double qd[3], const prru_loads *l, double qdd[3]);
/* Why forward dynamics fails at (q, qd, l), in words for a message that
 * names the state (no trailing period): q outside the workspace; q on its
 * boundary; too near it to trust the dynamics (prru_mass_rcond below
 * mass_rcond_min, given with both numbers); M not positive definite;
 * velocities or loads that overflow the arithmetic (naming qd and the
 * loads, not q). Returns prru_forward_dynamics' status there (msg "" when
 * PRRU_OK). The library's one diagnosis of a state, used by every caller
 * that reports a failed state (eval, simulate, track). */
PRRU_API int prru_forward_dynamics_why(const prru_model *m, prru_data *d, const double q[3],
                                       const double qd[3], const prru_loads *l, char *msg, int msglen);
/* Actuator forces that produce qdd under l->fp, l->mp (l->fd ignored):
 * the solution of J_d^T fd = tau = M qdd - (G + J_T,P^T fp + J_R,P^T mp
 * + passive - h) of least norm, fd = J_d^+T tau (J_d^-T tau for three
 * actuators). PRRU_ESINGULAR where J_d is singular (prru_check_regular) or
 * too near the workspace boundary (prru_stretch, see mass_rcond_min). With four actuators every fd + t n (n: prru_actuator_null)
 * gives the same motion; this one has no preload (fd . n = 0). */
PRRU_API int prru_inverse_dynamics(const prru_model *m, prru_data *d, const double q[3],
                                   const double qd[3], const double qdd[3], const prru_loads *l,
                                   double fd[]);
/* The same plus the internal preload t (N) along n: fd = J_d^+T tau + t n,
 * so fd . n = t (to rounding) and the motion is the same for every t. For
 * models/4prru.json n = (-1, -1, 1, 1)/2 at q1 = q2 = 0 (any q3): a
 * positive t adds t/2 of upward force on sliders 3 and 4 and t/2 of
 * downward force on sliders 1 and 2, the two pairs bracing the platform
 * against each other. PRRU_EINPUT for a
 * non-finite t, and for a non-zero t on a model without redundant
 * actuators (nact = 3); t = 0 is prru_inverse_dynamics. */
PRRU_API int prru_inverse_dynamics_preload(const prru_model *m, prru_data *d, const double q[3],
                                           const double qd[3], const double qdd[3], const prru_loads *l,
                                           double preload, double fd[]);
/* n: the unit vector spanning null(J_d^T) (J_d^T n = 0, |n| = 1), with
 * n_NACT > 0 (the largest-magnitude component positive if n_NACT = 0 to
 * rounding): the actuator-force pattern that is in equilibrium by itself.
 * Computed from the 3x3 minors of J_d (the generalized cross product of its
 * columns). Needs a regular q (prru_check_regular's statuses); PRRU_EINPUT
 * with three actuators (n then does not exist; n is left untouched). */
PRRU_API int prru_actuator_null(const prru_model *m, prru_data *d, const double q[3],
                                double n[]);
/* The joint reaction coordinates (eq. 31, nlambda of them) at the
 * state's qdd, which it solves for first and leaves in d->qdd; lambda is
 * also left in d->r. The sliders receive the actuator forces net of the
 * drives' armature, damping and friction (model format 2). Computed by the
 * generated closed form prru_joint_reactions (no linear solve).
 * With four limbs (the 4-PRRU, null(Q) of dimension 1) Q^T Phi^-1 Q is singular: every
 * lambda + s z (z: prru_reaction_null) satisfies the equations of motion
 * equally well, and the reactions reported are the solution of least
 * Euclidean norm, lambda . z = 0 (coordinates in N and N m as they stand).
 * z is left in d->lambda_null. PRRU_ESINGULAR where the joints cannot
 * carry the loads at all (a constraint singularity, which shows at rest
 * too), PRRU_EINPUT where velocities or loads overflow the arithmetic. */
PRRU_API int prru_reactions(const prru_model *m, prru_data *d, const double q[3], const double qd[3],
                            const prru_loads *l, double lambda[]);
/* z: the unit vector spanning null(Q) at q (Q z = 0, |z| = 1), the one
 * statically indeterminate reaction pattern of the 4-PRRU. Physically: a
 * lateral force along e2 (normal to the plane y = 0 of limbs 3 and 4,
 * whose hinges are all parallel to e2, so no joint of theirs is free
 * along it) that runs rail 3 -> slider 3 -> upper link 3 -> lower link 3
 * -> platform (at O') -> lower link 4 -> upper link 4 -> slider 4 -> rail 4
 * and back through the ground.
 * Limb 3 pushes O' along +e2 and limb 4 along -e2 (C3's force along e2 is
 * +f, C4's -f: they cancel on the platform), each limb carrying f out of
 * its own plane y = 0 to its rail, and rails 3 and 4 close the loop
 * through the ground; every joint of limbs 3 and 4 carries the force f
 * along e2 (none along e1, e3) and the moments that carry it along the
 * links; every coordinate of limbs 1 and 2 is 0 (to rounding).
 * It loads no body and moves nothing, so rigid-body dynamics cannot
 * determine how much of it is present (that depends on the joints'
 * compliance and fit; prru_reactions reports none of it). Sign: the first
 * coordinate (in lambda order) of magnitude at least half the largest is
 * positive, here C3's force along e2. PRRU_EINPUT when
 * three limbs (z untouched); otherwise the statuses of
 * prru_reactions at q. */
PRRU_API int prru_reaction_null(const prru_model *m, prru_data *d, const double q[3],
                                double z[]);
/* T, V (J). */
PRRU_API int prru_energies(const prru_model *m, const double q[3], const double qd[3], double *T,
                           double *V);
/* The power (W) delivered to the machine at (q, qd): *load_power =
 * fd . d' + fp . v_O' + mp . w_P, the actuator forces on the sliders
 * (d' = J_d qd), the platform force at O' (v_O' = J_T,O' qd) and the
 * platform moment (w_P = J_R,P qd); *passive_power = Q_p . qd, the drives'
 * damping and friction (prru_model_passive; dissipated: <= 0). Gravity is
 * in V, so d/dt (T + V) = *load_power + *passive_power along every motion:
 * integrated, the work-energy balance of a run (prru paper). Raw kernel
 * outputs as prru_model_*: NaN where q is out of reach. Either pointer
 * may be NULL. */
PRRU_API void prru_power(const prru_model *m, const double q[3], const double qd[3], const prru_loads *l,
                         double *load_power, double *passive_power);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_DYNAMICS_H */
