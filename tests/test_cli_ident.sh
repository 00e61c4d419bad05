#!/usr/bin/env bash
# prru excite and prru identify on the model the binary was built from:
#  - excite: exit 0, the model line, its columns, no NaN, the bounds it was
#    given (amplitudes, force limits), byte-identical on a second run, and
#    its fd columns are what `prru id --traj` computes for its q, qd, qdd;
#  - identify on excite's own (noise-free) data: every base parameter equals
#    the model's combination to 16 eps cond (relative, or of its resolution), the
#    written model file is accepted by the generator;
#  - with Gaussian noise (sigma 0.5 N, seeded) on the forces: every base
#    parameter within 4 of its reported standard errors of the truth, the
#    residual sigma within 5 % of 0.5 N;
#  - from t, the sliders d and fd alone (forward kinematics and
#    Savitzky-Golay derivatives at 2 ms): within 1e-5;
#  - prru measure on a tracked run (quantised d, noisy forces, 500 Hz):
#    readings against the run, the suggested window, and identify from them
#    writing a model that loads, within 4 se of the exact-rate fit;
#  - bad input: messages naming the option, file and row, exit 2 or 1, and
#    no model file written (an old one kept).
# shellcheck source=tests/cli_lib.sh
. "$(dirname "$0")/cli_lib.sh"

fds=$(act_names fd)
ds=$(act_names d)

# ---- excite ----
"$PRRU" excite --evals 400 --period 8 --harmonics 4 --amplitude 0.2,0.2,0.02 --fd-max "$(nlist 400)" \
  --out "$tmp/ex.csv" 2>"$tmp/ex.err" && ok || bad "excite: $(cat "$tmp/ex.err")"
[ "$(head -n 1 "$tmp/ex.csv")" = "$csv_comment" ] && ok || bad "excite: model line: $(head -n 1 "$tmp/ex.csv")"
grep -qx "t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3,$ds,$fds" "$tmp/ex.csv" && ok || bad "excite: header"
grep -qi nan "$tmp/ex.csv" && bad "excite: NaN written" || ok
grep -q "condition number" "$tmp/ex.err" && ok || bad "excite: no summary on stderr"
python3 - "$tmp/ex.csv" "$nact" <<'PY' && ok || bad "excite: bounds or row count"
import csv, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith('#'))]
head, data = rows[0], [[float(x) for x in r] for r in rows[1:]]
col = {n: i for i, n in enumerate(head)}
n = int(sys.argv[2])
assert len(data) == 801, len(data)                  # 8 s at 0.01 s, both ends
assert abs(data[-1][0] - 8.0) < 1e-12
for r in data:
    assert abs(r[col['q1']]) <= 0.2 + 1e-12 and abs(r[col['q2']]) <= 0.2 + 1e-12
    assert abs(r[col['q3']]) <= 0.02 + 1e-12
    assert all(abs(r[col['fd%d' % (i + 1)]]) <= 400 for i in range(n))
# periodic: the last row is the first
assert all(abs(a - b) <= 1e-9 * (1 + abs(b)) for a, b in zip(data[0][1:10], data[-1][1:10]))
PY
"$PRRU" excite --evals 400 --period 8 --harmonics 4 --amplitude 0.2,0.2,0.02 --fd-max "$(nlist 400)" \
  --out "$tmp/ex2.csv" 2>/dev/null
cmp -s "$tmp/ex.csv" "$tmp/ex2.csv" && ok || bad "excite is not deterministic"
"$PRRU" id --traj "$tmp/ex.csv" --out "$tmp/id.csv" 2>"$tmp/id.err" && ok || bad "id on excite's output: $(cat "$tmp/id.err")"
python3 - "$tmp/ex.csv" "$tmp/id.csv" "$nact" <<'PY' && ok || bad "excite's fd differ from prru id's"
import csv, sys
def table(p):
    rows = list(csv.reader(l for l in open(p) if not l.startswith('#')))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]
ha, a = table(sys.argv[1]); hb, b = table(sys.argv[2])
n = int(sys.argv[3])
scale = max(abs(r[ha.index('fd1')]) for r in a)
err = max(abs(ra[ha.index('fd%d' % (i + 1))] - rb[hb.index('fd%d' % (i + 1))])
          for ra, rb in zip(a, b) for i in range(n))
assert len(a) == len(b) and err <= 1e-12 * scale, err
PY

