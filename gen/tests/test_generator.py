"""The generator as a whole: model validation, output, determinism."""

import ast
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import unittest

from prrugen import dynamics, mechanism, model, sym

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
MODEL = os.path.join(ROOT, "models", "3prru_paper.json")
ENTRY = os.path.join(GEN_DIR, "prru_gen.py")
# Every file one generation of the paper's model writes (its name,
# paper3prru, the prefix), in sorted order: the default set, and with both
# opt-in sets (--derivatives, --regressor).
OUTPUT_FILES = ["paper3prru_kernels.c", "paper3prru_kernels.h", "paper3prru_mechanism.c",
                "paper3prru_mechanism.h", "paper3prru_param_kernels.c",
                "paper3prru_param_kernels.h"]
ALL_FILES = sorted(OUTPUT_FILES + ["paper3prru_derivs.c", "paper3prru_derivs.h",
                                   "paper3prru_regressor.c", "paper3prru_regressor.h"])


def read_dir(d):
    out = {}
    for f in sorted(os.listdir(d)):
        with open(os.path.join(d, f), "rb") as fh:
            out[f] = fh.read()
    return out


def run_gen(*args, env=None):
    return subprocess.run([sys.executable, ENTRY] + list(args),
                          capture_output=True, text=True, env=env)


class StandardLibraryOnly(unittest.TestCase):
    def test_generator_imports_only_the_standard_library(self):
        local = {"prrugen", "tests", "prru_gen", "prru_mjcf"}
        for folder, _, files in os.walk(GEN_DIR):
            for f in files:
                if not f.endswith(".py"):
                    continue
                path = os.path.join(folder, f)
                with open(path, encoding="utf-8") as fh:
                    tree = ast.parse(fh.read(), path)
                for node in ast.walk(tree):
                    if isinstance(node, ast.Import):
                        names = [a.name for a in node.names]
                    elif isinstance(node, ast.ImportFrom):
                        if node.level:
                            continue
                        names = [node.module]
                    else:
                        continue
                    for n in names:
                        top = n.split(".")[0]
                        self.assertTrue(top in sys.stdlib_module_names
                                        or top in local,
                                        "%s imports %s" % (path, n))


class Mechanism(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = model.load(MODEL)
        cls.mech = mechanism.build(cls.model)
        cls.deriv = dynamics.Derivation(cls.mech, cls.model)

    def test_loops_close_at_random_reachable_states(self):
        rng = random.Random(7)
        rs, ps = self.deriv.poses()
        joints = {j.name: j for j in self.mech.joints}
        for _ in range(20):
            env = {"q1": rng.uniform(-0.5, 0.5), "q2": rng.uniform(-0.6, 0.5),
                   "q3": rng.uniform(-1, 0.2)}
            for i in range(3):
                a = sym.evaluate(joints["A%d" % (i + 1)].centre, env)
                b = sym.evaluate(joints["B%d" % (i + 1)].centre, env)
                c = sym.evaluate(joints["C%d" % (i + 1)].centre, env)
                limb = self.model.limbs[i]
                self.assertAlmostEqual(math.dist(a, b), float(limb.l1),
                                       places=12)
                self.assertAlmostEqual(math.dist(b, c), float(limb.l2),
                                       places=12)
            # every rotation is orthonormal
            r = sym.evaluate(rs, env)
            for k in range(10):
                m = [r[9 * k + 3 * i:9 * k + 3 * i + 3] for i in range(3)]
                for i in range(3):
                    for j in range(3):
                        dot = sum(m[i][t] * m[j][t] for t in range(3))
                        self.assertAlmostEqual(dot, float(i == j), places=13)

    def test_public_reference_point(self):
        env = dict(q1=0.1, q2=0.2, q3=-0.8, qd1=0.3, qd2=-0.4, qd3=0.5)
        want = {
            "M": [0.45906598061227876, 0.0034180053946637732,
                  -0.067202143647255787, 0.0034180053946637732,
                  0.17775860212149512, -0.75886870659132982,
                  -0.067202143647255787, -0.75886870659132982, 12.39],
            "h": [-0.0026294266343440007, 0.0043554318154298796,
                  -0.061280218724993618],
            "G": [0.6592530291795793, 7.4445020116609459,
                  -121.54590000000001],
            "d": [-0.61587356199245987, -0.56196351700317267,
                  -0.63523945236562458]}
        got = {"M": self.deriv.mass(), "h": self.deriv.bias(),
               "G": self.deriv.gravity_force(), "d": self.deriv.actuators()}
        for key, values in want.items():
            vals = sym.evaluate(got[key], env)
            scale = max(abs(v) for v in values)
            for v, w in zip(vals, values):
                self.assertLessEqual(abs(v - w), 1e-12 * scale, key)
        self.assertIs(self.deriv.mass()[8], sym.const(self.model.total_mass))


class Solves(unittest.TestCase):
    """eom_solve's two ways to solve M x = b, on random symmetric matrices."""

    @staticmethod
    def _det(a):
        return (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))

    def _check(self, solve, k, definite, rng):
        sym.reset()  # the solves' atoms (_u0, _x1, ...) are defined anew
        g = [[rng.uniform(-1, 1) for _ in range(3)] for _ in range(3)]
        a = [[sum(g[i][n] * g[j][n] for n in range(3)) + (0.3 if i == j else 0)
              for j in range(3)] for i in range(3)]
        if not definite:
            a[1][1] = -a[1][1]
        names = [["m%d%d" % (min(i, j), max(i, j)) for j in range(3)] for i in range(3)]
        e = [[sym.const(round(a[i][j], 6)) if (i, j) == (k, k) else sym.sym(names[i][j])
              for j in range(3)] for i in range(3)]
        if k is not None:
            a[k][k] = round(a[k][k], 6)
        env = {names[i][j]: a[i][j] for i in range(3) for j in range(3)}
        b = [rng.uniform(-1, 1) for _ in range(3)]
        env.update({"c%d" % i: b[i] for i in range(3)})
        x, minors, _ = solve(e, [sym.sym("c%d" % i) for i in range(3)])
        x, minors = sym.evaluate(x, env), sym.evaluate(minors, env)
        for i in range(3):
            self.assertAlmostEqual(sum(a[i][j] * x[j] for j in range(3)), b[i], delta=1e-12)
        self.assertAlmostEqual(minors[2], self._det(a), delta=1e-12)
        self.assertEqual(all(v > 0 for v in minors), definite)

    def test_pivot_and_adjugate_solves(self):
        from prrugen import kernels
        rng = random.Random(7)
        for _ in range(20):
            for definite in (True, False):
                self._check(kernels._adjugate_solve, None, definite, rng)
                for k in range(3):
                    self._check(lambda e, b, k=k: kernels._pivot_solve(e, b, k), k,
                                definite, rng)


