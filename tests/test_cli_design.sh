#!/usr/bin/env bash
# prru optimize, prru sensitivity and prru merge, for any model: a short
# optimisation writes a model file the generator accepts and a report whose
# numbers are the maps it wrote; two runs are byte-identical; sensitivity
# shards merge into exactly the file (and the output) of one run; bad input
# (unknown variables, infeasible bounds, a start that does not assemble, a
# workspace with no regular point, no feasible design, broken shard sets)
# exits 2 or 1 with a message naming the problem and writes nothing.
. "$(dirname "$0")/cli_lib.sh"

# A small rectangle around home (regular for any buildable model) and a
# coarse grid keep this fast; the paper-sized run is studies/optimize_paper.sh.
Q1="-0.2:0.2:13" Q2="-0.25:0.15:11"
# nothing_written DIR: no file at all (no output, no partial file) in DIR.
nothing_written() {
  if [ -z "$(ls -A "$1")" ]; then ok; else bad "$2: left $(ls -A "$1" | tr '\n' ' ')"; fi
}

# Help speaks of the robot and the numbers, not of the code inside.
for c in optimize sensitivity merge; do "$PRRU" $c --help >"$tmp/help_$c.txt" || bad "$c --help failed"; done
{ grep -n -i -E "gsl|odeiv|hybridsj|kernel|descriptor|(^|[^a-z0-9])prru_[a-z]|runtime|generated" "$tmp"/help_*.txt
  grep -n -E "PRRU_|DBL_" "$tmp"/help_*.txt; } >"$tmp/jargon.txt"
[ -s "$tmp/jargon.txt" ] && bad "help texts with internal names: $(head -c 300 "$tmp/jargon.txt")" || ok

# ---- optimize: a short run ----
opt() { "$PRRU" optimize --vars l2,b12 --range 5 --q1 "$Q1" --q2 "$Q2" --max-iter 40 "$@"; }
mkdir "$tmp/o1" "$tmp/o2"
opt --out "$tmp/o1/m.json" --report "$tmp/o1/rep" >"$tmp/o1/stdout" 2>"$tmp/o1/stderr" \
  || bad "optimize failed: $(head -c 400 "$tmp/o1/stderr")"
opt --out "$tmp/o2/m.json" --report "$tmp/o2/rep/" >"$tmp/o2/stdout" 2>/dev/null || bad "optimize again failed"
# (report.txt and after_map.csv name the model file: o1 or o2)
for f in m.json rep/report.txt rep/before_map.csv rep/after_map.csv; do
  cmp -s <(sed 's|/o[12]/|/oX/|g' "$tmp/o1/$f") <(sed 's|/o[12]/|/oX/|g' "$tmp/o2/$f") \
    && ok || bad "two optimize runs differ in $f"
done
cmp -s <(sed 's|/o[12]/|/oX/|g' "$tmp/o1/stdout") <(sed 's|/o[12]/|/oX/|g' "$tmp/o2/stdout") \
  && ok || bad "two optimize runs print differently"
[ -f "$tmp/o1/rep/optimize_maps.png" ] || ! command -v gnuplot >/dev/null && ok \
  || bad "optimize_maps.png missing although gnuplot is installed"
ls "$tmp/o1" | grep -q partial && bad "a partial file or directory is left" || ok
# --precision float: the report and stdout say so, the result is feasible;
# another value exits 2.
mkdir "$tmp/of"
opt --precision float --out "$tmp/of/m.json" --report "$tmp/of/rep" >"$tmp/of/stdout" 2>"$tmp/of/stderr" \
  || bad "optimize --precision float failed: $(head -c 400 "$tmp/of/stderr")"
grep -q '^precision: float (' "$tmp/of/rep/report.txt" && grep -q '^precision: float (' "$tmp/of/stdout" \
  && [ -f "$tmp/of/m.json" ] && ok || bad "optimize --precision float: no precision line or no model"
! grep -q '^precision:' "$tmp/o1/rep/report.txt" && ok || bad "optimize (double): a precision line"
expect 2 "--precision 'half': must be double or float" -- optimize --vars l2 --q1 "$Q1" --q2 "$Q2" \
  --precision half --out "$tmp/of/x.json" --report "$tmp/of/xrep"
