"""A small symbolic engine: hash-consed expression DAG over exact rationals.

Every expression is interned: building the same expression twice returns the
same object, so equality is identity and common subexpressions are shared by
construction. Sums and products are n-ary and canonical (terms sorted by
creation order, which is deterministic because the program is), which makes
`a + b` and `b + a` the same node and lets like terms and powers collect.

Node kinds (Expr.op):
  const  args = (Fraction,)
  sym    args = (name,)
  add    args = (constant, ((coef, term), ...))   term: not const/add, coef 1
  mul    args = (coef, ((base, exponent), ...))   exponent: Fraction != 0
  sin cos tan tanh asin acos   args = (x,)
  atan2  args = (y, x)

A symbol may be defined (define()): it stands for an expression of other
symbols, its value, and may carry its own partial derivatives and time
derivative, themselves defined symbols. The mechanism's intermediate
angles are such atoms, so that derivatives go through them by the chain
rule (d sin(g) = cos(g) dg, dg a symbol) instead of through their closed
forms, whose derivatives grow with every differentiation; the lowering to
C and evaluate() substitute the values.

Simplifications applied at construction, because they are what makes the
mechanism's expressions small: 0/1 elimination, constant folding, like terms
and powers, a sin^2 + a cos^2 = a, and sin/cos of inverse trig functions
(sin(acos x) = sqrt(1 - x^2), cos(atan2(y, x)) = x / hypot(x, y), ...), which
removes every angle of the inverse kinematics from the derived quantities.
"""

import math
from fractions import Fraction

_table = {}
_counter = [0]


class Expr:
    __slots__ = ("op", "args", "id", "_free", "_def")

    def __init__(self, op, args, ident):
        self.op, self.args, self.id = op, args, ident
        self._free = None
        self._def = None              # a defined symbol's Definition

    def __hash__(self):
        return self.id

    def __repr__(self):
        return to_str(self)

    # Operators make mechanism code read like the spec's formulas.
    def __add__(self, o): return add(self, o)
    def __radd__(self, o): return add(o, self)
    def __sub__(self, o): return add(self, mul(-1, o))
    def __rsub__(self, o): return add(o, mul(-1, self))
    def __mul__(self, o): return mul(self, o)
    def __rmul__(self, o): return mul(o, self)
    def __truediv__(self, o): return mul(self, power(o, -1))
    def __rtruediv__(self, o): return mul(o, power(self, -1))
    def __neg__(self): return mul(-1, self)
    def __pow__(self, e): return power(self, e)


def _key_part(a):
    if isinstance(a, Expr):
        return ("e", a.id)
    if isinstance(a, tuple):
        return tuple(_key_part(x) for x in a)
    return a


def _intern(op, args):
    key = (op, _key_part(args))
    node = _table.get(key)
    if node is None:
        _counter[0] += 1
        node = Expr(op, args, _counter[0])
        _table[key] = node
    return node


def const(v):
    return _intern("const", (Fraction(v),))


def sym(name):
    return _intern("sym", (name,))


ZERO = const(0)
ONE = const(1)


class Definition:
    __slots__ = ("value", "partials", "rate")

    def __init__(self, value, partials, rate):
        self.value = value            # the expression the symbol stands for
        self.partials = partials      # {symbol id: d value / d symbol}
        self.rate = rate              # d value / dt along the mechanism's
                                      # q' = qd, or None


def define(name, value, partials=None, rate=None):
    """The symbol `name` standing for `value`. partials {symbol: Expr} and
    rate give derivatives that differentiation then uses instead of
    differentiating the value; they must equal the value's own."""
    s = sym(name)
    value = as_expr(value)
    if s._def is not None and s._def.value is not value:
        raise ValueError("symbol %s is already defined otherwise" % name)
    if s._free is not None and s._def is None:
        raise ValueError("symbol %s is used before its definition" % name)
    s._def = Definition(value, {k.id: as_expr(v) for k, v in
                                (partials or {}).items()},
                        None if rate is None else as_expr(rate))
    return s


def definition(e):
    """The Definition of a defined symbol, else None."""
    return e._def


def atom_trig(e):
    """sin or cos of a defined symbol as that of its value, in closed form
    (sin(atan2(y, x)) = y / hypot(x, y), ...); None for anything else."""
    if e.op in ("sin", "cos") and e.args[0]._def is not None:
        return (sin if e.op == "sin" else cos)(e.args[0]._def.value)
    return None


