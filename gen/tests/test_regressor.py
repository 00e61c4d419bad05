"""The regressor (prru_regressor.{h,c}, prrugen/regressor.py).

- Y pi, evaluated from the symbolic expressions, equals M qdd + h - G -
  passive of the constant derivation (the model's numbers folded in) at
  random states, for the paper's model and the prototype (centres of mass,
  products of inertia, tilted gravity, drives);
- Y does not depend on the inertial parameters (no parameter symbol is
  left in it), only on q, qd, qdd and the smoothing velocity;
- the standard parameters of a body with an offset centre of mass obey the
  parallel-axis rule, and the column names are unique and ordered;
- the other generated files are unchanged by it, and the regressor files
  are byte-identical when generated twice in one process.
"""

import os
import random
import unittest
from fractions import Fraction

from prrugen import dynamics, mechanism, model, regressor, sym

import prru_gen  # noqa: E402  (gen/ is on the path: tests run from gen/)

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
PAPER = os.path.join(ROOT, "models", "3prru_paper.json")
PROTO = os.path.join(ROOT, "models", "prototype_example.json")


def _regressor(m):
    sym.reset()
    rm = regressor.RegressorModel(m)
    deriv = dynamics.Derivation(mechanism.build(rm), rm)
    return regressor.regressor_kernel(m, deriv, rm)


def _dynamics(m):
    """tau = M qdd + h - G - passive of the constant derivation."""
    sym.reset()
    deriv = dynamics.Derivation(mechanism.build(m), m)
    mass, h, g = deriv.mass(), deriv.bias(), deriv.gravity_force()
    passive = deriv.passive()
    qdd = [sym.sym("qdd%d" % (i + 1)) for i in range(3)]
    return [sym.add(*([sym.mul(mass[3 * i + j], qdd[j]) for j in range(3)]
                      + [h[i], -g[i], -passive[i]])) for i in range(3)]


def _states(n, seed):
    rnd = random.Random(seed)
    for _ in range(n):
        env = {"q1": rnd.uniform(-0.2, 0.2), "q2": rnd.uniform(-0.2, 0.2),
               "q3": rnd.uniform(-0.03, 0.03)}
        for k in range(3):
            env["qd%d" % (k + 1)] = rnd.uniform(-1, 1)
            env["qdd%d" % (k + 1)] = rnd.uniform(-4, 4)
        yield env


class RegressorTest(unittest.TestCase):
    def check_model(self, path):
        m = model.load(path)
        vs = float(m.coulomb_velocity) if m.coulomb_velocity else 1.0
        pi = [float(x) for x in regressor.model_standard(m)]
        tau = _dynamics(m)
        states = list(_states(20, 5))
        want = [sym.evaluate(tau, env) for env in states]
        k = _regressor(m)
        y = k.outputs[0][1]
        npar = len(regressor.param_names(m))
        self.assertEqual(len(y), 3 * npar)
        allowed = {"q1", "q2", "q3", "qd1", "qd2", "qd3", "qdd1", "qdd2",
                   "qdd3", "vs1"}
        names = set()
        for e in y:
            for s in sym.topological([sym.as_expr(e)]):
                if s.op == "sym" and sym.definition(s) is None:
                    names.add(s.args[0])
        self.assertLessEqual(names, allowed)
        worst = 0.0
        for env, w in zip(states, want):
            env = dict(env, vs1=vs)
            yv = sym.evaluate(y, env)
            for i in range(3):
                got = sum(yv[i * npar + j] * pi[j] for j in range(npar))
                scale = max(abs(x) for x in w)
                worst = max(worst, abs(got - w[i]) / scale)
        self.assertLess(worst, 1e-12)

    def test_paper(self):
        self.check_model(PAPER)

    def test_prototype(self):
        self.check_model(PROTO)

    def test_parallel_axes(self):
        m = model.load(PROTO)
        pi = regressor.model_standard(m)
        b = 0
        mass, c, i = m.masses[b], m.coms[b], m.inertias[b]
        p = pi[10 * b:10 * b + 10]
        self.assertEqual(p[0], mass)
        self.assertEqual(p[1:4], [mass * x for x in c])
        # I_O,xx = I_c,xx + m (cy^2 + cz^2); I_O,xy = I_c,xy - m cx cy.
        self.assertEqual(p[4], i[0] + mass * (c[1] ** 2 + c[2] ** 2))
        self.assertEqual(p[7], i[3] - mass * c[0] * c[1])
        self.assertIsInstance(p[4], Fraction)

    def test_names(self):
        for path in (PAPER, PROTO):
            m = model.load(path)
            names = regressor.param_names(m)
            self.assertEqual(len(names), 10 * len(m.body_names) + 3 * m.nlimb)
            self.assertEqual(len(set(names)), len(names))
            self.assertEqual(names[:2], ["P.m", "P.mcx"])
            self.assertEqual(names[-1], "coulomb%d" % m.nlimb)

    def test_files(self):
        files, _ = prru_gen.generate(PAPER, sets=("regressor",))
        again, _ = prru_gen.generate(PAPER, sets=("regressor",))
        for name in ("paper3prru_regressor.h", "paper3prru_regressor.c"):
            self.assertIn(name, files)
            self.assertEqual(files[name], again[name])
        # The committed generated/ holds the same regressor files.
        for name in ("paper3prru_regressor.h", "paper3prru_regressor.c"):
            with open(os.path.join(ROOT, "generated", name),
                      encoding="utf-8") as f:
                self.assertEqual(f.read(), files[name], name)


if __name__ == "__main__":
    unittest.main()
