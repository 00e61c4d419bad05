/* Design variables, validity, the global-index objective over a grid with
 * the parameter kernels of the designed model's topology (topology.h),
 * Nelder-Mead optimisation and finite difference sensitivity; definitions
 * in prru_design.h. */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multimin.h>

#include "internal.h"
#include "prru_design.h"
#include "topology.h"

/* ---- Names ---- */

static const char *const axis_names[3] = {"x", "y", "z"};
static const char *const inertia_names[6] = {"xx", "yy", "zz", "xy", "xz", "yz"};

#define OFF(member) offsetof(prru_params, member)

static double *at(prru_params *p, size_t off)
{
  return (double *)(void *)((char *)p + off);
}

static double get(const prru_params *p, size_t off)
{
  return *(const double *)(const void *)((const char *)p + off);
}

static int body_index(const prru_mechanism *me, const char *s, size_t len)
{
  for (int b = 0; b < me->nbody; b++)
    if (strlen(me->body_names[b]) == len && strncmp(me->body_names[b], s, len) == 0) return b;
  return -1;
}

/* Bodies named by s[0..len): a body, or the kind L, U, S of every limb. */
static int bodies_of(const prru_mechanism *me, const char *s, size_t len, int bodies[PRRU_MAX_BODY])
{
  int b = body_index(me, s, len);
  if (b >= 0) {
    bodies[0] = b;
    return 1;
  }
  if (len != 1) return 0;
  const int *kind = s[0] == 'L' ? me->lower : s[0] == 'U' ? me->upper : s[0] == 'S' ? me->slider : NULL;
  if (!kind) return 0;
  for (int i = 0; i < me->nlimb; i++) bodies[i] = kind[i];
  return me->nlimb;
}

static void add(prru_design_var *v, size_t off)
{
  v->offset[v->n++] = off;
}

/* Limbs from a digit string ("12"): each once, within 1..nmax. */
static int limbs_of(const char *digits, int nmax, int limbs[PRRU_MAX_LIMB])
{
  int n = 0, seen[10] = {0};
  if (!*digits) return 0;
  for (const char *c = digits; *c; c++) {
    if (*c < '1' || *c > '9') return 0;
    int l = *c - '0';
    if (l > nmax || seen[l] || n >= PRRU_MAX_LIMB) return 0;
    seen[l] = 1;
    limbs[n++] = l - 1;
  }
  return n;
}

static int parse_geometry(const prru_mechanism *me, const char *name, prru_design_var *v)
{
  static const struct {
    const char *base;
    size_t off;
    int bare_digits; /* b12, a1: digits may follow without '_' */
  } geo[] = {{"b", OFF(b), 1}, {"l1", OFF(l1), 0}, {"l2", OFF(l2), 0}, {"a", OFF(a), 1}};
  for (size_t g = 0; g < sizeof geo / sizeof geo[0]; g++) {
    size_t bl = strlen(geo[g].base);
    if (strncmp(name, geo[g].base, bl) != 0) continue;
    const char *rest = name + bl;
    int nmax = geo[g].off == OFF(a) ? 2 : me->nlimb, limbs[PRRU_MAX_LIMB], n;
    if (!*rest) {
      n = nmax;
      for (int i = 0; i < n; i++) limbs[i] = i;
    } else if (*rest == '_') {
      n = limbs_of(rest + 1, nmax, limbs);
    } else if (geo[g].bare_digits) {
      n = limbs_of(rest, nmax, limbs);
    } else {
      continue;
    }
    if (n == 0) return 0;
    for (int i = 0; i < n; i++) add(v, geo[g].off + (size_t)limbs[i] * sizeof(double));
    return 1;
  }
  return 0;
}

static int parse_inertial(const prru_mechanism *me, const char *name, prru_design_var *v)
{
  int bodies[PRRU_MAX_BODY], nb;
  if (strncmp(name, "m_", 2) == 0) {
    nb = bodies_of(me, name + 2, strlen(name + 2), bodies);
    for (int i = 0; i < nb; i++) add(v, OFF(mass) + (size_t)bodies[i] * sizeof(double));
    return nb > 0;
  }
  int is_com = strncmp(name, "com_", 4) == 0, is_i = strncmp(name, "I_", 2) == 0;
  if (!is_com && !is_i) return 0;
  const char *s = name + (is_com ? 4 : 2), *us = strrchr(s, '_');
  if (!us) return 0;
  nb = bodies_of(me, s, (size_t)(us - s), bodies);
  int comp = -1;
  for (int c = 0; c < (is_com ? 3 : 6); c++)
    if (strcmp(us + 1, is_com ? axis_names[c] : inertia_names[c]) == 0) comp = c;
  if (nb == 0 || comp < 0) return 0;
  for (int i = 0; i < nb; i++)
    add(v, is_com ? OFF(com) + ((size_t)bodies[i] * 3 + (size_t)comp) * sizeof(double)
                  : OFF(inertia) + ((size_t)bodies[i] * 6 + (size_t)comp) * sizeof(double));
  return 1;
}

static int parse_armature(const prru_mechanism *me, const char *name, prru_design_var *v)
{
  if (strcmp(name, "armature") == 0) {
    for (int i = 0; i < me->nact; i++) add(v, OFF(armature) + (size_t)i * sizeof(double));
    return 1;
  }
  if (strncmp(name, "armature_", 9) != 0) return 0;
  int acts[PRRU_MAX_LIMB], n = limbs_of(name + 9, me->nact, acts);
  for (int i = 0; i < n; i++) add(v, OFF(armature) + (size_t)acts[i] * sizeof(double));
  return n > 0;
}

