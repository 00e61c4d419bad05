"""The Python binding against the prru CLI, which links the same runtime
statically and prints every number with 17 significant digits: the values
must agree bit for bit. Plus round trips (FK(IK), ID(FD)), the error
mapping, argument checks, the library search, and the ctypes mirror
against the struct definitions in the C headers.

Environment: PRRU_LIB (libprru.so), PRRU (the CLI; default: cli/prru of
the library's build directory), PRRU_SOURCE_DIR (default: this file's
tree). Works for any model the library was built for (3 or 4 actuators).
"""

import ctypes
import csv
import json
import shutil
import math
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import prru
from prru import _lib

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE_DIR = os.environ.get("PRRU_SOURCE_DIR") or os.path.dirname(os.path.dirname(HERE))
LIB = os.environ.get("PRRU_LIB")
if not LIB:
    sys.exit("test_prru: set PRRU_LIB to the libprru.so under test")
CLI = os.environ.get("PRRU") or os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(LIB))), "cli", "prru")

try:
    import numpy
except ImportError:
    numpy = None
# Set by ctest to 1 when the build found NumPy for this interpreter: then the
# NumPy tests must run, not be skipped.
if numpy is None and os.environ.get("PRRU_EXPECT_NUMPY") == "1":
    sys.exit("test_prru: NumPy was importable by %s when the build was configured and is "
             "not now: reconfigure, or reinstall NumPy" % sys.executable)


def cli(*args, ok=True):
    """Runs the CLI: its JSON on success, (exit status, stderr) when ok=False."""
    if not os.access(CLI, os.X_OK):
        raise AssertionError("the prru CLI %s is missing: build it, or set PRRU" % CLI)
    p = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True)
    if not ok:
        return p.returncode, p.stderr
    if p.returncode != 0:
        raise AssertionError("%s %s: exit %d: %s" % (CLI, " ".join(map(str, args)),
                                                     p.returncode, p.stderr))
    return p.stdout


def read(path):
    with open(path) as f:
        return f.read()


def arg(v):
    return ",".join(repr(float(x)) for x in v)


def flat(m):
    """Row-major elements of a matrix given as rows or flat (JSON either way)."""
    out = []
    for x in m:
        out.extend(flat(x) if isinstance(x, (list, tuple)) else [x])
    return out


def Linearization_keys(dt):
    """The fields of a Linearization that hold numbers (Ad, Bd with dt)."""
    keys = ("qdd", "dqdd_dq", "dqdd_dqd", "dqdd_dfd", "dqdd_dfp", "dqdd_dmp", "A", "B")
    return keys + (("Ad", "Bd") if dt else ())


def bits(x):
    """A float's identity: equal bits compare equal, NaN too."""
    if isinstance(x, (int, float)):
        return float(x).hex()
    return [bits(v) for v in x]


def parse(text):
    """JSON with every number a float ("-0" stays -0.0)."""
    return json.loads(text, parse_int=float)


MODEL = prru.Model(LIB)


def random_states(n, seed):
    """n regular states (q, qd, fd, fp, mp) near q1 = q2 = 0, where every
    valid model assembles."""
    rng, out = random.Random(seed), []
    while len(out) < n:
        q = [rng.uniform(-0.3, 0.3), rng.uniform(-0.35, 0.3), rng.uniform(-1.0, -0.5)]
        try:
            MODEL.check(q)
        except (prru.Unreachable, prru.Singular):
            continue
        out.append((q, [rng.uniform(-1, 1) for _ in range(3)],
                    [rng.uniform(-60, 60) for _ in range(MODEL.nact)],
                    [rng.uniform(-30, 30) for _ in range(3)],
                    [rng.uniform(-3, 3) for _ in range(3)]))
    return out


class TestIdentity(unittest.TestCase):
    def test_descriptor_matches_cli(self):
        out = parse(cli("eval", "--q", "0,0,-0.8"))
        self.assertEqual(out["model"], {"name": MODEL.name, "file": MODEL.model_file,
                                        "sha256": MODEL.sha256, "kernels": MODEL.kernels})
        self.assertEqual(list(MODEL.lambda_labels), out["lambda_labels"])
        self.assertEqual(len(out["d"]), MODEL.nact)
        version = cli("--version")
        self.assertIn("model actuators: %d\n" % MODEL.nact, version)
        self.assertIn("model format: %d\n" % MODEL.format, version)

    def test_descriptor_is_consistent(self):
        m = MODEL
        self.assertEqual(m.nbody, 1 + 3 * m.nlimb)
        self.assertEqual(len(m.body_names), m.nbody)
        self.assertEqual(m.body_names[m.platform], "P")
        self.assertEqual([m.body_names[i] for i in m.slider],
                         ["S%d" % (i + 1) for i in range(m.nlimb)])
        self.assertLessEqual(abs(m.total_mass - sum(m.mass)), 1e-14 * m.total_mass)
        self.assertEqual(sum(j.lambda_count for j in m.joints), m.nlambda)
        for j in m.joints:
            for k in range(j.lambda_offset, j.lambda_offset + j.lambda_count):
                self.assertTrue(m.lambda_labels[k].startswith(j.name + "_"))
        self.assertEqual(len(m.sha256), 64)
        self.assertEqual(m.npreload, m.nact - 3)

    def test_model_file_numbers(self):
        """Masses and gravity against the model file itself."""
        path = os.path.join(SOURCE_DIR, "models", MODEL.model_file)
        if not os.path.exists(path):
            self.skipTest("model file %s not in the source tree" % path)
        with open(path) as f:
            spec = json.load(f)
        named = [n for n in spec["bodies"] if n in MODEL.body_names]
        self.assertGreater(len(named), 0)
        for name in named:
            self.assertEqual(MODEL.mass[MODEL.body_names.index(name)],
                             spec["bodies"][name]["mass"])
        g = spec["gravity"]
        self.assertEqual(list(MODEL.gravity), g if isinstance(g, list) else [0.0, 0.0, -g])


