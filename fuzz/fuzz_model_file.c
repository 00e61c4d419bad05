/* libFuzzer harness: prru_model_file_parse, the model-file reader behind
 * --model, PRRU_MODEL and prru_model_load (jansson, then the generator's
 * validation rules in C with exact decimal arithmetic). A model file is
 * user input that reaches every command, so it is parsed here with its
 * exact length and no terminator, as prru_model_file_read delivers it.
 * Oracles: on success the sizes of a 3- or 4-limb model, every number
 * finite, masses and lengths positive, the two SHA-256 as 64 hex digits,
 * and a second parse of the same bytes giving the same spec byte for byte
 * (nothing read from uninitialised memory); on failure a message naming
 * the file. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "prru_model_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int finite_all(const double *v, size_t n)
{
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

static int hex64(const char *s) { return strlen(s) == 64 && strspn(s, "0123456789abcdef") == 64; }

static void check_spec(const prru_model_spec *s)
{
  if (!(s->format == 1 || s->format == 2) || !(s->nlimb == 3 || s->nlimb == 4) || s->nbody != 1 + 3 * s->nlimb)
    abort();
  if (!s->name[0] || !memchr(s->name, 0, sizeof s->name) || !memchr(s->description, 0, sizeof s->description))
    abort();
  if (!finite_all(s->gravity, 3) || !(s->coulomb_velocity >= 0) || !isfinite(s->coulomb_velocity)) abort();
  for (int i = 0; i < s->nlimb; i++) {
    const prru_model_limb *l = &s->limb[i];
    if (!(l->b > 0 && l->l1 > 0 && l->l2 > 0 && isfinite(l->b) && isfinite(l->l1) && isfinite(l->l2)) ||
        !isfinite(l->a))
      abort();
    if (!(s->armature[i] >= 0 && s->damping[i] >= 0 && s->coulomb[i] >= 0) ||
        !isfinite(s->armature[i] + s->damping[i] + s->coulomb[i]))
      abort();
  }
  for (int b = 0; b < s->nbody; b++)
    if (!(s->mass[b] > 0) || !isfinite(s->mass[b]) || !finite_all(s->com[b], 3) || !finite_all(s->inertia[b], 6))
      abort();
  if (!hex64(s->sha256) || !hex64(s->canonical_sha256)) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char msg[512] = "";
  /* Zeroed first, so that padding and unused entries compare equal
   * between the two parses. */
  prru_model_spec *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
  if (!a || !b) abort();
  const prru_status st = prru_model_file_parse((const char *)data, size, "fuzz.json", a, msg, sizeof msg);
  if (st == PRRU_OK) {
    check_spec(a);
    if (prru_model_file_parse((const char *)data, size, "fuzz.json", b, msg, sizeof msg) != PRRU_OK ||
        memcmp(a, b, sizeof *a) != 0)
      abort();
  } else if (st != PRRU_ENOMEM && (!msg[0] || strncmp(msg, "fuzz.json", 9) != 0)) {
    abort();
  }
  free(a);
  free(b);
  return 0;
}
