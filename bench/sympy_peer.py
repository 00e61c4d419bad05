#!/usr/bin/env python3
"""The SymPy peer of prru_dynamics, for the benchmark only (never shipped).

usage: python3 bench/sympy_peer.py MODEL.json --out FILE.c

The usual route, done as well as SymPy does it: the bodies' poses (the
same pose functions the generator derives, R_b(q) and the centres p_b(q),
carried over to SymPy expressions), then everything else in SymPy: the
Jacobians by differentiation (J_T = dp/dq; the body-frame angular one from
R^T dR/dq_j), their time derivatives along qd for the bias, and

  M = sum_b m J_T^T J_T + J_R^T I_b J_R,
  h = sum_b J_T^T m (dJ_T/dt qd) + J_R^T (I_b (dJ_R/dt qd) + w x I_b w),
  G = sum_b J_T^T m g,

then sympy.cse over the 15 outputs at once and SymPy's C99 printer, with
small integer powers printed as products (pow(x, 2) is slower) and sqrt,
1/x as SymPy prints them. Written as

  static void peer_dynamics(const double q[3], const double qd[3],
                            double M[9], double h[3], double G[3]);

(static and, with GCC, noinline: bench/bench_peer.c includes the file but
calls it as it calls prru_dynamics, which lives in another translation unit).

For a model with drives (armature) the file only defines PEER_UNAVAILABLE
with the reason: the peer covers the rigid bodies only. The derivation
takes about 3 s (half a minute on a loaded machine), so the bench build
caches FILE.c in the build tree (regenerated when the model or this script
changes).
"""

import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "gen"))
sys.setrecursionlimit(20000)

import sympy  # noqa: E402
from sympy.printing.c import C99CodePrinter  # noqa: E402

from prrugen import dynamics, mechanism, model as model_mod, sym  # noqa: E402

Q = sympy.symbols("q1 q2 q3")
QD = sympy.symbols("qd1 qd2 qd3")


def to_sympy(e, memo):
    """The generator's expression e as a SymPy expression."""
    r = memo.get(e.id)
    if r is not None:
        return r
    op, a = e.op, e.args
    if op == "const":
        r = sympy.Rational(a[0].numerator, a[0].denominator)
    elif op == "sym" and sym.definition(e) is not None:
        # An atom of the generator (an intermediate angle): its value.
        r = to_sympy(sym.definition(e).value, memo)
    elif op == "sym":
        r = {"q1": Q[0], "q2": Q[1], "q3": Q[2]}[a[0]]
    elif sym.atom_trig(e) is not None:
        # As the poses had it before atoms: sin(atan2(y, x)) = y / hypot.
        r = to_sympy(sym.atom_trig(e), memo)
    elif op == "add":
        c, terms = a
        r = sympy.Add(sympy.Rational(c.numerator, c.denominator),
                      *[sympy.Rational(k.numerator, k.denominator) *
                        to_sympy(t, memo) for k, t in terms])
    elif op == "mul":
        c, factors = a
        r = sympy.Mul(sympy.Rational(c.numerator, c.denominator),
                      *[sympy.Pow(to_sympy(b, memo),
                                  sympy.Rational(x.numerator, x.denominator))
                        for b, x in factors])
    elif op in ("sin", "cos", "tan", "tanh", "asin", "acos"):
        r = getattr(sympy, op)(to_sympy(a[0], memo))
    elif op == "atan2":
        r = sympy.atan2(to_sympy(a[0], memo), to_sympy(a[1], memo))
    else:
        raise ValueError("no SymPy form for %r" % op)
    memo[e.id] = r
    return r


def rational(x):
    from fractions import Fraction
    f = Fraction(x)
    return sympy.Rational(f.numerator, f.denominator)


def body_terms(t, memo):
    """(m, I_b, R, p) of one body, SymPy."""
    m = rational(t.body.mass)
    inertia = sympy.Matrix(3, 3, lambda i, j: to_sympy(sym.as_expr(
        t.inertia[i][j]), memo))
    rot = sympy.Matrix(3, 3, lambda i, j: to_sympy(t.rotation[i][j], memo))
    p = sympy.Matrix([to_sympy(x, memo) for x in t.body.centre])
    return m, inertia, rot, p


def along_qd(v):
    """d/dt of a vector expression in q: sum_k dv/dq_k qd_k."""
    return sum((v.diff(Q[k]) * QD[k] for k in range(3)), sympy.zeros(*v.shape))


