/* The kernel table of prru_bench: one evaluation of each kernel, generated
 * (g_) and reference (r_) side, the timed batch loops around them, and
 * what the generated side executes (operation counts). */
#include <string.h>

#include "bench.h"
#include "prru_param_kernels.h"
#ifdef PRRU_BENCH_HAVE_DME
#include "prru_dme.h"
#endif

/* What the generated side of the runtime's paths executes (runtime/src/core.c,
 * reactions.c): the generated kernels named, plus the listed numerics. */
#define PRRU_BENCH_OPS_FORWARD_DYNAMICS "eom_solve (eom and the solve of M qdd = b fused): " \
  PRRU_OPS_EOM_SOLVE
#if PRRU_NACT == 3
#define PRRU_BENCH_OPS_JD_INVERSE "J_d^-1 and fd in the kernel; conditioning test"
#define PRRU_BENCH_OPS_JD_ALGEBRA "3x3 algebra"
#else /* the redundant 4-PRRU: J_d^+ (spec section 12) */
#define PRRU_BENCH_OPS_JD_INVERSE "J_d^+ by Householder QR of the 4x3 J_d"
#define PRRU_BENCH_OPS_JD_ALGEBRA "J_d^+ by Householder QR, 4x4 and 3x4 algebra"
#endif
#define PRRU_BENCH_OPS_INVERSE_DYNAMICS "inverse_terms (ik_jd and M qdd - b fused, " \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_INVERSE_TERMS) " arithmetic) + " PRRU_BENCH_OPS_JD_INVERSE
#define PRRU_BENCH_OPS_REACTIONS "forward_dynamics + joint_reactions (" \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_EOM_SOLVE) " + " PRRU_OPS_ARITH_STR(PRRU_ARITH_JOINT_REACTIONS) \
  " arithmetic): closed form, no solve"
#define PRRU_BENCH_OPS_W_R "ik_jd + mass + platform_jacobian (" \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_IK_JD) " + " PRRU_OPS_ARITH_STR(PRRU_ARITH_MASS) " + " \
  PRRU_OPS_ARITH_STR(PRRU_ARITH_PLATFORM_JACOBIAN) " arithmetic) + " PRRU_BENCH_OPS_JD_ALGEBRA \
  ", one Jacobi rotation"
#define PRRU_OPS_ARITH_STR(x) PRRU_OPS_STR_(x)
#define PRRU_OPS_STR_(x) #x

volatile double bench_sink;

/* ---- One evaluation of each kernel, generated (g_) and reference (r_) ----
 * Each writes its outputs contiguously into out and returns non-zero on
 * failure. They are static inline in this file so the batch loops below call
 * the library function directly, with no extra indirection per call. */

static inline int g_jd(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_jd(s->q, out);
  return 0;
}
static inline int r_jd(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_jd(&c->p, s->q, out);
}
static inline int g_ik_jd(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_ik_jd(s->q, out, out + PRRU_NACT);
  return 0;
}
static inline int r_ik_jd(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_ik(&c->p, s->q, out) | prru_ref_jd(&c->p, s->q, out + PRRU_NACT);
}
static inline int g_jacobians(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_jacobians(s->q, out);
  return 0;
}
static inline int r_jacobians(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_jacobians(&c->p, c->w, s->q, out);
}
static inline int g_bias_terms(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_bias_terms(s->q, s->qd, out);
  return 0;
}
static inline int r_bias_terms(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_bias_terms(&c->p, c->w, s->q, s->qd, out);
}
static inline int g_mass(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_mass(s->q, out);
  return 0;
}
static inline int r_mass(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_mass(&c->p, c->w, s->q, out);
}
static inline int g_bias(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_bias(s->q, s->qd, out);
  return 0;
}
static inline int r_bias(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_bias(&c->p, c->w, s->q, s->qd, out);
}
static inline int g_gravity(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_gravity(s->q, out);
  return 0;
}
static inline int r_gravity(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_gravity(&c->p, c->w, s->q, out);
}
static inline int g_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  (void)c;
  prru_dynamics(s->q, s->qd, out, out + 9, out + 12);
  return 0;
}
static inline int r_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_dynamics(&c->p, c->w, s->q, s->qd, out, out + 9, out + 12);
}
static inline int g_forward_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_forward_dynamics(&c->m, c->d, s->q, s->qd, &s->l, out);
}
static inline int r_forward_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_forward_dynamics(&c->p, c->w, s->q, s->qd, s->l.fd, s->l.fp, s->l.mp, out);
}
static inline int g_inverse_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_inverse_dynamics(&c->m, c->d, s->q, s->qd, s->qdd, &s->l, out);
}
static inline int r_inverse_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_inverse_dynamics(&c->p, c->w, s->q, s->qd, s->qdd, s->l.fp, s->l.mp, out);
}
static inline int g_reactions(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_reactions(&c->m, c->d, s->q, s->qd, &s->l, out);
}
static inline int r_reactions(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_reactions(&c->p, c->w, s->q, s->qd, s->l.fd, s->l.fp, s->l.mp, out);
}
/* The runtime-parameter kernels with the model's own numbers, against the
 * same reference as their constant-folded namesakes. */
static inline int g_param_ik_jd(bench_ctx *c, const bench_state *s, double *out)
{
  prru_param_ik_jd(&c->pd, s->q, out, out + PRRU_NACT);
  return 0;
}
static inline int r_param_ik_jd(bench_ctx *c, const bench_state *s, double *out)
{
  return r_ik_jd(c, s, out);
}
static inline int g_param_mass(bench_ctx *c, const bench_state *s, double *out)
{
  prru_param_mass(&c->pd, s->q, out);
  return 0;
}
static inline int r_param_mass(bench_ctx *c, const bench_state *s, double *out)
{
  return r_mass(c, s, out);
}
static inline int g_param_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  prru_param_dynamics(&c->pd, s->q, s->qd, out, out + 9, out + 12);
  return 0;
}
static inline int r_param_dynamics(bench_ctx *c, const bench_state *s, double *out)
{
  return r_dynamics(c, s, out);
}
#ifdef PRRU_BENCH_HAVE_DME
/* prru_dme_eval computes the whole ellipse (w_R, axes, the translational
 * segment): that is what the runtime offers for w_R, so that is timed. */
