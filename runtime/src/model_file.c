/* The model file read in C: the rules, the messages and the numbers of the
 * generator (gen/prrugen/model.py), function for function (each validating
 * function below names its Python peer).
 *
 * JSON by jansson: it refuses duplicate keys (JSON_REJECT_DUPLICATES), is
 * strict RFC 8259 (no NaN/Infinity tokens), reports a real overflow (1e999)
 * as an error rather than an infinity, tells integers from reals, and is
 * maintained in Debian. What the generator decides differently is decided
 * here before or after jansson: the number tokens are scanned from the text
 * first (their exact decimal value decides range and every inequality, as
 * the generator's Fractions do), out-of-range ones are blanked to 0 so that
 * jansson never sees them and the message can name their key, and jansson's
 * own refusals (NaN, duplicates, surrogates) are reworded as the generator
 * words them.
 *
 * Exactness: the generator decides inertia definiteness, the triangle
 * inequalities and the assembly at q = 0 in exact rational arithmetic. So
 * does this file, in fixed-width integers: a number has at most MAX_DIGITS
 * significant digits and lies in [1e-9, 1e6] (or is 0) once checked, so
 * value * 10^SCALE is an integer below 10^56 and every determinant below
 * 2^560, inside the BIG_WORDS * 32 bits of struct big. No double comparison
 * decides a boundary case. */
#include "prru_model_file.h"

#include <errno.h>
#include <jansson.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "sha256.h"

enum {
  MAX_DIGITS = 40, /* model.MAX_DIGITS */
  MAX_DEPTH = 32,  /* model.MAX_DEPTH */
  MAX_EXP_DIGITS = 9,
  SCALE = 49,      /* >= 9 + MAX_DIGITS - 1: makes every checked value whole */
  BIG_WORDS = 24
};

enum { NUM_OK, NUM_RANGE, NUM_PRECISE };

typedef struct {
  const char *text; /* the token in the caller's text */
  size_t len;
  int kind, zero, neg;
  long exp10;        /* of the last significant digit */
  size_t first, sig; /* significant digits: offset in digits(), count */
  json_t *node;
} num;

typedef struct {
  const char *path;
  char *msg;
  int msglen;
  num *nums;
  size_t nnum;
} ctx;

typedef struct { uint32_t w[BIG_WORDS]; } big; /* two's complement */

/* ---- messages ------------------------------------------------------- */