def derive(model):
    """M (9), h (3), G (3), SymPy, for a model without drives."""
    sym.reset()
    deriv = dynamics.Derivation(mechanism.build(model), model)
    memo = {}
    qd = sympy.Matrix(QD)
    g = sympy.Matrix([rational(x) for x in model.gravity])
    M, h, G = sympy.zeros(3, 3), sympy.zeros(3, 1), sympy.zeros(3, 1)
    for t in deriv.terms:
        m, inertia, rot, p = body_terms(t, memo)
        jt = p.jacobian(Q)
        cols = []
        for k in range(3):
            w = rot.T * rot.diff(Q[k])  # skew: body-frame rate of R
            cols.append([w[2, 1], w[0, 2], w[1, 0]])
        jr = sympy.Matrix(3, 3, lambda i, j: cols[j][i])
        omega = jr * qd
        M += m * jt.T * jt + jr.T * inertia * jr
        h += jt.T * (m * along_qd(jt * qd)) + \
            jr.T * (inertia * along_qd(omega) + omega.cross(inertia * omega))
        G += jt.T * (m * g)
    return list(M), list(h), list(G)


class ProductPowers(C99CodePrinter):
    """x**2 .. x**4 as products, x**-1 .. x**-4 as 1.0/(...)."""

    def _print_Pow(self, expr):
        b, e = expr.base, expr.exp
        if e.is_Integer and 2 <= abs(int(e)) <= 4:
            base = self.parenthesize(b, 100)
            # Parenthesized: the Mul printer writes a/x**3 as a/<this>.
            prod = "(%s)" % "*".join([base] * abs(int(e)))
            return prod if e > 0 else "1.0/%s" % prod
        return super()._print_Pow(expr)


def c_source(outputs):
    M, h, G = outputs
    flat = M + h + G
    start = time.perf_counter()
    temps, reduced = sympy.cse(flat, symbols=sympy.numbered_symbols("x"),
                               optimizations="basic")
    cse_s = time.perf_counter() - start
    pr = ProductPowers()
    # noinline: called from the timing loop as prru_dynamics is (another
    # translation unit), never optimised into it.
    lines = ["#include <math.h>", "",
             "#if defined(__GNUC__)", "__attribute__((noinline))", "#endif",
             "static void peer_dynamics(const double q[3], const double qd[3], "
             "double M[9], double h[3], double G[3])", "{"]
    for i in range(3):
        lines.append("  const double q%d = q[%d], qd%d = qd[%d];"
                     % (i + 1, i, i + 1, i))
    used = set()
    for s, e in temps:
        used |= {x.name for x in e.free_symbols}
    used |= {x.name for e in reduced for x in e.free_symbols}
    for n in ("q1", "q2", "q3", "qd1", "qd2", "qd3"):
        if n not in used:
            lines.append("  (void)%s;" % n)
    for s, e in temps:
        lines.append("  const double %s = %s;" % (s, pr.doprint(e)))
    names = ["M[%d]" % i for i in range(9)] + ["h[%d]" % i for i in range(3)] \
        + ["G[%d]" % i for i in range(3)]
    for n, e in zip(names, reduced):
        lines.append("  %s = %s;" % (n, pr.doprint(e)))
    lines.append("}")
    return "\n".join(lines) + "\n", len(temps), cse_s


def write(path, text):
    """Whole or not at all: a stopped run leaves no half file behind."""
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("model")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    try:
        model = model_mod.load(args.model)
    except model_mod.ModelError as exc:
        print("sympy_peer: error: %s" % exc, file=sys.stderr)
        return 2
    if any(model.armature):
        # Not an error for the bench build: it reports the peer missing.
        write(args.out, "/* GENERATED by bench/sympy_peer.py */\n"
              "#define PEER_UNAVAILABLE \"the model has drive armature, "
              "which the peer does not cover\"\n")
        print("sympy_peer: %s: the model has drives: no peer" % args.out)
        return 0
    t0 = time.perf_counter()
    outputs = derive(model)
    derive_s = time.perf_counter() - t0
    text, ntemp, cse_s = c_source(outputs)
    head = ("/* GENERATED by bench/sympy_peer.py from %s with SymPy %s: the "
            "benchmark's peer of prru_dynamics.\n * Derivation %.1f s, cse %.1f s, "
            "%d temporaries. */\n" % (os.path.basename(args.model),
                                      sympy.__version__, derive_s, cse_s,
                                      ntemp))
    head += "#define PEER_DERIVE_S %.3f\n#define PEER_CSE_S %.3f\n" % (
        derive_s, cse_s)
    write(args.out, head + text)
    print("sympy_peer: %s: derivation %.1f s, cse %.1f s, %d temporaries"
          % (args.out, derive_s, cse_s, ntemp))
    return 0


if __name__ == "__main__":
    sys.exit(main())
