/* Models as run-time data (prru.h): prru_model_load reads a model file
 * into a descriptor of its own and picks the kernels that evaluate it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "prru.h"
#include "prru_ident.h"
#include "prru_control.h"
#include "prru_model_file.h"

/* A loaded model's storage (prru_model.own). */
typedef struct {
  prru_mechanism mech;
  /* Its topology, its numbers as that topology's parameter kernels read
   * them, and as their simple variant reads them where it applies (NULL
   * if not asked for). */
  const prru_topology *topo;
  prru_topo_derived derived;
  prru_topo_simple *simple;
  char name[PRRU_MODEL_NAME_MAX + 1];
  char description[4 * PRRU_MODEL_DESCRIPTION_MAX + 1];
  char sha256[65];
  char *path;
} loaded_model;

/* Every entry from i on without a limit: a model's entries past its
 * actuators are none, whatever the struct held. */
static void limits_none_from(prru_limits *l, int i)
{
  for (; i < PRRU_MAX_ACT; i++) {
    l->force_max[i] = l->speed_max[i] = l->d_max[i] = INFINITY;
    l->d_min[i] = -INFINITY;
  }
}

void prru_limits_none(prru_limits *l) { limits_none_from(l, 0); }

void prru_model_limits(const prru_model *m, prru_limits *out)
{
  const prru_mechanism *me = m->mech;
  limits_none_from(out, me->nact);
  for (int i = 0; i < me->nact; i++) {
    out->force_max[i] = me->force_max[i], out->speed_max[i] = me->speed_max[i];
    out->d_min[i] = me->d_min[i], out->d_max[i] = me->d_max[i];
  }
}

double prru_model_drive_ratio(const prru_model *m, int i)
{
  if (i < 0 || i >= m->mech->nact || !(m->mech->lead[i] > 0)) return NAN;
  return prru_drive_ratio(m->mech->lead[i], m->mech->gear[i]);
}

int prru_model_has_lead(const prru_model *m)
{
  for (int i = 0; i < m->mech->nact; i++)
    if (!(m->mech->lead[i] > 0)) return 0;
  return 1;
}

int prru_model_motor_units(const prru_model *m, const double f[], double tau[],
                           double current[])
{
  const prru_mechanism *me = m->mech;
  if (!prru_model_has_lead(m)) return PRRU_EINPUT;
  for (int i = 0; i < me->nact; i++) {
    /* tau_m = f lead / (2 pi gear): the drive's ideal transmission */
    double t = f[i] / prru_drive_ratio(me->lead[i], me->gear[i]);
    if (tau) tau[i] = t;
    if (current) current[i] = me->torque_constant[i] > 0 ? t / me->torque_constant[i] : NAN;
  }
  return PRRU_OK;
}

/* text as one positive value for each of na actuators or one each. */
static int limit_values(int na, const char *name, const char *text, double v[], char *msg, int msglen)
{
  if (!strchr(text, ',')) {
    if (prru_parse_double(text, &v[0]) != PRRU_OK || !(v[0] > 0))
      return prru_fail(msg, msglen, PRRU_EINPUT, "--%s: '%s' is not a positive number", name, text);
    for (int i = 1; i < na; i++) v[i] = v[0];
    return PRRU_OK;
  }
  if (prru_parse_list(text, v, na) != PRRU_OK)
    return prru_fail(msg, msglen, PRRU_EINPUT, "--%s: '%s' is not one number or %d comma-separated numbers",
                     name, text, na);
  for (int i = 0; i < na; i++)
    if (!(v[i] > 0))
      return prru_fail(msg, msglen, PRRU_EINPUT, "--%s: the limit of actuator %d must be positive", name, i + 1);
  return PRRU_OK;
}

