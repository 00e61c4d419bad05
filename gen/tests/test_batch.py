"""The batched kernels (batch.py): their C shape, on the paper model.

- every name of BATCH_KERNELS that the scalar list has gets a batched
  variant (the derivative kernels included), plus dme_terms with the outputs of ik_jd, mass and
  platform_jacobian in that order;
- a batched kernel performs exactly the scalar kernel's operations (the
  operation counts agree: the same lowered graph);
- no early return (the reachability test is a select), each loop marked
  with the loop macro, sin and cos of the inputs in loops of their own,
  one per function (sin and cos of one argument in one loop become a
  sincos call, which has no vector variant);
- the kinematic kernels call sin and cos themselves, the others the
  vector-capable names;
- deterministic: emitting twice gives the same text;
- on a model whose drives have Coulomb friction, tanh is called by its
  vector-capable name and the outputs are multiplied by 1 or NaN, not
  selected (GCC would branch around the call); without calls, selects.
(The values are checked in C against the scalar kernels by
tests/test_batch.c.)
"""

import os
import re
import unittest

from prrugen import batch, cgen, dynamics, mechanism, model, sym
from prrugen.kernels import derivative_kernels, kernels

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
PAPER = os.path.join(ROOT, "models", "3prru_paper.json")
PROTOTYPE = os.path.join(ROOT, "models", "prototype_example.json")


class BatchedKernels(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sym.reset()
        m = model.load(PAPER)
        deriv = dynamics.Derivation(mechanism.build(m), m)
        cls.scalar = kernels(deriv) + derivative_kernels(deriv)
        cls.batched = batch.batch_kernels(cls.scalar)
        cls.emitted = {k.name: batch.emit_batch(k, "prru", "PRRU_BATCH_LOOP",
                                                "PRRU_BATCH_%s")
                       for k in cls.batched}

    def test_the_kernels_and_the_fused_one(self):
        names = [k.name for k in self.batched]
        self.assertEqual(names, list(batch.BATCH_KERNELS) + ["dme_terms"])
        fused = next(k for k in self.batched if k.name == "dme_terms")
        self.assertEqual([a for a, _ in fused.outputs], ["d", "Jd", "M", "JP"])

    def test_same_operations_as_the_scalar_kernel(self):
        for k in self.scalar:
            if k.name in self.emitted:
                self.assertEqual(self.emitted[k.name].counts,
                                 cgen.emit(k, "prru").counts, k.name)

    def test_loop_shape(self):
        for name, e in self.emitted.items():
            self.assertNotIn("return", e.body, name)
            loops = e.body.count("for (long k = 0; k < m; k++)")
            self.assertEqual(e.body.count("PRRU_BATCH_LOOP"), loops, name)
            # The trig loops: their assignments w<j>[k] = f(input).
            calls = re.findall(r"w\d+\[k\] = (\w+)\(", e.body)
            self.assertTrue(calls, name)
            loop_of = re.split(r"for \(long k = 0; k < m; k\+\+\)", e.body)
            for body in loop_of:
                fns = {f.lower()[-3:] for f in
                       re.findall(r"w\d+\[k\] = (\w+)\(", body)}
                self.assertLessEqual(len(fns), 1, "%s: %s" % (name, fns))
            self.assertTrue(e.signature.startswith(
                "void prru_batch_%s(int n, const double *q" % name), name)

    def test_vector_trig_only_outside_the_kinematic_kernels(self):
        for name, e in self.emitted.items():
            vector = "PRRU_BATCH_SIN(" in e.body or "PRRU_BATCH_COS(" in e.body
            self.assertEqual(vector, name not in batch.EXACT, name)

    def test_deterministic(self):
        k = self.batched[-1]
        a = batch.emit_batch(k, "prru", "L", "V_%s").body
        b = batch.emit_batch(k, "prru", "L", "V_%s").body
        self.assertEqual(a, b)


if __name__ == "__main__":
    unittest.main()


class CallsInTheLoop(unittest.TestCase):
    def test_tanh_vector_name_and_no_select(self):
        sym.reset()
        m = model.load(PROTOTYPE)
        ks = {k.name: k for k in batch.batch_kernels(
            kernels(dynamics.Derivation(mechanism.build(m), m)))}
        body = batch.emit_batch(ks["eom_solve"], "prru", "PRRU_BATCH_LOOP",
                                "PRRU_BATCH_%s").body
        self.assertIn("PRRU_BATCH_TANH(", body)
        self.assertNotIn("tanh(", body.replace("PRRU_BATCH_TANH(", ""))
        self.assertIn("const double okf = ok ? 1.0 : (double)NAN;", body)
        self.assertNotIn("ok ? t", body)
        self.assertEqual(body.count("* okf;"), 9 + 3 + 3 + 3)
        # dynamics has no call in its loop: selects, as before.
        body = batch.emit_batch(ks["dynamics"], "prru", "PRRU_BATCH_LOOP",
                                "PRRU_BATCH_%s").body
        self.assertNotIn("okf", body)
        self.assertIn(": (double)NAN;", body)
