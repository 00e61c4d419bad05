/* Design optimisation of the rotational dynamic manipulability w_R (paper
 * section 5: choose geometry and inertia so that the w_R surface drops
 * toward the plane w_R = 1 over the workspace) and the sensitivity of the
 * global index to every parameter.
 *
 * A design is a prru_params (prru_descriptor.h): every number of a model,
 * which the parameter kernels of the model's topology take at run time, so
 * that a candidate costs no code generation. Designs have the topology of
 * the model designed (three or four limbs: its limbs, bodies and
 * actuators, so its parameter names and their count): the problem holds
 * that model (prru_design_problem.model), and a function that needs the
 * topology without a problem takes it first (m). Only m's topology is
 * read, never its numbers: a design is the prru_params given. A design is
 * judged exactly as a model's map is by `prru map`: w_R by prru_dme_from,
 * regularity by prru_jd_regular (with the design's own length scale, the
 * mean upper link), a regular pose whose det J_d has the other sign than
 * at home (0, 0, q3) counted as singular (the other assembly mode, cut off
 * from home by the singular locus; three actuators only), the global index
 * by prru_map_summarize; a design evaluated here and the same design
 * written as a model file, regenerated and mapped by `prru map` give the
 * same index (to the kernels' 1e-13 agreement).
 *
 * Parameter names (one number each):
 *   b_i, l1_i, l2_i        rail offset, upper link, lower link of limb i (m)
 *   a_1, a_2               U-joint offsets of limbs 1 and 2 (m)
 *   m_B                    mass of body B (kg), B one of P L1.. U1.. S1..
 *   com_B_x, com_B_y, com_B_z            its centre of mass (m, body frame)
 *   I_B_xx, I_B_yy, I_B_zz, I_B_xy, I_B_xz, I_B_yz
 *                          its inertia about the centre of mass (kg m^2)
 *   armature_i             reflected drive inertia of actuator i (kg)
 * Design variables tie parameters together (they move by the same amount;
 * the variable's value and bounds are those of the first one listed):
 *   b, l1, l2              every limb's; a: limbs 1 and 2 (a_1, a_2)
 *   b_12, l1_3, a_1, ...   the limbs listed by their digits: b_12 is b_1
 *                          and b_2 tied; b and a also without the
 *                          underscore (b12, b3, a1), as the paper names them
 *   m_B, com_B_x, I_B_xx   with B a body, or a body kind L, U or S for that
 *                          body of every limb (m_U: every upper link's mass)
 *   armature, armature_i   every actuator's, or actuator i's.
 * Gravity, damping and Coulomb friction do not change w_R and are no
 * design variables.
 *
 * Threading: the calls write only into their prru_design_data and
 * outputs; use one prru_design_data per thread. An evaluation splits the
 * grid's rows over prru_design_data.nthreads threads and sums them in row
 * order, so the result has the same bits for any number of threads.
 * prru_design_evaluate allocates nothing (it starts the threads). */
#ifndef PRRU_DESIGN_H
#define PRRU_DESIGN_H

#include <stddef.h>

#include "prru_dme.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most parameters one design variable can tie (every body of a kind,
 * every limb). */
#define PRRU_DESIGN_MAX_TIE (PRRU_MAX_BODY)

typedef struct {
  char name[24];                       /* as parsed, e.g. "b12", "I_U_xx" */
  int n;                               /* parameters tied */
  size_t offset[PRRU_DESIGN_MAX_TIE];  /* byte offsets of the doubles in prru_params */
  double lo, hi;                       /* bounds of the value (the first parameter's) */
} prru_design_var;

/* Parses a parameter or variable name (grammar above) of m's topology
 * (its limbs, bodies and actuators) into v (bounds not set): PRRU_OK, or
 * PRRU_EINPUT with msg saying why. */
PRRU_API int prru_design_var_parse(const prru_model *m, const char *name, prru_design_var *v, char *msg,
                                   int msglen);
