"""The topology kernels (prru_gen.py --topology N: prru_pN_kernels.{h,c}).

- the committed generated/ holds what the generator makes now (as `make
  check-generated` checks), and two generations are byte-identical;
- they are derived from the structure alone: another reference model
  changes only prru_pN_params_reference (and the banner naming it);
- every kernel of the constant set is there, with the batched forms the
  runtime calls, and no name meets the constant or per-model ones;
- eom_solve eliminates M_22 first: constant in q and qd for every
  parameter value (checked on the expression), as in the constant kernels;
- the command line takes a model file or --topology, not both or neither.
"""

import contextlib
import io
import os
import re
import unittest

from prrugen import dynamics, kernels, mechanism, params, sym

import prru_gen  # noqa: E402  (gen/ is on the path: tests run from gen/)

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
PAPER = os.path.join(ROOT, "models", "3prru_paper.json")

BATCHED = ("ik_jd", "mass", "platform_jacobian", "dynamics", "eom",
           "eom_solve", "dme_terms")


class TopologyKernels(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.files = {n: prru_gen.generate_topology(n)[0] for n in (3, 4)}

    def test_committed_and_deterministic(self):
        for n in (3, 4):
            again, _ = prru_gen.generate_topology(n)
            self.assertEqual(again, self.files[n])
            for name, text in self.files[n].items():
                with open(os.path.join(ROOT, "generated", name),
                          encoding="utf-8") as f:
                    self.assertEqual(f.read(), text, "generated/%s is stale" % name)

    def test_every_kernel_and_batched_form(self):
        for n in (3, 4):
            h = self.files[n]["prru_p%d_kernels.h" % n]
            sym.reset()
            m = params.ParamModel(params.Topology(n))
            names = [k.name for k in kernels.kernels(
                dynamics.Derivation(mechanism.build(m), m))]
            self.assertIn("joint_reactions", names)
            self.assertEqual("reaction_nullspace" in names, n == 4)
            # Every kernel reads the derived numbers (prru_pN_derive), the
            # regressor the parameters as given (its caller sets v_s).
            for k in names:
                self.assertRegex(h, r"void prru_p%d_%s\(const prru_p%d_derived \*p, "
                                 r"const double q\[3\]" % (n, k, n))
            self.assertRegex(h, r"void prru_p%d_regressor\(const prru_params%d \*p, " % (n, n))
            self.assertRegex(h, r"void prru_p%d_derive\(const prru_params%d \*p, "
                             r"prru_p%d_derived \*d\);" % (n, n, n))
            for k in BATCHED:
                self.assertRegex(h, r"void prru_p%d_batch_%s\(const prru_p%d_derived "
                                 r"\*p, int n," % (n, k, n))
            declared = re.findall(r"^void (\w+)\(", h, re.M)
            self.assertTrue(all(d.startswith("prru_p%d_" % n) for d in declared))
            self.assertIn("#define PRRU_P%d_UNSEEN_FINITE_EOM_SOLVE(" % n, h)
            self.assertIn("GENERATED FILE: DO NOT EDIT", h)
            self.assertIn("--topology %d" % n, h)

    def test_structure_only(self):
        # Another reference model of the topology (the prototype: format 2,
        # unequal limbs, centres of mass, products of inertia, drives)
        # changes the banner's file and hash and the reference initializer,
        # nothing else: no decision was taken on a model's values.
        def body(text):
            text = text.split(" */\n", 1)[1]
            return re.sub(r"params_reference = \{.*?\n\};", "", text, flags=re.S)
        saved = dict(params.TOPOLOGY_REFERENCE)
        try:
            params.TOPOLOGY_REFERENCE[3] = os.path.join("models", "prototype_example.json")
            other, _ = prru_gen.generate_topology(3)
        finally:
            params.TOPOLOGY_REFERENCE.update(saved)
        for name, text in self.files[3].items():
            self.assertNotEqual(other[name], text)
            self.assertEqual(body(other[name]),
                             body(text).replace("3prru_paper.json", "prototype_example.json"),
                             name)
        for n in (3, 4):
            c = self.files[n]["prru_p%d_kernels.c" % n]
            # Every member is read into a local once, at the top.
            # (the float batch rounds each to float once: (float)p->...)
            self.assertNotIn("p->", re.sub(r"const (double|float) p_\w+ = (\(float\))?p->[^;]*;", "",
                                           body(c)))
            for member in ("p->com[0][0]", "p->inertia[0][5]", "p->armature[%d]" % (n - 1),
                           "p->coulomb_velocity", "p->gravity[0]", "p->b[%d]" % (n - 1)):
                self.assertIn(member, c)

    def test_eom_solve_pivot_is_structural(self):
        for n in (3, 4):
            sym.reset()
            m = params.ParamModel(params.Topology(n))
            d = dynamics.Derivation(mechanism.build(m), m)
            mass = d.mass()
            state = {x.id for x in list(d.mech.q) + list(d.mech.qd)}
            # M_22 depends on the parameters only; M_00 and M_11 on q.
            self.assertFalse(sym.free_symbols(mass[8]) & state)
            self.assertTrue(sym.free_symbols(mass[0]) & state)
            self.assertTrue(sym.free_symbols(mass[4]) & state)
            h = self.files[n]["prru_p%d_kernels.h" % n]
            self.assertIn("M_22, constant in q and qd for any parameters", h)

    def test_command_line(self):
        for argv in ([PAPER, "--topology", "3", "--out", "x"], ["--out", "x"],
                     ["--topology", "5", "--out", "x"],
                     ["--topology", "3", "--prefix", "abc", "--out", "x"]):
            err = io.StringIO()
            with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as cm:
                prru_gen.main(argv)
            self.assertEqual(cm.exception.code, 2, argv)
            self.assertIn("prru_gen.py: error:", err.getvalue())


if __name__ == "__main__":
    unittest.main()
