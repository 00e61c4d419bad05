#!/usr/bin/env bash
# prru dme and prru map, for any model: JSON and CSV outputs checked with
# python (stdlib), the model's identity in them,
# singular/unreachable poses reported as statuses (null / NaN, never a
# number), the printed global index recomputed from the CSV, and every kind
# of bad grid rejected with exit 2 and a message naming the argument.
. "$(dirname "$0")/cli_lib.sh"
# The paper's values (w_R(0) = 1.80468, symmetry in q1) are in
# paper_cli_dme.sh; these checks hold for any model.
check() { jcheck "$@"; }

# dme at the home pose: the model object and the ellipse's geometry.
"$PRRU" dme --q 0,0,0 >"$tmp/d.json" || bad "dme at q = 0 failed"
check "$tmp/d.json" "d['model'] == model" "dme: model object"
check "$tmp/d.json" "d['status'] == 'ok' and d['w_R'] >= 1" "dme at home: ok, w_R >= 1"
check "$tmp/d.json" "abs(d['semi_axes'][1] / d['semi_axes'][0] - d['w_R']) < 1e-14 * d['w_R']" "w_R = major/minor"
check "$tmp/d.json" "abs(d['sigma'][0] / d['sigma'][1] - d['w_R']) < 1e-14 * d['w_R']" "w_R = sigma1/sigma2"
check "$tmp/d.json" "max(abs(a[2]) for a in d['axis_directions']) < 1e-14 and d['translational_direction'] == [0, 0, 1]" "axes at home in span{e1, e2}; segment along z"
check "$tmp/d.json" "all(abs(sum(x * x for x in a) - 1) < 1e-14 for a in d['axis_directions']) and abs(sum(x * y for x, y in zip(*d['axis_directions']))) < 1e-14" "semi-axis directions orthonormal"
check "$tmp/d.json" "len(d['Mt']) == $nact and all(len(r) == $nact for r in d['Mt'] + d['JtR'] + d['JtT']) and len(d['JtR']) == len(d['JtT']) == 3" "Mt $nact x $nact, JtR and JtT 3 x $nact"
check "$tmp/d.json" "all(abs(d['Mt'][i][j] - d['Mt'][j][i]) == 0 for i in range($nact) for j in range($nact))" "Mt symmetric"
# Away from home: the semi-axes stay in span{e1, v}, v = (0, cos q1, sin q1).
"$PRRU" dme --q 0.3,-0.4,-0.5 >"$tmp/d2.json" || bad "dme failed"
check "$tmp/d2.json" "max(abs(a[1] * math.sin(0.3) - a[2] * math.cos(0.3)) for a in d['axis_directions']) < 1e-14" "semi-axes in span{e1, v}"

# Mt = J_d^+T M J_d^+ with J_d^+ = (J_d^T J_d)^-1 J_d^T (J_d^-1 for three
# actuators), from the M and J_d that prru eval prints at the same pose.
"$PRRU" eval --q 0.3,-0.4,-0.5 >"$tmp/e2.json" || bad "eval failed"
r=$(python3 - "$tmp/d2.json" "$tmp/e2.json" <<'PY'
import json, sys
dm, ev = (json.load(open(f)) for f in sys.argv[1:])
N = len(ev['d'])
J, M = ev['Jd'], ev['M']  # lists of rows
A = [[sum(J[k][i] * J[k][j] for k in range(N)) for j in range(3)] for i in range(3)]
det = (A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
       + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]))
inv = [[(A[(j + 1) % 3][(i + 1) % 3] * A[(j + 2) % 3][(i + 2) % 3] - A[(j + 1) % 3][(i + 2) % 3] * A[(j + 2) % 3][(i + 1) % 3]) / det
        for j in range(3)] for i in range(3)]
P = [[sum(inv[i][k] * J[c][k] for k in range(3)) for c in range(N)] for i in range(3)]  # J_d^+, 3 x N
Mt = [[sum(P[a][r] * M[a][b] * P[b][c] for a in range(3) for b in range(3)) for c in range(N)] for r in range(N)]
scale = max(abs(x) for row in Mt for x in row)
print(max(abs(Mt[r][c] - dm['Mt'][r][c]) for r in range(N) for c in range(N)) / scale)
PY
)
below "$r" 1e-12 "dme Mt differs from J_d^+T M J_d^+ built from eval's M and J_d"

