/* Time-optimal parameterisation of waypoint paths by reachability
 * analysis (TOPP-RA; prru_traj.h states the method). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prru_traj.h"
#include "internal.h"

/* The linear programmes' bounding box: a vertex on it means the limits do
 * not bound the motion (no force limit acts along the path there). */
#define BOX 1e15
/* A row holds at a vertex when its excess is below this share of the
 * row's terms there (rounding of the 2 x 2 solve and of the terms). */
#define ROW_TOL 1e-9
/* Rows of one interval's programme: force limits at both ends (2 sides),
 * speed at both ends, x >= 0 at both ends, the target set (2), the box (3). */
#define MAX_ROWS (4 * PRRU_MAX_ACT + 9)
/* Points of an interval checked with the exact inverse dynamics. */
#define CHECK_POINTS 8
/* "Active": within this share of a limit. */
#define ACTIVE_TOL 1e-3

/* What the programmes need at one grid point. f = a u + b x + c + h(x)
 * per actuator; h (damping and friction) enters as hc + hs x. */
typedef struct {
  double a[PRRU_MAX_ACT], b[PRRU_MAX_ACT], c[PRRU_MAX_ACT];
  double w[PRRU_MAX_ACT];                      /* dd_i / ds */
  double hs[PRRU_MAX_ACT], hc[PRRU_MAX_ACT];   /* h as hc + hs x */
  double mu_hi[PRRU_MAX_ACT], mu_lo[PRRU_MAX_ACT]; /* tightenings (N) */
  double rho[PRRU_MAX_ACT];                    /* speed tightening factor on x */
} topp_point;

typedef struct {
  double al, be, ga; /* al u + be x <= ga */
} lp_row;

typedef struct {
  const prru_model *m;
  int na; /* m's actuators */
  prru_data *d;
  const prru_limits *lim;
  int N, seg;
  prru_path_side side; /* det J_d's side of the singular set along the path */
  int drives;
  int tangent;        /* how the drives are linearised */
  double tangent_from; /* tangents once x moves less than this (relative) */
  const double *qa, *qb;
  double dq[3];
  topp_point *p;      /* N + 1 */
  double *lo, *hi;    /* controllable sets, N + 1 */
  double *x, *u, *xprev;
  char *msg;
  int msglen;
} topp_ctx;

static const prru_loads NO_LOADS = {{0}, {0}, {0}};

static void path_pose(const topp_ctx *c, double s, double q[3])
{
  for (int k = 0; k < 3; k++) q[k] = c->qa[k] + s * c->dq[k];
}

static int id(const topp_ctx *c, const double q[3], double v, double acc, double f[])
{
  double qd[3], qdd[3];
  for (int k = 0; k < 3; k++) qd[k] = c->dq[k] * v, qdd[k] = c->dq[k] * acc;
  return prru_inverse_dynamics(c->m, c->d, q, qd, qdd, &NO_LOADS, f);
}

int prru_limits_ratio(const prru_model *m, prru_data *d, const prru_limits *lim,
                      const double q[3], const double qd[3], const double qdd[3],
                      double fd[], double dd[], double *ratio, int *which,
                      int *kind)
{
  const int na = m->mech->nact;
  double f[PRRU_MAX_ACT], v[PRRU_MAX_ACT];
  int st = prru_inverse_dynamics(m, d, q, qd, qdd, &NO_LOADS, f);
  if (st != PRRU_OK) return st;
  /* prru_inverse_dynamics leaves J_d in d->Jd: dd = J_d qd. */
  double r = 0;
  int wi = 0, wk = 0;
  for (int i = 0; i < na; i++) {
    v[i] = 0;
    for (int k = 0; k < 3; k++) v[i] += d->Jd[3 * i + k] * qd[k];
    double rf = fabs(f[i]) / lim->force_max[i], rv = fabs(v[i]) / lim->speed_max[i];
    if (rf > r) r = rf, wi = i, wk = 0;
    if (rv > r) r = rv, wi = i, wk = 1;
  }
  if (fd) memcpy(fd, f, (size_t)na * sizeof *f);
  if (dd) memcpy(dd, v, (size_t)na * sizeof *v);
  if (ratio) *ratio = r;
  if (which) *which = wi;
  if (kind) *kind = wk;
  return PRRU_OK;
}

/* "segment K (waypoint K to K+1), s = S (grid point J of N)". */
static int where(const topp_ctx *c, int j, char *buf, size_t len)
{
  return snprintf(buf, len, "segment %d (waypoint %d to %d), s = %.6g (grid point %d of %d)",
                  c->seg + 1, c->seg + 1, c->seg + 2, (double)j / c->N, j, c->N);
}

/* The pose at grid point j: usable, on the same side of the singular
 * locus as the path's start, every slider within its stroke; then its
 * terms a, b, c, w. */
