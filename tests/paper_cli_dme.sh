#!/usr/bin/env bash
# prru dme, prru map and the fig. 7 part of prru paper against the paper's
# model (registered only for models/3prru_paper.json): the spec's w_R at
# home, the ellipse's axes along e1 and e2 there, the symmetry of the
# symmetric design in q1, and the fig. 7 summary.
. "$(dirname "$0")/cli_lib.sh"

[ "$model_sha" = "$paper_sha" ] && ok || bad "paper_cli_dme.sh run for model $model_name ($model_file), not the paper's"

"$PRRU" dme --q 0,0,0 >"$tmp/d.json" || bad "dme at q = 0 failed"
jcheck "$tmp/d.json" "d['status'] == 'ok' and abs(d['w_R'] - 1.80468) < 5e-6" "w_R(0,0) = 1.80468"
jcheck "$tmp/d.json" "d['axis_directions'] == [[1, 0, 0], [0, 1, 0]] and d['translational_direction'] == [0, 0, 1]" "axes at home along e1, v = e2; segment along z"
# Symmetry in q1 through the CLI.
"$PRRU" dme --q 0.3,-0.4,-0.5 >"$tmp/d2.json" || bad "dme failed"
"$PRRU" dme --q -0.3,-0.4,-0.5 >"$tmp/d3.json" || bad "dme failed"
w2=$(json "$tmp/d2.json" "repr(d['w_R'])")
jcheck "$tmp/d3.json" "abs(d['w_R'] - $w2) <= 1e-12 * $w2" "w_R symmetric in q1"

# The map over fig. 7's range: every status appears, w_R symmetric in q1.
"$PRRU" map --q1 -0.5235987755982988:0.5235987755982988:31 --q2 -0.7853981633974483:1.2:25 --q3 0 \
  --rcond-min 4e-3 --out "$tmp/m.csv" >"$tmp/m.txt" 2>"$tmp/m.err" || bad "map failed: $(cat "$tmp/m.err")"
r=$(python3 - "$tmp/m.csv" <<'PY'
import csv, sys
rows = list(csv.reader(l for l in open(sys.argv[1]) if not l.startswith('#')))[1:]
errs = []
st = {}
for r in rows:
    st[r[4]] = st.get(r[4], 0) + 1
if not (st.get('ok') and st.get('singular') and st.get('unreachable')): errs.append('statuses %s' % st)
for i in range(31):
    for j in range(25):
        a, b = rows[i * 25 + j], rows[(30 - i) * 25 + j]
        if float(a[0]) != -float(b[0]) or a[4] != b[4] or (a[4] == 'ok' and abs(float(a[3]) - float(b[3])) > 1e-12 * float(a[3])):
            errs.append('asymmetry %s %s' % (a, b)); break
print('; '.join(errs[:3]) if errs else 'ok')
PY
)
[ "$r" = ok ] && ok || bad "map CSV: $r"

# prru paper's fig. 7 summary quotes the paper's value next to the computed one.
"$PRRU" paper --out "$tmp/paper" >"$tmp/paper.out" 2>"$tmp/paper.err"
rc=$?
if [ $rc -eq 0 ]; then
  grep -qF "w_R(0, 0) = 1.80468076533 (the paper's value: 1.80468)" "$tmp/paper/summary.txt" && ok || bad "summary.txt: w_R(0, 0)"
  [ "$(head -1 "$tmp/paper/fig7_map.csv")" = "$csv_comment" ] && ok || bad "fig7_map.csv: comment line"
  [ "$(grep -vc '^#' "$tmp/paper/fig7_map.csv")" -eq $((201 * 201 + 1)) ] && ok || bad "fig7_map.csv: 201 x 201 rows"
elif grep -q "gnuplot not found" "$tmp/paper.err"; then
  echo "paper_cli_dme: gnuplot not installed, fig. 7 summary not checked"
else
  bad "paper exited $rc: $(head -c 300 "$tmp/paper.err")"
fi

finish paper_cli_dme
