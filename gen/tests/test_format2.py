"""Format-2 model files: the loader, the derived dynamics of a model with
every new feature (models/prototype_example.json: per-limb geometry, tilted
gravity, centres of mass, products of inertia, drives), format-1 files
against their format-2 transcription, and determinism within one process.

The derived quantities are checked numerically against definitions they
were not built from: M against the Hessian of the kinetic energy, h against
the Christoffel symbols of M, G against -dV/dq by finite differences, the
passive force against J_d^T (-c dd - f tanh(dd / v_s)).
"""

import json
import math
import os
import random
import tempfile
import unittest
from fractions import Fraction

from prrugen import dynamics, mechanism, model, sym

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
PAPER = os.path.join(ROOT, "models", "3prru_paper.json")
PROTO = os.path.join(ROOT, "models", "prototype_example.json")

import prru_gen  # noqa: E402  (gen/ is on the path: tests run from gen/)
from tests.test_generator import OUTPUT_FILES  # noqa: E402


def _load_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def _derive(path):
    sym.reset()
    m = model.load(path)
    return m, dynamics.Derivation(mechanism.build(m), m)


def _states(n, seed):
    rng = random.Random(seed)
    for _ in range(n):
        yield {"q1": rng.uniform(-0.3, 0.3), "q2": rng.uniform(-0.4, 0.3),
               "q3": rng.uniform(-1.0, -0.5), "qd1": rng.uniform(-1, 1),
               "qd2": rng.uniform(-1, 1), "qd3": rng.uniform(-1, 1)}


def _paper_as_format2():
    """The paper's model written in format 2 (same numbers)."""
    m = _load_json(PAPER)
    g = m["geometry"]
    m["format"] = 2
    m["gravity"] = [0, 0, -9.81]
    m["geometry"] = {"b": [g["b12"], g["b12"], g["b3"]], "l1": g["l1"],
                     "l2": [g["l2"]] * 3, "a": [g["a"], g["a"]]}
    for body in m["bodies"].values():
        body["com"] = [0, 0, 0]
        i = body["inertia"]
        body["inertia"] = [i[0], i[1], i[2], 0, 0, 0]
    m["actuators"] = {"armature": 0, "damping": [0, 0, 0], "coulomb": 0}
    return m


