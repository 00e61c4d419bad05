/* w_R over a (q1, q2) grid with POSIX threads. Rows (fixed q1) are handed
 * out one at a time under a mutex: a row is n2 evaluations, so the lock is
 * negligible, and a thread that is descheduled for a while (the machine
 * shared) does not leave its static share of rows to the end. Each row is
 * evaluated in blocks of points by the batched kernels and prru_dme_batch,
 * which cost the same at every point. */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "prru_dme.h"
#include "prru_f_batch.h"

void prru_map_options_default(prru_map_options *o)
{
  o->nthreads = 2;
  o->progress = NULL;
  o->ctx = NULL;
  o->interrupt = NULL;
  o->precision = PRRU_PRECISION_DOUBLE;
}

const char *prru_precision_name(int precision)
{
  return precision == PRRU_PRECISION_DOUBLE ? "double" : precision == PRRU_PRECISION_FLOAT ? "float" : NULL;
}

int prru_precision_parse(const char *s)
{
  return !strcmp(s, "double") ? PRRU_PRECISION_DOUBLE : !strcmp(s, "float") ? PRRU_PRECISION_FLOAT : -1;
}

int prru_precision_available(const prru_model *m, int precision)
{
  if (precision == PRRU_PRECISION_DOUBLE) return PRRU_OK;
  /* The float batched kernels are the build's model's, with its numbers. */
  if (precision == PRRU_PRECISION_FLOAT && m->kernels == &prru_kernels_specialised) return PRRU_OK;
  return PRRU_EINPUT;
}

double prru_map_axis(double lo, double hi, int n, int i)
{
  return (lo * (double)(n - 1 - i) + hi * (double)i) / (double)(n - 1);
}

int prru_map_check(const prru_map_grid *g)
{
  if (!(isfinite(g->q1_lo) && isfinite(g->q1_hi) && isfinite(g->q2_lo) && isfinite(g->q2_hi) &&
        isfinite(g->q3)))
    return PRRU_EINPUT;
  if (g->n1 < 2 || g->n2 < 2 || !(g->q1_lo < g->q1_hi) || !(g->q2_lo < g->q2_hi))
    return PRRU_EINPUT;
  /* The spacing must be representable (1e308 - -1e308 is not). */
  if (!isfinite(g->q1_hi - g->q1_lo) || !isfinite(g->q2_hi - g->q2_lo)) return PRRU_EINPUT;
  /* k = i n2 + j must fit a long and the outputs an allocation. */
  if ((double)g->n1 * (double)g->n2 > 1e10) return PRRU_EINPUT;
  return PRRU_OK;
}

typedef struct {
  const prru_model *m;
  const prru_map_grid *g;
  double *w;
  unsigned char *st;
  const prru_map_options *o;
  pthread_mutex_t lock;
  int next_row, row_end, stop; /* rows next_row .. row_end - 1 are left */
  int row_begin;               /* w[0], st[0] belong to this row's first point */
  int home;                    /* prru_map_home_mode */
  double L;                    /* prru_length_scale */
  long done;
} map_job;

/* Points per call of the batched kernel: its outputs (d, J_d, M, J_P; 34
 * doubles a point with three actuators) stay in the first-level cache. */
#define MAP_BLOCK 128

/* A worker's batch: q and the batched kernel's outputs, rows of MAP_BLOCK;
 * prru_dme_batch's scratch and the statuses when the caller wants none. */
typedef struct {
  double q[3 * MAP_BLOCK], d[PRRU_MAX_ACT * MAP_BLOCK], Jd[3 * PRRU_MAX_ACT * MAP_BLOCK],
      M[9 * MAP_BLOCK], JP[18 * MAP_BLOCK];
  unsigned char st[MAP_BLOCK];
  prru_dme_batch_ws ws;
  /* --precision float: the float kernels' inputs and outputs, and the
   * points whose status float leaves to double (their index, w_R and
   * status there). */
  float qf[3 * MAP_BLOCK], df[PRRU_MAX_ACT * MAP_BLOCK], Jdf[3 * PRRU_MAX_ACT * MAP_BLOCK],
      Mf[9 * MAP_BLOCK], JPf[18 * MAP_BLOCK];
  unsigned char sure[MAP_BLOCK], stx[MAP_BLOCK];
  int redo[MAP_BLOCK];
  double wx[MAP_BLOCK];
  prru_dme_batch_wsf wsf;
} map_block;

