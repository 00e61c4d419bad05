#!/usr/bin/env bash
# The prru command line, for any model: the model's identity in every
# output, outputs checked against each other (fk(ik(q)), the equations of
# motion with eval's own M, h, G, J_d and passive forces, simulate -> id),
# round trips through the CSV interfaces, and the exit status and message
# of every kind of bad argument. The paper's numbers are in paper_cli.sh.
# Needs $PRRU (path to the binary), $PRRU_MODEL, $PRRU_SOURCE_DIR.
. "$(dirname "$0")/cli_lib.sh"

# A pose every model in models/ reaches with a regular J_d (checked below),
# and one with velocities.
Q=0.1,0.2,-0.8
QD=0.3,-0.4,0.5

# ---- Model identity ----
[ -n "$prru_version" ] && ok || bad "no project version in $PRRU_SOURCE_DIR/CMakeLists.txt"
"$PRRU" --version >"$tmp/v.txt" 2>"$tmp/v.err" && ok || bad "--version failed: $(cat "$tmp/v.err")"
printf 'prru %s\nmodel: %s\nmodel file: %s\nmodel format: %s\nmodel sha256: %s\n' "$prru_version" \
  "$model_name" "$model_file" "$model_format" "$model_sha" >"$tmp/v.want"
cmp -s "$tmp/v.txt" "$tmp/v.want" && ok || bad "--version: got '$(cat "$tmp/v.txt")', want '$(cat "$tmp/v.want")'"
"$PRRU" version >"$tmp/v2.txt" && cmp -s "$tmp/v2.txt" "$tmp/v.want" && ok || bad "'prru version' differs from --version"
expect 2 "takes no arguments" -- --version extra
"$PRRU" --help >"$tmp/h.txt" && grep -q -- "--version" "$tmp/h.txt" && grep -qF "$model_name ($model_file)" "$tmp/h.txt" \
  && ok || bad "usage does not mention --version and the model: $(head -c 300 "$tmp/h.txt")"
# No help text counts reactions or actuators with another model's numbers.
for c in eval simulate fk id; do
  "$PRRU" $c --help >"$tmp/help_$c.txt" || bad "$c --help failed"
done
nl=$(python3 -c "import json, subprocess, sys; print(len(json.loads(subprocess.run([sys.argv[1], 'eval', '--q', '$Q'], capture_output=True, text=True).stdout)['lambda']))" "$PRRU")
tr '\n' ' ' <"$tmp/help_eval.txt" | grep -q "the $nl joint reaction" && tr '\n' ' ' <"$tmp/help_simulate.txt" | grep -q "the $nl joint reaction" \
  && ok || bad "help texts do not give the model's $nl reaction coordinates"
grep -qi "spec" "$tmp"/help_*.txt && bad "help text talks of 'spec'" || ok

# ---- eval: the model object and the equations of motion ----
"$PRRU" eval --q "$Q" --qd "$QD" --fd 50,40,25 >"$tmp/f.json" || bad "eval with loads failed"
jcheck "$tmp/f.json" "d['model'] == model" "eval: model object"
jcheck "$tmp/f.json" "len(d['lambda']) == len(d['lambda_labels']) == len(set(d['lambda_labels'])) > 0" "eval: one unique label per reaction coordinate"
jcheck "$tmp/f.json" "len(d['d']) == len(d['fd']) and len(d['Jd']) == 3 * len(d['d']) and len(d['passive']) == 3" "eval: sizes"
jcheck "$tmp/f.json" "0 < d['Jd_rcond'] and all(math.isfinite(x) for x in d['lambda'] + d['qdd'])" "eval: regular and finite at $Q"
# M qdd + h = G + J_d^T fd + passive with the printed M, h, G, J_d, passive.
r=$(json "$tmp/f.json" "max(abs(sum(d['M'][3*i+j]*d['qdd'][j] for j in range(3)) + d['h'][i] - d['G'][i] - d['passive'][i] - sum(d['Jd'][3*j+i]*d['fd'][j] for j in range(len(d['fd'])))) / (1 + abs(d['G'][i]) + sum(abs(x) for x in d['fd'])) for i in range(3))")
below "$r" 1e-13 "eval qdd residual (with passive forces)"
# Passive drive forces: zero at rest for any model; at speed non-zero
# exactly when the model has damping or Coulomb friction.
"$PRRU" eval --q "$Q" --fd 50,40,25 >"$tmp/rest.json" || bad "eval at rest failed"
jcheck "$tmp/rest.json" "d['passive'] == [0, 0, 0]" "passive forces at rest"
drives=$(python3 -c "import json, sys; a = json.load(open(sys.argv[1])).get('actuators', {}); print(int(any(a.get(k) and any(a[k]) for k in ('damping', 'coulomb'))))" "$PRRU_MODEL")
if [ "$drives" = 1 ]; then
  jcheck "$tmp/f.json" "any(abs(x) > 1e-6 for x in d['passive'])" "passive forces of a model with drives"
else
  jcheck "$tmp/f.json" "d['passive'] == [0, 0, 0]" "passive forces of a model without drives"
fi

