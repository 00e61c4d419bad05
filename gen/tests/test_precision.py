"""Single precision (--precision float): the float spelling of the same
lowered kernels, its literals, its files, its command line and its
refusal of constants a float cannot hold."""

import os
import re
import subprocess
import sys
import tempfile
import unittest

from prrugen import batch, cgen, dynamics, mechanism, model, render, sym
from prrugen.kernels import kernels

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
MODEL = os.path.join(ROOT, "models", "3prru_paper.json")
ENTRY = os.path.join(GEN_DIR, "prru_gen.py")
sys.path.insert(0, GEN_DIR)
import prru_gen  # noqa: E402


def as_float(text):
    """A double kernel's C text respelled as the float emitter spells it:
    what the float kernel must be if it is the same graph."""
    text = text.replace("(double)NAN", "NAN")
    text = text.replace("1.7976931348623157e308", "FLT_MAX")
    text = re.sub(r"\bdouble\b", "float", text)
    text = re.sub(r"\b(sin|cos|sqrt|tanh|atan2|fabs|pow|tan|asin|acos)\(",
                  r"\1f(", text)
    return re.sub(r"(?<![\w.])(\d+\.\d*(?:e[-+]?\d+)?|\d+e[-+]?\d+)(?![\w.])",
                  lambda m: cgen.c_float(m.group(1)), text)


class FloatLiterals(unittest.TestCase):
    def test_shortest_literal_that_rounds_to_the_nearest_float(self):
        self.assertEqual(cgen.c_float("1.0"), "1.0f")
        self.assertEqual(cgen.c_float("0.0"), "0.0f")
        self.assertEqual(cgen.c_float("0.23"), "0.23f")
        self.assertEqual(cgen.c_float("1.3333333333333333"), "1.3333334f")
        self.assertEqual(cgen.c_float("1e-05"), "1e-05f")
        self.assertEqual(cgen.c_float("100.0"), "100.0f")
        for text in ("0.1", "9.81", "3.4028234663852886e+38", "1.1754943508222875e-38"):
            lit = cgen.c_float(text)
            self.assertEqual(cgen._round_float(float(lit[:-1])),
                             cgen._round_float(float(text)), lit)

    def test_out_of_range_constants_are_refused(self):
        for text, what in (("1e+39", "overflows"), ("3.4028236e+38", "overflows"),
                           ("1e-39", "underflows"), ("1e-300", "underflows")):
            with self.assertRaises(cgen.RangeError) as cm:
                cgen.c_float(text)
            self.assertIn(what + " single precision", str(cm.exception))


class SameGraph(unittest.TestCase):
    """The float kernels are the double kernels' graph (one derivation, one
    CSE) in another spelling, and the double spelling is unchanged."""

    @classmethod
    def setUpClass(cls):
        sym.reset()
        m = model.load(MODEL)
        cls.kernels = [k for k in kernels(dynamics.Derivation(mechanism.build(m), m))
                       if k.name in render.CONTROLLER_KERNELS]

    def test_float_body_is_the_double_body_respelled(self):
        self.assertEqual(sorted(k.name for k in self.kernels),
                         sorted(render.CONTROLLER_KERNELS))
        for k in self.kernels:
            with self.subTest(k.name):
                d = cgen.emit(k, "prru")
                f = cgen.emit(k, "prru_f", cgen.FLOAT)
                self.assertEqual(f.counts, d.counts)
                self.assertEqual(f.body, as_float(d.body))
                self.assertEqual(f.signature,
                                 as_float(d.signature).replace("prru_", "prru_f_", 1))
                self.assertNotRegex(f.body + f.signature, r"\bdouble\b")


class FloatBatch(unittest.TestCase):
    """The float batched dme_terms is the double one's graph respelled,
    with the vector sinf and cosf (the double one calls sin and cos
    themselves, to agree with the scalar kernels bit for bit), and the
    double batches are spelled as before."""

    @classmethod
    def setUpClass(cls):
        sym.reset()
        m = model.load(MODEL)
        cls.kernels = kernels(dynamics.Derivation(mechanism.build(m), m))

    def test_float_batch_is_the_double_batch_respelled(self):
        emitted = render.float_batch(self.kernels, "prru_f")
        self.assertEqual([e.name for e in emitted], ["dme_terms"])
        fused = batch.batch_kernels(self.kernels, (), batch.FUSED)[0]
        d = batch.emit_batch(fused, "prru", "PRRU_BATCH_LOOP", "PRRU_BATCH_%s")
        f = emitted[0]
        expected = as_float(d.body).replace("PRRU_BATCH_LOOP", "PRRU_F_BATCH_LOOP")
        expected = re.sub(r"\b(sin|cos)f\(", lambda x: "PRRU_F_BATCH_%sF(" % x.group(1).upper(),
                          expected)
        self.assertEqual(f.body, expected)
        self.assertEqual(f.signature, as_float(d.signature).replace("prru_", "prru_f_", 1))
        self.assertEqual(f.counts, d.counts)
        self.assertNotRegex(f.body + f.signature, r"\bdouble\b")
        self.assertIn("PRRU_F_BATCH_SINF(", f.body)


class FloatFiles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = model.load(MODEL)
        cls.files, cls.emitted = prru_gen.generate_float(cls.model, prefix="prru")

    def test_names_and_no_double(self):
        self.assertEqual(sorted(self.files), ["prru_f_batch.c", "prru_f_batch.h",
                                              "prru_f_kernels.c", "prru_f_kernels.h"])
        for name, text in self.files.items():
            self.assertNotRegex(text, r"\bdouble\b", name)
            for fn in re.findall(r"^void (\w+)\(", text, re.M):
                self.assertTrue(fn.startswith("prru_f_"), fn)
            for macro in re.findall(r"^#define (\w+)", text, re.M):
                self.assertTrue(macro.startswith("PRRU_F_"), macro)

    def test_banner_names_the_source_and_precision(self):
        for name, text in self.files.items():
            head = text.split("*/", 1)[0]
            self.assertIn("GENERATED FILE: DO NOT EDIT", head, name)
            self.assertIn("3prru_paper.json --precision float", head, name)
            self.assertIn(self.model.sha256, head, name)
            self.assertIn("in float precision", head, name)


class CommandLine(unittest.TestCase):
    def run_gen(self, *args):
        with tempfile.TemporaryDirectory() as tmp:
            return subprocess.run([sys.executable, ENTRY] + list(args) +
                                  ["--out", os.path.join(tmp, "out")],
                                  capture_output=True, text=True)

    def test_other_precision_exits_2(self):
        for value in ("half", "Float", ""):
            r = self.run_gen(MODEL, "--precision", value)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn("--precision", r.stderr)

    def test_float_topology_exits_2(self):
        r = self.run_gen("--topology", "3", "--precision", "float")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--precision", r.stderr)

    def test_float_writes_only_the_float_set(self):
        with tempfile.TemporaryDirectory() as tmp:
            r = subprocess.run([sys.executable, ENTRY, MODEL, "--precision",
                                "float", "--out", tmp, "--quiet"],
                               capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(sorted(os.listdir(tmp)),
                             ["paper3prru_f_batch.c", "paper3prru_f_batch.h",
                              "paper3prru_f_kernels.c", "paper3prru_f_kernels.h"])


if __name__ == "__main__":
    unittest.main()