static int point_terms(topp_ctx *c, int j)
{
  double q[3], rc, f0[PRRU_MAX_ACT], f1[PRRU_MAX_ACT], f2[PRRU_MAX_ACT];
  char at[160];
  topp_point *p = &c->p[j];
  path_pose(c, (double)j / c->N, q);
  where(c, j, at, sizeof at);
  int st = prru_traj_pose_ok(c->m, c->d, q, &rc);
  if (st != PRRU_OK)
    return prru_fail(c->msg, c->msglen, PRRU_EINPUT, "%s: q = (%.9g, %.9g, %.9g) is %s", at,
                     q[0], q[1], q[2],
                     st == PRRU_EUNREACHABLE ? "outside the workspace"
                     : st == PRRU_ESINGULAR  ? "at a singularity (J_d singular)"
                                             : prru_strerror(st));
  if (prru_path_side_crossed(&c->side, c->d->Jd, c->na))
    return prru_fail(c->msg, c->msglen, PRRU_EINPUT,
                     "%s: the path crosses a singularity before q = (%.9g, %.9g, %.9g) (det J_d "
                     "changes sign)", at, q[0], q[1], q[2]);
  for (int i = 0; i < c->na; i++) {
    if (!(c->d->d[i] >= c->lim->d_min[i] && c->d->d[i] <= c->lim->d_max[i]))
      return prru_fail(c->msg, c->msglen, PRRU_EINPUT,
                       "%s: slider %d at d = %.9g m is outside its stroke [%g, %g] m", at, i + 1,
                       c->d->d[i], c->lim->d_min[i], c->lim->d_max[i]);
    p->w[i] = 0;
    for (int k = 0; k < 3; k++) p->w[i] += c->d->Jd[3 * i + k] * c->dq[k];
  }
  /* Inverse dynamics is affine in qdd and, without the drives' odd terms,
   * even and quadratic in qd: c at rest, a from a unit s'', b from the
   * even part at s' = +-1. */
  if ((st = id(c, q, 0, 0, f0)) != PRRU_OK || (st = id(c, q, 0, 1, f1)) != PRRU_OK ||
      (st = id(c, q, 1, 0, f2)) != PRRU_OK)
    goto refused;
  for (int i = 0; i < c->na; i++) p->c[i] = f0[i], p->a[i] = f1[i] - f0[i], p->b[i] = f2[i];
  if ((st = id(c, q, -1, 0, f2)) != PRRU_OK) goto refused;
  for (int i = 0; i < c->na; i++) {
    p->b[i] = 0.5 * (p->b[i] + f2[i]) - p->c[i];
    p->hs[i] = p->hc[i] = p->mu_hi[i] = p->mu_lo[i] = 0;
    p->rho[i] = 1;
  }
  return PRRU_OK;
refused:
  return prru_fail(c->msg, c->msglen, st, "%s: q = (%.9g, %.9g, %.9g): inverse dynamics refuses "
                   "the pose (%s)", at, q[0], q[1], q[2], prru_strerror(st));
}

/* The drives' term h (the odd part of inverse dynamics in s') at grid
 * point j and s'^2 = x. */
static int drive_term(topp_ctx *c, int j, double x, double h[])
{
  double q[3], fp[PRRU_MAX_ACT], fm[PRRU_MAX_ACT];
  const double v = sqrt(x);
  path_pose(c, (double)j / c->N, q);
  int st = id(c, q, v, 0, fp);
  if (st == PRRU_OK) st = id(c, q, -v, 0, fm);
  if (st != PRRU_OK) return st;
  for (int i = 0; i < c->na; i++) h[i] = 0.5 * (fp[i] - fm[i]);
  return PRRU_OK;
}

/* h at grid point j as its secant through x = 0, h(x0) / x0 x (h(0) =
 * 0): exact at 0 and x0, below a concave h between them, so never
 * stricter than the drives near rest. */
static int drive_secant(topp_ctx *c, int j, double x0)
{
  double h0[PRRU_MAX_ACT];
  int st = drive_term(c, j, x0, h0);
  if (st != PRRU_OK) return st;
  for (int i = 0; i < c->na; i++) c->p[j].hs[i] = h0[i] / x0, c->p[j].hc[i] = 0;
  return PRRU_OK;
}

/* h at grid point j as its tangent at x0, h(x0) + h'(x0) (x - x0): exact
 * at x0, and a Newton step for the passes' fixed point (secants alone
 * converged by 3e-3 in 60 passes where friction nearly balances the force
 * limit), but above a concave h everywhere else: far from x0 it can make
 * a feasible path look infeasible, so tangents take over only once x has
 * settled (solve_segment). h' by central differences over 1e-4 x0, whose error
 * (1e-8 of h'' x0^2) only slows the iteration down. */
static int drive_tangent(topp_ctx *c, int j, double x0)
{
  double h0[PRRU_MAX_ACT], hp[PRRU_MAX_ACT], hm[PRRU_MAX_ACT];
  const double dx = 1e-4 * x0;
  int st = drive_term(c, j, x0, h0);
  if (st == PRRU_OK) st = drive_term(c, j, x0 + dx, hp);
  if (st == PRRU_OK) st = drive_term(c, j, x0 - dx, hm);
  if (st != PRRU_OK) return st;
  for (int i = 0; i < c->na; i++) {
    c->p[j].hs[i] = (hp[i] - hm[i]) / (2 * dx);
    c->p[j].hc[i] = h0[i] - c->p[j].hs[i] * x0;
  }
  return PRRU_OK;
}

/* The largest x the speed limits allow at grid point j. */
static double speed_bound(const topp_ctx *c, int j)
{
  double xs = INFINITY;
  for (int i = 0; i < c->na; i++) {
    double w = fabs(c->p[j].w[i]), v = c->lim->speed_max[i];
    if (w > 0 && isfinite(v)) xs = fmin(xs, c->p[j].rho[i] * (v / w) * (v / w));
  }
  return xs;
}