/* "LO,HI" / "LO:HI" for every slider or LO,HI per slider. */
static int stroke_values(int na, const char *text, double lo[], double hi[], char *msg, int msglen)
{
  char buf[512];
  double v[2 * PRRU_MAX_ACT];
  int n = 1;
  if (strlen(text) >= sizeof buf) return prru_fail(msg, msglen, PRRU_EINPUT, "--stroke: too long");
  strcpy(buf, text);
  char *colon = strchr(buf, ':');
  if (colon && !strchr(buf, ',') && !strchr(colon + 1, ':')) *colon = ',';
  for (const char *c = buf; *c; c++) n += *c == ',';
  if ((n != 2 && n != 2 * na) || prru_parse_list(buf, v, n) != PRRU_OK)
    return prru_fail(msg, msglen, PRRU_EINPUT, "--stroke: '%s': give LO,HI for all sliders or %d numbers "
                     "(LO,HI per slider)", text, 2 * na);
  for (int i = 0; i < na; i++) {
    const double a = v[n == 2 ? 0 : 2 * i], b = v[n == 2 ? 1 : 2 * i + 1];
    if (!(a < b))
      return prru_fail(msg, msglen, PRRU_EINPUT, "--stroke: slider %d's range [%g, %g] is empty (LO must be "
                       "below HI)", i + 1, a, b);
    lo[i] = a, hi[i] = b;
  }
  return PRRU_OK;
}

int prru_limits_for_run(const prru_model *m, const prru_limit_args *a, prru_limits *out, char *msg, int msglen)
{
  prru_limits l;
  if (msg && msglen > 0) msg[0] = 0;
  if (a && a->none) prru_limits_none(&l);
  else prru_model_limits(m, &l);
  int st = PRRU_OK;
  const int na = m->mech->nact;
  if (a && a->force_max) st = limit_values(na, "force-max", a->force_max, l.force_max, msg, msglen);
  if (!st && a && a->speed_max) st = limit_values(na, "speed-max", a->speed_max, l.speed_max, msg, msglen);
  if (!st && a && a->stroke) st = stroke_values(na, a->stroke, l.d_min, l.d_max, msg, msglen);
  if (!st) *out = l;
  return st;
}

/* One kind of limit: "none", "X UNIT" or "X1,..,XN UNIT". */
static void describe_kind(int na, char *buf, size_t len, const char *name, const double *v, const char *unit)
{
  int same = 1, any = 0;
  for (int i = 0; i < na; i++) same &= v[i] == v[0], any |= isfinite(v[i]);
  size_t n = strlen(buf);
  if (!any) {
    snprintf(buf + n, len - n, "%s none", name);
    return;
  }
  n += (size_t)snprintf(buf + n, len - n, "%s ", name);
  for (int i = 0; i < (same ? 1 : na) && n < len; i++)
    n += (size_t)snprintf(buf + n, len - n, "%s%.9g", i ? "," : "", v[i]);
  if (n < len) snprintf(buf + n, len - n, " %s", unit);
}

void prru_limits_describe(const prru_model *m, const prru_limits *l, char *buf, size_t len)
{
  if (len == 0) return;
  const int na = m->mech->nact;
  buf[0] = 0;
  describe_kind(na, buf, len, "force_max", l->force_max, "N");
  strncat(buf, ", ", len - strlen(buf) - 1);
  describe_kind(na, buf, len, "speed_max", l->speed_max, "m/s");
  strncat(buf, ", ", len - strlen(buf) - 1);
  int same = 1, any = 0;
  for (int i = 0; i < na; i++)
    same &= l->d_min[i] == l->d_min[0] && l->d_max[i] == l->d_max[0],
        any |= isfinite(l->d_min[i]) || isfinite(l->d_max[i]);
  size_t n = strlen(buf);
  if (!any) {
    snprintf(buf + n, len - n, "stroke none");
    return;
  }
  n += (size_t)snprintf(buf + n, len - n, "stroke");
  for (int i = 0; i < (same ? 1 : na) && n < len; i++)
    n += (size_t)snprintf(buf + n, len - n, "%s[%.9g, %.9g]", i ? ", " : " ", l->d_min[i], l->d_max[i]);
  if (n < len) snprintf(buf + n, len - n, " m");
}

int prru_model_with_limits(prru_model *out, const prru_model *src, const prru_limits *l)
{
  const loaded_model *s = src->own;
  loaded_model *c = calloc(1, sizeof *c);
  const char *file = s ? s->path : src->mech->model_file;
  char *p = malloc(strlen(file) + 1);
  if (!c || !p) {
    free(c), free(p);
    return PRRU_ENOMEM;
  }
  strcpy(p, file);
  if (s) {
    *c = *s;
    c->mech.name = c->name, c->mech.description = c->description, c->mech.sha256 = c->sha256;
    c->simple = NULL;
    if (s->simple && !(c->simple = malloc(sizeof *c->simple))) {
      free(c), free(p);
      return PRRU_ENOMEM;
    }
    if (s->simple) *c->simple = *s->simple;
  } else {
    c->mech = *src->mech;
  }
  c->path = p;
  c->mech.model_file = p;
  for (int i = 0; i < c->mech.nact; i++) {
    c->mech.force_max[i] = l->force_max[i], c->mech.speed_max[i] = l->speed_max[i];
    c->mech.d_min[i] = l->d_min[i], c->mech.d_max[i] = l->d_max[i];
  }
  *out = *src;
  out->mech = &c->mech;
  out->own = c;
  if (src->kernel_params)
    out->kernel_params = src->kernels == s->topo->simple ? (void *)c->simple : (void *)&c->derived;
  return PRRU_OK;
}

