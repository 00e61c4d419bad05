#!/usr/bin/env python3
"""A seeded generator of valid model files, for the generic test suite.

usage: python3 tests/random_model.py --seed N --out FILE [--limbs 3|4]
                                     [--format 1|2] [--structure S]

The same seed (and options) always writes the same file. What varies, within
the spec (sections 11-13) and what gen/prrugen/model.py accepts:
  - 3 or 4 limbs (--limbs; default: from the seed), format 1 (3 limbs,
    symmetric, principal moments) or format 2 (--format; default: format 2
    except one seed in five of the 3-limb ones);
  - overall size scaled by 0.1x .. 10x (log-uniform), and per-limb rail
    offsets b, upper and lower links l1, l2 and U-joint offsets a1, a2;
  - masses over a decade (one overall factor 0.3x .. 3x, then +-30 % per
    body), centres of mass off the body frames (up to 15 % of the body's
    size per axis), full inertia tensors with products of inertia (random
    principal axes; principal moments from positive second moments, so
    positive definite with strict triangle inequalities);
  - drives: armature, viscous damping and smoothed Coulomb force per
    actuator, each present or absent by the seed;
  - gravity tilted up to 15 degrees off -z, magnitude 9.0 .. 10.6 m/s^2;
  - structure (--structure; default: general except two format-2 seeds in
    ten, seed % 10 in (4, 5), so one of each number of limbs): simple is a format-2 model with every centre of
    mass, product of inertia and drive written as exactly 0 and gravity
    along -z, what the topology kernels' simple variant (prru_p3s_*,
    prru_p4s_*) evaluates, so that 4-limb models exercise it too (format 1
    is always of that structure).
Every model keeps the workspace the generic tests use: the limbs assemble
at q = 0 with the upper links between 25 % and 55 % of full stretch (the
paper's is 39 %), and every pose in TEST_POSES is reachable with J_d well
conditioned (|acos argument| <= MAX_ACOS, Hadamard ratio of J_d >= MIN_HADAMARD);
a draw that misses is drawn again from the same stream. The written file is
validated by the generator's own gen/prrugen/model.py (parse), and its
warnings must be empty. Exit status: 0 written, 2 bad arguments, 1 no valid
model in MAX_DRAWS draws (a bug of this script).
"""

import argparse
import json
import math
import os
import random
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "gen"))
from prrugen import model as model_mod  # noqa: E402

# The paper's model (spec sections 3 and 5): the centre of every range.
PAPER_L1, PAPER_L2, PAPER_A = 0.230, 0.225, 0.045
PAPER_MASS = {"P": 1.77, "L": 0.64, "U": 1.31, "S": 1.59}
# (q1, q2) of the fixed states of the generic tests (tests/test_*.{c,sh},
# validation/): each must be reachable and regular on every random model.
# The corners of validate_mujoco's sampling box (Q_SPREAD) are included.
TEST_POSES = ((0.0, 0.0), (0.1, 0.2), (-0.3, 0.4), (0.25, -0.35),
              (0.05, 0.1), (0.1, -0.05), (0.0, math.pi / 6),
              (0.3, 0.4), (-0.3, -0.4), (0.3, -0.4), (-0.3, 0.4),
              (0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5))
MAX_ACOS = 0.9
MIN_HADAMARD = 0.05
MAX_DRAWS = 1000


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def rot(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    if axis == 0:
        return ((1, 0, 0), (0, c, -s), (0, s, c))
    if axis == 1:
        return ((c, 0, s), (0, 1, 0), (-s, 0, c))
    return ((c, -s, 0), (s, c, 0), (0, 0, 1))


def matmul(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3))
                       for j in range(3)) for i in range(3))


def matvec(a, v):
    return tuple(sum(a[i][k] * v[k] for k in range(3)) for i in range(3))