static prru_status fail(ctx *c, const char *key, const char *fmt, ...)
{
  char reason[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(reason, sizeof reason, fmt, ap);
  va_end(ap);
  if (c->msg && c->msglen > 0) {
    if (key && *key)
      snprintf(c->msg, (size_t)c->msglen, "%s: %s: %s", c->path, key, reason);
    else
      snprintf(c->msg, (size_t)c->msglen, "%s: %s", c->path, reason);
  }
  return PRRU_EPARSE;
}

/* Locale-independent decimal text to the nearest double (jansson reads
 * with '.' whatever LC_NUMERIC says). */
static double decimal_value(const char *s)
{
  json_t *j = json_loadb(s, strlen(s), JSON_DECODE_ANY | JSON_DECODE_INT_AS_REAL, NULL);
  double v = j ? json_real_value(j) : 0.0;
  json_decref(j);
  return v;
}

/* Python's repr(float): the shortest digits that read back, fixed notation
 * for decimal exponents -4 <= e < 16, else d.ddde+XX. */
static void py_repr(double x, char out[40])
{
  char buf[48], digits[24], trial[48];
  int p, nd = 0, e = 0, decpt, i, n = 0;
  const char *s;
  if (x == 0) {
    strcpy(out, x < 0 || 1 / x < 0 ? "-0.0" : "0.0");
    return;
  }
  for (p = 1; p <= 17; p++) {
    snprintf(buf, sizeof buf, "%.*e", p - 1, x);
    nd = 0;
    for (s = buf; *s && *s != 'e'; s++)
      if (*s >= '0' && *s <= '9')
        digits[nd++] = *s;
    digits[nd] = '\0';
    e = atoi(s + 1);
    snprintf(trial, sizeof trial, "%s%c.%se%d", x < 0 ? "-" : "", digits[0],
             nd > 1 ? digits + 1 : "0", e);
    if (decimal_value(trial) == x)
      break;
  }
  while (nd > 1 && digits[nd - 1] == '0')
    digits[--nd] = '\0';
  decpt = e + 1;
  if (x < 0)
    out[n++] = '-';
  if (decpt <= -4 || decpt > 16) {
    out[n++] = digits[0];
    if (nd > 1)
      n += sprintf(out + n, ".%s", digits + 1);
    sprintf(out + n, "e%c%02d", e < 0 ? '-' : '+', e < 0 ? -e : e);
  } else if (decpt <= 0) {
    n += sprintf(out + n, "0.");
    for (i = 0; i < -decpt; i++)
      out[n++] = '0';
    strcpy(out + n, digits);
  } else if (decpt >= nd) {
    n += sprintf(out + n, "%s", digits);
    for (i = 0; i < decpt - nd; i++)
      out[n++] = '0';
    strcpy(out + n, ".0");
  } else {
    memcpy(out + n, digits, (size_t)decpt);
    n += decpt;
    sprintf(out + n, ".%s", digits + decpt);
  }
}

/* One code point of valid UTF-8 (jansson's strings, the checked file). */
static uint32_t utf8_next(const unsigned char **p)
{
  const unsigned char *s = *p;
  uint32_t c = s[0];
  int n = c < 0x80 ? 0 : c < 0xe0 ? 1 : c < 0xf0 ? 2 : 3, i;
  if (n)
    c &= 0x3f >> n;
  for (i = 1; i <= n; i++)
    c = c << 6 | (s[i] & 0x3f);
  *p = s + n + 1;
  return c;
}

/* model._key_text: a user's key escaped (unicode_escape), short. */
static void key_text(const char *key, size_t len, char *out, size_t outlen)
{
  char esc[64];
  size_t n = 0, i;
  int simple = len >= 1 && len <= 40;
  const unsigned char *p = (const unsigned char *)key, *end = p + len;
  for (i = 0; i < len && simple; i++)
    simple = (key[i] >= 'a' && key[i] <= 'z') || (key[i] >= 'A' && key[i] <= 'Z')
             || (key[i] >= '0' && key[i] <= '9') || key[i] == '_';
  if (simple) {
    snprintf(out, outlen, "%s", key);
    return;
  }
  while (p < end && n <= 40) { /* 41 characters tell "longer than 40" */
    uint32_t c = utf8_next(&p);
    char one[16];
    if (c >= 0x10000)
      sprintf(one, "\\U%08x", (unsigned)c);
    else if (c >= 256)
      sprintf(one, "\\u%04x", (unsigned)c);
    else if (c == '\\')
      strcpy(one, "\\\\");
    else if (c == '\t')
      strcpy(one, "\\t");
    else if (c == '\n')
      strcpy(one, "\\n");
    else if (c == '\r')
      strcpy(one, "\\r");
    else if (c < ' ' || c >= 0x7f)
      sprintf(one, "\\x%02x", (unsigned)c);
    else if (c == '"')
      strcpy(one, "\\\"");
    else
      one[0] = (char)c, one[1] = '\0';
    for (i = 0; one[i] && n < sizeof esc - 1; i++)
      esc[n++] = one[i];
  }
  if (n > 40)
    n = 37, memcpy(esc + n, "...", 4), n += 3;
  esc[n] = '\0';
  snprintf(out, outlen, "\"%s\"", esc);
}

/* ---- numbers -------------------------------------------------------- */

static int is_digit(char c) { return c >= '0' && c <= '9'; }

/* The digits of a number token, integer part then fraction. */
static char token_digit(const num *n, size_t i)
{
  const char *t = n->text + (n->text[0] == '-');
  size_t ilen = 0;
  while (is_digit(t[ilen]))
    ilen++;
  return i < ilen ? t[i] : t[i + 1];
}

/* model._parse_number's classification of a token already known to match
 * JSON's number grammar. */
static void classify(num *n)
{
  const char *t = n->text, *end = t + n->len, *p;
  size_t ndig = 0, flen = 0, first = (size_t)-1, last = 0, ed = 0;
  long e = 0;
  int eneg = 0, dot = 0;
  n->neg = t[0] == '-';
  for (p = t + n->neg; p < end && *p != 'e' && *p != 'E'; p++) {
    if (*p == '.') {
      dot = 1;
      continue;
    }
    if (*p != '0') {
      if (first == (size_t)-1)
        first = ndig;
      last = ndig;
    }
    ndig++;
    flen += (size_t)dot;
  }
  n->kind = NUM_OK;
  n->zero = first == (size_t)-1;
  if (n->zero)
    return;
  if (p < end) {
    p++;
    if (*p == '-' || *p == '+')
      eneg = *p++ == '-';
    while (p < end && *p == '0')
      p++;
    for (; p < end; p++, ed++)
      if (ed < MAX_EXP_DIGITS)
        e = 10 * e + (*p - '0');
  }
  if (ed > MAX_EXP_DIGITS) {
    n->kind = NUM_RANGE;
    return;
  }
  if (eneg)
    e = -e;
  /* Decimal's adjusted(): exponent of the leading significant digit. */
  {
    long adjusted = e - (long)flen + (long)(ndig - first) - 1;
    n->first = first;
    n->sig = last - first + 1;
    n->exp10 = e - (long)flen + (long)(ndig - 1 - last);
    if (adjusted < -30 || adjusted > 30)
      n->kind = NUM_RANGE;
    else if (n->sig > MAX_DIGITS)
      n->kind = NUM_PRECISE;
  }
}

/* exp10 of the leading digit: for the magnitude check. */
static long adjusted(const num *n) { return n->exp10 + (long)n->sig - 1; }

/* The token shortened as model._OutOfRange.text. */
static void token_text(const num *n, char out[48])
{
  if (n->len <= 40)
    snprintf(out, 48, "%.*s", (int)n->len, n->text);
  else
    snprintf(out, 48, "%.20s...%.10s", n->text, n->text + n->len - 10);
}

static int by_node(const void *a, const void *b)
{
  const json_t *x = ((const num *)a)->node, *y = ((const num *)b)->node;
  return x < y ? -1 : x > y;
}

static const num *find_num(const ctx *c, const json_t *v)
{
  num key;
  key.node = (json_t *)v;
  return c->nnum > 0 ? bsearch(&key, c->nums, c->nnum, sizeof key, by_node) : NULL;
}

static double num_value(const ctx *c, const json_t *v)
{
  const num *n = find_num(c, v);
  return n->zero ? 0.0 : json_real_value(v); /* float(Fraction(-0)) = 0.0 */
}

/* ---- exact integers --------------------------------------------------- */

static void big_set(big *r, uint32_t v)
{
  memset(r, 0, sizeof *r);
  r->w[0] = v;
}

static void big_muladd(big *r, uint32_t m, uint32_t a)
{
  uint64_t carry = a;
  int i;
  for (i = 0; i < BIG_WORDS; i++) {
    uint64_t t = (uint64_t)r->w[i] * m + carry;
    r->w[i] = (uint32_t)t;
    carry = t >> 32;
  }
}

static void big_add(big *r, const big *a, const big *b)
{
  uint64_t carry = 0;
  int i;
  for (i = 0; i < BIG_WORDS; i++) {
    uint64_t t = (uint64_t)a->w[i] + b->w[i] + carry;
    r->w[i] = (uint32_t)t;
    carry = t >> 32;
  }
}

static void big_neg(big *r)
{
  int i;
  for (i = 0; i < BIG_WORDS; i++)
    r->w[i] = ~r->w[i];
  big_muladd(r, 1, 1);
}

static void big_sub(big *r, const big *a, const big *b)
{
  big nb = *b;
  big_neg(&nb);
  big_add(r, a, &nb);
}

static void big_mul(big *r, const big *a, const big *b)
{
  big t;
  int i, j;
  memset(&t, 0, sizeof t);
  for (i = 0; i < BIG_WORDS; i++) {
    uint64_t carry = 0;
    for (j = 0; i + j < BIG_WORDS; j++) {
      uint64_t x = (uint64_t)a->w[i] * b->w[j] + t.w[i + j] + carry;
      t.w[i + j] = (uint32_t)x;
      carry = x >> 32;
    }
  }
  *r = t;
}

static int big_sign(const big *a)
{
  int i;
  if (a->w[BIG_WORDS - 1] >> 31)
    return -1;
  for (i = 0; i < BIG_WORDS; i++)
    if (a->w[i])
      return 1;
  return 0;
}

/* value * 10^SCALE, exactly. */
static void big_num(big *r, const ctx *c, const json_t *v)
{
  const num *n = find_num(c, v);
  size_t i;
  long shift;
  big_set(r, 0);
  if (n->zero)
    return;
  for (i = 0; i < n->sig; i++)
    big_muladd(r, 10, (uint32_t)(token_digit(n, n->first + i) - '0'));
  for (shift = SCALE + n->exp10; shift > 0; shift--)
    big_muladd(r, 10, 0);
  if (n->neg)
    big_neg(r);
}

/* float() of an exact value * 10^-SCALE, correctly rounded. */
static double big_value(const big *a)
{
  char digits[BIG_WORDS * 10 + 16], out[BIG_WORDS * 10 + 24];
  big m = *a;
  int neg = big_sign(a) < 0, n = 0, i;
  if (neg)
    big_neg(&m);
  do {
    uint64_t rem = 0;
    for (i = BIG_WORDS - 1; i >= 0; i--) {
      uint64_t cur = rem << 32 | m.w[i];
      m.w[i] = (uint32_t)(cur / 10);
      rem = cur % 10;
    }
    digits[n++] = (char)('0' + rem);
  } while (big_sign(&m) != 0);
  for (i = 0; i < n; i++)
    out[neg + i] = digits[n - 1 - i];
  if (neg)
    out[0] = '-';
  sprintf(out + neg + n, "e-%d", SCALE);
  return decimal_value(out);
}

/* ---- model._json_text ------------------------------------------------- */

typedef struct {
  char b[72];
  size_t n;
} jbuf;

enum { JTEXT_MAX = 60 };

static void jput(jbuf *j, const char *s)
{
  while (*s && j->n <= JTEXT_MAX)
    j->b[j->n++] = *s++;
}

static void jstring(jbuf *j, const char *s, size_t len)
{
  const unsigned char *p = (const unsigned char *)s, *end = p + len;
  jput(j, "\"");
  while (p < end && j->n <= JTEXT_MAX) {
    uint32_t c = utf8_next(&p);
    char one[16];
    if (c == '"' || c == '\\')
      sprintf(one, "\\%c", (char)c);
    else if (c == '\n')
      strcpy(one, "\\n");
    else if (c == '\r')
      strcpy(one, "\\r");
    else if (c == '\t')
      strcpy(one, "\\t");
    else if (c == '\b')
      strcpy(one, "\\b");
    else if (c == '\f')
      strcpy(one, "\\f");
    else if (c < 0x20 || (c >= 0x80 && c < 0x10000))
      sprintf(one, "\\u%04x", (unsigned)c);
    else if (c >= 0x10000)
      sprintf(one, "\\u%04x\\u%04x", (unsigned)(0xd800 + ((c - 0x10000) >> 10)),
              (unsigned)(0xdc00 + ((c - 0x10000) & 0x3ff)));
    else
      one[0] = (char)c, one[1] = '\0';
    jput(j, one);
  }
  jput(j, "\"");
}

static void jdump(const ctx *c, jbuf *j, const json_t *v)
{
  char text[48];
  size_t i;
  const char *k;
  json_t *x;
  int first = 1;
  if (j->n > JTEXT_MAX)
    return;
  switch (json_typeof(v)) {
  case JSON_OBJECT:
    jput(j, "{");
    json_object_foreach((json_t *)v, k, x) {
      if (j->n > JTEXT_MAX)
        break;
      jput(j, first ? "" : ", ");
      first = 0;
      jstring(j, k, strlen(k));
      jput(j, ": ");
      jdump(c, j, x);
    }
    jput(j, "}");
    break;
  case JSON_ARRAY:
    jput(j, "[");
    for (i = 0; i < json_array_size(v) && j->n <= JTEXT_MAX; i++) {
      jput(j, i ? ", " : "");
      jdump(c, j, json_array_get(v, i));
    }
    jput(j, "]");
    break;
  case JSON_STRING:
    jstring(j, json_string_value(v), json_string_length(v));
    break;
  case JSON_REAL: {
    const num *n = find_num(c, v);
    if (n->kind != NUM_OK) {
      token_text(n, text);
      jput(j, "\"");
      jput(j, text);
      jput(j, "\"");
    } else {
      py_repr(num_value(c, v), text);
      jput(j, text);
    }
    break;
  }
  case JSON_TRUE:
    jput(j, "true");
    break;
  case JSON_FALSE:
    jput(j, "false");
    break;
  default:
    jput(j, "null");
  }
}

static const char *json_text(const ctx *c, const json_t *v, jbuf *j)
{
  j->n = 0;
  jdump(c, j, v);
  if (j->n > JTEXT_MAX)
    j->n = 57, memcpy(j->b + j->n, "...", 3), j->n += 3;
  j->b[j->n] = '\0';
  return j->b;
}

/* ---- values (model._number and friends) ------------------------------- */

static prru_status number(ctx *c, const char *key, const json_t *v, double *out)
{
  char text[48];
  jbuf j;
  const num *n;
  if (!json_is_real(v))
    return fail(c, key, "must be a number (got %s)", json_text(c, v, &j));
  n = find_num(c, v);
  token_text(n, text);
  if (n->kind == NUM_PRECISE)
    return fail(c, key, "has more than %d significant digits (got %s)",
                MAX_DIGITS, text);
  if (n->kind == NUM_RANGE)
    return fail(c, key, "magnitude %s is outside [1e-9, 1e6]", text);
  /* |v| > 1e6 or 0 < |v| < 1e-9, from the decimal digits: exact. */
  if (!n->zero && (adjusted(n) > 6 || adjusted(n) < -9
                   || (adjusted(n) == 6 && n->sig > 1)
                   || (adjusted(n) == 6 && token_digit(n, n->first) != '1'))) {
    py_repr(json_real_value(v), text);
    return fail(c, key, "magnitude %s is outside [1e-9, 1e6]", text);
  }
  *out = num_value(c, v);
  return PRRU_OK;
}

static int num_sign(const ctx *c, const json_t *v)
{
  const num *n = find_num(c, v);
  return n->zero ? 0 : n->neg ? -1 : 1;
}

static prru_status positive(ctx *c, const char *key, const json_t *v, double *out)
{
  char text[40];
  prru_status st = number(c, key, v, out);
  if (st)
    return st;
  if (num_sign(c, v) <= 0) {
    py_repr(*out, text);
    return fail(c, key, "must be positive (got %s)", text);
  }
  return PRRU_OK;
}

static prru_status nonnegative(ctx *c, const char *key, const json_t *v, double *out)
{
  char text[40];
  prru_status st = number(c, key, v, out);
  if (st)
    return st;
  if (num_sign(c, v) < 0) {
    py_repr(*out, text);
    return fail(c, key, "must not be negative (got %s)", text);
  }
  return PRRU_OK;
}

typedef prru_status (*check_fn)(ctx *, const char *, const json_t *, double *);

/* model._object: a JSON object with only allowed keys and every required. */
static prru_status object(ctx *c, const char *key, const json_t *v,
                          const char *const *allowed, int nallowed,
                          const char *const *required, int nrequired)
{
  const char *k;
  json_t *x;
  char where[160], list[160] = "";
  int i;
  if (!json_is_object(v))
    return fail(c, *key ? key : "(top level)", "must be a JSON object");
  for (i = 0; i < nallowed; i++)
    snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
             i ? ", " : "", allowed[i]);
  json_object_foreach((json_t *)v, k, x) {
    char text[80];
    for (i = 0; i < nallowed && strcmp(k, allowed[i]); i++)
      ;
    if (i == nallowed) {
      key_text(k, strlen(k), text, sizeof text);
      snprintf(where, sizeof where, "%s%s%s", key, *key ? "." : "", text);
      return fail(c, where, "unknown key (allowed: %s)", list);
    }
  }
  for (i = 0; i < nrequired; i++)
    if (!json_object_get(v, required[i])) {
      snprintf(where, sizeof where, "%s%s%s", key, *key ? "." : "", required[i]);
      return fail(c, where, "missing");
    }
  return PRRU_OK;
}