void prru_model_default(prru_model *m)
{
  m->mech = &prru_mech;
  m->jd_rcond_min = 1e-8;
  m->mass_rcond_min = 1e-6;
  m->kernels = &prru_kernels_specialised;
  m->kernel_params = NULL;
  m->own = NULL;
}

void prru_model_free(prru_model *m)
{
  loaded_model *l = m->own;
  if (l) free(l->path), free(l->simple);
  free(l);
  prru_model_default(m);
}

/* The inverse of a symmetric positive definite 3 x 3 (the inertia
 * tensors the loader accepted). */
static void inverse3(const double a[9], double inv[9])
{
  const double c0 = a[4] * a[8] - a[5] * a[7], c1 = a[2] * a[7] - a[1] * a[8], c2 = a[1] * a[5] - a[2] * a[4];
  const double det = a[0] * c0 + a[3] * c1 + a[6] * c2;
  const double c[9] = {c0, c1, c2, a[5] * a[6] - a[3] * a[8], a[0] * a[8] - a[2] * a[6], a[2] * a[3] - a[0] * a[5],
                       a[3] * a[7] - a[4] * a[6], a[1] * a[6] - a[0] * a[7], a[0] * a[4] - a[1] * a[3]};
  for (int i = 0; i < 9; i++) inv[i] = c[i] / det;
}

/* The spec's numbers into a descriptor of l's topology (names, joints
 * and layout are the topology's). */
static void fill_mechanism(const prru_model_spec *s, loaded_model *l)
{
  prru_mechanism *me = &l->mech;
  memset(me, 0, sizeof *me);
  prru_topology_layout(l->topo, me);
  memcpy(l->name, s->name, sizeof l->name);
  memcpy(l->description, s->description, sizeof l->description);
  memcpy(l->sha256, s->sha256, sizeof l->sha256);
  me->name = l->name;
  me->description = l->description;
  me->model_file = l->path;
  me->sha256 = l->sha256;
  me->format = s->format;
  memcpy(me->gravity, s->gravity, sizeof me->gravity);
  me->total_mass = 0;
  for (int b = 0; b < me->nbody; b++) {
    const double *I = s->inertia[b];
    const double T[9] = {I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2]};
    me->mass[b] = s->mass[b];
    me->total_mass += s->mass[b];
    memcpy(me->com[b], s->com[b], sizeof me->com[b]);
    memcpy(me->inertia[b], T, sizeof T);
    inverse3(T, me->inertia_inv[b]);
  }
  for (int i = 0; i < me->nlimb; i++) {
    me->b[i] = s->limb[i].b, me->l1[i] = s->limb[i].l1;
    me->l2[i] = s->limb[i].l2, me->a[i] = s->limb[i].a;
    me->armature[i] = s->armature[i];
    me->damping[i] = s->damping[i];
    me->coulomb[i] = s->coulomb[i];
  }
  me->coulomb_velocity = s->coulomb_velocity;
  for (int i = 0; i < me->nact; i++) {
    me->lead[i] = s->lead[i], me->gear[i] = s->gear[i];
    me->torque_constant[i] = s->torque_constant[i];
    me->force_max[i] = s->force_max[i], me->speed_max[i] = s->speed_max[i];
    me->d_min[i] = s->d_min[i], me->d_max[i] = s->d_max[i];
    me->rotor_inertia[i] = s->rotor_inertia[i], me->torque_max[i] = s->torque_max[i];
    me->motor_speed_max[i] = s->motor_speed_max[i];
  }
  me->drive_keys = s->keys;
}

