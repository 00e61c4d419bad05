#!/usr/bin/env python3
"""Write the MuJoCo (MJCF) model of a 3-PRRU (or 4-PRRU) model file.

usage: python3 gen/prru_mjcf.py MODEL.json --out FILE.xml

The MJCF is the independent check of the generated dynamics (see
validation/validate_mujoco.c), so this file deliberately does not reuse the
symbolic mechanism of prrugen: it evaluates the spec's pose formulas
(section 4 of 3prru-model.md, and section 12 for the fourth limb of the
redundant variant, with each limb's own geometry) once, in floating point,
at the home pose and places every MuJoCo body frame at the frame origin of
its pose function there; each body's <inertial> then puts
the centre of mass at the model's com (p_b = origin_b + R_b com) with the
inertia tensor about it. Format 2's gravity vector, and the drives' armature
and damping (MuJoCo's slide-joint armature and damping) are MJCF settings;
the smoothed Coulomb force is not a MuJoCo law and rides along as custom
data for validate_mujoco. From then on MuJoCo's own tree kinematics and
dynamics take over; the only thing shared with the generator is the
validated model file (prrugen.model).

The template (templates/prru_mjcf.xml) holds one limb's chain, one weld
and one drive's custom data as blocks that are written once per limb (per
platform copy 2..n for the welds): three or four limbs, one template.
"""

import argparse
import math
import os
import re
import string
import sys
from xml.sax.saxutils import escape

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from prrugen import model as model_mod  # noqa: E402
from prrugen import output  # noqa: E402

TEMPLATE = os.path.join(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))), "templates", "prru_mjcf.xml")

# Every MuJoCo joint coordinate is 0 here. q1 = q2 = 0 makes every rotation
# of the home pose elementary, and every valid model file assembles there at
# any height (prrugen.model checks it); q3 is the paper's working height. Any
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


IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def poses(limbs, q):
    """Spec sections 4 and 12 at q for per-limb geometry (limbs: three or
    four dicts of floats b, l1, l2, a): per limb the frames (R, p) of S, U,
    L at the frame origins of the spec, the joint centres A, B, C and the
    U joint's first axis (the lower link's long axis, world); and the
    platform."""
    q1, q2, q3 = q
    r_p = matmul(rx(q1), ry(q2))
    p_p = (0.0, 0.0, q3)
    out = []
    # limbs 1, 2 (section 4): plane x = 0, hinges along e1
    for s, g in ((-1.0, limbs[0]), (1.0, limbs[1])):
        c = add(p_p, matvec(r_p, (0.0, s * g["a"], 0.0)))
        r_l = rx(q1)
        b = add(c, matvec(r_l, (0.0, s * g["l2"], 0.0)))
        p_l = add(c, matvec(r_l, (0.0, s * g["l2"] / 2, 0.0)))
        y_a = s * g["b"]
        alpha = s * acos_checked(s * (y_a - b[1]) / g["l1"],
                                 "limb %d" % (1 if s < 0 else 2))
        d = b[2] + s * g["l1"] * math.sin(alpha)
        a = (0.0, y_a, d)
        out.append(dict(S=(IDENTITY, a), U=(rx(alpha), scale(0.5, add(a, b))),
                        L=(r_l, p_l), A=a, B=b, C=c,
                        hinge=E1, u_first=matvec(r_l, E2)))
    # limb 3 (section 4) and limb 4 (section 12): plane y = 0, hinges along
    # e2, U joint at O', lower link R_L3 = R_L4 = Ry(gamma)
    gamma = math.atan2(math.sin(q2), math.cos(q1) * math.cos(q2))
    r_l = ry(gamma)
    x3 = matvec(r_l, E1)
    g = limbs[2]
    b = add(p_p, scale(g["l2"], x3))
    p_l = add(p_p, scale(g["l2"] / 2, x3))
    alpha = acos_checked((b[0] - g["b"]) / g["l1"], "limb 3")
    d = b[2] + g["l1"] * math.sin(alpha)
    a = (g["b"], 0.0, d)
    out.append(dict(S=(IDENTITY, a), U=(ry(alpha), scale(0.5, add(a, b))),
                    L=(r_l, p_l), A=a, B=b, C=p_p,
                    hinge=E2, u_first=x3))
    if len(limbs) == 4:
        # B_4 = p_P - l2_4 x3, alpha_4 = acos((x_B4 + b4) / l1_4),
        # d_4 = z_B4 + l1_4 sin(alpha_4), A_4 = (-b4, 0, d_4),
        # R_U4 = Ry(alpha_4); the U joint's first axis x4 = -x3
        g = limbs[3]
        b = sub(p_p, scale(g["l2"], x3))
        p_l = sub(p_p, scale(g["l2"] / 2, x3))
        alpha = acos_checked((b[0] + g["b"]) / g["l1"], "limb 4")
        d = b[2] + g["l1"] * math.sin(alpha)
        a = (-g["b"], 0.0, d)
        out.append(dict(S=(IDENTITY, a), U=(ry(alpha), scale(0.5, add(a, b))),
                        L=(r_l, p_l), A=a, B=b, C=p_p,
                        hinge=E2, u_first=scale(-1.0, x3)))
    elif len(limbs) != 3:
        raise ValueError("%d limbs: a model has 3 or 4" % len(limbs))
    return (r_p, p_p), out


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