def reset():
    """Forget every expression built since import. Term order follows
    creation order, so a generator run starts from here: the output of one
    model then never depends on what else the process built before. Ids
    keep increasing (only their order matters), so an expression kept from
    before a reset can never be confused with a new one."""
    global _table
    _table = dict(_BASE_TABLE)
    _diff_cache.clear()


def as_expr(x):
    if isinstance(x, Expr):
        return x
    if isinstance(x, (int, Fraction)):
        return const(x)
    raise TypeError("not an exact expression: %r" % (x,))


def is_const(e, value=None):
    return e.op == "const" and (value is None or e.args[0] == value)


def _split_coef(e):
    """e = coef * term with term free of a numeric factor."""
    if e.op == "mul" and e.args[0] != 1:
        return e.args[0], _make_mul(Fraction(1), e.args[1])
    return Fraction(1), e


# ---------------------------------------------------------------- sums ---

def add(*xs):
    c = Fraction(0)
    acc = {}
    for x in xs:
        x = as_expr(x)
        if x.op == "const":
            c += x.args[0]
        elif x.op == "add":
            c += x.args[0]
            for k, t in x.args[1]:
                acc[t] = acc.get(t, 0) + k
        elif _is_scaled_sum(x):
            # Flatten k (a + b) too, so that mirrored limbs cancel; the
            # result is put back in primitive form below.
            k0, s = x.args[0], x.args[1][0][0]
            c += k0 * s.args[0]
            for k, t in s.args[1]:
                acc[t] = acc.get(t, 0) + k0 * k
        else:
            k, t = _split_coef(x)
            acc[t] = acc.get(t, 0) + k
    terms = [(k, t) for t, k in acc.items() if k != 0]
    merged = _pythagoras(terms, c)
    if merged is not None:
        return add(const(merged[1]), *[mul(k, t) for k, t in merged[0]])
    terms.sort(key=lambda kt: kt[1].id)
    if not terms:
        return const(c)
    if c == 0 and len(terms) == 1:
        k, t = terms[0]
        return mul(k, t)
    # Primitive part: k (t0 + c1 t1 + ...) with the first coefficient 1, so
    # that scaled copies of one sum (a body's bias term times its mass, say)
    # share a single node and cost one multiplication each.
    k0 = terms[0][0]
    node = _intern("add", (c / k0, tuple((k / k0, t) for k, t in terms)))
    return node if k0 == 1 else _make_mul(k0, ((node, Fraction(1)),))


def _is_scaled_sum(x):
    return x.op == "mul" and len(x.args[1]) == 1 and x.args[1][0][1] == 1 \
        and x.args[1][0][0].op == "add"


def _trig_squares(t, fn):
    """Every factor fn(u)^2 of monomial t, as [(u, rest factors)]."""
    if t.op == "mul" and t.args[0] == 1:
        factors = t.args[1]
    elif t.op == "mul":
        return []
    else:
        factors = ((t, Fraction(1)),)
    return [(b.args[0], factors[:i] + factors[i + 1:])
            for i, (b, e) in enumerate(factors) if b.op == fn and e == 2]


def _pythagoras(terms, c):
    """sin^2 + cos^2 = 1 on a sum's terms: k R s^2 + k R c^2 -> k R and
    k R c^2 - k R -> -k R s^2 (and with s, c swapped; R may be the constant
    term). Returns (terms, constant) after one rewrite, or None."""
    trig = []
    for pos, (k, t) in enumerate(terms):
        for fn in ("sin", "cos"):
            for u, rest in _trig_squares(t, fn):
                trig.append((pos, fn, u, rest))
    if not trig:
        return None
    index = {(fn, u.id, _key_part(rest)): pos for pos, fn, u, rest in trig}
    position = {t.id: pos for pos, (_, t) in enumerate(terms)}
    for pos, fn, u, rest in trig:
        k = terms[pos][0]
        other = "cos" if fn == "sin" else "sin"
        rest_e = _make_mul_or_one(rest)
        partner = index.get((other, u.id, _key_part(rest)))
        if partner is not None and terms[partner][0] == k:
            out = [kt for i, kt in enumerate(terms) if i not in (pos, partner)]
            return out + [(k, rest_e)], c
        square = power(cos(u) if other == "cos" else sin(u), 2)
        if rest_e is ONE and c == -k:
            out = [kt for i, kt in enumerate(terms) if i != pos]
            return out + [(-k, square)], Fraction(0)
        partner = position.get(rest_e.id)
        if partner is not None and terms[partner][0] == -k:
            out = [kt for i, kt in enumerate(terms) if i not in (pos, partner)]
            return out + [(-k, mul(rest_e, square))], c
    return None


