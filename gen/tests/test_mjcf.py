"""gen/prru_mjcf.py: the MuJoCo model written from a model file."""

import importlib.util
import json
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
MODEL = os.path.join(ROOT, "models", "3prru_paper.json")
PROTO = os.path.join(ROOT, "models", "prototype_example.json")
FOUR = os.path.join(ROOT, "models", "4prru.json")
ENTRY = os.path.join(GEN_DIR, "prru_mjcf.py")

# Loaded by path: prru_mjcf is a script beside the prrugen package, not a
# package module (and the stdlib-only import check knows only prrugen).
_spec = importlib.util.spec_from_file_location("prru_mjcf", ENTRY)
prru_mjcf = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(prru_mjcf)


def run(*args):
    return subprocess.run([sys.executable, ENTRY] + list(args),
                          capture_output=True, text=True)


def numbers(text):
    return [float(x) for x in text.split()]


def quat_mat(q):
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
            (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
            (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)))


def world_frames(root):
    """World (R, p) of every named body, composing MJCF's relative poses
    the way MuJoCo does (independently of the generator's helpers)."""
    out = {}

    def walk(elem, r, p):
        for body in elem.findall("body"):
            rel_r = quat_mat(numbers(body.get("quat")))
            rel_p = numbers(body.get("pos"))
            wr = prru_mjcf.matmul(r, rel_r)
            wp = prru_mjcf.add(p, prru_mjcf.matvec(r, rel_p))
            out[body.get("name")] = (wr, wp)
            walk(body, wr, wp)

    walk(root.find("worldbody"), ((1, 0, 0), (0, 1, 0), (0, 0, 1)), (0, 0, 0))
    return out


def body(root, name):
    return next(b for b in root.iter("body") if b.get("name") == name)


def inertia_tensor(inertial):
    """R diag(moments) R^T of an <inertial>: the tensor MuJoCo uses, in the
    body frame (entries Ixx Iyy Izz Ixy Ixz Iyz)."""
    r = quat_mat(numbers(inertial.get("quat")))
    d = numbers(inertial.get("diaginertia"))
    t = [[sum(r[i][k] * d[k] * r[j][k] for k in range(3)) for j in range(3)]
         for i in range(3)]
    return [t[0][0], t[1][1], t[2][2], t[0][1], t[0][2], t[1][2]]


def without_header(text):
    """The MJCF without its leading comment (file name, hash, description)."""
    return re.sub(r"\A<!--.*?-->\n", "", text, flags=re.S)


