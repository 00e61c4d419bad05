"""The closed-form joint reactions (prrugen/reactions.py), numerically.

At random states of the paper's, the prototype's and the 4-limb model,
with qdd solving the equations of motion, the closed-form lambda satisfies
the equations of reaction Q lambda = Phi H qdd + K - Fbar (eq. 28) built
from the other derived quantities (the basis Q, the Jacobians H, the world
inertias, K), all 60 (78) rows, though the closed form uses only 57 (75)
of them; for four limbs the null direction z has Q z = 0, |z| = 1, C3's
force along e2 positive, and lambda . z = 0.
"""

import math
import os
import random
import unittest

from prrugen import dynamics, mechanism, model, sym
from prrugen.reactions import Reactions

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
MODELS = [os.path.join(ROOT, "models", n) for n in
          ("3prru_paper.json", "prototype_example.json", "4prru.json")]


def _solve3(m, b):
    """Gaussian elimination with partial pivoting, 3x3."""
    a = [list(m[3 * i:3 * i + 3]) + [b[i]] for i in range(3)]
    for k in range(3):
        p = max(range(k, 3), key=lambda i: abs(a[i][k]))
        a[k], a[p] = a[p], a[k]
        for i in range(k + 1, 3):
            f = a[i][k] / a[k][k]
            a[i] = [x - f * y for x, y in zip(a[i], a[k])]
    x = [0.0] * 3
    for i in (2, 1, 0):
        x[i] = (a[i][3] - sum(a[i][j] * x[j] for j in range(i + 1, 3))) \
            / a[i][i]
    return x


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0]]


class ClosedFormReactions(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.cases = []
        for path in MODELS:
            sym.reset()
            mdl = model.load(path)
            deriv = dynamics.Derivation(mechanism.build(mdl), mdl)
            n = len(deriv.mech.limbs)
            qdd = [sym.sym("qdd%d" % (i + 1)) for i in range(3)]
            fd = [sym.sym("fd%d" % (i + 1)) for i in range(n)]
            fp = [sym.sym("fp%d" % (i + 1)) for i in range(3)]
            mp = [sym.sym("mp%d" % (i + 1)) for i in range(3)]
            lam, z = Reactions(deriv, qdd, fd, fp, mp).solve()
            exprs = dict(lam=lam, z=z or [], M=deriv.mass(),
                         b=deriv.eom_rhs(fd, fp, mp), H=deriv.jacobians(),
                         K=deriv.wrench_bias(), I=deriv.inertia_world(),
                         Q=deriv.reaction_basis(), p=deriv.poses()[1],
                         dd=deriv.actuator_rates, ddb=deriv.actuator_bias,
                         Jd=deriv.actuator_jacobian(),
                         origin=deriv.terms[0].body.origin)
            cls.cases.append((os.path.basename(path), mdl, n, exprs))

    def _check(self, name, mdl, n, ex, rng):
        nb = 1 + 3 * n
        env = {"q1": rng.uniform(-0.3, 0.3), "q2": rng.uniform(-0.4, 0.3),
               "q3": rng.uniform(-0.9, -0.6)}
        for i in range(3):
            env["qd%d" % (i + 1)] = rng.uniform(-1, 1)
            env["fp%d" % (i + 1)] = rng.uniform(-30, 30)
            env["mp%d" % (i + 1)] = rng.uniform(-3, 3)
        for i in range(n):
            env["fd%d" % (i + 1)] = rng.uniform(-60, 60)
        for i in range(3):
            env["qdd%d" % (i + 1)] = 0.0
        mv = sym.evaluate(ex["M"], env)
        bv = sym.evaluate(ex["b"], env)
        if not all(math.isfinite(x) for x in bv):
            return False
        for i, x in enumerate(_solve3(mv, bv)):
            env["qdd%d" % (i + 1)] = x
        qdd = [env["qdd%d" % (i + 1)] for i in range(3)]
        ev = {k: sym.evaluate(v, env) for k, v in ex.items()}
        lam, Q, H, K, I, p = (ev[k] for k in ("lam", "Q", "H", "K", "I",
                                              "p"))
        nl = len(lam)
        # Fbar, then w = Phi H qdd + K - Fbar.
        F = [0.0] * (6 * nb)
        for b in range(nb):
            for k in range(3):
                F[3 * nb + 3 * b + k] = float(mdl.masses[b] *
                                              mdl.gravity[k])
        vs = float(mdl.coulomb_velocity or 1)
        for i in range(n):
            acc = ev["ddb"][i] + sum(ev["Jd"][3 * i + j] * qdd[j]
                                     for j in range(3))
            f = env["fd%d" % (i + 1)] - float(mdl.armature[i]) * acc \
                - float(mdl.damping[i]) * ev["dd"][i] \
                - float(mdl.coulomb[i]) * math.tanh(ev["dd"][i] / vs)
            F[3 * nb + 3 * (1 + 2 * n + i) + 2] += f
        fp = [env["fp%d" % (k + 1)] for k in range(3)]
        lever = _cross([o - c for o, c in zip(ev["origin"], p[0:3])], fp)
        for k in range(3):
            F[k] += env["mp%d" % (k + 1)] + lever[k]
            F[3 * nb + k] += fp[k]
        hq = [sum(H[3 * r + j] * qdd[j] for j in range(3))
              for r in range(6 * nb)]
        w = []
        for r in range(3 * nb):
            b, k = divmod(r, 3)
            w.append(sum(I[9 * b + 3 * k + j] * hq[3 * b + j]
                         for j in range(3)) + K[r] - F[r])
        for r in range(3 * nb, 6 * nb):
            b = (r - 3 * nb) // 3
            w.append(float(mdl.masses[b]) * hq[r] + K[r] - F[r])
        ql = [sum(Q[nl * r + c] * lam[c] for c in range(nl))
              for r in range(6 * nb)]
        scale = max(1.0, max(abs(x) for x in w + F))
        err = max(abs(a - b) for a, b in zip(ql, w)) / scale
        self.assertLess(err, 1e-12, "%s: Q lambda = w (eq. 28)" % name)
        if n == 4:
            z = ev["z"]
            qz = max(abs(sum(Q[nl * r + c] * z[c] for c in range(nl)))
                     for r in range(6 * nb))
            self.assertLess(qz, 1e-14, "%s: Q z = 0" % name)
            self.assertAlmostEqual(sum(x * x for x in z), 1.0, delta=1e-14)
            self.assertLess(abs(sum(a * b for a, b in zip(lam, z))),
                            1e-13 * max(abs(x) for x in lam))
            # C1, C2 come first with 4 coordinates each: C3's fy is 9.
            self.assertGreater(z[4 * 2 + 1], 0.0, "C3's force along e2")
        else:
            self.assertEqual(ex["z"], [])
        return True

    def test_equations_of_reaction_hold(self):
        rng = random.Random(13)
        for name, mdl, n, ex in self.cases:
            done = sum(self._check(name, mdl, n, ex, rng) for _ in range(6))
            self.assertGreaterEqual(done, 5, name)


if __name__ == "__main__":
    unittest.main()