/* Force rows of point p for an interval whose u multiplies the point's x
 * by ku and adds 2 Delta u (ku = 0 at the interval's start, 1 at its end). */
static int force_rows(const topp_ctx *c, const topp_point *p, double two_delta, lp_row *r)
{
  int n = 0;
  for (int i = 0; i < c->na; i++) {
    const double F = c->lim->force_max[i];
    if (!isfinite(F)) continue;
    const double B = p->b[i] + p->hs[i], A = p->a[i] + two_delta * B;
    const double C = p->c[i] + p->hc[i];
    r[n++] = (lp_row){A, B, F - p->mu_hi[i] - C};
    r[n++] = (lp_row){-A, -B, F - p->mu_lo[i] + C};
  }
  return n;
}

/* The rows of interval j (from grid point j to j + 1) with the target set
 * [klo, khi] for x_{j+1}. */
static int interval_rows(const topp_ctx *c, int j, double klo, double khi, lp_row *r)
{
  const double t2 = 2.0 / c->N;
  int n = force_rows(c, &c->p[j], 0, r);
  n += force_rows(c, &c->p[j + 1], t2, r + n);
  double xs0 = speed_bound(c, j), xs1 = speed_bound(c, j + 1);
  if (isfinite(xs0)) r[n++] = (lp_row){0, 1, xs0};
  if (isfinite(xs1)) r[n++] = (lp_row){t2, 1, xs1};
  r[n++] = (lp_row){0, -1, 0};
  r[n++] = (lp_row){-t2, -1, 0};
  r[n++] = (lp_row){t2, 1, khi};
  r[n++] = (lp_row){-t2, -1, -klo};
  r[n++] = (lp_row){1, 0, BOX};
  r[n++] = (lp_row){-1, 0, BOX};
  r[n++] = (lp_row){0, 1, BOX};
  return n;
}

static int row_holds(const lp_row *r, double u, double x)
{
  const double lhs = r->al * u + r->be * x;
  return lhs - r->ga <= ROW_TOL * (fabs(r->al * u) + fabs(r->be * x) + fabs(r->ga));
}

/* max of cu u + cx x over the rows, by enumerating the vertices (two
 * variables, a few dozen rows). 0 and the optimum, or -1 when empty. */
static int lp_max(const lp_row *r, int n, double cu, double cx, double *u, double *x)
{
  double best = -INFINITY;
  for (int i = 0; i < n; i++)
    for (int k = i + 1; k < n; k++) {
      const double det = r[i].al * r[k].be - r[i].be * r[k].al;
      const double sc = fabs(r[i].al * r[k].be) + fabs(r[i].be * r[k].al);
      if (!(fabs(det) > 1e-14 * sc)) continue;
      const double vu = (r[i].ga * r[k].be - r[i].be * r[k].ga) / det;
      const double vx = (r[i].al * r[k].ga - r[i].ga * r[k].al) / det;
      if (!isfinite(vu) || !isfinite(vx)) continue;
      int ok = 1;
      for (int l = 0; l < n && ok; l++) ok = row_holds(&r[l], vu, vx);
      if (ok && cu * vu + cx * vx > best) best = cu * vu + cx * vx, *u = vu, *x = vx;
    }
  return isfinite(best) ? 0 : -1;
}

/* The actuator whose static load at grid point j comes nearest its limit
 * (the limit to name where the path is infeasible). */
static void static_load(const topp_ctx *c, int j, char *buf, size_t len)
{
  int wi = 0;
  double r = -1;
  for (int i = 0; i < c->na; i++) {
    double ri = fabs(c->p[j].c[i]) / c->lim->force_max[i];
    if (ri > r) r = ri, wi = i;
  }
  snprintf(buf, len, "force_max of actuator %d: its static load there is %.6g N, its limit %.6g N%s",
           wi + 1, c->p[j].c[wi], c->lim->force_max[wi], r > 1 ? "" : " (the largest share)");
}

static int infeasible(const topp_ctx *c, int j, const char *why)
{
  char at[160], lim[200];
  where(c, j, at, sizeof at);
  static_load(c, j, lim, sizeof lim);
  return prru_fail(c->msg, c->msglen, PRRU_EINPUT, "infeasible at %s: %s; %s", at, why, lim);
}

/* At each grid point on its own: some (u, x >= 0) holds the forces within
 * their limits (rows at the point alone). The first point without one. */
static int pointwise(const topp_ctx *c)
{
  lp_row r[MAX_ROWS];
  for (int j = 0; j <= c->N; j++) {
    /* At a segment's ends the robot is at rest. */
    const int rest = j == 0 || j == c->N;
    int n = force_rows(c, &c->p[j], 0, r);
    r[n++] = (lp_row){0, -1, 0};
    r[n++] = (lp_row){1, 0, BOX};
    r[n++] = (lp_row){-1, 0, BOX};
    r[n++] = (lp_row){0, 1, rest ? 0 : BOX};
    double u, x;
    if (lp_max(r, n, 0, 1, &u, &x) != 0)
      return infeasible(c, j, rest ? "no acceleration holds the forces within force_max at rest"
                                   : "no acceleration holds the forces within force_max at any speed");
  }
  return PRRU_OK;
}