def _make_mul_or_one(factors):
    if not factors:
        return ONE
    return _make_mul(Fraction(1), factors)


# ------------------------------------------------------------ products ---

def _make_mul(coef, factors):
    if not factors:
        return const(coef)
    if coef == 1 and len(factors) == 1 and factors[0][1] == 1:
        return factors[0][0]
    return _intern("mul", (coef, tuple(factors)))


def mul(*xs):
    coef = Fraction(1)
    acc = {}
    for x in xs:
        x = as_expr(x)
        if x.op == "const":
            coef *= x.args[0]
        elif x.op == "mul":
            coef *= x.args[0]
            for b, e in x.args[1]:
                acc[b] = acc.get(b, 0) + e
        else:
            acc[x] = acc.get(x, 0) + 1
        if coef == 0:
            return ZERO
    factors = []
    for b, e in acc.items():
        if e == 0:
            continue
        if b.op == "const" and e.denominator == 1:
            coef *= b.args[0] ** e
        else:
            factors.append((b, Fraction(e)))
    factors.sort(key=lambda be: be[0].id)
    return _make_mul(coef, factors)


def _exact_root(v, n):
    """v**(1/n) for a positive Fraction when it is rational, else None."""
    def iroot(x):
        r = round(x ** (1.0 / n)) if x < 2 ** 1000 else None
        if r is None:
            return None
        for cand in (r - 1, r, r + 1):
            if cand >= 0 and cand ** n == x:
                return cand
        return None
    if v <= 0:
        return None
    a, b = iroot(v.numerator), iroot(v.denominator)
    if a is None or b is None:
        return None
    return Fraction(a, b)


def power(b, e):
    b = as_expr(b)
    e = Fraction(e)
    if e == 0:
        return ONE
    if e == 1:
        return b
    if b.op == "const":
        v = b.args[0]
        if v == 0:
            if e < 0:
                raise ZeroDivisionError("0 ** %s" % e)
            return ZERO
        if e.denominator == 1:
            return const(v ** int(e))
        root = _exact_root(v, e.denominator)
        if root is not None:
            return const(root ** e.numerator)
        return _make_mul(Fraction(1), ((b, e),))
    if b.op == "mul" and e.denominator == 1:
        n = int(e)
        return mul(const(b.args[0] ** n),
                   *[_make_mul(Fraction(1), ((bb, ee * n),))
                     for bb, ee in b.args[1]])
    return _make_mul(Fraction(1), ((b, e),))


def sqrt(x):
    return power(x, Fraction(1, 2))


# ----------------------------------------------------------- functions ---

def _negated(x):
    """If x = -y with y 'positive-looking', return y, else None."""
    if x.op == "mul" and x.args[0] < 0:
        return mul(-1, x)
    if x.op == "const" and x.args[0] < 0:
        return const(-x.args[0])
    return None


def sin(x):
    x = as_expr(x)
    if is_const(x, 0):
        return ZERO
    y = _negated(x)
    if y is not None:
        return -sin(y)
    if x.op == "asin":
        return x.args[0]
    if x.op == "acos":
        u = x.args[0]
        return sqrt(1 - u * u)
    if x.op == "atan2":
        yy, xx = x.args
        return yy * power(xx * xx + yy * yy, Fraction(-1, 2))
    return _intern("sin", (x,))


def cos(x):
    x = as_expr(x)
    if is_const(x, 0):
        return ONE
    y = _negated(x)
    if y is not None:
        return cos(y)
    if x.op == "acos":
        return x.args[0]
    if x.op == "asin":
        u = x.args[0]
        return sqrt(1 - u * u)
    if x.op == "atan2":
        yy, xx = x.args
        return xx * power(xx * xx + yy * yy, Fraction(-1, 2))
    return _intern("cos", (x,))


def tan(x):
    x = as_expr(x)
    if is_const(x, 0):
        return ZERO
    y = _negated(x)
    if y is not None:
        return -tan(y)
    if x.op == "atan2":
        return x.args[0] / x.args[1]
    return _intern("tan", (x,))


def tanh(x):
    x = as_expr(x)
    if is_const(x, 0):
        return ZERO
    y = _negated(x)
    if y is not None:
        return -tanh(y)
    return _intern("tanh", (x,))


