#!/usr/bin/env bash
# tests/random_model.py, the seeded generator of valid model files that
# tests/random_models.sh feeds to this suite: over 40 seeds every file is
# accepted by the generator's own validation (gen/prrugen/model.py) without
# warnings, the same seed writes the same bytes, and the draws cover what
# the generic suite must hold for: 3 and 4 limbs, format 1 and 2, products
# of inertia, centres of mass, drives, tilted gravity, sizes and masses
# over more than a decade, and the simple structure (no centre-of-mass
# offsets, products of inertia or drives, gravity along -z) of the
# topology kernels' variant in format 2 with both numbers of limbs.
. "$(dirname "$0")/cli_lib.sh"

python3 - "$PRRU_SOURCE_DIR" "$tmp" <<'PY' && ok || bad "random_model.py: see above"
import json, os, subprocess, sys
src, tmp = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.join(src, 'gen'))
from prrugen import model as model_mod
gen = os.path.join(src, 'tests', 'random_model.py')
seen = {'limbs': set(), 'format': set(), 'products': 0, 'com': 0, 'drives': 0, 'tilt': 0,
        'simple': set()}
lengths, masses, errs = [], [], []
for seed in range(40):
    out = os.path.join(tmp, 'r%d.json' % seed)
    r = subprocess.run([sys.executable, gen, '--seed', str(seed), '--out', out], capture_output=True, text=True)
    if r.returncode != 0:
        errs.append('seed %d: exit %d: %s' % (seed, r.returncode, r.stderr.strip()))
        continue
    text = open(out).read()
    subprocess.run([sys.executable, gen, '--seed', str(seed), '--out', out + '.2'], check=True, capture_output=True)
    if open(out + '.2').read() != text:
        errs.append('seed %d: a second run writes other bytes' % seed)
    m = model_mod.parse(text, out)
    if m.warnings():
        errs.append('seed %d: warnings %s' % (seed, m.warnings()))
    seen['limbs'].add(m.nlimb)
    seen['format'].add(m.format)
    seen['products'] += any(any(t[3:]) for t in m.inertias)
    seen['com'] += any(any(c) for c in m.coms)
    seen['drives'] += m.has_drives
    seen['tilt'] += m.gravity[0] != 0 or m.gravity[1] != 0
    if m.format == 2 and not (any(any(t[3:]) for t in m.inertias) or any(any(c) for c in m.coms)
                              or m.has_drives or m.gravity[0] or m.gravity[1]):
        seen['simple'].add(m.nlimb)
    lengths.append(float(m.limbs[0].l1))
    masses.append(float(m.total_mass))
if errs:
    sys.exit('\n'.join(errs[:5]))
if seen['limbs'] != {3, 4} or seen['format'] != {1, 2}:
    sys.exit('limbs %s, formats %s' % (seen['limbs'], seen['format']))
if min(seen['products'], seen['com'], seen['drives'], seen['tilt']) < 10:
    sys.exit('too few models with products/com/drives/tilt: %s' % seen)
if seen['simple'] != {3, 4}:
    sys.exit('format-2 models of the simple structure with %s limbs only' % sorted(seen['simple']))
if max(lengths) / min(lengths) < 10 or max(masses) / min(masses) < 3:
    sys.exit('sizes x%.3g, masses x%.3g apart' % (max(lengths) / min(lengths), max(masses) / min(masses)))
PY
# bad arguments: exit 2, named
python3 "$PRRU_SOURCE_DIR/tests/random_model.py" --seed 1 --limbs 4 --format 1 --out "$tmp/x.json" 2>"$tmp/err"
[ $? -eq 2 ] && grep -q "format 1 has 3 limbs" "$tmp/err" && [ ! -e "$tmp/x.json" ] && ok || bad "--limbs 4 --format 1: $(cat "$tmp/err")"
finish test_random_model