/* model._per_limb: one number for every limb, or a list of count. */
static prru_status per_limb(ctx *c, const char *key, const json_t *v, int count,
                            check_fn check, const char *what, double *out,
                            const json_t **nodes)
{
  char k[64];
  size_t i;
  prru_status st;
  if (json_is_array(v)) {
    if (json_array_size(v) != (size_t)count)
      return fail(c, key, "must be one number or a list of %d (%s), got %d entries",
                  count, what, (int)json_array_size(v));
    for (i = 0; i < (size_t)count; i++) {
      snprintf(k, sizeof k, "%s[%d]", key, (int)i);
      if ((st = check(c, k, json_array_get(v, i), out + i)))
        return st;
      if (nodes)
        nodes[i] = json_array_get(v, i);
    }
    return PRRU_OK;
  }
  if ((st = check(c, key, v, out)))
    return st;
  for (i = 0; i < (size_t)count; i++) {
    out[i] = out[0];
    if (nodes)
      nodes[i] = v;
  }
  return PRRU_OK;
}

static prru_status vector3(ctx *c, const char *key, const json_t *v,
                           const char *what, double out[3])
{
  char k[64];
  int i;
  prru_status st;
  if (!json_is_array(v) || json_array_size(v) != 3)
    return fail(c, key, "must be a list of 3 numbers (%s)", what);
  for (i = 0; i < 3; i++) {
    snprintf(k, sizeof k, "%s[%d]", key, i);
    if ((st = number(c, k, json_array_get(v, i), out + i)))
      return st;
  }
  return PRRU_OK;
}