typedef struct {
  map_job *job;
  map_block *block;
  int is_caller;
} map_worker;

/* Row `row` of the grid, points c0 .. c0 + n - 1 (n <= MAP_BLOCK), each as
 * prru_dme_eval evaluates it and classified by prru_mode_status: the
 * kernels' part (prru_ik_jd, prru_mass, prru_platform_jacobian) from the
 * batched dme_terms, the rest from prru_dme_batch, both bit for bit the
 * scalar path. */
/* The double path for n points of q (rows of n, in b->q): the kernels' part
 * (prru_ik_jd, prru_mass, prru_platform_jacobian) from the batched
 * dme_terms, the rest from prru_dme_batch, both bit for bit the scalar
 * path; w_R and status out. */
static void map_points_double(map_job *j, map_block *b, int n, double *w, unsigned char *st)
{
  KERNEL(j->m, batch_dme_terms)(j->m->kernel_params, n, b->q, b->d, b->Jd, b->M, b->JP);
  const int na = j->m->mech->nact;
  prru_dme_batch(na, n, b->d, b->Jd, b->M, b->JP, j->L, j->m->jd_rcond_min, j->home, &b->ws, w, st, NULL,
                 NULL);
  /* The stroke ends bound the workspace as the reach does (the scalar
   * path's prru_check_regular tests it in the same place). */
  for (int c = 0; c < n; c++) {
    if (st[c] == PRRU_EUNREACHABLE) continue;
    double dc[PRRU_MAX_ACT];
    for (int i = 0; i < na; i++) dc[i] = b->d[(long)i * n + c];
    if (prru_stroke_actuator(j->m, dc) >= 0) st[c] = PRRU_ESTROKE, w[c] = NAN;
  }
}

/* Whether float's sliders d (rows of n, point c) are inside the stroke by
 * more than their error: the float kernels' d is within 16 u of the sum of
 * its terms' magnitudes (tests/test_float_kernels.c), q3 and a few link
 * lengths, i.e. |d| + 4 L; the margin takes 16 times that. */
static int stroke_clear(const prru_model *m, const float *d, int n, int c, double L)
{
  for (int i = 0; i < m->mech->nact; i++) {
    const double di = d[(long)i * n + c], e = 256.0 * FLT_EPSILON * (fabs(di) + 4.0 * L);
    if (!(di - e >= m->mech->d_min[i] && di + e <= m->mech->d_max[i])) return 0;
  }
  return 1;
}

/* The float path: every point through the float kernels and
 * prru_dme_batch_f; the points whose float status is not surely double's
 * (sure[c] 0, or a slider within its error of a stroke end) again through
 * the double path, which then gives their status and w_R. So every status
 * is the double path's, and only the points near a threshold (and those
 * not ok) cost a double evaluation too. */
static void map_points_float(map_job *j, map_block *b, int n, double *w, unsigned char *st)
{
  for (int c = 0; c < 3 * n; c++) b->qf[c] = (float)b->q[c];
  prru_f_batch_dme_terms(n, b->qf, b->df, b->Jdf, b->Mf, b->JPf);
  prru_dme_batch_f(j->m->mech->nact, n, b->df, b->Jdf, b->Mf, b->JPf, j->L, j->m->jd_rcond_min, j->home, &b->wsf, w, st,
                   b->sure);
  int nx = 0;
  for (int c = 0; c < n; c++)
    if (!b->sure[c] || !stroke_clear(j->m, b->df, n, c, j->L)) b->redo[nx++] = c;
  if (nx == 0) return;
  /* The points to redo, compacted into rows of nx (in place: redo[x] >= x). */
  for (int r = 0; r < 3; r++)
    for (int x = 0; x < nx; x++) b->q[(long)r * nx + x] = b->q[(long)r * n + b->redo[x]];
  map_points_double(j, b, nx, b->wx, b->stx);
  for (int x = 0; x < nx; x++) {
    w[b->redo[x]] = b->wx[x];
    st[b->redo[x]] = b->stx[x];
  }
}