class CommandLine(unittest.TestCase):
    def test_regeneration_is_byte_identical_under_any_hash_seed(self):
        outs = []
        for seed in ("0", "12345"):
            with tempfile.TemporaryDirectory() as d:
                env = dict(os.environ, PYTHONHASHSEED=seed)
                r = run_gen(MODEL, "--out", d, "--quiet", env=env)
                self.assertEqual(r.returncode, 0, r.stderr)
                outs.append(read_dir(d))
        self.assertEqual(outs[0], outs[1])
        self.assertEqual(sorted(outs[0]), OUTPUT_FILES)

    def test_opt_in_sets_add_files_and_change_none(self):
        # Each set's files are the same whichever others are asked for,
        # and the committed generated/ is the whole set.
        outs = {}
        for flags in ((), ("--derivatives",), ("--regressor",),
                      ("--derivatives", "--regressor")):
            with tempfile.TemporaryDirectory() as d:
                r = run_gen(MODEL, "--out", d, "--quiet", *flags)
                self.assertEqual(r.returncode, 0, r.stderr)
                outs[flags] = read_dir(d)
        whole = outs[("--derivatives", "--regressor")]
        self.assertEqual(sorted(whole), ALL_FILES)
        self.assertEqual(sorted(outs[("--derivatives",)]), sorted(
            OUTPUT_FILES + ["paper3prru_derivs.c", "paper3prru_derivs.h"]))
        self.assertEqual(sorted(outs[("--regressor",)]), sorted(
            OUTPUT_FILES + ["paper3prru_regressor.c", "paper3prru_regressor.h"]))
        for files in outs.values():
            for name, text in files.items():
                self.assertEqual(text, whole[name], name)
        committed = read_dir(os.path.join(ROOT, "generated"))
        for name, text in whole.items():
            self.assertEqual(committed.get(name), text,
                             "generated/%s is stale: make regenerate" % name)
        self.assertIn("--derivatives --out <dir>",
                      whole["paper3prru_derivs.h"].decode())
        self.assertNotIn(b"eom_solve_derivs", whole["paper3prru_kernels.c"])

    def test_sets_apply_to_a_model_files_double_kernels_only(self):
        for args in (("--topology", "3", "--derivatives"),
                     (MODEL, "--precision", "float", "--regressor")):
            with tempfile.TemporaryDirectory() as d:
                r = run_gen(*args, "--out", os.path.join(d, "out"))
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn("double kernels only", r.stderr)
                self.assertFalse(os.path.exists(os.path.join(d, "out")))

    def test_types_header_replaces_the_type_definitions_only(self):
        # --types (the library's build): the descriptor and parameter
        # types come from the named header; every other byte is the same.
        outs = {}
        for flags in ((), ("--types", "prru_descriptor.h")):
            with tempfile.TemporaryDirectory() as d:
                r = run_gen(MODEL, "--out", d, "--quiet", "--prefix", "prru", *flags)
                self.assertEqual(r.returncode, 0, r.stderr)
                outs[flags] = read_dir(d)
        plain, typed = outs[()], outs[("--types", "prru_descriptor.h")]
        self.assertEqual(sorted(plain), sorted(typed))
        changed = sorted(n for n in plain if plain[n] != typed[n])
        self.assertEqual(changed, ["prru_mechanism.h", "prru_param_kernels.h"])
        mech = typed["prru_mechanism.h"].decode()
        self.assertIn('#include "prru_descriptor.h"', mech)
        self.assertNotIn("typedef struct", mech)
        self.assertIn("typedef struct", plain["prru_mechanism.h"].decode())
        params = typed["prru_param_kernels.h"].decode()
        self.assertIn('#include "prru_descriptor.h"', params)
        self.assertNotIn("typedef prru_params3 prru_params;", params)
        self.assertIn("typedef prru_params3 prru_params;", plain["prru_param_kernels.h"].decode())
        # A header name lands in an #include: refused unless it is plain.
        for bad in ('a".h', "x.c", "a b.h", "a\nb.h"):
            with tempfile.TemporaryDirectory() as d:
                r = run_gen(MODEL, "--out", os.path.join(d, "out"), "--types", bad)
                self.assertEqual(r.returncode, 2, (bad, r.stderr))
                self.assertIn("--types", r.stderr)
                self.assertFalse(os.path.exists(os.path.join(d, "out")))

    def test_help_and_summary(self):
        r = run_gen("--help")
        self.assertEqual(r.returncode, 0)
        self.assertIn("--out", r.stdout)
        with tempfile.TemporaryDirectory() as d:
            r = run_gen(MODEL, "--out", d)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertRegex(r.stdout, r"dynamics +\d+ arithmetic")


