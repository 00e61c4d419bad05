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
        signed = self._scaled(terms)
        if c != 0:
            signed.append((c > 0, self.num(abs(c))))
        return self._fold(signed)

    def _scaled(self, terms):
        """(positive?, node) per coefficient of the terms (k, expression):
        terms that share a coefficient are summed first and scaled once."""
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
        return signed

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
    top, so the CSE graph treats it as an input like q1. With hoisted (a
    hoist.Hoisted), the kernels are lowered by hoist.HoistGraph and the
    slots p->h[k] are members too."""

    def __init__(self, ctype, order, local, access, hoisted=None):
        self.ctype = ctype            # C struct type name
        self.order = order            # symbol names, in struct order
        self.local = local            # symbol name -> C local name
        self.access = access          # symbol name -> C expression
        self.order_set = frozenset(order)
        self.hoisted = hoisted

    def members(self):
        """Every member's symbol name: the parameters, then the slots."""
        if self.hoisted is None:
            return self.order
        from .hoist import slot_name
        return list(self.order) + [slot_name(k) for k in range(len(self.hoisted.exprs))]

    def knows(self, name):
        return name in self.order_set or (
            self.hoisted is not None and name.startswith("p->h["))


class _Names(dict):
    """Input symbol -> C local; parameter symbols are looked up on use."""

    def __init__(self, params):
        super().__init__()
        self.params = params

    def __missing__(self, key):
        if self.params is None or not self.params.knows(key):
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
    counts (what both forms of emit(), scalar and batched, share)."""

    def __init__(self, kernel):
        self.names = names = _Names(kernel.params)
        for arr, syms in kernel.inputs:
            for i, s in enumerate(syms):
                names[s] = "%s%d" % (arr, i + 1)
        hoisted = kernel.params.hoisted if kernel.params is not None else None
        if hoisted is None:
            self.graph = g = Graph(names)
        else:
            from .hoist import HoistGraph
            self.graph = g = HoistGraph(names, hoisted)
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


class Batched:
    """The batched (structure-of-arrays) form of a kernel for emit(): n
    states per call, component i of state k at x[i n + k], in chunks of
    chunk states. loop_macro precedes every loop over states (empty unless
    the build defines it, e.g. as _Pragma("omp simd")); call_name(fn) spells
    a call the loops may vectorise (sin and cos of an input, which get
    loops of their own, and the functions in vector_calls), e.g. as a
    vector-variant declaration of batch.py's prologue."""

    def __init__(self, loop_macro, call_name, vector_calls=(), chunk=32):
        self.loop_macro, self.call_name = loop_macro, call_name
        self.vector_calls, self.chunk = tuple(vector_calls), chunk


def _is_input_trig(n):
    return n.op == "call" and n.args[0] in ("sin", "cos") and \
        isinstance(n.args[1], Node) and n.args[1].op == "in"


class _Writer:
    """What the scalar and the batched forms of one kernel print alike:
    operands inline or as the temporaries tN (a node used more than once,
    and every call, is a temporary), literals and calls in the kernel's
    precision, the parameters' locals."""

    def __init__(self, low, precision, vector_calls=(), call_name=None):
        self.low, self.precision = low, precision
        self.real, self.lit = precision.ctype, precision.literal
        self.vector_calls, self.call_name = vector_calls, call_name
        self.temp = {}
        g = low.graph
        self.used_inputs = {g.nodes[i].args[0] for i in low.live
                            if g.nodes[i].op == "in"}

    def materialized(self, n):
        return n.op not in ("num", "in") and \
            (self.low.uses.get(n.index, 0) > 1 or n.op == "call")

    def expr(self, n, parent_prec=0, right=False):
        if n.op == "in":
            return n.args[0]
        if n.op == "num":
            return self.lit(n.args[0])
        if n.index in self.temp:
            return self.temp[n.index]
        return self.inline(n, parent_prec, right)

    def inline(self, n, parent_prec=0, right=False):
        if n.op == "call" and n.args[0] in self.vector_calls:
            return "%s(%s)" % (self.call_name(n.args[0]), self.expr(n.args[1]))
        return print_op(n, self.expr, parent_prec, right, self.precision.call)

    def define(self, n):
        """The line of n's temporary, named in order of definition."""
        name = self.temp[n.index] = "t%d" % len(self.temp)
        return "const %s %s = %s;" % (self.real, name, self.inline(n))

    def param_locals(self, params):
        """A local per parameter the kernel uses (a float kernel converts
        each once, explicitly)."""
        cast = "" if self.real == "double" else "(%s)" % self.real
        return ["const %s %s = %s%s;" % (self.real, params.local(s), cast,
                                         params.access(s))
                for s in params.members() if params.local(s) in self.used_inputs]

    def guard_conditions(self, compare):
        """The guard as conditions compare(value, bound): every guard
        expression within [-1, 1] and, with guards, every q finite."""
        fabs = self.precision.call("fabs")
        return [compare("%s(%s)" % (fabs, self.expr(n)), self.lit("1.0"))
                for n in self.low.guard_nodes] + \
            [compare("%s(%s)" % (fabs, self.expr(n)), self.precision.huge)
             for n in self.low.finite_nodes]

    def unused_arrays(self, kernel):
        return [arr for arr, syms in kernel.inputs
                if not any(("%s%d" % (arr, i + 1)) in self.used_inputs
                           for i in range(len(syms)))]