# ---- identify, noise-free ----
"$PRRU" identify --data "$tmp/ex.csv" --out "$tmp/id.json" --report "$tmp/rep.csv" 2>"$tmp/idf.err" \
  && ok || bad "identify: $(cat "$tmp/idf.err")"
[ "$(head -n 1 "$tmp/rep.csv")" = "$csv_comment" ] && ok || bad "identify: report model line"
# check_report FILE TOL SIGMAS: |estimate - prior| <= TOL max(|prior|,
# resolution) + SIGMAS se for every base parameter. TOL "cond" is the
# rounding of a least-squares fit to exact data: 16 eps cond, cond the
# report's 2-norm condition number of the column-scaled regressor (a
# backward-stable solve moves the scaled estimates by ~eps cond times the
# data's relative rounding, which is a few eps of the forces' terms: 16
# allows terms 16x the forces they sum to); in units of the resolution
# (the value giving forces of the data's RMS size) or of the prior.
check_report() {
  python3 - "$1" "$2" "$3" <<'PY'
import csv, re, sys
text = open(sys.argv[1]).read()
rows = list(csv.DictReader(l for l in text.splitlines() if not l.startswith('#')))
k = float(sys.argv[3])
if sys.argv[2] == 'cond':
    tol = 16 * sys.float_info.epsilon * float(re.search(r'condition number ([0-9.e+-]+)', text).group(1))
else:
    tol = float(sys.argv[2])
assert len(rows) > 10
worst = 0
for r in rows:
    e, p, se, res = (float(r[x]) for x in ('estimate', 'prior', 'se', 'resolution'))
    bound = tol * max(abs(p), res) + k * se
    worst = max(worst, abs(e - p) / bound)
print(worst)
sys.exit(0 if worst <= 1 else 1)
PY
}
w=$(check_report "$tmp/rep.csv" cond 0) && ok || bad "noise-free identification: worst error / bound $w"
python3 "$PRRU_SOURCE_DIR/gen/prru_gen.py" "$tmp/id.json" --out "$tmp/gen" --quiet 2>"$tmp/gen.err" \
  && ok || bad "the identified model file is refused by the generator: $(cat "$tmp/gen.err")"
# The written model's base parameters (the report's model column) are the
# estimate's, to the same rounding rule as the estimate's own (16 eps cond
# of max(|prior|, resolution)); its masses are the model's own to what
# that rounding allows a mass: a base parameter's error spreads over the
# members of its combination, each of which it can move by up to
# 16 eps cond max(|prior_i|, res_i) (its coefficients are O(1)): relative
# to a mass, at most 16 eps cond max_i max(1, res_i / |prior_i|).
python3 - "$tmp/id.json" "$PRRU_MODEL" "$tmp/rep.csv" <<'PY' && ok || bad "identified model: base parameters or masses off"
import csv, json, re, sys
a = json.load(open(sys.argv[1])); m = json.load(open(sys.argv[2]))
text = open(sys.argv[3]).read()
rows = list(csv.DictReader(l for l in text.splitlines() if not l.startswith('#')))
tol = 16 * sys.float_info.epsilon * float(re.search(r'condition number ([0-9.e+-]+)', text).group(1))
spread = 1.0
for r in rows:
    e, p, res, mod = (float(r[x]) for x in ('estimate', 'prior', 'resolution', 'model'))
    assert abs(mod - e) <= tol * max(abs(p), res), (r['parameter'], mod, e)
    if p != 0:
        spread = max(spread, res / abs(p))
for name, body in m["bodies"].items():
    assert abs(a["bodies"][name]["mass"] - body["mass"]) <= tol * spread * body["mass"], \
        (name, a["bodies"][name]["mass"], body["mass"], tol * spread)
PY

# ---- issue 27 item 2: the most common CAD error ----
# The true robot's masses x1.05: prru track's plant as the robot, its log
# (q, qd, the plant's qdd, fd: exact rates) as data. The least-squares
# change of each base parameter loaded onto one standard parameter made
# armature3 negative (exit 1, no model); the consistent fit writes a model
# the generator accepts, whose base parameters are the estimate's within
# rounding: d^2 <= 1 (the model without drives puts the truth on the
# drives' bound, so the estimate is a rounding outside it; the fit moves
# it back by ~1e-12 of the drives' scale, d^2 ~ 1e-5 on the paper model).
"$PRRU" excite --out "$tmp/exd.csv" 2>/dev/null
"$PRRU" track --ref "$tmp/exd.csv" --mismatch mass=1.05 --out "$tmp/cad.csv" >/dev/null 2>&1
"$PRRU" identify --data "$tmp/cad.csv" --out "$tmp/cad.json" --report "$tmp/cadrep.csv" 2>"$tmp/cad.err" \
  && ok || bad "identify, masses x1.05: $(cat "$tmp/cad.err")"
