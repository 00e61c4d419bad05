"""The symbolic engine: rules checked by random numeric evaluation."""

import math
import random
import unittest
from fractions import Fraction

from prrugen import sym
from prrugen.cgen import evaluate_lowered

X, Y, Z = sym.sym("x"), sym.sym("y"), sym.sym("z")


def points(n=25, seed=1):
    rng = random.Random(seed)
    for _ in range(n):
        yield {"x": rng.uniform(-0.9, 0.9), "y": rng.uniform(-0.9, 0.9),
               "z": rng.uniform(0.2, 2.0)}


def value(e, env):
    return sym.evaluate([e], env)[0]


class Canonical(unittest.TestCase):
    def test_interning_makes_equal_expressions_identical(self):
        self.assertIs(X + Y, Y + X)
        self.assertIs(X * Y * Z, Z * (Y * X))
        self.assertIs(sym.sin(X + 1), sym.sin(1 + X))

    def test_zero_one_elimination_and_constant_folding(self):
        self.assertIs(X * 0, sym.ZERO)
        self.assertIs(X * 1, X)
        self.assertIs(X + 0, X)
        self.assertIs(X ** 0, sym.ONE)
        self.assertIs(sym.const(2) * Fraction(3, 4), sym.const(Fraction(3, 2)))
        self.assertIs(sym.sqrt(Fraction(9, 4)), sym.const(Fraction(3, 2)))

    def test_like_terms_and_powers_collect(self):
        self.assertIs(X + X, 2 * X)
        self.assertIs(X * Y - Y * X, sym.ZERO)
        self.assertIs(X * X * X, X ** 3)
        self.assertIs(X ** Fraction(1, 2) * X ** Fraction(1, 2), X)
        self.assertIs(X / X, sym.ONE)

    def test_pythagoras(self):
        e = 3 * sym.sin(X) ** 2 * Y + 3 * sym.cos(X) ** 2 * Y + Z
        self.assertIs(e, 3 * Y + Z)
        self.assertIs(sym.sin(X) ** 2 + sym.cos(X) ** 2, sym.ONE)

    def test_pythagoras_finds_the_pair_among_other_trig_squares(self):
        # sin(y)^2 sits beside the pair: the rule must look past it.
        s2 = sym.sin(Y) ** 2
        e = s2 * sym.sin(X) ** 2 * Z + s2 * sym.cos(X) ** 2 * Z
        self.assertIs(e, s2 * Z)

    def test_inverse_trig_rewrites_keep_values(self):
        u = X * Fraction(1, 2)
        cases = [sym.sin(sym.acos(u)), sym.cos(sym.acos(u)),
                 sym.sin(sym.asin(u)), sym.cos(sym.asin(u)),
                 sym.sin(sym.atan2(Y, Z)), sym.cos(sym.atan2(Y, Z)),
                 sym.tan(sym.atan2(Y, Z)), sym.sin(-X), sym.cos(-X)]
        plain = [lambda e: math.sin(math.acos(e["x"] / 2)),
                 lambda e: math.cos(math.acos(e["x"] / 2)),
                 lambda e: math.sin(math.asin(e["x"] / 2)),
                 lambda e: math.cos(math.asin(e["x"] / 2)),
                 lambda e: math.sin(math.atan2(e["y"], e["z"])),
                 lambda e: math.cos(math.atan2(e["y"], e["z"])),
                 lambda e: math.tan(math.atan2(e["y"], e["z"])),
                 lambda e: math.sin(-e["x"]), lambda e: math.cos(-e["x"])]
        for e, f in zip(cases, plain):
            self.assertNotIn(e.op, ("acos", "asin", "atan2"))
            for env in points():
                self.assertAlmostEqual(value(e, env), f(env), places=14)

    def test_sort_order_is_creation_order_not_hash(self):
        e = sym.sym("zz_late") + sym.sym("aa_later")
        self.assertEqual([t.args[0] for _, t in e.args[1]],
                         ["zz_late", "aa_later"])


