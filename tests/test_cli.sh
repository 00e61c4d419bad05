#!/usr/bin/env bash
# The prru command line, for any model: the model's identity in every
# output, outputs checked against each other (fk(ik(q)), the equations of
# motion with eval's own M, h, G, J_d and passive forces, simulate -> id),
# round trips through the CSV interfaces, and the exit status and message
# of every kind of bad argument. Lists of actuator values have as many
# entries as the model has sliders ($nact, from `prru --version`); a model
# with a redundant fourth actuator also gets its own checks (null vectors,
# id --preload, least-squares fk, the paper scenario's fourth force). The
# paper's numbers are in paper_cli.sh.
# Needs $PRRU (path to the binary), $PRRU_MODEL, $PRRU_SOURCE_DIR.
. "$(dirname "$0")/cli_lib.sh"

# A pose every model in models/ reaches with a regular J_d (checked below),
# and one with velocities. Actuator lists have $nact entries (cli_lib.sh:
# fdlist gives a redundant actuator the third one's value).
Q=0.1,0.2,-0.8
QD=0.3,-0.4,0.5
FD=$(fdlist 50 40 25)

# ---- Model identity ----
[ -n "$prru_version" ] && ok || bad "no project version in $PRRU_SOURCE_DIR/CMakeLists.txt"
"$PRRU" --version >"$tmp/v.txt" 2>"$tmp/v.err" && ok || bad "--version failed: $(cat "$tmp/v.err")"
printf 'prru %s\nmodel: %s\nmodel file: %s\nmodel format: %s\nmodel actuators: %s\nmodel sha256: %s\nmodel kernels: %s\n' \
  "$prru_version" "$model_name" "$model_file" "$model_format" "$nact" "$model_sha" "$model_kernels" >"$tmp/v.want"
cmp -s "$tmp/v.txt" "$tmp/v.want" && ok || bad "--version: got '$(cat "$tmp/v.txt")', want '$(cat "$tmp/v.want")'"
"$PRRU" version >"$tmp/v2.txt" && cmp -s "$tmp/v2.txt" "$tmp/v.want" && ok || bad "'prru version' differs from --version"
expect 2 "takes no arguments" -- --version extra
# The actuators --version reports are the model file's sliders S1..Sn.
file_nact=$(python3 -c 'import json, sys; print(sum(1 for b in json.load(open(sys.argv[1]))["bodies"] if b[0] == "S"))' "$PRRU_MODEL")
[ "$nact" = "$file_nact" ] && ok || bad "--version says $nact actuators, the model file has $file_nact sliders"
"$PRRU" --help >"$tmp/h.txt" && grep -q -- "--version" "$tmp/h.txt" && grep -qF "$model_name ($model_file)" "$tmp/h.txt" \
  && ok || bad "usage does not mention --version and the model: $(head -c 300 "$tmp/h.txt")"
# Every command the usage lists answers COMMAND --help with its usage
# (docs/cli.md is made of them; `version --help` was exit 2).
for c in $(sed -n '/^commands:/,/^$/s/^  \([a-z][a-z0-9-]*\) .*/\1/p' "$tmp/h.txt"); do
  "$PRRU" $c --help >"$tmp/hc.txt" 2>&1 && grep -q "^usage: prru $c" "$tmp/hc.txt" && ok ||
    bad "$c --help: no usage line: $(head -c 200 "$tmp/hc.txt")"
done
# No help text counts reactions or actuators with another model's numbers.
for c in eval simulate ik fk id dme map paper; do
  "$PRRU" $c --help >"$tmp/help_$c.txt" || bad "$c --help failed"
done
nl=$(python3 -c "import json, subprocess, sys; print(len(json.loads(subprocess.run([sys.argv[1], 'eval', '--q', '$Q'], capture_output=True, text=True).stdout)['lambda']))" "$PRRU")
tr '\n' ' ' <"$tmp/help_eval.txt" | grep -q "the $nl joint reaction" && tr '\n' ' ' <"$tmp/help_simulate.txt" | grep -q "the $nl joint reaction" \
  && ok || bad "help texts do not give the model's $nl reaction coordinates"
grep -qi "spec" "$tmp"/help_*.txt && bad "help text talks of 'spec'" || ok
# Help speaks of the robot and the numbers, not of the code inside.
for c in plot animate traj track excite identify optimize sensitivity merge; do
  "$PRRU" $c --help >"$tmp/help_$c.txt" || bad "$c --help failed"
