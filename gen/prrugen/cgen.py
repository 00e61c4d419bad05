"""Lowering symbolic expressions to straight-line C.

The expressions of one kernel (all its outputs together) are lowered into a
graph of binary operations that is itself hash-consed, so any operation that
appears twice is computed once: that is the common-subexpression
elimination, and it works across outputs (M, h and G share their terms).
Nodes used more than once become `const double` temporaries; the rest are
printed inline. Rational powers become products, one sqrt, and one shared
reciprocal per denominator, so the only divisions are 1/x.
"""

import heapq
import math
import struct
from fractions import Fraction

from . import sym
from .model import c_double

ARITH = ("add", "sub", "mul", "div", "neg")
PREC = {"add": 1, "sub": 1, "mul": 2, "div": 2, "neg": 3}


# Latencies (cycles, about those of current x86-64 cores) by which the
# lowering associates sums and products: only their relative sizes matter.
_LATENCY = {"add": 3, "sub": 3, "mul": 3, "div": 13, "neg": 1}
_CALL_LATENCY = {"sqrt": 20, "sin": 40, "cos": 40}


class Node:
    __slots__ = ("op", "args", "index")

    def __init__(self, op, args, index):
        self.op, self.args, self.index = op, args, index


class Graph:
    """Hash-consed operation graph of one kernel."""

    def __init__(self, names):
        self.nodes = []
        self.ready = []             # per node: its latency from the inputs
        self._table = {}
        self._lowered = {}
        self.names = names          # symbol name -> C local name

    def node(self, op, *args):
        if op in ("add", "mul"):
            args = tuple(sorted(args, key=lambda n: n.index))
        key = (op,) + tuple(a.index if isinstance(a, Node) else a
                            for a in args)
        n = self._table.get(key)
        if n is None:
            n = Node(op, args, len(self.nodes))
            self.nodes.append(n)
            self._table[key] = n
            start = max([self.ready[a.index] for a in args
                         if isinstance(a, Node)], default=0)
            self.ready.append(0 if op in ("in", "num") else start + (
                _CALL_LATENCY.get(args[0], 20) if op == "call"
                else _LATENCY[op]))
        return n

    def num(self, value):
        return self.node("num", c_double(value))

    # -- lowering ---------------------------------------------------------
    def lower(self, e):
        n = self._lowered.get(e.id)
        if n is None:
            n = self._lower(e)
            self._lowered[e.id] = n
        return n

    def _lower(self, e):
        op = e.op
        if op == "const":
            v = e.args[0]
            return self.num(v) if v >= 0 else self.node("neg", self.num(-v))
        if op == "sym":
            d = sym.definition(e)
            if d is not None:
                return self.lower(d.value)
            return self.node("in", self.names[e.args[0]])
        if op == "add":
            return self._sum(e)
        if op == "mul":
            coef, factors = e.args
            base = factors[0][0]
            if coef < 0 and len(factors) == 1 and factors[0][1] == 1 \
                    and base.op == "add" and base.id not in self._lowered:
                # -k (a - b) as k (b - a): no negation.
                n = self._sum(base, negate=True)
                return n if coef == -1 else \
                    self.node("mul", self.num(-coef), n)
            n = self._product(factors, abs(coef) if abs(coef) != 1 else None)
            return self.node("neg", n) if coef < 0 else n
        closed = sym.atom_trig(e)
        if closed is not None:
            return self.lower(closed)
        return self.node("call", op, *[self.lower(a) for a in e.args])

    def _sum(self, e, negate=False):
        c, terms = e.args
        if negate:
            c, terms = -c, [(-k, t) for k, t in terms]
        # Terms that share a coefficient are summed first and scaled once.
        groups = {}
        for k, t in terms:
            groups.setdefault(abs(k), []).append((k > 0, self.lower(t)))
        signed = []
        for k, members in groups.items():
            if k == 1:
                signed += members
                continue
            positive = members[0][0]
            inner = self._fold([(p == positive, n) for p, n in members])
            signed.append((positive, self.node("mul", self.num(k), inner)))
        if c != 0:
            signed.append((c > 0, self.num(abs(c))))
        return self._fold(signed)

    def _fold(self, signed):
        """The sum of (positive?, node), the two operands ready first added
        first and each partial sum queued at its own ready time (Huffman on
        the latencies from the inputs, Graph.ready): the operand ready last
        waits for one addition only. Negative only if every term is."""
        heap = [(self.ready[n.index], k, pos, n)
                for k, (pos, n) in enumerate(signed)]
        heapq.heapify(heap)
        k = len(heap)
        while len(heap) > 1:
            _, _, pa, a = heapq.heappop(heap)
            _, _, pb, b = heapq.heappop(heap)
            if pa == pb:
                pos, n = pa, self.node("add", a, b)
            elif pa:
                pos, n = True, self.node("sub", a, b)
            else:
                pos, n = True, self.node("sub", b, a)
            heapq.heappush(heap, (self.ready[n.index], k, pos, n))
            k += 1
        _, _, pos, n = heap[0]
        return n if pos else self.node("neg", n)

    def _product(self, factors, coef=None):
        """The product of the factors (and a constant), associated as _fold
        associates sums."""
        nodes = [self.power(self.lower(b), e) for b, e in factors]
        if coef is not None:
            nodes.append(self.num(coef))
        heap = [(self.ready[n.index], k, n) for k, n in enumerate(nodes)]
        heapq.heapify(heap)
        k = len(heap)
        while len(heap) > 1:
            _, _, a = heapq.heappop(heap)
            _, _, b = heapq.heappop(heap)
            n = self.node("mul", a, b)
            heapq.heappush(heap, (self.ready[n.index], k, n))
            k += 1
        return heap[0][2]

    def power(self, base, e):
        """base^e from one reciprocal 1/base and one sqrt(base) per base.

        x^(-1/2) is sqrt(x) * (1/x), not 1/sqrt(x): the square root and the
        division start together instead of one after the other, and 1/x is
        the one division that x^-1, x^-3/2, ... share."""
        p = e.numerator
        if e.denominator == 1:
            return self._ipow(base, p) if p > 0 else \
                self._ipow(self.node("div", self.num(1), base), -p)
        if e.denominator != 2:
            return self.node("call", "pow", base, self.num(e))
        root = self.node("call", "sqrt", base)
        if p > 0:   # x^(p/2) = x^((p-1)/2) sqrt(x)
            return root if p == 1 else \
                self.node("mul", self._ipow(base, (p - 1) // 2), root)
        recip = self.node("div", self.num(1), base)
        return self.node("mul", root, self._ipow(recip, (1 - p) // 2))

    def _ipow(self, base, p):
        if p == 1:
            return base
        if p % 2 == 0:
            half = self._ipow(base, p // 2)
            return self.node("mul", half, half)
        return self.node("mul", self._ipow(base, p - 1), base)


class RangeError(ValueError):
    """A constant of a kernel that is finite and nonzero as a double but
    not a normal number in the precision asked for."""

    def __init__(self, value, reason):
        self.value, self.reason = value, reason
        super().__init__("constant %r %s" % (value, reason))


FLT_MAX = struct.unpack("<f", b"\xff\xff\x7f\x7f")[0]
FLT_MIN = 2.0 ** -126


def _round_float(x):
    """x rounded to the nearest IEEE binary32, as a Python float (inf when
    it overflows)."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)


def c_float(text):
    """A C float literal (f suffix) of the binary32 nearest the double
    constant text (a c_double), the shortest that rounds back to it.
    RangeError if it overflows or falls below FLT_MIN (a subnormal keeps
    fewer digits than the kernels' accuracy assumes; 0 loses the term)."""
    x = float(text)
    f = _round_float(x)
    if math.isinf(f):
        raise RangeError(x, "overflows single precision (above FLT_MAX "
                         "%.9g)" % FLT_MAX)
    if x != 0 and abs(f) < FLT_MIN:
        raise RangeError(x, "underflows single precision (below FLT_MIN "
                         "%.9g)" % FLT_MIN)
    for digits in range(1, 10):
        s = "%.*g" % (digits, f)
        if _round_float(float(s)) == f:
            break
    # The same digits as Python writes a double (100.0, not 1e+02; always
    # a '.' or an exponent, so the suffix makes a float literal).
    return repr(float(s)) + "f"


class Precision:
    """How the emitter spells one floating-point type: the C type, the
    literals, the <math.h> names (sin or sinf), the largest finite value
    of the finiteness guards and the NaN fill. The symbolic expressions and
    their lowering (the CSE graph) are the same for every precision."""

    def __init__(self, name, literal, suffix, huge, nan):
        self.name = self.ctype = name
        self.literal, self.suffix = literal, suffix
        self.huge, self.nan = huge, nan

    def call(self, fn):
        return fn + self.suffix


DOUBLE = Precision("double", lambda text: text, "",
                   "1.7976931348623157e308", "(double)NAN")
FLOAT = Precision("float", c_float, "f", "FLT_MAX", "NAN")
PRECISIONS = {"double": DOUBLE, "float": FLOAT}


def print_op(n, expr, parent_prec=0, right=False, call=None):
    """C text of operation node n, its operands printed by
    expr(node, precedence, right) (a temporary's name, an input, or the
    operand inline); call(name) spells a <math.h> function (default: as
    named, the double one)."""
    op = n.op
    if op == "call":
        return "%s(%s)" % (call(n.args[0]) if call else n.args[0],
                           ", ".join(expr(a) for a in n.args[1:]))
    if op == "neg":
        s = "-" + expr(n.args[0], 3)
    else:
        sym_op = {"add": "+", "sub": "-", "mul": "*", "div": "/"}[op]
        p = PREC[op]
        s = "%s %s %s" % (expr(n.args[0], p), sym_op,
                          expr(n.args[1], p, right=True))
    p = PREC[op]
    # Left-associative printing: a right operand of equal precedence
    # needs parentheses (a - (b + c)), a left one does not.
    if p < parent_prec or (p == parent_prec and right):
        return "(" + s + ")"
    return s


class Kernel:
    """One C function: inputs (C array, symbol names), outputs (C array, exprs)."""

    def __init__(self, name, doc, inputs, outputs, guards=(), params=None,
                 witnesses=(), pattern=None):
        self.name, self.doc = name, doc
        self.inputs = inputs          # [(array name, [symbol names])]
        self.outputs = outputs        # [(array name, [Expr])]
        self.guards = list(guards)    # Exprs required to lie in [-1, 1]
        self.params = params          # ParamsArg, or None
        # Output arrays whose finiteness the runtime tests after a call:
        # unseen_inputs() names the inputs those tests do not cover.
        self.witnesses = tuple(witnesses)
        # (dense rows, dense cols, positions): the one output is the
        # entries at these row-major positions of a dense matrix whose
        # other entries are identically zero.
        self.pattern = pattern


class ParamsArg:
    """A leading `const TYPE *p` argument whose members are symbols: each
    member a kernel uses is loaded once into a local (local(name)) at the
    top, so the CSE graph treats it as an input like q1."""

    def __init__(self, ctype, order, local, access):
        self.ctype = ctype            # C struct type name
        self.order = order            # symbol names, in struct order
        self.local = local            # symbol name -> C local name
        self.access = access          # symbol name -> C expression
        self.order_set = frozenset(order)


class _Names(dict):
    """Input symbol -> C local; parameter symbols are looked up on use."""

    def __init__(self, params):
        super().__init__()
        self.params = params

    def __missing__(self, key):
        if self.params is None or key not in self.params.order_set:
            raise KeyError(key)
        self[key] = self.params.local(key)
        return self[key]


def _uses(roots):
    """Operand-use counts of the nodes reachable from roots."""
    uses, stack = {}, list(roots)
    for r in roots:
        uses[r.index] = uses.get(r.index, 0) + 1
    seen = set()
    while stack:
        n = stack.pop()
        if n.index in seen:
            continue
        seen.add(n.index)
        for a in n.args:
            if isinstance(a, Node):
                uses[a.index] = uses.get(a.index, 0) + 1
                stack.append(a)
    return uses, seen


# Calls f with f(x) NaN or infinite whenever x is (sin(inf) is NaN,
# sqrt(inf) is inf); tanh(inf) = 1, atan2(inf, 1) = pi/2 and pow are not.
_STRICT_CALLS = ("sqrt", "sin", "cos", "tan", "asin", "acos")


def _strict(graph):
    """Per node of graph: the inputs (C local names) such that a NaN or an
    infinity in any of them makes the node NaN or infinite, whatever the
    other inputs are. IEEE arithmetic propagates both through +, -, * and a
    numerator (inf - inf, inf * 0 and inf / inf are NaN); a denominator does
    not (1 / inf = 0)."""
    strict = []
    for n in graph.nodes:                 # operands precede their users
        op = n.op
        if op == "in":
            s = frozenset((n.args[0],))
        elif op in ("add", "sub", "mul", "neg"):
            s = frozenset().union(*[strict[a.index] for a in n.args])
        elif op == "div":
            s = strict[n.args[0].index]
        elif op == "call" and n.args[0] in _STRICT_CALLS:
            s = strict[n.args[1].index]
        else:
            s = frozenset()
        strict.append(s)
    return strict


def unseen_inputs(kernel):
    """{input array: [indices]} of the inputs whose NaN or infinity can
    leave every output in kernel.witnesses finite: a caller that tests
    those outputs' finiteness must test these inputs itself, and no
    other. With guards, a non-finite q makes every output NaN."""
    low = Lowered(kernel)
    missing = set(kernel.witnesses) - {arr for arr, _ in low.out_nodes}
    if missing:
        raise ValueError("%s: no output %s" % (kernel.name, ", ".join(sorted(missing))))
    strict = _strict(low.graph)
    seen = set()
    for arr, ns in low.out_nodes:
        if arr in kernel.witnesses:
            for n in ns:
                seen |= strict[n.index]
    seen |= {n.args[0] for n in low.finite_nodes}
    return {arr: [i for i in range(len(syms)) if low.names[syms[i]] not in seen]
            for arr, syms in kernel.inputs}


class Emitted:
    def __init__(self, name, signature, body, counts, doc):
        self.name, self.signature, self.body = name, signature, body
        self.counts, self.doc = counts, doc

    @property
    def arithmetic(self):
        return sum(self.counts.get(k, 0) for k in ARITH)

    def summary(self):
        parts = ["%d %s" % (self.counts[k], k) for k in ARITH
                 if self.counts.get(k)]
        calls = sorted((k[5:], v) for k, v in self.counts.items()
                       if k.startswith("call:"))
        text = "%d arithmetic (%s)" % (self.arithmetic, ", ".join(parts)
                                       or "none")
        if calls:
            text += "; calls: " + ", ".join("%s %d" % kv for kv in calls)
        return text


class Lowered:
    """A kernel lowered to one graph: its guard, finiteness and output
    nodes, how often each node is used, the live nodes and the operation
    counts (what the scalar and the batched emitters share)."""

    def __init__(self, kernel):
        self.names = names = _Names(kernel.params)
        for arr, syms in kernel.inputs:
            for i, s in enumerate(syms):
                names[s] = "%s%d" % (arr, i + 1)
        self.graph = g = Graph(names)
        self.guard_nodes = [g.lower(x) for x in kernel.guards]
        # With guards, q itself must be finite too (q3 appears in no guard).
        self.finite_nodes = [g.node("in", names[s]) for s in kernel.inputs[0][1]] \
            if self.guard_nodes else []
        self.out_nodes = [(arr, [g.lower(x) for x in exprs])
                          for arr, exprs in kernel.outputs]
        roots = self.guard_nodes + self.finite_nodes + \
            [n for _, ns in self.out_nodes for n in ns]
        self.uses, self.live = _uses(roots)
        self.counts = counts = {}
        for i in sorted(self.live):
            n = g.nodes[i]
            if n.op in ARITH:
                counts[n.op] = counts.get(n.op, 0) + 1
            elif n.op == "call":
                key = "call:" + n.args[0]
                counts[key] = counts.get(key, 0) + 1


def emit(kernel, prefix, precision=DOUBLE):
    """The C function of kernel, named <prefix>_<kernel.name>, in the
    precision given (DOUBLE or FLOAT): the same graph, spelled for that
    type. RangeError if a constant does not fit the type."""
    params = kernel.params
    real, lit = precision.ctype, precision.literal
    low = Lowered(kernel)
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
        return print_op(n, expr, parent_prec, right, precision.call)

    # Inputs of the guard first, then the guard, then everything else.
    guard_live = _uses(guard_nodes)[1] if guard_nodes else set()
    lines = []
    for arr, syms in kernel.inputs:
        for i, s in enumerate(syms):
            lines.append("const %s %s%d = %s[%d];" % (real, arr, i + 1, arr, i))
    used_inputs = {g.nodes[i].args[0] for i in live if g.nodes[i].op == "in"}
    if params is not None:
        lines += ["const %s %s = %s;" % (real, params.local(s), params.access(s))
                  for s in params.order]
    lines = [l for l in lines if l.split()[2] in used_inputs]

    def emit_temps(indices):
        for i in sorted(indices):
            n = g.nodes[i]
            if i in temp or not materialized(n):
                continue
            name = "t%d" % len(temp)
            lines.append("const %s %s = %s;" % (real, name, inline(n)))
            temp[i] = name

    if guard_nodes:
        emit_temps(guard_live)
        fabs = precision.call("fabs")
        conds = ["%s(%s) <= %s" % (fabs, expr(n), lit("1.0"))
                 for n in guard_nodes]
        conds += ["%s(%s) <= %s" % (fabs, expr(n), precision.huge)
                  for n in finite_nodes]
        fills = ["for (int i = 0; i < %d; i++) %s[i] = %s;"
                 % (len(ns), arr, precision.nan) for arr, ns in out_nodes]
        lines.append("/* Unreachable or non-finite q: every output is NaN. */")
        lines.append("if (!(%s)) {" % " &&\n      ".join(conds))
        lines += ["  " + f for f in fills]
        lines.append("  return;")
        lines.append("}")
    # Each temporary right before its first use and each output stored as
    # soon as it is complete, rather than every temporary first and the
    # outputs last: GCC does not reorder straight-line code before register
    # allocation on x86-64, so the order printed is the order run.
    def pending(n):
        return isinstance(n, Node) and n.op not in ("num", "in") and \
            n.index not in temp

    def emit_needed(root):
        """root's temporaries in operand order, each after its operands
        (iterative, like _uses: the sums of long kernels nest deeply)."""
        stack, seen = [(root, False)], set()
        while stack:
            n, done = stack.pop()
            if done:
                if materialized(n) and n.index not in temp:
                    temp[n.index] = "t%d" % len(temp)
                    lines.append("const %s %s = %s;" % (real, temp[n.index], inline(n)))
                continue
            if not pending(n) or n.index in seen:
                continue
            seen.add(n.index)
            stack.append((n, True))
            stack.extend((a, False) for a in reversed(n.args) if pending(a))

    for arr, ns in out_nodes:
        for i, n in enumerate(ns):
            emit_needed(n)
            lines.append("%s[%d] = %s;" % (arr, i, expr(n)))
    for arr, syms in kernel.inputs:
        if not any(("%s%d" % (arr, i + 1)) in used_inputs
                   for i in range(len(syms))):
            lines.insert(0, "(void)%s;" % arr)
    args = []
    if params is not None:
        args.append("const %s *p" % params.ctype)
        if not any(params.local(s) in used_inputs for s in params.order):
            lines.insert(0, "(void)p;")
    args += ["const %s %s[%d]" % (real, arr, len(syms))
             for arr, syms in kernel.inputs]
    args += ["%s %s[%d]" % (real, arr, len(ns)) for arr, ns in out_nodes]
    signature = "void %s_%s(%s)" % (prefix, kernel.name, ", ".join(args))
    body = "\n".join("  " + l.replace("\n", "\n  ") for l in lines)
    return Emitted(kernel.name, signature, body, counts, kernel.doc)


def evaluate_lowered(exprs, env):
    """Evaluate exprs through the lowered graph, as the C code would.

    Used by the tests to show that lowering and CSE preserve values."""
    import math
    names = {k: k for k in env}
    g = Graph(names)
    roots = [g.lower(sym.as_expr(e)) for e in exprs]
    fns = {"sin": math.sin, "cos": math.cos, "tan": math.tan,
           "tanh": math.tanh,
           "asin": math.asin, "acos": math.acos, "atan2": math.atan2,
           "sqrt": math.sqrt, "pow": lambda b, e: b ** e}
    vals = []
    for n in g.nodes:
        a = [vals[x.index] if isinstance(x, Node) else x for x in n.args]
        op = n.op
        if op == "in":
            v = float(env[a[0]])
        elif op == "num":
            v = float(a[0])
        elif op == "add":
            v = a[0] + a[1]
        elif op == "sub":
            v = a[0] - a[1]
        elif op == "mul":
            v = a[0] * a[1]
        elif op == "div":
            v = a[0] / a[1]
        elif op == "neg":
            v = -a[0]
        else:
            v = fns[a[0]](*a[1:])
        vals.append(v)
    return [vals[r.index] for r in roots]