class Loader(unittest.TestCase):
    def test_prototype_model_is_normalized(self):
        m = model.load(PROTO)
        self.assertEqual(m.format, 2)
        self.assertEqual(m.gravity, (Fraction("0.12"), Fraction("-0.07"),
                                     Fraction("-9.806")))
        self.assertEqual([float(l.b) for l in m.limbs], [0.358, 0.3625, 0.3171])
        self.assertEqual(m.limbs[2].a, 0)
        self.assertEqual(len(m.inertias[0]), 6)
        self.assertTrue(m.has_drives and m.has_passive)
        self.assertEqual(m.coulomb_velocity, Fraction("0.004"))

    def test_format1_defaults(self):
        m = model.load(PAPER)
        self.assertEqual(m.format, 1)
        self.assertEqual(m.gravity, (0, 0, Fraction("-9.81")))
        self.assertFalse(m.has_drives)
        self.assertTrue(all(c == (0, 0, 0) for c in m.coms))
        self.assertTrue(all(i[3:] == (0, 0, 0) for i in m.inertias))

    def bad(self, edit, key, reason):
        m = _load_json(PROTO)
        edit(m)
        with self.assertRaises(model.ModelError) as ctx:
            model.parse(json.dumps(m), "p.json")
        msg = str(ctx.exception)
        self.assertTrue(msg.startswith("p.json: "), msg)
        if key:
            self.assertIn(key + ":", msg)
        self.assertIn(reason, msg)
        self.assertNotIn("\n", msg)
        return msg

    def test_rejections(self):
        body = lambda b, k, v: lambda m: m["bodies"][b].__setitem__(k, v)  # noqa: E731
        geo = lambda k, v: lambda m: m["geometry"].__setitem__(k, v)  # noqa: E731
        act = lambda k, v: lambda m: m["actuators"].__setitem__(k, v)  # noqa: E731
        cases = [
            (lambda m: m.__setitem__("format", 3), "format", "must be 1 or 2"),
            (lambda m: m.__setitem__("format", True), "format", "must be 1 or 2"),
            (geo("b", 0.36), "geometry.b", "list of 3 rail offsets"),
            (geo("b", [0.36, 0.36]), "geometry.b", "list of 3"),
            (geo("l1", [0.23, 0.23]), "geometry.l1", "list of 3"),
            (geo("l2", [0.225, -0.2, 0.225]), "geometry.l2[1]", "positive"),
            (geo("a", [0.045, 0.045, 0.0]), "geometry.a", "list of 2"),
            (geo("b", [0.36, 0.9, 0.315]), "geometry", "limb 2 cannot be assembled"),
            (lambda m: m.__setitem__("gravity", [0, -9.81]), "gravity", "3 numbers"),
            (lambda m: m.__setitem__("gravity", [0, "x", -9.81]), "gravity[1]",
             "must be a number"),
            (body("P", "com", [0, 0]), "bodies.P.com", "3 numbers"),
            (body("L1", "inertia", [1e-3, 1e-3, 1e-3, 2e-3, 0, 0]),
             "bodies.L1.inertia", "not positive definite"),
            # PD, but principal moments (0.1, 0.1, 0.3) break the triangle
            # inequality: no mass distribution has them.
            (body("U1", "inertia", [0.1, 0.1, 0.3, 0, 0, 0]),
             "bodies.U1.inertia", "triangle"),
            (body("U2", "inertia", [1, 2, 3, 4, 5]), "bodies.U2.inertia",
             "6 tensor entries"),
            (act("damping", [1, -2, 3]), "actuators.damping[1]", "must not be negative"),
            (act("armature", [1, 2]), "actuators.armature", "list of 3"),
            (lambda m: m["actuators"].pop("coulomb_velocity"),
             "actuators.coulomb_velocity", "missing"),
            (act("coulomb_velocity", 0), "actuators.coulomb_velocity", "positive"),
            (act("stiction", 1), "actuators.stiction", "unknown key"),
            (body("S1", "density", 1), "bodies.S1.density", "unknown key"),
        ]
        for edit, key, reason in cases:
            with self.subTest(key=key, reason=reason):
                self.bad(edit, key, reason)

    def test_format1_keeps_its_rules(self):
        m = _load_json(PAPER)
        m["bodies"]["P"]["com"] = [0, 0, 0]
        with self.assertRaises(model.ModelError) as ctx:
            model.parse(json.dumps(m), "p.json")
        self.assertIn("bodies.P.com: unknown key", str(ctx.exception))

    def test_unknown_key_is_escaped_and_truncated(self):
        msg = self.bad(lambda m: m["geometry"].__setitem__(
            "\x1b[31m" + "k" * 500000, 1), None, "unknown key")
        self.assertLess(len(msg), 300)
        self.assertNotIn("\x1b", msg)
        self.assertIn("\\x1b", msg)