python3 "$PRRU_SOURCE_DIR/gen/prru_gen.py" "$tmp/cad.json" --out "$tmp/cadgen" --quiet 2>"$tmp/cadgen.err" \
  && ok || bad "the model identified with masses x1.05 is refused by the generator: $(cat "$tmp/cadgen.err")"
d2=$(sed -n 's/.*Mahalanobis distance^2 of its base parameters to the estimate \([^,]*\),.*/\1/p' "$tmp/cadrep.csv")
awk -v d="$d2" 'BEGIN { exit !(d != "" && d + 0 <= 1) }' && ok || bad "masses x1.05: d^2 '$d2' > 1"

# ---- issue 27 item 3: measurements (prru measure) ----
# The masses-x1.05 run as the sensors see it: encoders of 1 um on d, 0.2 N
# of force noise, 500 Hz (every other row of track's 1 ms).
"$PRRU" measure --run "$tmp/cad.csv" --out "$tmp/meas.csv" --rate 500 --d-resolution 1e-6 --force-noise 0.2 \
  --seed 3 2>"$tmp/meas.err" && ok || bad "measure: $(cat "$tmp/meas.err")"
"$PRRU" measure --run "$tmp/cad.csv" --out "$tmp/meas2.csv" --rate 500 --d-resolution 1e-6 --force-noise 0.2 \
  --seed 3 2>/dev/null && cmp -s "$tmp/meas.csv" "$tmp/meas2.csv" && ok || bad "measure: a seed gives other bytes"
"$PRRU" measure --run "$tmp/cad.csv" --out "$tmp/meas3.csv" --rate 500 --d-resolution 1e-6 --force-noise 0.2 \
  --seed 4 2>/dev/null && ! cmp -s "$tmp/meas.csv" "$tmp/meas3.csv" && ok || bad "measure: seeds 3 and 4 agree"
# The readings against the run: every other row; d on the 1 um grid and
# within half a count of the truth; the force errors' mean and standard
# deviation those of N(0, 0.2^2) over n samples (within 5 standard errors:
# 5 sigma / sqrt(n) for the mean, 5 sigma / sqrt(2 n) for the deviation);
# the suggested window's qdd error at most the default's.
python3 - "$tmp/cad.csv" "$tmp/meas.csv" "$nact" <<'PY' && ok || bad "measure: readings (above)"
import csv, math, sys
def rows(f):
    return list(csv.DictReader(l for l in open(f) if not l.startswith('#')))
run, meas, nact = rows(sys.argv[1]), rows(sys.argv[2]), int(sys.argv[3])
lines = open(sys.argv[2]).read().splitlines()
assert lines[2].startswith('# for identify: --window'), lines[2]
w = lines[2].split()
best, default = float(w[11]), float(w[-1].rstrip(')'))
assert best <= default, (best, default)
assert list(meas[0]) == ['t'] + ['d%d' % (i + 1) for i in range(nact)] + ['fd%d' % (i + 1) for i in range(nact)]
assert len(meas) == (len(run) - 1) // 2 + 1, (len(meas), len(run))
errs = []
for k, m in enumerate(meas):
    r = run[2 * k]
    assert float(m['t']) == float(r['t']), (k, m['t'], r['t'])
    for i in range(1, nact + 1):
        d, dt = float(m['d%d' % i]), float(r['d%d' % i])
        assert abs(d / 1e-6 - round(d / 1e-6)) < 1e-6 and abs(d - dt) <= 0.5e-6 * (1 + 1e-9), (k, i, d, dt)
        errs.append(float(m['fd%d' % i]) - float(r['fd%d' % i]))
