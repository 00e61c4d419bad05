"""Hoisting (hoist.py): the topology kernels lowered with what the
parameters alone determine read from slots agree with the plain lowering
at random designs and states, cost fewer operations, and their slots
depend on the parameters only.

Tolerance: both sides evaluate the same expressions in double, only
grouped differently (terms that share a state part summed as one
coefficient first, as constant folding does), so they differ by rounding:
a few units of 2^-52 times the size of the terms. The outputs' terms are
bounded by the kernel's largest output at these regular states (masses
and lengths within 0.8-1.25x of the reference model's); 1e-12 of that
output is 4500 ulp of it and far below any modelling difference.
"""

import random
import unittest

from prrugen import cgen, dynamics, hoist, mechanism, model, params, sym
from prrugen.kernels import kernels

from tests.test_params import _env, PAPER, FOUR


def _derivation(nlimb):
    sym.reset()
    pm = params.ParamModel(params.Topology(nlimb))
    return pm, dynamics.Derivation(mechanism.build(pm), pm)


class HoistTest(unittest.TestCase):
    def _check(self, nlimb, path, names):
        pm, deriv = _derivation(nlimb)
        h = hoist.Hoisted(pm.order)
        ks = {k.name: k for k in params.topology_kernels(deriv, pm, "x", (), h)}
        rng = random.Random(20261127 + nlimb)
        base = _env(model.load(path), pm)
        for trial in range(6):
            env = {k: v * rng.uniform(0.8, 1.25) for k, v in base.items()}
            env.update({"q1": rng.uniform(-0.2, 0.2), "q2": rng.uniform(-0.2, 0.2),
                        "q3": rng.uniform(-0.85, -0.75),   # reachable for both models
                        "qd1": rng.uniform(-1, 1), "qd2": rng.uniform(-1, 1),
                        "qd3": rng.uniform(-1, 1)})
            for n in names:
                k = ks[n]
                exprs = [x for _, xs in k.outputs for x in xs]
                for arr, syms in k.inputs:
                    for i, s in enumerate(syms):
                        env.setdefault(s, rng.uniform(-2, 2))
                plain = cgen.evaluate_lowered(exprs, env)
                hoisted = cgen.evaluate_lowered(exprs, env, h)
                self.assertTrue(all(v == v for v in plain), "%s: unreachable state" % n)
                # Both sides sum the same terms in another grouping: each
                # output's rounding is a few ulp of the kernel's terms, none
                # larger here than its largest output (regular states, the
                # models' own scales, no floor in any unit).
                scale = max(abs(v) for v in plain)
                for a, b in zip(plain, hoisted):
                    self.assertLessEqual(abs(a - b), 1e-12 * scale,
                                         "%d limbs, %s: %r vs %r" % (nlimb, n, a, b))
        # Fewer operations than the plain lowering, and only parameters in
        # the slots.
        for n in names:
            plain = cgen.Lowered(params.topology_kernels(deriv, pm, "x")[
                [k.name for k in kernels(deriv)].index(n)])
            lowered = cgen.Lowered(ks[n])
            self.assertLess(lowered.counts["mul"] + lowered.counts.get("add", 0),
                            plain.counts["mul"] + plain.counts.get("add", 0), n)
        for e in h.exprs:
            self.assertTrue(h.depends_on_params_only(e))
            self.assertNotIn(e.op, ("sym", "const"))

    def test_three_limbs(self):
        self._check(3, PAPER, ("mass", "dynamics", "eom_solve", "inverse_terms"))

    def test_four_limbs(self):
        self._check(4, FOUR, ("dynamics", "eom_solve"))

    def test_slots_shared_and_deterministic(self):
        # Two lowerings of one kernel name the same slots, in the same order.
        pm, deriv = _derivation(3)
        h = hoist.Hoisted(pm.order)
        k = [k for k in params.topology_kernels(deriv, pm, "x", (), h) if k.name == "mass"][0]
        cgen.Lowered(k)
        first = list(h.exprs)
        cgen.Lowered(k)
        self.assertEqual(first, h.exprs)
        self.assertTrue(first)


if __name__ == "__main__":
    unittest.main()