class Differentiation(unittest.TestCase):
    EXPRS = [
        X * Y ** 3 + Z, X / (Y + 2), sym.sqrt(Z + X * X),
        sym.sin(X * Y), sym.cos(X + Z), sym.tan(X), sym.asin(X * Y),
        sym.acos(X / 2), sym.atan2(Y, Z + X), sym.atan2(X, Y - 2),
        X ** Fraction(-3, 2) * 0 + Z ** Fraction(-3, 2),
        Z ** Fraction(1, 3), sym.sin(X) ** 2 * sym.cos(Y) / Z,
        sym.acos((Fraction(36, 23) - sym.cos(X) * Fraction(27, 23)) / 2),
    ]

    def test_every_rule_against_central_differences(self):
        h = 1e-6
        for e in self.EXPRS:
            for s in (X, Y, Z):
                d = sym.diff(e, s)
                for env in points(8):
                    name = s.args[0]
                    hi, lo = dict(env), dict(env)
                    hi[name] += h
                    lo[name] -= h
                    fd = (value(e, hi) - value(e, lo)) / (2 * h)
                    an = value(d, env)
                    self.assertLessEqual(abs(an - fd), 1e-7 * (1 + abs(fd)),
                                         "d/d%s of %s" % (name, e))

    def test_directional_derivative_is_chain_rule(self):
        e = sym.sin(X) * Y ** 2
        xd, yd = sym.sym("xd"), sym.sym("yd")
        d = sym.directional(e, [X, Y], [xd, yd])
        env = {"x": 0.3, "y": -0.7, "xd": 1.5, "yd": 0.25}
        expect = math.cos(0.3) * 0.49 * 1.5 + math.sin(0.3) * 2 * -0.7 * 0.25
        self.assertAlmostEqual(value(d, env), expect, places=15)


class Atoms(unittest.TestCase):
    """Defined symbols: g = atan2(y, x * z) with its partials, rate and
    rate bias as atoms, as mechanism.atom() builds them."""

    def setUp(self):
        self.x, self.y, self.z = sym.sym("x"), sym.sym("y"), sym.sym("z")
        self.q = [self.x, self.y]
        self.qd = [sym.sym("xd"), sym.sym("yd")]
        self.value = sym.atan2(self.y, self.x * self.z)
        dt = sym.TimeDerivative(self.q, self.qd)
        gx = sym.define("g_x", sym.diff(self.value, self.x))
        gy = sym.define("g_y", sym.diff(self.value, self.y))
        bias = sym.define("g_bias", dt(gx) * self.qd[0] + dt(gy) * self.qd[1])
        rate = sym.define("g_rate", gx * self.qd[0] + gy * self.qd[1],
                          rate=bias)
        self.g = sym.define("g", self.value, {self.x: gx, self.y: gy}, rate)
        self.env = {"x": 0.4, "y": -0.3, "z": 1.7, "xd": 0.8, "yd": -1.1}

    def test_values_and_free_symbols_come_from_the_definition(self):
        e = sym.sin(self.g) * self.z
        self.assertAlmostEqual(value(e, self.env), math.sin(math.atan2(
            -0.3, 0.4 * 1.7)) * 1.7, places=15)
        names = {sym.to_str(sym.sym(n)) for n in ("g", "x", "y", "z")}
        got = {sym.to_str(n) for n in sym.topological([e]) if n.op == "sym"}
        self.assertLessEqual(names, got)

    def test_derivatives_through_the_atom_equal_those_of_its_value(self):
        plain = sym.cos(self.value) * self.x ** 2
        atom = sym.cos(self.g) * self.x ** 2
        dt = sym.TimeDerivative(self.q, self.qd)
        for a, b in [(sym.diff(atom, self.x), sym.diff(plain, self.x)),
                     (sym.diff(atom, self.z), sym.diff(plain, self.z)),
                     (dt(atom), dt(plain)), (dt(dt(atom)), dt(dt(plain)))]:
            self.assertAlmostEqual(value(a, self.env), value(b, self.env),
                                   places=13)
        # The chain rule stops at the atom: d sin(g) = cos(g) g_x, short.
        self.assertIs(sym.diff(sym.sin(self.g), self.x),
                      sym.cos(self.g) * sym.sym("g_x"))
        self.assertIs(dt(self.g), sym.sym("g_rate"))
        self.assertIs(dt(sym.sym("g_rate")), sym.sym("g_bias"))

    def test_explicit_partials_hold_the_atom_fixed(self):
        e = sym.sin(self.g) * self.x + self.y
        self.assertIs(sym.diff(e, self.x, explicit=True), sym.sin(self.g))
        self.assertIs(sym.diff(e, self.g, explicit=True), sym.cos(self.g) * self.x)

    def test_lowering_substitutes_the_values(self):
        exprs = [sym.sin(self.g) * sym.sym("g_rate"), sym.sym("g_bias"),
                 sym.cos(self.g) ** 2]
        want = sym.evaluate(exprs, self.env)
        got = evaluate_lowered(exprs, self.env)
        for w, g in zip(want, got):
            self.assertAlmostEqual(w, g, places=13)

    def test_redefinition_and_definition_after_use_are_refused(self):
        with self.assertRaises(ValueError):
            sym.define("g", self.x)
        s = sym.sym("late")
        sym.diff(s * self.x, self.x)     # used: its free symbols are known
        with self.assertRaises(ValueError):
            sym.define("late", self.x)