int prru_design_var_parse(const prru_model *m, const char *name, prru_design_var *v, char *msg, int msglen)
{
  memset(v, 0, sizeof *v);
  if (strlen(name) >= sizeof v->name)
    return prru_fail(msg, msglen, PRRU_EINPUT, "'%.30s...': not a design parameter (too long)", name);
  snprintf(v->name, sizeof v->name, "%s", name);
  const prru_mechanism *me = m->mech;
  if (parse_geometry(me, name, v) || parse_inertial(me, name, v) || parse_armature(me, name, v))
    return PRRU_OK;
  return prru_fail(msg, msglen, PRRU_EINPUT,
                   "'%s': not a design parameter (b, l1, l2, a with limb digits such as b12, "
                   "l1_2; m_B, com_B_x, I_B_xy with B a body (P L1 U1 S1 ...) or L, U, S; "
                   "armature[_i])",
                   name);
}

/* Single parameters in order: geometry by limb (b, l1, l2 of every limb,
 * then a_1, a_2), then every body's mass, com, inertia, then the
 * armatures. */
#define NPERBODY 10

static int ngeo(const prru_mechanism *me)
{
  return 3 * me->nlimb + 2;
}

int prru_design_param_count(const prru_model *m)
{
  const prru_mechanism *me = m->mech;
  return ngeo(me) + NPERBODY * me->nbody + me->nact;
}

int prru_design_param(const prru_model *m, int k, prru_design_var *v)
{
  const prru_mechanism *me = m->mech;
  const int n = me->nlimb;
  memset(v, 0, sizeof *v);
  if (k < 0 || k >= prru_design_param_count(m)) return PRRU_EINPUT;
  if (k < ngeo(me)) {
    static const char *const base[3] = {"b", "l1", "l2"};
    static const size_t off[3] = {OFF(b), OFF(l1), OFF(l2)};
    int g = k < 3 * n ? k / n : -1, i = g >= 0 ? k % n : k - 3 * n;
    snprintf(v->name, sizeof v->name, "%s_%d", g >= 0 ? base[g] : "a", i + 1);
    add(v, (g >= 0 ? off[g] : OFF(a)) + (size_t)i * sizeof(double));
    return PRRU_OK;
  }
  k -= ngeo(me);
  if (k < NPERBODY * me->nbody) {
    int b = k / NPERBODY, c = k % NPERBODY;
    const char *bn = me->body_names[b];
    if (c == 0) {
      snprintf(v->name, sizeof v->name, "m_%s", bn);
      add(v, OFF(mass) + (size_t)b * sizeof(double));
    } else if (c < 4) {
      snprintf(v->name, sizeof v->name, "com_%s_%s", bn, axis_names[c - 1]);
      add(v, OFF(com) + ((size_t)b * 3 + (size_t)(c - 1)) * sizeof(double));
    } else {
      snprintf(v->name, sizeof v->name, "I_%s_%s", bn, inertia_names[c - 4]);
      add(v, OFF(inertia) + ((size_t)b * 6 + (size_t)(c - 4)) * sizeof(double));
    }
    return PRRU_OK;
  }
  k -= NPERBODY * me->nbody;
  snprintf(v->name, sizeof v->name, "armature_%d", k + 1);
  add(v, OFF(armature) + (size_t)k * sizeof(double));
  return PRRU_OK;
}

double prru_design_get(const prru_params *p, const prru_design_var *v)
{
  return get(p, v->offset[0]);
}

void prru_design_set(prru_params *p, const prru_params *base, const prru_design_var *v, double x)
{
  double shift = x - get(base, v->offset[0]);
  double vals[PRRU_DESIGN_MAX_TIE];
  for (int i = 0; i < v->n; i++) vals[i] = get(base, v->offset[i]); /* p may be base */
  for (int i = 0; i < v->n; i++) *at(p, v->offset[i]) = i == 0 ? x : vals[i] + shift;
}

void prru_design_assign(prru_params *p, const prru_design_var *v, double x)
{
  for (int i = 0; i < v->n; i++) *at(p, v->offset[i]) = x;
}

double prru_design_length_scale(const prru_model *m, const prru_params *p)
{
  /* The same sum as prru_length_scale, so that a design and its
   * regenerated model use the same bits. */
  const int n = m->mech->nlimb;
  double s = 0;
  for (int i = 0; i < n; i++) s += p->l1[i];
  return s / n;
}

double prru_design_scale(const prru_model *m, const prru_params *p, const prru_design_var *v)
{
  size_t off = v->offset[0];
  double x = fabs(get(p, off));
  if (off >= OFF(com) && off < OFF(com) + sizeof p->com) return prru_design_length_scale(m, p);
  if (off >= OFF(inertia) && off < OFF(inertia) + sizeof p->inertia) {
    size_t e = (off - OFF(inertia)) / sizeof(double);
    if (e % 6 < 3) return x;
    const double *t = p->inertia[e / 6];
    return (fabs(t[0]) + fabs(t[1]) + fabs(t[2])) / 3.0;
  }
  if (off >= OFF(armature) && off < OFF(armature) + sizeof p->armature && !(x > 0)) {
    const prru_mechanism *me = m->mech;
    double s = 0;
    for (int i = 0; i < me->nlimb; i++) s += p->mass[me->slider[i]];
    return s / me->nlimb;
  }
  return x;
}

/* v's k-th parameter alone (for its own value and scale). */
static prru_design_var member(const prru_design_var *v, int k)
{
  prru_design_var m = *v;
  m.n = 1;
  m.offset[0] = v->offset[k];
  return m;
}