# The model file: format 2, every key, what the generator accepts.
jcheck "$tmp/o1/m.json" "d['format'] == 2 and d['name'] == '${model_name:0:12}_opt' and set(d) == {'format', 'name', 'description', 'gravity', 'geometry', 'bodies', 'actuators'} and len(d['geometry']['b']) == $nact and len(d['bodies']) == 1 + 3 * $nact and all(len(b['inertia']) == 6 and len(b['com']) == 3 for b in d['bodies'].values())" \
  "optimize: a complete format-2 model"
python3 "$PRRU_SOURCE_DIR/gen/prru_gen.py" "$tmp/o1/m.json" --out "$tmp/o1/gen" --quiet \
  && ok || bad "the generator refuses the optimised model"
# The report's numbers: after <= before, after from the after map (17 digits).
field() { sed -n "s/^$2: //p" "$1"; }
before=$(field "$tmp/o1/rep/report.txt" before_index) after=$(field "$tmp/o1/rep/report.txt" after_index)
python3 - "$tmp/o1/rep" "$before" "$after" <<'PY' && ok || bad "report numbers are not the maps'"
import sys
d, before, after = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
def index(path):
    rows = [l.split(',') for l in open(path) if not l.startswith('#')][1:]
    ok = [float(r[3]) for r in rows if r[4].strip() == 'ok']
    s = 0.0
    for w in ok:
        s += w - 1.0
    return s / len(ok), len(ok) == len(rows)
ib, _ = index(d + '/before_map.csv')
ia, all_ok = index(d + '/after_map.csv')
sys.exit(0 if abs(ib - before) <= 1e-12 * before and abs(ia - after) <= 1e-12 * after
         and after <= before and all_ok else 1)
PY
# The variables moved within their bounds (5 %).
python3 - "$tmp/o1/m.json" "$PRRU_MODEL" <<'PY' && ok || bad "optimised variables outside their bounds"
import json, sys
new = json.load(open(sys.argv[1]))['geometry']
old = json.load(open(sys.argv[2]))['geometry']
def limbs(g, k, n):
    v = g[k] if k in g else g['b12' if k == 'b' else k]
    return v if isinstance(v, list) else [v] * n
n = len(new['b'])
l2o = limbs(old, 'l2', n)
b1 = (old['b'][0] if 'b' in old else old['b12'])
ok = all(abs(x - y) <= 0.05 * y * (1 + 1e-12) for x, y in zip(new['l2'], l2o))
ok = ok and abs(new['b'][0] - b1) <= 0.05 * b1 * (1 + 1e-12)
sys.exit(0 if ok else 1)
PY

# Tied limbs whose lengths differ (the last limb's l2 set 4.4 % shorter:
# 0.215 m of the paper's 0.225, relative so that any model's limb still
# assembles): every limb keeps its own -+ 5 % of its start (tied parameters
# move by one shift, so the bounds are the intersection of every limb's),
# within the rounding of the 17-digit model file (1e-12 relative, as above).
mkdir "$tmp/o3"
short=$(json "$PRRU_MODEL" "'%.17g' % ((lambda v: v[-1] if isinstance(v, list) else v)(d['geometry']['l2']) * 0.215 / 0.225)")
(umask 022 && opt --set "l2_$nact=$short" --out "$tmp/o3/m.json" --report "$tmp/o3/rep" >/dev/null 2>"$tmp/o3/stderr") \
  || bad "optimize with unequal limbs failed: $(head -c 300 "$tmp/o3/stderr")"
# The report directory gets the mode mkdir(2) gives under the umask (022:
# 755, as prru paper's), not the staging directory's private 700.
[ "$(stat -c %a "$tmp/o3/rep")" = 755 ] && ok || bad "optimize --report under umask 022: mode $(stat -c %a "$tmp/o3/rep")"
python3 - "$tmp/o3/m.json" "$PRRU_MODEL" "$short" <<'PY' && ok || bad "a tied limb left its own bounds: $(json "$tmp/o3/m.json" "d['geometry']['l2']")"
import json, sys
new = json.load(open(sys.argv[1]))['geometry']['l2']
old = json.load(open(sys.argv[2]))['geometry']['l2']
old = list(old) if isinstance(old, list) else [old] * len(new)
old[-1] = float(sys.argv[3])
sys.exit(0 if all(abs(x - y) <= 0.05 * y * (1 + 1e-12) for x, y in zip(new, old)) else 1)
PY

