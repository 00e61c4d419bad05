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
                f.write(text.replace("$S1_mass", "1.0"))
            with self.assertRaises(ValueError) as ctx:
                prru_mjcf.render(MODEL, bad)
        self.assertIn("S1_mass", str(ctx.exception))
        self.assertIn(bad, str(ctx.exception))

    def test_description_cannot_break_the_xml_comment(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d.update(description="a -- b"))
            ET.fromstring(prru_mjcf.render(path))


if __name__ == "__main__":
    unittest.main()