n = len(errs)
mean = sum(errs) / n
sd = math.sqrt(sum((e - mean) ** 2 for e in errs) / (n - 1))
assert abs(mean) <= 5 * 0.2 / math.sqrt(n), mean
assert abs(sd - 0.2) <= 5 * 0.2 / math.sqrt(2 * n), sd
PY
win=$(sed -n 's/^# for identify: \(--window [0-9]* --degree [0-9]* --d-resolution [0-9.e+-]*\) .*/\1/p' "$tmp/meas.csv")
# identify with the suggested window writes a model that loads (the fit
# left L3 on the consistent set's boundary, a principal moment below the
# file's 1e-9, written as 0: a model nothing could load), and its base
# parameters lie within 4 standard errors of the exact-rate fit's
# (cadrep.csv: the truth's own, to rounding).
# shellcheck disable=SC2086
"$PRRU" identify --data "$tmp/meas.csv" $win --out "$tmp/mid.json" --report "$tmp/midrep.csv" 2>"$tmp/mid.err" \
  && ok || bad "identify on measured data ($win): $(cat "$tmp/mid.err")"
"$PRRU" --model "$tmp/mid.json" version >/dev/null 2>"$tmp/midv.err" && ok \
  || bad "the model identified from measured data does not load: $(cat "$tmp/midv.err")"
python3 - "$tmp/cadrep.csv" "$tmp/midrep.csv" <<'PY' && ok || bad "measured identification: base parameters (above)"
import csv, sys
def rd(f):
    return {r['parameter']: r for r in csv.DictReader(l for l in open(f) if not l.startswith('#'))}
exact, meas = rd(sys.argv[1]), rd(sys.argv[2])
worst = max((abs(float(meas[k]['estimate']) - float(exact[k]['estimate'])) / float(meas[k]['se']), k) for k in exact)
assert worst[0] <= 4, worst
PY
# The default window on quantised encoders: identify's refusal now names
# the differentiation, not only the force signs.
"$PRRU" identify --data "$tmp/meas.csv" --d-resolution 1e-6 --out "$tmp/mid4.json" --report "$tmp/mid4rep.csv" 2>"$tmp/mid4.err"
st=$?
if [ $st = 0 ]; then ok; else
  [ $st = 1 ] && grep -q "differentiated from q (--window 4 --degree 4).*prru measure" "$tmp/mid4.err" && ok \
    || bad "identify's refusal on differentiated data: exit $st: $(cat "$tmp/mid4.err")"
fi
# Four quantised sliders disagree by up to the resolution: without
# --d-resolution the first row has no pose, and the message says what to give.
if [ "$nact" = 4 ]; then
  "$PRRU" identify --data "$tmp/meas.csv" --out "$tmp/mid5.json" --report "$tmp/mid5rep.csv" 2>"$tmp/mid5.err"
  [ $? = 1 ] && grep -q "data row 1: no pose for the sliders.*give --d-resolution" "$tmp/mid5.err" && ok \
    || bad "4 quantised sliders without --d-resolution: $(cat "$tmp/mid5.err")"
fi
"$PRRU" identify --data "$tmp/meas.csv" --d-resolution 0 --out "$tmp/mid6.json" 2>"$tmp/mid6.err"
[ $? = 2 ] && grep -q -- "--d-resolution: 0 must be positive" "$tmp/mid6.err" && ok \
  || bad "identify --d-resolution 0: $(cat "$tmp/mid6.err")"
# Bad input: named, exit 2, the old output kept.
echo keep >"$tmp/keep.csv"
"$PRRU" measure --run "$tmp/cad.csv" --out "$tmp/keep.csv" --rate 300 2>"$tmp/e1"
[ $? = 2 ] && grep -q "rate 300: no row at t = " "$tmp/e1" && [ "$(cat "$tmp/keep.csv")" = keep ] && ok \
  || bad "measure --rate off the run's clock: $(cat "$tmp/e1")"
"$PRRU" measure --run "$tmp/cad.csv" --out "$tmp/keep.csv" --force-noise -1 2>"$tmp/e2"
[ $? = 2 ] && grep -q -- "--force-noise" "$tmp/e2" && [ "$(cat "$tmp/keep.csv")" = keep ] && ok \
  || bad "measure --force-noise -1: $(cat "$tmp/e2")"
cut -d, -f1-4 "$tmp/cad.csv" >"$tmp/nofd.csv"
"$PRRU" measure --run "$tmp/nofd.csv" --out "$tmp/keep.csv" 2>"$tmp/e3"
[ $? = 2 ] && grep -q "nofd.csv: missing column 'd1'" "$tmp/e3" && [ "$(cat "$tmp/keep.csv")" = keep ] && ok \
  || bad "measure on a run without d, fd: $(cat "$tmp/e3")"
"$PRRU" measure --run "$tmp/cad.csv" --out "$tmp/cad.csv" 2>"$tmp/e4"
[ $? = 2 ] && ok || bad "measure --out onto --run: $(cat "$tmp/e4")"