/* The number of single parameters of m's topology, and the k-th
 * (0-based, order of the list above: geometry by limb, then every body's
 * m, com, I, then the armatures) as a one-parameter variable named
 * canonically ("b_1"). */
PRRU_API int prru_design_param_count(const prru_model *m);
PRRU_API int prru_design_param(const prru_model *m, int k, prru_design_var *v);
/* The variable's value in p (its first parameter's). */
PRRU_API double prru_design_get(const prru_params *p, const prru_design_var *v);
/* Sets the variable to x: every tied parameter moves by x minus the
 * first one's value in base (p and base may be the same). */
PRRU_API void prru_design_set(prru_params *p, const prru_params *base, const prru_design_var *v, double x);
/* Sets every parameter the variable ties to x itself (b12 = 0.3 makes b1
 * and b2 both 0.3): a start design stated outright (prru optimize
 * --set), where prru_design_set keeps the tied parameters' differences. */
PRRU_API void prru_design_assign(prru_params *p, const prru_design_var *v, double x);
/* A natural scale of the variable at p (a design of m's topology), for
 * difference steps and scaled sensitivities: |value|, or where the value
 * may be 0, the body's mean principal moment (products of inertia), the
 * design's length scale (centres of mass), the mean slider mass
 * (armature). */
PRRU_API double prru_design_scale(const prru_model *m, const prru_params *p, const prru_design_var *v);

/* Bounds of v: -+ pct % (0 < pct < 100) of the value of every parameter v
 * ties (of its prru_design_scale where it is 0). Tied parameters move by
 * one shift (prru_design_set), so the bounds of the value are the
 * intersection of every parameter's: no tied parameter leaves its own
 * -+ pct %, whatever the limbs' values. PRRU_OK, or PRRU_EINPUT (pct). */
PRRU_API int prru_design_var_bounds(const prru_model *m, const prru_params *p, prru_design_var *v,
                                    double pct);

/* The length scale of p, a design of m's topology: the mean upper link
 * (prru_length_scale). */
PRRU_API double prru_design_length_scale(const prru_model *m, const prru_params *p);

/* Is p a buildable robot of m's topology, by the rules a model file must
 * follow: lengths and masses positive, armature not negative, every
 * number 0 or of magnitude in [1e-9, 1e6], inertia tensors positive
 * definite with principal moments obeying the triangle inequality, and
 * every limb assembled at q = 0 (horizontal gap |b - a - l2| shorter
 * than l1).
 * PRRU_OK, or PRRU_EINPUT with msg naming the parameter and the rule (or
 * saying that m, NULL or of no topology, has no design). */
PRRU_API int prru_design_check(const prru_model *m, const prru_params *p, char *msg, int msglen);

typedef enum {
  PRRU_OBJ_MEAN = 0, /* global index: mean of w_R - 1 over the regular grid points */
  PRRU_OBJ_MAX = 1,  /* the largest w_R on the grid */
  PRRU_OBJ_LOG = 2   /* mean of ln w_R over the regular grid points */
} prru_objective;

/* "mean", "max", "log"; PRRU_OK or PRRU_EINPUT. */
PRRU_API int prru_objective_parse(const char *s, prru_objective *o);
PRRU_API const char *prru_objective_name(prru_objective o);

/* The optimisation problem: where and how a design is judged. */
typedef struct {
  /* The model designed: its topology is the designs' (prru_params of its
   * limbs, bodies and actuators, evaluated with its topology's parameter
   * kernels); it must outlive the problem. */
  const prru_model *model;
  prru_map_grid grid;     /* the workspace rectangle (prru_map_check) */
  double rcond_min;       /* J_d regular where rcond >= this, in (0, 1) */
  prru_objective objective;
  int stroke;             /* non-zero: every slider within [stroke_lo, stroke_hi] */
  double stroke_lo, stroke_hi; /* m */
  /* The constraints enter as a penalty: merit = objective + weight *
   * (regularity violation + stroke violation), both 0 exactly when the
   * design is feasible. */
  double penalty_weight;
} prru_design_problem;