# ---- ik / fk round trip ----
"$PRRU" ik --q "$Q" >"$tmp/ik.json" || bad "ik failed"
jcheck "$tmp/ik.json" "d['model'] == model and d['singular'] is False" "ik: model object, regular"
dq=$(json "$tmp/ik.json" "','.join(repr(x) for x in d['d'])")
"$PRRU" fk --d "$dq" >"$tmp/fk.json" || bad "fk failed"
jcheck "$tmp/fk.json" "d['model'] == model and d['residual'] < 1e-13" "fk: model object, residual"
r=$(json "$tmp/fk.json" "max(abs(a-b) for a,b in zip(d['q'],[$Q]))")
below "$r" 1e-12 "fk(ik(q)) off"
"$PRRU" ik --q 0,0,-0.8 >"$tmp/ik0.json" || bad "ik at (0, 0, -0.8) failed"
dq=$(json "$tmp/ik0.json" "','.join(repr(x) for x in d['d'])")
"$PRRU" fk --d "$dq" --seed 0.05,-0.05,-0.7 >"$tmp/fk0.json" || bad "fk from a seed failed"
r=$(json "$tmp/fk0.json" "max(abs(a-b) for a,b in zip(d['q'],[0,0,-0.8]))")
below "$r" 1e-12 "fk(ik(0, 0, -0.8)) off"

# ---- simulate -> id recovers the constant actuator forces ----
"$PRRU" simulate --q0 0.05,0.1,-0.8 --fd 55,45,30 --t-end 0.2 --dt 0.01 --out "$tmp/sim.csv" || bad "simulate failed"
[ "$(head -1 "$tmp/sim.csv")" = "$csv_comment" ] && ok || bad "CSV comment line: '$(head -1 "$tmp/sim.csv")', want '$csv_comment'"
[ "$(sed -n 2p "$tmp/sim.csv" | cut -d, -f1-10)" = "t,q1,q2,q3,qd1,qd2,qd3,d1,d2,d3" ] && ok || bad "CSV header"
[ "$(grep -vc '^#' "$tmp/sim.csv")" -eq 22 ] && ok || bad "21 samples expected, got $(($(grep -vc '^#' "$tmp/sim.csv") - 1))"
[ "$(grep -c '^#' "$tmp/sim.csv")" -eq 1 ] && ok || bad "one comment line expected"
"$PRRU" id --traj "$tmp/sim.csv" --out "$tmp/id.csv" || bad "id failed"
[ "$(head -1 "$tmp/id.csv")" = "$csv_comment" ] && ok || bad "id: CSV comment line"
r=$(python3 - "$tmp/id.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#')))
assert len(rows) == 21, len(rows)
print(max(abs(float(r['fd%d' % (i + 1)]) - f) / f for r in rows for i, f in enumerate((55, 45, 30))))
PY
)
below "$r" 1e-9 "id of simulate: rel err"
# id reads comment lines anywhere (before the header, between rows) and
# counts lines from the top of the file in its messages.
{ echo "$csv_comment"; echo "# another comment"; sed -n 2,4p "$tmp/sim.csv"; echo "  # indented"; sed -n 5p "$tmp/sim.csv"; } >"$tmp/traj_c.csv"
"$PRRU" id --traj "$tmp/traj_c.csv" >"$tmp/id_c.csv" || bad "id of a CSV with comments failed"
[ "$(grep -vc '^#' "$tmp/id_c.csv")" -eq 4 ] && ok || bad "id of a CSV with comments: $(cat "$tmp/id_c.csv")"
printf '# prru x\nt,t\n0,1\n' >"$tmp/dup.csv"
expect 2 "dup.csv:2: column 't' appears twice" -- id --traj "$tmp/dup.csv"

# ---- map: the comment line in the CSV, the model in the summary ----
"$PRRU" map --q1 -0.2:0.2:3 --q2 -0.2:0.2:3 --q3 -0.8 --out "$tmp/map.csv" >"$tmp/map.txt" || bad "map failed"
[ "$(head -1 "$tmp/map.csv")" = "$csv_comment" ] && ok || bad "map: CSV comment line"
[ "$(sed -n 2p "$tmp/map.csv")" = "q1,q2,q3,w_R,status" ] && ok || bad "map: CSV header"
grep -qxF "model: $model_name ($model_file, sha256 $model_sha)" "$tmp/map.txt" && ok || bad "map summary lacks the model: $(cat "$tmp/map.txt")"

# ---- paper: runs with any model, names it, warns unless it is the paper's ----
"$PRRU" paper --out "$tmp/paper" --skip-map >"$tmp/paper.out" 2>"$tmp/paper.err"
rc=$?
if [ $rc -eq 0 ] || { [ $rc -eq 1 ] && grep -q "gnuplot not found" "$tmp/paper.err"; }; then ok
else bad "paper exited $rc: $(head -c 300 "$tmp/paper.err")"; fi
warning="warning: model $model_name is not the paper's; the figures show this model, not the paper's results"
n=$(grep -cF "$warning" "$tmp/paper.err")
if [ "$model_sha" = "$paper_sha" ]; then
  [ "$n" -eq 0 ] && ok || bad "paper warns for the paper's own model: $(cat "$tmp/paper.err")"