class TestModelFile(unittest.TestCase):
    """Model("file.json"): a model file read by the library at run time."""

    @classmethod
    def setUpClass(cls):
        cls.built = os.environ.get("PRRU_BUILD_MODEL")
        if not cls.built:
            raise unittest.SkipTest("PRRU_BUILD_MODEL (the build's model file) not set; ctest sets it")
        cls.tmp = tempfile.mkdtemp(prefix="prru-model-")
        with open(cls.built) as f:
            cls.spec = json.load(f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def write(self, name, spec, indent=None):
        path = os.path.join(self.tmp, name)
        with open(path, "w") as f:
            json.dump(spec, f, indent=indent)
        return path

    def test_same_numbers_specialised(self):
        """The build's model re-spelt (other whitespace): the same robot, the
        specialised kernels, bit for bit the built-in model's results."""
        path = self.write("respelt.json", self.spec, indent=7)
        m = prru.Model(path)  # a first argument ending in .json: a model file
        self.assertIs(m.lib, MODEL.lib)  # the library from $PRRU_LIB
        self.assertEqual(m.kernels, "specialised")
        self.assertEqual(MODEL.kernels, "specialised")
        self.assertEqual(m.model_file, path)
        for q, qd, fd, fp, mp in random_states(5, 11):
            self.assertEqual(bits(m.dynamics(q, qd)), bits(MODEL.dynamics(q, qd)))
            self.assertEqual(bits(m.forward_dynamics(q, qd, fd, fp, mp)),
                             bits(MODEL.forward_dynamics(q, qd, fd, fp, mp)))

    def test_other_numbers_parameter(self):
        """The platform 0.5 and 1 kg heavier: the parameter kernels. G is
        linear in the platform's mass, so the first change is half the
        second; at q1 = q2 = 0 the platform's centre of mass moves with q3
        one to one (dp_c/dq3 = e3, whatever its offset), so G3 changes by
        0.5 g_z exactly. Both to the rounding of G's terms."""
        spec = json.loads(json.dumps(self.spec))
        models = []
        for dm in (0.5, 1.0):
            spec["bodies"]["P"]["mass"] = self.spec["bodies"]["P"]["mass"] + dm
            models.append(prru.Model(model=self.write("heavier%g.json" % dm, spec), lib=MODEL.lib))
        half, one = models
        self.assertEqual(half.kernels, "parameter")
        with self.assertRaisesRegex(prru.PrruError, "has no single-precision kernels"):
            half.map((-0.1, 0.1, 2), (-0.1, 0.1, 2), precision="float")
        self.assertEqual(half.mass[half.platform], MODEL.mass[MODEL.platform] + 0.5)
        checked = 0
        for z in (-0.9, -0.75, -0.6):
            q = [0.0, 0.0, z]
            try:
                MODEL.check(q)
            except (prru.Unreachable, prru.Singular):
                continue
            g0, gh, g1 = (m.dynamics(q)[2] for m in (MODEL, half, one))
            scale = 64 * 2.2e-16 * (sum(abs(x) for x in g1) + 1.0)
            self.assertLessEqual(abs((gh[2] - g0[2]) - 0.5 * MODEL.gravity[2]), scale)
            for i in range(3):
                self.assertLessEqual(abs((gh[i] - g0[i]) - 0.5 * (g1[i] - g0[i])), scale)
            checked += 1
        self.assertGreater(checked, 0)

    def test_drives_and_stroke(self):
        """models/prototype_drives.json (spec 13): the descriptor's drives in
        rail units (torque_max 0.64 N m through lead 0.02 m: 0.64 2 pi / 0.02
        N; 3000 rev/min: 1 m/s, to the rounding of those few operations),
        and a slider beyond its stroke is OutOfStroke, an Unreachable."""
        if MODEL.nlimb != 3:
            self.skipTest("a 3-limb model file")
        m = prru.Model(model=os.path.join(SOURCE_DIR, "models", "prototype_drives.json"), lib=MODEL.lib)
        self.assertEqual(list(m.lead), [0.02] * 3)
        self.assertEqual(list(m.torque_constant), [0.11] * 3)
        self.assertEqual((list(m.d_min), list(m.d_max)), ([-0.05] * 3, [0.45] * 3))
        for f, v in zip(m.force_max, m.speed_max):
            self.assertLessEqual(abs(f - 0.64 * 2 * math.pi / 0.02), 8 * 2.2e-16 * f)
            self.assertLessEqual(abs(v - 1.0), 8 * 2.2e-16)
        m.check([0.0, 0.0, 0.2])
        with self.assertRaises(prru.OutOfStroke) as e:
            m.check([0.0, 0.0, 0.3])
        self.assertIsInstance(e.exception, prru.Unreachable)
        self.assertEqual(e.exception.status, 9)
        # A map over the stroke's edge names those points as the library
        # does (prru_dme_status_name), each one a pose check() refuses.
        r = m.map((-0.3, 0.3, 7), (-0.3, 0.3, 7), q3=0.2)
        seen = set()
        for i, q1 in enumerate(r.q1):
            for j, q2 in enumerate(r.q2):
                seen.add(r.status[i][j])
                if r.status[i][j] == "out_of_stroke":
                    with self.assertRaises(prru.OutOfStroke):
                        m.check([q1, q2, 0.2])
        self.assertEqual(seen, {"ok", "out_of_stroke"})

    def test_refusals(self):
        with self.assertRaises(prru.PrruIOError) as e:
            prru.Model(model=os.path.join(self.tmp, "missing.json"), lib=MODEL.lib)
        self.assertIn("missing.json", str(e.exception))
        spec = json.loads(json.dumps(self.spec))
        spec["bodies"]["P"]["mass"] = -1.0
        with self.assertRaises(prru.ParseError) as e:
            prru.Model(model=self.write("negative.json", spec), lib=MODEL.lib)
        self.assertIn("mass", str(e.exception))

    def test_other_topology(self):
        """Any model file loads, whatever the library's build: the other
        topology's committed model, on its parameter kernels, sized by its
        own counts. ID(FD(fd)) gives back the generalised forces J_d^T fd
        (exactly fd with three actuators, its minimum-norm part with four)
        within K = 256 times the rounding bound of the two solves:
        |M|_1 bfd (FD's error in qdd, bfd = u (kappa_1(M) |qdd| +
        |M^-1|_1 S), mapped by M) plus u (|M|_1 |qdd| + S) (ID's own),
        S = |h| + |G| + |passive| + max_j sum_i |J_d,ij fd_i|."""
        other = os.path.join(SOURCE_DIR, "models",
                             "3prru_paper.json" if MODEL.nlimb == 4 else "4prru.json")
        m = prru.Model(model=other, lib=MODEL.lib)
        self.assertEqual((m.nlimb, m.nact), (7 - MODEL.nlimb, 7 - MODEL.nlimb))
        self.assertEqual(m.kernels, "parameter")
        q, qd = (0.05, -0.08, -0.36), (0.2, -0.1, 0.05)
        fd = [30.0 + 5 * i for i in range(m.nact)]
        d, Jd = m.ik(q)
        self.assertEqual(len(d), m.nact)
        qdd = list(m.forward_dynamics(q, qd, fd))
        back = list(m.inverse_dynamics(q, qd, qdd))
        self.assertEqual(len(back), m.nact)
        M, h, G = m.dynamics(q, qd)
        M = [list(r) for r in M]
        Jd = [list(r) for r in Jd]
        u, n1 = 2.0 ** -53, lambda a: max(sum(abs(a[i][j]) for i in range(3)) for j in range(3))
        c = [[M[(i + 1) % 3][(j + 1) % 3] * M[(i + 2) % 3][(j + 2) % 3]
              - M[(i + 1) % 3][(j + 2) % 3] * M[(i + 2) % 3][(j + 1) % 3] for i in range(3)]
             for j in range(3)]
        det = sum(M[0][j] * c[j][0] for j in range(3))
        Minv = [[c[i][j] / det for j in range(3)] for i in range(3)]
        S = (max(map(abs, h)) + max(map(abs, G)) + max(map(abs, m.passive(q, qd)))
             + max(sum(abs(Jd[i][j] * fd[i]) for i in range(m.nact)) for j in range(3)))
        nq = max(map(abs, qdd))
        bfd = u * (n1(M) * n1(Minv) * nq + n1(Minv) * S)
        bound = 256 * (n1(M) * bfd + u * (n1(M) * nq + S))
        for j in range(3):
            a = sum(Jd[i][j] * fd[i] for i in range(m.nact))
            b = sum(Jd[i][j] * back[i] for i in range(m.nact))
            self.assertLessEqual(abs(a - b), bound, (j, a, b, bound))


class TestExamples(unittest.TestCase):
    def test_body_frames_figure(self):
        """python/examples/body_frames.py (docs/img/body_frames.png) draws
        the library's model: a PNG of its stated size."""
        if not shutil.which("gnuplot"):
            self.skipTest("gnuplot not installed (make demo installs gnuplot-nox)")
        with tempfile.TemporaryDirectory() as tmp:
            png = os.path.join(tmp, "frames.png")
            script = os.path.join(SOURCE_DIR, "python", "examples", "body_frames.py")
            p = subprocess.run([sys.executable, script, png], capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(png, "rb") as f:
                head = f.read(24)
            self.assertEqual(head[:8], b"\x89PNG\r\n\x1a\n")
            self.assertEqual((int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")),
                             (1100, 900))


class TestAgainstCli(unittest.TestCase):
    """Every value bit for bit as `prru eval`, `ik`, `fk`, `dme` print it."""

    def test_eval(self):
        for q, qd, fd, fp, mp in random_states(6, 1):
            out = parse(cli("eval", "--q", arg(q), "--qd", arg(qd), "--fd", arg(fd),
                                 "--fp", arg(fp), "--mp", arg(mp)))
            M, h, G = MODEL.dynamics(q, qd)
            self.assertEqual(bits(flat(M)), bits(flat(out["M"])))
            self.assertEqual(bits(h), bits(out["h"]))
            self.assertEqual(bits(G), bits(out["G"]))
            self.assertEqual(bits(MODEL.passive(q, qd)), bits(out["passive"]))
            d, Jd = MODEL.ik(q)
            self.assertEqual(bits(d), bits(out["d"]))
            self.assertEqual(bits(flat(Jd)), bits(flat(out["Jd"])))
            self.assertEqual(bits(MODEL.check(q)), bits(out["Jd_rcond"]))
            self.assertEqual(bits(MODEL.forward_dynamics(q, qd, fd, fp, mp)), bits(out["qdd"]))
            lam = MODEL.reactions(q, qd, fd, fp, mp)
            self.assertEqual(bits(lam), bits(out["lambda"]))
            self.assertEqual(MODEL.reactions(q, qd, fd, fp, mp, labelled=True),
                             dict(zip(out["lambda_labels"], out["lambda"])))
            if MODEL.npreload:
                n = MODEL.actuator_null(q)
                self.assertEqual(bits(n), bits(out["actuator_null"]))
            if MODEL.nreaction_null:
                self.assertEqual(bits(MODEL.reaction_null(q)), bits(out["reaction_null"]))

    def test_linearize_batch(self):
        """Model.linearize_batch: per state, linearize's numbers, or the
        exception linearize raises there, returned; the other states stand.
        The batched kernel's own rule (a few ulp of q1, q2 propagated,
        where the vector sin and cos take part) is test_batch's, in C; this
        checks the binding, whose mistakes (a state's or a block's place)
        are O(1) of a block: 1e-12 of the block's largest entry is above
        that rule's few ulp by four orders and below a misplaced entry by
        twelve."""
        states = [tuple(s) for s in random_states(6, 11)]
        bad = [3.0, 0.0, 0.0]
        states.insert(2, (bad,) + states[0][1:])
        for dt in (None, 0.002):
            got = MODEL.linearize_batch(states, dt=dt)
            self.assertEqual(len(got), len(states))
            self.assertIsInstance(got[2], prru.Unreachable)
            with self.assertRaises(prru.Unreachable):
                MODEL.linearize(*states[2], dt=dt)
            for k, (lin, st) in enumerate(zip(got, states)):
                if k == 2:
                    continue
                want = MODEL.linearize(*st, dt=dt)
                for key in Linearization_keys(dt):
                    a, b = flat(getattr(lin, key)), flat(getattr(want, key))
                    scale = max(1e-300, max(abs(x) for x in b))
                    self.assertLessEqual(max(abs(x - y) for x, y in zip(a, b)), 1e-12 * scale,
                                         "state %d %s" % (k, key))
        self.assertEqual(MODEL.linearize_batch([]), [])
        with self.assertRaises(ValueError):
            MODEL.linearize_batch([states[0][:2]])
        with self.assertRaises(ValueError):
            MODEL.linearize_batch(states, dt=-1.0)

    def test_linearize(self):
        """Model.linearize equals `prru linearize` to the bit, with and
        without --dt; the CLI's refusals are the binding's."""
        keys = ("qdd", "dqdd_dq", "dqdd_dqd", "dqdd_dfd", "dqdd_dfp", "dqdd_dmp", "A", "B")
        for k, (q, qd, fd, fp, mp) in enumerate(random_states(4, 7)):
            dt = 0.002 if k % 2 else None
            args = ["linearize", "--q", arg(q), "--qd", arg(qd), "--fd", arg(fd),
                    "--fp", arg(fp), "--mp", arg(mp)] + (["--dt", repr(dt)] if dt else [])
            out = parse(cli(*args))
            lin = MODEL.linearize(q, qd, fd, fp, mp, dt=dt)
            for key in keys + (("Ad", "Bd") if dt else ()):
                self.assertEqual(bits(flat(getattr(lin, key))), bits(flat(out[key])), key)
            self.assertEqual(bits(lin.qdd), bits(MODEL.forward_dynamics(q, qd, fd, fp, mp)))
            if not dt:
                self.assertIsNone(lin.Ad)
                self.assertNotIn("Ad", out)
        with self.assertRaises(ValueError):
            MODEL.linearize(q, qd, fd, dt=0.0)
        with self.assertRaises(prru.Unreachable):
            MODEL.linearize([3.0, 0.0, 0.0], qd, fd)
        if MODEL.nlimb == 3 and MODEL.model_file != "prototype_drives.json":
            # A model loaded at run time: the topology's kernels, the CLI's numbers.
            path = os.path.join(SOURCE_DIR, "models", "prototype_drives.json")
            other = prru.Model(model=path, lib=MODEL.lib)
            q, qd, fd = [0.0, 0.0, 0.1], [0.1, 0.2, 0.3], [1.0, 2.0, 3.0]
            lin = other.linearize(q, qd, fd, dt=0.01)
            out = parse(cli("--model", path, "linearize", "--q", arg(q), "--qd", arg(qd),
                            "--fd", arg(fd), "--dt", "0.01"))
            self.assertEqual(out["model"]["kernels"], "parameter")
            for key in keys + ("Ad", "Bd"):
                self.assertEqual(bits(flat(getattr(lin, key))), bits(flat(out[key])), key)

    def test_ik_fk_dme(self):
        for q, _, _, _, _ in random_states(4, 2):
            out = parse(cli("ik", "--q", arg(q)))
            d, Jd = MODEL.ik(q)
            self.assertEqual(bits(d), bits(out["d"]))
            self.assertEqual(bits(flat(Jd)), bits(flat(out["Jd"])))
            fk = parse(cli("fk", "--d", arg(d)))
            self.assertEqual(bits(MODEL.fk(d)), bits(fk["q"]))
            qq, res = MODEL.fk_lsq(d)
            if fk["method"] == "least-squares":
                self.assertEqual(bits(qq), bits(fk["q"]))
                self.assertEqual(bits(res), bits(fk["residual"]))
            lsq = parse(cli("fk", "--d", arg(d), "--lsq", "--seed", arg(q)))
            qq, res = MODEL.fk_lsq(d, seed=q)
            self.assertEqual(bits(qq), bits(lsq["q"]))
            self.assertEqual(bits(res), bits(lsq["residual"]))
            dme = parse(cli("dme", "--q", arg(q)))
            o = MODEL.dme(q)
            self.assertEqual(bits(o.w_R), bits(dme["w_R"]))
            self.assertEqual(bits(MODEL.w_R(q)), bits(dme["w_R"]))
            self.assertEqual(bits(o.jd_rcond), bits(dme["Jd_rcond"]))
            self.assertEqual(bits(o.sigma), bits(dme["sigma"]))
            self.assertEqual(bits(o.semi_axis), bits(dme["semi_axes"]))
            self.assertEqual(bits(flat(o.axis_dir)), bits(flat(dme["axis_directions"])))
            self.assertEqual(bits(o.sigma_T), bits(dme["sigma_T"]))
            self.assertEqual(bits(o.half_length_T), bits(dme["translational_half_length"]))
            self.assertEqual(bits(o.dir_T), bits(dme["translational_direction"]))
            self.assertEqual(bits(flat(o.Mt)), bits(flat(dme["Mt"])))
            self.assertEqual(bits(flat(o.JtR)), bits(flat(dme["JtR"])))
            self.assertEqual(bits(flat(o.JtT)), bits(flat(dme["JtT"])))

    def test_inconsistent_sliders(self):
        """More sliders than coordinates: a fourth slider 1 mm off where the
        others put it has no exact pose (fk: NoConvergence, CLI exit 1);
        fk_lsq gives the CLI's least-squares fit and residual."""
        if MODEL.nact == 3:
            self.skipTest("three sliders are always consistent")
        q = random_states(1, 12)[0][0]
        d = MODEL.ik(q)[0]
        d[-1] += 1e-3
        self.assertEqual(cli("fk", "--d", arg(d), ok=False)[0], 1)
        with self.assertRaisesRegex(prru.NoConvergence, "did not converge"):
            MODEL.fk(d)
        out = parse(cli("fk", "--d", arg(d), "--lsq"))
        qq, res = MODEL.fk_lsq(d)
        self.assertEqual(bits(qq), bits(out["q"]))
        self.assertEqual(bits(res), bits(out["residual"]))
        self.assertGreater(res, 1e-4)

    def test_simulate_paper(self):
        """The paper scenario's first 0.05 s, every sample and column, with
        the CLI's default reactions."""
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "run.csv")
            cli("simulate", "--scenario", "paper", "--t-end", "0.05", "--out", path)
            lines = [l for l in read(path).splitlines() if not l.startswith("#")]
        header = lines[0].split(",")
        rows = [[float(x) for x in l.split(",")] for l in lines[1:]]
        run = MODEL.simulate(scenario="paper", t_end=0.05, reactions=True)
        self.assertEqual(len(run), len(rows))
        col = {name: i for i, name in enumerate(header)}
        n = MODEL.nact
        for k, row in enumerate(rows):
            def pick(names):
                return [row[col[c]] for c in names]
            self.assertEqual(bits(run.t[k]), bits(row[col["t"]]))
            self.assertEqual(bits(run.q[k]), bits(pick(["q1", "q2", "q3"])))
            self.assertEqual(bits(run.qd[k]), bits(pick(["qd1", "qd2", "qd3"])))
            self.assertEqual(bits(run.qdd[k]), bits(pick(["qdd1", "qdd2", "qdd3"])))
            self.assertEqual(bits(run.d[k]), bits(pick(["d%d" % (i + 1) for i in range(n)])))
            self.assertEqual(bits(run.lambda_[k]), bits(pick(MODEL.lambda_labels)))
            self.assertEqual(bits([run.T[k], run.V[k]]), bits(pick(["T", "V"])))

    def test_map(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "map.csv")
            text = cli("map", "--q1", "-0.5:0.5:5", "--q2", "-0.7:0.5:4", "--q3", "-0.1",
                       "--rcond-min", "4e-3", "--out", path)
            lines = [l for l in read(path).splitlines() if not l.startswith("#")]
        rows = [l.split(",") for l in lines[1:]]
        r = MODEL.map((-0.5, 0.5, 5), (-0.7, 0.5, 4), -0.1, jd_rcond_min=4e-3)
        self.assertEqual(len(rows), 20)
        for k, row in enumerate(rows):
            i, j = divmod(k, 4)
            self.assertEqual(bits([r.q1[i], r.q2[j], r.q3]), bits([float(x) for x in row[:3]]))
            self.assertEqual(bits(r.w_R[i][j]), bits(float(row[3])))
            self.assertEqual(r.status[i][j], row[4])
        index = float(re.search(r"global_index: (\S+)", text).group(1))
        self.assertEqual("%.10g" % r.summary["index"], "%.10g" % index)
        self.assertEqual(r.summary["n_points"], 20)

    def test_measure(self):
        # The binding's measure against prru measure on the same tracked
        # run: the same rows, quantised sliders and seeded noise to the bit,
        # and the same differentiation setting.
        n = MODEL.nact
        with tempfile.TemporaryDirectory() as tmp:
            traj, run, meas = (os.path.join(tmp, f) for f in ("traj.csv", "run.csv", "meas.csv"))
            cli("traj", "--waypoints", "0,0,-0.8;0.1,0.05,-0.78", "--durations", "0.3", "--dt", "0.001",
                "--out", traj)
            cli("track", "--ref", traj, "--dt", "0.001", "--out", run)
            cli("measure", "--run", run, "--out", meas, "--rate", "500", "--d-resolution", "1e-6",
                "--force-noise", "0.2", "--seed", "7")
            rows = list(csv.DictReader(l for l in read(run).splitlines() if not l.startswith("#")))
            text = read(meas)
        col = lambda r, p, k: [float(r["%s%d" % (p, i + 1)]) for i in range(k)]
        m = MODEL.measure([float(r["t"]) for r in rows], [col(r, "d", n) for r in rows],
                          [col(r, "fd", n) for r in rows], rate=500, d_resolution=1e-6,
                          force_noise=0.2, seed=7, qdd=[col(r, "qdd", 3) for r in rows])
        out = [l.split(",") for l in text.splitlines() if not l.startswith("#")][1:]
        self.assertEqual(len(out), len(m.t))
        for k, r in enumerate(out):
            self.assertEqual(bits([m.t[k]] + list(m.d[k]) + list(m.fd[k])), bits([float(x) for x in r]))
        w = re.search(r"--window (\d+) --degree (\d+)", text)
        self.assertEqual((m.window, m.degree), (int(w.group(1)), int(w.group(2))))
        self.assertLessEqual(m.qdd_error, m.default_error)
        t = [float(r["t"]) for r in rows]
        with self.assertRaisesRegex(prru.InputError, "no row at t = "):
            MODEL.measure(t, [col(r, "d", n) for r in rows], [col(r, "fd", n) for r in rows], rate=300)
        with self.assertRaisesRegex(ValueError, "as many rows"):
            MODEL.measure(t[:-1], [col(r, "d", n) for r in rows], [col(r, "fd", n) for r in rows])
        with self.assertRaisesRegex(ValueError, "force_noise must be non-negative"):
            MODEL.measure(t, [col(r, "d", n) for r in rows], [col(r, "fd", n) for r in rows], force_noise=-1)

    def test_map_precision_float(self):
        # precision="float" is prru map --precision float: the same
        # statuses and w_R as the CLI's float map (to its 17 digits), the
        # statuses those of the double map; another value or a model
        # without float kernels (the parameter kernels) is refused.
        args = ("--q1", "-1:1:13", "--q2", "-1:1:11", "--q3", "0.05", "--rcond-min", "4e-3")
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "map.csv")
            text = cli("map", *args, "--precision", "float", "--out", path)
            lines = [l for l in read(path).splitlines() if not l.startswith("#")]
        self.assertIn("precision: float (", text)
        rows = [l.split(",") for l in lines[1:]]
        r = MODEL.map((-1, 1, 13), (-1, 1, 11), 0.05, jd_rcond_min=4e-3, precision="float")
        d = MODEL.map((-1, 1, 13), (-1, 1, 11), 0.05, jd_rcond_min=4e-3)
        flat = [s for row in r.status for s in row]
        self.assertEqual(flat, [row[4] for row in rows])
        self.assertEqual(flat, [s for row in d.status for s in row])
        w = [x for row in r.w_R for x in row]
        self.assertEqual(["%.17g" % x if x == x else "NaN" for x in w], [row[3] for row in rows])
        self.assertEqual(r.summary["precision"], "float")
        self.assertEqual(d.summary["precision"], "double")
        with self.assertRaisesRegex(ValueError, "precision must be 'double' or 'float', got 'half'"):
            MODEL.map((-1, 1, 3), (-1, 1, 3), precision="half")

    def test_map_other_mode(self):
        # A grid reaching past the singular locus: the binding's statuses
        # and counts are the CLI's, other_mode included (three actuators;
        # with four J_d has no sign and no point is other_mode).
        args = ("--q1", "-1:1:13", "--q2", "-1:1:11", "--q3", "0.05", "--rcond-min", "4e-3")
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "map.csv")
            text = cli("map", *args, "--out", path)
            lines = [l for l in read(path).splitlines() if not l.startswith("#")]
        statuses = [l.split(",")[4] for l in lines[1:]]
        r = MODEL.map((-1, 1, 13), (-1, 1, 11), 0.05, jd_rcond_min=4e-3)
        self.assertEqual([s for row in r.status for s in row], statuses)
        s = r.summary
        n_other = statuses.count("other_mode")
        self.assertEqual(s["n_other_mode"], n_other)
        self.assertEqual(n_other > 0, MODEL.nact == 3)
        counts = re.search(r"ok (\d+), singular (\d+), unreachable (\d+), other assembly mode (\d+)",
                           text).groups()
        self.assertEqual([int(c) for c in counts],
                         [s["n_ok"], s["n_singular"] - n_other, s["n_unreachable"], n_other])