/* model._minors_ok on an exact symmetric 3x3 (scaled: signs only). */
static int minors_ok(const big m[3][3], int strict)
{
  big t1, t2, t3, d3, d2[3];
  static const int pr[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  int i;
  for (i = 0; i < 3; i++) {
    big_mul(&t1, &m[pr[i][0]][pr[i][0]], &m[pr[i][1]][pr[i][1]]);
    big_mul(&t2, &m[pr[i][0]][pr[i][1]], &m[pr[i][1]][pr[i][0]]);
    big_sub(&d2[i], &t1, &t2);
  }
  /* det3 by the first row, as the generator */
  big_mul(&t1, &m[1][1], &m[2][2]), big_mul(&t2, &m[1][2], &m[2][1]);
  big_sub(&t3, &t1, &t2), big_mul(&d3, &m[0][0], &t3);
  big_mul(&t1, &m[1][0], &m[2][2]), big_mul(&t2, &m[1][2], &m[2][0]);
  big_sub(&t3, &t1, &t2), big_mul(&t3, &m[0][1], &t3), big_sub(&d3, &d3, &t3);
  big_mul(&t1, &m[1][0], &m[2][1]), big_mul(&t2, &m[1][1], &m[2][0]);
  big_sub(&t3, &t1, &t2), big_mul(&t3, &m[0][2], &t3), big_add(&d3, &d3, &t3);
  if (strict)
    return big_sign(&m[0][0]) > 0 && big_sign(&d2[0]) > 0 && big_sign(&d3) > 0;
  for (i = 0; i < 3; i++)
    if (big_sign(&m[i][i]) < 0 || big_sign(&d2[i]) < 0)
      return 0;
  return big_sign(&d3) >= 0;
}

/* model._inertia */
static prru_status inertia(ctx *c, const char *key, const json_t *v, int fmt,
                           double out[6])
{
  static const int idx[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
  char k[64], t[3][40];
  size_t n = json_is_array(v) ? json_array_size(v) : 0;
  big e[6], m[3][3], s[3][3], tr;
  int i, j;
  prru_status st;
  if (!json_is_array(v) || !(n == 3 || (fmt == 2 && n == 6)))
    return fail(c, key, fmt == 1
                ? "must be a list of 3 principal moments [Ixx, Iyy, Izz] in the body frame"
                : "must be a list of 3 principal moments [Ixx, Iyy, Izz] or 6 tensor "
                  "entries [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] about the centre of mass, "
                  "in body axes");
  for (i = 0; i < (int)n; i++) {
    snprintf(k, sizeof k, "%s[%d]", key, i);
    if ((st = (n == 3 ? positive : number)(c, k, json_array_get(v, (size_t)i), out + i)))
      return st;
    big_num(&e[i], c, json_array_get(v, (size_t)i));
  }
  if (n == 3) {
    for (i = 0; i < 3; i++) {
      int a = (i + 1) % 3, b = (i + 2) % 3;
      big sum, diff;
      big_add(&sum, &e[a], &e[b]);
      big_sub(&diff, &e[i], &sum);
      if (big_sign(&diff) > 0) {
        py_repr(out[i], t[0]), py_repr(out[a], t[1]), py_repr(out[b], t[2]);
        return fail(c, key, "violates the triangle inequality (I%d = %s > %s + %s): "
                    "no rigid body has it", i + 1, t[0], t[1], t[2]);
      }
    }
    out[3] = out[4] = out[5] = 0.0;
    return PRRU_OK;
  }
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      m[i][j] = e[idx[i][j]];
  if (!minors_ok((const big(*)[3])m, 1))
    return fail(c, key, "is not positive definite: no rigid body has this inertia tensor");
  /* 2 S = tr(I) E - 2 I: the generator's S scaled by 2, same signs. */
  big_add(&tr, &e[0], &e[1]), big_add(&tr, &tr, &e[2]);
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++) {
      big twice;
      big_add(&twice, &m[i][j], &m[i][j]);
      if (i == j)
        big_sub(&s[i][j], &tr, &twice);
      else
        big_set(&s[i][j], 0), big_sub(&s[i][j], &s[i][j], &twice);
    }
  if (!minors_ok((const big(*)[3])s, 0))
    return fail(c, key, "violates the triangle inequality of its principal moments: "
                "no rigid body has it");
  return PRRU_OK;
}

/* ---- the file's sections ---------------------------------------------- */

/* Exact nodes of every limb's b, l1, l2, a (NULL: a = 0), for the assembly
 * check. */
typedef struct { const json_t *b, *l1, *l2, *a; } limb_nodes;

static const char *const GEOMETRY_KEYS[] = {"b12", "b3", "l1", "l2", "a"};
static const char *const GEOMETRY2_KEYS[] = {"b", "l1", "l2", "a"};

/* model._geometry1 */
static prru_status geometry1(ctx *c, const json_t *geo, prru_model_spec *m,
                             limb_nodes *ln)
{
  double g[5];
  const json_t *node[5];
  char k[32];
  int i;
  prru_status st = object(c, "geometry", geo, GEOMETRY_KEYS, 5, GEOMETRY_KEYS, 5);
  if (st)
    return st;
  for (i = 0; i < 5; i++) {
    snprintf(k, sizeof k, "geometry.%s", GEOMETRY_KEYS[i]);
    node[i] = json_object_get(geo, GEOMETRY_KEYS[i]);
    if ((st = positive(c, k, node[i], g + i)))
      return st;
  }
  m->nlimb = 3;
  for (i = 0; i < 3; i++) {
    m->limb[i].b = g[i < 2 ? 0 : 1];
    m->limb[i].l1 = g[2], m->limb[i].l2 = g[3];
    m->limb[i].a = i < 2 ? g[4] : 0.0;
    ln[i].b = node[i < 2 ? 0 : 1];
    ln[i].l1 = node[2], ln[i].l2 = node[3];
    ln[i].a = i < 2 ? node[4] : NULL;
  }
  return PRRU_OK;
}

/* model._geometry2: the number of rails sets the number of limbs. */
static prru_status geometry2(ctx *c, const json_t *geo, prru_model_spec *m,
                             limb_nodes *ln)
{
  double b[4], l1[4], l2[4], a[2];
  const json_t *nb[4], *nl1[4], *nl2[4], *na[2];
  const json_t *vb;
  char what[64];
  int n, i;
  prru_status st = object(c, "geometry", geo, GEOMETRY2_KEYS, 4, GEOMETRY2_KEYS, 4);
  if (st)
    return st;
  vb = json_object_get(geo, "b");
  if (!json_is_array(vb) || json_array_size(vb) < 3 || json_array_size(vb) > 4)
    return fail(c, "geometry.b", "must be a list of 3 rail offsets [b1, b2, b3], "
                "or 4 for the redundant 4-limb variant [b1, b2, b3, b4]");
  n = (int)json_array_size(vb);
  strcpy(what, n == 3 ? "rail offsets b1, b2, b3" : "rail offsets b1, b2, b3, b4");
  if ((st = per_limb(c, "geometry.b", vb, n, positive, what, b, nb))
      || (st = per_limb(c, "geometry.l1", json_object_get(geo, "l1"), n, positive,
                        "one upper link per limb", l1, nl1))
      || (st = per_limb(c, "geometry.l2", json_object_get(geo, "l2"), n, positive,
                        "one lower link per limb", l2, nl2))
      || (st = per_limb(c, "geometry.a", json_object_get(geo, "a"), 2, positive,
                        "U-joint offsets a1, a2 of limbs 1 and 2", a, na)))
    return st;
  m->nlimb = n;
  for (i = 0; i < n; i++) {
    m->limb[i].b = b[i], m->limb[i].l1 = l1[i], m->limb[i].l2 = l2[i];
    m->limb[i].a = i < 2 ? a[i] : 0.0;
    ln[i].b = nb[i], ln[i].l1 = nl1[i], ln[i].l2 = nl2[i];
    ln[i].a = i < 2 ? na[i] : NULL;
  }
  return PRRU_OK;
}

/* model._check_assembly: |b - a - l2| < l1 exactly, as -1 < gap/l1 < 1. */
static prru_status check_assembly(ctx *c, const prru_model_spec *m,
                                  const limb_nodes *ln, int fmt)
{
  static const int groups1[2] = {0, 2};
  int i, ng = fmt == 1 ? 2 : m->nlimb;
  for (i = 0; i < ng; i++) {
    int l = fmt == 1 ? groups1[i] : i;
    big b, a, l2, l1, gap, t;
    char label[24], tg[40], tl[40];
    big_num(&b, c, ln[l].b), big_num(&l2, c, ln[l].l2), big_num(&l1, c, ln[l].l1);
    if (ln[l].a)
      big_num(&a, c, ln[l].a);
    else
      big_set(&a, 0);
    big_sub(&gap, &b, &a), big_sub(&gap, &gap, &l2);
    big_sub(&t, &l1, &gap);
    if (big_sign(&t) > 0) {
      big_add(&t, &l1, &gap);
      if (big_sign(&t) > 0)
        continue;
    }
    if (fmt == 1)
      strcpy(label, l == 0 ? "limbs 1, 2" : "limb 3");
    else
      snprintf(label, sizeof label, "limb %d", l + 1);
    py_repr(big_value(&gap), tg), py_repr(m->limb[l].l1, tl);
    return fail(c, "geometry", "%s cannot be assembled at q = 0: the horizontal gap "
                "%s m must be shorter than the upper link l1 = %s m", label, tg, tl);
  }
  return PRRU_OK;
}

/* model._gravity */
static prru_status gravity(ctx *c, const json_t *v, int fmt, double g[3])
{
  char text[40];
  double mag;
  prru_status st;
  if (fmt == 2 && json_is_array(v))
    return vector3(c, "gravity", v, "acceleration in {S}, m/s^2", g);
  if ((st = number(c, "gravity", v, &mag)))
    return st;
  if (num_sign(c, v) < 0) {
    py_repr(mag, text);
    return fail(c, "gravity", "is the magnitude along -z and must not be negative "
                "(got %s)", text);
  }
  g[0] = g[1] = 0.0;
  g[2] = mag == 0 ? 0.0 : -mag; /* float(-g) = -float(g); -0 is 0 */
  return PRRU_OK;
}

static const char *const ACTUATOR_KEYS[] = {
    "armature", "damping", "coulomb", "coulomb_velocity", "lead", "gear",
    "rotor_inertia", "torque_constant", "stroke", "force_max", "torque_max",
    "speed_max", "motor_speed_max"};
enum { NACTUATOR_KEYS = sizeof ACTUATOR_KEYS / sizeof *ACTUATOR_KEYS };

/* model._stroke: one pair [d_min, d_max] for every actuator, or n pairs. */
static prru_status stroke(ctx *c, const json_t *v, prru_model_spec *m)
{
  static const char *const key = "actuators.stroke";
  int n = m->nlimb, nested = 0, npair, i;
  size_t k;
  prru_status st;
  for (k = 0; json_is_array(v) && k < json_array_size(v); k++)
    nested |= json_is_array(json_array_get(v, k));
  if (nested && json_array_size(v) != (size_t)n)
    return fail(c, key, "must be one pair [d_min, d_max] (m) or a list of %d pairs "
                "(one per actuator), got %d entries", n, (int)json_array_size(v));
  if (!nested && !(json_is_array(v) && json_array_size(v) == 2))
    return fail(c, key, "must be one pair [d_min, d_max] (m) or a list of %d pairs "
                "(one per actuator)", n);
  npair = nested ? n : 1;
  for (i = 0; i < npair; i++) {
    const json_t *pair = nested ? json_array_get(v, (size_t)i) : v;
    char where[48], kk[56], tl[40], th[40];
    big lo, hi, diff;
    if (nested)
      snprintf(where, sizeof where, "%s[%d]", key, i);
    else
      snprintf(where, sizeof where, "%s", key);
    if (!json_is_array(pair) || json_array_size(pair) != 2)
      return fail(c, where, "must be a pair [d_min, d_max] (m)");
    snprintf(kk, sizeof kk, "%s[0]", where);
    if ((st = number(c, kk, json_array_get(pair, 0), &m->d_min[i])))
      return st;
    snprintf(kk, sizeof kk, "%s[1]", where);
    if ((st = number(c, kk, json_array_get(pair, 1), &m->d_max[i])))
      return st;
    big_num(&lo, c, json_array_get(pair, 0)), big_num(&hi, c, json_array_get(pair, 1));
    big_sub(&diff, &hi, &lo);
    if (big_sign(&diff) <= 0) {
      py_repr(m->d_min[i], tl), py_repr(m->d_max[i], th);
      return fail(c, where, "d_min = %s m must be below d_max = %s m", tl, th);
    }
  }
  for (i = npair; i < n; i++)
    m->d_min[i] = m->d_min[0], m->d_max[i] = m->d_max[0];
  return PRRU_OK;
}

/* Bit of a section 13 key (PRRU_DRIVE_*), 0 for section 11's. */
static unsigned drive_bit(const char *key)
{
  int i;
  for (i = 4; i < NACTUATOR_KEYS; i++)
    if (strcmp(key, ACTUATOR_KEYS[i]) == 0)
      return 1u << (i - 4);
  return 0;
}

/* No section 13 key: no lead, gear 1, no limits. */
static void drives_none(prru_model_spec *m)
{
  int i;
  for (i = 0; i < m->nlimb; i++) {
    m->lead[i] = m->rotor_inertia[i] = m->torque_constant[i] = 0.0;
    m->torque_max[i] = m->motor_speed_max[i] = 0.0;
    m->gear[i] = 1.0;
    m->d_min[i] = -INFINITY, m->d_max[i] = INFINITY;
    m->force_max[i] = m->speed_max[i] = INFINITY;
  }
  m->keys = 0;
}

/* model._drives: section 13 in key order, then the keys' relations. */
static prru_status drives(ctx *c, const json_t *v, prru_model_spec *m)
{
  static const char *const pairs[3][3] = {
      {"armature", "rotor_inertia", "drive inertia"},
      {"force_max", "torque_max", "force limit"},
      {"speed_max", "motor_speed_max", "speed limit"}};
  static const char *const needs_lead[4] = {"rotor_inertia", "torque_max",
                                            "motor_speed_max", "torque_constant"};
  double *lists[] = {m->lead, m->gear, m->rotor_inertia, m->torque_constant, NULL,
                     m->force_max, m->torque_max, m->speed_max, m->motor_speed_max};
  int i, j, n = m->nlimb;
  char k[40];
  prru_status st;
  drives_none(m);
  for (j = 4; j < NACTUATOR_KEYS; j++) {
    const json_t *x = json_object_get(v, ACTUATOR_KEYS[j]);
    if (!x)
      continue;
    m->keys |= drive_bit(ACTUATOR_KEYS[j]);
    snprintf(k, sizeof k, "actuators.%s", ACTUATOR_KEYS[j]);
    if (j == 8)
      st = stroke(c, x, m);
    else
      st = per_limb(c, k, x, n, j == 6 ? nonnegative : positive, "one per actuator",
                    lists[j - 4], NULL);
    if (st)
      return st;
  }
  for (j = 0; j < 3; j++)
    if (json_object_get(v, pairs[j][0]) && json_object_get(v, pairs[j][1])) {
      snprintf(k, sizeof k, "actuators.%s", pairs[j][1]);
      return fail(c, k, "given with actuators.%s: both set the %s of every actuator "
                  "(ambiguous); give one", pairs[j][0], pairs[j][2]);
    }
  if (!(m->keys & PRRU_DRIVE_LEAD))
    for (j = 0; j < 4; j++)
      if (m->keys & drive_bit(needs_lead[j])) {
        snprintf(k, sizeof k, "actuators.%s", needs_lead[j]);
        return fail(c, k, "needs actuators.lead (m of slider travel per screw "
                    "revolution) to convert between motor and rail");
      }
  for (i = 0; i < n; i++) {
    double w = m->lead[i] > 0 ? prru_drive_ratio(m->lead[i], m->gear[i]) : 0.0;
    if (m->keys & PRRU_DRIVE_ROTOR_INERTIA)
      m->armature[i] = m->rotor_inertia[i] * w * w; /* model.reflected_armature */
    if (m->keys & PRRU_DRIVE_TORQUE_MAX)
      m->force_max[i] = m->torque_max[i] * w;
    if (m->keys & PRRU_DRIVE_MOTOR_SPEED_MAX) /* model.motor_speed_to_rail */
      m->speed_max[i] = m->motor_speed_max[i] / 60.0 * m->lead[i] / m->gear[i];
  }
  return PRRU_OK;
}

/* model._actuators: absent or null means no drives. */
static prru_status actuators(ctx *c, const json_t *v, prru_model_spec *m)
{
  double *lists[3] = {m->armature, m->damping, m->coulomb};
  int i, n = m->nlimb, any = 0;
  char k[40];
  prru_status st;
  const json_t *vs;
  for (i = 0; i < n; i++)
    m->armature[i] = m->damping[i] = m->coulomb[i] = 0.0;
  m->coulomb_velocity = 0.0;
  drives_none(m);
  if (!v || json_is_null(v))
    return PRRU_OK;
  if ((st = object(c, "actuators", v, ACTUATOR_KEYS, NACTUATOR_KEYS, NULL, 0)))
    return st;
  for (i = 0; i < 3; i++) {
    const json_t *x = json_object_get(v, ACTUATOR_KEYS[i]);
    snprintf(k, sizeof k, "actuators.%s", ACTUATOR_KEYS[i]);
    if (x && (st = per_limb(c, k, x, n, nonnegative, "one per actuator", lists[i], NULL)))
      return st;
  }
  for (i = 0; i < n; i++)
    any |= m->coulomb[i] != 0.0; /* exact: a checked number is 0 or >= 1e-9 */
  vs = json_object_get(v, "coulomb_velocity");
  if (vs && (st = positive(c, "actuators.coulomb_velocity", vs, &m->coulomb_velocity)))
    return st;
  if (any && !vs)
    return fail(c, "actuators.coulomb_velocity", "missing: the Coulomb force "
                "-f tanh(dd / v_s) needs the smoothing velocity v_s (m/s)");
  if (!any)
    m->coulomb_velocity = 0.0;
  return drives(c, v, m);
}

static const char *const TOP_KEYS[] = {"format", "name", "description", "gravity",
                                       "geometry", "bodies", "actuators"};
static const char *const BODY_KEYS[] = {"mass", "inertia", "com"};

static void body_name(int nlimb, int i, char out[4])
{
  if (i == 0)
    strcpy(out, "P");
  else
    sprintf(out, "%c%d", "LUS"[(i - 1) / nlimb], (i - 1) % nlimb + 1);
}

/* name: [a-z][a-z0-9_]{0,15}, the C prefix. */
static int valid_name(const json_t *v)
{
  const char *s = json_string_value(v);
  size_t n = json_string_length(v), i;
  if (!json_is_string(v) || n < 1 || n > PRRU_MODEL_NAME_MAX || s[0] < 'a' || s[0] > 'z')
    return 0;
  for (i = 1; i < n; i++)
    if (!((s[i] >= 'a' && s[i] <= 'z') || is_digit(s[i]) || s[i] == '_'))
      return 0;
  return 1;
}

/* One line: no control character, no comment end, at most 400 characters
 * (code points; the text is valid UTF-8 without surrogates). */
static int valid_description(const json_t *v)
{
  const char *s = json_string_value(v);
  size_t n = json_string_length(v), i, chars = 0;
  if (!json_is_string(v))
    return 0;
  for (i = 0; i < n; i++) {
    if ((unsigned char)s[i] < 32 || (s[i] == '*' && i + 1 < n && s[i + 1] == '/'))
      return 0;
    chars += ((unsigned char)s[i] & 0xc0) != 0x80;
  }
  return chars <= PRRU_MODEL_DESCRIPTION_MAX;
}

/* model.parse after the JSON layer. */
static prru_status validate(ctx *c, const json_t *data, prru_model_spec *m)
{
  const json_t *v;
  limb_nodes ln[PRRU_MAX_LIMB];
  jbuf j;
  char key[40], bname[4];
  int fmt = 1, i, nbody;
  prru_status st;
  if (json_is_object(data) && (v = json_object_get(data, "format"))) {
    const num *n = json_is_real(v) ? find_num(c, v) : NULL;
    /* fmt in (1, 2) compares the exact value: "1.0" and "1e0" are 1. */
    if (!n || n->kind != NUM_OK || n->neg || n->zero || n->sig != 1
        || n->exp10 != 0 || (token_digit(n, n->first) != '1'
                             && token_digit(n, n->first) != '2'))
      return fail(c, "format", "must be 1 or 2 (got %s)", json_text(c, v, &j));
    fmt = token_digit(n, n->first) - '0';
  }
  if ((st = object(c, "", data, TOP_KEYS, fmt == 1 ? 6 : 7, TOP_KEYS + 1, 5)))
    return st;
  m->format = fmt;
  v = json_object_get(data, "name");
  if (!valid_name(v))
    return fail(c, "name", "must be a lower-case C identifier of at most 16 "
                "characters (it becomes the C prefix)");
  strcpy(m->name, json_string_value(v));
  v = json_object_get(data, "description");
  if (!valid_description(v))
    return fail(c, "description", "must be one line of text (at most 400 "
                "characters, no '*/')");
  strcpy(m->description, json_string_value(v));
  if ((st = gravity(c, json_object_get(data, "gravity"), fmt, m->gravity)))
    return st;
  v = json_object_get(data, "geometry");
  if ((st = fmt == 1 ? geometry1(c, v, m, ln) : geometry2(c, v, m, ln))
      || (st = check_assembly(c, m, ln, fmt)))
    return st;
  nbody = m->nbody = 1 + 3 * m->nlimb;
  {
    char names[PRRU_MAX_BODY][4];
    const char *list[PRRU_MAX_BODY];
    const json_t *bodies = json_object_get(data, "bodies");
    for (i = 0; i < nbody; i++)
      body_name(m->nlimb, i, names[i]), list[i] = names[i];
    if ((st = object(c, "bodies", bodies, list, nbody, list, nbody)))
      return st;
    for (i = 0; i < nbody; i++) {
      const json_t *body = json_object_get(bodies, names[i]), *com;
      strcpy(bname, names[i]);
      snprintf(key, sizeof key, "bodies.%s", bname);
      if ((st = object(c, key, body, BODY_KEYS, fmt == 1 ? 2 : 3, BODY_KEYS, 2)))
        return st;
      snprintf(key, sizeof key, "bodies.%s.mass", bname);
      if ((st = positive(c, key, json_object_get(body, "mass"), &m->mass[i])))
        return st;
      snprintf(key, sizeof key, "bodies.%s.inertia", bname);
      if ((st = inertia(c, key, json_object_get(body, "inertia"), fmt, m->inertia[i])))
        return st;
      com = json_object_get(body, "com");
      snprintf(key, sizeof key, "bodies.%s.com", bname);
      if (com && (st = vector3(c, key, com, "centre of mass in the body frame, m",
                               m->com[i])))
        return st;
      if (!com)
        m->com[i][0] = m->com[i][1] = m->com[i][2] = 0.0;
    }
  }
  return actuators(c, json_object_get(data, "actuators"), m);
}

/* ---- the JSON layer (model._load_json) -------------------------------- */

static int number_grammar(const char *t, size_t n)
{
  size_t i = t[0] == '-';
  if (i >= n || !is_digit(t[i]))
    return 0;
  if (t[i] == '0')
    i++;
  else
    while (i < n && is_digit(t[i]))
      i++;
  if (i < n && t[i] == '.') {
    if (++i >= n || !is_digit(t[i]))
      return 0;
    while (i < n && is_digit(t[i]))
      i++;
  }
  if (i < n && (t[i] == 'e' || t[i] == 'E')) {
    i++;
    if (i < n && (t[i] == '+' || t[i] == '-'))
      i++;
    if (i >= n || !is_digit(t[i]))
      return 0;
    while (i < n && is_digit(t[i]))
      i++;
  }
  return i == n;
}

static int token_char(char ch)
{
  return is_digit(ch) || (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z')
         || ch == '-' || ch == '+' || ch == '.';
}

/* Outside strings: the bracket depth (model._depth scans alike) and the
 * number tokens in document order; copy gets out-of-range tokens blanked
 * to "0" so that jansson parses what the generator parses. */
static prru_status scan(ctx *c, const char *s, size_t n, char *copy, int *deepest)
{
  size_t i = 0, cap = 0;
  int depth = 0;
  *deepest = 0;
  while (i < n) {
    char ch = s[i];
    if (ch == '"') {
      for (i++; i < n && s[i] != '"'; i++)
        if (s[i] == '\\')
          i++;
      i++;
    } else if (ch == '[' || ch == '{') {
      if (++depth > *deepest)
        *deepest = depth;
      i++;
    } else if (ch == ']' || ch == '}') {
      depth--;
      i++;
    } else if (token_char(ch)) {
      size_t start = i;
      while (i < n && token_char(s[i]))
        i++;
      if ((ch == '-' || is_digit(ch)) && number_grammar(s + start, i - start)) {
        num *x;
        if (c->nnum == cap) {
          num *more = realloc(c->nums, (cap = 2 * cap + 64) * sizeof *more);
          if (!more)
            return PRRU_ENOMEM;
          c->nums = more;
        }
        x = &c->nums[c->nnum++];
        memset(x, 0, sizeof *x);
        x->text = s + start;
        x->len = i - start;
        classify(x);
        if (x->kind != NUM_OK) {
          memset(copy + start, ' ', i - start);
          copy[start] = '0';
        }
      }
    } else {
      i++;
    }
  }
  return PRRU_OK;
}

/* The reals of a parsed document in document order (jansson keeps object
 * keys in insertion order). */
static void collect(const json_t *v, ctx *c, size_t *k)
{
  size_t i;
  const char *key;
  json_t *x;
  if (json_is_real(v)) {
    if (*k < c->nnum)
      c->nums[*k].node = (json_t *)v;
    ++*k;
  } else if (json_is_array(v)) {
    for (i = 0; i < json_array_size(v); i++)
      collect(json_array_get(v, i), c, k);
  } else if (json_is_object(v)) {
    json_object_foreach((json_t *)v, key, x)
      collect(x, c, k);
  }
}

static int starts(const char *s, size_t n, size_t at, const char *word)
{
  size_t w = strlen(word);
  return at + w <= n && memcmp(s + at, word, w) == 0;
}

/* jansson's refusal in the generator's words where the generator words it
 * itself; Python's json and jansson word the rest differently. */
static prru_status json_refusal(ctx *c, const char *s, size_t n, const json_error_t *e)
{
  size_t pos = (size_t)e->position;
  if (json_error_code(e) == json_error_duplicate_key && pos >= 2 && pos <= n) {
    /* the key token ends at pos: its opening quote is the first quote
     * before it not escaped by an odd run of backslashes */
    size_t q = pos - 1, b;
    while (q-- > 0) {
      if (s[q] != '"')
        continue;
      for (b = 0; b < q && s[q - 1 - b] == '\\'; b++)
        ;
      if (b % 2 == 0)
        break;
    }
    {
      json_t *k = json_loadb(s + q, pos - q, JSON_DECODE_ANY, NULL);
      char text[80];
      if (k && json_is_string(k)) {
        key_text(json_string_value(k), json_string_length(k), text, sizeof text);
        json_decref(k);
        return fail(c, NULL, "not valid JSON: duplicate key %s%s%s",
                    text[0] == '"' ? "" : "'", text, text[0] == '"' ? "" : "'");
      }
      json_decref(k);
    }
  }
  if (strncmp(e->text, "invalid token", 13) == 0) {
    size_t t = pos;
    while (t > 0 && ((s[t - 1] >= 'a' && s[t - 1] <= 'z') || (s[t - 1] >= 'A' && s[t - 1] <= 'Z')))
      t--;
    if (pos >= 1 && s[pos - 1] == '-') /* jansson stops after the sign */
      return starts(s, n, pos - 1, "-Infinity")
             ? fail(c, NULL, "not valid JSON: non-finite number -Infinity")
             : fail(c, NULL, "not valid JSON: %s (line %d, column %d)", e->text,
                    e->line, e->column);
    if (starts(s, n, t, "NaN"))
      return fail(c, NULL, "not valid JSON: non-finite number NaN");
    if (starts(s, n, t, "Infinity"))
      return fail(c, NULL, "not valid JSON: non-finite number Infinity");
  }
  if (strncmp(e->text, "invalid Unicode", 15) == 0)
    return fail(c, NULL, "not valid JSON: a string holds a lone UTF-16 surrogate "
                "escape (\\udXXX): not text");
  if (strncmp(e->text, "NUL byte in object key", 22) == 0)
    return fail(c, NULL, "not valid JSON: an object key holds U+0000");
  return fail(c, NULL, "not valid JSON: %s (line %d, column %d)", e->text, e->line,
              e->column);
}

/* Python's json before its parser: a BOM, or nothing but whitespace. */
static prru_status json_prefix(ctx *c, const char *s, size_t n)
{
  size_t i, line = 1, last = (size_t)-1;
  if (n >= 3 && memcmp(s, "\xef\xbb\xbf", 3) == 0)
    return fail(c, NULL, "not valid JSON: Unexpected UTF-8 BOM (decode using "
                "utf-8-sig): line 1 column 1 (char 0)");
  for (i = 0; i < n; i++) {
    if (s[i] != ' ' && s[i] != '\t' && s[i] != '\n' && s[i] != '\r')
      return PRRU_OK;
    if (s[i] == '\n')
      line++, last = i;
  }
  return fail(c, NULL, "not valid JSON: Expecting value: line %d column %d (char %d)",
              (int)line, (int)(n - last), (int)n);
}

/* Strict UTF-8 (Python's bytes.decode("utf-8")): no overlong forms, no
 * surrogates, nothing above U+10FFFF. */
static int valid_utf8(const unsigned char *s, size_t n)
{
  size_t i = 0;
  while (i < n) {
    unsigned c = s[i];
    size_t k, len;
    unsigned lo = 0x80, hi = 0xbf;
    if (c < 0x80) {
      i++;
      continue;
    }
    if (c >= 0xc2 && c <= 0xdf)
      len = 1;
    else if (c >= 0xe0 && c <= 0xef)
      len = 2, lo = c == 0xe0 ? 0xa0 : 0x80, hi = c == 0xed ? 0x9f : 0xbf;
    else if (c >= 0xf0 && c <= 0xf4)
      len = 3, lo = c == 0xf0 ? 0x90 : 0x80, hi = c == 0xf4 ? 0x8f : 0xbf;
    else
      return 0;
    if (len > n - 1 - i)
      return 0;
    for (k = 1; k <= len; k++) {
      unsigned b = s[i + k];
      if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xbf))
        return 0;
    }
    i += len + 1;
  }
  return 1;
}

