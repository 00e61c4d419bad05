#define _POSIX_C_SOURCE 200809L
/* Prints what prru_model_file_read makes of a model file, as one JSON
 * object: {"ok": true, ...every number with %.17g...} or {"ok": false,
 * "status": s, "message": m}. tests/model_conformance.py compares it with
 * the generator's reading (gen/prrugen/model.py). With --time N, prints
 * the median wall time of N loads instead. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "prru_model_file.h"

static void string(const char *s)
{
  putchar('"');
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      printf("\\%c", c);
    else if (c < 0x20)
      printf("\\u%04x", c);
    else
      putchar(c);
  }
  putchar('"');
}

/* %.17g, or Python json's Infinity tokens (the limits' "none"). */
static void number(double x)
{
  if (isinf(x))
    printf("%sInfinity", x < 0 ? "-" : "");
  else
    printf("%.17g", x);
}

static void list(const char *key, const double *v, int n)
{
  int i;
  printf(", \"%s\": [", key);
  for (i = 0; i < n; i++)
    printf("%s", i ? ", " : ""), number(v[i]);
  putchar(']');
}

static int cmp(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
  prru_model_spec m;
  char msg[1024];
  int st, i;
  if (argc == 4 && strcmp(argv[1], "--time") == 0) {
    int n = atoi(argv[2]);
    double *t = malloc((size_t)n * sizeof *t);
    for (i = 0; i < n; i++) {
      struct timespec a, b;
      clock_gettime(CLOCK_MONOTONIC, &a);
      st = prru_model_file_read(argv[3], &m, msg, sizeof msg);
      clock_gettime(CLOCK_MONOTONIC, &b);
      if (st) {
        fprintf(stderr, "%s\n", msg);
        return 1;
      }
      t[i] = (b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec);
    }
    qsort(t, (size_t)n, sizeof *t, cmp);
    printf("%.6f\n", 1e3 * t[n / 2]);
    free(t);
    return 0;
  }
  if (argc != 2) {
    fprintf(stderr, "usage: model_file_dump FILE | --time N FILE\n");
    return 2;
  }
  st = prru_model_file_read(argv[1], &m, msg, sizeof msg);
  if (st) {
    printf("{\"ok\": false, \"status\": %d, \"message\": ", st);
    string(msg);
    printf("}\n");
    return 0;
  }
  printf("{\"ok\": true, \"name\": ");
  string(m.name);
  printf(", \"description\": ");
  string(m.description);
  printf(", \"format\": %d, \"nlimb\": %d", m.format, m.nlimb);
  list("gravity", m.gravity, 3);
  printf(", \"limbs\": [");
  for (i = 0; i < m.nlimb; i++)
    printf("%s[%.17g, %.17g, %.17g, %.17g]", i ? ", " : "", m.limb[i].b,
           m.limb[i].l1, m.limb[i].l2, m.limb[i].a);
  putchar(']');
  list("masses", m.mass, m.nbody);
  printf(", \"coms\": [");
  for (i = 0; i < m.nbody; i++)
    printf("%s[%.17g, %.17g, %.17g]", i ? ", " : "", m.com[i][0], m.com[i][1], m.com[i][2]);
  printf("], \"inertias\": [");
  for (i = 0; i < m.nbody; i++)
    printf("%s[%.17g, %.17g, %.17g, %.17g, %.17g, %.17g]", i ? ", " : "", m.inertia[i][0],
           m.inertia[i][1], m.inertia[i][2], m.inertia[i][3], m.inertia[i][4], m.inertia[i][5]);
  putchar(']');
  list("armature", m.armature, m.nlimb);
  list("damping", m.damping, m.nlimb);
  list("coulomb", m.coulomb, m.nlimb);
  {
    static const char *const names[] = {"lead", "gear", "rotor_inertia", "torque_constant",
                                        "stroke", "force_max", "torque_max", "speed_max",
                                        "motor_speed_max"};
    int first = 1;
    printf(", \"drive_keys\": [");
    for (i = 0; i < 9; i++)
      if (m.keys & (1u << i))
        printf("%s\"%s\"", first ? "" : ", ", names[i]), first = 0;
    putchar(']');
  }
  list("lead", m.lead, m.nlimb);
  list("gear", m.gear, m.nlimb);
  list("rotor_inertia", m.rotor_inertia, m.nlimb);
  list("torque_constant", m.torque_constant, m.nlimb);
  list("d_min", m.d_min, m.nlimb);
  list("d_max", m.d_max, m.nlimb);
  list("torque_max", m.torque_max, m.nlimb);
  list("motor_speed_max", m.motor_speed_max, m.nlimb);
  list("force_max", m.force_max, m.nlimb);
  list("speed_max", m.speed_max, m.nlimb);
  printf(", \"coulomb_velocity\": %.17g, \"sha256\": \"%s\", \"canonical_sha256\": \"%s\"}\n",
         m.coulomb_velocity, m.sha256, m.canonical_sha256);
  return 0;
}