class PrototypeDynamics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model, cls.deriv = _derive(PROTO)
        cls.m, cls.h, cls.g = cls.deriv.mass(), cls.deriv.bias(), \
            cls.deriv.gravity_force()
        cls.t, cls.v = cls.deriv.kinetic(), cls.deriv.potential()
        cls.passive = cls.deriv.passive()
        cls.jd = cls.deriv.actuator_jacobian()

    def ev(self, exprs, env):
        return sym.evaluate(exprs, env)

    def test_mass_is_the_hessian_of_the_kinetic_energy(self):
        # T is quadratic in qd: T(e_i + e_j) - T(e_i) - T(e_j) = M_ij.
        for env in _states(5, 1):
            m = self.ev(self.m, env)
            def t_at(v):
                e = dict(env, qd1=v[0], qd2=v[1], qd3=v[2])
                return self.ev([self.t], e)[0]
            for i in range(3):
                for j in range(3):
                    ei = [float(k == i) for k in range(3)]
                    ej = [float(k == j) for k in range(3)]
                    both = [a + b for a, b in zip(ei, ej)]
                    mij = t_at(both) - t_at(ei) - t_at(ej) if i != j \
                        else 2 * t_at(ei)
                    self.assertAlmostEqual(m[3 * i + j], mij, delta=1e-12)

    def test_bias_matches_christoffel_symbols(self):
        h = 1e-6
        for env in _states(5, 2):
            qd = [env["qd1"], env["qd2"], env["qd3"]]
            dm = []
            for k in range(3):
                hi = dict(env, **{"q%d" % (k + 1): env["q%d" % (k + 1)] + h})
                lo = dict(env, **{"q%d" % (k + 1): env["q%d" % (k + 1)] - h})
                dm.append([(a - b) / (2 * h) for a, b in
                           zip(self.ev(self.m, hi), self.ev(self.m, lo))])
            got = self.ev(self.h, env)
            for i in range(3):
                want = sum((dm[k][3 * i + j] - 0.5 * dm[i][3 * j + k])
                           * qd[j] * qd[k] for j in range(3) for k in range(3))
                self.assertAlmostEqual(got[i], want, delta=1e-7)

    def test_gravity_is_minus_the_gradient_of_the_potential(self):
        h = 1e-6
        for env in _states(5, 3):
            got = self.ev(self.g, env)
            for k in range(3):
                key = "q%d" % (k + 1)
                vp = self.ev([self.v], dict(env, **{key: env[key] + h}))[0]
                vm = self.ev([self.v], dict(env, **{key: env[key] - h}))[0]
                self.assertAlmostEqual(got[k], -(vp - vm) / (2 * h), delta=1e-6)

    def test_potential_uses_the_gravity_vector_and_the_centres(self):
        env = next(_states(1, 4))
        _, ps = self.deriv.poses()
        p = self.ev(ps, env)
        g = [float(x) for x in self.model.gravity]
        want = -sum(float(m) * sum(g[k] * p[3 * b + k] for k in range(3))
                    for b, m in enumerate(self.model.masses))
        self.assertAlmostEqual(self.ev([self.v], env)[0], want, delta=1e-12)

    def test_passive_force_is_the_drives_law(self):
        vs = float(self.model.coulomb_velocity)
        for env in _states(5, 5):
            jd = self.ev(self.jd, env)
            qd = [env["qd1"], env["qd2"], env["qd3"]]
            forces = []
            for i in range(3):
                dd = sum(jd[3 * i + j] * qd[j] for j in range(3))
                forces.append(-float(self.model.damping[i]) * dd
                              - float(self.model.coulomb[i]) * math.tanh(dd / vs))
            want = [sum(jd[3 * i + j] * forces[i] for i in range(3))
                    for j in range(3)]
            for a, b in zip(self.ev(self.passive, env), want):
                self.assertAlmostEqual(a, b, delta=1e-12)

    def test_centre_of_mass_offsets(self):
        env = next(_states(1, 6))
        rs, ps = self.deriv.poses()
        r, p = self.ev(rs, env), self.ev(ps, env)
        for b, body in enumerate(self.deriv.mech.bodies):
            origin = self.ev(body.origin, env)
            com = [float(x) for x in self.model.coms[b]]
            for i in range(3):
                want = origin[i] + sum(r[9 * b + 3 * i + k] * com[k]
                                       for k in range(3))
                self.assertAlmostEqual(p[3 * b + i], want, delta=1e-15)

    def test_loops_close_with_per_limb_lengths(self):
        joints = {j.name: j for j in self.deriv.mech.joints}
        for env in _states(5, 7):
            for i, limb in enumerate(self.model.limbs):
                a = self.ev(joints["A%d" % (i + 1)].centre, env)
                b = self.ev(joints["B%d" % (i + 1)].centre, env)
                c = self.ev(joints["C%d" % (i + 1)].centre, env)
                self.assertAlmostEqual(math.dist(a, b), float(limb.l1), places=12)
                self.assertAlmostEqual(math.dist(b, c), float(limb.l2), places=12)