/* Backward pass: the controllable sets, from rest at the segment's end. */
static int backward(topp_ctx *c)
{
  lp_row r[MAX_ROWS];
  c->lo[c->N] = c->hi[c->N] = 0;
  for (int j = c->N - 1; j >= 0; j--) {
    int n = interval_rows(c, j, c->lo[j + 1], c->hi[j + 1], r);
    double u, xhi, xlo;
    if (lp_max(r, n, 0, 1, &u, &xhi) != 0 || lp_max(r, n, 0, -1, &u, &xlo) != 0)
      return infeasible(c, j, "no admissible motion from here comes to rest at the segment's end");
    c->lo[j] = fmax(0.0, xlo);
    c->hi[j] = xhi;
  }
  if (c->lo[0] > 0)
    return infeasible(c, 0, "the robot cannot start from rest here within the limits");
  return PRRU_OK;
}

/* Forward pass: from rest, the largest u keeping x_{j+1} controllable. */
static int forward(topp_ctx *c)
{
  lp_row r[MAX_ROWS];
  const double t2 = 2.0 / c->N;
  c->x[0] = 0;
  for (int j = 0; j < c->N; j++) {
    const double x = c->x[j];
    int n = interval_rows(c, j, c->lo[j + 1], c->hi[j + 1], r);
    double ulo = -INFINITY, uhi = INFINITY;
    for (int k = 0; k < n; k++) {
      const double rhs = r[k].ga - r[k].be * x;
      if (r[k].al > 0) uhi = fmin(uhi, rhs / r[k].al);
      if (r[k].al < 0) ulo = fmax(ulo, rhs / r[k].al);
    }
    /* x_j on the edge of K_j leaves an interval empty by rounding: the
     * smaller end is the safer acceleration (the check judges it). */
    double u = fmin(uhi, fmax(ulo, uhi));
    if (!isfinite(u) || fabs(u) >= BOX)
      return infeasible(c, j, "the limits do not bound the acceleration here");
    c->x[j + 1] = j + 1 == c->N ? 0.0 : fmax(0.0, x + t2 * u);
  }
  for (int j = 0; j < c->N; j++) c->u[j] = (c->x[j + 1] - c->x[j]) / t2;
  c->u[c->N] = 0;
  for (int j = 1; j < c->N; j++)
    if (!(c->x[j] > 0))
      return infeasible(c, j, "the fastest motion within the limits comes to a stop here");
  return PRRU_OK;
}

/* The interval's state at fraction sg of interval j (x linear in s). */
static int state_at(topp_ctx *c, int j, double sg, double f[], double v[])
{
  const double s = (j + sg) / c->N, x = c->x[j] + sg * (c->x[j + 1] - c->x[j]);
  double q[3], qd[3], qdd[3];
  path_pose(c, s, q);
  for (int i = 0; i < 3; i++) qd[i] = c->dq[i] * sqrt(fmax(x, 0.0)), qdd[i] = c->dq[i] * c->u[j];
  int st = prru_limits_ratio(c->m, c->d, c->lim, q, qd, qdd, f, v, NULL, NULL, NULL);
  if (st != PRRU_OK) {
    char at[160];
    where(c, j, at, sizeof at);
    return prru_fail(c->msg, c->msglen, st, "%s: inverse dynamics refuses the pose at s = %.9g (%s)",
                     at, s, prru_strerror(st));
  }
  return PRRU_OK;
}

/* Slider i's speed over the Coulomb velocity at fraction sg of interval
 * j, with dd_i/ds interpolated linearly between the grid points: only
 * where to look, not a checked value. */
static double coulomb_arg(const topp_ctx *c, int j, int i, double sg)
{
  const double w = c->p[j].w[i] + sg * (c->p[j + 1].w[i] - c->p[j].w[i]);
  const double x = c->x[j] + sg * (c->x[j + 1] - c->x[j]);
  return w * sqrt(fmax(x, 0.0)) / c->m->mech->coulomb_velocity;
}

/* The points of interval j checked with the exact inverse dynamics, in
 * increasing order: CHECK_POINTS + 1 uniform in s, where the forces are
 * smooth in s, and, where a slider's speed passes through the ramp of
 * its smoothed Coulomb force (tanh of the speed over coulomb_velocity:
 * in an interval leaving or reaching rest it rises to its full value
 * within a small fraction of the interval), the points where the speed
 * crosses +-2^k coulomb_velocity, k = -4..4, so that the ramp is
 * resolved too. */