def principal_axes(t):
    """Eigen-decomposition of a symmetric 3x3 tensor t = V diag(w) V^T by
    cyclic Jacobi rotations, iterated until the off-diagonal entries are
    below rounding (Numerical Recipes' test): w and the rotation V
    (det +1, columns = principal axes)."""
    a = [list(map(float, row)) for row in t]
    v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    for _ in range(100):
        if all(a[p][q] == 0.0 for p, q in ((0, 1), (0, 2), (1, 2))):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p][q]
            if apq == 0.0:
                continue
            g = 100.0 * abs(apq)
            if abs(a[p][p]) + g == abs(a[p][p]) \
                    and abs(a[q][q]) + g == abs(a[q][q]):
                a[p][q] = a[q][p] = 0.0
                continue
            theta = (a[q][q] - a[p][p]) / (2.0 * apq)
            tan = math.copysign(1.0, theta) / (abs(theta)
                                                + math.sqrt(theta * theta + 1.0))
            c = 1.0 / math.sqrt(tan * tan + 1.0)
            s = tan * c
            # a <- J^T a J, v <- v J with J the rotation in the (p, q) plane
            for k in range(3):
                akp, akq = a[k][p], a[k][q]
                a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
            for k in range(3):
                apk, aqk = a[p][k], a[q][k]
                a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
            a[p][q] = a[q][p] = 0.0
            for k in range(3):
                vkp, vkq = v[k][p], v[k][q]
                v[k][p], v[k][q] = c * vkp - s * vkq, s * vkp + c * vkq
    else:
        raise ValueError("inertia tensor: Jacobi iteration did not converge")
    v = tuple(tuple(row) for row in v)
    det = sum(v[0][i] * (v[1][(i + 1) % 3] * v[2][(i + 2) % 3]
                         - v[1][(i + 2) % 3] * v[2][(i + 1) % 3])
              for i in range(3))
    if det < 0:
        v = tuple((row[0], row[1], -row[2]) for row in v)
    # the moments from the original tensor, w_i = v_i^T t v_i
    w = tuple(sum(v[k][i] * float(t[k][l]) * v[l][i] for k in range(3)
                  for l in range(3)) for i in range(3))
    return w, v


def inertial(mass, com, entries, share=1):
    """The <inertial> attributes of one body: mass and centre of mass in
    the body frame, and the tensor (Ixx Iyy Izz Ixy Ixz Iyz) about that
    centre in body axes, divided by share (the platform's copies).

    A tensor without products of inertia is diaginertia with the identity
    quat. MJCF's fullinertia would state any other tensor directly, but
    MuJoCo 2.2.2's compiler diagonalises it with mju_eig3, whose Jacobi
    iteration stops once a rotation's cosine exceeds 1 - 1e-12 (angles up
    to ~1e-6 rad): the compiled tensor is off by up to ~1e-8 relative,
    which the exact level of validate_mujoco sees (~3e-10 in the
    accelerations). So the principal axes are computed here to rounding and
    written as quat + diaginertia, which MuJoCo uses as given."""
    xx, yy, zz, xy, xz, yz = (float(x) / share for x in entries)
    if xy == 0 and xz == 0 and yz == 0:
        quat_text, moments = "1.0 0.0 0.0 0.0", (xx, yy, zz)
    else:
        moments, axes = principal_axes(((xx, xy, xz), (xy, yy, yz),
                                        (xz, yz, zz)))
        quat_text = fmt(quat(axes))
    return {"mass": repr(float(mass) / share), "com": fmt(com),
            "iquat": quat_text, "inertia": fmt(moments)}