int prru_design_var_bounds(const prru_model *m, const prru_params *p, prru_design_var *v, double pct)
{
  if (!(pct > 0 && pct < 100)) return PRRU_EINPUT;
  /* Every parameter's bounds are symmetric, x_k -+ pct % r_k: the shifts
   * all of them allow are -+ pct % of the smallest r_k. */
  double r = INFINITY;
  for (int k = 0; k < v->n; k++) {
    prru_design_var one = member(v, k);
    double x = fabs(prru_design_get(p, &one));
    r = fmin(r, x > 0 ? x : prru_design_scale(m, p, &one));
  }
  double x0 = prru_design_get(p, v);
  v->lo = x0 - pct / 100 * r;
  v->hi = x0 + pct / 100 * r;
  return PRRU_OK;
}

/* ---- Validity ---- */

static int in_file_range(double x)
{
  return isfinite(x) && (x == 0.0 || (fabs(x) >= 1e-9 && fabs(x) <= 1e6));
}

/* Leading minors (strict) or all principal minors (non-strict) of a
 * symmetric 3x3, as the model loader's Sylvester test. */
static int minors_ok(const double m[3][3], int strict)
{
  double d01 = m[0][0] * m[1][1] - m[0][1] * m[0][1], d02 = m[0][0] * m[2][2] - m[0][2] * m[0][2];
  double d12 = m[1][1] * m[2][2] - m[1][2] * m[1][2];
  double d3 = m[0][0] * d12 - m[0][1] * (m[0][1] * m[2][2] - m[1][2] * m[0][2]) +
              m[0][2] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
  if (strict) return m[0][0] > 0 && d01 > 0 && d3 > 0;
  return m[0][0] >= 0 && m[1][1] >= 0 && m[2][2] >= 0 && d01 >= 0 && d02 >= 0 && d12 >= 0 &&
         d3 >= 0;
}

static int inertia_ok(const double e[6], const char *body, char *msg, int msglen)
{
  const double t[3][3] = {{e[0], e[3], e[4]}, {e[3], e[1], e[5]}, {e[4], e[5], e[2]}};
  if (!minors_ok(t, 1))
    return prru_fail(msg, msglen, PRRU_EINPUT, "I_%s: the inertia tensor is not positive definite",
                     body);
  /* tr(I)/2 E - I = the second moment of the mass, positive semidefinite:
   * the triangle inequality of the principal moments. */
  double h = (e[0] + e[1] + e[2]) / 2;
  const double s[3][3] = {{h - e[0], -e[3], -e[4]}, {-e[3], h - e[1], -e[5]}, {-e[4], -e[5], h - e[2]}};
  if (!minors_ok(s, 0))
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "I_%s: the principal moments violate the triangle inequality (no rigid body)",
                     body);
  return PRRU_OK;
}

static int numbers_ok(const prru_model *m, const prru_params *p, char *msg, int msglen)
{
  for (int k = 0; k < prru_design_param_count(m); k++) {
    prru_design_var v;
    prru_design_param(m, k, &v);
    double x = prru_design_get(p, &v);
    if (!in_file_range(x))
      return prru_fail(msg, msglen, PRRU_EINPUT, "%s = %.17g: not 0 and not of magnitude in [1e-9, 1e6]",
                       v.name, x);
  }
  return PRRU_OK;
}

static int limb_ok(const prru_params *p, int i, char *msg, int msglen)
{
  if (!(p->b[i] > 0) || !(p->l1[i] > 0) || !(p->l2[i] > 0))
    return prru_fail(msg, msglen, PRRU_EINPUT, "limb %d: b, l1, l2 must be positive (%g, %g, %g)",
                     i + 1, p->b[i], p->l1[i], p->l2[i]);
  double a = i < 2 ? p->a[i] : 0.0;
  if (i < 2 && !(a > 0))
    return prru_fail(msg, msglen, PRRU_EINPUT, "a_%d = %g: must be positive", i + 1, a);
  double gap = p->b[i] - a - p->l2[i];
  if (!(fabs(gap) < p->l1[i]))
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "limb %d cannot be assembled at q = 0: the horizontal gap b - a - l2 = %g m "
                     "must be shorter than l1 = %g m",
                     i + 1, gap, p->l1[i]);
  return PRRU_OK;
}

int prru_design_check(const prru_model *m, const prru_params *p, char *msg, int msglen)
{
  /* A design is evaluated with its model's topology's kernels: without
   * them there is nothing to judge it by (a problem never defaulted). */
  if (!m || !prru_topology_of(m->mech->nlimb))
    return prru_fail(msg, msglen, PRRU_EINPUT, "no model of 3 or 4 limbs to design");
  const prru_mechanism *me = m->mech;
  int st = numbers_ok(m, p, msg, msglen);
  for (int i = 0; i < me->nlimb && st == PRRU_OK; i++) st = limb_ok(p, i, msg, msglen);
  for (int b = 0; b < me->nbody && st == PRRU_OK; b++) {
    if (!(p->mass[b] > 0))
      return prru_fail(msg, msglen, PRRU_EINPUT, "m_%s = %g: must be positive", me->body_names[b],
                       p->mass[b]);
    st = inertia_ok(p->inertia[b], me->body_names[b], msg, msglen);
  }
  for (int i = 0; i < me->nact && st == PRRU_OK; i++)
    if (!(p->armature[i] >= 0))
      return prru_fail(msg, msglen, PRRU_EINPUT, "armature_%d = %g: must not be negative", i + 1,
                       p->armature[i]);
  return st;
}

/* ---- Objective ---- */

int prru_objective_parse(const char *s, prru_objective *o)
{
  for (int k = 0; k < 3; k++)
    if (strcmp(s, prru_objective_name((prru_objective)k)) == 0) {
      *o = (prru_objective)k;
      return PRRU_OK;
    }
  return PRRU_EINPUT;
}

