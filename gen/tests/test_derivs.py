"""The derivative kernels (kernels.derivative_kernels), numerically.

Through the lowered graph (cgen.evaluate_lowered, the arithmetic the C
code does), eom_solve_derivs's blocks equal central differences of
eom_solve's qdd and inverse_derivs's those of inverse_terms's fd, on the
prototype with drives (armature, damping, smoothed Coulomb) and on the
4-limb model, at a non-hover state with loads; and their values (qdd, fd)
are eom_solve's and inverse_terms's to the bit (one CSE graph each, the
same expressions). With four actuators inverse_derivs gives tau's
derivatives and dJ_d/dq (the runtime composes the minimum-norm fd's):
those against differences of inverse_terms's tau and jd's J_d.

Tolerance: a central difference with step h has truncation error
h^2 |f'''| / 6 and rounding error about eps |f| / h; with h = 1e-6
(relative to the variable's scale 1) and |f|, |f'''| of order 10 to 100
in SI units here, both stay below 1e-8, so 1e-7 (1 + max |block|) leaves
a margin of ten while any wrong term (of order the block) fails. The
tight check is the C test tests/test_derivs.c.
"""

import os
import unittest

from prrugen import cgen, dynamics, mechanism, model, sym
from prrugen.kernels import derivative_kernels, kernels

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
H = 1e-6


def _by_name(path):
    sym.reset()
    m = model.load(os.path.join(ROOT, "models", path))
    deriv = dynamics.Derivation(mechanism.build(m), m)
    return {k.name: k for k in kernels(deriv) + derivative_kernels(deriv)}


def _run(k, vals):
    env = {}
    for (_, names), v in zip(k.inputs, vals):
        env.update(zip(names, v))
    flat = cgen.evaluate_lowered([x for _, ex in k.outputs for x in ex], env)
    out, i = {}, 0
    for arr, ex in k.outputs:
        out[arr] = flat[i:i + len(ex)]
        i += len(ex)
    return out


class DerivativeKernels(unittest.TestCase):
    def check(self, ks, value, deriv, args, out, blocks):
        got = _run(ks[deriv], args)
        self.assertEqual(got[out], _run(ks[value], args)[out])
        for arg, name in blocks:
            n = len(args[arg])
            block = got[name]
            scale = 1 + max(abs(x) for x in block)
            for c in range(n):
                up = [list(v) for v in args]
                dn = [list(v) for v in args]
                up[arg][c] += H
                dn[arg][c] -= H
                a, b = _run(ks[value], up)[out], _run(ks[value], dn)[out]
                for i in range(3):
                    fdiff = (a[i] - b[i]) / (2 * H)
                    self.assertLess(abs(fdiff - block[i * n + c]),
                                    1e-7 * scale, (deriv, name, i, c))

    def test_forward_and_inverse(self):
        for path in ("prototype_drives.json", "4prru.json"):
            with self.subTest(model=path):
                ks = _by_name(path)
                nact = len(ks["ik"].outputs[0][1])
                q, qd = [0.02, -0.03, 0.0], [0.3, -0.2, 0.1]
                fp, mp = [1.0, -2.0, 0.5], [0.1, 0.2, -0.3]
                fd = [5.0 + i for i in range(nact)]
                self.check(ks, "eom_solve", "eom_solve_derivs",
                           [q, qd, fd, fp, mp], "qdd",
                           [(0, "Dq"), (1, "Dqd"), (2, "Dfd"), (3, "Dfp"),
                            (4, "Dmp")])
                if nact == 3:
                    self.check(ks, "inverse_terms", "inverse_derivs",
                               [q, qd, [1.0, 2.0, -3.0], fp, mp], "fd",
                               [(0, "Dq"), (1, "Dqd"), (2, "Dqdd")])
                else:
                    args = [q, qd, [1.0, 2.0, -3.0], fp, mp]
                    self.check(ks, "inverse_terms", "inverse_derivs", args,
                               "tau", [(0, "Dq"), (1, "Dqd"), (2, "Dqdd")])
                    self.check_djd(ks, args)

    def check_djd(self, ks, args):
        """Four actuators: DJd (block k = dJ_d/dq_k) against differences
        of jd's J_d; J_d to the bit inverse_terms's."""
        got = _run(ks["inverse_derivs"], args)
        self.assertEqual(got["Jd"], _run(ks["inverse_terms"], args)["Jd"])
        n = len(got["Jd"])
        scale = 1 + max(abs(x) for x in got["DJd"])
        for k in range(3):
            up, dn = list(args[0]), list(args[0])
            up[k] += H
            dn[k] -= H
            a, b = _run(ks["jd"], [up])["Jd"], _run(ks["jd"], [dn])["Jd"]
            for i in range(n):
                self.assertLess(abs((a[i] - b[i]) / (2 * H)
                                    - got["DJd"][n * k + i]),
                                1e-7 * scale, ("DJd", k, i))


if __name__ == "__main__":
    unittest.main()
