/* libFuzzer harness: load-schedule CSVs (prru_schedule_parse_csv, the
 * in-memory body of prru_schedule_read_csv used by `prru simulate --loads`
 * and scenario files).
 * Oracles: on success the times strictly increase, and evaluating the
 * schedule before, at, between and after the rows gives finite loads: a
 * table of finite numbers must never feed the integrator inf or NaN. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_finite(const prru_load_schedule *s, double t)
{
  prru_loads l;
  prru_schedule_eval(s, t, &l);
  for (int k = 0; k < 3; k++)
    if (!isfinite(l.fd[k]) || !isfinite(l.fp[k]) || !isfinite(l.mp[k])) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char msg[256] = "";
  prru_load_schedule s;
  prru_model m;
  prru_model_default(&m);
  int st = prru_schedule_parse_csv(&m, &s, (const char *)data, size, "loads.csv", msg, sizeof msg);
  if (st != PRRU_OK) {
    if (!msg[0] || s.rows || s.nrows) abort();
    return 0;
  }
  if (s.kind != PRRU_LOAD_TABLE || s.nrows < 1 || !s.rows || s.nact != m.mech->nact) abort();
  const double *r = s.rows;
  const int row = s.nact + 7; /* t, the forces, fp, mp */
  for (int i = 1; i < s.nrows; i++)
    if (!(r[row * i] > r[row * (i - 1)])) abort();
  check_finite(&s, r[0] - 1.0);
  check_finite(&s, -HUGE_VAL);
  check_finite(&s, HUGE_VAL);
  for (int i = 0; i < s.nrows; i++) {
    check_finite(&s, r[row * i]);
    if (i + 1 < s.nrows) {
      /* Interior points, computed without overflowing for any finite pair. */
      check_finite(&s, 0.5 * r[row * i] + 0.5 * r[row * (i + 1)]);
      check_finite(&s, 0.25 * r[row * i] + 0.75 * r[row * (i + 1)]);
      check_finite(&s, nextafter(r[row * i], HUGE_VAL));
    }
  }
  prru_schedule_free(&s);
  return 0;
}
