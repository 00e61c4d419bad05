/* Model files written from a model's numbers (prru_model_file_text,
 * prru_control.h): what identify and optimize hand back to the user, in
 * the format the loader and the generator read (format 2, spec 11-13). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "prru_control.h"
#include "prru_model_file.h"

typedef struct {
  char *s;
  size_t len, cap;
  int oom;
} text_buf;

static void put(text_buf *b, const char *fmt, ...)
{
  if (b->oom) return;
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    const int n = vsnprintf(b->s ? b->s + b->len : NULL, b->s ? b->cap - b->len : 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
      b->oom = 1;
      return;
    }
    if (b->s && b->len + (size_t)n < b->cap) {
      b->len += (size_t)n;
      return;
    }
    size_t cap = b->cap ? 2 * b->cap : 4096;
    while (cap <= b->len + (size_t)n) cap *= 2;
    char *s = realloc(b->s, cap);
    if (!s) {
      b->oom = 1;
      return;
    }
    b->s = s, b->cap = cap;
  }
}

/* Magnitudes below 1e-9 as 0: model files hold none (the loader refuses
 * them as typing errors). */
static double file_number(double v) { return fabs(v) < 1e-9 ? 0.0 : v; }

static void put_list(text_buf *b, const double *v, int n)
{
  put(b, "[");
  for (int i = 0; i < n; i++) put(b, "%s%.17g", i ? ", " : "", file_number(v[i]));
  put(b, "]");
}

/* A JSON string of text (prru_json_char's escapes). */
static void put_string(text_buf *b, const char *text)
{
  put(b, "\"");
  for (const char *s = text; *s;) {
    char c[8];
    size_t used;
    put(b, "%.*s", (int)prru_json_char(s, c, &used), c);
    s += used;
  }
  put(b, "\"");
}

/* ",\n    \"key\": " then one number when every actuator has it, else the list. */
static void drive_key(text_buf *b, int na, const char *key, const double *v)
{
  int same = 1;
  for (int i = 1; i < na; i++) same &= v[i] == v[0];
  put(b, ",\n    \"%s\": ", key);
  if (same)
    put(b, "%.17g", file_number(v[0]));
  else
    put_list(b, v, na);
}

/* The drive keys of spec 13 the model's file gave, kept as they were; a
 * changed armature goes back into rotor_inertia where the file gave that. */
static void drive_keys(text_buf *b, const prru_model *m, const double armature[])
{
  const prru_mechanism *me = m->mech;
  const unsigned k = me->drive_keys;
  const int na = me->nact;
  if (k & PRRU_DRIVE_LEAD) drive_key(b, na, "lead", me->lead);
  if (k & PRRU_DRIVE_GEAR) drive_key(b, na, "gear", me->gear);
  if (k & PRRU_DRIVE_ROTOR_INERTIA) {
    double J[PRRU_MAX_ACT];
    for (int i = 0; i < na; i++) {
      const double w = prru_model_drive_ratio(m, i);
      J[i] = armature[i] == me->armature[i] ? me->rotor_inertia[i] : armature[i] / (w * w);
    }
    drive_key(b, na, "rotor_inertia", J);
  }
  if (k & PRRU_DRIVE_TORQUE_CONSTANT) drive_key(b, na, "torque_constant", me->torque_constant);
  if (k & PRRU_DRIVE_STROKE) {
    int same = 1;
    for (int i = 1; i < na; i++) same &= me->d_min[i] == me->d_min[0] && me->d_max[i] == me->d_max[0];
    put(b, ",\n    \"stroke\": %s", same ? "" : "[");
    for (int i = 0; i < (same ? 1 : na); i++)
      put(b, "%s[%.17g, %.17g]", i ? ", " : "", file_number(me->d_min[i]), file_number(me->d_max[i]));
    if (!same) put(b, "]");
  }
  if (k & PRRU_DRIVE_FORCE_MAX) drive_key(b, na, "force_max", me->force_max);
  if (k & PRRU_DRIVE_TORQUE_MAX) drive_key(b, na, "torque_max", me->torque_max);
  if (k & PRRU_DRIVE_SPEED_MAX) drive_key(b, na, "speed_max", me->speed_max);
  if (k & PRRU_DRIVE_MOTOR_SPEED_MAX) drive_key(b, na, "motor_speed_max", me->motor_speed_max);
}