def modified_model(tmpdir, edit, base=MODEL):
    with open(base, encoding="utf-8") as f:
        data = json.load(f)
    edit(data)
    path = os.path.join(tmpdir, "model.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(data, f)
    return path


class Output(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.text = prru_mjcf.render(MODEL)
        cls.root = ET.fromstring(cls.text)

    def test_deterministic_and_cli_writes_render(self):
        self.assertEqual(prru_mjcf.render(MODEL), self.text)
        with tempfile.TemporaryDirectory() as tmp:
            outs = []
            for name in ("a.xml", "b.xml"):
                path = os.path.join(tmp, name)
                r = run(MODEL, "--out", path)
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertEqual(r.stdout + r.stderr, "")
                with open(path, "rb") as f:
                    outs.append(f.read())
            self.assertEqual(outs[0], outs[1])
            self.assertEqual(outs[0].decode("utf-8"), self.text)

    def test_structure(self):
        bodies = [b.get("name") for b in self.root.iter("body")]
        self.assertEqual(sorted(bodies), sorted(
            ["S%d" % i for i in (1, 2, 3)] + ["U%d" % i for i in (1, 2, 3)]
            + ["L%d" % i for i in (1, 2, 3)]
            + ["platform%d" % i for i in (1, 2, 3)]))
        joints = {j.get("name"): j.get("type")
                  for j in self.root.find("worldbody").iter("joint")}
        self.assertEqual(len(joints), 15)
        for i in (1, 2, 3):
            self.assertEqual(joints["P%d" % i], "slide")
            for k in ("A%d", "B%d", "C%da", "C%db"):
                self.assertEqual(joints[k % i], "hinge")
        welds = self.root.find("equality").findall("weld")
        self.assertEqual(len(welds), 2)      # 15 - 12 = 3 DOF
        # contacts off, inertia only from <inertial>
        self.assertEqual(self.root.find("compiler").get("inertiafromgeom"),
                         "false")
        for g in self.root.find("worldbody").iter("geom"):
            self.assertEqual((g.get("contype"), g.get("conaffinity")), (None, None))
        dflt = self.root.find("default").find("geom")
        self.assertEqual((dflt.get("contype"), dflt.get("conaffinity")), ("0", "0"))
        self.assertEqual(numbers(self.root.find("option").get("gravity")),
                         [0.0, 0.0, -9.81])

    def test_masses_and_inertias_from_the_model_file(self):
        with open(MODEL, encoding="utf-8") as f:
            spec = json.load(f)["bodies"]
        total_p, inertia_p = 0.0, [0.0, 0.0, 0.0]
        for body in self.root.iter("body"):
            name = body.get("name")
            inert = body.find("inertial")
            self.assertEqual(numbers(inert.get("pos")), [0.0, 0.0, 0.0])
            mass, moments = float(inert.get("mass")), numbers(inert.get("diaginertia"))
            self.assertEqual(numbers(inert.get("quat")), [1.0, 0.0, 0.0, 0.0])
            if name.startswith("platform"):
                total_p += mass
                inertia_p = [a + b for a, b in zip(inertia_p, moments)]
            else:
                self.assertEqual(mass, spec[name]["mass"])
                self.assertEqual(moments, spec[name]["inertia"])
        self.assertAlmostEqual(total_p, spec["P"]["mass"], delta=1e-15)
        for a, b in zip(inertia_p, spec["P"]["inertia"]):
            self.assertAlmostEqual(a, b, delta=1e-18)

    def test_home_pose_is_the_spec_pose_and_the_loops_close(self):
        frames = world_frames(self.root)
        q3 = prru_mjcf.HOME_Q[2]
        # spec section 10: at q1 = q2 = 0 every d_i = q3 + 0.2116601048851672
        for i in (1, 2, 3):
            self.assertAlmostEqual(frames["S%d" % i][1][2], q3 + 0.2116601048851672,
                                   delta=1e-15)
            r, p = frames["platform%d" % i]
            for a, b in zip(p, (0.0, 0.0, q3)):
                self.assertAlmostEqual(a, b, delta=1e-15)
            for row, ident in zip(r, ((1, 0, 0), (0, 1, 0), (0, 0, 1))):
                for a, b in zip(row, ident):
                    self.assertAlmostEqual(a, b, delta=1e-15)
        self.assertEqual(frames["S1"][1][:2], (0.0, -0.36))
        self.assertEqual(frames["S3"][1][:2], (0.315, 0.0))
        # every U joint's centre is the same world point from both sides
        for i, c in ((1, (0, -0.045, q3)), (2, (0, 0.045, q3)), (3, (0, 0, q3))):
            body = next(b for b in self.root.iter("body")
                        if b.get("name") == "platform%d" % i)
            r, p = frames["platform%d" % i]
            for jn in body.findall("joint"):
                w = prru_mjcf.add(p, prru_mjcf.matvec(r, numbers(jn.get("pos"))))
                for a, b in zip(w, c):
                    self.assertAlmostEqual(a, b, delta=1e-15)

    def test_no_drives_and_no_coulomb(self):
        for i in (1, 2, 3):
            slide = next(j for j in self.root.iter("joint")
                         if j.get("name") == "P%d" % i)
            self.assertEqual((float(slide.get("armature")),
                              float(slide.get("damping"))), (0.0, 0.0))
        data = {n.get("name"): numbers(n.get("data"))
                for n in self.root.find("custom").findall("numeric")}
        self.assertEqual(data, {"P%d_coulomb" % i: [0.0, 0.0]
                                for i in (1, 2, 3)})

    def test_format2_transcription_gives_the_same_mjcf(self):
        # spec section 11: format-1 files stay valid, and the same robot
        # written in format 2 is the same MuJoCo model
        with open(MODEL, encoding="utf-8") as f:
            d = json.load(f)
        g = d["geometry"]
        d.update(format=2, gravity=[0, 0, -d["gravity"]])
        d["geometry"] = {"b": [g["b12"], g["b12"], g["b3"]], "l1": g["l1"],
                         "l2": [g["l2"]] * 3, "a": [g["a"], g["a"]]}
        for name, b in d["bodies"].items():
            b.update(com=[0, 0, 0], inertia=b["inertia"] + [0, 0, 0])
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "paper2.json")
            with open(path, "w", encoding="utf-8") as f:
                json.dump(d, f)
            text = prru_mjcf.render(path)
        self.assertEqual(without_header(text), without_header(self.text))

    def test_geometry_change_reaches_the_mjcf(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d["geometry"].update(l1=0.25))
            root = ET.fromstring(prru_mjcf.render(path))
        s1 = world_frames(root)["S1"][1][2]
        # d = z_B + l1 sin(acos((b12 - a - l2) / l1)) at q1 = q2 = 0
        expect = prru_mjcf.HOME_Q[2] + math.sqrt(0.25 ** 2 - 0.09 ** 2)
        self.assertAlmostEqual(s1, expect, delta=1e-15)


class Format2(unittest.TestCase):
    """models/prototype_example.json: per-limb geometry, gravity vector,
    centres of mass, inertia tensors with products, drives."""

    @classmethod
    def setUpClass(cls):
        cls.text = prru_mjcf.render(PROTO)
        cls.root = ET.fromstring(cls.text)
        with open(PROTO, encoding="utf-8") as f:
            cls.spec = json.load(f)

    def test_gravity_vector(self):
        self.assertEqual(numbers(self.root.find("option").get("gravity")),
                         self.spec["gravity"])

    def test_per_limb_geometry_home_pose_and_loops(self):
        g = self.spec["geometry"]
        b, l1, l2, a = g["b"], g["l1"], g["l2"], g["a"] + [0.0]
        q3 = prru_mjcf.HOME_Q[2]
        frames = world_frames(self.root)
        rails = ((0.0, -b[0]), (0.0, b[1]), (b[2], 0.0))
        centres = ((0.0, -a[0], q3), (0.0, a[1], q3), (0.0, 0.0, q3))
        for i in range(3):
            r, p = frames["S%d" % (i + 1)]
            self.assertEqual(p[:2], rails[i])
            # d_i at q1 = q2 = 0: z_B + sqrt(l1^2 - (b - a - l2)^2)
            gap = b[i] - a[i] - l2[i]
            self.assertAlmostEqual(p[2], q3 + math.sqrt(l1[i] ** 2 - gap ** 2),
                                   delta=1e-15)
            # the U joint's centre, seen from the platform copy, is C_i
            rp, pp = frames["platform%d" % (i + 1)]
            for jn in body(self.root, "platform%d" % (i + 1)).findall("joint"):
                w = prru_mjcf.add(pp, prru_mjcf.matvec(rp, numbers(jn.get("pos"))))
                for x, y in zip(w, centres[i]):
                    self.assertAlmostEqual(x, y, delta=1e-15)
            # joint B_i from the upper and the lower link coincide
            ru, pu = frames["U%d" % (i + 1)]
            rl, pl = frames["L%d" % (i + 1)]
            b_u = numbers(body(self.root, "U%d" % (i + 1)).find("geom")
                          .get("fromto"))[3:]
            b_l = numbers(body(self.root, "L%d" % (i + 1)).find("joint")
                          .get("pos"))
            for x, y in zip(prru_mjcf.add(pu, prru_mjcf.matvec(ru, b_u)),
                            prru_mjcf.add(pl, prru_mjcf.matvec(rl, b_l))):
                self.assertAlmostEqual(x, y, delta=1e-15)

    def test_centres_of_mass_and_inertia_tensors(self):
        bodies = self.spec["bodies"]
        copies = [body(self.root, "platform%d" % i).find("inertial")
                  for i in (1, 2, 3)]
        for name, spec in bodies.items():
            if name == "P":
                inertials, share = copies, 3
            else:
                inertials, share = [body(self.root, name).find("inertial")], 1
            for inert in inertials:
                # com is the inertial's position in the body frame, exactly
                self.assertEqual(numbers(inert.get("pos")), spec["com"], name)
                # no fullinertia: MuJoCo 2.2.2 diagonalises it inexactly
                self.assertIsNone(inert.get("fullinertia"))
                self.assertAlmostEqual(float(inert.get("mass")) * share,
                                       spec["mass"], delta=1e-15)
                t = inertia_tensor(inert)
                scale = max(abs(x) for x in spec["inertia"])
                for k, (x, y) in enumerate(zip(t, spec["inertia"])):
                    # rounding (MuJoCo's own fullinertia: ~1e-8)
                    self.assertLess(abs(x * share - y), 2e-15 * scale,
                                    "%s inertia[%d]" % (name, k))

    def test_drives(self):
        act = self.spec["actuators"]
        data = {n.get("name"): numbers(n.get("data"))
                for n in self.root.find("custom").findall("numeric")}
        for i in range(3):
            slide = next(j for j in self.root.iter("joint")
                         if j.get("name") == "P%d" % (i + 1))
            self.assertEqual(float(slide.get("armature")), act["armature"][i])
            self.assertEqual(float(slide.get("damping")), act["damping"][i])
            self.assertIsNone(slide.get("frictionloss"))  # not MuJoCo's law
            self.assertEqual(data["P%d_coulomb" % (i + 1)],
                             [act["coulomb"][i], act["coulomb_velocity"]])

    def test_com_change_reaches_the_mjcf(self):
        def edit(d):
            d["bodies"]["U2"]["com"] = [0.01, -0.02, 0.03]
            d["bodies"]["U2"]["inertia"][5] = 0.0001
        with tempfile.TemporaryDirectory() as tmp:
            root = ET.fromstring(prru_mjcf.render(modified_model(tmp, edit,
                                                                 PROTO)))
        inert = body(root, "U2").find("inertial")
        self.assertEqual(numbers(inert.get("pos")), [0.01, -0.02, 0.03])
        self.assertAlmostEqual(inertia_tensor(inert)[5], 0.0001, delta=1e-18)


def ry(t):
    c, s_ = math.cos(t), math.sin(t)
    return ((c, 0.0, s_), (0.0, 1.0, 0.0), (-s_, 0.0, c))


def assert_close(case, u, v, delta, msg=None):
    case.assertEqual(len(u), len(v))
    for x, y in zip(u, v):
        case.assertAlmostEqual(x, y, delta=delta, msg=msg)


class FourLimbs(unittest.TestCase):
    """models/4prru.json, the redundant 4-PRRU (spec section 12): limb 4
    mirrors limb 3 (rail at x = -b4, hinges along e2, U joint at O'); four
    chains, a quarter of the platform on each copy, three welds (18 rows,
    one of them redundant)."""

    @classmethod
    def setUpClass(cls):
        cls.text = prru_mjcf.render(FOUR)
        cls.root = ET.fromstring(cls.text)
        with open(FOUR, encoding="utf-8") as f:
            cls.spec = json.load(f)
        # limb 4 with its own numbers, none equal to limb 3's
        def edit(d):
            d["geometry"].update(b=[0.36, 0.36, 0.315, 0.30],
                                 l1=[0.23, 0.23, 0.23, 0.24],
                                 l2=[0.225, 0.225, 0.225, 0.21])
        with tempfile.TemporaryDirectory() as tmp:
            cls.own_text = prru_mjcf.render(modified_model(tmp, edit, FOUR))
        cls.own = ET.fromstring(cls.own_text)

    def test_structure_and_body_count(self):
        bodies = [b.get("name") for b in self.root.iter("body")]
        self.assertEqual(len(bodies), 16)
        self.assertEqual(sorted(bodies), sorted(
            "%s%d" % (k, i) for k in ("S", "U", "L", "platform")
            for i in (1, 2, 3, 4)))
        # the model file's 13 bodies, each once; P split into 4 copies
        self.assertEqual(sorted(set(bodies) - {"platform%d" % i
                                                for i in (1, 2, 3, 4)}),
                         sorted(set(self.spec["bodies"]) - {"P"}))
        joints = {j.get("name"): j.get("type")
                  for j in self.root.find("worldbody").iter("joint")}
        self.assertEqual(len(joints), 20)           # 5 per chain
        for i in (1, 2, 3, 4):
            self.assertEqual(joints["P%d" % i], "slide")
            for k in ("A%d", "B%d", "C%da", "C%db"):
                self.assertEqual(joints[k % i], "hinge")
        welds = self.root.find("equality").findall("weld")
        # 3 welds = 18 rows; 20 - 18 = 2 < 3 DOF: one row is redundant
        self.assertEqual([(w.get("body1"), w.get("body2")) for w in welds],
                         [("platform1", "platform%d" % j) for j in (2, 3, 4)])
        data = {n.get("name"): numbers(n.get("data"))
                for n in self.root.find("custom").findall("numeric")}
        self.assertEqual(data, {"P%d_coulomb" % i: [0.0, 0.0]
                                for i in (1, 2, 3, 4)})
        self.assertEqual(self.root.get("model"), self.spec["name"])
        self.assertIn("one\n     weld row is redundant", self.text)

    def test_masses_and_a_quarter_of_the_platform_per_copy(self):
        bodies = self.spec["bodies"]
        total, moments = 0.0, [0.0, 0.0, 0.0]
        for b in self.root.iter("body"):
            name, inert = b.get("name"), b.find("inertial")
            mass = float(inert.get("mass"))
            if name.startswith("platform"):
                # a power-of-two share: exact
                self.assertEqual(mass * 4, bodies["P"]["mass"])
                self.assertEqual([x * 4 for x in numbers(inert.get("diaginertia"))],
                                 bodies["P"]["inertia"])
                total += mass
                moments = [x + y for x, y in
                           zip(moments, numbers(inert.get("diaginertia")))]
            else:
                self.assertEqual(mass, bodies[name]["mass"], name)
                self.assertEqual(numbers(inert.get("diaginertia")),
                                 bodies[name]["inertia"], name)
        self.assertEqual(total, bodies["P"]["mass"])
        self.assertEqual(moments, bodies["P"]["inertia"])

    def check_home(self, root, g):
        """Spec 12 at q1 = q2 = 0: limb 4's frames, d_4 and its loop."""
        b4, l1, l2 = g["b"][3], g["l1"][3], g["l2"][3]
        q3 = prru_mjcf.HOME_Q[2]
        frames = world_frames(root)
        ident = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        # B_4 = p_P - l2 x3 with x3 = e1; alpha_4 = acos((x_B4 + b4) / l1)
        b_4 = (-l2, 0.0, q3)
        alpha = math.acos((b_4[0] + b4) / l1)
        d_4 = b_4[2] + l1 * math.sin(alpha)
        self.assertAlmostEqual(d_4, q3 + math.sqrt(l1 ** 2 - (b4 - l2) ** 2),
                               delta=1e-15)
        a_4 = (-b4, 0.0, d_4)
        r, p = frames["S4"]
        assert_close(self, p, a_4, 1e-15, "S_4 at A_4")
        for row, e in zip(r, ident):
            assert_close(self, row, e, 1e-15)
        r, p = frames["U4"]
        for row, e in zip(r, ry(alpha)):
            assert_close(self, row, e, 1e-15, "R_U4 = Ry(alpha_4)")
        assert_close(self, p, prru_mjcf.scale(0.5, prru_mjcf.add(a_4, b_4)),
                     1e-15, "p_U4")
        r, p = frames["L4"]
        for row, e in zip(r, ident):
            assert_close(self, row, e, 1e-15, "R_L4 = Ry(gamma = 0)")
        assert_close(self, p, (-l2 / 2, 0.0, q3), 1e-15, "p_L4")
        for i in (1, 2, 3, 4):
            r, p = frames["platform%d" % i]
            assert_close(self, p, (0.0, 0.0, q3), 1e-15)
            for row, e in zip(r, ident):
                assert_close(self, row, e, 1e-15)
        # joint axes in world: slide e3, hinges e2, U joint x4 = -x3 and w
        axes = {}
        for name in ("S4", "U4", "L4", "platform4"):
            rb, _ = frames[name]
            for jn in body(root, name).findall("joint"):
                axes[jn.get("name")] = prru_mjcf.matvec(rb, numbers(jn.get("axis")))
        self.assertEqual(sorted(axes), ["A4", "B4", "C4a", "C4b", "P4"])
        for name, axis in (("P4", (0, 0, 1)), ("A4", (0, 1, 0)), ("B4", (0, 1, 0)),
                           ("C4a", (-1, 0, 0)), ("C4b", (0, 0, 1))):
            assert_close(self, axes[name], axis, 1e-15, name)
        return a_4, b_4, d_4

    def check_loops(self, root, centres):
        """Every joint's centre is the same world point from both of its
        bodies: A_i (slider frame origin / upper link), B_i (upper / lower
        link), C_i (lower link / platform copy)."""
        frames = world_frames(root)

        def world(name, local):
            r, p = frames[name]
            return prru_mjcf.add(p, prru_mjcf.matvec(r, local))

        for i, c in enumerate(centres, start=1):
            u = numbers(body(root, "U%d" % i).find("geom").get("fromto"))
            l_ = numbers(body(root, "L%d" % i).find("geom").get("fromto"))
            a_from_s = world("S%d" % i, numbers(
                body(root, "S%d" % i).find("joint").get("pos")))
            a_from_u = world("U%d" % i, numbers(
                body(root, "U%d" % i).find("joint").get("pos")))
            assert_close(self, a_from_s, a_from_u, 1e-15, "A%d" % i)
            assert_close(self, a_from_u, world("U%d" % i, u[:3]), 1e-15)
            b_from_u = world("U%d" % i, u[3:])
            b_from_l = world("L%d" % i, numbers(
                body(root, "L%d" % i).find("joint").get("pos")))
            assert_close(self, b_from_u, b_from_l, 1e-15, "B%d" % i)
            c_from_l = world("L%d" % i, l_[3:])
            for jn in body(root, "platform%d" % i).findall("joint"):
                assert_close(self, world("platform%d" % i,
                                         numbers(jn.get("pos"))), c, 1e-15)
            assert_close(self, c_from_l, c, 1e-15, "C%d" % i)
            yield a_from_s, b_from_u, c

    def test_limb4_home_pose_d4_and_closed_loops(self):
        g = self.spec["geometry"]
        a_4, b_4, d_4 = self.check_home(self.root, {
            "b": g["b"], "l1": [g["l1"]] * 4, "l2": [g["l2"]] * 4})
        # the paper's geometry: d_4 = d_3 = q3 + 0.2116601048851672 (spec 10)
        frames = world_frames(self.root)
        self.assertAlmostEqual(d_4, prru_mjcf.HOME_Q[2] + 0.2116601048851672,
                               delta=1e-15)
        self.assertAlmostEqual(frames["S3"][1][2], d_4, delta=1e-15)
        # limb 4 is limb 3 mirrored in the plane x = 0
        for name in ("S", "U", "L"):
            p3, p4 = frames[name + "3"][1], frames[name + "4"][1]
            assert_close(self, p4, (-p3[0], p3[1], p3[2]), 1e-15, name)
        q3 = prru_mjcf.HOME_Q[2]
        centres = ((0, -g["a"], q3), (0, g["a"], q3), (0, 0, q3), (0, 0, q3))
        for i, (a, b, c) in enumerate(self.check_loops(self.root, centres)):
            self.assertAlmostEqual(math.dist(a, b), g["l1"], delta=1e-15)
            self.assertAlmostEqual(math.dist(b, c), g["l2"], delta=1e-15)
        assert_close(self, a, a_4, 1e-15)
        assert_close(self, b, b_4, 1e-15)

    def test_limb4_uses_its_own_geometry(self):
        g = {"b": [0.36, 0.36, 0.315, 0.30], "l1": [0.23, 0.23, 0.23, 0.24],
             "l2": [0.225, 0.225, 0.225, 0.21]}
        self.check_home(self.own, g)
        q3 = prru_mjcf.HOME_Q[2]
        centres = ((0, -0.045, q3), (0, 0.045, q3), (0, 0, q3), (0, 0, q3))
        lengths = list(zip(g["l1"], g["l2"]))
        for (l1, l2), (a, b, c) in zip(lengths, self.check_loops(self.own,
                                                                 centres)):
            self.assertAlmostEqual(math.dist(a, b), l1, delta=1e-15)
            self.assertAlmostEqual(math.dist(b, c), l2, delta=1e-15)
        # limbs 1-3 are the paper's: the same frames as in 4prru.json
        mine, paper = world_frames(self.own), world_frames(self.root)
        for k in ("S", "U", "L", "platform"):
            for i in (1, 2, 3):
                self.assertEqual(mine["%s%d" % (k, i)], paper["%s%d" % (k, i)])

    def test_pose_formulas_off_home(self):
        """prru_mjcf.poses away from home, against spec 12 written out:
        limb 4 closes (|A_4 B_4| = l1_4, |B_4 O'| = l2_4, the upper link's
        local x runs from A_4 to B_4) and, for b4 = b3 and equal links,
        d_4(q1, q2, q3) = d_3(q1, -q2, q3) (the mirror)."""
        rng = random.Random(11)
        paper = [dict(b=0.36, l1=0.23, l2=0.225, a=0.045)] * 2 + \
            [dict(b=0.315, l1=0.23, l2=0.225, a=0.0)] * 2
        own = paper[:3] + [dict(b=0.30, l1=0.24, l2=0.21, a=0.0)]
        for _ in range(50):
            q = (rng.uniform(-0.3, 0.3), rng.uniform(-0.4, 0.4),
                 rng.uniform(-1.0, 0.0))
            for limbs in (paper, own):
                g = limbs[3]
                (r_p, p_p), chains = prru_mjcf.poses(limbs, q)
                self.assertEqual(len(chains), 4)
                l4 = chains[3]
                gamma = math.atan2(math.sin(q[1]), math.cos(q[0]) * math.cos(q[1]))
                x3 = (math.cos(gamma), 0.0, -math.sin(gamma))
                b_4 = tuple(p - g["l2"] * x for p, x in zip(p_p, x3))
                alpha = math.acos((b_4[0] + g["b"]) / g["l1"])
                d_4 = b_4[2] + g["l1"] * math.sin(alpha)
                assert_close(self, l4["B"], b_4, 1e-15)
                assert_close(self, l4["A"], (-g["b"], 0.0, d_4), 1e-15)
                assert_close(self, l4["C"], p_p, 0.0)
                assert_close(self, l4["u_first"], [-x for x in x3], 1e-15)
                for row, e in zip(l4["U"][0], ry(alpha)):
                    assert_close(self, row, e, 1e-15)
                for row, e in zip(l4["L"][0], ry(gamma)):
                    assert_close(self, row, e, 1e-15)
                self.assertAlmostEqual(math.dist(l4["A"], l4["B"]), g["l1"],
                                       delta=1e-15)
                self.assertAlmostEqual(math.dist(l4["B"], p_p), g["l2"],
                                       delta=1e-15)
                along = prru_mjcf.matvec(l4["U"][0], (g["l1"], 0.0, 0.0))
                assert_close(self, prru_mjcf.add(l4["A"], along), l4["B"], 1e-15)
            (_, _), mirrored = prru_mjcf.poses(paper, (q[0], -q[1], q[2]))
            (_, _), chains = prru_mjcf.poses(paper, q)
            self.assertAlmostEqual(chains[3]["A"][2], mirrored[2]["A"][2],
                                   delta=1e-15)

    def test_unreachable_limb4_is_reported(self):
        # a pose where limb 4's upper link cannot reach: named, not a NaN
        limbs = [dict(b=0.36, l1=0.23, l2=0.225, a=0.045)] * 2 + \
            [dict(b=0.315, l1=0.23, l2=0.225, a=0.0),
             dict(b=0.60, l1=0.23, l2=0.225, a=0.0)]
        with self.assertRaises(ValueError) as ctx:
            prru_mjcf.poses(limbs, prru_mjcf.HOME_Q)
        self.assertIn("limb 4", str(ctx.exception))

    def test_cli_writes_the_four_limb_model(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "m4.xml")
            r = run(FOUR, "--out", path)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(path, encoding="utf-8") as f:
                self.assertEqual(f.read(), self.text)


class PrincipalAxes(unittest.TestCase):
    def test_reconstructs_random_tensors_to_rounding(self):
        rng = random.Random(7)
        for _ in range(300):
            # a rigid body's tensor: tr(S) E - S with S = sum m r r^T
            pts = [[rng.uniform(-1, 1) for _ in range(3)] for _ in range(4)]
            s_ = [[sum(p[i] * p[j] for p in pts) for j in range(3)]
                  for i in range(3)]
            tr = sum(s_[i][i] for i in range(3))
            t = [[(tr if i == j else 0) - s_[i][j] for j in range(3)]
                 for i in range(3)]
            w, v = prru_mjcf.principal_axes(t)
            for i in range(3):
                for j in range(3):
                    rec = sum(v[i][k] * w[k] * v[j][k] for k in range(3))
                    self.assertLess(abs(rec - t[i][j]), 4e-15 * tr)
                    dot = sum(v[k][i] * v[k][j] for k in range(3))
                    self.assertLess(abs(dot - (i == j)), 4e-15)
            det = sum(v[0][i] * (v[1][(i + 1) % 3] * v[2][(i + 2) % 3]
                                 - v[1][(i + 2) % 3] * v[2][(i + 1) % 3])
                      for i in range(3))
            self.assertAlmostEqual(det, 1.0, delta=4e-15)

    def test_diagonal_tensor_is_its_own_principal_form(self):
        w, v = prru_mjcf.principal_axes(((3.0, 0, 0), (0, 1.0, 0), (0, 0, 2.0)))
        self.assertEqual(w, (3.0, 1.0, 2.0))
        self.assertEqual(v, ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))


