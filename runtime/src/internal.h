/* Helpers shared inside the runtime, not part of its API. */
#ifndef PRRU_INTERNAL_H
#define PRRU_INTERNAL_H
#include <stddef.h>

#include "prru.h"

/* C99 has no M_PI. */
#define PRRU_PI 3.14159265358979323846

/* Formats msg (if non-NULL) and returns status. */
int prru_fail(char *msg, int msglen, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* Reads a whole file (at most 256 MiB); NULL with msg on failure. */
char *prru_read_file(const char *path, size_t *len, char *msg, int msglen);
/* 1 / (|A|_1 |A^-1|_1) of a 3x3 matrix via its adjugate (no pivoting:
 * callers only invert J_d, whose conditioning this is); 0 when the
 * determinant is 0 or not finite. Fills inv = A^-1 when non-NULL and the
 * determinant is usable. */
double prru_rcond3(const double a[9], double inv[9]);
/* The model's length scale (m): the mean upper-link length. Tolerances on
 * lengths and the conditioning of J_d are relative to it. */
double prru_length_scale(const prru_mechanism *me);
/* Turns GSL's abort-on-error handler off, once per process: every runtime
 * call checks GSL's status codes itself. Thread-safe. */
void prru_gsl_init(void);
#endif