static void canonical_hash(prru_model_spec *m)
{
  static const char magic[] = "prru-model-canonical-1\n";
  prru_sha256_ctx h;
  unsigned char d[32], head[2];
  int i;
  prru_sha256_init(&h);
  prru_sha256_update(&h, magic, sizeof magic - 1);
  head[0] = (unsigned char)m->format, head[1] = (unsigned char)m->nlimb;
  prru_sha256_update(&h, head, 2);

  {
    double v[3 + 4 * PRRU_MAX_LIMB + 10 * PRRU_MAX_BODY + 3 * PRRU_MAX_LIMB + 1
             + 7 * PRRU_MAX_LIMB];
    int n = 0, k;
    for (i = 0; i < 3; i++)
      v[n++] = m->gravity[i];
    for (i = 0; i < m->nlimb; i++)
      v[n++] = m->limb[i].b, v[n++] = m->limb[i].l1, v[n++] = m->limb[i].l2,
      v[n++] = m->limb[i].a;
    for (i = 0; i < m->nbody; i++) {
      v[n++] = m->mass[i];
      for (k = 0; k < 3; k++)
        v[n++] = m->com[i][k];
      for (k = 0; k < 6; k++)
        v[n++] = m->inertia[i][k];
    }
    for (i = 0; i < m->nlimb; i++)
      v[n++] = m->armature[i], v[n++] = m->damping[i], v[n++] = m->coulomb[i];
    v[n++] = m->coulomb_velocity;
    for (i = 0; m->keys && i < m->nlimb; i++) /* only with section 13's keys */
      v[n++] = m->lead[i], v[n++] = m->gear[i], v[n++] = m->torque_constant[i],
      v[n++] = m->d_min[i], v[n++] = m->d_max[i], v[n++] = m->force_max[i],
      v[n++] = m->speed_max[i];
    for (i = 0; i < n; i++) {
      unsigned char le[8];
      uint64_t bits;
      memcpy(&bits, &v[i], 8);
      for (k = 0; k < 8; k++)
        le[k] = (unsigned char)(bits >> (8 * k));
      prru_sha256_update(&h, le, 8);
    }
  }

  prru_sha256_final(&h, d);
  prru_sha256_to_hex(d, m->canonical_sha256);
}

