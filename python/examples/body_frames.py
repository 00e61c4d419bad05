#!/usr/bin/env python3
"""Every body's frame at the home pose, drawn: the figure a model file's
com and inertia entries refer to (docs/img/body_frames.png).

    python3 python/examples/body_frames.py OUT.png [MODEL.json]

The poses come from the library's pose kernel (Model.poses) at q = (0, 0,
-L) (L the mean upper-link length); each frame's origin is its centre of
mass less R com. Axes: x solid, y dashed,
z dotted (they stay apart in greyscale), each labelled at its tip; links
as thick grey lines between the joints A, B, C and the platform. Needs
gnuplot (pngcairo) and libprru.so ($PRRU_LIB, else build/ of this tree).
"""

import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import prru  # noqa: E402


def home(model):
    """q = (0, 0, -L), L the mean upper-link length: every valid model
    assembles at q1 = q2 = 0, and the height only moves the mechanism up
    and down (J_d does not depend on it); one link below {S}'s origin the
    world frame stands clear of the platform's."""
    q = [0.0, 0.0, -sum(model.l1) / len(model.l1)]
    try:
        model.check(q)
    except (prru.Unreachable, prru.Singular) as e:
        raise SystemExit("body_frames: q = (0, 0, %.4g): %s" % (q[2], e))
    return q


def frames(model, q):
    """Per body: name, frame origin o = p - R com, and R (rows)."""
    R, p = model.poses(q)
    out = []
    for b, name in enumerate(model.body_names):
        r, c = R[b], model.com[b]
        o = [p[b][i] - sum(r[i][j] * c[j] for j in range(3)) for i in range(3)]
        out.append((name, o, r))
    return out


def script(model, q, fr, png):
    L = sum(model.l1) / len(model.l1)
    a = 0.35 * L  # axis length
    lines = []
    # Joints from the frames (docs/model.md section 4): A_i is the slider's
    # origin, the upper link's origin is the midpoint of A_i B_i and the
    # lower link's that of B_i C_i.
    by = {n: (o, r) for n, o, r in fr}
    C = []
    for i in range(model.nlimb):
        A = by["S%d" % (i + 1)][0]
        B = [2 * by["U%d" % (i + 1)][0][k] - A[k] for k in range(3)]
        Ci = [2 * by["L%d" % (i + 1)][0][k] - B[k] for k in range(3)]
        C.append(Ci)
        lines += [(A, B, 5), (B, Ci, 5), ((A[0], A[1], A[2] - 1.0 * L), (A[0], A[1], A[2] + 0.8 * L), 3)]
    # The platform: its U joints C_1, C_2 and O' (C_3 = C_4 = O').
    lines += [(C[0], C[1], 9)]
    g = [
        "set terminal pngcairo size 1100,900 enhanced font 'Sans,11'",
        "set output '%s'" % png.replace("'", "''"),
        "set title 'Body frames at the home pose'",
        "set label 1 \"model %s at q = (0, 0, %.3g m); axes x solid, y dashed, z dotted; the world frame S grey at its origin; "
        "rails, links and the platform grey\" at screen 0.01,0.02 font ',9' tc rgb '#555555'"
        % (model.name.replace('"', ''), q[2]),
        "set view 68, 305, 1.6, 1.2",
        "set border 0", "unset xtics", "unset ytics", "unset ztics",
        "unset xlabel", "unset ylabel", "unset zlabel",
        "set view equal xyz",
        "set ticslevel 0",
        "unset key",
    ]
    for (s, e, w) in lines:
        g.append("set arrow from %.9g,%.9g,%.9g to %.9g,%.9g,%.9g nohead lw %d lc rgb '#bbbbbb' back"
                 % (tuple(s) + tuple(e) + (w,)))
    dash = {0: "dt 1", 1: "dt (8,5)", 2: "dt (2,4)"}
    # {S}: the world frame at its origin, long grey axes.
    for k in range(3):
        e = [1.6 * a * (i == k) for i in range(3)]
        g.append("set arrow from 0,0,0 to %.9g,%.9g,%.9g head size 0.015,20 lw 2.5 lc rgb '#777777' %s front"
                 % (tuple(e) + (dash[k],)))
        g.append("set label %d '%s_S' at %.9g,%.9g,%.9g font ',10' tc rgb '#555555' front"
                 % (100 + k, "xyz"[k], 1.75 * e[0], 1.75 * e[1], 1.75 * e[2]))
    tag = 2
    for name, o, r in fr:
        for k in range(3):
            e = [o[i] + a * r[i][k] for i in range(3)]
            g.append("set arrow from %.9g,%.9g,%.9g to %.9g,%.9g,%.9g head size 0.012,20 lw 2 lc rgb 'black' %s front"
                     % (tuple(o) + tuple(e) + (dash[k],)))
            g.append("set label %d '%s' at %.9g,%.9g,%.9g font ',9' front"
                     % (tag, "xyz"[k], e[0] + 0.08 * a * r[0][k], e[1] + 0.08 * a * r[1][k], e[2] + 0.08 * a * r[2][k]))
            tag += 1
        g.append("set label %d '%s' at %.9g,%.9g,%.9g font ',11:Bold' offset -2.5,-1 front" % (tag, name, o[0], o[1], o[2]))
        tag += 1
    xs = [c for s, e, _ in lines for c in (s[0], e[0])] + [o[0] for _, o, _ in fr]
    ys = [c for s, e, _ in lines for c in (s[1], e[1])] + [o[1] for _, o, _ in fr]
    zs = [c for s, e, _ in lines for c in (s[2], e[2])] + [o[2] for _, o, _ in fr]
    pad = 0.5 * a
    g.append("set xrange [%.9g:%.9g]" % (min(xs) - pad, max(xs) + pad))
    g.append("set yrange [%.9g:%.9g]" % (min(ys) - pad, max(ys) + pad))
    g.append("set zrange [%.9g:%.9g]" % (min(zs) - pad, max(zs) + pad))
    g.append("splot 1/0 notitle")
    return "\n".join(g) + "\n"


def main(argv):
    if len(argv) not in (2, 3):
        raise SystemExit(__doc__.strip().splitlines()[3].strip())
    model = prru.Model(model=argv[2]) if len(argv) == 3 else prru.Model()
    q = home(model)
    text = script(model, q, frames(model, q), argv[1])
    with tempfile.NamedTemporaryFile("w", suffix=".gp", delete=False) as f:
        f.write(text)
    try:
        r = subprocess.run(["gnuplot", f.name], capture_output=True, text=True)
    finally:
        os.unlink(f.name)
    if r.returncode != 0:
        raise SystemExit("body_frames: gnuplot failed: %s" % r.stderr.strip())
    print("body_frames: %s (%s)" % (argv[1], model.name))


if __name__ == "__main__":
    main(sys.argv)
