"""The simple structural variant of the topology kernels (params.STRUCTURES,
prru_gen.py --topology N --structure simple: prru_pNs_kernels.{h,c}).

- at random designs of that structure (the reference model's numbers
  scaled 0.8-1.25x each, a body's principal moments together; every centre of mass, product of inertia and drive
  number 0, gravity along -z) and random states, every kernel of the
  variant, hoisted as in C, equals the general kernel, hoisted: the
  variant is the general expression with those members set to exactly 0;
- it reads none of those members, and costs fewer operations;
- the committed generated/ holds it, and the generator refuses
  --structure without --topology.

Tolerance: both sides sum the same nonzero terms (the general side's
other terms are products with an exact 0), grouped differently, so they
differ by rounding: a few ulp of the kernel's terms, which at these
regular states and the models' own scales are no larger than its largest
output (test_hoist's rule); 1e-12 of that output is thousands of ulp and
far below any modelling difference.
"""

import os
import random
import unittest

from prrugen import cgen, dynamics, hoist, mechanism, model, params, sym
from prrugen.kernels import derivative_kernels

import prru_gen  # noqa: E402  (gen/ is on the path: tests run from gen/)
from tests.test_generator import ROOT, run_gen
from tests.test_params import _env, PAPER, FOUR

# What the simple structure drops, as parameter symbol names.
DROPPED = ("p->com[", "p->armature[", "p->damping[", "p->coulomb[",
           "p->gravity[0]", "p->gravity[1]")


def _kernels(nlimb, structure):
    sym.reset()
    pm = params.ParamModel(params.Topology(nlimb), structure)
    deriv = dynamics.Derivation(mechanism.build(pm), pm)
    h = hoist.Hoisted(pm.order)
    ks = params.topology_kernels(deriv, pm, "x", derivative_kernels(deriv), h)
    return pm, h, {k.name: k for k in ks}


def _values(nlimb, structure, envs):
    """{kernel: [outputs at each env]} and the kernels' arithmetic."""
    pm, h, ks = _kernels(nlimb, structure)
    out, ops = {}, {}
    for name, k in ks.items():
        exprs = [x for _, xs in k.outputs for x in xs]
        out[name] = [cgen.evaluate_lowered(exprs, env, h) for env in envs]
        if k.pattern is not None:
            # A sparse output (its identically zero entries left out,
            # which differ between the structures): scattered to dense.
            rows, cols, at = k.pattern
            dense = []
            for values in out[name]:
                full = [0.0] * (rows * cols)
                for i, v in zip(at, values):
                    full[i] = v
                dense.append(full)
            out[name] = dense
        counts = cgen.Lowered(k).counts
        ops[name] = sum(counts.get(c, 0) for c in cgen.ARITH)
    return pm, out, ops


def _simple_envs(nlimb, path, n):
    """n random designs of the simple structure and states, each an env
    of every symbol either set reads (the general ParamModel's names)."""
    sym.reset()
    general = params.ParamModel(params.Topology(nlimb))
    base = _env(model.load(path), general)
    rng = random.Random(20261127 + 10 * nlimb)
    envs = []
    for _ in range(n):
        env = {}
        # One factor per body's principal moments (so that they keep the
        # triangle inequality of a real body), one per other number.
        factors = {}
        for name, v in sorted(base.items()):
            drop = name.startswith(DROPPED) or (
                name.startswith("p->inertia[") and int(name[-2]) >= 3)
            group = name.rsplit("[", 1)[0] if name.startswith("p->inertia[") else name
            f = factors.setdefault(group, rng.uniform(0.8, 1.25))
            env[name] = 0.0 if drop else v * f
        env.update({"q1": rng.uniform(-0.2, 0.2), "q2": rng.uniform(-0.2, 0.2),
                    "q3": rng.uniform(-0.85, -0.75),   # reachable for both models
                    "qd1": rng.uniform(-1, 1), "qd2": rng.uniform(-1, 1),
                    "qd3": rng.uniform(-1, 1), "p->coulomb_velocity": 0.01})
        for arr in ("qdd", "fd", "fp", "mp"):
            for i in range(nlimb if arr == "fd" else 3):
                env["%s%d" % (arr, i + 1)] = rng.uniform(-2, 2)
        envs.append(env)
    return envs


class SimpleStructure(unittest.TestCase):
    def _check(self, nlimb, path):
        envs = _simple_envs(nlimb, path, 4)
        _, general, gops = _values(nlimb, "general", envs)
        pm, simple, sops = _values(nlimb, "simple", envs)
        self.assertFalse([s for s in pm.order if s.startswith(DROPPED)])
        self.assertFalse([s for s in pm.order if s.startswith("p->inertia[")
                          and int(s[-2]) >= 3])
        # The regressor is the general set's alone (every parameter is a
        # column whatever the structure).
        self.assertEqual(set(general) - set(simple), {"regressor"} & set(general))
        for name, rows in simple.items():
            for env_rows in zip(rows, general[name]):
                a, b = env_rows
                self.assertTrue(all(v == v for v in b), "%s: unreachable state" % name)
                scale = max(abs(v) for v in b) or 1.0
                for x, y in zip(a, b):
                    self.assertLessEqual(abs(x - y), 1e-12 * scale,
                                         "%d limbs, %s: %r vs %r" % (nlimb, name, x, y))
        for name in ("dynamics", "eom_solve", "inverse_terms", "joint_reactions"):
            self.assertLess(sops[name], gops[name], name)

    def test_three_limbs(self):
        self._check(3, PAPER)

    def test_four_limbs(self):
        self._check(4, FOUR)

    def test_committed_and_names(self):
        for n in (3, 4):
            files, _ = prru_gen.generate_topology(n, structure="simple")
            self.assertEqual(sorted(files), ["prru_p%ds_kernels.c" % n,
                                             "prru_p%ds_kernels.h" % n])
            h = files["prru_p%ds_kernels.h" % n]
            self.assertIn('#include "prru_p%d_kernels.h"' % n, h)
            self.assertIn("--topology %d --structure simple" % n, h)
            self.assertNotIn("p->params.com", files["prru_p%ds_kernels.c" % n])
            for name, text in files.items():
                with open(os.path.join(ROOT, "generated", name),
                          encoding="utf-8") as f:
                    self.assertEqual(f.read(), text, "generated/%s is stale" % name)

    def test_structure_needs_topology(self):
        r = run_gen(PAPER, "--structure", "simple", "--out", "/tmp/never")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--structure applies to --topology only", r.stderr)


if __name__ == "__main__":
    unittest.main()