/* Row `row` of the grid, points c0 .. c0 + n - 1 (n <= MAP_BLOCK), each as
 * prru_dme_eval evaluates it and classified by prru_mode_status. */
static void map_block_eval(map_job *j, map_block *b, int row, int c0, int n)
{
  const prru_map_grid *g = j->g;
  const double q1 = prru_map_axis(g->q1_lo, g->q1_hi, g->n1, row);
  for (int c = 0; c < n; c++) {
    b->q[c] = q1;
    b->q[n + c] = prru_map_axis(g->q2_lo, g->q2_hi, g->n2, c0 + c);
    b->q[2 * n + c] = g->q3;
  }
  const long k = (long)(row - j->row_begin) * g->n2 + c0;
  unsigned char *st = j->st ? j->st + k : b->st;
  if (j->o->precision == PRRU_PRECISION_FLOAT)
    map_points_float(j, b, n, j->w + k, st);
  else
    map_points_double(j, b, n, j->w + k, st);
}

/* The next row to do, or -1 when there is none or the map was stopped. */
static int take_row(map_job *j, long finished_points)
{
  pthread_mutex_lock(&j->lock);
  j->done += finished_points;
  if (j->o->interrupt && *j->o->interrupt) j->stop = 1;
  int row = (j->stop || j->next_row >= j->row_end) ? -1 : j->next_row++;
  pthread_mutex_unlock(&j->lock);
  return row;
}

/* The caller's progress report; a non-zero answer stops the map. */
static void report_progress(map_job *j)
{
  const long total = (long)(j->row_end - j->row_begin) * j->g->n2;
  pthread_mutex_lock(&j->lock);
  long done = j->done;
  pthread_mutex_unlock(&j->lock);
  if (j->o->progress(done, total, j->o->ctx)) {
    pthread_mutex_lock(&j->lock);
    j->stop = 1;
    pthread_mutex_unlock(&j->lock);
  }
}

static void *map_worker_run(void *arg)
{
  map_worker *w = arg;
  map_job *j = w->job;
  const prru_map_grid *g = j->g;
  const int reports = w->is_caller && j->o->progress;
  int reported = 0;
  int row = take_row(j, 0);
  while (row >= 0) {
    for (int c0 = 0; c0 < g->n2; c0 += MAP_BLOCK)
      map_block_eval(j, w->block, row, c0, g->n2 - c0 < MAP_BLOCK ? g->n2 - c0 : MAP_BLOCK);
    row = take_row(j, g->n2);
    if (reports) {
      report_progress(j);
      reported = 1;
    }
  }
  /* A caller that got no row at all (the other threads took every row
   * while it was descheduled) still reports once, so that the callback
   * can always stop the map. */
  if (reports && !reported) report_progress(j);
  return NULL;
}

int prru_map_eval_rows(const prru_model *m, const prru_map_grid *g, int row_begin, int row_end,
                       const prru_map_options *o, double *w_R, unsigned char *status)
{
  if (prru_map_check(g) != PRRU_OK || o->nthreads < 1 || o->nthreads > 256) return PRRU_EINPUT;
  if (prru_precision_available(m, o->precision) != PRRU_OK) return PRRU_EINPUT;
  if (row_begin < 0 || row_end > g->n1 || row_begin >= row_end) return PRRU_EINPUT;
  const int nrows = row_end - row_begin;
  int nt = o->nthreads > nrows ? nrows : o->nthreads;
  map_job job = {m, g, w_R, status, o, PTHREAD_MUTEX_INITIALIZER, row_begin, row_end, 0, row_begin,
                 prru_map_home_mode(m, g), prru_length_scale(m->mech), 0};
  map_worker *workers = calloc((size_t)nt, sizeof *workers);
  pthread_t *tid = calloc((size_t)nt, sizeof *tid);
  int rc = PRRU_OK, started = 0;
  if (!workers || !tid) rc = PRRU_ENOMEM;
  for (int t = 0; t < nt && rc == PRRU_OK; t++) {
    workers[t].job = &job;
    workers[t].is_caller = t == 0;
    /* 64-byte aligned (malloc gives 16), as PRRU_ALIGN64. */
    void *p = NULL;
    if (posix_memalign(&p, 64, sizeof(map_block)) != 0) p = NULL;
    workers[t].block = p;
    if (!workers[t].block) rc = PRRU_ENOMEM;
  }
  if (rc == PRRU_OK) {
    for (int t = 1; t < nt; t++) {
      if (pthread_create(&tid[t], NULL, map_worker_run, &workers[t]) != 0) break;
      started++;
    }
    /* With fewer threads than asked for the caller still does every row
     * that is left: slower, never wrong. */
    map_worker_run(&workers[0]);
    for (int t = 1; t <= started; t++) pthread_join(tid[t], NULL);
    if (job.stop) rc = PRRU_EINTERRUPTED;
  }
  if (workers)
    for (int t = 0; t < nt; t++) free(workers[t].block);
  free(workers);
  free(tid);
  pthread_mutex_destroy(&job.lock);
  if (rc == PRRU_OK && o->progress) o->progress(job.done, job.done, o->ctx);
  return rc;
}