# ---- identify from a data file whose path is hostile to the model file ----
# The description names the --data path: one with "*/" (a directory ending
# in '*'), a trigraph "??/", bytes that are not UTF-8, a quote, a backslash,
# a newline and over 600 characters in all must still give a model file
# that the generator accepts, its description still ending in the file name.
hd="$tmp/q??/star*/$(printf 'bad\377\376"\\\nname')/$(printf 'a%.0s' $(seq 200))/$(printf 'b%.0s' $(seq 200))"
mkdir -p "$hd" && ln -s "$tmp/ex.csv" "$hd/data.csv"
"$PRRU" identify --data "$hd/data.csv" --out "$tmp/hid.json" --report "$tmp/hrep.csv" 2>"$tmp/hid.err" \
  && ok || bad "identify from a hostile path: $(cat "$tmp/hid.err")"
python3 "$PRRU_SOURCE_DIR/gen/prru_gen.py" "$tmp/hid.json" --out "$tmp/hgen" --quiet 2>"$tmp/hgen.err" \
  && ok || bad "a model file identified from a hostile path is refused by the generator: $(cat "$tmp/hgen.err")"
json "$tmp/hid.json" 'd["description"]' | grep -q "/data.csv (prior: model $model_name)$" \
  && ok || bad "the description lost the data file's name: $(json "$tmp/hid.json" 'd["description"]')"

# ---- identify with noise ----
# 4 periods of data: enough samples for the noise to average.
"$PRRU" excite --evals 400 --period 8 --harmonics 4 --amplitude 0.2,0.2,0.02 --fd-max "$(nlist 400)" \
  --periods 4 --out "$tmp/ex4.csv" 2>/dev/null
python3 - "$tmp/ex4.csv" "$tmp/noisy.csv" "$nact" <<'PY'
import random, sys
rnd = random.Random(20171)
out, head = [], None
for l in open(sys.argv[1]).read().splitlines():
    if l.startswith('#'):
        out.append(l); continue
    if head is None:
        head = l.split(','); out.append(l); continue
    v = l.split(',')
    for i in range(int(sys.argv[3])):
        k = head.index('fd%d' % (i + 1))
        v[k] = repr(float(v[k]) + rnd.gauss(0, 0.5))
    out.append(','.join(v))
open(sys.argv[2], 'w').write('\n'.join(out) + '\n')
PY
"$PRRU" identify --data "$tmp/noisy.csv" --out "$tmp/idn.json" --report "$tmp/repn.csv" 2>"$tmp/idn.err" \
  && ok || bad "noisy identify: $(cat "$tmp/idn.err")"
w=$(check_report "$tmp/repn.csv" 0 4) && ok || bad "noisy identification: worst |error| / (4 se) $w"
sigma=$(sed -n 's/.*residual sigma \([0-9.e+-]*\) N.*/\1/p' "$tmp/repn.csv")
python3 -c "import sys; sys.exit(0 if abs(float(sys.argv[1]) / 0.5 - 1) < 0.05 else 1)" "$sigma" \
  && ok || bad "residual sigma $sigma, noise 0.5 N"

# ---- identify from the sliders alone ----
"$PRRU" excite --evals 400 --period 8 --harmonics 4 --amplitude 0.2,0.2,0.02 --fd-max "$(nlist 400)" \
  --dt 0.002 --out "$tmp/exf.csv" 2>/dev/null
python3 - "$tmp/exf.csv" "$tmp/d.csv" "$nact" <<'PY'
import sys
n = int(sys.argv[3])
keep = ['t'] + ['d%d' % (i + 1) for i in range(n)] + ['fd%d' % (i + 1) for i in range(n)]
out, idx = [], None
for l in open(sys.argv[1]).read().splitlines():
    if l.startswith('#'):
        out.append(l); continue
    v = l.split(',')
    if idx is None:
        idx = [v.index(k) for k in keep]
    out.append(','.join(v[i] for i in idx))
open(sys.argv[2], 'w').write('\n'.join(out) + '\n')
PY
"$PRRU" identify --data "$tmp/d.csv" --out "$tmp/idd.json" --report "$tmp/repd.csv" 2>"$tmp/idd.err" \
  && ok || bad "identify from d: $(cat "$tmp/idd.err")"
w=$(check_report "$tmp/repd.csv" 1e-5 0) && ok || bad "identification from d and fd: worst error / bound $w"

