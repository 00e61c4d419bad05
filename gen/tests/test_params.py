"""The runtime-parameter kernels (prru_param_kernels.{h,c}).

- the constant kernels and the descriptor are what they were without them
  (generated on their own, by render.render alone, byte for byte);
- the parameter expressions, evaluated numerically at the model's values,
  equal the constant expressions, and at other values differ (every
  parameter is a live symbol);
- no value-dependent simplification: two models of the same limb count
  give the same parameter kernels, only the initializer of
  <prefix>_params_model differs;
- <prefix>_params_model holds the model's numbers;
- determinism within one process and the C shape of the kernels (the
  leading `const <prefix>_params *p`, each member loaded once).
"""

import math
import os
import random
import re
import unittest
from fractions import Fraction

from prrugen import dynamics, mechanism, model, params, render, sym
from prrugen.kernels import kernels

import prru_gen  # noqa: E402  (gen/ is on the path: tests run from gen/)

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
PAPER = os.path.join(ROOT, "models", "3prru_paper.json")
PROTO = os.path.join(ROOT, "models", "prototype_example.json")
FOUR = os.path.join(ROOT, "models", "4prru.json")


def _env(m, pm):
    """{parameter symbol name: float} holding model m's numbers."""
    env = {}

    def put(symbols, values):
        for s, v in zip(symbols, values):
            env[s.args[0]] = float(v)
    put([l.b for l in pm.limbs], [l.b for l in m.limbs])
    put([l.l1 for l in pm.limbs], [l.l1 for l in m.limbs])
    put([l.l2 for l in pm.limbs], [l.l2 for l in m.limbs])
    put([l.a for l in pm.limbs[:2]], [l.a for l in m.limbs[:2]])
    put(pm.gravity, m.gravity)
    put(pm.masses, m.masses)
    for sc, vc in zip(pm.coms, m.coms):
        put(sc, vc)
    for si, vi in zip(pm.inertias, m.inertias):
        put(si, vi)
    put(pm.armature, m.armature)
    put(pm.damping, m.damping)
    put(pm.coulomb, m.coulomb)
    env[pm.coulomb_velocity.args[0]] = float(m.coulomb_velocity or 1)
    return env


def _outputs(deriv, names):
    ks = {k.name: k for k in kernels(deriv)}
    return [x for n in names for _, xs in ks[n].outputs for x in xs]


class ConstantKernelsUnchanged(unittest.TestCase):
    def test_constant_files_as_generated_without_the_parameter_kernels(self):
        for path in (PAPER, PROTO, FOUR):
            m = model.load(path)
            sym.reset()
            deriv = dynamics.Derivation(mechanism.build(m), m)
            alone, _ = render.render(m, deriv, prru_gen.TEMPLATES, "prru")
            files, _ = prru_gen.generate_model(m, prefix="prru",
                                               sets=prru_gen.SETS)
            self.assertEqual(sorted(files), sorted(sorted(alone) + [
                "prru_derivs.c", "prru_derivs.h",
                "prru_param_kernels.c", "prru_param_kernels.h",
                "prru_regressor.c", "prru_regressor.h"]))
            for name, text in alone.items():
                self.assertEqual(files[name], text, "%s: %s" % (path, name))

    def test_deterministic_within_one_process(self):
        first, _ = prru_gen.generate(PROTO)
        prru_gen.generate(FOUR)
        self.assertEqual(first, prru_gen.generate(PROTO)[0])


class ParameterExpressions(unittest.TestCase):
    NAMES = ("ik", "jd", "mass", "bias", "gravity", "energy",
             "actuator_rates", "passive")

    def _compare(self, path, states=6):
        m = model.load(path)
        sym.reset()
        const = _outputs(dynamics.Derivation(mechanism.build(m), m),
                         self.NAMES)
        sym.reset()
        pm = params.ParamModel(m)
        par = _outputs(dynamics.Derivation(mechanism.build(pm), pm),
                       self.NAMES)
        self.assertEqual(len(const), len(par))
        env = _env(m, pm)
        rng = random.Random(7)
        for _ in range(states):
            q = {"q1": rng.uniform(-0.2, 0.2), "q2": rng.uniform(-0.2, 0.2),
                 "q3": rng.uniform(-0.9, -0.6), "qd1": rng.uniform(-1, 1),
                 "qd2": rng.uniform(-1, 1), "qd3": rng.uniform(-1, 1)}
            want = sym.evaluate(const, q)
            got = sym.evaluate(par, dict(q, **env))
            scale = max(abs(w) for w in want)
            for g, w in zip(got, want):
                self.assertLessEqual(abs(g - w), 1e-12 * scale)
        return m, pm, par, env

    def test_equal_to_the_constant_expressions_at_the_model_values(self):
        for path in (PAPER, PROTO, FOUR):
            self._compare(path)

    def test_every_parameter_moves_an_output(self):
        m, pm, par, env = self._compare(PROTO, states=1)
        # Slow enough that tanh(dd / v_s) is not saturated (v_s = 4 mm/s).
        q = {"q1": 0.1, "q2": -0.15, "q3": -0.8, "qd1": 3e-3, "qd2": -2e-3,
             "qd3": 5e-3}
        base = sym.evaluate(par, dict(q, **env))
        used = set()
        for e in par:
            used |= {n.args[0] for n in sym.topological([e])
                     if n.op == "sym"}
        # Structurally unused, whatever the values: a[2] (limb 3's U joint
        # is O'), and the inertia of a body about the axes it cannot turn
        # about (a slider does not turn; a link turns about its hinge only).
        unused = {"p->a[2]"}
        mech = mechanism.build(pm)
        for j, body in enumerate(mech.bodies):
            axes = {axis for axis, _ in body.chain}
            if len(axes) < 2:
                unused |= {"p->inertia[%d][%d]" % (j, k) for k in range(6)
                           if k not in axes}
        self.assertEqual(set(pm.order) - used, unused)
        for name in pm.order:
            if name in unused:
                continue
            moved = dict(env)
            moved[name] = env[name] * 1.01 + 1e-3
            got = sym.evaluate(par, dict(q, **moved))
            self.assertTrue(any(abs(g - b) > 1e-12 * (1 + abs(b))
                                for g, b in zip(got, base)), name)

    def test_param_symbols_never_meet_input_names(self):
        pm = params.ParamModel(model.load(FOUR))
        self.assertTrue(all(params.is_param(n) for n in pm.order))
        self.assertEqual(len(set(pm.order)), len(pm.order))
        locals_ = [params.local_name(n) for n in pm.order]
        self.assertEqual(len(set(locals_)), len(locals_))
        for n in locals_:
            self.assertRegex(n, r"^p_[a-z0-9_]+$")


