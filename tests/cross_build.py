#!/usr/bin/env python3
"""One build, any model: `prru --model FILE eval` on one build against the
build specialised for FILE (its constant-folded kernels), state by state.

usage: cross_build.py PRRU_ANY PRRU_SPECIALISED MODEL_FILE

PRRU_ANY evaluates MODEL_FILE with its topology's parameter kernels (the
file is not the build's model: the test fails if PRRU_ANY says otherwise);
PRRU_SPECIALISED is the CLI of a build generated from MODEL_FILE. Both
evaluate the same exact function of the same numbers by different
straight-line programs, so each is within its rounding of the exact value
and they differ by at most the sum. The bounds, per output, in the unit
roundoff u = 2^-53 with K = 256 (test_trust's multiple, the same as the
in-build comparison of the two kernel paths in test_model_load):

  kernel outputs y (M, h, G, d, J_d): |y_a - y_s| <= 2 K u max|y|
      each entry is a sum of products of the model's numbers and
      trigonometric functions of q whose terms are bounded by the
      output's own scale at the regular, well-inside states drawn here;
  qdd: |dqdd| <= 2 K u (kappa_1(M) |qdd| + |M^-1|_1 S),
      S = |h| + |G| + max_j sum_i |J_d,ij fd_i| (infinity norms): the
      forward solve's first-order perturbation bound for errors of
      relative size K u in M and in the terms of b = J_d^T fd - h - G;
  lambda: |dlambda| <= 2 KR u kappa_1(M_s) max(|lambda|, W),
      KR = 1024 (test_reactions' multiple), M_s = D^-1 M D^-1 with
      D = diag(L, L, 1) (L the mean upper link: prru_mass_rcond's
      scaling), W = the machine's weight m |g|: the reactions solve
      through M, and a reaction near 0 is compared at the size of the
      forces the joints carry.

A failure prints the state, the output, the difference and its bound.
"""
import json
import math
import random
import subprocess
import sys

U = 2.0 ** -53
K = 256.0
KR = 1024.0


def norm_inf(v):
    return max((abs(x) for x in v), default=0.0)


def flat(x):
    if isinstance(x, list):
        out = []
        for e in x:
            out.extend(flat(e))
        return out
    return [x]


def inverse3(a):
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = a
    c = [[a11 * a22 - a12 * a21, a02 * a21 - a01 * a22, a01 * a12 - a02 * a11],
         [a12 * a20 - a10 * a22, a00 * a22 - a02 * a20, a02 * a10 - a00 * a12],
         [a10 * a21 - a11 * a20, a01 * a20 - a00 * a21, a00 * a11 - a01 * a10]]
    det = a00 * c[0][0] + a01 * c[1][0] + a02 * c[2][0]
    return [[c[i][j] / det for j in range(3)] for i in range(3)]


def norm1(a):
    return max(sum(abs(a[i][j]) for i in range(3)) for j in range(3))