const char *prru_objective_name(prru_objective o)
{
  return o == PRRU_OBJ_MAX ? "max" : o == PRRU_OBJ_LOG ? "log" : "mean";
}

void prru_design_problem_default(const prru_model *m, prru_design_problem *pr, const prru_map_grid *g)
{
  pr->model = m;
  pr->grid = *g;
  pr->rcond_min = 4e-3;
  pr->objective = PRRU_OBJ_MEAN;
  pr->stroke = 0;
  pr->stroke_lo = pr->stroke_hi = 0.0;
  pr->penalty_weight = 1000.0;
}

int prru_design_problem_stroke(prru_design_problem *pr, const prru_limits *l, char *msg, int msglen)
{
  double lo = -INFINITY, hi = INFINITY;
  for (int i = 0; i < pr->model->mech->nact; i++)
    lo = fmax(lo, l->d_min[i]), hi = fmin(hi, l->d_max[i]);
  if (isinf(lo) && isinf(hi)) return PRRU_OK;
  if (!(lo < hi))
    return prru_fail(msg, msglen, PRRU_EINPUT, "the sliders' strokes have no common interval ([%g, %g]): the "
                     "design's stroke is one interval for all", lo, hi);
  pr->stroke = 1;
  pr->stroke_lo = lo, pr->stroke_hi = hi;
  return PRRU_OK;
}

int prru_design_problem_check(const prru_design_problem *pr, char *msg, int msglen)
{
  if (!pr->model || !prru_topology_of(pr->model->mech->nlimb))
    return prru_fail(msg, msglen, PRRU_EINPUT, "the problem has no model of 3 or 4 limbs "
                                               "(prru_design_problem_default sets it)");
  if (prru_map_check(&pr->grid) != PRRU_OK)
    return prru_fail(msg, msglen, PRRU_EINPUT, "the grid is not valid (finite ranges lo < hi, "
                                               "at least 2 points per axis)");
  if (!(pr->rcond_min > 0 && pr->rcond_min < 1))
    return prru_fail(msg, msglen, PRRU_EINPUT, "rcond_min %g: must be in (0, 1)", pr->rcond_min);
  if (pr->stroke && !(isfinite(pr->stroke_lo) && isfinite(pr->stroke_hi) &&
                      pr->stroke_lo < pr->stroke_hi))
    return prru_fail(msg, msglen, PRRU_EINPUT, "stroke %g:%g: needs finite lo < hi", pr->stroke_lo,
                     pr->stroke_hi);
  if (!(pr->penalty_weight > 0 && isfinite(pr->penalty_weight)))
    return prru_fail(msg, msglen, PRRU_EINPUT, "penalty weight %g: must be positive",
                     pr->penalty_weight);
  return PRRU_OK;
}

/* What one grid row adds to an evaluation; rows are summed in order, so
 * the result does not depend on which thread did which row. */
struct prru_design_row {
  double viol, stroke, dmin, dmax;
  long nreach;
  int changed;
};

int prru_design_data_alloc(prru_design_data *dd, const prru_map_grid *g)
{
  dd->n = (long)g->n1 * g->n2;
  dd->nthreads = 2;
  dd->precision = PRRU_PRECISION_DOUBLE;
  dd->w_R = malloc((size_t)dd->n * sizeof *dd->w_R);
  dd->status = malloc((size_t)dd->n);
  dd->rows = malloc((size_t)g->n1 * sizeof *dd->rows);
  if (dd->w_R && dd->status && dd->rows) return PRRU_OK;
  prru_design_data_free(dd);
  return PRRU_ENOMEM;
}

void prru_design_data_free(prru_design_data *dd)
{
  free(dd->w_R);
  free(dd->status);
  free(dd->rows);
  dd->w_R = NULL;
  dd->status = NULL;
  dd->rows = NULL;
  dd->n = 0;
}

/* Distance of the nact sliders outside [lo, hi], summed. */
static double stroke_excess(const prru_design_problem *pr, const double d[], int nact)
{
  double e = 0;
  for (int i = 0; i < nact; i++) e += fmax(0.0, pr->stroke_lo - d[i]) + fmax(0.0, d[i] - pr->stroke_hi);
  return e;
}

/* The assembly mode of the design at home, (0, 0, q3), as
 * prru_map_home_mode tells the model's (0: no point is in "the other"
 * mode). */
static int home_mode(const prru_topology *t, const prru_topo_derived *p, double q3)
{
  const double q[3] = {0.0, 0.0, q3};
  double d[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3];
  t->general->ik_jd(p, q, d, Jd);
  return prru_assembly_mode(d, Jd, t->nact);
}

/* The design's kernels at a block of grid points, from the batched
 * dme_terms (bit for bit its topology's ik_jd, mass, platform_jacobian):
 * rows of GRID_BLOCK, point c's entry i at [i * n + c]; then w_R, the
 * status, rcond and the mode of every point from prru_dme_batch (bit for
 * bit prru_jd_regular, prru_mode_status and prru_dme_from). */
#define GRID_BLOCK 64
typedef struct {
  int n;
  double q[3 * GRID_BLOCK], d[PRRU_MAX_ACT * GRID_BLOCK], Jd[3 * PRRU_MAX_ACT * GRID_BLOCK],
      M[9 * GRID_BLOCK], JP[18 * GRID_BLOCK], rc[GRID_BLOCK];
  unsigned char st[GRID_BLOCK], other[GRID_BLOCK];
  prru_dme_batch_ws ws;
} grid_block;

/* The float evaluation of a block (prru_design_data.precision): its
 * kernels' inputs and outputs, and the points redone in double. */