class GeneratedParameterKernels(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.paper, _ = prru_gen.generate(PAPER, prefix="prru")
        cls.proto, _ = prru_gen.generate(PROTO, prefix="prru")

    def test_no_value_dependent_simplification(self):
        # The paper's model (equal limbs, no centres of mass, no products of
        # inertia, no drives, gravity along -z) and the prototype's give the
        # same mapping onto the topology kernels: only the initializer and
        # the banner differ (the topology kernels themselves:
        # test_topology.TopologyKernels.test_structure_only).
        def body(text):
            text = text.split(" */\n", 1)[1]
            return re.sub(r"params_model = \{.*?\n\};", "", text, flags=re.S)
        for name in ("prru_param_kernels.c", "prru_param_kernels.h"):
            self.assertEqual(body(self.paper[name]), body(self.proto[name]),
                             name)

    def test_model_values_in_the_initializer(self):
        m = model.load(PROTO)
        c = self.proto["prru_param_kernels.c"]
        init = re.search(r"prru_params_model = \{(.*?)\n\};", c, re.S).group(1)
        numbers = [float(x) for x in re.findall(
            r"-?\d+(?:\.\d*)?(?:e[-+]?\d+)?", re.sub(r"/\*.*?\*/|PRRU_DESIGNATE\(\w+\)", "", init))]
        want = [l.b for l in m.limbs] + [l.l1 for l in m.limbs] + \
            [l.l2 for l in m.limbs] + [l.a for l in m.limbs] + \
            list(m.gravity) + list(m.masses) + \
            [x for c3 in m.coms for x in c3] + \
            [x for i6 in m.inertias for x in i6] + list(m.armature) + \
            list(m.damping) + list(m.coulomb) + [m.coulomb_velocity]
        self.assertEqual(numbers, [float(Fraction(w)) for w in want])
        paper = self.paper["prru_param_kernels.c"]
        self.assertIn("PRRU_DESIGNATE(coulomb_velocity) 1.0", paper)

    def test_c_shape(self):
        # Every parameter kernel is the topology kernel of the model's limbs
        # (generated once per topology), named after the model; the .c holds
        # the model's numbers alone.
        c = self.paper["prru_param_kernels.c"]
        h = self.paper["prru_param_kernels.h"]
        for k in params.PARAM_KERNELS:
            self.assertIn("#define prru_param_%s prru_p3_%s\n" % (k, k), h)
            self.assertIn("#define PRRU_PARAM_ARITH_%s PRRU_P3_ARITH_%s\n" % (k.upper(), k.upper()), h)
        for k in render.param_kernel_names():
            self.assertIn("#define prru_param_%s prru_p3_%s\n" % (k, k), h)
        self.assertIn("typedef prru_params3 prru_params;", h)
        self.assertEqual(re.findall(r"#include .*", h),
                         ['#include "prru_kernels.h"', '#include "prru_p3_kernels.h"'])
        self.assertEqual(re.findall(r"#include .*", c), ['#include "prru_param_kernels.h"'])
        self.assertNotIn("(", c.split("params_model = {", 1)[1].replace("PRRU_DESIGNATE(", ""))
        four, _ = prru_gen.generate(os.path.join(ROOT, "models", "4prru.json"), prefix="m4")
        self.assertIn("#define m4_param_eom prru_p4_eom\n", four["m4_param_kernels.h"])
        self.assertIn("typedef prru_params4 m4_params;", four["m4_param_kernels.h"])
        # Every name the header maps is a kernel the topology file defines.
        topo = prru_gen.generate_topology(3)[0]["prru_p3_kernels.h"]
        for k in render.param_kernel_names():
            self.assertRegex(topo, r"void prru_p3_%s\(" % k)


if __name__ == "__main__":
    unittest.main()