# ---- bad input ----
echo old >"$tmp/keep.json"
expect 2 "--data and --out are required" -- identify --data "$tmp/ex.csv"
cut -d, -f1-13 "$tmp/ex.csv" >"$tmp/nofd.csv"
expect 2 "missing column 'fd1'" -- identify --data "$tmp/nofd.csv" --out "$tmp/keep.json"
# (ex.csv: the model line, the limits line, 4 comment lines, the header, then data rows)
awk -F, 'BEGIN{OFS=","} /^#/ {print; next} NR==10 {$2=2.5} {print}' "$tmp/ex.csv" >"$tmp/far.csv"
expect 1 "data row 3" -- identify --data "$tmp/far.csv" --out "$tmp/keep.json"
grep -q "not reachable" "$tmp/err" && ok || bad "unreachable row: reason missing: $(cat "$tmp/err")"
awk -F, 'BEGIN{OFS=","} /^#/ {print; next} NR==9 {$1=0} {print}' "$tmp/ex.csv" >"$tmp/time.csv"
expect 2 "is not after the previous row's" -- identify --data "$tmp/time.csv" --out "$tmp/keep.json"
head -n 12 "$tmp/ex.csv" >"$tmp/short.csv"
expect 1 "fewer than the" -- identify --data "$tmp/short.csv" --out "$tmp/keep.json"
python3 - "$tmp/ex.csv" "$tmp/flip.csv" <<'PY'
import sys
out, head = [], None
for l in open(sys.argv[1]).read().splitlines():
    if l.startswith('#'):
        out.append(l); continue
    if head is None:
        head = l.split(','); out.append(l); continue
    v = l.split(',')
    for k, name in enumerate(head):
        if name.startswith('fd'):
            v[k] = repr(-float(v[k]))
    out.append(','.join(v))
open(sys.argv[2], 'w').write('\n'.join(out) + '\n')
PY
expect 1 "the data contradict physics" -- identify --data "$tmp/flip.csv" --out "$tmp/keep.json" --report "$tmp/flip_rep.csv"
grep -q "Mahalanobis distance^2 .*above the chi^2 quantile" "$tmp/err" && ok || bad "flipped signs: no evidence: $(cat "$tmp/err")"
[ "$(cat "$tmp/keep.json")" = old ] && ok || bad "a refused identification changed the model file"
expect 2 "both go to stdout" -- identify --data "$tmp/ex.csv" --out -
# Issue 30 item 4: the data file as --out or --report (by device and
# inode: ./f and f alike) is refused, the data as they were.
cp "$tmp/ex.csv" "$tmp/exs.csv"
expect 2 "--data $tmp/exs.csv and --out $tmp/./exs.csv are the same file" -- identify --data "$tmp/exs.csv" --out "$tmp/./exs.csv"
expect 2 "--data $tmp/exs.csv and --report $tmp//exs.csv are the same file" -- identify --data "$tmp/exs.csv" \
  --out "$tmp/x.json" --report "$tmp//exs.csv"
echo old >"$tmp/rep_same.csv"
expect 2 "are the same file" -- identify --data "$tmp/ex.csv" --out "$tmp/rep_same.csv" --report "$tmp/./rep_same.csv"
cmp -s "$tmp/ex.csv" "$tmp/exs.csv" && [ "$(cat "$tmp/rep_same.csv")" = old ] && ok || bad "identify changed its input or old report"
expect 2 "--name" -- identify --data "$tmp/ex.csv" --out "$tmp/x.json" --name Bad-Name
expect 2 "--coulomb-velocity" -- identify --data "$tmp/ex.csv" --out "$tmp/x.json" --coulomb-velocity 0
expect 2 "centre" -- excite --centre 3,0,0 --out "$tmp/c.csv"
expect 2 "--harmonics" -- excite --harmonics 0 --out "$tmp/c.csv"
expect 2 "--period" -- excite --period -1 --out "$tmp/c.csv"
# Issue 30 item 3: the default dt longer than the run printed "--dt:
# (null)" (printf of a NULL string): the message names the dt in effect.
expect 2 "--dt: 0.01 s (the default) is longer than the run (0.005 s" -- excite --period 0.005 --out "$tmp/c.csv"
expect 2 "--dt: 0.5 s is longer than the run (0.2 s" -- excite --period 0.1 --periods 2 --dt 0.5 --out "$tmp/c.csv"
grep -q "(null)" "$tmp/err" && bad "excite --dt message prints (null): $(cat "$tmp/err")" || ok
expect 2 "--fd-max" -- excite --fd-max 0 --out "$tmp/c.csv"
expect 2 "--stroke" -- excite --stroke 0.3,0.2 --out "$tmp/c.csv"
expect 2 "outside its stroke" -- excite --stroke 0.5,0.6 --out "$tmp/c.csv"
expect 1 "no feasible excitation" -- excite --fd-max 1 --evals 50 --out "$tmp/c.csv"
[ ! -e "$tmp/c.csv" ] && ok || bad "a refused excite wrote its output"
[ ! -e "$tmp/x.json" ] && ok || bad "a refused identify wrote its output"

