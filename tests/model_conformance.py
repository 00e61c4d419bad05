#!/usr/bin/env python3
"""The C model loader (prru_model_file_read, through tests/model_file_dump)
against the generator's reading (gen/prrugen/model.py load) over the
conformance corpus (tests/models/conformance: valid/ must be accepted and
invalid/ refused by the generator), the committed models and a file over
the 1 MiB limit. Required of the C side: the same accept/refuse; for a
refused file the same message, except a plain JSON syntax error, which each
JSON parser words in its own way (both must say "path: not valid JSON: ");
for an accepted file every number bitwise equal to float() of the
generator's exact value, the same file SHA-256 and the same canonical
SHA-256 (model.canonical_sha256).

usage: model_conformance.py DUMP_PROGRAM REPO_ROOT"""

import glob
import json
import os
import re
import struct
import subprocess
import sys
import tempfile


def python_side(model, path):
    try:
        m = model.load(path)
    except model.ModelError as exc:
        return {"ok": False, "message": str(exc)}
    f = float
    dr = m.drives
    return {"ok": True, "name": m.name, "description": m.description,
            "format": m.format, "nlimb": m.nlimb,
            "gravity": [f(x) for x in m.gravity],
            "limbs": [[f(l.b), f(l.l1), f(l.l2), f(l.a)] for l in m.limbs],
            "masses": [f(x) for x in m.masses],
            "coms": [[f(x) for x in c] for c in m.coms],
            "inertias": [[f(x) for x in i] for i in m.inertias],
            "armature": [f(x) for x in m.armature],
            "damping": [f(x) for x in m.damping],
            "coulomb": [f(x) for x in m.coulomb],
            "coulomb_velocity": f(m.coulomb_velocity or 0),
            "drive_keys": list(dr.keys),
            "lead": [f(x or 0) for x in dr.lead],
            "gear": [f(x) for x in dr.gear],
            "rotor_inertia": [f(x or 0) for x in dr.rotor_inertia],
            "torque_constant": [f(x or 0) for x in dr.torque_constant],
            "d_min": [dr.stroke_limits(i)[0] for i in range(m.nlimb)],
            "d_max": [dr.stroke_limits(i)[1] for i in range(m.nlimb)],
            "torque_max": [f(x or 0) for x in dr.torque_max],
            "motor_speed_max": [f(x or 0) for x in dr.motor_speed_max],
            "force_max": [dr.force_limit(i) for i in range(m.nlimb)],
            "speed_max": [dr.speed_limit(i) for i in range(m.nlimb)],
            "sha256": m.sha256, "canonical_sha256": model.canonical_sha256(m)}


def bits(value):
    """Numbers as their binary64 bit patterns, recursively."""
    if isinstance(value, float) or (isinstance(value, int)
                                    and not isinstance(value, bool)):
        return struct.pack("<d", float(value)).hex()
    if isinstance(value, list):
        return [bits(v) for v in value]
    return value


SYNTAX_PY = re.compile(r": not valid JSON: .*: line \d+ column \d+ \(char \d+\)$")
SYNTAX_C = re.compile(r": not valid JSON: .* \(line \d+, column \d+\)$")


def compare(py, c, path):
    if py["ok"] != c["ok"]:
        return "python %s, C %s" % (py.get("message", "accepts"),
                                    c.get("message", "accepts"))
    if not py["ok"]:
        if py["message"] == c["message"]:
            return None
        if SYNTAX_PY.search(py["message"]) and SYNTAX_C.search(c["message"]):
            return None
        return "messages differ:\n  python: %s\n  C:      %s" % (py["message"],
                                                               c["message"])
    for key in py:
        if key == "ok":
            continue
        if key in ("format", "nlimb", "drive_keys"):
            same = py[key] == c[key]
        else:
            same = bits(py[key]) == bits(c[key])
        if not same:
            return "%s differs: python %r, C %r" % (key, py[key], c[key])
    return None


def main():
    dump, root = sys.argv[1], sys.argv[2]
    sys.path.insert(0, os.path.join(root, "gen"))
    from prrugen import model
    corpus = os.path.join(root, "tests", "models", "conformance")
    files = [(p, True) for p in sorted(glob.glob(os.path.join(corpus, "valid", "*.json")))]
    files += [(p, False) for p in sorted(glob.glob(os.path.join(corpus, "invalid", "*.json")))]
    files += [(p, True) for p in sorted(glob.glob(os.path.join(root, "models", "*.json")))]
    tmp = tempfile.mkdtemp()
    big = os.path.join(tmp, "big.json")
    with open(big, "w") as f:
        f.write(" " * (model.MAX_BYTES + 1))
    files += [(big, False), (os.path.join(tmp, "missing.json"), False)]
    failures = 0
    for path, valid in files:
        py = python_side(model, path)
        if py["ok"] != valid:
            print("FAIL %s: the generator %s it" % (
                path, "refuses" if valid else "accepts"))
            failures += 1
            continue
        out = subprocess.run([dump, path], capture_output=True, text=True,
                             check=True).stdout
        c = json.loads(out)
        why = compare(py, c, path)
        if why:
            print("FAIL %s: %s" % (path, why))
            failures += 1
        elif not valid:
            print("ok   %s: %s" % (os.path.basename(path), c["message"][:110]))
    # A layout edit keeps the canonical hash; a number edit changes it.
    paper = model.load(os.path.join(root, "models", "3prru_paper.json"))
    reordered = model.load(os.path.join(corpus, "valid", "paper_reordered.json"))
    exponents = model.load(os.path.join(corpus, "valid", "paper_exponents.json"))
    bumped = model.parse(open(os.path.join(root, "models", "3prru_paper.json"))
                         .read().replace("1.31", "1.3100000000000003"))
    if not (model.canonical_sha256(paper) == model.canonical_sha256(reordered)
            == model.canonical_sha256(exponents) != model.canonical_sha256(bumped)
            and paper.sha256 != reordered.sha256):
        print("FAIL canonical hash: layout edits must keep it, number edits change it")
        failures += 1
    os.remove(big)
    os.rmdir(tmp)
    print("%d files, %d failures" % (len(files), failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