#define RAMP_POINTS 9
#define MAX_SAMPLES (CHECK_POINTS + 1 + 2 * RAMP_POINTS * PRRU_MAX_ACT)
static int sample_points(const topp_ctx *c, int j, double *sg)
{
  int n = 0;
  for (int k = 0; k <= CHECK_POINTS; k++) sg[n++] = (double)k / CHECK_POINTS;
  if (!(c->m->mech->coulomb_velocity > 0)) return n;
  for (int i = 0; i < c->na; i++) {
    if (c->m->mech->coulomb[i] == 0) continue;
    const double z0 = coulomb_arg(c, j, i, 0), z1 = coulomb_arg(c, j, i, 1);
    for (int k = 0; k < 2 * RAMP_POINTS; k++) {
      const double zt = (k % 2 ? -1 : 1) * ldexp(1.0, k / 2 - RAMP_POINTS / 2);
      if (!((z0 - zt) * (z1 - zt) < 0)) continue;
      double lo = 0, hi = 1;
      for (int b = 0; b < 60; b++) {
        const double mid = 0.5 * (lo + hi);
        if ((coulomb_arg(c, j, i, mid) - zt) * (z0 - zt) > 0)
          lo = mid;
        else
          hi = mid;
      }
      sg[n++] = 0.5 * (lo + hi);
    }
  }
  for (int a = 1; a < n; a++)
    for (int b = a; b > 0 && sg[b] < sg[b - 1]; b--) {
      const double t = sg[b];
      sg[b] = sg[b - 1], sg[b - 1] = t;
    }
  return n;
}

/* The largest |f_i| on [lo, hi] of interval j near its sample mid, by
 * golden sections to 1e-12 of the interval: the samples resolve the
 * forces' shape, so one local maximum lies between a best sample's
 * neighbours. *sg, *f: where and the signed force there. */
static int refine_force(topp_ctx *c, int j, int i, double lo, double hi, double *sg, double *f)
{
  const double g = 0.5 * (sqrt(5.0) - 1);
  double fa[PRRU_MAX_ACT], fb[PRRU_MAX_ACT], v[PRRU_MAX_ACT];
  double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
  int st = state_at(c, j, a, fa, v);
  if (st == PRRU_OK) st = state_at(c, j, b, fb, v);
  double ya = fabs(fa[i]), yb = fabs(fb[i]), sa = fa[i], sb = fb[i];
  while (st == PRRU_OK && hi - lo > 1e-12) {
    if (ya >= yb) {
      hi = b, b = a, yb = ya, sb = sa;
      a = hi - g * (hi - lo);
      st = state_at(c, j, a, fa, v);
      ya = fabs(fa[i]), sa = fa[i];
    } else {
      lo = a, a = b, ya = yb, sa = sb;
      b = lo + g * (hi - lo);
      st = state_at(c, j, b, fb, v);
      yb = fabs(fb[i]), sb = fb[i];
    }
  }
  if (st != PRRU_OK) return st;
  if (fabs(sa) > fabs(*f)) *sg = a, *f = sa;
  if (fabs(sb) > fabs(*f)) *sg = b, *f = sb;
  return PRRU_OK;
}

/* Exact inverse dynamics at the sample points of every interval
 * (sample_points), and each actuator's force maximised between the
 * neighbours of its largest sample wherever that sample is within
 * ACTIVE_TOL of the limit (the profile presses against its limits
 * on nearly every interval, and between samples the force can rise
 * above both): where a limit is exceeded by more than
 * PRRU_TOPP_CHECK_TOL, tighten it at both ends by the excess. *excess:
 * the largest relative excess; *active: intervals with a limit within
 * ACTIVE_TOL at an end. */
static int check(topp_ctx *c, double *excess, int *active)
{
  *excess = 0;
  *active = 0;
  for (int j = 0; j < c->N; j++) {
    double sg[MAX_SAMPLES], fbig[PRRU_MAX_ACT] = {0}, vbig[PRRU_MAX_ACT] = {0};
    int best[PRRU_MAX_ACT] = {0}, act = 0;
    const int n = sample_points(c, j, sg);
    for (int k = 0; k < n; k++) {
      double f[PRRU_MAX_ACT], v[PRRU_MAX_ACT];
      int st = state_at(c, j, sg[k], f, v);
      if (st != PRRU_OK) return st;
      for (int i = 0; i < c->na; i++) {
        if (fabs(f[i]) > fabs(fbig[i])) fbig[i] = f[i], best[i] = k;
        vbig[i] = fmax(vbig[i], fabs(v[i]));
        if ((sg[k] == 0 || sg[k] == 1) &&
            (fabs(f[i]) >= (1 - ACTIVE_TOL) * c->lim->force_max[i] ||
             fabs(v[i]) >= (1 - ACTIVE_TOL) * c->lim->speed_max[i]))
          act = 1;
      }
    }
    for (int i = 0; i < c->na; i++) {
      const double F = c->lim->force_max[i], V = c->lim->speed_max[i];
      if (fabs(fbig[i]) >= (1 - ACTIVE_TOL) * F) {
        const int k = best[i];
        double at = sg[k];
        int st = refine_force(c, j, i, sg[k > 0 ? k - 1 : 0], sg[k < n - 1 ? k + 1 : n - 1], &at, &fbig[i]);
        if (st != PRRU_OK) return st;
      }
      const double ef = fabs(fbig[i]) - F, rv = vbig[i] / V;
      if (ef > PRRU_TOPP_CHECK_TOL * F) {
        *excess = fmax(*excess, ef / F);
        for (int e = j; e <= j + 1; e++) {
          double *mu = fbig[i] > 0 ? &c->p[e].mu_hi[i] : &c->p[e].mu_lo[i];
          *mu += ef + PRRU_TOPP_CHECK_TOL * F;
        }
      }
      if (rv > 1 + PRRU_TOPP_CHECK_TOL) {
        *excess = fmax(*excess, rv - 1);
        for (int e = j; e <= j + 1; e++) c->p[e].rho[i] /= rv * rv * (1 + PRRU_TOPP_CHECK_TOL);
      }
    }
    *active += act;
  }
  return PRRU_OK;
}