/* Fig. 7-like defaults for designs of m on a grid: rcond_min 4e-3
 * (cond_1 <= 250), mean, no stroke limits, weight 1000. */
PRRU_API void prru_design_problem_default(const prru_model *m, prru_design_problem *pr,
                                          const prru_map_grid *g);
/* PRRU_OK, or PRRU_EINPUT with msg (model, grid, rcond_min, stroke,
 * weight). */
PRRU_API int prru_design_problem_check(const prru_design_problem *pr, char *msg, int msglen);
/* A run's strokes (prru_limits_for_run) as the problem's: one interval
 * for every slider of its model (pr->model set), the intersection of
 * theirs (none when no slider has one). PRRU_OK, or PRRU_EINPUT with msg
 * when they have no common interval (pr untouched). */
PRRU_API int prru_design_problem_stroke(prru_design_problem *pr, const prru_limits *l, char *msg, int msglen);

/* The status of a regular grid point in the other assembly mode: the
 * map's (PRRU_DME_OTHER_MODE, classified by prru_mode_status);
 * prru_map_summarize counts it as singular and in n_other_mode. */
#define PRRU_DESIGN_OTHER_MODE PRRU_DME_OTHER_MODE

struct prru_design_row;

/* Per-grid-point workspace, allocated once per problem. */
typedef struct {
  long n;
  int nthreads;          /* threads per evaluation (default 2; the result is the same for any) */
  double *w_R;           /* n, NaN where status != PRRU_OK */
  unsigned char *status; /* n, a prru_status per point or PRRU_DESIGN_OTHER_MODE */
  struct prru_design_row *rows; /* per grid row sums (private) */
  int precision; /* PRRU_PRECISION_DOUBLE (default) or _FLOAT: w_R and the sliders' range in
                    float (the topology's f_batch_dme_terms), the statuses double's as in the maps
                    (prru_dme.h), rcond double's wherever it is penalised */
} prru_design_data;

/* PRRU_OK or PRRU_ENOMEM; nthreads 2, double. */
PRRU_API int prru_design_data_alloc(prru_design_data *dd, const prru_map_grid *g);
PRRU_API void prru_design_data_free(prru_design_data *dd);

typedef struct {
  int valid;                 /* prru_design_check passed (otherwise only merit is set) */
  prru_map_summary sum;      /* the map's summary of the grid */
  double objective;          /* the chosen measure; NaN when no point is regular */
  long n_other_mode;          /* sum.n_other_mode (of sum.n_singular) */
  /* Regularity violation: the mean over the grid points of, with r =
   * rcond_min, C = ln(r / DBL_EPSILON) and s = rcond (home's mode) or
   * -rcond (the other): 0 for s >= r, min(C, ln(r / s)) for 0 < s < r,
   * C + ln(1 + |s| / r) for s <= 0, C where unreachable (J_d's
   * conditioning falls to 0 at the reach boundary and at the mode change,
   * so it is continuous there). */
  double reg_violation;
  /* Stroke violation: the mean over the reachable points of the sum over
   * the sliders of the distance outside [lo, hi], in units of the length
   * scale (0 without stroke limits). */
  double stroke_violation;
  double d_min, d_max;       /* slider range over the reachable points (m) */
  double merit;              /* what the optimiser minimizes */
  int feasible;              /* valid, every point regular, strokes kept */
} prru_design_eval;

/* Evaluates p on the problem's grid into dd and ev. The design is checked
 * first (prru_design_check); an invalid one gets merit = 1e30 and
 * ev->valid = 0. Returns PRRU_OK, or PRRU_EINPUT for an invalid design. */
PRRU_API int prru_design_evaluate(const prru_design_problem *pr, const prru_params *p,
                                  prru_design_data *dd, prru_design_eval *ev);

/* ---- Optimisation ---- */