/* After the UTF-8 check: model.parse. */
static prru_status parse_checked(ctx *c, const char *text, size_t len,
                                 prru_model_spec *out)
{
  char *copy;
  json_t *data;
  json_error_t e;
  prru_model_spec m;
  int deepest;
  size_t k = 0;
  prru_status st;
  if (!(copy = malloc(len ? len : 1)))
    return PRRU_ENOMEM;
  memcpy(copy, text, len);
  st = scan(c, text, len, copy, &deepest);
  if (!st && deepest > MAX_DEPTH)
    st = fail(c, NULL, "not valid JSON: nested deeper than %d levels", MAX_DEPTH);
  if (!st)
    st = json_prefix(c, text, len);
  if (st) {
    free(copy);
    return st;
  }
  data = json_loadb(copy, len, JSON_REJECT_DUPLICATES | JSON_DECODE_ANY
                    | JSON_DECODE_INT_AS_REAL | JSON_ALLOW_NUL, &e);
  if (!data) {
    st = json_refusal(c, copy, len, &e);
    free(copy);
    return st;
  }
  free(copy);
  collect(data, c, &k);
  if (k != c->nnum) {
    json_decref(data);
    return fail(c, NULL, "internal error: %d numbers parsed, %d scanned", (int)k,
                (int)c->nnum);
  }
  if (c->nnum > 0) /* a file without numbers: nums may be NULL, which qsort must not get */
    qsort(c->nums, c->nnum, sizeof *c->nums, by_node);
  memset(&m, 0, sizeof m);
  st = validate(c, data, &m);
  json_decref(data);
  if (st)
    return st;
  prru_sha256_hex(text, len, m.sha256);
  canonical_hash(&m);
  *out = m;
  return PRRU_OK;
}