class Errors(unittest.TestCase):
    def check_fails(self, args, *needles):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out.xml")
            r = run(*(list(args) + ["--out", out]))
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertTrue(r.stderr.startswith("prru_mjcf: error: "), r.stderr)
            for n in needles:
                self.assertIn(n, r.stderr)
            self.assertFalse(os.path.exists(out), "wrote output despite the error")

    def test_missing_file(self):
        self.check_fails(["/nonexistent/model.json"], "/nonexistent/model.json",
                         "cannot read")

    def test_bad_mass_names_file_and_key(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d["bodies"]["U2"].update(mass=-1))
            self.check_fails([path], path, "bodies.U2.mass", "positive")

    def test_unassemblable_geometry(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d["geometry"].update(l1=0.01))
            self.check_fails([path], path, "geometry", "cannot be assembled")

    def test_template_mismatch_is_reported(self):
        with open(prru_mjcf.TEMPLATE, encoding="utf-8") as f:
            text = f.read()
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "t.xml")
            with open(bad, "w", encoding="utf-8") as f:
                f.write(text.replace("$S_mass", "1.0"))
            with self.assertRaises(ValueError) as ctx:
                prru_mjcf.render(MODEL, bad)
        self.assertIn("S_mass", str(ctx.exception))
        self.assertIn("block 'limb'", str(ctx.exception))
        self.assertIn(bad, str(ctx.exception))

    def test_template_block_mismatch_is_reported(self):
        with open(prru_mjcf.TEMPLATE, encoding="utf-8") as f:
            text = f.read()
        cases = (
            # a block the generator has no values for
            (text.replace("@repeat weld", "@repeat welds")
                 .replace("@end weld ", "@end welds "), "welds"),
            # a block without its end: its text stays and is reported
            (text.replace("<!--@end coulomb -->\n", ""), "coulomb"),
            # a per-limb value used outside its block
            (text.replace('model="$name"', 'model="$S_pos"'), "S_pos"),
        )
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "t.xml")
            for bad_text, needle in cases:
                with open(bad, "w", encoding="utf-8") as f:
                    f.write(bad_text)
                with self.assertRaises(ValueError) as ctx:
                    prru_mjcf.render(MODEL, bad)
                self.assertIn(needle, str(ctx.exception))
                self.assertIn(bad, str(ctx.exception))

    def test_description_cannot_break_the_xml_comment(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d.update(description="a -- b"))
            ET.fromstring(prru_mjcf.render(path))