/* Called once per iteration; a non-zero return stops the run. */
typedef int (*prru_design_progress_fn)(int iter, int evals, const prru_design_eval *best,
                                       double size, void *ctx);

typedef struct {
  int max_iter;          /* Nelder-Mead iterations over all restarts (default 600) */
  double tol;            /* simplex size at which a run stops (default 1e-5) */
  int restarts;          /* fresh simplices from the best point (default 2) */
  int nthreads;          /* threads per evaluation (default 2; the same result for any) */
  prru_design_progress_fn progress; void *ctx;
  int precision;         /* of each evaluation: PRRU_PRECISION_DOUBLE (default) or _FLOAT */
} prru_design_options;

PRRU_API void prru_design_options_default(prru_design_options *o);

typedef struct {
  prru_params best;      /* the best design found */
  prru_design_eval start_eval, best_eval;
  double x0[64], x[64];  /* the variables at the start and at the best design */
  int iterations, evaluations, restarts_done;
  int converged;         /* the last run stopped at tol (not at max_iter) */
} prru_design_result;

/* The most design variables. */
#define PRRU_DESIGN_MAX_VARS 64

/* Minimizes the merit over the variables within their bounds (GSL
 * nmsimplex2 on x = lo + (hi - lo) (1 + sin u) / 2, which keeps every
 * candidate inside the box without clipping), from start, then restarts
 * from the best point while that improves it. The best design is the
 * feasible one of lowest merit, or without any feasible evaluation the
 * lowest merit (r->best_eval.feasible says which). Deterministic: the
 * same inputs give the same bits.
 * PRRU_OK; PRRU_EINPUT (bad bounds: lo >= hi, a start outside them, more
 * than PRRU_DESIGN_MAX_VARS, msg says which); PRRU_EINTERRUPTED (the
 * progress callback stopped it; r holds the best so far); PRRU_ENOMEM. */
PRRU_API int prru_design_optimize(const prru_design_problem *pr, const prru_params *start,
                                  const prru_design_var *vars, int nvar, const prru_design_options *o,
                                  prru_design_result *r, char *msg, int msglen);

/* ---- Sensitivity ---- */

typedef struct {
  double value;          /* the parameter at the design */
  double step;           /* h = rel_step * scale */
  double scale;          /* prru_design_scale */
  double f_plus, f_minus; /* objective at value + h and value - h */
  double derivative;     /* (f_plus - f_minus) / (2 h) */
  /* The regular set changed between value - h and value + h (a grid point
   * crossed the singularity tolerance or the reach): the difference then
   * mixes the derivative with a jump; the derivative is still reported. */
  int set_changed;
} prru_design_sens;

/* Is rel_step a usable relative step for v at p (a design of m's
 * topology): in (0, 0.5), and the
 * step h = rel_step * scale not lost to rounding (value +- h, for every
 * tied parameter, must differ by 2 h to within 1 %). PRRU_OK, or
 * PRRU_EINPUT with msg giving the smallest step that is. */
PRRU_API int prru_design_step_check(const prru_model *m, const prru_params *p, const prru_design_var *v,
                                    double rel_step, char *msg, int msglen);
/* Central difference of the objective with respect to v at p (why not
 * closed-form derivatives: docs/studies.md; truncation O(h^2), 1.5e-4 of
 * the largest sensitivity at rel_step 1e-4 on fig. 7's rectangle). Perturbed
 * designs are evaluated without prru_design_check (a parameter at 0, such
 * as an armature, is differentiated through 0); p itself must be valid.
 * PRRU_OK, PRRU_EINPUT (p invalid, rel_step refused by
 * prru_design_step_check) or PRRU_ESINGULAR (no regular grid point at
 * value +- h). */
PRRU_API int prru_design_sensitivity(const prru_design_problem *pr, const prru_params *p,
                                     const prru_design_var *v, double rel_step, prru_design_data *dd,
                                     prru_design_sens *s);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_DESIGN_H */