void prru_model_params(const prru_model *m, prru_params *p)
{
  const prru_mechanism *me = m->mech;
  memset(p, 0, sizeof *p); /* the entries past the model's sizes: 0, every time */
  for (int i = 0; i < me->nlimb; i++) {
    p->b[i] = me->b[i], p->l1[i] = me->l1[i], p->l2[i] = me->l2[i], p->a[i] = me->a[i];
    p->armature[i] = me->armature[i], p->damping[i] = me->damping[i], p->coulomb[i] = me->coulomb[i];
  }
  memcpy(p->gravity, me->gravity, sizeof p->gravity);
  for (int b = 0; b < me->nbody; b++) {
    const double *T = me->inertia[b];
    const double I[6] = {T[0], T[4], T[8], T[1], T[2], T[5]};
    p->mass[b] = me->mass[b];
    memcpy(p->com[b], me->com[b], sizeof p->com[b]);
    memcpy(p->inertia[b], I, sizeof I);
  }
  /* The parameter kernels divide by v_s even where no Coulomb force acts
   * (prru_params_model likewise holds 1 m/s there). */
  p->coulomb_velocity = me->coulomb_velocity > 0 ? me->coulomb_velocity : 1.0;
}

static int same(const double *a, const double *b, int n)
{
  for (int i = 0; i < n; i++)
    if (a[i] != b[i]) return 0;
  return 1;
}

int prru_model_is_built(const prru_model *m, int only_geometry)
{
  /* The one comparison with the build's own model: its specialised
   * kernels apply to no other. */
  const prru_mechanism *a = m->mech, *b = &prru_mech;
  if (a == b) return 1;
  if (a->nlimb != b->nlimb) return 0;
  const int nl = b->nlimb, na = b->nact;
  int ok = same(a->gravity, b->gravity, 3) && same(a->b, b->b, nl) && same(a->l1, b->l1, nl) &&
           same(a->l2, b->l2, nl) && same(a->a, b->a, nl);
  if (!ok || only_geometry) return ok;
  for (int k = 0; k < b->nbody && ok; k++)
    ok = a->mass[k] == b->mass[k] && same(a->com[k], b->com[k], 3) && same(a->inertia[k], b->inertia[k], 9);
  return ok && same(a->armature, b->armature, na) && same(a->damping, b->damping, na) &&
         same(a->coulomb, b->coulomb, na) && a->coulomb_velocity == b->coulomb_velocity;
}

int prru_model_load(prru_model *m, const char *path, char *msg, int msglen)
{
  if (msg && msglen > 0) msg[0] = 0;
  prru_model_spec *s = malloc(sizeof *s);
  loaded_model *l = calloc(1, sizeof *l);
  char *p = path ? malloc(strlen(path) + 1) : NULL;
  if (!s || !l || !p) {
    free(s), free(l), free(p);
    if (msg && msglen > 0) snprintf(msg, (size_t)msglen, "%s: out of memory", path ? path : "(null)");
    return PRRU_ENOMEM;
  }
  strcpy(p, path);
  int st = prru_model_file_read(path, s, msg, msglen);
  /* Every topology a valid file can have is in every build (the reader
   * accepts 3 or 4 limbs): the test guards the two against drifting. */
  if (st == PRRU_OK && !prru_topology_of(s->nlimb)) {
    snprintf(msg, (size_t)msglen, "%s: a model with %d limbs: this library evaluates 3 or 4", path, s->nlimb);
    st = PRRU_EINPUT;
  }
  if (st != PRRU_OK) {
    free(s), free(l), free(p);
    return st;
  }
  l->path = p;
  l->topo = prru_topology_of(s->nlimb);
  fill_mechanism(s, l);
  free(s);
  prru_model tmp;
  prru_model_default(&tmp);
  tmp.mech = &l->mech;
  tmp.own = l;
  prru_params numbers;
  prru_model_params(&tmp, &numbers);
  l->topo->derive(&numbers, &l->derived);
  if (!prru_model_is_built(&tmp, 0) && (st = prru_model_use_parameter_kernels(&tmp)) != PRRU_OK) {
    free(l->path), free(l);
    if (msg && msglen > 0) snprintf(msg, (size_t)msglen, "%s: out of memory", path);
    return st;
  }
  /* Settings kept from m only where it was a model already: a fresh
   * struct is defaults. */
  *m = tmp;
  return PRRU_OK;
}

int prru_model_use_general_kernels(prru_model *m)
{
  loaded_model *l = m->own;
  if (!l) return PRRU_EINPUT;
  m->kernels = l->topo->general;
  m->kernel_params = &l->derived;
  return PRRU_OK;
}

