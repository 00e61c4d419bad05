"""Hoisting: what the topology kernels compute from a model's numbers
alone is computed once per model instead of at every call.

A topology kernel reads every number of the model from its argument, so
lowered as derived, a product such as m l1 l2 cos(q1), or a sum whose
terms share their state part (m1 l1 c1 s2 + m2 l2 c1 s2), repeats the
parameters' arithmetic at every call, where a constant kernel has folded
it into one number. HoistGraph lowers them as the constant kernel is
lowered:

* the terms of a sum are grouped by their state part (the factors that
  depend on q, qd, ...) and each group's parameter coefficients summed:
  (m1 l1 + m2 l2) c1 s2;
* the parameter factors of a product are taken together: (m l1 l2) c1;
* every subexpression of the parameters alone (other than a parameter
  itself) is a slot h[k] of the derived numbers, which <prefix>_derive
  computes from the parameters once (render.render_topology).

The slots are shared by every kernel of a topology (one Hoisted per
generated file, keyed by the expression, which the symbolic engine
interns). Regrouping changes only the order of floating-point
operations, as constant folding does.
"""

from . import sym
from .cgen import Graph


class Hoisted:
    """The slots h[k] of one topology: parameter-only expressions, in the
    order the kernels first needed them (deterministic: the derivation
    and the kernels' order are)."""

    def __init__(self, param_names):
        self.param_ids = frozenset(sym.sym(n).id for n in param_names)
        self._slots = {}
        self.exprs = []

    def depends_on_params_only(self, e):
        return sym.free_symbols(e) <= self.param_ids

    def slot(self, e):
        """The slot of parameter-only e (a new one the first time)."""
        k = self._slots.get(e.id)
        if k is None:
            k = self._slots[e.id] = len(self.exprs)
            self.exprs.append(e)
        return k


def slot_name(k):
    """The symbol name of slot k (a ParamsArg member, like p->b[0])."""
    return "p->h[%d]" % k


class HoistGraph(Graph):
    """cgen.Graph for the kernels of a topology: parameter-only
    subexpressions become the inputs h[k] (Hoisted), sums and products are
    regrouped so that their parameter parts are such subexpressions."""

    def __init__(self, names, hoisted):
        super().__init__(names)
        self.hoisted = hoisted

    def _params_only(self, e):
        return self.hoisted.depends_on_params_only(e)

    def lower(self, e):
        n = self._lowered.get(e.id)
        if n is None:
            if e.op not in ("const", "sym") and self._params_only(e):
                n = self.node("in", self.names[slot_name(self.hoisted.slot(e))])
            else:
                n = self._lower(e)
            self._lowered[e.id] = n
        return n

    def _split(self, coef, factors):
        """(parameter part, state part) of coef * factors."""
        pf = [(b, x) for b, x in factors if self._params_only(b)]
        sf = tuple((b, x) for b, x in factors if not self._params_only(b))
        return sym.mul(coef, *[sym.power(b, x) for b, x in pf]), \
            sym._make_mul_or_one(sf)

    def _lower(self, e):
        if e.op == "mul":
            coef, factors = e.args
            part, state = self._split(coef, factors)
            if part.op != "const" and part.op != "sym":
                # The parameters' product as one slot, times the state part.
                return self.node("mul", self.lower(part), self.lower(state))
        return super()._lower(e)

    def _sum(self, e, negate=False):
        c, terms = e.args
        if negate:
            c, terms = -c, [(-k, t) for k, t in terms]
        groups = {}       # state part id -> [state part, parameter parts]
        for k, t in terms:
            if self._params_only(t):
                key, part = sym.ONE, sym.mul(k, t)
            elif t.op == "mul":
                part, key = self._split(k, t.args[1])
            else:
                key, part = t, sym.const(k)
            groups.setdefault(key.id, [key, []])[1].append(part)
        if c != 0 and sym.ONE.id in groups:
            groups[sym.ONE.id][1].append(sym.const(c))
            c = 0
        numeric, signed = [], []
        for key, parts in groups.values():
            coef = sym.add(*parts)
            if coef.op == "const" and key is sym.ONE:
                c = coef.args[0]          # the parameter terms cancelled
            elif coef.op == "const":
                if coef.args[0] != 0:
                    numeric.append((coef.args[0], key))
            elif key is sym.ONE:
                signed.append((True, self.lower(coef)))
            else:
                signed.append((True, self.node("mul", self.lower(coef),
                                               self.lower(key))))
        # Terms with a numeric coefficient as cgen.Graph lowers them.
        signed += self._scaled(numeric)
        if c != 0:
            signed.append((c > 0, self.num(abs(c))))
        if not signed:
            return self.num(0)
        return self._fold(signed)