class FormatTranscription(unittest.TestCase):
    def test_format2_transcription_gives_the_same_kernels(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "paper2.json")
            with open(path, "w") as f:
                json.dump(_paper_as_format2(), f)
            one, _ = prru_gen.generate(PAPER)
            two, _ = prru_gen.generate(path)
        self.assertEqual(sorted(one), sorted(two))
        for name in one:
            # Everything after the banner (which names the file and its
            # hash) is identical, apart from the descriptor's identity.
            a = one[name].split(" */\n", 1)[1]
            b = two[name].split(" */\n", 1)[1]
            if name.endswith("mechanism.c"):
                for key in ("model_file", "sha256", "format"):
                    a = "\n".join(l for l in a.splitlines() if "PRRU_DESIGNATE(%s)" % key not in l)
                    b = "\n".join(l for l in b.splitlines() if "PRRU_DESIGNATE(%s)" % key not in l)
            self.assertEqual(a, b, name)


DRIVES = os.path.join(ROOT, "models", "prototype_drives.json")


class Drives(unittest.TestCase):
    """Spec 13 (models/prototype_drives.json): the rotor inertia enters the
    kernels as the armature J_r (2 pi gear / lead)^2 would, and the
    descriptor carries the drives and the limits in rail units. Tolerance
    of the conversions: the generator's and these formulas are each a few
    correctly rounded operations on the same doubles: 8 u."""

    def test_rotor_inertia_is_the_reflected_armature(self):
        m = model.load(DRIVES)
        spec = json.load(open(DRIVES))
        acts = spec["actuators"]
        u = 2.0 ** -53
        k = []
        for i, J in enumerate(acts["rotor_inertia"]):
            k.append(float(m.armature[i]))
            want = J * (2 * math.pi * acts["gear"] / acts["lead"]) ** 2
            self.assertLessEqual(abs(k[-1] - want), 8 * u * want)
        del acts["rotor_inertia"], acts["lead"], acts["gear"], acts["torque_constant"]
        del acts["torque_max"], acts["motor_speed_max"]
        acts["armature"] = k
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "proto_drives.json")
            with open(path, "w") as f:
                json.dump(spec, f)
            one, _ = prru_gen.generate(DRIVES)
            two, _ = prru_gen.generate(path)
        for name in one:
            if not name.endswith("mechanism.c"):
                self.assertEqual(one[name].split(" */\n", 1)[1], two[name].split(" */\n", 1)[1], name)
        text = one["proto_drives_mechanism.c"]

        def field(key):
            line = next(l for l in text.splitlines() if "PRRU_DESIGNATE(%s)" % key in l)
            return line.split(")", 1)[1].strip().rstrip(",")

        force = [float(x) for x in field("force_max").strip("{}").split(",")]
        for f in force:
            want = 0.64 * 2 * math.pi / 0.02
            self.assertLessEqual(abs(f - want), 8 * u * want)
        self.assertEqual(field("speed_max"), "{1.0, 1.0, 1.0}")
        self.assertEqual(field("d_min"), "{-0.05, -0.05, -0.05}")
        self.assertEqual(field("d_max"), "{0.45, 0.45, 0.45}")
        self.assertEqual(field("lead"), "{0.02, 0.02, 0.02}")
        self.assertEqual(field("drive_keys"), "%du" % (1 | 2 | 4 | 8 | 16 | 64 | 256))
        none = two["proto_drives_mechanism.c"]
        self.assertIn("PRRU_DESIGNATE(force_max) {HUGE_VAL, HUGE_VAL, HUGE_VAL}", none)
        self.assertIn("PRRU_DESIGNATE(lead) {0.0, 0.0, 0.0}", none)


class Determinism(unittest.TestCase):
    def test_output_does_not_depend_on_what_the_process_built_before(self):
        first, _ = prru_gen.generate(PROTO)
        prru_gen.generate(PAPER)
        again, _ = prru_gen.generate(PROTO)
        self.assertEqual(first, again)
        paper, _ = prru_gen.generate(PAPER)
        prru_gen.generate(PROTO)
        self.assertEqual(paper, prru_gen.generate(PAPER)[0])

    def test_prefix_option(self):
        files, _ = prru_gen.generate(PROTO, prefix="prru")
        self.assertEqual(sorted(files), [f.replace("paper3prru_", "prru_") for f in OUTPUT_FILES])
        self.assertIn('PRRU_DESIGNATE(name) "proto"', files["prru_mechanism.c"])
        own, _ = prru_gen.generate(PROTO)
        self.assertIn("void proto_dynamics(", own["proto_kernels.c"])


