"""gen/prru_mjcf.py: the MuJoCo model written from a model file."""

import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
MODEL = os.path.join(ROOT, "models", "3prru_paper.json")
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


def modified_model(tmpdir, edit):
    with open(MODEL, encoding="utf-8") as f:
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

    def test_geometry_change_reaches_the_mjcf(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = modified_model(tmp, lambda d: d["geometry"].update(l1=0.25))
            root = ET.fromstring(prru_mjcf.render(path))
        s1 = world_frames(root)["S1"][1][2]
        # d = z_B + l1 sin(acos((b12 - a - l2) / l1)) at q1 = q2 = 0
        expect = prru_mjcf.HOME_Q[2] + math.sqrt(0.25 ** 2 - 0.09 ** 2)
        self.assertAlmostEqual(s1, expect, delta=1e-15)


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