def csv_rows(text):
    """The data rows of a CLI CSV as dicts of floats (comments skipped)."""
    return [{k: float(v) for k, v in r.items()}
            for r in csv.DictReader(l for l in text.splitlines() if not l.startswith("#"))]


class TestMotion(unittest.TestCase):
    """limits, quintic, time_optimal and track against prru traj and prru
    track: the same library calls, so the same rows to the bit."""

    WPS = [[0, 0, -0.8], [0.1, 0.05, -0.78], [0, 0, -0.8]]
    WPS_TEXT = "0,0,-0.8;0.1,0.05,-0.78;0,0,-0.8"

    def static_load(self):
        return max(abs(f) for q in self.WPS for f in MODEL.inverse_dynamics(q, [0] * 3, [0] * 3))

    def motion_columns(self, mo, k):
        n = MODEL.nact
        row = {"t": mo.t[k]}
        for name, width in (("q", 3), ("qd", 3), ("qdd", 3), ("d", n), ("dd", n), ("fd", n)):
            for i in range(width):
                row["%s%d" % (name, i + 1)] = getattr(mo, name)[k][i]
        return row

    def same_rows(self, mo, rows):
        self.assertEqual(len(mo.t), len(rows))
        for k, r in enumerate(rows):
            mine = self.motion_columns(mo, k)
            self.assertEqual(bits([mine[c] for c in r]), bits(list(r.values())), "row %d" % k)

    def test_limits(self):
        n = MODEL.nact
        own = MODEL.limits()
        self.assertEqual(len(own.force_max), n)
        none = MODEL.limits(model_limits=False)
        self.assertEqual(none, prru.Limits((math.inf,) * n, (math.inf,) * n, ((-math.inf, math.inf),) * n))
        lim = MODEL.limits(force_max=100, speed_max=[0.1 * (i + 1) for i in range(n)], stroke=(-1, 1))
        self.assertEqual(lim.force_max, (100.0,) * n)
        self.assertEqual(lim.speed_max[-1], 0.1 * n)
        self.assertEqual(lim.stroke, ((-1.0, 1.0),) * n)
        # The model file's limits (spec 13) are what the library applies.
        with tempfile.TemporaryDirectory() as tmp:
            model = json.loads(read(os.environ.get("PRRU_BUILD_MODEL")
                                    or os.path.join(SOURCE_DIR, "models", "3prru_paper.json")))
            model.setdefault("format", 1)
            if model["format"] == 1:
                g = model["geometry"]
                model["geometry"] = {"b": [g["b12"], g["b12"], g["b3"]], "l1": g["l1"], "l2": g["l2"],
                                     "a": g["a"]}
                model["format"] = 2
            model.setdefault("actuators", {}).update(
                {"force_max": [300 + i for i in range(n)], "speed_max": 0.5, "stroke": [-2, 2]})
            path = os.path.join(tmp, "lim.json")
            with open(path, "w") as f:
                json.dump(model, f)
            m = prru.Model(LIB, model=path)
        self.assertEqual(m.limits(), prru.Limits(tuple(300.0 + i for i in range(n)), (0.5,) * n,
                                                 ((-2.0, 2.0),) * n))
        self.assertEqual(m.limits(force_max=50).force_max, (50.0,) * n)
        for kw, pattern in (({"force_max": -1}, r"force_max\[0\] must be > 0"),
                            ({"speed_max": [1] * (n + 1)}, "speed_max must have %d" % n),
                            ({"stroke": (1, 0)}, r"stroke\[0\]: slider 1's range \[1.0, 0.0\] is empty"),
                            ({"force_max": math.nan}, r"force_max\[0\] must be a number")):
            with self.subTest(kw=kw), self.assertRaisesRegex(ValueError, pattern):
                MODEL.limits(**kw)
        with self.assertRaisesRegex(TypeError, "limits must be a prru.Limits"):
            MODEL.time_optimal(self.WPS, limits={"force_max": 1})

    def test_quintic(self):
        mo = MODEL.quintic(self.WPS, [0.3, 0.25])
        rows = csv_rows(cli("traj", "--waypoints", self.WPS_TEXT, "--durations", "0.3,0.25"))
        self.same_rows(mo, rows)
        # The forces (not in prru traj's rows) are inverse dynamics.
        k = len(mo.t) // 3
        self.assertEqual(bits(mo.fd[k]), bits(MODEL.inverse_dynamics(mo.q[k], mo.qd[k], mo.qdd[k])))
        with self.assertRaisesRegex(prru.InputError, "duration"):
            MODEL.quintic(self.WPS, [0.3, -1])
        with self.assertRaisesRegex(ValueError, "durations must have 2 elements"):
            MODEL.quintic(self.WPS, [0.3])
        # Far beyond the links' reach: the first sample outside, named.
        with self.assertRaisesRegex(prru.Unreachable, r"quintic: sample \d+ \(t = "):
            MODEL.quintic([[0, 0, -0.8], [1.5, 1.5, -0.8]], [1])

    def test_time_optimal(self):
        F = 3 * self.static_load()
        lim = MODEL.limits(model_limits=False, force_max=F, speed_max=0.4)
        r = MODEL.time_optimal(self.WPS, limits=lim)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "topp.csv")
            p = subprocess.run([CLI, "traj", "--time-optimal", "--waypoints", self.WPS_TEXT, "--no-limits",
                                "--force-max", repr(F), "--speed-max", "0.4", "--out", out],
                               capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            text = read(out)
        self.same_rows(r.motion, csv_rows(text))
        dur = float(re.search(r"3 waypoints, ([0-9.e+-]+) s", p.stderr).group(1))
        self.assertEqual("%.9g" % r.duration, "%.9g" % dur)
        self.assertEqual(r.limits, lim)
        self.assertEqual(r.grid, 400)
        self.assertGreaterEqual(r.active_fraction, 0.95)
        self.assertLess(r.duration, sum(r.quintic_durations))
        # Every row within the limits (ROW_TOL), and some force at its limit.
        peak = max(abs(f) for row in r.motion.fd for f in row)
        self.assertLessEqual(peak, F * (1 + 1e-6))  # PRRU_TOPP_ROW_TOL
        self.assertGreaterEqual(peak, F * (1 - 1e-3))
        with self.assertRaisesRegex(prru.InputError, "force_max of actuator"):
            MODEL.time_optimal(self.WPS, limits=MODEL.limits(model_limits=False,
                                                            force_max=0.5 * self.static_load()))

    def test_track(self):
        ref = MODEL.quintic(self.WPS[:2], [0.3])
        run = MODEL.track(ref, mismatch={"mass": 1.1}, limits=MODEL.limits(model_limits=False))
        # prru track --ref on prru traj's rows: the same reference (the C2
        # quintic through the same rows) as the binding's from ref.
        with tempfile.TemporaryDirectory() as tmp:
            tr, out, summ = (os.path.join(tmp, f) for f in ("traj.csv", "tr.csv", "tr.json"))
            cli("traj", "--waypoints", ";".join(self.WPS_TEXT.split(";")[:2]), "--durations", "0.3",
                "--out", tr)
            cli("track", "--ref", tr, "--mismatch", "mass=1.1", "--no-limits", "--out", out, "--summary", summ)
            rows, s = csv_rows(read(out)), json.loads(read(summ))
        n = MODEL.nact
        self.assertEqual(len(run.t), len(rows))
        for k in (0, len(rows) // 2, len(rows) - 1):
            r = rows[k]
            self.assertEqual(bits(run.q[k]), bits([r["q%d" % (i + 1)] for i in range(3)]))
            self.assertEqual(bits(run.q_ref[k]), bits([r["qr%d" % (i + 1)] for i in range(3)]))
            self.assertEqual(bits(run.fd[k]), bits([r["fd%d" % (i + 1)] for i in range(n)]))
            self.assertEqual(bits(run.qdd[k]), bits([r["qdd%d" % (i + 1)] for i in range(3)]))
        for key in ("rms_error", "max_error", "max_fd", "max_dd", "over_speed_fraction", "feedforward_peak",
                    "samples", "kp", "kd"):
            self.assertEqual(bits(run.summary[key]), bits(s[key]), key)
        self.assertEqual((run.summary["controller"], s["controller"]), ("computed_torque",) * 2)
        # The library's summary is over the rows' own slider speeds.
        self.assertEqual(list(run.summary["max_dd"]), [max(abs(r[i]) for r in run.dd) for i in range(n)])
        self.assertEqual(run.summary["status"], "complete")
        self.assertGreater(max(run.summary["max_error"]), 0)  # the mismatch shows
        exact = MODEL.track(ref)
        self.assertLess(max(exact.summary["max_error"]), 1e-6 * max(run.summary["max_error"]) + 1e-9)
        # A stroke the reference leaves: named, nothing run.
        d0 = ref.d[0][0]
        with self.assertRaisesRegex(prru.InputError, r"reference at sample 1 \(t = 0 s\): slider 1"):
            MODEL.track(ref, limits=MODEL.limits(model_limits=False, stroke=(d0 + 1e-3, d0 + 1)))
        with self.assertRaisesRegex(ValueError, "mismatch: unknown key 'weight'"):
            MODEL.track(ref, mismatch={"weight": 2})
        # A callback-free run keeps the rows it made when the plant fails.
        with self.assertRaises(prru.Unreachable) as cm:
            MODEL.track(ref, limits=MODEL.limits(model_limits=False,
                                                 stroke=(min(min(r) for r in ref.d) - 1e-9,
                                                         max(max(r) for r in ref.d) + 1e-9)),
                        mismatch={"mass": 3})
        self.assertGreater(len(cm.exception.run.t), 0)

    def test_track_lqr(self):
        """controller='lqr' is prru track --controller lqr: the same rows
        and summary to the bit, the default weights reported; bad choices
        refused as the CLI refuses them."""
        ref = MODEL.quintic(self.WPS[:2], [0.3])
        run = MODEL.track(ref, period=0.002, controller="lqr", mismatch={"mass": 1.2},
                          limits=MODEL.limits(model_limits=False))
        with tempfile.TemporaryDirectory() as tmp:
            tr, out, summ = (os.path.join(tmp, f) for f in ("traj.csv", "tr.csv", "tr.json"))
            cli("traj", "--waypoints", ";".join(self.WPS_TEXT.split(";")[:2]), "--durations", "0.3",
                "--out", tr)
            cli("track", "--ref", tr, "--period", "0.002", "--controller", "lqr", "--mismatch", "mass=1.2",
                "--no-limits", "--out", out, "--summary", summ)
            rows, s = csv_rows(read(out)), json.loads(read(summ))
        n = MODEL.nact
        self.assertEqual(len(run.t), len(rows))
        for k in (0, len(rows) // 2, len(rows) - 1):
            r = rows[k]
            self.assertEqual(bits(run.q[k]), bits([r["q%d" % (i + 1)] for i in range(3)]))
            self.assertEqual(bits(run.fd[k]), bits([r["fd%d" % (i + 1)] for i in range(n)]))
        for key in ("rms_error", "max_error", "max_fd", "lqr_q", "lqr_r", "samples"):
            self.assertEqual(bits(run.summary[key]), bits(s[key]), key)
        self.assertEqual((run.summary["controller"], len(run.summary["lqr_q"]), len(run.summary["lqr_r"])),
                         ("lqr", 6, n))
        self.assertGreater(max(run.summary["max_error"]), 0)  # the mismatch shows
        # Given weights are used as given; stiffer position weights track
        # the heavier plant closer.
        q = [10 * v for v in run.summary["lqr_q"]]
        stiff = MODEL.track(ref, period=0.002, controller="lqr", lqr_q=q, lqr_r=run.summary["lqr_r"],
                            mismatch={"mass": 1.2}, limits=MODEL.limits(model_limits=False))
        self.assertEqual(bits(stiff.summary["lqr_q"]), bits(q))
        self.assertLess(max(stiff.summary["max_error"]), max(run.summary["max_error"]))
        # All weights 0 is the default (prru_control.h's rule, prru track's too).
        zero = MODEL.track(ref, period=0.002, controller="lqr", lqr_q=[0] * 6, lqr_r=[0] * n,
                           mismatch={"mass": 1.2}, limits=MODEL.limits(model_limits=False))
        for key in ("lqr_q", "lqr_r", "max_error"):
            self.assertEqual(bits(zero.summary[key]), bits(run.summary[key]), key)
        for kw, msg in ((dict(controller="lqr"), "needs period > 0"),
                        (dict(controller="pid", period=0.002), "controller must be"),
                        (dict(period=0.002, lqr_q=[1] * 6), "belong to controller='lqr'"),
                        (dict(controller="lqr", period=0.002, lqr_q=[1, 1, 1, -1, 1, 1]), "lqr_q"),
                        (dict(controller="lqr", period=0.002, lqr_r=[1] * (n - 1) + [0]), "lqr_r"),
                        (dict(controller="lqr", period=0.002, lqr_r=[1] * (n + 1)), "lqr_r")):
            with self.subTest(**{k: str(v) for k, v in kw.items()}):
                with self.assertRaisesRegex(ValueError, msg):
                    MODEL.track(ref, **kw)


class TestIdentification(unittest.TestCase):
    """excite and identify against prru excite and prru identify: the same
    library calls, so the same rows and the same model numbers."""

    ARGS = dict(evals=300, period=8.0, harmonics=4, amplitude=(0.2, 0.2, 0.02), dt=0.01)

    @classmethod
    def setUpClass(cls):
        cls.ex = MODEL.excite(**cls.ARGS)

    def test_excite(self):
        ex, n = self.ex, MODEL.nact
        text = cli("excite", "--evals", "300", "--period", "8", "--harmonics", "4", "--amplitude", "0.2,0.2,0.02",
                   "--dt", "0.01")
        rows = csv_rows(text)
        self.assertEqual(len(rows), len(ex.motion.t))
        for k in (0, len(rows) // 3, len(rows) - 1):
            r, mo = rows[k], ex.motion
            mine = [mo.t[k]] + list(mo.q[k]) + list(mo.qd[k]) + list(mo.qdd[k]) + list(mo.d[k]) + list(mo.fd[k])
            cols = (["t"] + ["q%d" % i for i in (1, 2, 3)] + ["qd%d" % i for i in (1, 2, 3)]
                    + ["qdd%d" % i for i in (1, 2, 3)] + ["d%d" % (i + 1) for i in range(n)]
                    + ["fd%d" % (i + 1) for i in range(n)])
            self.assertEqual(bits(mine), bits([r[c] for c in cols]), "row %d" % k)
        cond = float(re.search(r"condition number ([0-9.e+-]+) \(start", text).group(1))
        self.assertEqual("%.6g" % ex.cond, "%.6g" % cond)
        a1 = [float(x) for x in re.search(r"# q1: a ([^;]+);", text).group(1).split()]
        self.assertEqual(bits(list(ex.a[0])), bits(a1))
        self.assertEqual(ex.harmonics, 4)
        self.assertEqual(ex.limits, MODEL.limits())
        # With a stroke that just holds this excitation (the run's model,
        # which bounds the reach, evaluates everything, the base parameters
        # included, as in prru excite): the same coefficients.
        lo = min(min(r) for r in ex.motion.d) - 0.002
        hi = max(max(r) for r in ex.motion.d) + 0.002
        ex2 = MODEL.excite(limits=MODEL.limits(stroke=(lo, hi)), **self.ARGS)
        text2 = cli("excite", "--evals", "300", "--period", "8", "--harmonics", "4", "--amplitude",
                    "0.2,0.2,0.02", "--dt", "0.01", "--stroke", "%r,%r" % (lo, hi))
        a2 = [float(x) for x in re.search(r"# q1: a ([^;]+);", text2).group(1).split()]
        self.assertEqual(bits(list(ex2.a[0])), bits(a2))
        with self.assertRaisesRegex(ValueError, "harmonics must be at most 8"):
            MODEL.excite(harmonics=9)
        with self.assertRaisesRegex(ValueError, "rcond_min must lie between 0 and 1"):
            MODEL.excite(rcond_min=2)

    def test_identify(self):
        mo, n = self.ex.motion, MODEL.nact
        with tempfile.TemporaryDirectory() as tmp:
            data, out, rep = (os.path.join(tmp, f) for f in ("ex.csv", "id.json", "rep.csv"))
            with open(data, "w") as f:
                f.write("t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,%s\n" % ",".join("fd%d" % (i + 1) for i in range(n)))
                for k in range(len(mo.t)):
                    f.write(",".join(repr(float(x)) for x in [mo.t[k]] + list(mo.q[k]) + list(mo.qd[k])
                                     + list(mo.qdd[k]) + list(mo.fd[k])) + "\n")
            cli("identify", "--data", data, "--out", out, "--report", rep)
            theirs, report = json.loads(read(out)), read(rep)
            r = MODEL.identify(mo.t, mo.q, mo.qd, mo.qdd, mo.fd)
            mine = json.loads(r.text)
            r.write(os.path.join(tmp, "mine.json"))
            written = prru.Model(LIB, model=os.path.join(tmp, "mine.json"))
        self.assertEqual(mine["name"], theirs["name"])
        for key in ("gravity", "geometry", "bodies", "actuators"):
            self.assertEqual(mine[key], theirs[key], key)
        self.assertEqual(written.name, theirs["name"])
        rows = list(csv.DictReader(l for l in report.splitlines() if not l.startswith("#")))
        self.assertEqual(len(rows), r.nbase)
        for p, row in zip(r.parameters, rows):
            self.assertEqual(p.name, row["parameter"])
            self.assertEqual(bits([p.estimate, p.se, p.prior, p.model]),
                             bits([float(row[k]) for k in ("estimate", "se", "prior", "model")]))
        sigma = float(re.search(r"residual sigma ([0-9.e+-]+) N", report).group(1))
        self.assertEqual("%.6g" % r.sigma, "%.6g" % sigma)
        # Too few samples; a sample outside the workspace, named.
        with self.assertRaisesRegex(prru.InputError, "fewer than the"):
            MODEL.identify(mo.t[:3], mo.q[:3], mo.qd[:3], mo.qdd[:3], mo.fd[:3])
        q = [list(x) for x in mo.q]
        q[5] = [1.5, 1.5, q[5][2]]
        with self.assertRaisesRegex(prru.InputError, r"sample 6 \(t = 0.05\)"):
            MODEL.identify(mo.t, q, mo.qd, mo.qdd, mo.fd)
        # Forces of the wrong sign: no physical robot explains them.
        neg = [[-x for x in row] for row in mo.fd]
        with self.assertRaisesRegex(prru.Singular, "the data contradict physics") as cm:
            MODEL.identify(mo.t, mo.q, mo.qd, mo.qdd, neg)
        self.assertIsNone(cm.exception.result.text)
        with self.assertRaisesRegex(ValueError, "no model to write"):
            cm.exception.result.write(os.path.join(HERE, "never.json"))


class TestDesign(unittest.TestCase):
    """optimize against prru optimize: the same library optimiser, so the
    same design to the bit."""

    def test_optimize(self):
        grid = dict(q1=(-0.2, 0.2, 13), q2=(-0.25, 0.15, 11))
        d = MODEL.optimize(["l2", "b12"], range=5, max_iter=40, **grid)
        with tempfile.TemporaryDirectory() as tmp:
            out, rep = os.path.join(tmp, "o.json"), os.path.join(tmp, "rep")
            cli("optimize", "--vars", "l2,b12", "--range", "5", "--q1", "-0.2:0.2:13", "--q2", "-0.25:0.15:11",
                "--max-iter", "40", "--out", out, "--report", rep)
            theirs, report = json.loads(read(out)), read(os.path.join(rep, "report.txt"))
            d.write(os.path.join(tmp, "mine.json"))
            written = prru.Model(LIB, model=os.path.join(tmp, "mine.json"))
        mine = json.loads(d.text)
        self.assertEqual(mine["name"], theirs["name"])
        for key in ("gravity", "geometry", "bodies", "actuators"):
            self.assertEqual(mine[key], theirs[key], key)
        self.assertEqual(written.name, theirs["name"])
        for name, before, after, lo, hi in d.variables:
            row = re.search(r"^%s +(\S+) +(\S+) +(\S+) +(\S+)" % name, report, re.M)
            self.assertEqual(bits([before, after, lo, hi]), bits([float(x) for x in row.groups()]))
        after = float(re.search(r"^after_index: (\S+)", report, re.M).group(1))
        self.assertEqual(bits(d.best["index"]), bits(after))
        self.assertTrue(d.best["feasible"])
        # precision="float" is prru optimize --precision float, bit for bit.
        f = MODEL.optimize(["l2", "b12"], range=5, max_iter=40, precision="float", **grid)
        with tempfile.TemporaryDirectory() as tmp:
            rep = os.path.join(tmp, "rep")
            cli("optimize", "--vars", "l2,b12", "--range", "5", "--q1", "-0.2:0.2:13", "--q2", "-0.25:0.15:11",
                "--max-iter", "40", "--precision", "float", "--out", os.path.join(tmp, "o.json"), "--report", rep)
            report = read(os.path.join(rep, "report.txt"))
        self.assertIn("precision: float (", report)
        after = float(re.search(r"^after_index: (\S+)", report, re.M).group(1))
        self.assertEqual(bits(f.best["index"]), bits(after))
        with self.assertRaisesRegex(ValueError, "precision must be 'double' or 'float', got 'single'"):
            MODEL.optimize(["l2"], precision="single", **grid)
        with self.assertRaisesRegex(ValueError, r"vars\[0\]: "):
            MODEL.optimize(["no_such_thing"], **grid)
        with self.assertRaisesRegex(ValueError, "outside the bounds"):
            MODEL.optimize([("l2", 10.0, 11.0)], **grid)
        with self.assertRaisesRegex(ValueError, "objective must be one of mean, max, log"):
            MODEL.optimize(["l2"], objective="median", **grid)
        # Platform tilted by 80 degrees about both axes: beyond reach.
        with self.assertRaisesRegex(prru.InputError, "no grid point of the workspace is regular"):
            MODEL.optimize(["l2"], q1=(1.4, 1.5, 5), q2=(1.4, 1.5, 5))
        # A stroke no slider keeps: no feasible design; the best one comes along.
        with self.assertRaisesRegex(prru.NoConvergence, "no feasible design found") as cm:
            MODEL.optimize(["l2"], range=0.1, max_iter=5,
                           limits=MODEL.limits(model_limits=False, stroke=(50, 51)), **grid)
        self.assertIsNone(cm.exception.design.text)
        self.assertFalse(cm.exception.design.best["feasible"])


class TestRoundTrips(unittest.TestCase):
    def test_fk_of_ik(self):
        for q, _, _, _, _ in random_states(20, 3):
            d, _ = MODEL.ik(q)
            back = MODEL.fk(d)
            for a, b in zip(back, q):
                self.assertLessEqual(abs(a - b), 1e-12)

    def test_inverse_of_forward_dynamics(self):
        for q, qd, fd, fp, mp in random_states(20, 4):
            qdd = MODEL.forward_dynamics(q, qd, fd, fp, mp)
            if MODEL.npreload:
                n = MODEL.actuator_null(q)
                preload = sum(a * b for a, b in zip(fd, n))
                back = MODEL.inverse_dynamics(q, qd, qdd, fp, mp, preload=preload)
                fd0 = MODEL.inverse_dynamics(q, qd, qdd, fp, mp)
                self.assertLessEqual(abs(sum(a * b for a, b in zip(fd0, n))), 1e-9)
            else:
                back = MODEL.inverse_dynamics(q, qd, qdd, fp, mp)
            scale = max(abs(x) for x in fd)
            for a, b in zip(back, fd):
                self.assertLessEqual(abs(a - b), 1e-10 * scale)
            again = MODEL.forward_dynamics(q, qd, back, fp, mp)
            for a, b in zip(again, qdd):
                self.assertLessEqual(abs(a - b), 1e-10 * max(1.0, max(map(abs, qdd))))

    def test_equations_of_motion(self):
        """M qdd + h = G + J_d^T fd + passive from the separate dynamics,
        ik, passive and forward-dynamics calls (platform loads 0)."""
        for q, qd, fd, _, _ in random_states(10, 5):
            M, h, G = MODEL.dynamics(q, qd)
            _, Jd = MODEL.ik(q)
            p = MODEL.passive(q, qd)
            qdd = MODEL.forward_dynamics(q, qd, fd)
            for i in range(3):
                terms = ([M[i][j] * qdd[j] for j in range(3)] + [h[i], -G[i], -p[i]]
                         + [-Jd[k][i] * fd[k] for k in range(MODEL.nact)])
                self.assertLessEqual(abs(math.fsum(terms)), 1e-13 * max(map(abs, terms)))

    def test_first_sample_is_the_initial_state(self):
        q, qd, fd, _, _ = random_states(1, 6)[0]
        run = MODEL.simulate(q, qd, fd=fd, t_end=0.01, dt=0.005)
        T, V = MODEL.energy(q, qd)
        self.assertEqual(bits([run.T[0], run.V[0]]), bits([T, V]))
        self.assertEqual(bits(run.q[0]), bits(q))

    def test_power(self):
        """power() against the products of ik's J_d, platform_jacobian and
        passive summed exactly (fsum): the library's sums round each product
        through at most nact + 12 operations, these 3, so they differ by at
        most 2 gamma_(nact+12) times the sum of the products' magnitudes."""
        u = 2.0 ** -53
        gamma = (MODEL.nact + 12) * u / (1 - (MODEL.nact + 12) * u)
        for q, qd, fd, fp, mp in random_states(5, 11):
            load, passive = MODEL.power(q, qd, fd, fp, mp)
            _, Jd = MODEL.ik(q)
            JR, JT = MODEL.platform_jacobian(q)
            terms = ([fd[i] * Jd[i][k] * qd[k] for i in range(MODEL.nact) for k in range(3)]
                     + [fp[i] * JT[i][k] * qd[k] for i in range(3) for k in range(3)]
                     + [mp[i] * JR[i][k] * qd[k] for i in range(3) for k in range(3)])
            self.assertLessEqual(abs(load - math.fsum(terms)),
                                 2 * gamma * math.fsum(map(abs, terms)))
            pterms = [a * b for a, b in zip(MODEL.passive(q, qd), qd)]
            self.assertLessEqual(abs(passive - math.fsum(pterms)),
                                 2 * gamma * math.fsum(map(abs, pterms)))
            self.assertEqual(MODEL.power(q, qd)[0], 0.0)


class TestPoses(unittest.TestCase):
    def test_poses_energy_and_platform_jacobian(self):
        """Rotations orthonormal; V = -sum m_b g . p_b from the poses and the
        descriptor's masses and gravity equals energy()'s; the platform
        Jacobians against central differences of R_P and of O' = p_P -
        R_P com_P (the descriptor's centre of mass)."""
        m, h = MODEL, 1e-6
        P = m.platform
        for q, qd, _, _, _ in random_states(5, 10):
            R, p = m.poses(q)
            self.assertEqual((len(R), len(p)), (m.nbody, m.nbody))
            for Rb in R:
                for i in range(3):
                    for j in range(3):
                        dot = sum(Rb[k][i] * Rb[k][j] for k in range(3))
                        self.assertLessEqual(abs(dot - (i == j)), 1e-14)
            V = -math.fsum(m.mass[b] * m.gravity[k] * p[b][k]
                           for b in range(m.nbody) for k in range(3))
            self.assertLessEqual(abs(V - m.energy(q)[1]), 1e-13 * abs(V))

            def origin(qq):
                Rq, pq = m.poses(qq)
                return [pq[P][i] - sum(Rq[P][i][k] * m.com[P][k] for k in range(3))
                        for i in range(3)]
            qp = [a + h * b for a, b in zip(q, qd)]
            qm = [a - h * b for a, b in zip(q, qd)]
            Rp, Rm = m.poses(qp)[0][P], m.poses(qm)[0][P]
            dR = [[(Rp[i][j] - Rm[i][j]) / (2 * h) for j in range(3)] for i in range(3)]
            W = [[sum(dR[i][k] * R[P][j][k] for k in range(3)) for j in range(3)]
                 for i in range(3)]  # dR R^T, skew: omega's cross matrix
            omega = [W[2][1], W[0][2], W[1][0]]
            v = [(a - b) / (2 * h) for a, b in zip(origin(qp), origin(qm))]
            JR, JT = m.platform_jacobian(q)
            for i in range(3):
                self.assertLessEqual(abs(sum(JR[i][j] * qd[j] for j in range(3)) - omega[i]),
                                     1e-8)
                self.assertLessEqual(abs(sum(JT[i][j] * qd[j] for j in range(3)) - v[i]), 1e-8)


class TestThreads(unittest.TestCase):
    def test_one_model_shared_by_threads(self):
        """Calls from several threads on one Model (its workspace is locked
        per call) give the serial results."""
        import threading
        states = random_states(8, 11)
        serial = [MODEL.reactions(q, qd, fd, fp, mp) for q, qd, fd, fp, mp in states]
        results, errors_seen = {}, []

        def work(k):
            try:
                for r in range(1000):
                    i = (k + r) % len(states)
                    q, qd, fd, fp, mp = states[i]
                    lam = MODEL.reactions(q, qd, fd, fp, mp)
                    if bits(lam) != bits(serial[i]):
                        results[(k, r)] = (i, lam)
            except Exception as e:  # reported below, not lost in the thread
                errors_seen.append(e)
        threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertEqual(errors_seen, [])
        self.assertEqual(results, {}, "results that differ from the serial ones")


class TestSimulation(unittest.TestCase):
    def test_scenario_paper_fields(self):
        s = MODEL.paper_scenario()
        self.assertEqual(s.q0, (0.0, math.pi / 6, -0.8))
        self.assertEqual(s.fd[:3], (50.0, 40.0, 25.0))
        self.assertEqual(s.harmonic, (50.0, 4 * math.pi))
        self.assertEqual((s.t_end, s.dt, s.stepper), (1.0, 1e-3, "rk8pd"))

    def test_table_equals_constant_loads(self):
        q, qd, fd, fp, mp = random_states(1, 7)[0]
        fd = [x / 10 for x in fd]
        a = MODEL.simulate(q, qd, fd=fd, fp=fp, mp=mp, t_end=0.02, dt=0.005)
        rows = [[0.0] + fd + fp + mp, [1.0] + fd + fp + mp]
        b = MODEL.simulate(q, qd, table=rows, t_end=0.02, dt=0.005)
        self.assertEqual(bits(a.q), bits(b.q))
        self.assertEqual(bits(a.qdd), bits(b.qdd))
        self.assertIsNone(a.lambda_)

    def test_scenario_file_with_a_load_table(self):
        """A scenario file whose loads come from a CSV table: read here and
        simulated, against `prru simulate --scenario` on the same file."""
        q, qd, fd, fp, _ = random_states(1, 8)[0]
        n = MODEL.nact
        names = ["t"] + ["fd%d" % (i + 1) for i in range(n)] + ["fp1", "fp2", "fp3"]
        table = [[0.0] + fd + fp, [0.012] + [-x for x in fd] + fp, [0.02] + fd + [0.0] * 3]
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "s.scn")
            with open(os.path.join(tmp, "loads.csv"), "w") as f:
                f.write(",".join(names) + "\n")
                f.writelines(arg(row) + "\n" for row in table)
            with open(path, "w") as f:
                f.write("q0 = %s\nqd0 = %s\nloads = loads.csv\nt_end = 0.03\ndt = 0.01\n"
                        "stepper = rkf45\n" % (arg(q), arg(qd)))
            s = MODEL.read_scenario(path)
            self.assertEqual((s.t_end, s.dt, s.stepper), (0.03, 0.01, "rkf45"))
            self.assertEqual([list(r) for r in s.table], [r + [0.0] * 3 for r in table])
            run = MODEL.simulate(scenario=s)
            again = MODEL.simulate(q, qd, table=table, t_end=0.03, dt=0.01, stepper="rkf45")
            csv = os.path.join(tmp, "run.csv")
            cli("simulate", "--scenario", path, "--no-reactions", "--out", csv)
            lines = [l for l in read(csv).splitlines() if not l.startswith("#")]
            with open(path, "a") as f:
                f.write("bogus = 1\n")
            with self.assertRaises(prru.ParseError) as e:
                MODEL.read_scenario(path)
            self.assertIn("s.scn:7", str(e.exception))
            with self.assertRaises(prru.PrruIOError):
                MODEL.read_scenario(os.path.join(tmp, "missing.scn"))
        self.assertEqual(len(run), 4)
        self.assertEqual(len(lines), 5)
        for k, line in enumerate(lines[1:]):
            row = [float(x) for x in line.split(",")]
            self.assertEqual(bits(run.q[k]), bits(row[1:4]))
            self.assertEqual(bits(run.qd[k]), bits(row[4:7]))
        self.assertEqual(bits(again.q), bits(run.q))

    def test_on_sample_stops_and_sees_every_sample(self):
        seen = []
        run = MODEL.simulate(scenario="paper", t_end=0.1, dt=0.01,
                             on_sample=lambda s: seen.append(s) or s.t >= 0.05)
        self.assertTrue(run.stopped)
        self.assertEqual(len(run), 6)
        self.assertEqual([s.t for s in seen], run.t)
        self.assertEqual(list(seen[-1].q), run.q[-1])

    def test_callback_exception_propagates_with_samples(self):
        class Stop(Exception):
            pass

        def cb(s):
            if s.t > 0.015:
                raise Stop()
        with self.assertRaises(Stop) as e:
            MODEL.simulate(scenario="paper", t_end=0.1, dt=0.01, on_sample=cb)
        self.assertEqual(e.exception.trajectory.t, [0.0, 0.01, 0.02])

    def test_ctrl_c_stops_a_long_run(self):
        """SIGINT during a long run (sent once the first sample is out):
        KeyboardInterrupt carrying the samples computed so far, long
        before the end of the run."""
        code = ("import sys, prru\n"
                "m = prru.Model()\n"
                "def first(s):\n"
                "    if s.t == 0: print('running', flush=True)\n"
                "try:\n"
                "    m.simulate([0, 0, -0.8], t_end=300, dt=1e-3, on_sample=first)\n"
                "except KeyboardInterrupt as e:\n"
                "    print(len(e.trajectory), e.trajectory.t[-1])\n"
                "    sys.exit(3)\n")
        env = dict(os.environ, PRRU_LIB=LIB, PYTHONPATH=os.path.dirname(HERE))
        p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                             env=env)
        try:
            self.assertEqual(p.stdout.readline(), "running\n")
            time.sleep(0.1)
            p.send_signal(signal.SIGINT)
            out, _ = p.communicate(timeout=120)
        finally:
            p.kill()
            p.wait()
        self.assertEqual(p.returncode, 3)
        n, t = out.split()
        self.assertGreater(int(n), 0)
        self.assertLess(float(t), 300)

    def test_ctrl_c_inside_a_long_sample_interval(self):
        """SIGINT 0.3 s into a run whose first sample interval takes about
        100 s of integration (50000 s of a swaying robot, rkf45 at the
        tightest tolerance: ~2 ms per simulated second, unloaded) stops
        it at once: the library polls the flag inside every right-hand-side
        evaluation, and the waiting main thread sets it. KeyboardInterrupt
        carries the one sample delivered (t = 0). The 1 s bound leaves
        room for a loaded machine: the flag is seen within one evaluation
        (microseconds) of the main thread's handler, which runs within
        _interrupt.POLL_SECONDS (0.05 s) of the signal. Before the fix the
        run stopped only at the next sample, 50000 s of simulated time on."""
        code = ("import json, os, signal, sys, threading, time, prru\n"
                "m = prru.Model()\n"
                "q = [0.0, 0.0, -0.8]\n"
                "fd = m.inverse_dynamics(q, [0.0] * 3, [0.0] * 3)\n"
                "sent = []\n"
                "def send():\n"
                "    sent.append(time.monotonic())\n"
                "    os.kill(os.getpid(), signal.SIGINT)\n"
                "threading.Timer(0.3, send).start()\n"
                "try:\n"
                "    m.simulate(q, [1.0, 1.0, 0.0], fd=fd, t_end=1e5, dt=5e4,\n"
                "               stepper='rkf45', atol=3e-14, rtol=3e-14, max_steps=10**9)\n"
                "except KeyboardInterrupt as e:\n"
                "    print(json.dumps([time.monotonic() - sent[0], e.trajectory.t, e.t_stop]))\n"
                "    sys.exit(3)\n")
        env = dict(os.environ, PRRU_LIB=LIB, PYTHONPATH=os.path.dirname(HERE))
        p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                             env=env)
        try:
            out, _ = p.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            out = "still running 20 s after it started"
        finally:
            p.kill()
            p.wait()
        self.assertEqual(p.returncode, 3, out)
        waited, t, t_stop = json.loads(out)
        self.assertLess(waited, 1.0, out)
        self.assertEqual((t, t_stop), ([0.0], 0.0))

    def test_leaving_the_workspace_keeps_the_samples(self):
        f = [5000.0, -5000.0] + [0.0] * (MODEL.nact - 2)
        with self.assertRaises((prru.Singular, prru.Unreachable)) as e:
            MODEL.simulate([0, 0, -0.8], fd=f, t_end=1, dt=0.01)
        err = e.exception
        self.assertRegex(str(err), r"^simulate: stopped at t = ")
        self.assertGreater(len(err.trajectory), 0)
        self.assertEqual(err.t_stop, err.trajectory.t[-1])

    def test_bad_settings(self):
        with self.assertRaisesRegex(prru.InputError, "abs_tol = 1e-20 is below"):
            MODEL.simulate(atol=1e-20, t_end=0.01)
        with self.assertRaisesRegex(ValueError, "stepper"):
            MODEL.simulate(stepper="euler")
        with self.assertRaisesRegex(ValueError, "t_end"):
            MODEL.simulate(t_end=-1)
        with self.assertRaisesRegex(TypeError, "unknown setting"):
            MODEL.simulate(tend=1)
        with self.assertRaisesRegex(ValueError, r"table\[1\]: times must increase"):
            MODEL.simulate(table=[[0.0] + [1.0] * MODEL.nact, [0.0] + [1.0] * MODEL.nact])
        with self.assertRaisesRegex(ValueError, r"table\[0\] must have"):
            MODEL.simulate(table=[[0.0, 1.0]])


class TestErrors(unittest.TestCase):
    def test_unreachable_like_the_cli(self):
        q = [1.55, 0.0, 0.0]
        status, err = cli("ik", "--q", arg(q), ok=False)
        self.assertEqual(status, 1)
        text = MODEL.lib.status_text(prru.Unreachable.status)
        self.assertIn(text, err)
        for call in (MODEL.ik, MODEL.dynamics, MODEL.forward_dynamics, MODEL.check,
                     MODEL.dme, MODEL.poses, MODEL.energy, MODEL.power):
            with self.assertRaises(prru.Unreachable) as e:
                call(q)
            self.assertIn(text, str(e.exception))
            self.assertEqual(e.exception.status, 2)

    def test_singular(self):
        strict = prru.Model(MODEL.lib, jd_rcond_min=1.0)
        q = [0.0, 0.0, -0.8]
        with self.assertRaisesRegex(prru.Singular, "singular configuration"):
            strict.check(q)
        with self.assertRaises(prru.Singular):
            strict.dme(q)
        with self.assertRaises(prru.Singular):
            strict.inverse_dynamics(q, [0] * 3, [0] * 3)
        self.assertGreater(MODEL.check(q), 0)

    def test_no_convergence(self):
        d = [10.0, -10.0] + [0.0] * (MODEL.nact - 2)
        self.assertEqual(cli("fk", "--d", arg(d), ok=False)[0], 1)
        with self.assertRaisesRegex(prru.NoConvergence, "did not converge"):
            MODEL.fk(d)

    def test_input_errors(self):
        q = [0.0, 0.0, -0.8]
        if MODEL.npreload == 0:
            with self.assertRaises(prru.InputError):
                MODEL.inverse_dynamics(q, [0] * 3, [0] * 3, preload=1.0)
            with self.assertRaises(ValueError):  # InputError is a ValueError
                MODEL.actuator_null(q)
        if MODEL.nreaction_null == 0:
            with self.assertRaises(prru.InputError):
                MODEL.reaction_null(q)
        with self.assertRaisesRegex(prru.InputError, "invalid input"):
            MODEL.energy(q, [1e200, 0, 0])

    def assert_finite_or_raises(self, what, call):
        """call() raises a PrruError or returns only finite numbers."""
        try:
            out = call()
        except prru.PrruError:
            return
        numbers = flat([out] if isinstance(out, float) else out)
        self.assertTrue(all(map(math.isfinite, numbers)), "%s returned %r" % (what, out))

    def test_no_result_is_silently_non_finite(self):
        """A result that is not finite cannot be used: it is an error, never
        returned. dynamics with a huge qd (h overflows) raises InputError
        naming qd, as forward_dynamics does; and at the edge of the
        workspace, where check_reachable accepts q but J_d is not finite
        (a sqrt of the inverse kinematics at 0), the q-only calls raise
        Singular, as the library's forward dynamics does there."""
        q = [0.0, 0.2, -0.8]
        huge = [1e200, 0.0, 0.0]
        with self.assertRaisesRegex(prru.InputError, r"^dynamics: q = \(.*\), "
                                    r"qd = \(9.9999999999999997e\+199, 0, 0\): invalid input "
                                    r".*\(qd too large\)$"):
            MODEL.dynamics(q, huge)
        with self.assertRaisesRegex(prru.InputError, r"^forward_dynamics: q = \(.*\), "
                                    r"qd = \(9.9999999999999997e\+199, 0, 0\), .*invalid input"):
            MODEL.forward_dynamics(q, huge)
        # The last reachable q1 (bisection, q2 = 0, q3 = -0.8): the edge.
        lo, hi = 0.0, 1.55
        self.assertRaises(prru.Unreachable, MODEL.ik, [hi, 0.0, -0.8])
        while (lo + hi) / 2 not in (lo, hi):
            mid = (lo + hi) / 2
            try:
                MODEL.ik([mid, 0.0, -0.8])
                lo = mid
            except prru.Unreachable:
                hi = mid
            except prru.Singular:  # J_d not finite there
                lo = mid
        edge = [lo, 0.0, -0.8]
        z3, zn = [0.0] * 3, [0.0] * MODEL.nact
        states = [(q, huge, zn), (q, [0.0, 1e160, 0.0], zn), (edge, z3, zn),
                  (edge, [1.0, 1.0, 1.0], [1.0] * MODEL.nact), (q, z3, [1e307] * MODEL.nact)]
        for x, xd, fd in states:
            for what, call in (
                    ("check", lambda: MODEL.check(x)), ("ik", lambda: MODEL.ik(x)),
                    ("fk", lambda: MODEL.fk(MODEL.ik(x)[0])),
                    ("fk_lsq", lambda: MODEL.fk_lsq(MODEL.ik(x)[0])),
                    ("platform_jacobian", lambda: MODEL.platform_jacobian(x)),
                    ("poses", lambda: MODEL.poses(x)),
                    ("dynamics", lambda: MODEL.dynamics(x, xd)),
                    ("passive", lambda: MODEL.passive(x, xd)),
                    ("forward_dynamics", lambda: MODEL.forward_dynamics(x, xd, fd)),
                    ("inverse_dynamics", lambda: MODEL.inverse_dynamics(x, xd, xd)),
                    ("actuator_null", lambda: MODEL.actuator_null(x)),
                    ("reactions", lambda: MODEL.reactions(x, xd, fd)),
                    ("reaction_null", lambda: MODEL.reaction_null(x)),
                    ("energy", lambda: MODEL.energy(x, xd)),
                    ("dme", lambda: MODEL.dme(x)), ("w_R", lambda: MODEL.w_R(x))):
                with self.subTest(call=what, q=x, qd=xd):
                    self.assert_finite_or_raises(what, call)
        # A map's summary over no ok point: no number (None), not NaN.
        r = MODEL.map((1.55, 1.56, 2), (0.0, 0.01, 2), 0.0)
        self.assertEqual(r.summary["n_ok"], 0)
        for k in ("index", "index_log", "w_min", "w_max", "w_min_q", "w_max_q"):
            self.assertIsNone(r.summary[k], k)

    def test_argument_checks(self):
        with self.assertRaisesRegex(ValueError, "^q must have 3 elements, got 2$"):
            MODEL.ik([0, 0])
        with self.assertRaisesRegex(ValueError, r"^qd\[1\] must be finite, got nan$"):
            MODEL.dynamics([0, 0, -0.8], [0, float("nan"), 0])
        with self.assertRaisesRegex(ValueError, r"^fd must have %d elements" % MODEL.nact):
            MODEL.forward_dynamics([0, 0, -0.8], fd=[1.0] * (MODEL.nact + 1))
        with self.assertRaisesRegex(ValueError, r"^fp\[2\] must be finite, got inf$"):
            MODEL.reactions([0, 0, -0.8], fp=[0, 0, math.inf])
        with self.assertRaisesRegex(TypeError, "^q must be a sequence"):
            MODEL.ik("0,0,0")
        with self.assertRaisesRegex(TypeError, r"^q\[0\] must be a real number"):
            MODEL.ik([None, 0, 0])
        with self.assertRaisesRegex(ValueError, "preload must be finite"):
            MODEL.inverse_dynamics([0, 0, -0.8], [0] * 3, [0] * 3, preload=math.nan)
        with self.assertRaisesRegex(ValueError, "^d must have"):
            MODEL.fk([0.0] * (MODEL.nact - 1))
        with self.assertRaisesRegex(ValueError, "q1: start must be below stop"):
            MODEL.map((0.5, -0.5, 3), (0, 1, 3))
        with self.assertRaisesRegex(ValueError, "q2 count must be at least 2"):
            MODEL.map((-0.5, 0.5, 3), (0, 1, 1))

    def test_sequences_of_any_kind(self):
        import array
        q = [0.05, -0.1, -0.7]
        ref = MODEL.dynamics(q)
        self.assertEqual(MODEL.dynamics(tuple(q)), ref)
        self.assertEqual(MODEL.dynamics(array.array("d", q)), ref)

        class ArrayLike:  # what the binding reads of a NumPy array
            ndim = 1

            def __len__(self):
                return 3

            def tolist(self):
                return list(q)
        self.assertEqual(MODEL.dynamics(ArrayLike()), ref)
        with self.assertRaisesRegex(TypeError, "^q must be a sequence of 3 numbers, got generator"):
            MODEL.dynamics(x for x in q)

    def test_unordered_and_non_numeric_containers(self):
        """A dict gives its keys when read as a sequence and a set has no
        order: every vector argument of every method refuses them (and
        strings, bytes, dict views, iterators) with TypeError naming it."""
        n = MODEL.nact
        q, z3, zn = [0.0, 0.0, -0.8], [0.0] * 3, [0.0] * n
        d = MODEL.ik(q)[0]
        row = [0.0] + [1.0] * n
        calls = {  # name -> (good value, call with that argument replaced)
            "check q": (q, lambda v: MODEL.check(v)),
            "ik q": (q, lambda v: MODEL.ik(v)),
            "fk d": (d, lambda v: MODEL.fk(v)),
            "fk seed": (q, lambda v: MODEL.fk(d, seed=v)),
            "fk_lsq d": (d, lambda v: MODEL.fk_lsq(v)),
            "fk_lsq seed": (q, lambda v: MODEL.fk_lsq(d, v)),
            "platform_jacobian q": (q, lambda v: MODEL.platform_jacobian(v)),
            "poses q": (q, lambda v: MODEL.poses(v)),
            "dynamics q": (q, lambda v: MODEL.dynamics(v)),
            "dynamics qd": (z3, lambda v: MODEL.dynamics(q, v)),
            "passive q": (q, lambda v: MODEL.passive(v, z3)),
            "passive qd": (z3, lambda v: MODEL.passive(q, v)),
            "forward_dynamics q": (q, lambda v: MODEL.forward_dynamics(v)),
            "forward_dynamics qd": (z3, lambda v: MODEL.forward_dynamics(q, v)),
            "forward_dynamics fd": (zn, lambda v: MODEL.forward_dynamics(q, fd=v)),
            "forward_dynamics fp": (z3, lambda v: MODEL.forward_dynamics(q, fp=v)),
            "forward_dynamics mp": (z3, lambda v: MODEL.forward_dynamics(q, mp=v)),
            "inverse_dynamics q": (q, lambda v: MODEL.inverse_dynamics(v, z3, z3)),
            "inverse_dynamics qd": (z3, lambda v: MODEL.inverse_dynamics(q, v, z3)),
            "inverse_dynamics qdd": (z3, lambda v: MODEL.inverse_dynamics(q, z3, v)),
            "inverse_dynamics fp": (z3, lambda v: MODEL.inverse_dynamics(q, z3, z3, fp=v)),
            "inverse_dynamics mp": (z3, lambda v: MODEL.inverse_dynamics(q, z3, z3, mp=v)),
            "actuator_null q": (q, lambda v: MODEL.actuator_null(v)),
            "reactions q": (q, lambda v: MODEL.reactions(v)),
            "reactions qd": (z3, lambda v: MODEL.reactions(q, v)),
            "reactions fd": (zn, lambda v: MODEL.reactions(q, fd=v)),
            "reactions fp": (z3, lambda v: MODEL.reactions(q, fp=v)),
            "reactions mp": (z3, lambda v: MODEL.reactions(q, mp=v)),
            "reaction_null q": (q, lambda v: MODEL.reaction_null(v)),
            "energy q": (q, lambda v: MODEL.energy(v)),
            "energy qd": (z3, lambda v: MODEL.energy(q, v)),
            "dme q": (q, lambda v: MODEL.dme(v)),
            "w_R q": (q, lambda v: MODEL.w_R(v)),
            "simulate q0": (q, lambda v: MODEL.simulate(v, t_end=0.01)),
            "simulate qd0": (z3, lambda v: MODEL.simulate(q, v, t_end=0.01)),
            "simulate fd": (zn, lambda v: MODEL.simulate(q, fd=v, t_end=0.01)),
            "simulate fp": (z3, lambda v: MODEL.simulate(q, fp=v, t_end=0.01)),
            "simulate mp": (z3, lambda v: MODEL.simulate(q, mp=v, t_end=0.01)),
            "simulate harmonic": ([1.0, 2.0], lambda v: MODEL.simulate(q, harmonic=v,
                                                                        t_end=0.01)),
            "simulate table": ([tuple(row), tuple([1.0] + row[1:])],
                               lambda v: MODEL.simulate(q, table=v, t_end=0.01)),
            "simulate table[1]": ([1.0] + row[1:],
                                  lambda v: MODEL.simulate(q, table=[row, v], t_end=0.01)),
            "map q1": ([-0.1, 0.1, 2], lambda v: MODEL.map(v, (-0.1, 0.1, 2), -0.8)),
            "map q2": ([-0.1, 0.1, 2], lambda v: MODEL.map((-0.1, 0.1, 2), v, -0.8)),
        }
        for key, (good, call) in calls.items():
            name = key.split(" ", 1)[1]
            bad = {"dict": dict(enumerate(good)), "set": set(good),
                   "frozenset": frozenset(good), "dict_values": dict(enumerate(good)).values(),
                   "str": ",".join(map(str, good)), "bytes": b"\0" * len(good),
                   "list_iterator": iter(good)}
            for kind, value in bad.items():
                with self.subTest(call=key, given=kind):
                    with self.assertRaisesRegex(TypeError, r"^%s must be .*, got %s$"
                                                % (re.escape(name), kind)):
                        call(value)
        with self.assertRaisesRegex(TypeError, r"^q\[1\] must be a real number, got str$"):
            MODEL.ik([0.0, "0.1", -0.8])


class TestLibrarySearch(unittest.TestCase):
    def test_explicit_file_directory_and_env(self):
        build = os.path.dirname(os.path.dirname(os.path.abspath(LIB)))
        self.assertIs(prru.load_library(LIB), MODEL.lib)
        self.assertIs(prru.load_library(build), MODEL.lib)
        self.assertIs(prru.Model().lib, MODEL.lib)  # via $PRRU_LIB

    def test_not_found_names_what_was_tried(self):
        missing = os.path.join(tempfile.gettempdir(), "no-such-dir-prru", "libprru.so")
        with self.assertRaises(prru.LibraryNotFound) as e:
            prru.Model(missing)
        self.assertIn(missing + " (argument): no such file", str(e.exception))
        self.assertIsInstance(e.exception, OSError)
        env = dict(os.environ, PRRU_LIB=missing, PYTHONPATH=os.path.dirname(HERE))
        p = subprocess.run([sys.executable, "-c", "import prru; prru.Model()"],
                           capture_output=True, text=True, env=env)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(missing + " ($PRRU_LIB): no such file", p.stderr)
        self.assertIn("LibraryNotFound", p.stderr)

    def test_not_a_prru_library(self):
        import _ctypes  # a shared object that is not prru's
        if not getattr(_ctypes, "__file__", None):
            self.skipTest("_ctypes is built into this Python")
        with self.assertRaisesRegex(prru.LibraryNotFound, "not a prru library"):
            prru.load_library(_ctypes.__file__)


def c_struct_fields(text, name):
    """(field, element type, element count) of `typedef struct {...} name;`."""
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    m = re.search(r"typedef struct \{([^{}]*)\} %s;" % name, text)
    if not m:
        raise AssertionError("struct %s not found" % name)
    body = m.group(1)
    out = []
    for decl in body.split(";"):
        decl = " ".join(decl.split())
        if not decl:
            continue
        if "(" in decl:  # a function pointer: prru_sample_fn etc. are typedefs here
            raise AssertionError("unexpected declaration %r" % decl)
        first = re.match(r"((?:(?:const|volatile|unsigned)\s+)*[A-Za-z_]\w*)\s*(.*)$", decl)
        ctype, rest = first.group(1), first.group(2)
        for part in rest.split(","):
            part = part.strip()
            ptr = part.startswith("*")
            fname = re.match(r"\**\s*([A-Za-z_][A-Za-z_0-9]*)", part).group(1)
            dims = re.findall(r"\[([^\]]+)\]", part)
            out.append((fname, ctype + (" *" if ptr else ""), dims))
    return out


class TestLayout(unittest.TestCase):
    """The ctypes mirror against the C headers, field by field: names in
    order, element sizes and counts (array sizes evaluated with this
    model's sizes)."""

    def sizes(self):
        m = MODEL
        return {"PRRU_NACT": m.nact, "PRRU_NBODY": m.nbody, "PRRU_NLIMB": m.nlimb,
                "PRRU_NREG": 10 * m.nbody + 3 * m.nact, "PRRU_EXCITE_MAX_HARMONICS": 8,
                "PRRU_MAX_ACT": 4, "PRRU_MAX_LIMB": 4, "PRRU_MAX_BODY": 13, "PRRU_MAX_JOINT": 16,
                "PRRU_MAX_LAMBDA": 76, "PRRU_MAX_REG": 142,
                "PRRU_DESIGN_MAX_TIE": 13, "PRRU_DESIGN_MAX_VARS": 64,
                "PRRU_NLAMBDA": m.nlambda, "PRRU_NJOINT": m.njoint, "PRRU_NH": 6 * m.nbody,
                "PRRU_NQ": 3,
                # generated/'s descriptor carries the paper model's name
                "PAPER3PRRU_NACT": m.nact, "PAPER3PRRU_NBODY": m.nbody,
                "PAPER3PRRU_NLIMB": m.nlimb, "PAPER3PRRU_NJOINT": m.njoint,
                "PAPER3PRRU_NLAMBDA": m.nlambda}

    def check(self, header, cname, pytype):
        text = read(os.path.join(SOURCE_DIR, header))
        cfields = c_struct_fields(text, cname)
        pyfields = pytype._fields_
        self.assertEqual([f for f, _, _ in cfields],
                         [("lambda" if f == "lambda_" else f) for f, _ in pyfields],
                         "%s: field names" % cname)
        env = self.sizes()
        csize = {"double": 8, "int": 4, "long": 8, "char": 1, "const char *": 8, "unsigned long": 8,
                 "size_t": 8, "prru_objective": 4,
                 "unsigned char": 1, "prru_stepper": 4, "prru_load_kind": 4}  # enums: int
        for (fname, ctype, dims), (_, pyt) in zip(cfields, pyfields):
            count = 1
            for d in dims:
                count *= eval(d, {"__builtins__": {}}, env)
            elem = pyt
            while issubclass(elem, ctypes.Array):
                elem = elem._type_
            n = ctypes.sizeof(pyt) // ctypes.sizeof(elem)
            self.assertEqual(n, count, "%s.%s: element count" % (cname, fname))
            base = ctype.replace("volatile ", "")
            if base in csize:
                self.assertEqual(ctypes.sizeof(elem), csize[base], "%s.%s: type" % (cname, fname))
            elif base.endswith("*") or base.endswith("_fn"):
                self.assertEqual(ctypes.sizeof(elem), 8, "%s.%s: pointer" % (cname, fname))

    def test_headers(self):
        t = MODEL.lib.types
        for header, cname, pytype in (
                ("runtime/include/prru_dynamics.h", "prru_model", _lib._Model),
                ("runtime/include/prru_dynamics.h", "prru_loads", t.Loads),
                ("runtime/include/prru_dynamics.h", "prru_data", t.Data),
                ("runtime/include/prru_sim.h", "prru_load_schedule", t.Schedule),
                ("runtime/include/prru_sim.h", "prru_sample", t.Sample),
                ("runtime/include/prru_sim.h", "prru_sim_options", t.SimOptions),
                ("runtime/include/prru_sim.h", "prru_scenario", t.Scenario),
                ("runtime/include/prru_dme.h", "prru_dme", t.Dme),
                ("runtime/include/prru_dme.h", "prru_map_grid", _lib._MapGrid),
                ("runtime/include/prru_dme.h", "prru_map_summary", _lib._MapSummary),
                ("runtime/include/prru_dme.h", "prru_map_options", _lib._MapOptions),
                ("runtime/include/prru_descriptor.h", "prru_joint_info", _lib._JointInfo),
                ("runtime/include/prru_descriptor.h", "prru_mechanism", t.Mechanism),
                ("runtime/include/prru_dynamics.h", "prru_limits", t.Limits),
                ("runtime/include/prru_traj.h", "prru_quintic", _lib._Quintic),
                ("runtime/include/prru_traj.h", "prru_topp", _lib._Topp),
                ("runtime/include/prru_traj.h", "prru_path_side", _lib._PathSide),
                ("runtime/include/prru_descriptor.h", "prru_params", t.Params),
                ("runtime/include/prru_control.h", "prru_track_sample", t.TrackSample),
                ("runtime/include/prru_control.h", "prru_track_options", t.TrackOptions),
                ("runtime/include/prru_control.h", "prru_track_summary", t.TrackSummary),
                ("runtime/include/prru_ident.h", "prru_base", t.Base),
                ("runtime/include/prru_ident.h", "prru_ident_result", t.IdentResult),
                ("runtime/include/prru_ident.h", "prru_consistent_options", _lib._ConsistentOptions),
                ("runtime/include/prru_ident.h", "prru_consistent_result", t.ConsistentResult),
                ("runtime/include/prru_ident.h", "prru_identification", t.Identification),
                ("runtime/include/prru_ident.h", "prru_fourier", _lib._Fourier),
                ("runtime/include/prru_ident.h", "prru_excite_options", t.ExciteOptions),
                ("runtime/include/prru_ident.h", "prru_excite_result", t.ExciteResult),
                ("runtime/include/prru_design.h", "prru_design_var", t.DesignVar),
                ("runtime/include/prru_design.h", "prru_design_problem", _lib._DesignProblem),
                ("runtime/include/prru_design.h", "prru_design_eval", t.DesignEval),
                ("runtime/include/prru_design.h", "prru_design_options", t.DesignOptions),
                ("runtime/include/prru_design.h", "prru_design_result", t.DesignResult)):
            with self.subTest(struct=cname):
                self.check(header, cname, pytype)

    def test_samples_are_rows_of_doubles(self):
        t = MODEL.lib.types
        self.assertEqual(ctypes.sizeof(t.Sample), 8 * t.sample_width)

    def test_self_check_detects_a_wrong_mirror(self):
        """A mirror with one field too many, or an array one entry short,
        fails the load-time check against the library's own sizeof."""
        def widened(fields):
            return fields + [("extra", ctypes.c_double)]

        def shortened(fields):
            (name, t), rest = fields[0], fields[1:]
            return [(name, t._type_ * (t._length_ - 1))] + rest

        for change in (widened, shortened):
            class Shifted(_lib.Library):
                def __init__(self, path):
                    self.path = path
                    self.dll = ctypes.CDLL(path)
                    head = _lib._MechHead.in_dll(self.dll, "prru_mech")
                    self.types = _lib.Types(head.nact, head.nbody, head.nlimb, head.nlambda,
                                            head.njoint)
                    t = self.types
                    t.Loads = type("prru_loads", (ctypes.Structure,), {"_fields_": change(t.Loads._fields_)})
                    self._check_struct_sizes()
            with self.subTest(change=change.__name__), self.assertRaises(prru.LayoutError):
                Shifted(LIB)

    def test_public_types_follow_the_generated(self):
        """The library's prru_mechanism, prru_joint_info and prru_params
        (prru_descriptor.h, arrays of the maxima) have the fields of the
        generator's (a drop-in descriptor of any model, sized for it; the
        4-limb topology kernels' prru_params4) in the same order and types,
        and sized for the largest model the same."""
        maxima = {"PAPER3PRRU_NACT": 4, "PAPER3PRRU_NLIMB": 4, "PAPER3PRRU_NBODY": 13,
                  "PAPER3PRRU_NJOINT": 16, "PAPER3PRRU_NLAMBDA": 76, "PRRU_MAX_ACT": 4,
                  "PRRU_MAX_LIMB": 4, "PRRU_MAX_BODY": 13, "PRRU_MAX_JOINT": 16,
                  "PRRU_MAX_LAMBDA": 76}

        def fields(header, name, rename=()):
            out = []
            for f, t, dims in c_struct_fields(read(os.path.join(SOURCE_DIR, header)), name):
                for a, b in rename:
                    t = t.replace(a, b)
                out.append((f, t, [eval(d, {"__builtins__": {}}, maxima) for d in dims]))
            return out
        public = "runtime/include/prru_descriptor.h"
        gen = ("generated/paper3prru_mechanism.h", [("paper3prru_", "prru_")])
        self.assertEqual(fields(public, "prru_joint_info"), fields(gen[0], "paper3prru_joint_info", gen[1]))
        self.assertEqual(fields(public, "prru_mechanism"), fields(gen[0], "paper3prru_mechanism", gen[1]))
        self.assertEqual(fields(public, "prru_params"), fields("generated/prru_p4_kernels.h", "prru_params4"))

    def test_layout_is_the_same_for_every_model(self):
        """The structs are sized by the maxima of prru_sizes.h, not by the
        model: the mirror built for any descriptor sizes is the same."""
        a = _lib.Types(3, 10, 3, 57, 12)
        b = _lib.Types(4, 13, 4, 76, 16)
        for name in ("Mechanism", "Params", "Loads", "Data", "Sample", "Limits", "Dme", "Linearization",
                     "TrackSample", "TrackOptions", "TrackSummary", "Base", "IdentResult", "ExciteOptions",
                     "DesignVar", "DesignResult"):
            self.assertEqual(ctypes.sizeof(getattr(a, name)), ctypes.sizeof(getattr(b, name)), name)


@unittest.skipIf(numpy is None, "NumPy is not installed (the list path is tested)")
class TestNumpy(unittest.TestCase):
    def test_arrays_in_and_out(self):
        mn = prru.Model(MODEL.lib, numpy=True)
        for q, qd, fd, fp, mp in random_states(3, 9):
            qa, qda, fda = numpy.array(q), numpy.array(qd), numpy.array(fd)
            M, h, G = mn.dynamics(qa, qda)
            self.assertEqual(M.shape, (3, 3))
            self.assertEqual(bits(M.tolist()), bits(MODEL.dynamics(q, qd)[0]))
            d, Jd = mn.ik(qa)
            self.assertEqual(Jd.shape, (MODEL.nact, 3))
            self.assertEqual(bits(mn.forward_dynamics(qa, qda, fda).tolist()),
                             bits(MODEL.forward_dynamics(q, qd, fd)))
            self.assertEqual(bits(MODEL.forward_dynamics(qa, qda, fda)),
                             bits(MODEL.forward_dynamics(q, qd, fd)))
        run = mn.simulate(scenario="paper", t_end=0.01, reactions=True)
        ref = MODEL.simulate(scenario="paper", t_end=0.01, reactions=True)
        self.assertEqual(run.q.shape, (11, 3))
        self.assertEqual(run.lambda_.shape, (11, MODEL.nlambda))
        self.assertEqual(run.t.shape, (11,))
        self.assertEqual(bits(run.q.tolist()), bits(ref.q))
        self.assertEqual(bits(run.T.tolist()), bits(ref.T))
        with self.assertRaisesRegex(ValueError, r"shape \(3, 1\)"):
            MODEL.ik(numpy.zeros((3, 1)))
        r = mn.map((-0.2, 0.2, 3), (-0.2, 0.2, 4))
        self.assertEqual(r.w_R.shape, (3, 4))
        # A load table as a 2-D array (its rows in order), like a list of rows.
        fd = MODEL.inverse_dynamics([0, 0, -0.8], [0] * 3, [0] * 3)
        rows = [[0.0] + list(fd), [0.01] + list(fd)]
        self.assertEqual(bits(mn.simulate([0, 0, -0.8], table=numpy.array(rows),
                                          t_end=0.01).q.tolist()),
                         bits(MODEL.simulate([0, 0, -0.8], table=rows, t_end=0.01).q))


class TestWithoutNumpy(unittest.TestCase):
    def test_numpy_output_needs_numpy(self):
        """With NumPy unimportable (blocked in a child process if installed):
        plain lists, and numpy=True refused with the reason."""
        code = ("import sys; sys.modules['numpy'] = None\n"
                "import prru\n"
                "m = prru.Model()\n"
                "M, h, G = m.dynamics([0, 0, -0.8])\n"
                "assert type(M) is list and type(M[0]) is list and type(h) is list\n"
                "assert type(m.simulate(t_end=0.002, q0=[0, 0, -0.8]).q) is list\n"
                "prru.Model(numpy=True)\n")
        env = dict(os.environ, PRRU_LIB=LIB, PYTHONPATH=os.path.dirname(HERE))
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("ImportError: numpy=True needs NumPy, which is not installed", p.stderr)


if __name__ == "__main__":
    unittest.main()