/* The drives' rows at the current x, secants or tangents. */
static int linearise(topp_ctx *c)
{
  double xmax = 0;
  for (int j = 0; j <= c->N; j++) xmax = fmax(xmax, c->x[j]);
  for (int j = 1; j < c->N; j++) {
    const double x0 = fmax(c->x[j], 1e-9 * xmax);
    int st = c->tangent ? drive_tangent(c, j, x0) : drive_secant(c, j, x0);
    if (st != PRRU_OK) return st;
  }
  return PRRU_OK;
}

/* Re-linearises the drives at the current x; *change: the largest move
 * of x since the last linearisation, relative to the largest x. */
static int relinearise(topp_ctx *c, double *change)
{
  double xmax = 0, dx = 0;
  for (int j = 0; j <= c->N; j++) xmax = fmax(xmax, c->x[j]);
  for (int j = 0; j <= c->N; j++) dx = fmax(dx, fabs(c->x[j] - c->xprev[j]));
  *change = xmax > 0 ? dx / xmax : 0;
  memcpy(c->xprev, c->x, (size_t)(c->N + 1) * sizeof *c->x);
  if (!c->drives) return PRRU_OK;
  if (*change <= c->tangent_from) c->tangent = 1;
  return linearise(c);
}

static int solve_segment(topp_ctx *c, int *iterations, int *active)
{
  int st;
  for (int j = 0; j <= c->N; j++)
    if ((st = point_terms(c, j)) != PRRU_OK) return st;
  if ((st = pointwise(c)) != PRRU_OK) return st;
  memset(c->xprev, 0, (size_t)(c->N + 1) * sizeof *c->xprev);
  c->tangent = 0;
  c->tangent_from = 0.05;
  /* The first pass leaves the drives out (h = 0); after that each pass
   * linearises them at the previous one's x (secants, then tangents), and
   * the check runs once x has settled (1e-6 relative, or at once without
   * drives). A pass on tangents that finds the path infeasible may owe
   * it to their excess far from x0: back to the last x, on secants until
 * x has settled ten times closer. */
  for (int it = 1; it <= PRRU_TOPP_MAX_ITER; it++) {
    st = backward(c);
    if (st == PRRU_OK) st = forward(c);
    if (st == PRRU_EINPUT && c->tangent) {
      c->tangent = 0;
      c->tangent_from *= 0.1;
      memcpy(c->x, c->xprev, (size_t)(c->N + 1) * sizeof *c->x);
      if ((st = linearise(c)) != PRRU_OK) return st;
      continue;
    }
    if (st != PRRU_OK) return st;
    double change, excess;
    if ((st = relinearise(c, &change)) != PRRU_OK) return st;
    if (c->drives && (it == 1 || change > 1e-6)) continue;
    if ((st = check(c, &excess, active)) != PRRU_OK) return st;
    if (excess <= PRRU_TOPP_CHECK_TOL) {
      *iterations += it;
      return PRRU_OK;
    }
  }
  char at[160];
  where(c, 0, at, sizeof at);
  return prru_fail(c->msg, c->msglen, PRRU_ENOCONV,
                   "segment %d: the profile did not settle within the limits in %d passes "
                   "(force limits barely above what the loads and the drives' friction and "
                   "damping need?)", c->seg + 1, PRRU_TOPP_MAX_ITER);
}

static int has_drives(const prru_model *m)
{
  for (int i = 0; i < m->mech->nact; i++)
    if (m->mech->damping[i] != 0 || m->mech->coulomb[i] != 0) return 1;
  return 0;
}

static int topp_check_args(const prru_model *m, int n, const double *q, const prru_limits *lim,
                           int grid, char *msg, int msglen)
{
  if (!m || !q || !lim) return prru_fail(msg, msglen, PRRU_EINPUT, "no model, waypoints or limits");
  if (n < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "need at least 2 waypoints, got %d", n);
  if (grid != 0 && (grid < 2 || grid > 100000))
    return prru_fail(msg, msglen, PRRU_EINPUT, "grid: %d intervals per segment, need 2 to 100000", grid);
  int forces = 0;
  for (int i = 0; i < m->mech->nact; i++) {
    if (!(lim->force_max[i] > 0) || !(lim->speed_max[i] > 0) || isnan(lim->d_min[i]) ||
        isnan(lim->d_max[i]) || !(lim->d_min[i] < lim->d_max[i]))
      return prru_fail(msg, msglen, PRRU_EINPUT, "limits of actuator %d: force_max and speed_max "
                       "must be > 0 and d_min < d_max", i + 1);
    forces += isfinite(lim->force_max[i]);
  }
  if (!forces)
    return prru_fail(msg, msglen, PRRU_EINPUT, "time-optimal needs a force limit (force_max) on at "
                     "least one actuator: without one the accelerations are unbounded");
  for (int k = 0; k < n; k++) {
    if (!prru_finite_n(q + 3 * k, 3))
      return prru_fail(msg, msglen, PRRU_EINPUT, "waypoint %d is not finite", k + 1);
    if (k > 0 && q[3 * k] == q[3 * k - 3] && q[3 * k + 1] == q[3 * k - 2] &&
        q[3 * k + 2] == q[3 * k - 1])
      return prru_fail(msg, msglen, PRRU_EINPUT, "waypoints %d and %d coincide (a segment of "
                       "length 0)", k, k + 1);
  }
  return PRRU_OK;
}