typedef struct {
  float q[3 * GRID_BLOCK], d[PRRU_MAX_ACT * GRID_BLOCK], Jd[3 * PRRU_MAX_ACT * GRID_BLOCK],
      M[9 * GRID_BLOCK], JP[18 * GRID_BLOCK];
  unsigned char sure[GRID_BLOCK];
  int redo[GRID_BLOCK];
  grid_block x; /* the redone points, compacted */
  prru_dme_batch_wsf ws;
} grid_block_f;

/* A float point is taken as it is only where float's status is surely
 * double's (prru_dme_batch_f's sure: ok with rcond and the DME's tests
 * clear of their thresholds, so that its violation, 0, is double's too)
 * and its sliders are clear of the stroke limits by more than their error
 * (256 FLT_EPSILON (|d| + 4 L), as the map's stroke test). Its d, w_R then
 * enter in float; every other point is redone in double, rcond with it. */
static int float_point_clear(const prru_design_problem *pr, const grid_block_f *f, int n, int c,
                             double L, int nact)
{
  if (!f->sure[c]) return 0;
  for (int i = 0; i < nact; i++) {
    const double di = f->d[(long)i * n + c], e = 256.0 * FLT_EPSILON * (fabs(di) + 4.0 * L);
    if (pr->stroke && !(di - e >= pr->stroke_lo && di + e <= pr->stroke_hi)) return 0;
  }
  return 1;
}

/* b (q filled, n points) in float: w_R into w, and b's d, rc, st, other
 * as the double path gives them (d of the points taken in float: float's
 * converted; rc: rcond_min there, whose violation is 0 as the true rcond's). */
static void grid_block_float(const prru_design_problem *pr, const prru_topology *t,
                             const prru_topo_derived *p, double L, int home, grid_block *b,
                             grid_block_f *f, double *w)
{
  const int n = b->n, nact = t->nact;
  for (int i = 0; i < 3 * n; i++) f->q[i] = (float)b->q[i];
  t->f_batch_dme_terms(p, n, f->q, f->d, f->Jd, f->M, f->JP);
  prru_dme_batch_f(nact, n, f->d, f->Jd, f->M, f->JP, L, pr->rcond_min, home, &f->ws, w, b->st, f->sure);
  int nx = 0;
  for (int c = 0; c < n; c++) {
    for (int i = 0; i < nact; i++) b->d[(long)i * n + c] = f->d[(long)i * n + c];
    b->rc[c] = pr->rcond_min;
    b->other[c] = 0;
    if (!float_point_clear(pr, f, n, c, L, nact)) f->redo[nx++] = c;
  }
  if (nx == 0) return;
  grid_block *x = &f->x;
  x->n = nx;
  for (int r = 0; r < 3; r++)
    for (int k = 0; k < nx; k++) x->q[(long)r * nx + k] = b->q[(long)r * n + f->redo[k]];
  double wx[GRID_BLOCK];
  t->general->batch_dme_terms(p, nx, x->q, x->d, x->Jd, x->M, x->JP);
  prru_dme_batch(nact, nx, x->d, x->Jd, x->M, x->JP, L, pr->rcond_min, home, &x->ws, wx, x->st, x->rc, x->other);
  for (int k = 0; k < nx; k++) {
    const int c = f->redo[k];
    w[c] = wx[k];
    b->st[c] = x->st[k];
    b->rc[c] = x->rc[k];
    b->other[c] = x->other[k];
    for (int i = 0; i < nact; i++) b->d[(long)i * n + c] = x->d[(long)i * nx + k];
  }
}

/* Point c's share of the regularity violation, for the status the map
 * gives it: unreachable, singular (rcond below the tolerance), or regular
 * but in the other assembly mode (det J_d's sign not home's: cut off from
 * home by the singular locus; counted as singular, like the map does) are
 * not ok. The penalty is continuous in the signed conditioning s = +-rcond
 * (sign: home's mode or not), r = rcond_min, C = ln(r / eps):
 *   s >= r: 0;  0 < s < r: min(C, ln(r / s));  s <= 0: C + ln(1 + |s| / r);
 * unreachable points get C (rcond falls to 0 at the reach boundary); the
 * other mode's singular points are penalised too, so that it is continuous
 * across the locus. */
static double point_violation(const prru_design_problem *pr, const grid_block *b, int c)
{
  const double r = pr->rcond_min, cap = log(r / DBL_EPSILON), rc = b->rc[c];
  const int st = b->st[c];
  if (st == PRRU_EUNREACHABLE) return cap;
  if (b->other[c]) return cap + log1p(rc / r);
  return st == PRRU_OK ? 0.0 : rc > 0 && rc < r ? fmin(cap, log(r / rc)) : cap;
}

/* One design over the grid: rows handed out under a mutex (a row is n2
 * evaluations, the lock is negligible). compare: note in the row when a
 * point's regularity differs from the status dd holds from before. */
typedef struct {
  const prru_design_problem *pr;
  const prru_topology *t; /* the problem's model's: the design's kernels and sizes */
  const prru_topo_derived *p;
  prru_design_data *dd;
  double L;
  int home, compare, next_row;
  pthread_mutex_t lock;
} grid_job;