# ---- optimize: bad input, nothing written ----
mkdir "$tmp/bad"
B=(--q1 "$Q1" --q2 "$Q2" --out "$tmp/bad/m.json" --report "$tmp/bad/rep")
expect 2 "'nosuch': not a design parameter" -- optimize --vars l2,nosuch "${B[@]}"
expect 2 "infeasible" -- optimize --vars b12=0.4:0.3 "${B[@]}"
expect 2 "outside the bounds" -- optimize --vars l2=1e-3:2e-3 "${B[@]}"
expect 2 "cannot be assembled" -- optimize --vars l2 --set b3=10 "${B[@]}"
expect 2 "I_P: the inertia tensor is not positive definite" -- optimize --vars l2 --set I_P_xy=1 "${B[@]}"
expect 2 "--objective 'median'" -- optimize --vars l2 --objective median "${B[@]}"
expect 2 "--stroke: slider 1's range [1, 0] is empty" -- optimize --vars l2 --stroke 1:0 "${B[@]}"
expect 2 "--range '0'" -- optimize --vars l2 --range 0 "${B[@]}"
expect 2 "--rcond-min '0'" -- optimize --vars l2 --rcond-min 0 "${B[@]}"
expect 2 "--name 'Bad-Name'" -- optimize --vars l2 --name Bad-Name "${B[@]}"
expect 2 "--report is required" -- optimize --vars l2 --q1 "$Q1" --q2 "$Q2" --out "$tmp/bad/m.json"
# No regular point: the platform tilted by 80 degrees about both axes, far
# beyond the reach of the links (of the paper's, the prototype's and the
# 4-limb model's; the rails are vertical, so no height q3 would do).
NOREG=(--q1 1.4:1.5:5 --q2 1.4:1.5:5)
OUTS=(--out "$tmp/bad/m.json" --report "$tmp/bad/rep")
expect 1 "no grid point of the workspace is regular" -- optimize --vars l2 "${NOREG[@]}" "${OUTS[@]}"
# No feasible design: half the rectangle is beyond reach and 0.1 % cannot fix it.
expect 1 "no feasible design found" -- optimize --vars l2 --range 0.1 --max-iter 5 --q1 -1.5:1.5:9 \
  --q2 -1.5:1.5:9 --out "$tmp/bad/m.json" --report "$tmp/bad/rep"
# A stroke no slider can keep is infeasible too.
expect 1 "no feasible design found" -- optimize --vars l2 --range 0.1 --max-iter 5 --stroke 50:51 "${B[@]}"
# The model's own stroke (spec 13) acts by default: the same stroke in the
# model file is infeasible; --no-limits drops it (the report says so).
python3 - "$PRRU_MODEL" "$tmp/stroke.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
if d.get("format", 1) == 1:
    g = d["geometry"]
    d["geometry"] = {"b": [g["b12"], g["b12"], g["b3"]], "l1": g["l1"], "l2": g["l2"], "a": g["a"]}
    d["format"] = 2
d.setdefault("actuators", {})["stroke"] = [50, 51]
json.dump(d, open(sys.argv[2], "w"), indent=1)
PY
expect 1 "no feasible design found" -- --model "$tmp/stroke.json" optimize --vars l2 --range 0.1 --max-iter 5 "${B[@]}"
mkdir "$tmp/nolim"
"$PRRU" --model "$tmp/stroke.json" optimize --vars l2 --range 0.1 --max-iter 5 --q1 "$Q1" --q2 "$Q2" --no-limits \
  --out "$tmp/nolim/m.json" --report "$tmp/nolim/rep" >/dev/null 2>"$tmp/nolim/err" \
  || bad "optimize --no-limits: $(head -c 300 "$tmp/nolim/err")"
grep -qx "limits: force_max none, speed_max none, stroke none (w_R has no forces or speeds: only the stroke acts)" \
  "$tmp/nolim/rep/report.txt" && ! grep -q "sliders within" "$tmp/nolim/rep/report.txt" && ok \
  || bad "optimize --no-limits report: $(grep -E "limits|sliders" "$tmp/nolim/rep/report.txt")"