# Descriptions and file names that break an XML comment written raw: "--"
# in any form, a '-' before the closing "-->", markup, characters XML 1.0
# cannot hold at all (DEL and C1 it allows, but not on "one line").
HOSTILE_DESCRIPTIONS = [
    "a ---><worldbody><body name=\"evil\"/></worldbody><!-- b",
    "a --><mujoco/><!-- b",
    "a --!> <!-- b",
    "----",
    "-",
    "ends in a dash -",
    "ends in two dashes --",
    "]]> <![CDATA[ x ]]> &amp; &#0; &lt; < > ' \"",
    "\x7f \x85 \u2028 \u2029 \ufffe \uffff \U0001f600 \u00e9",
]
HOSTILE_FILES = ["m---><x><!--.json", "m-", "m\udcff--.json", "-"]


def xml_nodes(text):
    """(top-level nodes of the document, the element tree without
    comments): minidom keeps the comment before the root element."""
    from xml.dom import minidom
    doc = minidom.parseString(text.encode("utf-8"))
    return doc.childNodes, ET.tostring(ET.fromstring(text))


class HostileText(unittest.TestCase):
    """User text in the MJCF: the document parses, its elements and
    attributes are those of the paper model's, and the text stays in the
    one header comment."""

    @classmethod
    def setUpClass(cls):
        cls.nodes, cls.tree = xml_nodes(prru_mjcf.render(MODEL))

    def check(self, path, description, file_name):
        text = prru_mjcf.render(path)
        nodes, tree = xml_nodes(text)
        self.assertEqual(tree, self.tree)
        self.assertEqual([n.nodeType for n in nodes],
                         [n.nodeType for n in self.nodes])
        header = nodes[0].data
        self.assertIn("\n     %s\n" % prru_mjcf.xml_comment(description),
                      header)
        self.assertIn("`python3 gen/prru_mjcf.py %s`"
                      % prru_mjcf.xml_comment(file_name), header)
        self.assertEqual(len(re.findall("<!--", text)),
                         len(re.findall("-->", text)))

    def test_descriptions(self):
        for description in HOSTILE_DESCRIPTIONS:
            with self.subTest(description), \
                    tempfile.TemporaryDirectory() as tmp:
                path = modified_model(tmp, lambda d: d.update(
                    description=description))
                self.check(path, description, "model.json")

    def test_file_names(self):
        for name in HOSTILE_FILES:
            with self.subTest(name), tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, name)
                with open(MODEL, "rb") as f, open(path, "wb") as g:
                    g.write(f.read())
                self.check(path, prru_mjcf.model_mod.load(MODEL).description,
                           name)

    def test_written_file_parses(self):
        # Through the command line: the file is UTF-8 XML (a file name that
        # is not UTF-8 reaches Python as a lone surrogate).
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d.update(
                description=HOSTILE_DESCRIPTIONS[0]))
            hostile = os.path.join(tmp, HOSTILE_FILES[2])
            os.rename(path, hostile)
            out = os.path.join(tmp, "out.xml")
            r = run(hostile, "--out", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(out, "rb") as f:
                self.assertEqual(xml_nodes(f.read().decode("utf-8"))[1],
                                 self.tree)

    def test_comment_and_attribute_escaping(self):
        for t in HOSTILE_DESCRIPTIONS + HOSTILE_FILES:
            with self.subTest(t):
                c = prru_mjcf.xml_comment(t)
                self.assertNotIn("--", c)
                self.assertFalse(c.endswith("-"))
                a = prru_mjcf.xml_attribute(t)
                root = ET.fromstring('<a v="%s"/>' % a)
                self.assertEqual(root.get("v"), prru_mjcf._NOT_ONE_LINE_TEXT
                                 .sub(" ", t))


if __name__ == "__main__":
    unittest.main()
