#!/usr/bin/env python3
"""Write the MuJoCo (MJCF) model of a 3-PRRU model file.

usage: python3 gen/prru_mjcf.py MODEL.json --out FILE.xml

The MJCF is the independent check of the generated dynamics (see
validation/validate_mujoco.c), so this file deliberately does not reuse the
symbolic mechanism of prrugen: it evaluates the spec's pose formulas
(section 4 of 3prru-model.md) once, in floating point, at the home pose and
places every MuJoCo body frame there. From then on MuJoCo's own tree
kinematics and dynamics take over; the only thing shared with the generator
is the validated model file (prrugen.model).
"""

import argparse
import math
import os
import re
import string
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from prrugen import model as model_mod  # noqa: E402
from prrugen import output  # noqa: E402

TEMPLATE = os.path.join(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))), "templates", "prru_mjcf.xml")

# Every MuJoCo joint coordinate is 0 here. q1 = q2 = 0 makes every rotation
# of the home pose elementary; q3 is the paper's working height. Any
# reachable pose would do: the validation sets states through the poses.
HOME_Q = (0.0, 0.0, -0.8)

E1, E2, E3 = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


def rx(t):
    c, s = math.cos(t), math.sin(t)
    return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))


def ry(t):
    c, s = math.cos(t), math.sin(t)
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def matmul(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3))
                       for j in range(3)) for i in range(3))


def transpose(a):
    return tuple(tuple(a[j][i] for j in range(3)) for i in range(3))


def matvec(a, v):
    return tuple(sum(a[i][k] * v[k] for k in range(3)) for i in range(3))


def add(u, v):
    return tuple(x + y for x, y in zip(u, v))


def sub(u, v):
    return tuple(x - y for x, y in zip(u, v))


def scale(c, v):
    return tuple(c * x for x in v)


def quat(r):
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method,
    stable for every rotation), sign fixed so that the largest component
    is positive: the output is a function of r alone."""
    tr = r[0][0] + r[1][1] + r[2][2]
    cands = (tr, r[0][0], r[1][1], r[2][2])
    k = max(range(4), key=lambda i: cands[i])
    if k == 0:
        w = 0.5 * math.sqrt(1.0 + tr)
        x, y, z = ((r[2][1] - r[1][2]) / (4 * w), (r[0][2] - r[2][0]) / (4 * w),
                   (r[1][0] - r[0][1]) / (4 * w))
    elif k == 1:
        x = 0.5 * math.sqrt(1.0 + 2 * r[0][0] - tr)
        w, y, z = ((r[2][1] - r[1][2]) / (4 * x), (r[0][1] + r[1][0]) / (4 * x),
                   (r[0][2] + r[2][0]) / (4 * x))
    elif k == 2:
        y = 0.5 * math.sqrt(1.0 + 2 * r[1][1] - tr)
        w, x, z = ((r[0][2] - r[2][0]) / (4 * y), (r[0][1] + r[1][0]) / (4 * y),
                   (r[1][2] + r[2][1]) / (4 * y))
    else:
        z = 0.5 * math.sqrt(1.0 + 2 * r[2][2] - tr)
        w, x, y = ((r[1][0] - r[0][1]) / (4 * z), (r[0][2] + r[2][0]) / (4 * z),
                   (r[1][2] + r[2][1]) / (4 * z))
    return (w, x, y, z)


def acos_checked(x, what):
    if not -1.0 <= x <= 1.0:
        raise ValueError("%s: acos argument %r outside [-1, 1] at the home "
                         "pose" % (what, x))
    return math.acos(x)


def poses(g, q):
    """Spec section 4 at q: per limb the frames (R, p) of S, U, L, the joint
    centres A, B, C and the U joint's first axis (world); and the platform."""
    q1, q2, q3 = q
    r_p = matmul(rx(q1), ry(q2))
    p_p = (0.0, 0.0, q3)
    limbs = []
    for s in (-1.0, 1.0):
        c = add(p_p, matvec(r_p, (0.0, s * g["a"], 0.0)))
        r_l = rx(q1)
        b = add(c, matvec(r_l, (0.0, s * g["l2"], 0.0)))
        p_l = add(c, matvec(r_l, (0.0, s * g["l2"] / 2, 0.0)))
        y_a = s * g["b12"]
        alpha = s * acos_checked(s * (y_a - b[1]) / g["l1"],
                                 "limb %d" % (1 if s < 0 else 2))
        d = b[2] + s * g["l1"] * math.sin(alpha)
        a = (0.0, y_a, d)
        limbs.append(dict(S=(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), a),
                          U=(rx(alpha), scale(0.5, add(a, b))),
                          L=(r_l, p_l), A=a, B=b, C=c,
                          hinge=E1, u_first=matvec(r_l, E2),
                          long_axis=matvec(r_l, E2)))
    gamma = math.atan2(math.sin(q2), math.cos(q1) * math.cos(q2))
    r_l = ry(gamma)
    x3 = matvec(r_l, E1)
    b = add(p_p, scale(g["l2"], x3))
    p_l = add(p_p, scale(g["l2"] / 2, x3))
    alpha = acos_checked((b[0] - g["b3"]) / g["l1"], "limb 3")
    d = b[2] + g["l1"] * math.sin(alpha)
    a = (g["b3"], 0.0, d)
    limbs.append(dict(S=(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), a),
                      U=(ry(alpha), scale(0.5, add(a, b))),
                      L=(r_l, p_l), A=a, B=b, C=p_p,
                      hinge=E2, u_first=x3, long_axis=x3))
    return (r_p, p_p), limbs


def fmt(values):
    # repr() is the shortest decimal that round-trips: exact and stable.
    # +0.0 for -0.0 keeps the output free of sign noise.
    return " ".join(repr(float(v) + 0.0) for v in values)