def random_rotation(rng, max_angle):
    """Rz Ry Rx with each angle uniform in +-max_angle."""
    r = rot(2, rng.uniform(-max_angle, max_angle))
    r = matmul(r, rot(1, rng.uniform(-max_angle, max_angle)))
    return matmul(r, rot(0, rng.uniform(-max_angle, max_angle)))


# ---- kinematics of spec sections 4 and 12 (only what reachability needs)

def actuators(limbs, q):
    """d(q) per limb, or None where a limb cannot close (|acos arg| >
    MAX_ACOS: out of reach or too near stretch/fold for the tests)."""
    q1, q2, q3 = q
    rp = matmul(rot(0, q1), rot(1, q2))
    p = (0.0, 0.0, q3)
    d = []
    for i, (b, l1, l2, a) in enumerate(limbs):
        if i < 2:
            s = -1 if i == 0 else 1
            c = [p[k] + v for k, v in enumerate(matvec(rp, (0, s * a, 0)))]
            u = matvec(rot(0, q1), (0, s * l2, 0))
            bj = [c[k] + u[k] for k in range(3)]
            arg = s * (s * b - bj[1]) / l1
            if abs(arg) > MAX_ACOS:
                return None
            alpha = s * math.acos(arg)
            d.append(bj[2] + s * l1 * math.sin(alpha))
        else:
            gamma = math.atan2(math.sin(q2), math.cos(q1) * math.cos(q2))
            x3 = (math.cos(gamma), 0.0, -math.sin(gamma))
            sign = 1 if i == 2 else -1
            bj = [p[k] + sign * l2 * x3[k] for k in range(3)]
            arg = (bj[0] - sign * b) / l1
            if abs(arg) > MAX_ACOS:
                return None
            d.append(bj[2] + l1 * math.sin(math.acos(arg)))
    return d


def hadamard_jd(limbs, q, h=1e-6):
    """det(J_d^T J_d) / prod |column|^2 in (0, 1]: 1 for orthogonal
    columns, 0 at a singularity; invariant to the columns' units."""
    cols = []
    for k in range(3):
        qp, qm = list(q), list(q)
        qp[k] += h
        qm[k] -= h
        dp, dm = actuators(limbs, qp), actuators(limbs, qm)
        if dp is None or dm is None:
            return 0.0
        cols.append([(x - y) / (2 * h) for x, y in zip(dp, dm)])
    g = [[sum(a * b for a, b in zip(cols[i], cols[j])) for j in range(3)]
         for i in range(3)]
    det = (g[0][0] * (g[1][1] * g[2][2] - g[1][2] * g[2][1])
           - g[0][1] * (g[1][0] * g[2][2] - g[1][2] * g[2][0])
           + g[0][2] * (g[1][0] * g[2][1] - g[1][1] * g[2][0]))
    return det / (g[0][0] * g[1][1] * g[2][2])


def workspace_ok(limbs):
    return all(actuators(limbs, (q1, q2, -0.8)) is not None
               and hadamard_jd(limbs, (q1, q2, -0.8)) >= MIN_HADAMARD
               for q1, q2 in TEST_POSES)


# ---- the draws

def num(x):
    """6 significant digits: the file's text is what the tests read."""
    return float("%.6g" % x)


def draw_geometry(rng, nlimb, fmt, scale):
    """Per-limb (b, l1, l2, a); format 1 shares l1, l2, a and b of limbs 1
    and 2."""
    def one():
        l1 = PAPER_L1 * scale * rng.uniform(0.8, 1.25)
        l2 = PAPER_L2 * scale * rng.uniform(0.8, 1.25)
        a = PAPER_A * scale * rng.uniform(0.6, 1.5)
        return l1, l2, a
    if fmt == 1:
        l1, l2, a = (num(x) for x in one())
        b12 = num(a + l2 + rng.uniform(0.25, 0.55) * l1)
        b3 = num(l2 + rng.uniform(0.25, 0.55) * l1)
        return [(b12, l1, l2, a), (b12, l1, l2, a), (b3, l1, l2, 0.0)]
    limbs = []
    for i in range(nlimb):
        l1, l2, a = (num(x) for x in one())
        if i >= 2:
            a = 0.0
        b = num(a + l2 + rng.uniform(0.25, 0.55) * l1)
        limbs.append((b, l1, l2, a))
    return limbs