int prru_map_home_mode(const prru_model *m, const prru_map_grid *g)
{
  double d[PRRU_MAX_ACT], Jd[PRRU_MAX_ACT * 3];
  KERNEL(m, ik_jd)(m->kernel_params, (const double[3]){0.0, 0.0, g->q3}, d, Jd);
  return prru_assembly_mode(d, Jd, m->mech->nact);
}

int prru_map_eval(const prru_model *m, const prru_map_grid *g, const prru_map_options *o,
                  double *w_R, unsigned char *status, prru_map_summary *sum)
{
  if (prru_map_check(g) != PRRU_OK) return PRRU_EINPUT;
  /* The summary needs the statuses (NaN alone does not tell the kinds). */
  unsigned char *st = status;
  if (!st && sum) st = malloc((size_t)g->n1 * (size_t)g->n2);
  if (!st && sum) return PRRU_ENOMEM;
  int rc = prru_map_eval_rows(m, g, 0, g->n1, o, w_R, st);
  if (rc == PRRU_OK && sum) prru_map_summarize(g, w_R, st, sum);
  if (st != status) free(st);
  return rc;
}

void prru_map_summarize(const prru_map_grid *g, const double *w_R, const unsigned char *status,
                        prru_map_summary *sum)
{
  long n = (long)g->n1 * g->n2;
  double acc = 0.0, acc_log = 0.0;
  sum->n_points = n;
  sum->n_ok = sum->n_singular = sum->n_unreachable = sum->n_other_mode = 0;
  sum->w_min = sum->w_max = NAN;
  sum->w_min_q[0] = sum->w_min_q[1] = sum->w_max_q[0] = sum->w_max_q[1] = NAN;
  for (long k = 0; k < n; k++) {
    if (status[k] == PRRU_OK) {
      double w = w_R[k];
      int i = (int)(k / g->n2), j = (int)(k % g->n2);
      if (sum->n_ok == 0 || w < sum->w_min) {
        sum->w_min = w;
        sum->w_min_q[0] = prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i);
        sum->w_min_q[1] = prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j);
      }
      if (sum->n_ok == 0 || w > sum->w_max) {
        sum->w_max = w;
        sum->w_max_q[0] = prru_map_axis(g->q1_lo, g->q1_hi, g->n1, i);
        sum->w_max_q[1] = prru_map_axis(g->q2_lo, g->q2_hi, g->n2, j);
      }
      acc += w - 1.0;
      acc_log += log(w);
      sum->n_ok++;
    } else if (status[k] == PRRU_EUNREACHABLE || status[k] == PRRU_ESTROKE) {
      sum->n_unreachable++;
    } else {
      sum->n_other_mode += status[k] == PRRU_DME_OTHER_MODE;
      sum->n_singular++;
    }
  }
  sum->index = sum->n_ok ? acc / (double)sum->n_ok : NAN;
  sum->index_log = sum->n_ok ? acc_log / (double)sum->n_ok : NAN;
  sum->singular_fraction = (double)(sum->n_singular + sum->n_unreachable) / (double)n;
}