def evaluate(prru, model, q, qd, fd):
    cmd = [prru] + (["--model", model] if model else []) + [
        "eval", "--q", ",".join(repr(x) for x in q), "--qd", ",".join(repr(x) for x in qd),
        "--fd", ",".join(repr(x) for x in fd)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, "%s: exit %d: %s" % (" ".join(cmd), p.returncode, p.stderr.strip())
    return json.loads(p.stdout), None


def main(argv):
    if len(argv) != 4:
        sys.stderr.write(__doc__)
        return 2
    any_build, specialised, model = argv[1:]
    with open(model, encoding="utf-8") as f:
        spec = json.load(f)
    # The file's own numbers (spec sections 11-12): limbs from the bodies,
    # L the mean upper link, W the machine's weight.
    n = (len(spec["bodies"]) - 1) // 3
    l1 = spec["geometry"]["l1"]
    l1 = l1 if isinstance(l1, list) else [l1] * n
    L = sum(l1) / n
    g = spec["gravity"]
    W = sum(b["mass"] for b in spec["bodies"].values()) * (
        math.sqrt(sum(x * x for x in g)) if isinstance(g, list) else g)
    rng = random.Random(20261127)
    failures = checked = 0
    worst = {}

    def note(key, diff, bound):
        worst[key] = max(worst.get(key, 0.0), diff / bound if bound > 0 else math.inf)
    home, err = evaluate(specialised, None, [0.0, 0.0, -1.5 * L], [0, 0, 0], [0] * n)
    if home is None:
        print("FAIL", err)
        return 1
    nact = len(home["d"])
    for k in range(400):
        q = [rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), -L * rng.uniform(1.2, 2.4)]
        qd = [rng.uniform(-1, 1) for _ in range(3)]
        fd = [rng.uniform(-60, 60) for _ in range(nact)]
        s, err_s = evaluate(specialised, None, q, qd, fd)
        if s is None or s.get("Jd_rcond", 0) < 0.05 or "qdd" not in s or s["qdd"] is None:
            continue  # a state the specialised build itself does not trust: not drawn
        a, err_a = evaluate(any_build, model, q, qd, fd)
        if a is None:
            print("FAIL q=%r: the build evaluating any model refused what the specialised one "
                  "evaluates: %s" % (q, err_a))
            failures += 1
            continue
        if checked == 0:
            if a["model"]["kernels"] != "parameter" or s["model"]["kernels"] != "specialised":
                print("FAIL kernels: %s and %s (expected parameter and specialised)"
                      % (a["model"]["kernels"], s["model"]["kernels"]))
                return 1
            if a["model"]["sha256"] != s["model"]["sha256"]:
                print("FAIL the two builds name different model files")
                return 1
        checked += 1
        M = s["M"]
        for key in ("M", "h", "G", "d", "Jd"):
            ys, ya = flat(s[key]), flat(a[key])
            bound = 2 * K * U * norm_inf(ys)
            diff = max(abs(x - y) for x, y in zip(ys, ya))
            note(key, diff, bound)
            if len(ys) != len(ya) or not diff <= bound:
                print("FAIL q=%r %s: |diff| %.3g > bound %.3g" % (q, key, diff, bound))
                failures += 1
        Minv = inverse3(M)
        kappa = norm1(M) * norm1(Minv)
        Jd = s["Jd"]
        sj = max(sum(abs(Jd[i][j] * fd[i]) for i in range(nact)) for j in range(3))
        S = norm_inf(s["h"]) + norm_inf(s["G"]) + sj + norm_inf(s["passive"])
        bq = 2 * K * U * (kappa * norm_inf(s["qdd"]) + norm1(Minv) * S)
        dq = max(abs(x - y) for x, y in zip(s["qdd"], a["qdd"]))
        note("qdd", dq, bq)
        if not dq <= bq:
            print("FAIL q=%r qdd: |diff| %.3g > bound %.3g" % (q, dq, bq))
            failures += 1
        D = [L, L, 1.0]
        Ms = [[M[i][j] / (D[i] * D[j]) for j in range(3)] for i in range(3)]
        kappa_s = norm1(Ms) * norm1(inverse3(Ms))
        ls, la = s["lambda"], a["lambda"]
        bl = 2 * KR * U * kappa_s * max(norm_inf(ls), W)
        dl = max(abs(x - y) for x, y in zip(ls, la))
        note("lambda", dl, bl)
        if len(ls) != len(la) or not dl <= bl:
            print("FAIL q=%r lambda: |diff| %.3g > bound %.3g" % (q, dl, bl))
            failures += 1
        if checked >= 12:
            break
    if checked < 12:
        print("FAIL only %d regular states found" % checked)
        return 1
    print("%s: %d states, %s (parameter kernels) against %s (specialised): %s; worst "
          "difference / bound: %s" % (model, checked, any_build, specialised,
                                      "FAILED" if failures else "ok",
                                      ", ".join("%s %.2g" % kv for kv in sorted(worst.items()))))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