static void grid_row(grid_job *j, int i)
{
  const prru_design_problem *pr = j->pr;
  const prru_map_grid *g = &pr->grid;
  struct prru_design_row *r = &j->dd->rows[i];
  const int nact = j->t->nact;
  const double q1 = prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i);
  grid_block b PRRU_ALIGN64; /* about 40 KB of this thread's stack: no allocation */
  /* float: about 70 KB more, allocated (without it, double: slower, the
   * reference values) */
  grid_block_f *f = NULL;
  if (j->dd->precision == PRRU_PRECISION_FLOAT) {
    void *a = NULL;
    if (posix_memalign(&a, 64, sizeof *f) == 0) f = a;
  }
  memset(r, 0, sizeof *r);
  r->dmin = INFINITY;
  r->dmax = -INFINITY;
  for (int c0 = 0; c0 < g->n2; c0 += GRID_BLOCK) {
    b.n = g->n2 - c0 < GRID_BLOCK ? g->n2 - c0 : GRID_BLOCK;
    for (int t = 0; t < b.n; t++) {
      b.q[t] = q1;
      b.q[b.n + t] = prru_map_axis(g->q2_lo, g->q2_hi, g->n2, c0 + t);
      b.q[2 * b.n + t] = g->q3;
    }
    const long k0 = (long)i * g->n2 + c0;
    if (f) {
      grid_block_float(pr, j->t, j->p, j->L, j->home, &b, f, &j->dd->w_R[k0]);
    } else {
      j->t->general->batch_dme_terms(j->p, b.n, b.q, b.d, b.Jd, b.M, b.JP);
      prru_dme_batch(nact, b.n, b.d, b.Jd, b.M, b.JP, j->L, pr->rcond_min, j->home, &b.ws,
                     &j->dd->w_R[k0], b.st, b.rc, b.other);
    }
    for (int c = 0; c < b.n; c++) {
      const long k = k0 + c;
      const int st = b.st[c];
      if (j->compare && (st == PRRU_OK) != (j->dd->status[k] == PRRU_OK)) r->changed = 1;
      j->dd->status[k] = (unsigned char)st;
      r->viol += point_violation(pr, &b, c);
      if (st == PRRU_EUNREACHABLE) continue;
      r->nreach++;
      double d[PRRU_MAX_ACT];
      for (int a = 0; a < nact; a++) {
        d[a] = b.d[a * b.n + c];
        r->dmin = fmin(r->dmin, d[a]);
        r->dmax = fmax(r->dmax, d[a]);
      }
      if (pr->stroke) r->stroke += stroke_excess(pr, d, nact) / j->L;
    }
  }
  free(f);
}

static void *grid_worker(void *arg)
{
  grid_job *j = arg;
  for (;;) {
    pthread_mutex_lock(&j->lock);
    int i = j->next_row < j->pr->grid.n1 ? j->next_row++ : -1;
    pthread_mutex_unlock(&j->lock);
    if (i < 0) return NULL;
    grid_row(j, i);
  }
}

/* Every row of the grid for p, with dd->nthreads threads (the caller one
 * of them; fewer when threads cannot be started: slower, never wrong). */
static void grid_eval(const prru_design_problem *pr, const prru_params *p, prru_design_data *dd,
                      int compare)
{
  /* The design's numbers as its topology's kernels read them: derived
   * once here, on this thread's stack (an evaluation allocates nothing). */
  const prru_topology *t = prru_topology_of(pr->model->mech->nlimb);
  prru_topo_derived dp;
  t->derive(p, &dp);
  grid_job j = {pr, t, &dp, dd, prru_design_length_scale(pr->model, p), home_mode(t, &dp, pr->grid.q3),
                compare, 0, PTHREAD_MUTEX_INITIALIZER};
  enum { MAX_THREADS = 64 };
  pthread_t tid[MAX_THREADS];
  int nt = dd->nthreads < 1 ? 1 : dd->nthreads > MAX_THREADS ? MAX_THREADS : dd->nthreads, started = 0;
  if (nt > pr->grid.n1) nt = pr->grid.n1;
  for (int i = 1; i < nt; i++) {
    if (pthread_create(&tid[started], NULL, grid_worker, &j) != 0) break;
    started++;
  }
  grid_worker(&j);
  for (int i = 0; i < started; i++) pthread_join(tid[i], NULL);
  pthread_mutex_destroy(&j.lock);
}

static double objective_of(const prru_design_problem *pr, const prru_map_summary *s)
{
  if (s->n_ok == 0) return NAN;
  return pr->objective == PRRU_OBJ_MAX ? s->w_max : pr->objective == PRRU_OBJ_LOG ? s->index_log
                                                                                  : s->index;
}

/* The merit of an invalid design: above any valid design's. */
#define INVALID_MERIT 1e30

int prru_design_evaluate(const prru_design_problem *pr, const prru_params *p,
                         prru_design_data *dd, prru_design_eval *ev)
{
  memset(ev, 0, sizeof *ev);
  ev->objective = ev->d_min = ev->d_max = NAN;
  ev->merit = INVALID_MERIT;
  if (prru_design_check(pr->model, p, NULL, 0) != PRRU_OK) return PRRU_EINPUT;
  ev->valid = 1;
  const prru_map_grid *g = &pr->grid;
  grid_eval(pr, p, dd, 0);
  double viol = 0, stroke = 0, dmin = INFINITY, dmax = -INFINITY;
  long nreach = 0;
  for (int i = 0; i < g->n1; i++) {
    const struct prru_design_row *r = &dd->rows[i];
    viol += r->viol;
    stroke += r->stroke;
    nreach += r->nreach;
    dmin = fmin(dmin, r->dmin);
    dmax = fmax(dmax, r->dmax);
  }
  prru_map_summarize(g, dd->w_R, dd->status, &ev->sum);
  ev->n_other_mode = ev->sum.n_other_mode;
  ev->objective = objective_of(pr, &ev->sum);
  ev->reg_violation = viol / (double)dd->n;
  ev->stroke_violation = nreach ? stroke / (double)nreach : 0.0;
  if (nreach) {
    ev->d_min = dmin;
    ev->d_max = dmax;
  }
  double f = isfinite(ev->objective) ? ev->objective : 0.0;
  ev->merit = f + pr->penalty_weight * (ev->reg_violation + ev->stroke_violation);
  ev->feasible = ev->sum.n_ok == ev->sum.n_points && ev->stroke_violation == 0.0;
  return PRRU_OK;
}