void prru_topp_free(prru_topp *tp)
{
  free(tp->q);
  free(tp->x);
  free(tp->u);
  free(tp->t);
  memset(tp, 0, sizeof *tp);
}

/* Times of the grid points: constant s'' on each interval, so an interval
 * of length Delta takes 2 Delta / (s'_j + s'_{j+1}). */
static void grid_times(prru_topp *tp)
{
  const int N = tp->grid;
  double t = 0;
  for (int k = 0; k < tp->nseg; k++) {
    const double *x = tp->x + (size_t)k * (N + 1);
    double *tt = tp->t + (size_t)k * (N + 1);
    tt[0] = t;
    for (int j = 0; j < N; j++) {
      t += 2.0 / N / (sqrt(x[j]) + sqrt(x[j + 1]));
      tt[j + 1] = t;
    }
  }
  tp->duration = t;
}

int prru_topp_solve(prru_topp *tp, const prru_model *m, int n, const double *q,
                    const prru_limits *lim, int grid, char *msg, int msglen)
{
  memset(tp, 0, sizeof *tp);
  int st = topp_check_args(m, n, q, lim, grid, msg, msglen);
  if (st != PRRU_OK) return st;
  const int N = grid ? grid : PRRU_TOPP_GRID_DEFAULT;
  const size_t np = (size_t)(n - 1) * (size_t)(N + 1);
  topp_ctx c = {m, m->mech->nact, NULL, lim, N, 0, {0}, has_drives(m), 0, 0.05, NULL, NULL, {0}, NULL, NULL,
                NULL, NULL, NULL, NULL, msg, msglen};
  c.d = malloc(sizeof *c.d);
  c.p = malloc((size_t)(N + 1) * sizeof *c.p);
  c.lo = malloc(3 * (size_t)(N + 1) * sizeof *c.lo);
  c.xprev = malloc((size_t)(N + 1) * sizeof *c.xprev);
  tp->q = malloc((size_t)n * 3 * sizeof *tp->q);
  tp->x = malloc(np * sizeof *tp->x);
  tp->u = malloc(np * sizeof *tp->u);
  tp->t = malloc(np * sizeof *tp->t);
  if (!c.d || !c.p || !c.lo || !c.xprev || !tp->q || !tp->x || !tp->u || !tp->t) {
    st = prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
    goto done;
  }
  c.hi = c.lo + (N + 1);
  tp->nseg = n - 1;
  tp->grid = N;
  memcpy(tp->q, q, (size_t)n * 3 * sizeof *q);
  int active = 0;
  for (int k = 0; k < n - 1 && st == PRRU_OK; k++) {
    c.seg = k;
    c.qa = q + 3 * k;
    c.qb = q + 3 * k + 3;
    for (int i = 0; i < 3; i++) c.dq[i] = c.qb[i] - c.qa[i];
    c.x = tp->x + (size_t)k * (N + 1);
    c.u = tp->u + (size_t)k * (N + 1);
    int act = 0;
    st = solve_segment(&c, &tp->iterations, &act);
    active += act;
  }
  if (st == PRRU_OK) {
    grid_times(tp);
    tp->active_fraction = (double)active / ((double)(n - 1) * N);
  }
done:
  free(c.d);
  free(c.p);
  free(c.lo);
  free(c.xprev);
  if (st != PRRU_OK) prru_topp_free(tp);
  return st;
}

/* The interval holding t: the last one starting at or before t. */
static size_t topp_interval(const prru_topp *tp, double t)
{
  const size_t N = (size_t)tp->grid, np = (size_t)tp->nseg * (N + 1);
  size_t lo = 0, hi = np - 1;
  while (lo < hi) {
    size_t mid = (lo + hi + 1) / 2;
    if (tp->t[mid] <= t)
      lo = mid;
    else
      hi = mid - 1;
  }
  /* A segment's last point starts no interval: the next segment's first
   * (same time) does, or at the very end the last interval. */
  if (lo % (N + 1) == N) lo = lo + 1 < np ? lo + 1 : lo - 1;
  return lo;
}

int prru_topp_eval(const prru_topp *tp, double t, double q[3], double qd[3], double qdd[3])
{
  if (!tp || tp->nseg < 1 || !(t >= 0 && t <= tp->duration)) return PRRU_EINPUT;
  const size_t N = (size_t)tp->grid, g = topp_interval(tp, t);
  const size_t k = g / (N + 1), j = g % (N + 1);
  const double tau = t - tp->t[g], u = tp->u[g], v0 = sqrt(tp->x[g]);
  /* Exact for constant s'' (within the interval, s' >= 0). */
  const double s0 = (double)j / (double)N, s1 = (double)(j + 1) / (double)N;
  double s = fmin(s1, fmax(s0, s0 + v0 * tau + 0.5 * u * tau * tau));
  double v = fmax(0.0, v0 + u * tau);
  const double *qa = tp->q + 3 * k, *qb = qa + 3;
  for (int i = 0; i < 3; i++) {
    const double dq = qb[i] - qa[i];
    if (q) q[i] = qa[i] + s * dq;
    if (qd) qd[i] = dq * v + 0.0; /* no -0 at rest */
    if (qdd) qdd[i] = dq * u;
  }
  return PRRU_OK;
}

