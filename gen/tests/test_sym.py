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


class Lowering(unittest.TestCase):
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