/* ---- Optimisation ---- */

void prru_design_options_default(prru_design_options *o)
{
  o->max_iter = 600;
  o->tol = 1e-5;
  o->restarts = 2;
  o->nthreads = 2;
  o->precision = PRRU_PRECISION_DOUBLE;
  o->progress = NULL;
  o->ctx = NULL;
}

typedef struct {
  const prru_design_problem *pr;
  const prru_params *start;
  const prru_design_var *vars;
  int nvar, evals;
  prru_design_data *dd;
  prru_params cand;
  prru_design_eval ev;
  prru_design_result *r;
} opt_ctx;

/* The box transform: every u maps inside [lo, hi]. */
static double x_of_u(const prru_design_var *v, double u)
{
  return v->lo + (v->hi - v->lo) * 0.5 * (1.0 + sin(u));
}

static double u_of_x(const prru_design_var *v, double x)
{
  double s = 2.0 * (x - v->lo) / (v->hi - v->lo) - 1.0;
  return asin(fmax(-1.0, fmin(1.0, s)));
}

static void design_at(opt_ctx *c, const gsl_vector *u, double *x)
{
  c->cand = *c->start;
  for (int i = 0; i < c->nvar; i++) {
    x[i] = x_of_u(&c->vars[i], gsl_vector_get(u, (size_t)i));
    prru_design_set(&c->cand, &c->cand, &c->vars[i], x[i]);
  }
}

/* Is a better than b: feasible before infeasible (an exact penalty puts
 * the optimum on a constraint's edge, which Nelder-Mead approaches from
 * both sides: the best merit may lie a hair outside), then lower merit;
 * ties keep b, the first found, so the run is deterministic. */
static int better(const prru_design_eval *a, const prru_design_eval *b)
{
  if (a->feasible != b->feasible) return a->feasible;
  return a->merit < b->merit;
}

/* The merit at u; keeps the best design seen. */
static double merit_at(const gsl_vector *u, void *params)
{
  opt_ctx *c = params;
  double x[PRRU_DESIGN_MAX_VARS];
  design_at(c, u, x);
  prru_design_evaluate(c->pr, &c->cand, c->dd, &c->ev);
  c->evals++;
  if (better(&c->ev, &c->r->best_eval)) {
    c->r->best = c->cand;
    c->r->best_eval = c->ev;
    memcpy(c->r->x, x, sizeof(double) * (size_t)c->nvar);
  }
  return c->ev.merit;
}

static int check_vars(const prru_params *start, const prru_design_var *vars, int nvar, char *msg,
                      int msglen)
{
  if (nvar < 1 || nvar > PRRU_DESIGN_MAX_VARS)
    return prru_fail(msg, msglen, PRRU_EINPUT, "%d design variables: 1 to %d allowed", nvar,
                     PRRU_DESIGN_MAX_VARS);
  for (int i = 0; i < nvar; i++) {
    const prru_design_var *v = &vars[i];
    double x = prru_design_get(start, v);
    if (!(isfinite(v->lo) && isfinite(v->hi) && v->lo < v->hi))
      return prru_fail(msg, msglen, PRRU_EINPUT, "%s: infeasible bounds %.17g:%.17g (need lo < hi)",
                       v->name, v->lo, v->hi);
    if (!(x >= v->lo && x <= v->hi))
      return prru_fail(msg, msglen, PRRU_EINPUT, "%s: the start value %.17g is outside its bounds "
                       "%.17g:%.17g", v->name, x, v->lo, v->hi);
    for (int j = 0; j < i; j++)
      for (int a = 0; a < v->n; a++)
        for (int b = 0; b < vars[j].n; b++)
          if (v->offset[a] == vars[j].offset[b])
            return prru_fail(msg, msglen, PRRU_EINPUT, "%s and %s: a parameter appears in both",
                             vars[j].name, v->name);
  }
  return PRRU_OK;
}

/* One Nelder-Mead run from the result's best point; PRRU_OK or
 * PRRU_EINTERRUPTED / PRRU_ENOMEM. */
static int nm_run(opt_ctx *c, const prru_design_options *o, int *iter_left)
{
  const size_t n = (size_t)c->nvar;
  gsl_multimin_fminimizer *s = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2, n);
  gsl_vector *u = gsl_vector_alloc(n), *step = gsl_vector_alloc(n);
  int rc = s && u && step ? PRRU_OK : PRRU_ENOMEM;
  if (rc == PRRU_OK) {
    for (size_t i = 0; i < n; i++) {
      double u0 = u_of_x(&c->vars[i], c->r->x[i]);
      gsl_vector_set(u, i, u0);
      /* 0.2 rad: about 10 % of a variable's range near the middle; the
       * step points into the box at a bound (where sin is flat). */
      gsl_vector_set(step, i, u0 > 1.2 ? -0.4 : 0.2);
    }
    gsl_multimin_function f = {merit_at, n, c};
    if (gsl_multimin_fminimizer_set(s, &f, u, step) != GSL_SUCCESS) rc = PRRU_ENOMEM;
  }
  int status = GSL_CONTINUE;
  while (rc == PRRU_OK && status == GSL_CONTINUE && *iter_left > 0) {
    if (gsl_multimin_fminimizer_iterate(s) != GSL_SUCCESS) break; /* cannot improve */
    (*iter_left)--;
    c->r->iterations++;
    double size = gsl_multimin_fminimizer_size(s);
    status = gsl_multimin_test_size(size, o->tol);
    if (o->progress && o->progress(c->r->iterations, c->evals, &c->r->best_eval, size, o->ctx))
      rc = PRRU_EINTERRUPTED;
  }
  c->r->converged = status == GSL_SUCCESS;
  gsl_vector_free(u);
  gsl_vector_free(step);
  gsl_multimin_fminimizer_free(s);
  return rc;
}