done
# The words of the model identity (KERNELS kernels, the JSON member
# "kernels") and the environment variable PRRU_MODEL are the user's.
user_words='s/PRRU_MODEL//g; s/KERNELS kernels//g; s/^KERNELS: //; s/sha256, kernels/sha256/g'
# (gen's help is the generator's: C kernels and their prefix are its subject.)
for f in $(ls "$tmp"/help_*.txt | grep -v '/help_gen\.txt$') "$tmp/h.txt"; do
  sed "$user_words" "$f" | grep -n -i -E "gsl|odeiv|hybridsj|kernel|descriptor|(^|[^a-z0-9])prru_[a-z]|runtime|generated" | sed "s|^|$f:|"
  sed "$user_words" "$f" | grep -n -E "PRRU_|DBL_" | sed "s|^|$f:|"
done >"$tmp/jargon.txt"
[ -s "$tmp/jargon.txt" ] && bad "help texts with internal names: $(head -c 300 "$tmp/jargon.txt")" || ok
grep -qF -- "--fd $(act_names f)" "$tmp/help_eval.txt" && grep -qF -- "--d $(act_names d) " "$tmp/help_fk.txt" \
  && grep -qF "t,$(act_names fd) (N)" "$tmp/help_id.txt" && ok || bad "help texts do not list the model's $nact actuators"
# Help lines fit a terminal.
awk 'length > 80 { print FILENAME ": " $0; bad = 1 } END { exit bad }' "$tmp/h.txt" "$tmp"/help_*.txt >"$tmp/long.txt" \
  && ok || bad "help lines over 80 characters: $(head -c 300 "$tmp/long.txt")"

# ---- eval: the model object and the equations of motion ----
"$PRRU" eval --q "$Q" --qd "$QD" --fd "$FD" >"$tmp/f.json" || bad "eval with loads failed"
jcheck "$tmp/f.json" "d['model'] == model" "eval: model object"
jcheck "$tmp/f.json" "len(d['lambda']) == len(d['lambda_labels']) == len(set(d['lambda_labels'])) > 0" "eval: one unique label per reaction coordinate"
jcheck "$tmp/f.json" "len(d['d']) == len(d['fd']) == $nact and len(d['Jd']) == len(d['d']) and all(len(r) == 3 for r in d['Jd']) and len(d['M']) == 3 and all(len(r) == 3 for r in d['M']) and len(d['passive']) == 3" "eval: sizes"
jcheck "$tmp/f.json" "0 < d['Jd_rcond'] and all(math.isfinite(x) for x in d['lambda'] + d['qdd'])" "eval: regular and finite at $Q"
# M qdd + h = G + J_d^T fd + passive with the printed M, h, G, J_d, passive.
r=$(json "$tmp/f.json" "max(abs(sum(d['M'][i][j]*d['qdd'][j] for j in range(3)) + d['h'][i] - d['G'][i] - d['passive'][i] - sum(d['Jd'][j][i]*d['fd'][j] for j in range(len(d['fd'])))) / (1 + abs(d['G'][i]) + sum(abs(x) for x in d['fd'])) for i in range(3))")
below "$r" 1e-13 "eval qdd residual (with passive forces)"
# Passive drive forces: zero at rest for any model; at speed non-zero
# exactly when the model has damping or Coulomb friction.
"$PRRU" eval --q "$Q" --fd "$FD" >"$tmp/rest.json" || bad "eval at rest failed"
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
"$PRRU" simulate --q0 0.05,0.1,-0.8 --fd "$(fdlist 55 45 30)" --t-end 0.2 --dt 0.01 --out "$tmp/sim.csv" || bad "simulate failed"
[ "$(head -1 "$tmp/sim.csv")" = "$csv_comment" ] && ok || bad "CSV comment line: '$(head -1 "$tmp/sim.csv")', want '$csv_comment'"
[ "$(sed -n 2p "$tmp/sim.csv" | cut -d, -f1-$((7 + nact)))" = "t,q1,q2,q3,qd1,qd2,qd3,$(act_names d)" ] && ok || bad "CSV header"
[ "$(grep -vc '^#' "$tmp/sim.csv")" -eq 22 ] && ok || bad "21 samples expected, got $(($(grep -vc '^#' "$tmp/sim.csv") - 1))"
[ "$(grep -c '^#' "$tmp/sim.csv")" -eq 1 ] && ok || bad "one comment line expected"
"$PRRU" id --traj "$tmp/sim.csv" --out "$tmp/id.csv" || bad "id failed"
[ "$(head -1 "$tmp/id.csv")" = "$csv_comment" ] && ok || bad "id: CSV comment line"
# Three actuators: id gives back the forces. More: the least-norm forces,
# which differ from the simulated ones only along the null vector n of
# J_d^T (id --null-vector writes it), so fd_sim - fd_id = ((fd_sim) . n) n.
if [ "$nact" -gt 3 ]; then
  "$PRRU" id --traj "$tmp/sim.csv" --null-vector --out "$tmp/idn.csv" || bad "id --null-vector failed"