static inline int g_w_r(bench_ctx *c, const bench_state *s, double *out)
{
  prru_dme e;
  int st = prru_dme_eval(&c->m, c->d, s->q, &e);
  out[0] = e.w_R;
  return st;
}
static inline int r_w_r(bench_ctx *c, const bench_state *s, double *out)
{
  return prru_ref_w_r(&c->p, c->w, s->q, out);
}
#endif

/* n calls of one side of one kernel. Every output feeds the sink: one a
 * call, the next each time (out[j], j cycling through all nout), so the
 * timing pays one load and one add a call whatever the kernel's size (adding
 * all 180 entries of H would cost more than a cheap kernel), and no output
 * is dead even to a compiler that could see into the kernels. */
#define BENCH_BATCH(fn, eval, nout)                          \
  static void fn(bench_ctx *c, long n)                       \
  {                                                          \
    double out[MAXOUT], acc = 0.0;                           \
    long bad = 0;                                            \
    int j = 0;                                               \
    for (long k = 0; k < n; k++) {                           \
      bad += eval(c, &c->st[k & (NSTATES - 1)], out) != 0;   \
      acc += out[j];                                         \
      j = j + 1 == (nout) ? 0 : j + 1;                       \
    }                                                        \
    bench_sink += acc;                                       \
    c->failures += bad;                                      \
  }
#define BENCH_PAIR(name, nout)             \
  BENCH_BATCH(gb_##name, g_##name, nout)   \
  BENCH_BATCH(rb_##name, r_##name, nout)

BENCH_PAIR(jd, 3 * PRRU_NACT)
BENCH_PAIR(ik_jd, 4 * PRRU_NACT)
BENCH_PAIR(param_ik_jd, 4 * PRRU_NACT)
BENCH_PAIR(jacobians, 3 * PRRU_NH)
BENCH_PAIR(bias_terms, PRRU_NH)
BENCH_PAIR(mass, 9)
BENCH_PAIR(param_mass, 9)
BENCH_PAIR(bias, 3)
BENCH_PAIR(gravity, 3)
BENCH_PAIR(dynamics, 15)
BENCH_PAIR(param_dynamics, 15)
BENCH_PAIR(forward_dynamics, 3)
BENCH_PAIR(inverse_dynamics, PRRU_NACT)
BENCH_PAIR(reactions, PRRU_NLAMBDA)
#ifdef PRRU_BENCH_HAVE_DME
BENCH_PAIR(w_r, 1)
#endif

#define KERNEL(name, nout, ops) {#name, nout, g_##name, r_##name, gb_##name, rb_##name, ops, \
                                 NULL, 0, 0, {0, 0, 0}, {0, 0, 0}, 0, {0, 0, 0}, {0, 0, 0}, \
                                 {0, 0, 0}}
/* A runtime-parameter kernel, listed after the constant kernel it is
 * compared with. */
#define PARAM_KERNEL(name, NAME, nout)                                                       \
  {"param_" #name, nout, g_param_##name, r_param_##name, gb_param_##name, rb_param_##name, \
   PRRU_PARAM_OPS_##NAME, #name, PRRU_PARAM_ARITH_##NAME, PRRU_ARITH_##NAME,                 \
   {0, 0, 0}, {0, 0, 0}, 0, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}

bench_kernel bench_kernels[] = {
  KERNEL(jd, 3 * PRRU_NACT, PRRU_OPS_JD),
  KERNEL(ik_jd, 4 * PRRU_NACT, PRRU_OPS_IK_JD),
  PARAM_KERNEL(ik_jd, IK_JD, 4 * PRRU_NACT),
  KERNEL(jacobians, 3 * PRRU_NH, PRRU_OPS_JACOBIANS),
  KERNEL(bias_terms, PRRU_NH, PRRU_OPS_BIAS_TERMS),
  KERNEL(mass, 9, PRRU_OPS_MASS),
  PARAM_KERNEL(mass, MASS, 9),
  KERNEL(bias, 3, PRRU_OPS_BIAS),
  KERNEL(gravity, 3, PRRU_OPS_GRAVITY),
  KERNEL(dynamics, 15, PRRU_OPS_DYNAMICS),
  PARAM_KERNEL(dynamics, DYNAMICS, 15),
  KERNEL(forward_dynamics, 3, PRRU_BENCH_OPS_FORWARD_DYNAMICS),
  KERNEL(inverse_dynamics, PRRU_NACT, PRRU_BENCH_OPS_INVERSE_DYNAMICS),
  KERNEL(reactions, PRRU_NLAMBDA, PRRU_BENCH_OPS_REACTIONS),
#ifdef PRRU_BENCH_HAVE_DME
  KERNEL(w_r, 1, PRRU_BENCH_OPS_W_R),
#endif
};
const int bench_nkernels = (int)(sizeof bench_kernels / sizeof bench_kernels[0]);

void bench_warm_up(bench_ctx *c, long n) { gb_dynamics(c, n); }

const bench_kernel *bench_kernel_named(const char *name)
{
  for (int i = 0; i < bench_nkernels; i++)
    if (!strcmp(bench_kernels[i].name, name)) return &bench_kernels[i];
  return NULL;
}