# ---- the drives' limits (spec 13) act by default; options override ----
# The build's model with a stroke and a force limit (format 2 keeps the
# build's geometry, so excite accepts it). The default 30-evaluation
# excitation ($EX) leaves [0.19, 0.235] m (paper model): that stroke
# of [0.19, 0.235] m must shrink it; --no-limits must not.
python3 - "$PRRU_MODEL" "$tmp/lim.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
if d.get("format", 1) == 1:
    g = d["geometry"]
    n = 3
    d["geometry"] = {"b": [g["b12"], g["b12"], g["b3"]], "l1": g["l1"], "l2": g["l2"], "a": g["a"]}
    d["format"] = 2
d.setdefault("actuators", {})
d["actuators"].update({"stroke": [0.19, 0.235], "force_max": 60})
json.dump(d, open(sys.argv[2], "w"), indent=1)
PY
slider_range() { python3 -c '
import csv, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith("#"))]
h = rows[0]
v = [float(r[h.index(sys.argv[2])]) for r in rows[1:]]
print(min(v), max(v))' "$1" "$2"; }
if [ "$nact" -eq 3 ] && python3 -c 'import json,sys; sys.exit(0 if json.load(open(sys.argv[1])).get("name") == "paper3prru" else 1)' "$PRRU_MODEL"; then
  EX="--evals 400 --period 8 --harmonics 4 --amplitude 0.2,0.2,0.02"
  "$PRRU" --model "$tmp/lim.json" excite $EX --out "$tmp/lim.csv" 2>"$tmp/lim.err" \
    || bad "excite with the model's limits: $(cat "$tmp/lim.err")"
  grep -qx "# limits: force_max 60 N, speed_max none, stroke \[0.19, 0.235\] m" "$tmp/lim.csv" && ok \
    || bad "excite: limits line: $(grep limits "$tmp/lim.csv")"
  read -r lo hi <<<"$(slider_range "$tmp/lim.csv" d1)"
  python3 -c "import sys; sys.exit(0 if 0.19 <= $lo and $hi <= 0.235 else 1)" && ok \
    || bad "excite: slider 1 over [$lo, $hi] m, outside the model's stroke [0.19, 0.235]"
  "$PRRU" --model "$tmp/lim.json" excite $EX --no-limits --out "$tmp/nolim.csv" 2>/dev/null \
    && grep -qx "# limits: force_max 500 N, speed_max none, stroke none (force: excite's default where the run has none)" \
      "$tmp/nolim.csv" && ok || bad "excite --no-limits: $(grep limits "$tmp/nolim.csv")"
  read -r lo hi <<<"$(slider_range "$tmp/nolim.csv" d1)"
  python3 -c "import sys; sys.exit(0 if $lo < 0.19 else 1)" && ok \
    || bad "excite --no-limits: slider 1 kept within the dropped stroke ([$lo, $hi] m)"
  "$PRRU" --model "$tmp/lim.json" excite $EX --fd-max 400 --stroke 0.1:0.3 --speed-max 2 \
    --out "$tmp/ovr.csv" 2>/dev/null \
    && grep -qx "# limits: force_max 400 N, speed_max 2 m/s, stroke \[0.1, 0.3\] m" "$tmp/ovr.csv" && ok \
    || bad "excite --fd-max (alias) --stroke LO:HI --speed-max: $(grep limits "$tmp/ovr.csv")"
  # --speed-max: the slider speeds keep it at the excitation's dense check
  # points (period 8 s / 2000: every 4 ms, so every row at a multiple of
  # 0.02 s); the unlimited excitation reaches 0.136 m/s. Tolerance: the
  # same J_d qd from a time that may differ in its last bit: 1e-12.
  "$PRRU" excite $EX --speed-max 0.01 --out "$tmp/spd.csv" 2>/dev/null || bad "excite --speed-max"
  "$PRRU" id --traj "$tmp/spd.csv" --rates --out "$tmp/spdid.csv" 2>/dev/null || bad "id --rates of excite --speed-max"
  python3 - "$tmp/spdid.csv" "$nact" <<'PY' && ok || bad "excite --speed-max 0.01: a slider faster at a checked time"