prru_status prru_model_file_parse(const char *text, size_t len, const char *name,
                                  prru_model_spec *out, char *msg, int msglen)
{
  ctx c;
  prru_status st;
  memset(&c, 0, sizeof c);
  c.path = name ? name : "<model>";
  c.msg = msg, c.msglen = msglen;
  if (len > PRRU_MODEL_FILE_MAX_BYTES)
    return fail(&c, NULL, "file is larger than %d bytes; not a model file",
                PRRU_MODEL_FILE_MAX_BYTES);
  if (!valid_utf8((const unsigned char *)text, len))
    return fail(&c, NULL, "not UTF-8 text");
  st = parse_checked(&c, text, len, out);
  free(c.nums);
  return st;
}

prru_status prru_model_file_read(const char *path, prru_model_spec *out, char *msg,
                                 int msglen)
{
  ctx c;
  FILE *f;
  char *buf;
  size_t n = 0;
  int err = 0;
  prru_status st;
  memset(&c, 0, sizeof c);
  c.path = path, c.msg = msg, c.msglen = msglen;
  if (!(buf = malloc(PRRU_MODEL_FILE_MAX_BYTES + 1)))
    return PRRU_ENOMEM;
  errno = 0;
  if (!(f = fopen(path, "rb"))) {
    err = errno;
  } else {
    n = fread(buf, 1, PRRU_MODEL_FILE_MAX_BYTES + 1, f);
    if (ferror(f))
      err = errno ? errno : EIO;
    fclose(f);
  }
  if (err) {
    free(buf);
    fail(&c, NULL, "cannot read: %s", strerror(err));
    return PRRU_EIO;
  }
  st = prru_model_file_parse(buf, n, path, out, msg, msglen);
  free(buf);
  return st;
}