int prru_model_use_parameter_kernels(prru_model *m)
{
  loaded_model *l = m->own;
  if (!l) return PRRU_EINPUT;
  if (!l->topo->structure_simple(&l->derived)) return prru_model_use_general_kernels(m);
  if (!l->simple && !(l->simple = malloc(sizeof *l->simple))) return PRRU_ENOMEM;
  l->topo->simple_derive(&l->derived, l->simple);
  m->kernels = l->topo->simple;
  m->kernel_params = l->simple;
  return PRRU_OK;
}

void prru_model_ik_jd(const prru_model *m, const double q[3], double d[], double Jd[])
{
  KERNEL(m, ik_jd)(m->kernel_params, q, d, Jd);
}

void prru_model_dynamics(const prru_model *m, const double q[3], const double qd[3], double M[9], double h[3],
                         double G[3])
{
  KERNEL(m, dynamics)(m->kernel_params, q, qd, M, h, G);
}

void prru_model_passive(const prru_model *m, const double q[3], const double qd[3], double Qp[3])
{
  KERNEL(m, passive)(m->kernel_params, q, qd, Qp);
}

void prru_model_regressor(const prru_model *m, const double q[3], const double qd[3], const double qdd[3], double vs,
                          double *Y)
{
  KERNEL(m, regressor)(m->kernel_params, q, qd, qdd, vs, Y);
}

void prru_model_platform_jacobian(const prru_model *m, const double q[3], double JP[18])
{
  KERNEL(m, platform_jacobian)(m->kernel_params, q, JP);
}

void prru_model_poses(const prru_model *m, const double q[3], double R[], double pos[])
{
  KERNEL(m, poses)(m->kernel_params, q, R, pos);
}

void prru_body_origin(const prru_model *m, const double R[], const double pos[], int b,
                      double o[3])
{
  const double *Rb = R + 9 * b, *cb = m->mech->com[b];
  for (int c = 0; c < 3; c++) o[c] = pos[3 * b + c] - (Rb[3 * c] * cb[0] + Rb[3 * c + 1] * cb[1] + Rb[3 * c + 2] * cb[2]);
}

void prru_limb_joints(const prru_model *m, const double R[], const double pos[], int i,
                      double A[3], double B[3], double C[3])
{
  double u[3], l[3];
  prru_body_origin(m, R, pos, m->mech->slider[i], A);
  prru_body_origin(m, R, pos, m->mech->upper[i], u);
  prru_body_origin(m, R, pos, m->mech->lower[i], l);
  for (int c = 0; c < 3; c++) {
    B[c] = 2.0 * u[c] - A[c];
    C[c] = 2.0 * l[c] - B[c];
  }
}

void prru_model_actuator_rates(const prru_model *m, const double q[3], const double qd[3], double dd[],
                               double ddb[])
{
  KERNEL(m, actuator_rates)(m->kernel_params, q, qd, dd, ddb);
}

void prru_power(const prru_model *m, const double q[3], const double qd[3], const prru_loads *l,
                double *load_power, double *passive_power)
{
  double act[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3], JP[18], Qp[3], power = 0, passive = 0;
  KERNEL(m, ik_jd)(m->kernel_params, q, act, Jd);
  KERNEL(m, platform_jacobian)(m->kernel_params, q, JP);
  KERNEL(m, passive)(m->kernel_params, q, qd, Qp);
  for (int i = 0; i < m->mech->nact; i++) {
    double dd = 0;
    for (int k = 0; k < 3; k++) dd += Jd[3 * i + k] * qd[k];
    power += l->fd[i] * dd;
  }
  /* JP: rows 0-2 J_R,P, rows 3-5 J_T,O'. */
  for (int i = 0; i < 3; i++) {
    double w = 0, v = 0;
    for (int k = 0; k < 3; k++) {
      w += JP[3 * i + k] * qd[k];
      v += JP[3 * (3 + i) + k] * qd[k];
    }
    power += l->fp[i] * v + l->mp[i] * w;
  }
  for (int k = 0; k < 3; k++) passive += Qp[k] * qd[k];
  if (load_power) *load_power = power;
  if (passive_power) *passive_power = passive;
}

void prru_model_identity(const prru_model *m, char *buf, size_t len)
{
  if (len == 0) return;
  snprintf(buf, len, "model %s (%s, sha256 %s, %s kernels)", m->mech->name, m->mech->model_file, m->mech->sha256,
           m->kernels->path);
}