int prru_topp_row(const prru_model *m, prru_data *d, const prru_limits *lim, const prru_topp *tp, double t,
                  double q[3], double qd[3], double qdd[3], double fd[], double dd[],
                  char *msg, int msglen)
{
  double r;
  int which, kind;
  if (prru_topp_eval(tp, t, q, qd, qdd) != PRRU_OK)
    return prru_fail(msg, msglen, PRRU_EINPUT, "t = %.9g s is outside the profile [0, %.9g] s", t, tp->duration);
  int st = prru_limits_ratio(m, d, lim, q, qd, qdd, fd, dd, &r, &which, &kind);
  if (st != PRRU_OK)
    return prru_fail(msg, msglen, st, "t = %.9g s: inverse dynamics refuses q = (%.9g, %.9g, %.9g) (%s)", t, q[0],
                     q[1], q[2], prru_strerror(st));
  if (r > 1 + PRRU_TOPP_ROW_TOL)
    return prru_fail(msg, msglen, PRRU_ENOCONV, "t = %.9g s: the %s of actuator %d exceeds its limit by %.3g of "
                     "it; the profile cannot be trusted", t, kind ? "slider speed" : "force", which + 1, r - 1);
  for (int i = 0; i < m->mech->nact; i++)
    if (!(d->d[i] >= lim->d_min[i] && d->d[i] <= lim->d_max[i]))
      return prru_fail(msg, msglen, PRRU_ENOCONV, "t = %.9g s: slider %d at d = %.9g m is outside its stroke "
                       "between two grid points", t, i + 1, d->d[i]);
  return PRRU_OK;
}

/* The largest limit ratio along segment (qa, qb) under the quintic time
 * law of duration T at samples + 1 points; a status on a refused pose. */
static int quintic_ratio(const prru_model *m, prru_data *d, const prru_limits *lim,
                         const double *qa, const double *qb, double T, int samples, double *ratio)
{
  *ratio = 0;
  for (int k = 0; k <= samples; k++) {
    const double u = (double)k / samples;
    const double s = u * u * u * (10 + u * (-15 + 6 * u));
    const double sd = 30 * u * u * (1 + u * (-2 + u)) / T;
    const double sdd = u * (60 + u * (-180 + 120 * u)) / (T * T);
    double q[3], qd[3], qdd[3], r;
    for (int i = 0; i < 3; i++) {
      const double dq = qb[i] - qa[i];
      q[i] = qa[i] + s * dq, qd[i] = sd * dq, qdd[i] = sdd * dq;
    }
    int st = prru_limits_ratio(m, d, lim, q, qd, qdd, NULL, NULL, &r, NULL, NULL);
    if (st != PRRU_OK) return st;
    *ratio = fmax(*ratio, r);
  }
  return PRRU_OK;
}

int prru_quintic_fastest(const prru_model *m, int n, const double *q, const prru_limits *lim,
                         int samples, double *durations, char *msg, int msglen)
{
  int st = topp_check_args(m, n, q, lim, 0, msg, msglen);
  if (st != PRRU_OK) return st;
  if (samples < 2) return prru_fail(msg, msglen, PRRU_EINPUT, "need at least 2 samples per segment");
  prru_data *d = malloc(sizeof *d);
  if (!d) return prru_fail(msg, msglen, PRRU_ENOMEM, "out of memory");
  for (int k = 0; k < n - 1 && st == PRRU_OK; k++) {
    const double *qa = q + 3 * k, *qb = qa + 3;
    double lo = 1, hi = 1, r;
    /* Bracket [lo, hi]: lo fails, hi meets the limits. */
    if ((st = quintic_ratio(m, d, lim, qa, qb, 1, samples, &r)) != PRRU_OK) break;
    if (r <= 1) {
      do {
        hi = lo;
        lo *= 0.5;
        st = quintic_ratio(m, d, lim, qa, qb, lo, samples, &r);
      } while (st == PRRU_OK && r <= 1 && lo > 0x1p-60);
    } else {
      do {
        lo = hi;
        hi *= 2;
        st = quintic_ratio(m, d, lim, qa, qb, hi, samples, &r);
      } while (st == PRRU_OK && r > 1 && hi < 0x1p60);
      if (st == PRRU_OK && r > 1)
        st = prru_fail(msg, msglen, PRRU_EINPUT, "segment %d: no quintic of up to 2^60 s meets "
                       "the limits (the static loads exceed them)", k + 1);
    }
    while (st == PRRU_OK && hi - lo > 1e-9 * hi) {
      const double mid = 0.5 * (lo + hi);
      if ((st = quintic_ratio(m, d, lim, qa, qb, mid, samples, &r)) != PRRU_OK) break;
      *(r <= 1 ? &hi : &lo) = mid;
    }
    if (st == PRRU_OK) durations[k] = hi;
    else if (st != PRRU_EINPUT)
      st = prru_fail(msg, msglen, st, "segment %d: inverse dynamics refuses a pose of the "
                     "quintic (%s)", k + 1, prru_strerror(st));
  }
  free(d);
  return st;
}