def asin(x):
    x = as_expr(x)
    if is_const(x, 0):
        return ZERO
    y = _negated(x)
    if y is not None:
        return -asin(y)
    return _intern("asin", (x,))


def acos(x):
    x = as_expr(x)
    if is_const(x, 1):
        return ZERO
    return _intern("acos", (x,))


def atan2(y, x):
    y, x = as_expr(y), as_expr(x)
    if is_const(y, 0) and x.op == "const" and x.args[0] > 0:
        return ZERO
    return _intern("atan2", (y, x))


# ------------------------------------------------------ differentiation ---

def free_symbols(e):
    """Frozenset of the ids of the symbols e depends on (memoized)."""
    if e._free is not None:
        return e._free
    stack = [e]
    while stack:
        n = stack[-1]
        if n._free is not None:
            stack.pop()
            continue
        pending = [c for c in children(n) if c._free is None]
        if pending:
            stack.extend(pending)
            continue
        stack.pop()
        if n.op == "sym":
            n._free = frozenset((n.id,)).union(*[c._free for c in children(n)])
        else:
            n._free = frozenset().union(*[c._free for c in children(n)])
    return e._free


def children(e):
    if e.op == "add":
        return [t for _, t in e.args[1]]
    if e.op == "mul":
        return [b for b, _ in e.args[1]]
    if e.op == "sym":
        return [e._def.value] if e._def is not None else []
    if e.op == "const":
        return []
    return list(e.args)


_diff_cache = {}


def diff(e, s, explicit=False):
    """d e / d s for a symbol s; explicit: the partial derivative that
    holds every defined symbol (atom) other than s fixed."""
    e = as_expr(e)
    if s.id not in free_symbols(e):
        return ZERO
    key = (e.id, s.id, explicit)
    hit = _diff_cache.get(key)
    if hit is not None:
        return hit
    op = e.op
    if op == "sym":
        d = e._def
        if e is s:
            r = ONE
        elif explicit:
            r = ZERO
        elif s.id in d.partials:
            r = d.partials[s.id]
        else:
            r = diff(d.value, s)
    elif op == "add":
        r = add(*[mul(k, diff(t, s, explicit)) for k, t in e.args[1]])
    elif op == "mul":
        coef, factors = e.args
        terms = []
        for i, (b, ex) in enumerate(factors):
            db = diff(b, s, explicit)
            if is_const(db, 0):
                continue
            rest = [_make_mul(Fraction(1), ((bb, ee),))
                    for j, (bb, ee) in enumerate(factors) if j != i]
            terms.append(mul(coef, ex, power(b, ex - 1), db, *rest))
        r = add(*terms)
    else:
        x = e.args[0]
        dx = diff(x, s, explicit) if op != "atan2" else None
        if op == "sin":
            r = cos(x) * dx
        elif op == "cos":
            r = -sin(x) * dx
        elif op == "tan":
            r = (1 + e * e) * dx
        elif op == "tanh":
            r = (1 - e * e) * dx
        elif op == "asin":
            r = dx * power(1 - x * x, Fraction(-1, 2))
        elif op == "acos":
            r = -dx * power(1 - x * x, Fraction(-1, 2))
        elif op == "atan2":
            y, xx = e.args
            r = (xx * diff(y, s, explicit) - y * diff(xx, s, explicit)) \
                / (xx * xx + y * y)
        else:
            raise ValueError("cannot differentiate %s" % op)
    _diff_cache[key] = r
    return r


def directional(e, qs, qds):
    """Time derivative of e(q) along q' = qd (qd held constant)."""
    return add(*[mul(diff(e, q), qd) for q, qd in zip(qs, qds)])


