#!/usr/bin/env bash
# The prru command line against the paper's model (registered only when the
# kernels come from models/3prru_paper.json): the spec's public reference
# point, its reaction layout, the slider positions of known poses, the
# paper's singular pose and `prru paper` naming the model without a warning.
# Needs $PRRU (path to the binary).
. "$(dirname "$0")/cli_lib.sh"

[ "$model_sha" = "$paper_sha" ] && ok || bad "paper_cli.sh run for model $model_name ($model_file), not the paper's"

# eval at the spec's public reference point.
"$PRRU" eval --q 0.1,0.2,-0.8 --qd 0.3,-0.4,0.5 >"$tmp/e.json" || bad "eval failed"
r=$(json "$tmp/e.json" "max(abs(a-b)/abs(b) for a,b in [(d['M'][0][0],0.45906598061227876),(d['M'][1][2],-0.75886870659132982),(d['h'][2],-0.061280218724993618),(d['G'][1],7.4445020116609459),(d['d'][2],-0.63523945236562458),(d['Jd'][2][1],-0.2418333257655752)])")
below "$r" 1e-12 "eval vs spec point: rel err"
n=$(json "$tmp/e.json" "len(d['lambda'])"); [ "$n" = 57 ] && ok || bad "lambda has $n entries"
[ "$(json "$tmp/e.json" "d['lambda_labels'][0]+d['lambda_labels'][56]")" = "C1_fxP3_mz" ] && ok || bad "lambda labels"
jcheck "$tmp/e.json" "d['model'] == model and d['model']['name'] == 'paper3prru' and d['model']['file'] == '3prru_paper.json'" "eval: the paper's model object"
jcheck "$tmp/e.json" "d['passive'] == [0, 0, 0]" "the paper's model has no drive damping or friction"
# Help texts count the paper's reactions.
"$PRRU" eval --help | tr '\n' ' ' | grep -q "the 57 joint reaction coordinates" && ok || bad "eval --help: 57 reactions"

# ik at the home pose, fk of the spec point's slider positions.
"$PRRU" ik --q 0,0,0 >"$tmp/ik.json" || bad "ik failed"
r=$(json "$tmp/ik.json" "abs(d['d'][0]-0.2116601048851672)")
below "$r" 1e-15 "ik at q=0"
"$PRRU" fk --d -0.61587356199245987,-0.56196351700317267,-0.63523945236562458 >"$tmp/fk.json" || bad "fk failed"
r=$(json "$tmp/fk.json" "max(abs(a-b) for a,b in zip(d['q'],[0.1,0.2,-0.8]))")
below "$r" 1e-12 "fk(ik(q)) off"

# The paper's singular pose (det J_d = 0 to 3e-17, found by bisection on the
# generated J_d) and a run that crosses it.
QSING=0,-0.80611414893222655,0
expect 1 "singular" -- eval --q "$QSING"
"$PRRU" dme --q "$QSING" >"$tmp/dme.json"
jcheck "$tmp/dme.json" "d['status'] == 'singular'" "dme at $QSING"
expect 1 "stopped at t" -- simulate --q0 0,-0.79,0 --qd0 0,-3,0 --t-end 0.5 --out "$tmp/cross.csv"

# The workspace boundary (issue: eval returned qdd3 = -1.95e19 with exit 0
# here, where the mass matrix's rcond is 5e-16): refused with the reason.
expect 1 "too near the workspace boundary to trust the dynamics" -- \
  eval --q -0.785539441453726,1.0473859219383015,0 --qd 0.3,-0.2,0.1 --fd 50,40,25
# A run into the boundary: the same diagnosis whichever stepper and step
# budget (were: step budget exhausted / integrator failed / not reachable),
# every row before it kept.
for args in "" "--max-steps 10000000" "--stepper rkf45" "--stepper msbdf" "--rtol 1e-6 --atol 1e-6"; do
  # shellcheck disable=SC2086
  expect 1 "the motion reached the workspace boundary at t = 0.447" -- \
    simulate --q0 0.05,-0.1,-0.7 --fd 60,30,20 --t-end 1 $args --out "$tmp/edge.csv"
  rows=$(grep -vc '^#' "$tmp/edge.csv")
  [ "$rows" -eq 449 ] && ok || bad "simulate into the boundary ($args): $rows lines, want a header and 448 rows"
done

# prru paper on the paper's model: no warning, the model in the summary.
"$PRRU" paper --out "$tmp/paper" --skip-map >"$tmp/paper.out" 2>"$tmp/paper.err"
grep -q "warning" "$tmp/paper.err" && bad "paper warns for the paper's model: $(cat "$tmp/paper.err")" || ok
grep -qF "Model: paper3prru (3prru_paper.json, sha256 $paper_sha, specialised kernels), the paper's" "$tmp/paper/summary.txt" && ok || bad "summary.txt: model line"
grep -qF "fd = (50, 40, 25) N," "$tmp/paper/summary.txt" && grep -qF "fp = 50 (sin 4 pi t, -cos 4 pi t, 0) N" "$tmp/paper/summary.txt" \
  && ok || bad "summary.txt: the paper's loads"

finish paper_cli