else
  cp "$tmp/id.csv" "$tmp/idn.csv"
fi
r=$(python3 - "$tmp/idn.csv" "$(fdlist 55 45 30)" <<'PY'
import csv, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#')))
fsim = [float(x) for x in sys.argv[2].split(',')]
N = len(fsim)
assert len(rows) == 21, len(rows)
err = 0
for r in rows:
    fd = [float(r['fd%d' % (i + 1)]) for i in range(N)]
    if 'n1' in r:
        n = [float(r['n%d' % (i + 1)]) for i in range(N)]
        t = sum(a * b for a, b in zip(fsim, n))
        fd = [a + t * b for a, b in zip(fd, n)]
    err = max(err, max(abs(a - b) / abs(b) for a, b in zip(fd, fsim)))
print(err)
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
grep -qxF "model: $model_id" "$tmp/map.txt" && ok || bad "map summary lacks the model: $(cat "$tmp/map.txt")"

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
grep -qF "Model: $model_id" "$tmp/paper/summary.txt" && ok || bad "summary.txt lacks the model"
[ "$(head -1 "$tmp/paper/paper_sim.csv")" = "$csv_comment" ] && ok || bad "paper_sim.csv: comment line"
[ "$(grep -vc '^#' "$tmp/paper/paper_sim.csv")" -eq 1002 ] && ok || bad "paper_sim.csv: 1001 samples expected"
# Each figure says which of the paper's figures it is, or that it is none.
if [ $rc -eq 0 ]; then
  for f in fig_q fig_d fig4_u_joint_forces fig5_p_joint_forces fig6_p_joint_moments; do
    [ "$(head -c 8 "$tmp/paper/$f.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] && ok || bad "paper: $f.png is not a PNG"
  done
  for label in "fig4_u_joint_forces.png.*paper fig. 4" "fig5_p_joint_forces.png.*paper fig. 5" \
               "fig6_p_joint_moments.png.*paper fig. 6" "fig_q.png.*not one of its figures" "fig_d.png.*not one of its figures"; do
    tr '\n' ' ' <"$tmp/paper/paper_plots.gp" | sed 's/set output/\n/g' | grep -q "$label" && ok || bad "paper_plots.gp: no '$label'"
  done
fi
# Deterministic: a second run writes the same files (no timestamps).
"$PRRU" paper --out "$tmp/paper2" --skip-map >/dev/null 2>&1
cmp -s "$tmp/paper/paper_sim.csv" "$tmp/paper2/paper_sim.csv" && cmp -s "$tmp/paper/summary.txt" "$tmp/paper2/summary.txt" \
  && ok || bad "paper outputs differ between two runs"

# ---- Scenario files, the paper scenario and load tables ----
printf 'q0 = 0, 0.5235987755982988, -0.8\nfd = %s\nharmonic = 50, 12.566370614359172\nt_end = 0.05\ndt = 0.01\n' "$FD" >"$tmp/s.txt"
"$PRRU" simulate --scenario "$tmp/s.txt" --out "$tmp/s.csv" || bad "scenario file run"
"$PRRU" simulate --scenario paper --t-end 0.05 --dt 0.01 --out "$tmp/p.csv" || bad "paper scenario run"
cmp -s "$tmp/s.csv" "$tmp/p.csv" && ok || bad "scenario file (fd = $FD) = built-in paper scenario"
printf 't,%s\n0,%s\n1,%s\n' "$(act_names fd)" "$FD" "$FD" >"$tmp/loads.csv"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --loads "$tmp/loads.csv" --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/t.csv" || bad "loads table run"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --fd "$FD" --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/c.csv" || bad "constant run"
cmp -s "$tmp/t.csv" "$tmp/c.csv" && ok || bad "constant table = constant forces"
# A load table with the comment line `prru id` writes is read too.
{ echo "$csv_comment"; cat "$tmp/loads.csv"; } >"$tmp/loads_c.csv"
"$PRRU" simulate --q0 0,0.5235987755982988,-0.8 --loads "$tmp/loads_c.csv" --t-end 0.05 --dt 0.01 --no-reactions >"$tmp/tc.csv" || bad "loads table with a comment line"
cmp -s "$tmp/tc.csv" "$tmp/c.csv" && ok || bad "commented table = constant forces"

# Runs that leave the workspace keep their rows and exit 1.
expect 1 "stopped at t =" -- simulate --q0 0,0,-0.8 --fd "$(fdlist 200 -100 0)" --t-end 2 --dt 0.01 --out "$tmp/stop.csv"
rows=$(($(grep -vc '^#' "$tmp/stop.csv") - 1))
[ "$rows" -gt 1 ] && [ "$rows" -lt 201 ] && ok || bad "stopped run kept $rows rows"
grep -qi nan "$tmp/stop.csv" && bad "NaN in a CSV" || ok

# ---- Redundant actuation (more sliders than coordinates, spec section 12) ----
if [ "$nact" -gt 3 ]; then
  # eval: n spans null(J_d^T) (unit, last component positive), preload =
  # fd . n, z spans the reactions that load nothing (unit), lambda is the
  # least-norm solution (lambda . z = 0).
  jcheck "$tmp/f.json" "len(d['actuator_null']) == $nact and abs(sum(x * x for x in d['actuator_null']) - 1) < 1e-14 and d['actuator_null'][-1] > 0" "eval: actuator_null unit, n_N > 0"
  jcheck "$tmp/f.json" "max(abs(sum(d['Jd'][i][k] * d['actuator_null'][i] for i in range($nact))) for k in range(3)) < 1e-14" "eval: J_d^T n = 0"
  jcheck "$tmp/f.json" "abs(d['preload'] - sum(a * b for a, b in zip(d['fd'], d['actuator_null']))) < 1e-12" "eval: preload = fd . n"
  jcheck "$tmp/f.json" "len(d['reaction_null']) == len(d['lambda']) and abs(sum(x * x for x in d['reaction_null']) - 1) < 1e-14" "eval: reaction_null unit"
  jcheck "$tmp/f.json" "abs(sum(a * b for a, b in zip(d['lambda'], d['reaction_null']))) < 1e-12 * max(abs(x) for x in d['lambda'])" "eval: lambda . reaction_null = 0 (least norm)"
  # fd and fd + t n move the robot identically.
  fdt=$(json "$tmp/f.json" "','.join(repr(a + 30 * b) for a, b in zip(d['fd'], d['actuator_null']))")
  "$PRRU" eval --q "$Q" --qd "$QD" --fd "$fdt" >"$tmp/ft.json" || bad "eval with a preload failed"
  r=$(python3 -c "import json, sys; a, b = (json.load(open(f)) for f in sys.argv[1:]); print(max(abs(x - y) / (1 + abs(y)) for x, y in zip(a['qdd'], b['qdd'])), abs(a['preload'] - b['preload'] - 30))" "$tmp/ft.json" "$tmp/f.json")
  below "${r% *}" 1e-12 "eval: fd + 30 n changes qdd"
  below "${r#* }" 1e-11 "eval: fd + 30 n does not add 30 N of preload"
  # ik prints the same n.
  jcheck "$tmp/ik.json" "len(d['actuator_null']) == $nact" "ik: actuator_null"
  n_ik=$(json "$tmp/ik.json" "d['actuator_null']") n_ev=$(json "$tmp/f.json" "d['actuator_null']")
  [ "$n_ik" = "$n_ev" ] && ok || bad "ik and eval give different null vectors: $n_ik, $n_ev"

  # id --preload T: the forces move along n by exactly T (fd . n = T), and
  # J_d^T fd, what moves the robot, stays.
  "$PRRU" id --traj "$tmp/sim.csv" --preload 12.5 --null-vector --out "$tmp/idp.csv" || bad "id --preload failed"
  sed -n 2p "$tmp/idp.csv" | grep -q "^# fd = least-norm actuator forces + preload 12.5 N along n" && ok || bad "id: preload comment: $(sed -n 2p "$tmp/idp.csv")"
  [ "$(grep -v '^#' "$tmp/idp.csv" | head -1)" = "t,$(act_names fd),$(act_names n)" ] && ok || bad "id --null-vector header"
  python3 - "$tmp/idn.csv" "$tmp/idp.csv" "$tmp/sim.csv" "$PRRU" <<'PY' >"$tmp/idp.txt"
import csv, json, subprocess, sys
rd = lambda f: list(csv.DictReader(l for l in open(f) if not l.startswith('#')))
a, b, sim = rd(sys.argv[1]), rd(sys.argv[2]), rd(sys.argv[3])
N = sum(1 for k in a[0] if k.startswith('fd'))
T = 12.5
shift = dot = jt = 0
for k, (ra, rb) in enumerate(zip(a, b)):
    fa = [float(ra['fd%d' % (i + 1)]) for i in range(N)]
    fb = [float(rb['fd%d' % (i + 1)]) for i in range(N)]
    n = [float(rb['n%d' % (i + 1)]) for i in range(N)]
    scale = 1 + max(abs(x) for x in fa) + T
    shift = max(shift, max(abs(y - x - T * m) for x, y, m in zip(fa, fb, n)) / scale)
    dot = max(dot, abs(sum(x * m for x, m in zip(fb, n)) - T) / scale)
    dot = max(dot, abs(sum(x * m for x, m in zip(fa, n))) / scale)
    if k % 10 == 0:  # J_d^T fd unchanged, with ik's J_d at the row's pose
        q = ','.join(sim[k][c] for c in ('q1', 'q2', 'q3'))
        J = json.loads(subprocess.run([sys.argv[4], 'ik', '--q', q], capture_output=True, text=True).stdout)['Jd']
        jt = max(jt, max(abs(sum(J[i][c] * (y - x) for i, (x, y) in enumerate(zip(fa, fb)))) for c in range(3)) / scale)
print(shift, dot, jt)
PY
  read -r shift dot jt <"$tmp/idp.txt"
  below "${shift:-1}" 1e-14 "id --preload: fd_T - fd_0 = T n"
  below "${dot:-1}" 1e-14 "id --preload: fd_T . n = T, fd_0 . n = 0"
  below "${jt:-1}" 1e-14 "id --preload: J_d^T fd depends on T"
  # Without --preload: the same forces as --preload 0, and as before.
  "$PRRU" id --traj "$tmp/sim.csv" --preload 0 --out "$tmp/id0.csv" && cmp -s "$tmp/id0.csv" "$tmp/id.csv" && ok || bad "id --preload 0 differs from id"
  expect 2 "--preload: 'nan'" -- id --traj "$tmp/sim.csv" --preload nan
  expect 2 "--preload: '1e400'" -- id --traj "$tmp/sim.csv" --preload 1e400
  # A table with n columns is not a load table; the forces alone, preload
  # and all, simulate back to the same motion (sampled densely: simulate
  # interpolates the table linearly).
  "$PRRU" simulate --q0 0.05,0.1,-0.8 --loads "$tmp/idp.csv" --t-end 0.2 --dt 0.01 --no-reactions >/dev/null 2>"$tmp/err" \
    && bad "simulate read a table with n columns as loads" || ok
  "$PRRU" simulate --q0 0.05,0.1,-0.8 --fd "$(fdlist 55 45 30)" --t-end 0.2 --dt 0.001 --no-reactions --out "$tmp/simf.csv" || bad "simulate, dt 1 ms"
  "$PRRU" id --traj "$tmp/simf.csv" --preload -40 --out "$tmp/idm.csv" || bad "id --preload -40"
  "$PRRU" simulate --q0 0.05,0.1,-0.8 --loads "$tmp/idm.csv" --t-end 0.2 --dt 0.001 --no-reactions --out "$tmp/sim2.csv" || bad "simulate with id's forces"
  r=$(python3 - "$tmp/simf.csv" "$tmp/sim2.csv" <<'PY'
import csv, sys
rd = lambda f: list(csv.DictReader(l for l in open(f) if not l.startswith('#')))
a, b = rd(sys.argv[1]), rd(sys.argv[2])
print(max(abs(float(x[c]) - float(y[c])) for x, y in zip(a, b) for c in ('q1', 'q2', 'q3')) if len(a) == len(b) == 201 else 1)
PY
)
  below "$r" 1e-7 "simulate with id --preload -40 forces does not retrace the motion"

  # fk: least squares; fk and fk --lsq of ik(q) give q back; inconsistent
  # sliders are refused without --lsq and fitted with it.
  for q in 0.1,0.2,-0.8 -0.3,0.4,-0.6 0.25,-0.35,0.05; do
    "$PRRU" ik --q "$q" >"$tmp/ikq.json" || { bad "ik $q"; continue; }
    dq=$(json "$tmp/ikq.json" "','.join(repr(x) for x in d['d'])")
    for lsq in "" --lsq; do
      "$PRRU" fk --d "$dq" $lsq >"$tmp/fkq.json" || { bad "fk $lsq of ik($q) failed"; continue; }
      jcheck "$tmp/fkq.json" "d['method'] == 'least-squares' and d['consistent'] is True and d['residual'] < 1e-13 and max(abs(a - b) for a, b in zip(d['q'], [$q])) < 1e-12" "fk $lsq of ik($q)"
    done
  done
  dbad=$(json "$tmp/ik.json" "','.join(repr(x + (1e-4 if i == len(d['d']) - 1 else 0)) for i, x in enumerate(d['d']))")
  expect 1 "inconsistent" -- fk --d "$dbad"
  grep -qF -- "--lsq accepts that fit" "$tmp/err" && ok || bad "fk of inconsistent sliders: no hint at --lsq: $(cat "$tmp/err")"
  [ ! -s "$tmp/out" ] && ok || bad "fk of inconsistent sliders printed a result"
  "$PRRU" fk --d "$dbad" --lsq >"$tmp/fkl.json" || bad "fk --lsq of inconsistent sliders failed"
  jcheck "$tmp/fkl.json" "d['consistent'] is False and 1e-6 < d['residual'] < 1e-4 and max(abs(a - b) for a, b in zip(d['q'], [$Q])) < 1e-3" "fk --lsq of inconsistent sliders"

  # prru paper: the fourth actuator's force is said and documented.
  grep -qF "fd = ($(fdlist 50 40 25 | sed 's/,/, /g')) N" "$tmp/paper/summary.txt" && grep -q "least-norm" "$tmp/paper/summary.txt" \
    && ok || bad "paper summary: fd or the least-norm reactions not stated: $(head -5 "$tmp/paper/summary.txt")"
  grep -q "Limb 4 mirrors" "$tmp/help_paper.txt" && ok || bad "paper --help does not say what the fourth actuator gets"
  grep -qF "J_d^+" "$tmp/help_dme.txt" && ok || bad "dme --help does not name J_d^+"
else
  # Three actuators: the forces are unique; no null vectors in the JSON.
  expect 2 "no internal preload exists" -- id --traj "$tmp/sim.csv" --preload 5
  expect 2 "--null-vector" -- id --traj "$tmp/sim.csv" --null-vector
  jcheck "$tmp/f.json" "'actuator_null' not in d and 'reaction_null' not in d and 'preload' not in d" "eval of a 3-actuator model: no null vectors"
  jcheck "$tmp/ik.json" "'actuator_null' not in d" "ik of a 3-actuator model: no null vector"
  # fk --lsq agrees with Newton.
  "$PRRU" fk --d "$(json "$tmp/ik.json" "','.join(repr(x) for x in d['d'])")" --lsq >"$tmp/fkl.json" || bad "fk --lsq failed"
  jcheck "$tmp/fkl.json" "d['method'] == 'least-squares' and d['consistent'] is True and max(abs(a - b) for a, b in zip(d['q'], [$Q])) < 1e-12" "fk --lsq of ik(q)"
  jcheck "$tmp/fk.json" "d['method'] == 'newton'" "fk: Newton by default"
  grep -qF "J_d^-1" "$tmp/help_dme.txt" && ! grep -qF "J_d^+" "$tmp/help_dme.txt" && ok || bad "dme --help of a 3-actuator model: J_d^-1"
fi

# ---- linearize: the closed-form derivatives and the state-space pairs ----
"$PRRU" linearize --q "$Q" --qd "$QD" --fd "$FD" --dt 0.001 >"$tmp/lin.json" || bad "linearize failed"
jcheck "$tmp/lin.json" "d['model'] == model and d['dt'] == 0.001" "linearize: model object and dt"
jcheck "$tmp/lin.json" "[(len(d[k]), len(d[k][0])) for k in ('dqdd_dq', 'dqdd_dqd', 'dqdd_dfd', 'dqdd_dfp', 'dqdd_dmp', 'A', 'B', 'Ad', 'Bd')] == [(3, 3), (3, 3), (3, $nact), (3, 3), (3, 3), (6, 6), (6, $nact), (6, 6), (6, $nact)]" "linearize: sizes"
jcheck "$tmp/lin.json" "all(d['A'][i][k] == (1 if k == i + 3 else 0) for i in range(3) for k in range(6)) and all(d['A'][3 + i] == d['dqdd_dq'][i] + d['dqdd_dqd'][i] and d['B'][3 + i] == d['dqdd_dfd'][i] and d['B'][i] == [0] * $nact for i in range(3))" "linearize: A = [0 I; dqdd_dq dqdd_dqd], B = [0; dqdd_dfd]"
# qdd is eval's (the same expressions in another kernel: rounding apart,
# a few ulps of the terms, which are at most 1e3 times qdd here).
"$PRRU" eval --q "$Q" --qd "$QD" --fd "$FD" >"$tmp/lin_eval.json" || bad "eval for linearize failed"
r=$(python3 -c "import json, sys; a, b = (json.load(open(f))['qdd'] for f in sys.argv[1:]); print(max(abs(x - y) / (1 + abs(y)) for x, y in zip(a, b)))" "$tmp/lin.json" "$tmp/lin_eval.json")
below "$r" 1e-12 "linearize: qdd against eval's"
"$PRRU" linearize --q "$Q" --qd "$QD" --fd "$FD" >"$tmp/lin0.json" || bad "linearize without --dt failed"
jcheck "$tmp/lin0.json" "'Ad' not in d and 'Bd' not in d and 'dt' not in d" "linearize without --dt: no discrete pair"
expect 2 "--dt" -- linearize --q "$Q" --qd "$QD" --fd "$FD" --dt 0
expect 2 "--dt" -- linearize --q "$Q" --qd "$QD" --fd "$FD" --dt -0.001
expect 2 "--dt" -- linearize --q "$Q" --qd "$QD" --fd "$FD" --dt nan
expect 2 "are required" -- linearize --q "$Q" --fd "$FD"
expect 1 "outside the workspace" -- linearize --q 3,0,-0.8 --qd 0,0,0 --fd "$FD"
# A model of other numbers loaded at run time (the topology's kernels):
# its own qdd, eval's.
if [ "$nact" = 3 ] && [ "$(basename "$PRRU_MODEL")" != prototype_drives.json ]; then
  other=$PRRU_SOURCE_DIR/models/prototype_drives.json
  "$PRRU" --model "$other" linearize --q 0,0,0.1 --qd 0.1,0.2,0.3 --fd 1,2,3 >"$tmp/lin_other.json" &&
    "$PRRU" --model "$other" eval --q 0,0,0.1 --qd 0.1,0.2,0.3 --fd 1,2,3 >"$tmp/lin_other_eval.json" ||
    bad "linearize or eval with --model $other failed"
  jcheck "$tmp/lin_other.json" "d['model']['kernels'] == 'parameter'" "linearize --model: the parameter kernels"
  r=$(python3 -c "import json, sys; a, b = (json.load(open(f))['qdd'] for f in sys.argv[1:]); print(max(abs(x - y) / (1 + abs(y)) for x, y in zip(a, b)))" "$tmp/lin_other.json" "$tmp/lin_other_eval.json")
  below "$r" 1e-12 "linearize --model: qdd against eval's"
fi

# Bad arguments: exit 2 and a message naming the argument.
expect 2 "--q" -- eval --q 0.1,0.2
expect 2 "--q" -- eval --q 0.1,abc,0
expect 2 "--qd" -- eval --q 0,0,-0.8 --qd nan,0,0
expect 2 "--fd" -- eval --q 0,0,-0.8 --fd "$(nlist 1),5"
expect 2 "--fd" -- eval --q 0,0,-0.8 --fd 1,2
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
if [ "$nact" -gt 3 ]; then
  expect 1 "no pose reproduces all $nact slider positions" -- fk --d "$(fdlist 1 -1 0)"
else
  expect 1 "d out of reach" -- fk --d 1,-1,0
fi
expect 2 "--d" -- fk --d "$(nlist 0.2),0.2"
expect 2 "missing column" -- id --traj "$tmp/loads.csv"
expect 2 "cannot open" -- id --traj "$tmp/nonexistent.csv"
expect 1 "cannot create" -- paper --out /proc/nope
expect 0 "" -- --help
expect 0 "" -- simulate --help

# ---- one number syntax: multiples of pi wherever numbers are read ----
"$PRRU" eval --q 0,pi/6,-0.8 --qd -pi/4,2pi,0.5pi >"$tmp/pi.json" || bad "eval with pi failed"
"$PRRU" eval --q 0,0.52359877559829882,-0.8 --qd -0.78539816339744828,6.2831853071795862,1.5707963267948966 \
  >"$tmp/dec.json" || bad "eval failed"
cmp -s "$tmp/pi.json" "$tmp/dec.json" && ok || bad "eval: pi/6, -pi/4, 2pi, 0.5pi are not the decimal values"
"$PRRU" ik --q 0.1,2*pi/30,-0.8 >"$tmp/pi.json" && "$PRRU" ik --q 0.1,0.20943951023931953,-0.8 >"$tmp/dec.json" \
  && cmp -s "$tmp/pi.json" "$tmp/dec.json" && ok || bad "ik: 2*pi/30 is not 0.20943951023931953"
for v in "2 pi" "pi/-6" "pi/0" "pix" "--pi" "pi*2" "2pi/" "/6" "p" "1e400pi" "pi/6pi" "nanpi" "0xpi"; do
  expect 2 "is not 3 comma-separated finite numbers" -- ik --q "0,$v,-0.8"
done
# ---- one JSON matrix layout: a list of rows ----
"$PRRU" ik --q 0.1,0.2,-0.8 >"$tmp/ik.json" || bad "ik failed"
"$PRRU" dme --q 0.1,0.2,-0.8 >"$tmp/dme.json" || bad "dme failed"
jcheck "$tmp/ik.json" "len(d['Jd']) == $nact and all(isinstance(r, list) and len(r) == 3 for r in d['Jd'])" "ik: Jd is $nact rows of 3"
jcheck "$tmp/f.json" "[len(r) for r in d['M']] == [3, 3, 3] and len(d['Jd']) == $nact" "eval: M and Jd as rows"
jcheck "$tmp/dme.json" "[len(r) for r in d['Mt']] == [$nact] * $nact and [len(r) for r in d['JtR']] == [$nact] * 3 and [len(r) for r in d['axis_directions']] == [3, 3]" "dme: Mt, JtR, axes as rows"
"$PRRU" ik --q "$Q" >"$tmp/ikq.json" || bad "ik failed"
jcheck "$tmp/f.json" "d['Jd'] == json.load(open('$tmp/ikq.json'))['Jd']" "eval and ik print the same Jd rows"
# ---- --out - means stdout; a command that writes a directory refuses it ----
expect 2 "--out -: the study is a directory of files" -- paper --out -
[ ! -e ./- ] && ok || bad "paper --out - created a directory named -"

# ---- prru gen: the generator behind the tool, byte for byte ----
"$PRRU" gen "$PRRU_SOURCE_DIR/models/prototype_example.json" --out "$tmp/gen_cli" --quiet &&
  python3 "$PRRU_SOURCE_DIR/gen/prru_gen.py" "$PRRU_SOURCE_DIR/models/prototype_example.json" --out "$tmp/gen_py" \
    --quiet && diff -r "$tmp/gen_cli" "$tmp/gen_py" >/dev/null && [ -s "$tmp/gen_cli/proto_kernels.c" ] &&
  ok || bad "prru gen differs from gen/prru_gen.py"
"$PRRU" gen --help | grep -q -- "--precision" && ok || bad "prru gen --help is the generator's"
expect 1 "cannot read" -- gen "$tmp/no such model.json" --out "$tmp/gen_none"
[ ! -e "$tmp/gen_none" ] && ok || bad "prru gen wrote for a missing model"
PRRU_GENERATOR="$tmp/missing gen.py" "$PRRU" gen --help >/dev/null 2>"$tmp/err"
[ $? = 2 ] && grep -q "PRRU_GENERATOR=$tmp/missing gen.py" "$tmp/err" && ok || bad "PRRU_GENERATOR missing: $(cat "$tmp/err")"

finish test_cli