if __name__ == "__main__":
    unittest.main()


FOUR = os.path.join(ROOT, "models", "4prru.json")


class FourLimbs(unittest.TestCase):
    """The redundant 4-PRRU (spec section 12): limb 4 is limb 3 mirrored in
    the plane x = 0, so for models/4prru.json (b4 = b3, equal links)
    d_4(q1, q2, q3) = d_3(q1, -q2, q3); and the height q3 feels limb 4's
    mass exactly: M33 and G3 grow by its weight."""

    @classmethod
    def setUpClass(cls):
        cls.model, cls.deriv = _derive(FOUR)

    def test_sizes(self):
        mech = self.deriv.mech
        self.assertEqual(len(mech.bodies), 13)
        self.assertEqual([b.name for b in mech.bodies][-4:],
                         ["S1", "S2", "S3", "S4"])
        self.assertEqual(len(mech.actuators), 4)
        self.assertEqual(sum(len(j.basis) for j in mech.joints), 76)
        self.assertEqual([j.name for j in mech.joints][:4],
                         ["C1", "C2", "C3", "C4"])

    def test_limb4_mirrors_limb3(self):
        d = self.deriv.actuators()
        for env in _states(10, 8):
            mirrored = dict(env, q2=-env["q2"])
            d4 = self.ev_one(d[3], env)
            d3m = self.ev_one(d[2], mirrored)
            self.assertAlmostEqual(d4, d3m, delta=1e-15)

    def ev_one(self, e, env):
        return sym.evaluate([e], env)[0]

    def test_loops_close(self):
        joints = {j.name: j for j in self.deriv.mech.joints}
        for env in _states(5, 9):
            a = sym.evaluate(joints["A4"].centre, env)
            b = sym.evaluate(joints["B4"].centre, env)
            c = sym.evaluate(joints["C4"].centre, env)
            self.assertAlmostEqual(math.dist(a, b), 0.23, places=12)
            self.assertAlmostEqual(math.dist(b, c), 0.225, places=12)
            self.assertAlmostEqual(a[0], -0.315, places=15)
            self.assertAlmostEqual(a[1], 0.0, places=15)

    def test_adding_limb4_adds_its_mass_to_the_height(self):
        _, three = _derive(PAPER)
        m3, g3 = three.mass(), three.gravity_force()
        _, four = _derive(FOUR)
        m4, g4 = four.mass(), four.gravity_force()
        for env in _states(5, 10):
            v3 = sym.evaluate(m3 + g3, env)
            v4 = sym.evaluate(m4 + g4, env)
            self.assertAlmostEqual(v4[8] - v3[8], 0.64 + 1.31 + 1.59, delta=1e-12)
            self.assertAlmostEqual(v4[11] - v3[11], -9.81 * (0.64 + 1.31 + 1.59),
                                   delta=1e-10)

    def test_rejections(self):
        m = _load_json(FOUR)
        m["bodies"].pop("S4")
        with self.assertRaises(model.ModelError) as ctx:
            model.parse(json.dumps(m), "f.json")
        self.assertIn("bodies.S4: missing", str(ctx.exception))
        m = _load_json(FOUR)
        m["geometry"]["b"] = [0.36] * 5
        with self.assertRaises(model.ModelError) as ctx:
            model.parse(json.dumps(m), "f.json")
        self.assertIn("geometry.b: must be a list of 3", str(ctx.exception))
        m = _load_json(FOUR)
        m["geometry"]["l1"] = [0.23] * 3
        with self.assertRaises(model.ModelError) as ctx:
            model.parse(json.dumps(m), "f.json")
        self.assertIn("geometry.l1: must be one number or a list of 4",
                      str(ctx.exception))
