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
from .cgen import Node

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


def _is_input_trig(n):
    return n.op == "call" and n.args[0] in ("sin", "cos") and \
        isinstance(n.args[1], Node) and n.args[1].op == "in"


# Calls with a vector variant declared in PROLOGUE (besides sin and cos of
# the inputs, which get loops of their own).
VECTOR_CALLS = ("tanh",)


def emit_batch(kernel, prefix, loop_macro, vector_trig="%s",
               precision=cgen.DOUBLE):
    """cgen.Emitted for the batched variant of kernel, named
    <prefix>_batch_<name>. vector_trig % "SIN" is the name of the sin the
    vectorisable kernels call (kernels in EXACT call sin itself), likewise
    for the VECTOR_CALLS. precision cgen.FLOAT spells it in float (float
    literals, sinf, sqrtf, ...; vector_trig % "SINF" for every kernel: the
    float batches are not held to the scalar kernels bit for bit)."""
    single = precision is not cgen.DOUBLE
    if single:
        trig_name = lambda fn: vector_trig % (fn.upper() + "F")
    elif kernel.name in EXACT:
        trig_name = lambda fn: fn
    else:
        trig_name = lambda fn: vector_trig % fn.upper()
    real = precision.ctype
    lit = precision.literal if single else (lambda text: text)
    call = precision.call if single else None
    params = kernel.params
    low = cgen.Lowered(kernel)
    names, g, uses, live, counts = low.names, low.graph, low.uses, low.live, low.counts
    guard_nodes, finite_nodes, out_nodes = low.guard_nodes, low.finite_nodes, low.out_nodes

    def materialized(n):
        return n.op not in ("num", "in") and \
            (uses.get(n.index, 0) > 1 or n.op == "call")

    temp = {}

    def expr(n, parent_prec=0, right=False):
        if n.op == "in":
            return n.args[0]
        if n.op == "num":
            return lit(n.args[0])
        if n.index in temp:
            return temp[n.index]
        return inline(n, parent_prec, right)

    def inline(n, parent_prec=0, right=False):
        if n.op == "call" and n.args[0] in VECTOR_CALLS:
            return "%s(%s)" % (trig_name(n.args[0]), expr(n.args[1]))
        return cgen.print_op(n, expr, parent_prec, right, call)

    used_inputs = {g.nodes[i].args[0] for i in live if g.nodes[i].op == "in"}
    trig = [g.nodes[i] for i in sorted(live) if _is_input_trig(g.nodes[i])]
    trig_inputs = sorted({n.args[1].args[0] for n in trig})
    # Input name -> row index in its array.
    row = {}
    for arr, syms in kernel.inputs:
        for i, _ in enumerate(syms):
            row["%s%d" % (arr, i + 1)] = (arr, i)

    def load(name, index):
        arr, i = row[name]
        at = index if i == 0 else "%d * s + %s" % (i, index) if i > 1 \
            else "s + " + index
        return "const %s %s = %s[%s];" % (real, name, arr, at)

    lines = []
    if params is not None:
        # A float batch converts each parameter once, explicitly.
        cast = "(float)" if single else ""
        lines += ["const %s %s = %s%s;" % (real, params.local(s), cast,
                                           params.access(s))
                  for s in params.order if params.local(s) in used_inputs]
    lines.append("const long s = n;")
    lines.append("for (long k0 = 0; k0 < s; k0 += %d) {" % BATCH_CHUNK)
    lines.append("  const long m = s - k0 < %d ? s - k0 : %d;"
                 % (BATCH_CHUNK, BATCH_CHUNK))
    body = []
    if trig:
        body.append("%s %s;" % (real, ", ".join("w%d[%d]" % (j, BATCH_CHUNK)
                                              for j in range(len(trig)))))
        # One loop per function: sin and cos of one argument in one loop
        # would be merged into a sincos call, which has no vector variant.
        for fn in ("cos", "sin"):
            group = [(j, n) for j, n in enumerate(trig) if n.args[0] == fn]
            if not group:
                continue
            body.append(loop_macro)
            body.append("for (long k = 0; k < m; k++) {")
            body += ["  " + load(name, "k0 + k") for name in trig_inputs
                     if any(n.args[1].args[0] == name for _, n in group)]
            for j, n in group:
                body.append("  w%d[k] = %s(%s);" % (j, trig_name(fn),
                                                   n.args[1].args[0]))
                temp[n.index] = "w%d[k]" % j
            body.append("}")
    body.append(loop_macro)
    body.append("for (long k = 0; k < m; k++) {")
    inner = ["const long i = k0 + k;"]
    inner += [load(name, "i") for arr, syms in kernel.inputs
              for name in ("%s%d" % (arr, j + 1) for j in range(len(syms)))
              if name in used_inputs]
    for i in sorted(live):
        n = g.nodes[i]
        if i in temp or not materialized(n):
            continue
        name = "t%d" % len(temp)
        inner.append("const %s %s = %s;" % (real, name, inline(n)))
        temp[i] = name
    if guard_nodes:
        fabs = precision.call("fabs")
        conds = ["islessequal(%s(%s), %s)" % (fabs, expr(n), lit("1.0"))
                 for n in guard_nodes]
        conds += ["islessequal(%s(%s), %s)" % (fabs, expr(n), precision.huge)
                  for n in finite_nodes]
        inner.append("/* Unreachable or non-finite q: NaN (a select, not a "
                     "branch). */")
        inner.append("const int ok = %s;" % " &\n    ".join(conds))
    calls = any(g.nodes[i].op == "call" and g.nodes[i].args[0] != "sqrt"
                and not _is_input_trig(g.nodes[i]) for i in live)
    if guard_nodes and calls:
        inner.append("const %s okf = ok ? %s : %s;"
                     % (real, lit("1.0"), precision.nan))
    for arr, ns in out_nodes:
        for j, n in enumerate(ns):
            at = "i" if j == 0 else "s + i" if j == 1 else "%d * s + i" % j
            value = expr(n)
            if guard_nodes and calls:
                value = "%s * okf" % expr(n, cgen.PREC["mul"])
            elif guard_nodes:
                value = "ok ? %s : %s" % (value, precision.nan)
            inner.append("%s[%s] = %s;" % (arr, at, value))
    body += ["  " + l.replace("\n", "\n  ") for l in inner]
    body.append("}")
    lines += ["  " + l.replace("\n", "\n  ") for l in body]
    lines.append("}")
    args = []
    if params is not None:
        args.append("const %s *p" % params.ctype)
    args.append("int n")
    args += ["const %s *%s" % (real, arr) for arr, _ in kernel.inputs]
    args += ["%s *%s" % (real, arr) for arr, _ in out_nodes]
    unused = [arr for arr, syms in kernel.inputs
              if not any(("%s%d" % (arr, i + 1)) in used_inputs
                         for i in range(len(syms)))]
    lines = ["(void)%s;" % a for a in unused] + lines
    signature = "void %s_batch_%s(%s)" % (prefix, kernel.name, ", ".join(args))
    text = "\n".join("  " + l.replace("\n", "\n  ") for l in lines)
    return cgen.Emitted(kernel.name, signature, text, counts, kernel.doc)


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