def body_size(name, limbs, scale):
    """A length (m) per body axis for its second moments: links are long
    along their axis (local y for limbs 1-2, local x for limbs 3-4), the
    platform spans its U joints, sliders are blocks."""
    kind, i = name[0], int(name[1:]) - 1 if len(name) > 1 else 0
    if kind == "P":
        w = max(limbs[0][3] + limbs[1][3], 0.05 * scale)
        return (w, w, 0.3 * w)
    length = limbs[i][2] if kind == "L" else limbs[i][1] if kind == "U" \
        else 0.1 * scale
    thin = 0.12 * length if kind != "S" else 0.6 * length
    return (thin, length, thin) if i < 2 else (length, thin, thin)


def draw_body(rng, name, limbs, scale, mass_factor, fmt, simple=False):
    mass = PAPER_MASS[name[0]] * mass_factor * rng.uniform(0.7, 1.3)
    size = body_size(name, limbs, scale)
    # second moments int x_k^2 dm of a uniform box of these sides, each
    # varied and kept >= 5 % of the largest: principal moments
    # I_k = sum of the other two satisfy the triangle inequality strictly
    second = [mass * (s * rng.uniform(0.7, 1.3)) ** 2 / 12 for s in size]
    top = max(second)
    second = [max(x, 0.05 * top) for x in second]
    principal = (second[1] + second[2], second[0] + second[2],
                 second[0] + second[1])
    body = {"mass": num(mass)}
    if fmt == 1:
        body["inertia"] = [num(x) for x in principal]
        return body
    if simple:
        body["inertia"] = [num(x) for x in principal] + [0, 0, 0]
        body["com"] = [0, 0, 0]
        return body
    r = random_rotation(rng, 0.4)
    t = [[sum(r[i][k] * principal[k] * r[j][k] for k in range(3))
          for j in range(3)] for i in range(3)]
    body["inertia"] = [num(x) for x in (t[0][0], t[1][1], t[2][2], t[0][1],
                                        t[0][2], t[1][2])]
    body["com"] = [num(0.15 * s * rng.uniform(-1, 1)) for s in size]
    return body


def draw_actuators(rng, nlimb, total_mass):
    """Each drive term present with probability 2/3; one number for all
    actuators or one per actuator."""
    weight = total_mass * 9.81
    out = {}

    def per(lo, hi):
        if rng.random() < 0.3:
            return num(rng.uniform(lo, hi))
        return [num(rng.uniform(lo, hi)) for _ in range(nlimb)]
    if rng.random() < 2 / 3:
        out["armature"] = per(0.005 * total_mass, 0.03 * total_mass)
    if rng.random() < 2 / 3:
        out["damping"] = per(0.5 * total_mass, 2.0 * total_mass)
    if rng.random() < 2 / 3:
        out["coulomb"] = per(0.005 * weight, 0.04 * weight)
        out["coulomb_velocity"] = num(rng.uniform(0.002, 0.01))
    return out


def draw_gravity(rng, fmt, simple=False):
    g = rng.uniform(9.0, 10.6)
    if fmt == 1:
        return num(g)
    if simple:
        return [0, 0, num(-g)]
    tilt = math.radians(rng.uniform(0, 15))
    azimuth = rng.uniform(0, 2 * math.pi)
    return [num(-g * math.sin(tilt) * math.cos(azimuth)),
            num(-g * math.sin(tilt) * math.sin(azimuth)),
            num(-g * math.cos(tilt))]