# A stroke every slider keeps: |d| is below the sum of the largest base
# radius, link lengths and platform size, rounded up to whole metres.
R=$(python3 -c 'import json, math, sys
g = json.load(open(sys.argv[1]))["geometry"]
big = lambda v: max(v) if isinstance(v, list) else v
print(math.ceil(sum(big(g[k]) for k in ("b", "l1", "l2", "a"))))' "$tmp/stroke.json")
"$PRRU" --model "$tmp/stroke.json" optimize --vars l2 --range 0.1 --max-iter 5 --q1 "$Q1" --q2 "$Q2" \
  --stroke "-$R,$R" --out "$tmp/nolim/m2.json" --report "$tmp/nolim/rep2" >/dev/null 2>"$tmp/nolim/err2" \
  && grep -qx "limits: force_max none, speed_max none, stroke \[-$R, $R\] m (w_R has no forces or speeds: only the stroke acts)" \
    "$tmp/nolim/rep2/report.txt" && grep -q "sliders within \[-$R, $R\] m" "$tmp/nolim/rep2/report.txt" && ok \
  || bad "optimize --stroke over the model's: $(head -c 300 "$tmp/nolim/err2"; grep -E "limits|sliders" "$tmp/nolim/rep2/report.txt")"
echo x >"$tmp/bad/file"
expect 2 "exists and is not a directory" -- optimize --vars l2 --q1 "$Q1" --q2 "$Q2" --out "$tmp/bad/m.json" --report "$tmp/bad/file"
rm "$tmp/bad/file"
nothing_written "$tmp/bad" "optimize refusals"
# An existing model file stays as it was when the run fails.
echo keep >"$tmp/bad/m.json"
expect 1 "no grid point" -- optimize --vars l2 "${NOREG[@]}" "${OUTS[@]}"
[ "$(cat "$tmp/bad/m.json")" = keep ] && ok || bad "a failed optimize changed the existing model file"
rm "$tmp/bad/m.json"
expect 1 "cannot open" -- optimize --vars l2 --q1 "$Q1" --q2 "$Q2" --out "$tmp/nodir/m.json" --report "$tmp/bad/rep"
nothing_written "$tmp/bad" "optimize into a missing directory"

# A signal stops the run: exit 128 + signal, nothing written, no staging
# directory left. (TERM: a background job of a script ignores INT.)
mkdir "$tmp/int"
# The grid is large enough (2.25 M points an evaluation) that no machine
# converges within the second before the signal; at 201 x 201 a fast one did.
"$PRRU" optimize --vars b12,l2 --q1 -0.3:0.3:1501 --q2 -0.3:0.3:1501 --max-iter 1000000 \
  --out "$tmp/int/m.json" --report "$tmp/int/rep" >/dev/null 2>"$tmp/int.err" &
pid=$!
sleep 1
kill -TERM $pid
wait $pid
rc=$?
[ $rc -eq 143 ] && grep -q "interrupted (SIGTERM): nothing written" "$tmp/int.err" && ok \
  || bad "optimize stopped by SIGTERM: exit $rc, $(head -c 300 "$tmp/int.err")"
nothing_written "$tmp/int" "optimize stopped by a signal"

# ---- sensitivity: shards merge into one run, byte for byte ----
S=(--q1 "$Q1" --q2 "$Q2")
mkdir "$tmp/s"
"$PRRU" sensitivity "${S[@]}" --out "$tmp/s/one.csv" >"$tmp/s/one.out" || bad "sensitivity failed"
for k in 1 2 3 4 5; do
  "$PRRU" sensitivity "${S[@]}" --shard $k/5 --out "$tmp/s/p$k.csv" >/dev/null || bad "shard $k/5 failed"
done
"$PRRU" merge --in "$tmp/s/p4.csv,$tmp/s/p2.csv,$tmp/s/p5.csv,$tmp/s/p1.csv,$tmp/s/p3.csv" \
  --out "$tmp/s/merged.csv" >"$tmp/s/merged.out" || bad "merge failed"
cmp -s "$tmp/s/one.csv" "$tmp/s/merged.csv" && ok || bad "merged sensitivity CSV differs from one run"
cmp -s "$tmp/s/one.out" "$tmp/s/merged.out" && ok || bad "merge prints differently from one run"
nparam=$(( 3 * nact + 2 + 10 * (1 + 3 * nact) + nact ))
[ "$(grep -vc '^#' "$tmp/s/one.csv")" -eq $((nparam + 1)) ] && ok || bad "sensitivity: not one row per parameter"
# A slider's mass and its drive's armature enter w_R alike.
python3 - "$tmp/s/one.csv" <<'PY' && ok || bad "d/d m_S1 != d/d armature_1"
import sys
rows = {l.split(',')[0]: l.split(',') for l in open(sys.argv[1]) if not l.startswith('#')}
m, a = float(rows['m_S1'][6]), float(rows['armature_1'][6])
sys.exit(0 if abs(m - a) <= 1e-5 * abs(m) else 1)
PY
expect 2 "not a design parameter" -- sensitivity "${S[@]}" --params b_1,zz --out "$tmp/s/x.csv"
expect 2 "--shard '0/3'" -- sensitivity "${S[@]}" --shard 0/3 --out "$tmp/s/x.csv"
expect 2 "--shard '4/3'" -- sensitivity "${S[@]}" --shard 4/3 --out "$tmp/s/x.csv"
expect 2 "--step" -- sensitivity "${S[@]}" --step 0.7 --out "$tmp/s/x.csv"
# A bar chart that gnuplot leaves cut short (a full disk: gnuplot still
# exits 0) is exit 1, and the previous picture stays.
if command -v gnuplot >/dev/null; then
  mkdir -p "$tmp/cutbin"
  printf '#!/bin/sh\n"%s" "$@" || exit $?\nfor f in *.png; do truncate -s 300 "$f"; done\n' \
    "$(command -v gnuplot)" >"$tmp/cutbin/gnuplot"
  chmod +x "$tmp/cutbin/gnuplot"
  echo "old picture" >"$tmp/s/bars.png"
  PATH="$tmp/cutbin:$PATH" "$PRRU" sensitivity "${S[@]}" --params b_1 --out "$tmp/s/b1.csv" \
    --plot "$tmp/s/bars.png" >/dev/null 2>"$tmp/err"
  st=$?
  [ $st -eq 1 ] && grep -q "sens.png: gnuplot exited 0 but the file is not complete" "$tmp/err" \
    && [ "$(cat "$tmp/s/bars.png")" = "old picture" ] && ok \
    || bad "sensitivity --plot cut short: exit $st, $(head -c 300 "$tmp/err")"
fi
# A step that rounding loses (h far below DBL_EPSILON x the value) would
# give every derivative exactly 0: refused, naming --step.
expect 2 "--step '1e-300': b_1: the step" -- sensitivity "${S[@]}" --step 1e-300 --out "$tmp/s/x.csv"
expect 1 "no grid point of the workspace is regular" -- sensitivity "${NOREG[@]}" --out "$tmp/s/x.csv"
[ -e "$tmp/s/x.csv" ] && bad "a refused sensitivity wrote its file" || ok
# Broken shard sets: nothing merged.
expect 2 "does not belong" -- merge --in "$tmp/s/p1.csv,$tmp/s/p2.csv" --out "$tmp/s/x.csv"
expect 2 "both are shard 2/5" -- merge --in "$tmp/s/p1.csv,$tmp/s/p2.csv,$tmp/s/p2.csv,$tmp/s/p4.csv,$tmp/s/p5.csv" --out "$tmp/s/x.csv"
"$PRRU" sensitivity --q1 "$Q1" --q2 -0.25:0.15:12 --shard 3/5 --out "$tmp/s/q3.csv" >/dev/null
expect 2 "another sweep or settings" -- merge --in "$tmp/s/p1.csv,$tmp/s/p2.csv,$tmp/s/q3.csv,$tmp/s/p4.csv,$tmp/s/p5.csv" --out "$tmp/s/x.csv"
head -n -1 "$tmp/s/p2.csv" >"$tmp/s/cut.csv"
expect 2 "incomplete" -- merge --in "$tmp/s/p1.csv,$tmp/s/cut.csv,$tmp/s/p3.csv,$tmp/s/p4.csv,$tmp/s/p5.csv" --out "$tmp/s/x.csv"
expect 2 "not a shard" -- merge --in "$tmp/s/one.csv" --out "$tmp/s/x.csv"
expect 2 "cannot open" -- merge --in "$tmp/s/nosuch.csv" --out "$tmp/s/x.csv"
sed '1s/model /model other/' "$tmp/s/p1.csv" >"$tmp/s/other.csv"
expect 2 "not a shard of this model" -- merge --in "$tmp/s/other.csv,$tmp/s/p2.csv,$tmp/s/p3.csv,$tmp/s/p4.csv,$tmp/s/p5.csv" --out "$tmp/s/x.csv"
[ -e "$tmp/s/x.csv" ] && bad "a refused merge wrote its file" || ok

# ---- map shards: merged, exactly one run (a rectangle with every status) ----
mkdir "$tmp/m"
M=(--q1 -1.2:1.2:23 --q2 -1.3:0.9:17)
"$PRRU" map "${M[@]}" --out "$tmp/m/one.csv" >"$tmp/m/one.out" || bad "map failed"
for n in 1 4 23 30; do
  list=""
  for ((k = n; k >= 1; k--)); do
    "$PRRU" map "${M[@]}" --shard $k/$n --threads 1 --out "$tmp/m/s$k.csv" >/dev/null || bad "map shard $k/$n failed"
    list="$list${list:+,}$tmp/m/s$k.csv"
  done
  "$PRRU" merge --in "$list" --out "$tmp/m/merged.csv" >"$tmp/m/merged.out" || bad "map merge of $n failed"
  cmp -s "$tmp/m/one.csv" "$tmp/m/merged.csv" && ok || bad "map: $n shards merged differ from one run"
  cmp -s "$tmp/m/one.out" "$tmp/m/merged.out" && ok || bad "map: merge of $n prints differently from one run"
  rm -f "$tmp/m"/s*.csv
done
expect 2 "--shard '3/2'" -- map "${M[@]}" --shard 3/2 --out "$tmp/m/x.csv"
"$PRRU" map "${M[@]}" --shard 1/2 --out "$tmp/m/a.csv" >/dev/null
"$PRRU" map "${M[@]}" --shard 2/2 --rcond-min 1e-3 --out "$tmp/m/b.csv" >/dev/null
expect 2 "another sweep or settings" -- merge --in "$tmp/m/a.csv,$tmp/m/b.csv" --out "$tmp/m/x.csv"
"$PRRU" map "${M[@]}" --shard 2/2 --out "$tmp/m/b.csv" >/dev/null
expect 2 "only for sensitivity" -- merge --in "$tmp/m/a.csv,$tmp/m/b.csv" --out "$tmp/m/x.csv" --plot "$tmp/m/x.png"
sed -E '5s/,[a-z_]+$/,bogus/' "$tmp/m/a.csv" >"$tmp/m/c.csv"
expect 2 "c.csv: row 2: expected q1,q2,q3,w_R,status" -- merge --in "$tmp/m/c.csv,$tmp/m/b.csv" --out "$tmp/m/x.csv"
sed -E '5s/^[^,]+,/0.5,/' "$tmp/m/a.csv" >"$tmp/m/c.csv"
expect 2 "c.csv: row 2 does not belong to this grid" -- merge --in "$tmp/m/c.csv,$tmp/m/b.csv" --out "$tmp/m/x.csv"
# Values no map has (w_R = sigma_1/sigma_2 >= 1, finite where ok, NaN
# elsewhere) are refused as prru plot refuses them, naming the file and the
# row, instead of a global index of nan.
ok_line=$(grep -n ',ok$' "$tmp/m/a.csv" | head -1 | cut -d: -f1)
ok_row=$((ok_line - 3))
sing_line=$(grep -n ',NaN,[a-z_]*$' "$tmp/m/a.csv" | head -1 | cut -d: -f1)
[ -n "$ok_line" ] && [ -n "$sing_line" ] && ok || bad "the map shard has no ok or no other row (test input changed)"
for v in NaN inf 1e999 -5 0.5; do
  sed -E "${ok_line}s/,[^,]+,ok\$/,$v,ok/" "$tmp/m/a.csv" >"$tmp/m/c.csv"
  expect 2 "c.csv: row $ok_row: expected" -- merge --in "$tmp/m/c.csv,$tmp/m/b.csv" --out "$tmp/m/x.csv"
  expect 2 "c.csv:$ok_line: expected" -- plot "$tmp/m/c.csv" --out "$tmp/m/x.png"
done
sed -E "${sing_line}s/,NaN,([a-z_]+)\$/,1.5,\1/" "$tmp/m/a.csv" >"$tmp/m/c.csv"
expect 2 "c.csv: row $((sing_line - 3)): expected" -- merge --in "$tmp/m/c.csv,$tmp/m/b.csv" --out "$tmp/m/x.csv"
[ -e "$tmp/m/x.csv" ] && bad "a refused map merge wrote its file" || ok

echo "test_cli_design: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
