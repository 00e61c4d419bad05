#!/usr/bin/env bash
# The prru command line: outputs checked against the spec's public values,
# round trips through the CSV interfaces, and the exit status and message of
# every kind of bad argument. Needs $PRRU (path to the binary).
. "$(dirname "$0")/cli_lib.sh"

# Numbers from JSON with python (stdlib) so comparisons are numeric.
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

# eval at the spec's public reference point.
"$PRRU" eval --q 0.1,0.2,-0.8 --qd 0.3,-0.4,0.5 >"$tmp/e.json" || bad "eval failed"
r=$(json "$tmp/e.json" "max(abs(a-b)/abs(b) for a,b in [(d['M'][0],0.45906598061227876),(d['M'][5],-0.75886870659132982),(d['h'][2],-0.061280218724993618),(d['G'][1],7.4445020116609459),(d['d'][2],-0.63523945236562458),(d['Jd'][7],-0.2418333257655752)])")
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-12 else 1)" "$r" && ok || bad "eval vs spec point: rel err $r"
n=$(json "$tmp/e.json" "len(d['lambda'])"); [ "$n" = 57 ] && ok || bad "lambda has $n entries"
[ "$(json "$tmp/e.json" "d['lambda_labels'][0]+d['lambda_labels'][56]")" = "C1_fxP3_mz" ] && ok || bad "lambda labels"
# qdd from eval satisfies M qdd + h = G + J_d^T fd with the printed M, h, G, J_d.
"$PRRU" eval --q 0.1,0.2,-0.8 --qd 0.3,-0.4,0.5 --fd 50,40,25 >"$tmp/f.json" || bad "eval with loads"
r=$(json "$tmp/f.json" "max(abs(sum(d['M'][3*i+j]*d['qdd'][j] for j in range(3)) + d['h'][i] - d['G'][i] - sum(d['Jd'][3*j+i]*d['fd'][j] for j in range(3)))/130 for i in range(3))")
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-14 else 1)" "$r" && ok || bad "eval qdd residual $r"

# ik / fk round trip.
"$PRRU" ik --q 0,0,0 >"$tmp/ik.json" || bad "ik failed"
r=$(json "$tmp/ik.json" "abs(d['d'][0]-0.2116601048851672)")
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-15 else 1)" "$r" && ok || bad "ik at q=0: $r"
"$PRRU" fk --d -0.61587356199245987,-0.56196351700317267,-0.63523945236562458 >"$tmp/fk.json" || bad "fk failed"
r=$(json "$tmp/fk.json" "max(abs(a-b) for a,b in zip(d['q'],[0.1,0.2,-0.8]))")
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-12 else 1)" "$r" && ok || bad "fk(ik(q)) off by $r"

# simulate -> id recovers the constant actuator forces.
"$PRRU" simulate --q0 0.05,0.1,-0.8 --fd 55,45,30 --t-end 0.2 --dt 0.01 --out "$tmp/sim.csv" || bad "simulate failed"
[ "$(head -1 "$tmp/sim.csv" | cut -d, -f1-10)" = "t,q1,q2,q3,qd1,qd2,qd3,d1,d2,d3" ] && ok || bad "CSV header"
[ "$(wc -l <"$tmp/sim.csv")" -eq 22 ] && ok || bad "21 samples expected, got $(($(wc -l <"$tmp/sim.csv") - 1))"
"$PRRU" id --traj "$tmp/sim.csv" --out "$tmp/id.csv" || bad "id failed"
r=$(python3 - "$tmp/id.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print(max(abs(float(r['fd%d' % (i + 1)]) - f) / f for r in rows for i, f in enumerate((55, 45, 30))))
PY
)
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-9 else 1)" "$r" && ok || bad "id of simulate: rel err $r"

# Scenario files and the paper scenario.
printf 'q0 = 0, 0.5235987755982988, -0.8\nfd = 50, 40, 25\nharmonic = 50, 12.566370614359172\nt_end = 0.05\ndt = 0.01\n' >"$tmp/s.txt"
"$PRRU" simulate --scenario "$tmp/s.txt" --out "$tmp/s.csv" || bad "scenario file run"
"$PRRU" simulate --scenario paper --t-end 0.05 --dt 0.01 --out "$tmp/p.csv" || bad "paper scenario run"
cmp -s <(cut -d, -f1-10 "$tmp/s.csv") <(cut -d, -f1-10 "$tmp/p.csv") && ok || bad "scenario file = built-in paper scenario"
printf 't,fd1,fd2,fd3\n0,50,40,25\n1,50,40,25\n' >"$tmp/loads.csv"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --loads "$tmp/loads.csv" --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/t.csv" || bad "loads table run"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --fd 50,40,25 --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/c.csv" || bad "constant run"
cmp -s "$tmp/t.csv" "$tmp/c.csv" && ok || bad "constant table = constant forces"

# Runs that leave the workspace keep their rows and exit 1.
expect 1 "stopped at t =" -- simulate --q0 0,0,-0.8 --fd 200,-100,0 --t-end 2 --dt 0.01 --out "$tmp/stop.csv"
rows=$(($(wc -l <"$tmp/stop.csv") - 1))
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
