"""Batched (structure-of-arrays) variants of kernels: n states per call.

A batched kernel evaluates the same lowered graph as its scalar namesake
(cgen), so each output is computed by the same operations in the same
order and agrees bit for bit, but inside a loop over the states that a
compiler can vectorise:

* arrays hold one component per row of n: component i of state k is
  x[i n + k] (q1 of every state, then q2, ...);
* sin and cos of the inputs are taken in a first loop over a chunk of
  BATCH_CHUNK states into local arrays, so the arithmetic loop has no
  calls but sqrt, which vectorises as an instruction (vector sin/cos
  take part where the build provides them, see the header);
* the scalar kernel's early return for an unreachable q becomes a
  per-state select, so the loop has no branch; where the loop calls a
  function (tanh), each output is multiplied by 1 or NaN instead, because
  GCC sinks the work a select guards into a branch, and a branch around
  a call stops the loop from being vectorised.

Each loop carries PREFIX_BATCH_LOOP, empty unless the build defines it
(e.g. as _Pragma("omp simd") with -fopenmp-simd): the generated code stays
portable C99 that compiles to a plain scalar loop anywhere.
"""

from . import cgen

BATCH_CHUNK = 32

# Which kernels get a batched variant (in header order; the derivative
# kernels only in the sets that have them, kernels.derivative_kernels:
# prru_linearize_batch's, over the kernel table), and the fused
# ones that exist only batched: their outputs are those of the named scalar
# kernels (all with the inputs q, hence the same guards).
BATCH_KERNELS = ("ik_jd", "mass", "platform_jacobian", "dynamics", "eom",
                 "eom_solve", "eom_solve_derivs", "inverse_derivs")
FUSED = (("dme_terms", "prru_ik_jd, prru_mass and prru_platform_jacobian "
          "fused: what the manipulability maps need at each q.",
          ("ik_jd", "mass", "platform_jacobian")),)


# Kernels whose batched variants keep the scalar sin and cos, so that they
# agree bit for bit (w_R, computed from their outputs, is ill-conditioned
# near singular poses: a few ulp in J_d move it by 1e-12 there). The others
# call the vector sin and cos where the build provides them.
EXACT = ("ik_jd", "mass", "platform_jacobian", "dme_terms")


def batch_kernels(kernel_list, names=BATCH_KERNELS, fused=FUSED):
    """The kernels to emit batched, from the scalar kernel list."""
    by_name = {k.name: k for k in kernel_list}
    out = [by_name[n] for n in names if n in by_name]
    for name, doc, parts in fused:
        if not all(p in by_name for p in parts):
            continue
        first = by_name[parts[0]]
        outputs, seen = [], set()
        for p in parts:
            for arr, exprs in by_name[p].outputs:
                if arr not in seen:
                    seen.add(arr)
                    outputs.append((arr, exprs))
        out.append(cgen.Kernel(name, doc, first.inputs, outputs,
                               first.guards, first.params))
    return out


# Calls with a vector variant declared in PROLOGUE (besides sin and cos of
# the inputs, which get loops of their own).
VECTOR_CALLS = ("tanh",)


def emit_batch(kernel, prefix, loop_macro, vector_trig="%s",
               precision=cgen.DOUBLE):
    """cgen.Emitted for the batched variant of kernel, named
    <prefix>_batch_<name> (cgen.emit's batched form). vector_trig % "SIN"
    is the name of the sin the vectorisable kernels call (kernels in EXACT
    call sin itself), likewise for the VECTOR_CALLS. precision cgen.FLOAT
    spells it in float (float literals, sinf, sqrtf, ...; vector_trig %
    "SINF" for every kernel: the float batches are not held to the scalar
    kernels bit for bit)."""
    if precision is not cgen.DOUBLE:
        call_name = lambda fn: vector_trig % (fn.upper() + "F")  # noqa: E731
    elif kernel.name in EXACT:
        call_name = lambda fn: fn  # noqa: E731
    else:
        call_name = lambda fn: vector_trig % fn.upper()  # noqa: E731
    form = cgen.Batched(loop_macro, call_name, VECTOR_CALLS, BATCH_CHUNK)
    return cgen.emit(kernel, prefix, precision, form)