def _scalar_lines(kernel, w):
    """One state: inputs loaded into locals, the guard as an early return,
    each temporary right before its first use and each output stored as
    soon as it is complete."""
    low, g, real = w.low, w.low.graph, w.real
    lines = ["const %s %s%d = %s[%d];" % (real, arr, i + 1, arr, i)
             for arr, syms in kernel.inputs for i, _ in enumerate(syms)
             if "%s%d" % (arr, i + 1) in w.used_inputs]
    # Each parameter is loaded into its local right before the first line
    # that uses it, not all at the top: a topology kernel reads hundreds,
    # and loads printed first stay first (see below), all live at once.
    params = kernel.params
    access = {} if params is None else \
        {params.local(s): params.access(s) for s in params.members()}

    def load_params(root):
        stack, seen = [root], set()
        while stack:
            n = stack.pop()
            if not isinstance(n, Node) or n.index in seen:
                continue
            seen.add(n.index)
            if n.op == "in":
                name = n.args[0]
                if name in access:
                    lines.append("const %s %s = %s;" % (real, name, access.pop(name)))
            elif n.op != "num" and (n is root or n.index not in w.temp):
                stack.extend(n.args)

    def define(n):
        load_params(n)
        lines.append(w.define(n))

    if low.guard_nodes:
        # Inputs of the guard first, then the guard, then everything else.
        for i in sorted(_uses(low.guard_nodes)[1]):
            n = g.nodes[i]
            if i not in w.temp and w.materialized(n):
                define(n)
        for n in low.guard_nodes:
            load_params(n)
        conds = w.guard_conditions(lambda x, bound: "%s <= %s" % (x, bound))
        lines.append("/* Unreachable or non-finite q: every output is NaN. */")
        lines.append("if (!(%s)) {" % " &&\n      ".join(conds))
        lines += ["  for (int i = 0; i < %d; i++) %s[i] = %s;"
                  % (len(ns), arr, w.precision.nan) for arr, ns in low.out_nodes]
        lines.append("  return;")
        lines.append("}")
    # GCC does not reorder straight-line code before register allocation on
    # x86-64, so the order printed is the order run.

    def pending(n):
        return isinstance(n, Node) and n.op not in ("num", "in") and \
            n.index not in w.temp

    def emit_needed(root):
        """root's temporaries in operand order, each after its operands
        (iterative, like _uses: the sums of long kernels nest deeply)."""
        stack, seen = [(root, False)], set()
        while stack:
            n, done = stack.pop()
            if done:
                if w.materialized(n) and n.index not in w.temp:
                    define(n)
                continue
            if not pending(n) or n.index in seen:
                continue
            seen.add(n.index)
            stack.append((n, True))
            stack.extend((a, False) for a in reversed(n.args) if pending(a))

    for arr, ns in low.out_nodes:
        for i, n in enumerate(ns):
            emit_needed(n)
            load_params(n)
            lines.append("%s[%d] = %s;" % (arr, i, w.expr(n)))
    lines = ["(void)%s;" % arr for arr in reversed(w.unused_arrays(kernel))] + lines
    if params is not None and not any(params.local(s) in w.used_inputs
                                      for s in params.members()):
        lines.insert(0, "(void)p;")
    return lines


def _row(i, index):
    """Offset of component i of the state at index in a row-per-component
    array of s states."""
    return index if i == 0 else "s + " + index if i == 1 else \
        "%d * s + %s" % (i, index)