class TimeDerivative:
    """d/dt along q' = qd with qd constant, in forward mode.

    Equal to directional() but applied node by node: every intermediate's
    rate is one shared node, instead of three partial-derivative graphs
    combined only at the root, which makes velocity and bias terms about
    three times cheaper to evaluate."""

    def __init__(self, qs, qds):
        self.rate = {q.id: as_expr(qd) for q, qd in zip(qs, qds)}
        self.ids = frozenset(self.rate)
        self.memo = {}

    def __call__(self, e):
        e = as_expr(e)
        if not (free_symbols(e) & self.ids):
            return ZERO
        hit = self.memo.get(e.id)
        if hit is not None:
            return hit
        op = e.op
        if op == "sym":
            d = e._def
            if d is None:
                r = self.rate[e.id]
            else:
                r = d.rate if d.rate is not None else self(d.value)
        elif op == "add":
            r = add(*[mul(k, self(t)) for k, t in e.args[1]])
        elif op == "mul":
            coef, factors = e.args
            terms = []
            for i, (b, ex) in enumerate(factors):
                db = self(b)
                if is_const(db, 0):
                    continue
                rest = [_make_mul(Fraction(1), ((bb, ee),))
                        for j, (bb, ee) in enumerate(factors) if j != i]
                terms.append(mul(coef, ex, power(b, ex - 1), db, *rest))
            r = add(*terms)
        elif op == "atan2":
            y, x = e.args
            r = (x * self(y) - y * self(x)) / (x * x + y * y)
        else:
            x = e.args[0]
            dx = self(x)
            if op == "sin":
                r = cos(x) * dx
            elif op == "cos":
                r = -sin(x) * dx
            elif op == "tan":
                r = (1 + e * e) * dx
            elif op == "tanh":
                r = (1 - e * e) * dx
            elif op == "asin":
                r = dx * power(1 - x * x, Fraction(-1, 2))
            elif op == "acos":
                r = -dx * power(1 - x * x, Fraction(-1, 2))
            else:
                raise ValueError("cannot differentiate %s" % op)
        self.memo[e.id] = r
        return r


# ------------------------------------------------------------ evaluation ---

def _safe(fn):
    def f(*a):
        try:
            return fn(*a)
        except (ValueError, ZeroDivisionError, OverflowError):
            return math.nan
    return f


_NUMERIC = {
    "sin": _safe(math.sin), "cos": _safe(math.cos), "tan": _safe(math.tan),
    "tanh": _safe(math.tanh),
    "asin": _safe(math.asin), "acos": _safe(math.acos),
    "atan2": _safe(math.atan2),
}


def _pow(b, e):
    if e.denominator == 1:
        try:
            return b ** int(e)
        except ZeroDivisionError:
            return math.inf
    if b < 0:
        return math.nan
    if b == 0:
        return 0.0 if e > 0 else math.inf
    return b ** float(e)


def evaluate(exprs, env):
    """Float values of exprs under env {symbol name: float} (memoized)."""
    memo = {}

    def ev(n):
        v = memo.get(n.id)
        if v is not None:
            return v
        op = n.op
        if op == "const":
            v = float(n.args[0])
        elif op == "sym":
            d = n._def
            v = float(env[n.args[0]]) if d is None or n.args[0] in env \
                else ev(d.value)
        elif op == "add":
            v = float(n.args[0]) + math.fsum(float(k) * ev(t)
                                             for k, t in n.args[1])
        elif op == "mul":
            v = float(n.args[0])
            for b, e in n.args[1]:
                v *= _pow(ev(b), e)
        else:
            v = _NUMERIC[op](*[ev(a) for a in n.args])
        memo[n.id] = v
        return v

    for e in exprs:
        for n in topological([as_expr(e)]):
            ev(n)
    return [ev(as_expr(e)) for e in exprs]


def topological(roots):
    """All nodes reachable from roots, children before parents."""
    seen, order = set(), []
    for r in roots:
        if r.id in seen:
            continue
        stack = [(r, False)]
        while stack:
            n, done = stack.pop()
            if done:
                order.append(n)
                continue
            if n.id in seen:
                continue
            seen.add(n.id)
            stack.append((n, True))
            for c in reversed(children(n)):
                if c.id not in seen:
                    stack.append((c, False))
    return order


def to_str(e):
    op = e.op
    if op == "const":
        return str(e.args[0])
    if op == "sym":
        return e.args[0]
    if op == "add":
        parts = [("%s*%s" % (k, to_str(t)) if k != 1 else to_str(t))
                 for k, t in e.args[1]]
        if e.args[0] != 0:
            parts.insert(0, str(e.args[0]))
        return "(" + " + ".join(parts) + ")"
    if op == "mul":
        parts = [to_str(b) if ex == 1 else "%s^(%s)" % (to_str(b), ex)
                 for b, ex in e.args[1]]
        if e.args[0] != 1:
            parts.insert(0, str(e.args[0]))
        return "*".join(parts)
    return "%s(%s)" % (op, ", ".join(to_str(a) for a in e.args))


# Everything interned at import (ZERO, ONE, ...) survives reset().
_BASE_TABLE = dict(_table)