def _paper():
    with open(MODEL, encoding="utf-8") as f:
        return json.load(f)


def _bad_models():
    """(description, text, expected key, expected reason fragment)."""
    cases = []

    def edit(desc, fn, key, reason):
        m = _paper()
        fn(m)
        cases.append((desc, json.dumps(m), key, reason))

    cases.append(("truncated", json.dumps(_paper())[:-20], None, "not valid JSON"))
    cases.append(("NaN", json.dumps(_paper()).replace("9.81", "NaN"), None,
                  "non-finite"))
    cases.append(("duplicate key", json.dumps(_paper()).replace(
        '"gravity": 9.81', '"gravity": 9.81, "gravity": 9.8'), None,
        "duplicate key"))
    edit("missing body", lambda m: m["bodies"].pop("U2"), "bodies.U2",
         "missing")
    edit("unknown key", lambda m: m["geometry"].update(b4=1), "geometry.b4",
         "unknown key")
    edit("string mass", lambda m: m["bodies"]["P"].update(mass="1.7"),
         "bodies.P.mass", "must be a number")
    edit("bool", lambda m: m.update(gravity=True), "gravity",
         "must be a number")
    edit("negative length", lambda m: m["geometry"].update(l1=-0.23),
         "geometry.l1", "must be positive")
    edit("zero mass", lambda m: m["bodies"]["S3"].update(mass=0),
         "bodies.S3.mass", "must be positive")
    edit("huge", lambda m: m["geometry"].update(l2=1e300), "geometry.l2",
         "outside")
    edit("triangle", lambda m: m["bodies"]["L1"].update(
        inertia=[0.0025, 0.0003, 0.0030]), "bodies.L1.inertia", "triangle")
    edit("inertia count", lambda m: m["bodies"]["L1"].update(inertia=[1, 2]),
         "bodies.L1.inertia", "3 principal moments")
    edit("cannot assemble", lambda m: m["geometry"].update(b12=0.8),
         "geometry", "cannot be assembled")
    edit("bad name", lambda m: m.update(name="3prru"), "name",
         "C identifier")
    return cases


class BadModels(unittest.TestCase):
    def test_each_bad_model_is_rejected_with_key_and_reason(self):
        for desc, text, key, reason in _bad_models():
            with self.subTest(desc):
                with self.assertRaises(model.ModelError) as ctx:
                    model.parse(text, "m.json")
                msg = str(ctx.exception)
                self.assertTrue(msg.startswith("m.json: "), msg)
                if key:
                    self.assertIn(key + ":", msg)
                self.assertIn(reason, msg)

    def test_failed_generation_leaves_output_untouched(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "out")
            self.assertEqual(run_gen(MODEL, "--out", out, "--quiet")
                             .returncode, 0)
            before = read_dir(out)
            bad = os.path.join(d, "bad.json")
            with open(bad, "w") as f:
                f.write(_bad_models()[7][1])
            r = run_gen(bad, "--out", out)
            self.assertEqual(r.returncode, 1)
            self.assertIn("bad.json: geometry.l1: must be positive", r.stderr)
            after = read_dir(out)
            self.assertEqual(before, after)

    def test_missing_and_oversized_files(self):
        r = run_gen("/nonexistent/model.json", "--out", "/tmp/x")
        self.assertEqual(r.returncode, 1)
        self.assertIn("/nonexistent/model.json: cannot read", r.stderr)
        with tempfile.NamedTemporaryFile("w", suffix=".json") as f:
            f.write(" " * (model.MAX_BYTES + 10))
            f.flush()
            with self.assertRaises(model.ModelError) as ctx:
                model.load(f.name)
            self.assertIn("larger than", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