else
  [ "$n" -eq 1 ] && ok || bad "paper: want the warning once for model $model_name: $(cat "$tmp/paper.err")"
fi
grep -qF "Model: $model_name ($model_file, sha256 $model_sha)" "$tmp/paper/summary.txt" && ok || bad "summary.txt lacks the model"
[ "$(head -1 "$tmp/paper/paper_sim.csv")" = "$csv_comment" ] && ok || bad "paper_sim.csv: comment line"
[ "$(grep -vc '^#' "$tmp/paper/paper_sim.csv")" -eq 1002 ] && ok || bad "paper_sim.csv: 1001 samples expected"
# Deterministic: a second run writes the same files (no timestamps).
"$PRRU" paper --out "$tmp/paper2" --skip-map >/dev/null 2>&1
cmp -s "$tmp/paper/paper_sim.csv" "$tmp/paper2/paper_sim.csv" && cmp -s "$tmp/paper/summary.txt" "$tmp/paper2/summary.txt" \
  && ok || bad "paper outputs differ between two runs"

# ---- Scenario files, the paper scenario and load tables ----
printf 'q0 = 0, 0.5235987755982988, -0.8\nfd = 50, 40, 25\nharmonic = 50, 12.566370614359172\nt_end = 0.05\ndt = 0.01\n' >"$tmp/s.txt"
"$PRRU" simulate --scenario "$tmp/s.txt" --out "$tmp/s.csv" || bad "scenario file run"
"$PRRU" simulate --scenario paper --t-end 0.05 --dt 0.01 --out "$tmp/p.csv" || bad "paper scenario run"
cmp -s <(cut -d, -f1-10 "$tmp/s.csv") <(cut -d, -f1-10 "$tmp/p.csv") && ok || bad "scenario file = built-in paper scenario"
printf 't,fd1,fd2,fd3\n0,50,40,25\n1,50,40,25\n' >"$tmp/loads.csv"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --loads "$tmp/loads.csv" --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/t.csv" || bad "loads table run"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --fd 50,40,25 --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/c.csv" || bad "constant run"
cmp -s "$tmp/t.csv" "$tmp/c.csv" && ok || bad "constant table = constant forces"
# A load table with the comment line `prru id` writes is read too.
{ echo "$csv_comment"; cat "$tmp/loads.csv"; } >"$tmp/loads_c.csv"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --loads "$tmp/loads_c.csv" --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/tc.csv" || bad "loads table with a comment line"
cmp -s "$tmp/tc.csv" "$tmp/c.csv" && ok || bad "commented table = constant forces"

# Runs that leave the workspace keep their rows and exit 1.
expect 1 "stopped at t =" -- simulate --q0 0,0,-0.8 --fd 200,-100,0 --t-end 2 --dt 0.01 --out "$tmp/stop.csv"
rows=$(($(grep -vc '^#' "$tmp/stop.csv") - 1))
[ "$rows" -gt 1 ] && [ "$rows" -lt 201 ] && ok || bad "stopped run kept $rows rows"
grep -qi nan "$tmp/stop.csv" && bad "NaN in a CSV" || ok

# Bad arguments: exit 2 and a message naming the argument.
expect 2 "--q" -- eval --q 0.1,0.2
expect 2 "--q" -- eval --q 0.1,abc,0
expect 2 "--qd" -- eval --q 0,0,-0.8 --qd nan,0,0
expect 2 "--fd" -- eval --q 0,0,-0.8 --fd 1,2,3,4
expect 2 "unknown option" -- eval --q 0,0,-0.8 --frobnicate 1
expect 2 "missing value" -- eval --q
expect 2 "given twice" -- eval --q 0,0,0 --q 0,0,0
expect 2 "unknown command" -- frobnicate
expect 2 "--q is required" -- eval
expect 2 "--stepper" -- simulate --stepper euler
expect 2 "--t-end" -- simulate --t-end x
expect 2 "exclude" -- simulate --harmonic 1,2 --loads "$tmp/loads.csv"
expect 2 "cannot open" -- simulate --scenario "$tmp/nonexistent.txt"
expect 2 "unknown key" -- simulate --scenario <(printf 'velocity = 1\n')
expect 2 "--t-end" -- simulate --t-end -1
# Unreachable or singular states and impossible outputs: exit 1.
expect 1 "not reachable" -- eval --q 1.4,0,-0.8
expect 1 "not reachable" -- ik --q 0,1.5,0
expect 1 "not reachable" -- simulate --q0 1.4,0,-0.8
expect 1 "cannot open for writing" -- simulate --t-end 0.01 --out /nonexistent/dir/x.csv
expect 1 "d out of reach" -- fk --d 1,-1,0
expect 2 "missing column" -- id --traj "$tmp/loads.csv"
expect 2 "cannot open" -- id --traj "$tmp/nonexistent.csv"
expect 1 "cannot create" -- paper --out /proc/nope
expect 0 "" -- --help
expect 0 "" -- simulate --help

finish test_cli