int prru_model_name_valid(const char *s)
{
  size_t n = s ? strlen(s) : 0;
  if (n == 0 || n > PRRU_MODEL_NAME_MAX || !(s[0] >= 'a' && s[0] <= 'z')) return 0;
  for (size_t i = 1; i < n; i++)
    if (!((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= '0' && s[i] <= '9') || s[i] == '_')) return 0;
  return 1;
}

void prru_model_name_derive(const char *base, const char *suffix, char *out)
{
  const int keep = PRRU_MODEL_NAME_MAX - (int)strlen(suffix);
  snprintf(out, PRRU_MODEL_NAME_MAX + 1, "%.*s%s", keep > 0 ? keep : 0, base, suffix);
}

static void model_json(text_buf *b, const prru_model *m, const prru_params *p, const char *name,
                       const char *description)
{
  char desc[PRRU_DESCRIPTION_SIZE];
  put(b, "{\n  \"format\": 2,\n  \"name\": \"%s\",\n  \"description\": ", name);
  put_string(b, prru_description(desc, sizeof desc, description ? description : ""));
  put(b, ",\n  \"gravity\": ");
  put_list(b, p->gravity, 3);
  put(b, ",\n  \"geometry\": {\n    \"b\": ");
  put_list(b, p->b, m->mech->nlimb);
  put(b, ",\n    \"l1\": ");
  put_list(b, p->l1, m->mech->nlimb);
  put(b, ",\n    \"l2\": ");
  put_list(b, p->l2, m->mech->nlimb);
  put(b, ",\n    \"a\": ");
  put_list(b, p->a, 2);
  put(b, "\n  },\n  \"bodies\": {\n");
  for (int k = 0; k < m->mech->nbody; k++) {
    put(b, "    \"%s\": {\"mass\": %.17g, \"com\": ", m->mech->body_names[k], file_number(p->mass[k]));
    put_list(b, p->com[k], 3);
    put(b, ",\n      \"inertia\": ");
    put_list(b, p->inertia[k], 6);
    put(b, "}%s\n", k + 1 < m->mech->nbody ? "," : "");
  }
  put(b, "  },\n  \"actuators\": {\n    ");
  /* Where the file gave rotor_inertia, the armature goes back there. */
  if (!(m->mech->drive_keys & PRRU_DRIVE_ROTOR_INERTIA)) {
    put(b, "\"armature\": ");
    put_list(b, p->armature, m->mech->nact);
    put(b, ",\n    ");
  }
  put(b, "\"damping\": ");
  put_list(b, p->damping, m->mech->nact);
  put(b, ",\n    \"coulomb\": ");
  put_list(b, p->coulomb, m->mech->nact);
  put(b, ",\n    \"coulomb_velocity\": %.17g", p->coulomb_velocity);
  drive_keys(b, m, p->armature);
  put(b, "\n  }\n}\n");
}

int prru_model_file_text(const prru_model *m, const prru_params *p, const char *name, const char *description,
                         char **text, char *msg, int msglen)
{
  *text = NULL;
  if (!prru_model_name_valid(name))
    return prru_fail(msg, msglen, PRRU_EINPUT, "model name '%s' is not [a-z][a-z0-9_]{0,15}", name ? name : "");
  text_buf b = {NULL, 0, 0, 0};
  model_json(&b, m, p, name, description);
  prru_model_spec *spec = b.oom ? NULL : malloc(sizeof *spec);
  if (!spec) {
    free(b.s);
    return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  }
  /* Read back by the loader before anyone writes it: never a model file
   * nothing can load. */
  char why[700];
  int st = prru_model_file_parse(b.s, b.len, name, spec, why, sizeof why);
  free(spec);
  if (st != PRRU_OK) {
    free(b.s);
    return prru_fail(msg, msglen, st == PRRU_ENOMEM ? st : PRRU_EINPUT, "the model's numbers do not make a "
                     "valid model file: %s", why);
  }
  *text = b.s;
  return PRRU_OK;
}