class Lowering(unittest.TestCase):
    def test_sums_and_products_take_the_late_operand_last(self):
        # sqrt(w + 1) is ready long after p and r: it joins last, so one
        # operation follows it, not two. It is built before p and r, so
        # term and factor order (creation order) would put it first.
        from prrugen import cgen
        late = sym.sqrt(sym.sym("w_late") + 1)
        p, r = sym.sym("p_early"), sym.sym("r_early")
        g = cgen.Graph({n: n for n in ("w_late", "p_early", "r_early")})
        for e, op in ((late * p * r, "mul"), (late + p + r, "add")):
            n = g.lower(e)
            self.assertEqual(n.op, op)
            a, b = n.args
            root = g.lower(late)
            self.assertIn(root, (a, b))
            other = b if a is root else a
            self.assertEqual(other.op, op)
            self.assertEqual(g.ready[n.index], g.ready[root.index] + 3)


    def test_unseen_inputs(self):
        # A NaN or an infinity reaches an output through +, -, * and a
        # numerator, and sin, cos, sqrt; not through tanh or a denominator
        # (tanh(inf) = 1, 1 / inf = 0), nor from an output that is no
        # witness.
        from prrugen import cgen
        u, v, w = sym.sym("u"), sym.sym("v"), sym.sym("w")
        outs = [("o", [X * sym.sin(Y) + sym.tanh(Z) * u / v]), ("p", [w])]
        ins = [("a", ["x", "y", "z"]), ("b", ["u", "v", "w"])]
        k = cgen.Kernel("k", "", ins, outs, witnesses=("o",))
        self.assertEqual(cgen.unseen_inputs(k), {"a": [2], "b": [1, 2]})
        k = cgen.Kernel("k", "", ins, outs, witnesses=("o", "p"))
        self.assertEqual(cgen.unseen_inputs(k), {"a": [2], "b": [1]})
        # With guards, a non-finite first input array makes every output NaN.
        k = cgen.Kernel("k", "", ins, outs, guards=[X / 2], witnesses=("p",))
        self.assertEqual(cgen.unseen_inputs(k), {"a": [], "b": [0, 1]})
        with self.assertRaises(ValueError):
            cgen.unseen_inputs(cgen.Kernel("k", "", ins, outs, witnesses=("q",)))

    def test_cse_and_lowering_preserve_values(self):
        exprs = [e for e in Differentiation.EXPRS]
        exprs += [sym.diff(e, X) for e in Differentiation.EXPRS]
        exprs += [-X * Y / Z ** 2 - 3, Fraction(-5, 7) * X ** -3]
        for env in points(10):
            want = sym.evaluate(exprs, env)
            got = evaluate_lowered(exprs, env)
            for w, g, e in zip(want, got, exprs):
                self.assertLessEqual(abs(w - g), 1e-12 * (1 + abs(w)), str(e))


if __name__ == "__main__":
    unittest.main()