def relative(parent, child):
    """Child frame in the parent frame: (pos, quat) of MJCF <body>."""
    (r0, p0), (r1, p1) = parent, child
    return matvec(transpose(r0), sub(p1, p0)), quat(matmul(transpose(r0), r1))


def in_frame(frame, point):
    r, p = frame
    return matvec(transpose(r), sub(point, p))


def substitutions(m, path):
    g = {k: float(v) for k, v in m.geometry.items()}
    (r_p, p_p), limbs = poses(g, HOME_Q)
    platform = (r_p, p_p)
    masses = dict(zip(model_mod.BODY_NAMES, (float(x) for x in m.masses)))
    inertias = dict(zip(model_mod.BODY_NAMES,
                        (tuple(float(x) for x in i) for i in m.inertias)))
    world = (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
             (0.0, 0.0, 0.0))
    description = m.description.replace("--", "- -")  # "--" ends an XML comment
    sub_ = dict(model_file=os.path.basename(path), model_sha256=m.sha256,
                description=description, name=m.name,
                home_q=", ".join(repr(x) for x in HOME_Q),
                gravity_z=repr(-float(m.gravity)),
                platform_mass=repr(masses["P"] / 3),
                platform_inertia=fmt(x / 3 for x in inertias["P"]))
    for i, limb in enumerate(limbs, start=1):
        names = {"S": "S%d" % i, "U": "U%d" % i, "L": "L%d" % i}
        chain = [("S", world), ("U", limb["S"]), ("L", limb["U"])]
        for key, parent in chain:
            pos, q = relative(parent, limb[key])
            sub_[names[key] + "_pos"] = fmt(pos)
            sub_[names[key] + "_quat"] = fmt(q)
            sub_[names[key] + "_mass"] = repr(masses[names[key]])
            sub_[names[key] + "_inertia"] = fmt(inertias[names[key]])
        pos, q = relative(limb["L"], platform)
        sub_["platform%d_pos" % i] = fmt(pos)
        sub_["platform%d_quat" % i] = fmt(q)
        # Joint positions and axes are in the child body's frame.
        frame_s, frame_u, frame_l = limb["S"], limb["U"], limb["L"]
        sub_["P%d_pos" % i] = fmt(in_frame(frame_s, limb["A"]))
        sub_["P%d_axis" % i] = fmt(matvec(transpose(frame_s[0]), E3))
        sub_["A%d_pos" % i] = fmt(in_frame(frame_u, limb["A"]))
        sub_["A%d_axis" % i] = fmt(matvec(transpose(frame_u[0]), limb["hinge"]))
        sub_["B%d_pos" % i] = fmt(in_frame(frame_l, limb["B"]))
        sub_["B%d_axis" % i] = fmt(matvec(transpose(frame_l[0]), limb["hinge"]))
        # U joint: MuJoCo fixes a body's first joint axis in the parent and
        # its last in the body itself, so the pair (lower link's long axis,
        # platform normal w) needs no intermediate body.
        sub_["C%da_pos" % i] = fmt(in_frame(platform, limb["C"]))
        sub_["C%da_axis" % i] = fmt(matvec(transpose(r_p), limb["u_first"]))
        sub_["C%db_pos" % i] = sub_["C%da_pos" % i]
        sub_["C%db_axis" % i] = fmt(E3)  # w, in the platform's own frame
        # Display geoms along the links, joint centre to joint centre.
        sub_["U%d_fromto" % i] = fmt(in_frame(frame_u, limb["A"])
                                     + in_frame(frame_u, limb["B"]))
        sub_["L%d_fromto" % i] = fmt(in_frame(frame_l, limb["B"])
                                     + in_frame(frame_l, limb["C"]))
    return sub_


def render(model_path, template_path=TEMPLATE):
    """The MJCF text for a model file; ModelError / ValueError on failure."""
    m = model_mod.load(model_path)
    try:
        with open(template_path, encoding="utf-8") as f:
            text = f.read()
    except OSError as exc:
        raise ValueError("%s: cannot read template: %s"
                         % (template_path, exc.strerror)) from None
    try:
        values = substitutions(m, model_path)
    except ValueError as exc:
        raise ValueError("%s: %s" % (model_path, exc)) from None
    template = string.Template(text)
    used = set(template.get_identifiers())
    missing = sorted(used - set(values))
    unused = sorted(set(values) - used)
    if missing or unused:
        raise ValueError("%s: template and generator disagree (placeholders "
                         "without a value: %s; values without a placeholder: "
                         "%s)" % (template_path, ", ".join(missing) or "none",
                                  ", ".join(unused) or "none"))
    out = template.substitute(values)
    if re.search(r"<!--(?:(?!-->).)*--(?!>)", out, re.S):
        raise ValueError("%s: generated comment contains '--'" % template_path)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="prru_mjcf.py",
        description="Write the MuJoCo MJCF model of a 3-PRRU model file "
                    "(three tree chains, platform copies welded together).")
    parser.add_argument("model", help="model file (JSON), e.g. "
                        "models/3prru_paper.json")
    parser.add_argument("--out", required=True, metavar="FILE",
                        help="MJCF file to write")
    args = parser.parse_args(argv)
    try:
        text = render(args.model)
    except (model_mod.ModelError, ValueError) as exc:
        print("prru_mjcf: error: %s" % exc, file=sys.stderr)
        return 1
    try:
        out = os.path.abspath(args.out)
        output.write_files_atomically(os.path.dirname(out),
                                      {os.path.basename(out): text})
    except OSError as exc:
        print("prru_mjcf: error: %s: cannot write: %s"
              % (args.out, exc.strerror), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