int prru_design_optimize(const prru_design_problem *pr, const prru_params *start,
                         const prru_design_var *vars, int nvar, const prru_design_options *o,
                         prru_design_result *r, char *msg, int msglen)
{
  prru_gsl_init();
  memset(r, 0, sizeof *r);
  int st = prru_design_problem_check(pr, msg, msglen);
  if (st == PRRU_OK) st = check_vars(start, vars, nvar, msg, msglen);
  if (st != PRRU_OK) return st;
  prru_design_data dd;
  if (prru_design_data_alloc(&dd, &pr->grid) != PRRU_OK)
    return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory for the grid");
  dd.nthreads = o->nthreads;
  dd.precision = o->precision;
  opt_ctx c = {pr, start, vars, nvar, 0, &dd, *start, {0}, r};
  r->best = *start;
  prru_design_evaluate(pr, start, &dd, &r->start_eval);
  r->best_eval = r->start_eval;
  for (int i = 0; i < nvar; i++) r->x0[i] = r->x[i] = prru_design_get(start, &vars[i]);
  int iter_left = o->max_iter;
  prru_design_eval before = r->best_eval;
  st = nm_run(&c, o, &iter_left);
  /* Restarts: a fresh simplex at the best point escapes the collapse that
   * Nelder-Mead can suffer on a constraint's edge; stop once one gains
   * nothing. */
  while (st == PRRU_OK && r->restarts_done < o->restarts && iter_left > 0 &&
         better(&r->best_eval, &before)) {
    before = r->best_eval;
    r->restarts_done++;
    st = nm_run(&c, o, &iter_left);
  }
  r->evaluations = c.evals;
  prru_design_data_free(&dd);
  if (st == PRRU_ENOMEM) return prru_fail(msg, msglen, st, "out of memory for the optimiser");
  return st;
}

/* ---- Sensitivity ---- */

/* The objective of q on the grid; with compare, sets *changed when a
 * point's regularity differs from the statuses left in dd by the previous
 * call (which this one then replaces). */
static double objective_unchecked(const prru_design_problem *pr, const prru_params *q,
                                  prru_design_data *dd, int compare, int *changed)
{
  const prru_map_grid *g = &pr->grid;
  grid_eval(pr, q, dd, compare);
  for (int i = 0; i < g->n1; i++)
    if (dd->rows[i].changed) *changed = 1;
  prru_map_summary sum;
  prru_map_summarize(g, dd->w_R, dd->status, &sum);
  return objective_of(pr, &sum);
}

/* The step must be at least STEP_ROUNDING DBL_EPSILON M, M the largest
 * magnitude the perturbed sums involve: every tied parameter's value and
 * the variable's scale (an armature at 0 is added to the slider's mass,
 * of that scale). A rounding to doubles near M errs by at most
 * DBL_EPSILON M / 2; the step actually taken, (x_k + h) - (x_k - h),
 * passes through four (the ends, and the shift prru_design_set forms for
 * a tied parameter), so it is off 2 h by at most 2 DBL_EPSILON M: at most
 * 1 % when h >= 100 DBL_EPSILON M. Below, the difference quotient
 * measures rounding, and a step far below (1e-300) is lost entirely:
 * every derivative exactly 0. */
#define STEP_ROUNDING 100.0

int prru_design_step_check(const prru_model *m, const prru_params *p, const prru_design_var *v,
                           double rel_step, char *msg, int msglen)
{
  if (!(rel_step > 0 && rel_step < 0.5))
    return prru_fail(msg, msglen, PRRU_EINPUT, "step %.17g: must be in (0, 0.5)", rel_step);
  double scale = prru_design_scale(m, p, v), big = scale;
  for (int k = 0; k < v->n; k++) {
    prru_design_var one = member(v, k);
    big = fmax(big, fabs(prru_design_get(p, &one)));
  }
  double h_min = STEP_ROUNDING * DBL_EPSILON * big;
  if (!(rel_step * scale >= h_min))
    return prru_fail(msg, msglen, PRRU_EINPUT,
                     "%s: the step %.3g would be lost to rounding next to the magnitude %.3g; the "
                     "smallest relative step is %.3g (100 x 2.2e-16 x magnitude / scale)",
                     v->name, rel_step * scale, big, h_min / scale);
  return PRRU_OK;
}

int prru_design_sensitivity(const prru_design_problem *pr, const prru_params *p,
                            const prru_design_var *v, double rel_step, prru_design_data *dd,
                            prru_design_sens *s)
{
  memset(s, 0, sizeof *s);
  const prru_model *m = pr->model;
  if (prru_design_check(m, p, NULL, 0) != PRRU_OK ||
      prru_design_step_check(m, p, v, rel_step, NULL, 0) != PRRU_OK)
    return PRRU_EINPUT;
  s->value = prru_design_get(p, v);
  s->scale = prru_design_scale(m, p, v);
  s->step = rel_step * s->scale;
  /* Without the validity check: the difference may reach past a
   * parameter's limit (an armature of 0). */
  prru_params q = *p;
  prru_design_set(&q, p, v, s->value + s->step);
  s->f_plus = objective_unchecked(pr, &q, dd, 0, &s->set_changed);
  prru_design_set(&q, p, v, s->value - s->step);
  s->f_minus = objective_unchecked(pr, &q, dd, 1, &s->set_changed);
  if (!isfinite(s->f_plus) || !isfinite(s->f_minus)) return PRRU_ESINGULAR;
  s->derivative = (s->f_plus - s->f_minus) / (2.0 * s->step);
  return PRRU_OK;
}
