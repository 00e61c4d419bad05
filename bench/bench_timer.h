/* Timing primitives of prru_bench: a monotonic nanosecond clock and the
 * median / min / max of a set of repetitions.
 *
 * CLOCK_MONOTONIC rather than CLOCK_PROCESS_CPUTIME_ID: it is a vDSO call
 * (tens of ns, no syscall), it does not jump with NTP slews, and a batch is
 * long enough (milliseconds) that its resolution does not matter. */
#ifndef PRRU_BENCH_TIMER_H
#define PRRU_BENCH_TIMER_H

#include <stdlib.h>
#include <time.h>

static inline double bench_now_ns(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

typedef struct {
  double median, min, max; /* over the repetitions */
} bench_stats;

static int bench_cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Sorts v in place. For an even count the median is the mean of the two
 * middle values, so two repetitions do not silently report the faster one. */
static inline bench_stats bench_stats_of(double *v, int n)
{
  bench_stats s;
  qsort(v, (size_t)n, sizeof v[0], bench_cmp_double);
  s.min = v[0];
  s.max = v[n - 1];
  s.median = (n % 2) ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return s;
}

#endif