def draw_model(seed, nlimb, fmt, simple=False):
    rng = random.Random(seed)
    scale = log_uniform(rng, 0.1, 10)
    mass_factor = log_uniform(rng, 0.3, 3)
    for _ in range(MAX_DRAWS):
        limbs = draw_geometry(rng, nlimb, fmt, scale)
        if workspace_ok(limbs):
            break
    else:
        return None, scale, mass_factor
    names = model_mod.body_names(nlimb)
    bodies = {n: draw_body(rng, n, limbs, scale, mass_factor, fmt, simple)
              for n in names}
    total = sum(b["mass"] for b in bodies.values())
    doc = {}
    if fmt == 2:
        doc["format"] = 2
    doc["name"] = "rand%d" % seed
    doc["description"] = ("Random valid model (tests/random_model.py --seed "
                          "%d --limbs %d --format %d%s): size x%.3g, masses "
                          "x%.3g" % (seed, nlimb, fmt,
                                     " --structure simple" if simple else "",
                                     scale, mass_factor))
    doc["gravity"] = draw_gravity(rng, fmt, simple)
    if fmt == 1:
        doc["geometry"] = {"b12": limbs[0][0], "b3": limbs[2][0],
                           "l1": limbs[0][1], "l2": limbs[0][2],
                           "a": limbs[0][3]}
    else:
        doc["geometry"] = {"b": [l[0] for l in limbs],
                           "l1": [l[1] for l in limbs],
                           "l2": [l[2] for l in limbs],
                           "a": [limbs[0][3], limbs[1][3]]}
    doc["bodies"] = bodies
    if fmt == 2 and not simple:
        act = draw_actuators(rng, nlimb, total)
        if act:
            doc["actuators"] = act
    return doc, scale, mass_factor


def defaults(seed):
    """Limbs and format when not given: 4 limbs for odd seeds; format 1
    for one in five of the 3-limb seeds."""
    nlimb = 4 if seed % 2 else 3
    fmt = 1 if nlimb == 3 and seed % 10 == 0 else 2
    return nlimb, fmt


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--limbs", type=int, choices=(3, 4))
    ap.add_argument("--format", type=int, choices=(1, 2))
    ap.add_argument("--structure", choices=("general", "simple"))
    args = ap.parse_args(argv)
    if args.seed < 0 or args.seed >= 10 ** 12:
        ap.error("--seed must be in [0, 1e12) (the model's name is rand<seed>)")
    nlimb, fmt = defaults(args.seed)
    nlimb = args.limbs or nlimb
    fmt = args.format or (fmt if nlimb == 3 else 2)
    if fmt == 1 and nlimb == 4:
        ap.error("format 1 has 3 limbs (spec section 11)")
    structure = args.structure or ("simple" if fmt == 1 or args.seed % 10 in (4, 5)
                                   else "general")
    if fmt == 1 and structure == "general":
        ap.error("format 1 is of the simple structure (no centre-of-mass "
                 "offsets, products of inertia or drives)")
    doc, scale, mass_factor = draw_model(args.seed, nlimb, fmt,
                                         structure == "simple" and fmt == 2)
    if doc is None:
        print("random_model.py: seed %d: no geometry with the tests' "
              "workspace in %d draws" % (args.seed, MAX_DRAWS), file=sys.stderr)
        return 1
    text = json.dumps(doc, indent=1) + "\n"
    try:
        model = model_mod.parse(text, args.out)
    except model_mod.ModelError as exc:
        print("random_model.py: seed %d: the generator rejects the model: %s"
              % (args.seed, exc), file=sys.stderr)
        return 1
    if model.warnings():
        print("random_model.py: seed %d: %s" % (args.seed, model.warnings()),
              file=sys.stderr)
        return 1
    out_dir = os.path.dirname(os.path.abspath(args.out))
    fd, tmp = tempfile.mkstemp(dir=out_dir, prefix=".random_model.")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, args.out)
    print("%s: seed %d, %d limbs, format %d, %s structure, size x%.3g, "
          "masses x%.3g" % (args.out, args.seed, nlimb, fmt, structure, scale,
                            mass_factor))
    return 0


if __name__ == "__main__":
    sys.exit(main())