PROLOGUE = """/* Batched kernels. ${PREFIX}_BATCH_LOOP marks each loop over states whose
 * iterations are independent; the build may define it as _Pragma("omp simd")
 * (with -fopenmp-simd) to have the loops vectorised, and
 * ${PREFIX}_BATCH_TARGETS as a function attribute (e.g. target_clones).
 * With ${PREFIX}_BATCH_VECTOR_MATH defined (GCC), ${PREFIX}_BATCH_SIN,
 * _COS and _TANH are sin, cos and tanh declared as having vector variants
 * (glibc's libmvec, which <math.h> declares only under -ffast-math; the
 * kernels are never built with it), within a few units in the last place
 * of the scalar functions; the kinematic kernels call sin and cos
 * themselves and so agree with the scalar kernels bit for bit. */
#ifndef ${PREFIX}_BATCH_LOOP
#define ${PREFIX}_BATCH_LOOP
#endif
#ifndef ${PREFIX}_BATCH_TARGETS
#define ${PREFIX}_BATCH_TARGETS
#endif
#if defined(${PREFIX}_BATCH_VECTOR_MATH) && defined(__GNUC__) && !defined(__cplusplus)
#pragma omp declare simd notinbranch
extern double ${prefix}_batch_vsin(double) __asm__("sin");
#pragma omp declare simd notinbranch
extern double ${prefix}_batch_vcos(double) __asm__("cos");
/* const: tanh sets no errno (it cannot overflow) and reads no memory; a
 * call GCC thinks may write memory stops the loop around it from being
 * vectorised. */
#pragma omp declare simd notinbranch
extern double ${prefix}_batch_vtanh(double) __asm__("tanh") __attribute__((const));
#define ${PREFIX}_BATCH_SIN ${prefix}_batch_vsin
#define ${PREFIX}_BATCH_COS ${prefix}_batch_vcos
#define ${PREFIX}_BATCH_TANH ${prefix}_batch_vtanh
#else
#define ${PREFIX}_BATCH_SIN sin
#define ${PREFIX}_BATCH_COS cos
#define ${PREFIX}_BATCH_TANH tanh
#endif"""


FLOAT_PROLOGUE = """/* Single-precision batched kernels. ${PREFIX}_BATCH_LOOP and
 * ${PREFIX}_BATCH_TARGETS as for the other batched kernels. With
 * ${PREFIX}_BATCH_VECTOR_MATH defined (GCC), ${PREFIX}_BATCH_SINF and _COSF
 * are sinf and cosf declared as having vector variants (glibc's libmvec:
 * 8 lanes with AVX2, _ZGVdN8v_sinf), within a few units in the last place
 * of the scalar functions; every float batch calls them, so it agrees with
 * the scalar float kernels within their accuracy bound, not bit for bit. */
#ifndef ${PREFIX}_BATCH_LOOP
#define ${PREFIX}_BATCH_LOOP
#endif
#ifndef ${PREFIX}_BATCH_TARGETS
#define ${PREFIX}_BATCH_TARGETS
#endif
#if defined(${PREFIX}_BATCH_VECTOR_MATH) && defined(__GNUC__) && !defined(__cplusplus)
#pragma omp declare simd notinbranch
extern float ${prefix}_batch_vsinf(float) __asm__("sinf");
#pragma omp declare simd notinbranch
extern float ${prefix}_batch_vcosf(float) __asm__("cosf");
#define ${PREFIX}_BATCH_SINF ${prefix}_batch_vsinf
#define ${PREFIX}_BATCH_COSF ${prefix}_batch_vcosf
#else
#define ${PREFIX}_BATCH_SINF sinf
#define ${PREFIX}_BATCH_COSF cosf
#endif"""

# The kernels of the single-precision batch set: only the fused one the
# maps and the optimiser need.
FLOAT_FUSED = FUSED


def float_prologue(prefix):
    """Macros the float batched kernels' definitions need."""
    return FLOAT_PROLOGUE.replace("${PREFIX}", prefix.upper()).replace(
        "${prefix}", prefix)


def prologue(prefix):
    """Macros the batched kernels' definitions need (in the .c file)."""
    return PROLOGUE.replace("${PREFIX}", prefix.upper()).replace(
        "${prefix}", prefix)


HEADER_NOTE = """/* Batched kernels, <prefix>_batch_<name>(n, inputs..., outputs...): the
 * kernel of the same name (or, for dme_terms, the named ones fused) for n
 * states in one call. Every array holds one row of n per component:
 * component i of state k is x[i * n + k] (q = q1 of every state, then q2,
 * then q3; M = M[0][0] of every state, then M[0][1], ...). Outputs agree
 * with the scalar kernels state by state: bit for bit for ik_jd, mass,
 * platform_jacobian and dme_terms; for dynamics, eom, eom_solve (the
 * forward-dynamics step's kernel) and the derivative kernels bit for bit
 * unless the build provides vector sin, cos and tanh (see the source), then
 * within 1e-14 of each output's largest entry (h, b and qdd: 2e-14; the
 * derivatives: that plus the output's change under a few ulp of q1, q2,
 * as tests/test_batch.c checks). Outputs must not
 * overlap the inputs. Any alignment works; for speed give every array
 * 64-byte alignment and n a multiple of 8, so that each row starts on a
 * cache line (unaligned, the AVX-512 loops ran up to 1.5x slower). */"""


def header_note(prefix):
    return HEADER_NOTE.replace("<prefix>", prefix)