# Unreachable and singular poses: a valid answer (exit 0) with a status and nulls.
"$PRRU" dme --q 0,2,0 >"$tmp/u.json"; [ $? -eq 0 ] && ok || bad "dme of an unreachable pose should exit 0"
check "$tmp/u.json" "d['status'] == 'unreachable' and d['w_R'] is None and d['semi_axes'] == [None, None] and d['translational_half_length'] is None" "unreachable -> nulls"
"$PRRU" dme --q 0,0,0 --rcond-min 0.5 >"$tmp/s.json"; [ $? -eq 0 ] && ok || bad "dme of a singular pose should exit 0"
check "$tmp/s.json" "d['status'] == 'singular' and d['w_R'] is None and 0 < d['Jd_rcond'] < 0.5" "singular -> w_R null, rcond shown"
! grep -qiE 'nan|inf' "$tmp/u.json" "$tmp/s.json" && ok || bad "JSON must not contain NaN/Infinity"

# map: CSV layout, NaN + status at singular/unreachable points, the index.
"$PRRU" map --q1 -0.5235987755982988:0.5235987755982988:31 --q2 -0.7853981633974483:1.2:25 --q3 0 \
  --rcond-min 4e-3 --out "$tmp/m.csv" >"$tmp/m.txt" 2>"$tmp/m.err" || bad "map failed: $(cat "$tmp/m.err")"
[ "$(head -1 "$tmp/m.csv")" = "$csv_comment" ] && ok || bad "map CSV: comment line"
r=$(python3 - "$tmp/m.csv" "$tmp/m.txt" <<'PY'
import csv, math, sys
rows = list(csv.reader(l for l in open(sys.argv[1]) if not l.startswith('#')))
errs = []
if rows[0] != ['q1', 'q2', 'q3', 'w_R', 'status']: errs.append('header %s' % rows[0])
rows = rows[1:]
if len(rows) != 31 * 25: errs.append('%d rows' % len(rows))
st = {}
for r in rows:
    w = float(r[3])
    st[r[4]] = st.get(r[4], 0) + 1
    if r[4] == 'ok' and not (math.isfinite(w) and w >= 1): errs.append('ok row %s' % r)
    if r[4] != 'ok' and (r[3] != 'NaN' or r[4] not in ('singular', 'unreachable', 'other_mode')): errs.append('bad row %s' % r)
if not st.get('ok'): errs.append('statuses %s' % st)
ok = [float(r[3]) - 1 for r in rows if r[4] == 'ok']
idx = sum(ok) / len(ok)
frac = 1 - len(ok) / len(rows)
out = dict(l.split(':', 1) for l in open(sys.argv[2]).read().splitlines() if ':' in l)
gi = float(out['global_index'].split()[0]); sf = float(out['singular_fraction'].split()[0])
if abs(gi - idx) > 1e-9 * idx: errs.append('global_index %r vs CSV %r' % (gi, idx))
if abs(sf - frac) > 1e-9: errs.append('singular_fraction %r vs CSV %r' % (sf, frac))
# The grid: q1 outer, 25 points per q1, symmetric about q1 = 0.
for i in range(31):
    for j in range(25):
        a, b = rows[i * 25 + j], rows[(30 - i) * 25 + j]
        if float(a[0]) != -float(b[0]) or a[1] != b[1]:
            errs.append('grid %s %s' % (a, b)); break
print('; '.join(errs[:3]) if errs else 'ok')
PY
)
[ "$r" = ok ] && ok || bad "map CSV: $r"
# Threads do not change the file.
"$PRRU" map --q1 -0.5235987755982988:0.5235987755982988:31 --q2 -0.7853981633974483:1.2:25 \
  --rcond-min 4e-3 --threads 1 --out "$tmp/m1.csv" >/dev/null 2>&1 || bad "map --threads 1 failed"