LIMB_NOTES = (
    "rail at x = 0, y = -b1; hinges along e1; U joint about v, w",
    "rail at x = 0, y = +b2; hinges along e1; U joint about v, w",
    "rail at x = +b3, y = 0; hinges along e2; U joint about x3, w",
    "rail at x = -b4, y = 0; hinges along e2; U joint about x4 = -x3, w",
)

# What XML 1.0 allows in a document (its production Char), less the
# controls, which would not keep a text on one line (C0 incl. tab, LF and
# CR; DEL; C1) and the line and paragraph separators.
_NOT_ONE_LINE_TEXT = re.compile("[^\x20-\x7e\xa0-\u2027\u202a-\ud7ff"
                                "\ue000-\ufffd\U00010000-\U0010ffff]")


def xml_comment(text):
    """Any text made safe inside <!-- -->, on one line: characters outside
    _NOT_ONE_LINE_TEXT's set become spaces, no "--" survives (a space goes
    between every two '-') and a trailing '-' (before the "-->") gets a
    space after it. Readable, not reversible."""
    text = _NOT_ONE_LINE_TEXT.sub(" ", text)
    text = re.sub("-(?=-)", "- ", text)
    return text + " " if text.endswith("-") else text


def xml_attribute(text):
    """Any text as the value of a double-quoted attribute: characters XML
    cannot hold (even as references) become spaces, and markup characters
    are escaped."""
    return escape(_NOT_ONE_LINE_TEXT.sub(" ", text),
                  {'"': "&quot;", "'": "&apos;"})


def substitutions(m, path):
    """The template's values: (values of the document, {block name: one
    dict of values per repetition})."""
    limbs = [{k: float(getattr(limb, k)) for k in ("b", "l1", "l2", "a")}
             for limb in m.limbs]
    (r_p, p_p), chains = poses(limbs, HOME_Q)
    n = len(chains)
    platform = (r_p, p_p)
    index = {name: i for i, name in enumerate(m.body_names)}
    world = (IDENTITY, (0.0, 0.0, 0.0))
    nrows = 6 * (n - 1)
    # Every weld row is independent for three limbs. With four, limbs 3 and
    # 4 both hold O' in the plane y = 0: 5 n - 6 (n - 1) = 2, but the
    # rows' rank is one less, and the mechanism keeps its 3 DOF.
    if n == 3:
        redundancy = "15 - 12 = 3, no redundant row."
    else:
        redundancy = ("%d - %d + 1 = 3: limbs 3 and 4 both hold O' along e2, "
                      "so one\n     weld row is redundant (the %d rows have "
                      "rank %d)." % (5 * n, nrows, nrows, nrows - 1))
    # User text: the file name and description land in the header comment,
    # the name in an attribute.
    doc = dict(model_file=xml_comment(os.path.basename(path)),
               model_sha256=m.sha256,
               description=xml_comment(m.description),
               name=xml_attribute(m.name),
               nlimb=str(n), nweld=str(n - 1), nweld_rows=str(nrows),
               ntree=str(5 * n), redundancy=redundancy,
               home_q=", ".join(repr(x) for x in HOME_Q),
               gravity=fmt(m.gravity))
    i_p = index["P"]
    platform_inertial = inertial(m.masses[i_p], m.coms[i_p], m.inertias[i_p],
                                 share=n)
    limb_values, coulomb_values = [], []
    for i, limb in enumerate(chains, start=1):
        v = {"i": str(i), "limb_note": LIMB_NOTES[i - 1]}
        for key, value in platform_inertial.items():
            v["platform_" + key] = value
        chain = [("S", world), ("U", limb["S"]), ("L", limb["U"])]
        for key, parent in chain:
            pos, q = relative(parent, limb[key])
            v[key + "_pos"] = fmt(pos)
            v[key + "_quat"] = fmt(q)
            b = index["%s%d" % (key, i)]
            for attr, value in inertial(m.masses[b], m.coms[b],
                                        m.inertias[b]).items():
                v["%s_%s" % (key, attr)] = value
        pos, q = relative(limb["L"], platform)
        v["platform_pos"] = fmt(pos)
        v["platform_quat"] = fmt(q)
        # Joint positions and axes are in the child body's frame.
        frame_s, frame_u, frame_l = limb["S"], limb["U"], limb["L"]
        v["P_pos"] = fmt(in_frame(frame_s, limb["A"]))
        v["P_axis"] = fmt(matvec(transpose(frame_s[0]), E3))
        # The drive acts along the slide: its reflected inertia is MuJoCo's
        # armature and its viscous damping MuJoCo's (passive) damping on
        # that dof. The smoothed Coulomb force -f tanh(v / v_s) has no MJCF
        # counterpart (frictionloss is a different law); its parameters
        # travel as custom data and validate_mujoco applies the force
        # through qfrc_applied.
        v["P_armature"] = repr(float(m.armature[i - 1]))
        v["P_damping"] = repr(float(m.damping[i - 1]))
        coulomb_values.append({"i": str(i), "coulomb": fmt(
            (m.coulomb[i - 1], m.coulomb_velocity or 0))})
        v["A_pos"] = fmt(in_frame(frame_u, limb["A"]))
        v["A_axis"] = fmt(matvec(transpose(frame_u[0]), limb["hinge"]))
        v["B_pos"] = fmt(in_frame(frame_l, limb["B"]))
        v["B_axis"] = fmt(matvec(transpose(frame_l[0]), limb["hinge"]))
        # U joint: MuJoCo fixes a body's first joint axis in the parent and
        # its last in the body itself, so the pair (lower link's long axis,
        # platform normal w) needs no intermediate body.
        v["Ca_pos"] = fmt(in_frame(platform, limb["C"]))
        v["Ca_axis"] = fmt(matvec(transpose(r_p), limb["u_first"]))
        v["Cb_pos"] = v["Ca_pos"]
        v["Cb_axis"] = fmt(E3)  # w, in the platform's own frame
        # Display geoms along the links, joint centre to joint centre.
        v["U_fromto"] = fmt(in_frame(frame_u, limb["A"])
                            + in_frame(frame_u, limb["B"]))
        v["L_fromto"] = fmt(in_frame(frame_l, limb["B"])
                            + in_frame(frame_l, limb["C"]))
        limb_values.append(v)
    welds = [{"j": str(j)} for j in range(2, n + 1)]
    return doc, {"limb": limb_values, "weld": welds, "coulomb": coulomb_values}