import csv, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith("#"))]
h = rows[0]
top = max(abs(float(r[h.index("dd%d" % (i + 1))])) for k, r in enumerate(rows[1:]) if k % 2 == 0
          for i in range(int(sys.argv[2])))
assert 0.005 < top <= 0.01 * (1 + 1e-12), top
PY
  expect 2 "--force-max and --fd-max are the same limit: give one" \
    -- excite --force-max 1 --fd-max 1 --out "$tmp/c.csv"
  expect 2 "--speed-max: '-1' is not a positive number" -- excite --speed-max -1 --out "$tmp/c.csv"
  expect 2 "--stroke: '1,2,3': give LO,HI for all sliders or 6 numbers" -- excite --stroke 1,2,3 --out "$tmp/c.csv"
  # The writer keeps the drive keys as the file gives them (spec 13): the
  # identified armature goes back into rotor_inertia (no "armature" beside
  # it), every other key as written. Data: the paper's motion with the
  # forces of the model with drives (armature J (2 pi gear / lead)^2).
  python3 - "$tmp/lim.json" "$tmp/drv.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["actuators"] = {"lead": 0.02, "gear": 2, "rotor_inertia": [5e-6, 6e-6, 7e-6], "torque_constant": 0.11,
                  "stroke": [0.1, 0.35], "torque_max": 0.64, "motor_speed_max": 3000}
json.dump(d, open(sys.argv[2], "w"), indent=1)
PY
  "$PRRU" --model "$tmp/drv.json" id --traj "$tmp/ex.csv" --out "$tmp/drvfd.csv" 2>/dev/null || bad "id with drives"
  python3 - "$tmp/ex.csv" "$tmp/drvfd.csv" "$tmp/drvdata.csv" <<'PY'
import csv, sys
def rows(p): return [r for r in csv.reader(l for l in open(p) if not l.startswith('#'))]
a, b = rows(sys.argv[1]), rows(sys.argv[2])
out = [a[0]] + [[y[b[0].index(h)] if h in b[0][1:] else x for h, x in zip(a[0], r)] for r, y in zip(a[1:], b[1:])]
csv.writer(open(sys.argv[3], "w")).writerows(out)
PY
  "$PRRU" --model "$tmp/drv.json" identify --data "$tmp/drvdata.csv" --out "$tmp/drvid.json" \
    --report "$tmp/drvrep.csv" 2>"$tmp/drvid.err" || bad "identify with drives: $(cat "$tmp/drvid.err")"
  # Written back: J = k / w^2 (w = 2 pi gear / lead), reread: J w w, four
  # roundings of the same doubles (4 u of k, 8 u allowed); the report's
  # model column is the written model's base parameter to the estimate's
  # own rounding rule (16 eps cond max(|prior|, resolution), as above).
  python3 - "$tmp/drvid.json" "$tmp/drvrep.csv" "$PRRU_SOURCE_DIR/gen" <<'PY' && ok || bad "identify's model: drive keys not kept: $(tr -d '\n' <"$tmp/drvid.json" | grep -o '"actuators.*')"
import csv, json, sys
sys.path.insert(0, sys.argv[3])
from prrugen import model
a = json.load(open(sys.argv[1]))["actuators"]
assert "armature" not in a, a
want = {"lead": 0.02, "gear": 2, "torque_constant": 0.11, "stroke": [0.1, 0.35], "torque_max": 0.64,
        "motor_speed_max": 3000}
assert {k: a[k] for k in want} == want, a
m = model.load(sys.argv[1])
import re
text = open(sys.argv[2]).read()
cond = float(re.search(r"condition number ([0-9.e+-]+)", text).group(1))
rows = {r["parameter"]: r for r in csv.DictReader(l for l in text.splitlines() if not l.startswith("#"))}
u = 2.0 ** -53
for i in range(3):
    r = rows["armature%d" % (i + 1)]
    k = float(r["model"])
    tol = 16 * 2 * u * cond * max(abs(float(r["prior"])), float(r["resolution"])) + 8 * u * k
    assert abs(float(m.armature[i]) - k) <= tol, (i, float(m.armature[i]), k, tol)
PY
fi

finish test_cli_ident