cmp -s "$tmp/m.csv" "$tmp/m1.csv" && ok || bad "map with 1 and 2 threads differ"
# The other assembly mode: a regular grid point is other_mode exactly when
# det J_d (from the J_d that prru ik prints there) has the opposite sign to
# its value at the home pose q1 = q2 = 0 (three actuators: J_d is square).
if [ "$nact" -eq 3 ]; then
  r=$(python3 - "$tmp/m.csv" "$PRRU" <<'PY'
import csv, json, subprocess, sys
def det(q):
    J = json.loads(subprocess.run([sys.argv[2], 'ik', '--q', ','.join(q)], capture_output=True, text=True, check=True).stdout)['Jd']
    return (J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0])
            + J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]))
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith('#'))][1:]
home = det(['0', '0', rows[0][2]]) > 0
errs, n = [], {'ok': 0, 'other_mode': 0}
# every other_mode point, and the ok points of every fourth row and column
for i, r in enumerate(rows):
    if r[4] == 'other_mode' or (r[4] == 'ok' and (i // 25) % 4 == 0 and (i % 25) % 4 == 0):
        n[r[4]] += 1
        if (det(r[:3]) > 0) != (home == (r[4] == 'ok')): errs.append('%s at %s' % (r[4], r[:2]))
print('; '.join(errs[:3]) if errs else 'ok' if min(n.values()) > 0 else 'counts %s' % n)
PY
)
  [ "$r" = ok ] && ok || bad "map: other_mode is not the opposite sign of det J_d: $r"
else
  echo "note: $nact actuators: J_d is not square (no det J_d sign, no other assembly mode): the other_mode check is skipped"
fi
# Progress: a bar only when stderr is a terminal (long grids, or any with
# --progress); in a log only with --progress, as plain lines (no carriage
# return), ending at 100 %.
"$PRRU" map --q1 -0.5:0.5:11 --q2 -0.5:0.5:11 --out "$tmp/p.csv" --progress >/dev/null 2>"$tmp/p.err" || bad "map --progress"
grep -q '^map: 100% (121/121 points)$' "$tmp/p.err" && ! grep -q $'\r' "$tmp/p.err" && ok \
  || bad "map --progress into a file: not plain lines ending at 100 %: $(cat -A "$tmp/p.err")"
"$PRRU" map --q1 -0.5:0.5:201 --q2 -0.5:0.5:101 --out "$tmp/p.csv" >/dev/null 2>"$tmp/p.err" || bad "map"
[ ! -s "$tmp/p.err" ] && ok || bad "large map, stderr not a terminal: no progress expected: $(head -c 200 "$tmp/p.err")"
if command -v script >/dev/null; then
  # script(1) gives the command a terminal.
  script -qec "$PRRU map --q1 -0.5:0.5:201 --q2 -0.5:0.5:101 --out $tmp/p.csv" /dev/null >"$tmp/tty.txt" 2>&1
  grep -q $'\rmap \[#' "$tmp/tty.txt" && grep -q '100% (20301/20301 points)' "$tmp/tty.txt" && ok \
    || bad "map on a terminal: no progress bar: $(head -c 300 "$tmp/tty.txt")"
  script -qec "$PRRU map --q1 -0.5:0.5:11 --q2 -0.5:0.5:11 --out $tmp/p.csv" /dev/null >"$tmp/tty.txt" 2>&1
  grep -q 'map \[' "$tmp/tty.txt" && bad "small map on a terminal drew a bar" || ok
  script -qec "$PRRU simulate --t-end 2 --out $tmp/s.csv" /dev/null >"$tmp/tty.txt" 2>&1
  grep -q $'\rsimulate \[#' "$tmp/tty.txt" && ok || bad "simulate of 2001 samples on a terminal: no bar: $(head -c 300 "$tmp/tty.txt")"
fi
"$PRRU" simulate --t-end 2 --out "$tmp/s.csv" 2>"$tmp/p.err" || bad "simulate"
[ ! -s "$tmp/p.err" ] && ok || bad "simulate, stderr not a terminal: no progress expected: $(head -c 200 "$tmp/p.err")"
"$PRRU" simulate --t-end 0.05 --progress --out "$tmp/s.csv" 2>"$tmp/p.err" || bad "simulate --progress"
[ "$(grep -c '^simulate: [0-9]*%$' "$tmp/p.err")" -eq 11 ] && ! grep -q $'\r' "$tmp/p.err" && ok \
  || bad "simulate --progress into a file: not 11 plain lines: $(cat -A "$tmp/p.err" | head -c 300)"
# pi in ranges: -pi/6:pi/6:5 is the grid of the decimal range.
"$PRRU" map --q1 -pi/6:pi/6:5 --q2 -pi/4:0.5pi:3 --out "$tmp/pi.csv" >/dev/null 2>&1 || bad "map with pi ranges failed"
"$PRRU" map --q1 -0.52359877559829882:0.52359877559829882:5 --q2 -0.78539816339744828:1.5707963267948966:3 \
  --out "$tmp/dec.csv" >/dev/null 2>&1 || bad "map failed"
cmp -s "$tmp/pi.csv" "$tmp/dec.csv" && ok || bad "map: -pi/6:pi/6 and the decimal range differ"
expect 2 "--q1 'pi/0:1:5': START 'pi/0' is not a finite number" -- map --q1 pi/0:1:5 --q2 0:1:3 --out "$tmp/x.csv"
# --out -: the CSV on stdout, the summary on stderr.
"$PRRU" map --q1 -0.5:0.5:11 --q2 -0.5:0.5:11 --out "$tmp/p.csv" >"$tmp/p.txt" 2>/dev/null || bad "map"
"$PRRU" map --q1 -0.5:0.5:11 --q2 -0.5:0.5:11 --out - >"$tmp/dash.csv" 2>"$tmp/dash.txt" || bad "map --out -"
cmp -s "$tmp/p.csv" "$tmp/dash.csv" && cmp -s "$tmp/p.txt" "$tmp/dash.txt" && ok \
  || bad "map --out -: stdout is not the CSV or stderr not the summary: $(head -c 200 "$tmp/dash.txt")"

# --precision float: every status the double map's (decided in double),
# w_R within the derived bound 64 FLT_EPSILON w_R / rcond(J_d) relative
# (test_map_batch.c), rcond >= the map's 4e-3 at every ok point: so
# |w_f - w| / w <= 64 * 1.19e-7 * w / 4e-3 = 1.9e-3 w. The grid reaches
# the singular band, the other mode and out of reach (with three
# actuators: a redundant robot's 4 x 3 J_d keeps its rank over this grid
# and has no assembly modes to leave, so there only ok and out of reach).
"$PRRU" map --q1 -1.2:1.2:41 --q2 -1.3:1.3:37 --out "$tmp/md.csv" >"$tmp/md.txt" 2>&1 || bad "map (double) failed"
"$PRRU" map --q1 -1.2:1.2:41 --q2 -1.3:1.3:37 --precision float --out "$tmp/mf.csv" >"$tmp/mf.txt" 2>&1 \
  || bad "map --precision float failed: $(cat "$tmp/mf.txt")"
r=$(python3 - "$tmp/md.csv" "$tmp/mf.csv" "$nact" <<'PY'
import sys
rows = [[l.strip().split(",") for l in open(p) if not l.startswith("#")][1:] for p in sys.argv[1:3]]
kinds = {r[4] for r in rows[0]}
need = {"ok", "unreachable"} | ({"singular", "other_mode"} if sys.argv[3] == "3" else set())
if not need <= kinds:
    print("the grid lacks a status: %s" % sorted(kinds)); sys.exit()
for a, b in zip(*rows):
    if a[:3] != b[:3] or a[4] != b[4]:
        print("status differs at %s: %s vs %s" % (a[:2], a[4], b[4])); sys.exit()
    if a[4] == "ok":
        w, wf = float(a[3]), float(b[3])
        if not abs(wf - w) / w <= 64 * 1.1920929e-07 * w / 4e-3:
            print("w_R at %s: %r vs %r" % (a[:2], w, wf)); sys.exit()
print("ok")
PY
)
[ "$r" = ok ] && ok || bad "map --precision float against double: $r"
grep -q '^precision: float (' "$tmp/mf.txt" && ok || bad "map --precision float: the summary does not say so: $(head -3 "$tmp/mf.txt")"
! grep -q '^precision:' "$tmp/md.txt" && ok || bad "map (double): a precision line"
"$PRRU" map --q1 -1.2:1.2:41 --q2 -1.3:1.3:37 --precision double --out "$tmp/mdd.csv" >/dev/null 2>&1 \
  && cmp -s "$tmp/md.csv" "$tmp/mdd.csv" && ok || bad "map --precision double is not the default"
# Shards in float: the settings line says so, and prru merge's summary too.
for k in 1 2; do
  "$PRRU" map --q1 -1.2:1.2:41 --q2 -1.3:1.3:37 --precision float --shard $k/2 --out "$tmp/fs$k.csv" \
    >/dev/null 2>&1 || bad "map --precision float --shard $k/2 failed"
done
grep -q '^# shard 1/2 map .* precision=float$' "$tmp/fs1.csv" && ok || bad "float shard: settings line $(sed -n 2p "$tmp/fs1.csv")"
"$PRRU" merge --in "$tmp/fs1.csv,$tmp/fs2.csv" --out "$tmp/fm.csv" >"$tmp/fm.txt" 2>&1 || bad "merge of float shards: $(cat "$tmp/fm.txt")"
cmp -s "$tmp/fm.csv" "$tmp/mf.csv" && grep -q '^precision: float (' "$tmp/fm.txt" && ok \
  || bad "merge of float shards: not the float map or no precision line: $(head -3 "$tmp/fm.txt")"
expect 2 "--precision 'half': must be double or float" -- map --q1 0:1:5 --q2 0:1:5 --precision half --out "$tmp/x.csv"
expect 2 "--precision '': must be double or float" -- map --q1 0:1:5 --q2 0:1:5 --precision "" --out "$tmp/x.csv"

# Bad grids and arguments: exit 2, message naming the argument.
q2ok="--q2 -0.5:0.5:11"
expect 2 "--q1 '0:1:1': COUNT" -- map --q1 0:1:1 $q2ok --out "$tmp/x.csv"
expect 2 "--q1 '1:0:10': START must be less than STOP" -- map --q1 1:0:10 $q2ok --out "$tmp/x.csv"
expect 2 "--q1 '0:0:10': START must be less than STOP" -- map --q1 0:0:10 $q2ok --out "$tmp/x.csv"
expect 2 "--q1 'a:1:10': START 'a' is not a finite number" -- map --q1 a:1:10 $q2ok --out "$tmp/x.csv"
expect 2 "STOP 'nan' is not a finite number" -- map --q1 0:nan:10 $q2ok --out "$tmp/x.csv"
expect 2 "--q1 '0:1:x': COUNT 'x'" -- map --q1 0:1:x $q2ok --out "$tmp/x.csv"
expect 2 "--q1 '0:1:2.5': COUNT" -- map --q1 0:1:2.5 $q2ok --out "$tmp/x.csv"
expect 2 "--q1 '0:1': expected START:STOP:COUNT" -- map --q1 0:1 $q2ok --out "$tmp/x.csv"
expect 2 "--q1 '0:1:5:6': expected START:STOP:COUNT" -- map --q1 0:1:5:6 $q2ok --out "$tmp/x.csv"
expect 2 "--q2 '-1:1:0': COUNT" -- map --q1 0:1:5 --q2 -1:1:0 --out "$tmp/x.csv"
expect 2 "--q3: 'z' is not a finite number" -- map --q1 0:1:5 $q2ok --q3 z --out "$tmp/x.csv"
expect 2 "--q2 is required" -- map --q1 0:1:5 --out "$tmp/x.csv"
expect 2 "--q1 is required" -- map $q2ok --out "$tmp/x.csv"
expect 2 "--out is required" -- map --q1 0:1:5 $q2ok
expect 2 "--threads '0'" -- map --q1 0:1:5 $q2ok --threads 0 --out "$tmp/x.csv"
expect 2 "--rcond-min '2'" -- map --q1 0:1:5 $q2ok --rcond-min 2 --out "$tmp/x.csv"
[ ! -e "$tmp/x.csv" ] && ok || bad "a rejected map must not write its output"
expect 1 "cannot open for writing" -- map --q1 0:1:5 $q2ok --out "$tmp/no/such/dir.csv"
expect 2 "--q: '0,0' is not 3" -- dme --q 0,0
expect 2 "--q is required" -- dme
expect 2 "unknown option" -- dme --q 0,0,0 --bogus 1

finish test_cli_dme