# A block of the template repeated once per entry of its value list:
# "<!--@repeat NAME ...-->" and "<!--@end NAME -->" on lines of their own.
BLOCK = re.compile(r"^<!--@repeat (\w+)\b[^\n]*-->\n(.*?)^<!--@end \1 -->\n",
                   re.M | re.S)


def _fill(template_path, where, text, values):
    """string.Template substitution that insists on a value for every
    placeholder and a placeholder for every value."""
    template = string.Template(text)
    used = set(template.get_identifiers())
    missing = sorted(used - set(values))
    unused = sorted(set(values) - used)
    if missing or unused:
        raise ValueError("%s: template and generator disagree in %s "
                         "(placeholders without a value: %s; values without "
                         "a placeholder: %s)"
                         % (template_path, where, ", ".join(missing) or "none",
                            ", ".join(unused) or "none"))
    return template.substitute(values)


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
        doc, blocks = substitutions(m, model_path)
    except ValueError as exc:
        raise ValueError("%s: %s" % (model_path, exc)) from None
    # The blocks are expanded first and stand in the document as markers
    # (NUL cannot occur in a model's name or description), so that the
    # document's own substitution never sees their text.
    expanded, found = {}, []

    def cut(match):
        name = match.group(1)
        if name not in blocks or name in found:
            raise ValueError("%s: unknown or repeated block '%s'"
                             % (template_path, name))
        found.append(name)
        expanded[name] = "".join(
            _fill(template_path, "block '%s'" % name, match.group(2), v)
            for v in blocks[name])
        return "\0%s\0" % name

    outer = BLOCK.sub(cut, text)
    if sorted(found) != sorted(blocks):
        raise ValueError("%s: template and generator disagree (blocks "
                         "missing: %s)" % (template_path, ", ".join(
                             sorted(set(blocks) - set(found)))))
    out = _fill(template_path, "the document", outer, doc)
    for name, body in expanded.items():
        out = out.replace("\0%s\0" % name, body)
    if "\0" in out or "<!--@" in out:
        raise ValueError("%s: malformed block markers" % template_path)
    if re.search(r"<!--(?:(?!-->).)*--(?!>)", out, re.S):
        raise ValueError("%s: generated comment contains '--'" % template_path)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="prru_mjcf.py",
        description="Write the MuJoCo MJCF model of a 3-PRRU (or redundant "
                    "4-PRRU) model file (one tree chain per limb, platform "
                    "copies welded together).")
    parser.add_argument("model", help="model file (JSON), e.g. "
                        "models/3prru_paper.json")
    parser.add_argument("--out", required=True, metavar="FILE",
                        help="MJCF file to write")
    args = parser.parse_args(argv)
    return output.run_stoppable("prru_mjcf", args.out, lambda: _run(args))


def _run(args):
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