def _batched_lines(kernel, w, form):
    """n states in chunks: sin and cos of the inputs in loops of their own
    (so the arithmetic loop calls nothing that does not vectorise), then
    every temporary in graph order in one loop, the guard as a per-state
    select and each output stored to its row."""
    low, g, real, lit, nan = w.low, w.low.graph, w.real, w.lit, w.precision.nan
    loop = form.loop_macro
    trig = [g.nodes[i] for i in sorted(low.live) if _is_input_trig(g.nodes[i])]
    trig_inputs = sorted({n.args[1].args[0] for n in trig})
    row = {"%s%d" % (arr, i + 1): (arr, i)
           for arr, syms in kernel.inputs for i, _ in enumerate(syms)}

    def load(name, index):
        arr, i = row[name]
        return "const %s %s = %s[%s];" % (real, name, arr, _row(i, index))

    lines = w.param_locals(kernel.params) if kernel.params is not None else []
    lines.append("const long s = n;")
    lines.append("for (long k0 = 0; k0 < s; k0 += %d) {" % form.chunk)
    lines.append("  const long m = s - k0 < %d ? s - k0 : %d;"
                 % (form.chunk, form.chunk))
    body = []
    if trig:
        body.append("%s %s;" % (real, ", ".join("w%d[%d]" % (j, form.chunk)
                                              for j in range(len(trig)))))
        # One loop per function: sin and cos of one argument in one loop
        # would be merged into a sincos call, which has no vector variant.
        for fn in ("cos", "sin"):
            group = [(j, n) for j, n in enumerate(trig) if n.args[0] == fn]
            if not group:
                continue
            body.append(loop)
            body.append("for (long k = 0; k < m; k++) {")
            body += ["  " + load(name, "k0 + k") for name in trig_inputs
                     if any(n.args[1].args[0] == name for _, n in group)]
            for j, n in group:
                body.append("  w%d[k] = %s(%s);" % (j, form.call_name(fn),
                                                   n.args[1].args[0]))
                w.temp[n.index] = "w%d[k]" % j
            body.append("}")
    body.append(loop)
    body.append("for (long k = 0; k < m; k++) {")
    inner = ["const long i = k0 + k;"]
    inner += [load(name, "i") for arr, syms in kernel.inputs
              for name in ("%s%d" % (arr, j + 1) for j in range(len(syms)))
              if name in w.used_inputs]
    for i in sorted(low.live):
        n = g.nodes[i]
        if i not in w.temp and w.materialized(n):
            inner.append(w.define(n))
    guarded = bool(low.guard_nodes)
    if guarded:
        conds = w.guard_conditions(
            lambda x, bound: "islessequal(%s, %s)" % (x, bound))
        inner.append("/* Unreachable or non-finite q: NaN (a select, not a "
                     "branch). */")
        inner.append("const int ok = %s;" % " &\n    ".join(conds))
    # Where the loop calls a function, each output is multiplied by 1 or
    # NaN instead: GCC sinks the work a select guards into a branch, and a
    # branch around a call stops the loop from being vectorised.
    calls = any(g.nodes[i].op == "call" and g.nodes[i].args[0] != "sqrt"
                and not _is_input_trig(g.nodes[i]) for i in low.live)
    if guarded and calls:
        inner.append("const %s okf = ok ? %s : %s;" % (real, lit("1.0"), nan))
    for arr, ns in low.out_nodes:
        for j, n in enumerate(ns):
            value = w.expr(n)
            if guarded and calls:
                value = "%s * okf" % w.expr(n, PREC["mul"])
            elif guarded:
                value = "ok ? %s : %s" % (value, nan)
            inner.append("%s[%s] = %s;" % (arr, _row(j, "i"), value))
    body += ["  " + l.replace("\n", "\n  ") for l in inner]
    body.append("}")
    lines += ["  " + l.replace("\n", "\n  ") for l in body]
    lines.append("}")
    return ["(void)%s;" % a for a in w.unused_arrays(kernel)] + lines


def emit(kernel, prefix, precision=DOUBLE, batched=None):
    """The C function of kernel in the precision given (DOUBLE or FLOAT):
    <prefix>_<kernel.name> for one state, or with batched (a Batched)
    <prefix>_batch_<kernel.name> for n. The same graph, spelled for that
    type and form: the forms differ only in their loads, stores and guard,
    and in the order of their temporaries. RangeError if a constant does
    not fit the type."""
    low = Lowered(kernel)
    real = precision.ctype
    args = []
    if kernel.params is not None:
        args.append("const %s *p" % kernel.params.ctype)
    if batched is None:
        w = _Writer(low, precision)
        lines = _scalar_lines(kernel, w)
        args += ["const %s %s[%d]" % (real, arr, len(syms))
                 for arr, syms in kernel.inputs]
        args += ["%s %s[%d]" % (real, arr, len(ns)) for arr, ns in low.out_nodes]
        name = "%s_%s" % (prefix, kernel.name)
    else:
        w = _Writer(low, precision, batched.vector_calls, batched.call_name)
        lines = _batched_lines(kernel, w, batched)
        args.append("int n")
        args += ["const %s *%s" % (real, arr) for arr, _ in kernel.inputs]
        args += ["%s *%s" % (real, arr) for arr, _ in low.out_nodes]
        name = "%s_batch_%s" % (prefix, kernel.name)
    signature = "void %s(%s)" % (name, ", ".join(args))
    body = "\n".join("  " + l.replace("\n", "\n  ") for l in lines)
    return Emitted(kernel.name, signature, body, low.counts, kernel.doc)


def evaluate_lowered(exprs, env, hoisted=None):
    """Evaluate exprs through the lowered graph, as the C code would; with
    hoisted (a hoist.Hoisted), through hoist.HoistGraph, the slots'
    values first evaluated from env as <prefix>_derive would.

    Used by the tests to show that lowering and CSE preserve values."""
    import math
    if hoisted is None:
        g = Graph({k: k for k in env})
        roots = [g.lower(sym.as_expr(e)) for e in exprs]
    else:
        from .hoist import HoistGraph, slot_name

        class SlotNames(dict):
            def __missing__(self, key):
                return key
        g = HoistGraph(SlotNames(), hoisted)
        roots = [g.lower(sym.as_expr(e)) for e in exprs]
        env = dict(env)
        for k, v in enumerate(evaluate_lowered(hoisted.exprs, env)):
            env[slot_name(k)] = v
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
