#!/usr/bin/env bash
# prru traj, prru track and prru id from q(t), for any model: the quintic
# trajectory's rows against its defining properties and against prru ik;
# paths out of the workspace or across a singularity stopped at the first
# bad sample with the rows before it kept and no NaN; id from q(t) alone
# within the error bound it states, and its slider velocities, powers and
# reactions against prru ik and prru eval; track: exact model to 1e-9,
# mismatch error falling with the bandwidth, saturation reported and never
# exceeded, seeded noise reproducible, the CSV reference equal to the
# waypoints, and every kind of bad input refused with nothing written;
# track --controller lqr as accurate as computed torque on the exact model,
# its weights reported, its options' bad values refused (exit 2).
# traj --time-optimal: every row within the limits by prru id's exact
# inverse dynamics, faster than the scaled quintic, a limit active on >= 95 %
# of the grid, on the built model and (three actuators) the prototype's
# drives; infeasible limits named by grid point, bad options exit 2.
# Needs $PRRU, $PRRU_MODEL, $PRRU_SOURCE_DIR (cli_lib.sh).
. "$(dirname "$0")/cli_lib.sh"

WP='0,0,0;0.1,-0.08,0.02;0,0,0'
# A CSV's data (no '#' lines) as python rows: cols(FILE) -> header, rows.
PYCSV='
import csv, math, sys
def cols(p):
    r = list(csv.reader(l for l in open(p) if not l.startswith("#")))
    return r[0], [[float(x) for x in row] for row in r[1:]]
'

# ---- help ----
for c in traj track; do
  "$PRRU" $c --help >"$tmp/help_$c.txt" && ok || bad "$c --help failed"
done
{ grep -n -i -E "gsl|odeiv|kernel|descriptor|(^|[^a-z0-9])prru_[a-z]|runtime|generated" "$tmp"/help_*.txt
  grep -n -E "PRRU_|DBL_" "$tmp"/help_*.txt; } >"$tmp/jargon.txt"
[ -s "$tmp/jargon.txt" ] && bad "help with internal names: $(head -c 300 "$tmp/jargon.txt")" || ok
awk 'length > 80 { print FILENAME ": " $0; bad = 1 } END { exit bad }' "$tmp"/help_*.txt >"$tmp/long.txt" \
  && ok || bad "help lines over 80 columns: $(head -c 300 "$tmp/long.txt")"
grep -qF "$(act_names d),$(act_names dd)" "$tmp/help_traj.txt" && grep -qF "$(act_names sat)" "$tmp/help_track.txt" \
  && ok || bad "help texts do not list the model's $nact actuators"
"$PRRU" id --help >"$tmp/help_id.txt"
grep -qF "$(act_names pow)" "$tmp/help_id.txt" && grep -q -- "--window M" "$tmp/help_id.txt" && ok \
  || bad "id --help does not describe differentiation and powers"

# ---- prru traj ----
"$PRRU" traj --quintic --waypoints "$WP" --durations 1,1 --out "$tmp/t.csv" 2>"$tmp/err" \
  && ok || bad "traj failed: $(cat "$tmp/err")"
head -1 "$tmp/t.csv" | grep -qxF "$csv_comment" && ok || bad "traj: no model line"
python3 -c "$PYCSV
h, r = cols(sys.argv[1])
ix = {n: i for i, n in enumerate(h)}
assert h[:10] == 't q1 q2 q3 qd1 qd2 qd3 qdd1 qdd2 qdd3'.split(), h
assert len(r) == 2001 and r[-1][0] == 2.0, (len(r), r[-1][0])
wp = [[0, 0, 0], [0.1, -0.08, 0.02], [0, 0, 0]]
for k, row in ((0, r[0]), (1, r[1000]), (2, r[2000])):
    assert max(abs(row[1 + c] - wp[k][c]) for c in range(3)) < 1e-15, ('waypoint', k, row[:4])
    assert max(abs(v) for v in row[4:10]) < 1e-13, ('not at rest', k, row[4:10])
# Peak speed 1.875 dq / T at mid-segment (t = 0.5 is a sample).
mid = r[500]
for c in range(3):
    assert abs(mid[4 + c] - 1.875 * wp[1][c]) < 1e-14, ('peak speed', c, mid[4 + c])
    assert max(abs(row[4 + c]) for row in r) <= 1.875 * abs(wp[1][c]) + 1e-15
assert all(math.isfinite(v) for row in r for v in row)
" "$tmp/t.csv" && ok || bad "traj rows do not have the quintic's properties"
# d and dd = J_d qd against prru ik at a moving sample.
row=$(grep -v '^#' "$tmp/t.csv" | sed -n '301p')
q=$(echo "$row" | cut -d, -f2-4)
"$PRRU" ik --q "$q" >"$tmp/ik.json"
python3 -c "
import json, sys
ik = json.load(open(sys.argv[1])); row = [float(x) for x in sys.argv[2].split(',')]; n = int(sys.argv[3])
qd = row[4:7]; d = row[10:10 + n]; dd = row[10 + n:10 + 2 * n]
assert max(abs(a - b) for a, b in zip(d, ik['d'])) <= 1e-15 * max(1, max(map(abs, d))), (d, ik['d'])
jq = [sum(J[j] * qd[j] for j in range(3)) for J in ik['Jd']]
assert max(abs(a - b) for a, b in zip(dd, jq)) <= 1e-14 * max(1e-3, max(map(abs, jq))), (dd, jq)
" "$tmp/ik.json" "$row" "$nact" && ok || bad "traj d, dd disagree with prru ik's d and J_d qd"

# Towards a tilt no model reaches: the path leaves the workspace (or, on
# some models, first crosses a singularity); the rows before it kept.
"$PRRU" traj --waypoints '0,0,0;1.5,0,0' --durations 1 --out "$tmp/u.csv" 2>"$tmp/err"
st=$?
[ $st -eq 1 ] && grep -q -E "sample [0-9]+ \(t = .*(outside the workspace|crosses a singularity)" "$tmp/err" && ok \
  || bad "traj out of the workspace: exit $st, $(cat "$tmp/err")"
python3 -c "$PYCSV
import re
h, r = cols(sys.argv[1])
k = int(re.search(r'sample (\d+)', open(sys.argv[2]).read()).group(1))
assert len(r) == k - 1 and len(r) > 100, (len(r), k)
assert all(math.isfinite(v) for row in r for v in row)
" "$tmp/u.csv" "$tmp/err" && ok || bad "traj: rows before the bad sample not kept as they were, or NaN written"
grep -qi nan "$tmp/u.csv" && bad "NaN in the kept rows" || ok
# Sampled coarsely, the unreachable pose itself is the first bad sample.
"$PRRU" traj --waypoints '0,0,0;0.02,0,0;1.5,0,0' --durations 1,1 --dt 1 --out "$tmp/u1.csv" 2>"$tmp/err"
st=$?
[ $st -eq 1 ] && grep -qF "sample 3 (t = 2 s, segment 2: waypoint 2 to 3): q = (1.5, 0, 0) is outside the workspace" "$tmp/err" \
  && [ "$(grep -vc '^#' "$tmp/u1.csv")" -eq 3 ] && ok || bad "traj to an unreachable waypoint: exit $st, $(cat "$tmp/err")"

# Across a singularity: find a regular pose with the other sign of det J_d
# (3 actuators) on a line from home, if the model has one there.
if [ "$nact" -eq 3 ]; then
  detpy='
import json, sys
d = json.load(sys.stdin); J = d["Jd"]
det = J[0][0]*(J[1][1]*J[2][2]-J[1][2]*J[2][1]) - J[0][1]*(J[1][0]*J[2][2]-J[1][2]*J[2][0]) + J[0][2]*(J[1][0]*J[2][1]-J[1][1]*J[2][0])
print(("+" if det > 0 else "-") if not d["singular"] else "0")'
  home=$("$PRRU" ik --q 0,0,0 | python3 -c "$detpy")
  far=$(for q1 in 0.3 0.4 0.5 0.6; do
    s=$("$PRRU" ik --q "$q1,-pi/4,0" 2>/dev/null | python3 -c "$detpy" 2>/dev/null)
    if [ -n "$s" ] && [ "$s" != 0 ] && [ "$s" != "$home" ]; then echo "$q1"; fi
  done | head -1)
  if [ -n "$far" ]; then
    "$PRRU" traj --waypoints "0,0,0;$far,-pi/4,0" --durations 1 --out "$tmp/s.csv" 2>"$tmp/err"
    st=$?
    [ $st -eq 1 ] && grep -q "crosses a singularity" "$tmp/err" && ! grep -qi nan "$tmp/s.csv" && ok \
      || bad "traj across the singularity to q1 = $far: exit $st, $(cat "$tmp/err")"
    expect 2 "crosses a singularity" -- track --waypoints "0,0,0;$far,-pi/4,0" --durations 1 --out "$tmp/s2.csv"
    [ -e "$tmp/s2.csv" ] && bad "track wrote a file for a singular reference" || ok
    # prru id on rows that are each regular but of opposite det J_d signs:
    # stops at the second row, the first kept.
    printf 't,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,0,0,0,0,0,0,0,0,0\n1,%s,%s,0,0,0,0,0,0,0\n' \
      "$far" "$(python3 -c 'import math; print(repr(-math.pi/4))')" >"$tmp/jump.csv"
    "$PRRU" id --traj "$tmp/jump.csv" --out "$tmp/jump_fd.csv" 2>"$tmp/err"
    st=$?
    [ $st -eq 1 ] && grep -q "data row 2 (t = 1): the motion crosses a singularity" "$tmp/err" \
      && [ "$(grep -vc '^#' "$tmp/jump_fd.csv")" -eq 2 ] && ok \
      || bad "id across the singularity: exit $st, $(cat "$tmp/err")"
  else
    echo "note: no pose of opposite det J_d sign found near q2 = -pi/4; crossing check skipped"
  fi
fi

# Bad options: exit 2, nothing written.
expect 2 "need 2 (one per segment)" -- traj --waypoints "$WP" --durations 1 --out "$tmp/b.csv"
expect 2 "duration 2" -- traj --waypoints "$WP" --durations 1,-1 --out "$tmp/b.csv"
expect 2 "waypoint 2" -- traj --waypoints '0,0,0;0.1,x,0' --durations 1 --out "$tmp/b.csv"
expect 2 "at least 2" -- traj --waypoints '0,0,0' --durations 1 --out "$tmp/b.csv"
expect 2 "--dt" -- traj --waypoints "$WP" --durations 1,1 --dt 0 --out "$tmp/b.csv"
expect 2 "--waypoints is required" -- traj --durations 1
# Issue 30 item 1: a first duration of 1e-300 s wrote inf and NaN with exit
# 0; 1e-12 s lost the t = 0 row and ended moving. Rounding-lost durations
# are refused (the rule in runtime/src/traj.c), nothing written; a short
# one that is kept gives the t = 0 row and ends exactly at rest.
expect 2 "duration 1 (waypoint 1 to 2, 1e-300 s) is lost to rounding" -- \
  traj --waypoints '0,0,0;0.1,0,0' --durations 1e-300 --out "$tmp/lost.csv"
[ -e "$tmp/lost.csv" ] && bad "traj wrote a file for a lost duration" || ok
expect 2 "duration 1 (waypoint 1 to 2, 1e-300 s) is lost to rounding" -- \
  track --waypoints '0,0,0;0.1,0,0' --durations 1e-300 --out "$tmp/lost.csv"
"$PRRU" traj --waypoints '0,0,0;0.1,0,0' --durations 1e-12 --out "$tmp/short.csv" 2>"$tmp/err" \
  || bad "traj with a 1e-12 s segment: $(cat "$tmp/err")"
python3 -c "$PYCSV
h, r = cols(sys.argv[1])
assert len(r) == 2 and r[0][0] == 0 and r[1][0] == 1e-12, [x[0] for x in r]
assert all(math.isfinite(v) for row in r for v in row)
assert r[0][1:4] == [0, 0, 0] and r[1][1:4] == [0.1, 0, 0], r
assert all(v == 0 for row in r for v in row[4:10]), 'qd, qdd not 0 at the ends'
" "$tmp/short.csv" && ok || bad "traj with a 1e-12 s segment: rows $(cat "$tmp/short.csv")"
[ -e "$tmp/b.csv" ] && bad "a refused traj wrote its file" || ok

# ---- prru id from q(t) alone ----
# q = A sin(w t + p) per coordinate, 1 ms rows over 2 s, exact qd, qdd.
python3 -c "
import math, sys
A = (0.06, 0.05, 0.012); W = (4.0, 3.1, 5.3); P = (0.2, 1.0, -0.4)
with open(sys.argv[1], 'w') as f, open(sys.argv[2], 'w') as g:
    f.write('t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n'); g.write('t,q1,q2,q3\n')
    for i in range(2001):
        t = i * 1e-3
        q = [A[c] * math.sin(W[c] * t + P[c]) for c in range(3)]
        qd = [A[c] * W[c] * math.cos(W[c] * t + P[c]) for c in range(3)]
        qdd = [-W[c] ** 2 * q[c] for c in range(3)]
        f.write(','.join('%.17g' % v for v in [t] + q + qd + qdd) + '\n')
        g.write(','.join('%.17g' % v for v in [t] + q) + '\n')
print(max(A[c] * W[c] ** 5 for c in range(3)))
" "$tmp/exact.csv" "$tmp/qonly.csv" >"$tmp/d5max"
"$PRRU" id --traj "$tmp/exact.csv" --derivatives --rates --out "$tmp/id_exact.csv" 2>"$tmp/err" && ok || bad "id exact: $(cat "$tmp/err")"
"$PRRU" id --traj "$tmp/qonly.csv" --derivatives --rates --out "$tmp/id_q.csv" 2>"$tmp/err" && ok || bad "id q(t): $(cat "$tmp/err")"
grep -q "^# qd, qdd from q(t): least-squares polynomials of degree 4 over 9 rows" "$tmp/id_q.csv" && ok \
  || bad "id q(t): no comment line on the differentiation"
python3 -c "$PYCSV
import re
he, e = cols(sys.argv[1]); hq, q = cols(sys.argv[2])
note = [l for l in open(sys.argv[2]) if l.startswith('# qd, qdd')][0]
tq, tqdd = [float(x) for x in re.search(r'TRUNC qd (\S+) s\^\d+, qdd (\S+) s\^', note).groups()]
gq, gqdd = [float(x) for x in re.search(r'GAIN qd (\S+) s\^-1, qdd (\S+) s\^-2', note).groups()]
d5 = float(open(sys.argv[3]).read())
assert he == hq and len(e) == len(q) == 2001
ix = {n: i for i, n in enumerate(he)}
# The stated bound, plus the rounding of q's 17 digits through the noise gain.
bq, bqdd = tq * d5 + gq * 1e-16, tqdd * d5 + gqdd * 1e-16
wq = max(abs(a[ix['qd%d' % c]] - b[ix['qd%d' % c]]) for a, b in zip(e, q) for c in (1, 2, 3))
wqdd = max(abs(a[ix['qdd%d' % c]] - b[ix['qdd%d' % c]]) for a, b in zip(e, q) for c in (1, 2, 3))
assert wq <= bq and wqdd <= bqdd, ('beyond the stated bound', wq, bq, wqdd, bqdd)
assert wqdd >= 0.01 * bqdd, ('stated bound loose by 100x', wqdd, bqdd)
fd = ['fd%d' % i for i in range(1, 20) if 'fd%d' % i in ix]
sc = max(abs(a[ix[n]]) for a in e for n in fd)
wf = max(abs(a[ix[n]] - b[ix[n]]) for a, b in zip(e, q) for n in fd)
print('id from q(t): qd %.3g (bound %.3g), qdd %.3g (bound %.3g), fd %.3g N of %.3g N' % (wq, bq, wqdd, bqdd, wf, sc))
assert wf <= 1e-4 * sc, ('forces', wf, sc)
assert all(math.isfinite(v) for row in q for v in row)
" "$tmp/id_exact.csv" "$tmp/id_q.csv" "$tmp/d5max" && ok || bad "id from q(t) outside its stated bound"
# Powers are fd dd; dd = J_d qd against prru ik at one row.
python3 -c "$PYCSV
h, r = cols(sys.argv[1]); n = int(sys.argv[2]); ix = {c: i for i, c in enumerate(h)}
for row in r:
    for i in range(1, n + 1):
        assert row[ix['pow%d' % i]] == row[ix['fd%d' % i]] * row[ix['dd%d' % i]]
" "$tmp/id_exact.csv" "$nact" && ok || bad "id: power is not fd dd"
# Reactions at one row against prru eval with the same q, qd and forces.
"$PRRU" id --traj "$tmp/exact.csv" --reactions --out "$tmp/id_r.csv" 2>"$tmp/err" && ok || bad "id --reactions: $(cat "$tmp/err")"
row=$(grep -v '^#' "$tmp/exact.csv" | sed -n '778p')
fdrow=$(grep -v '^#' "$tmp/id_r.csv" | sed -n '778p' | cut -d, -f2-$((nact + 1)))
"$PRRU" eval --q "$(echo "$row" | cut -d, -f2-4)" --qd "$(echo "$row" | cut -d, -f5-7)" --fd "$fdrow" >"$tmp/ev.json"
python3 -c "$PYCSV
import json
h, r = cols(sys.argv[1]); ev = json.load(open(sys.argv[2])); row = r[776]
lam = row[1 + int(sys.argv[3]):]
assert len(lam) == len(ev['lambda'])
sc = max(abs(x) for x in ev['lambda'])
assert max(abs(a - b) for a, b in zip(lam, ev['lambda'])) <= 1e-12 * sc
" "$tmp/id_r.csv" "$tmp/ev.json" "$nact" && ok || bad "id --reactions disagree with prru eval"
# Refusals.
cut -d, -f1-5 "$tmp/exact.csv" >"$tmp/partial.csv"
expect 2 "has 1 of the 6 columns" -- id --traj "$tmp/partial.csv"
expect 2 "--window applies when" -- id --traj "$tmp/exact.csv" --window 3
expect 2 "--degree '9'" -- id --traj "$tmp/qonly.csv" --degree 9
expect 2 "--degree 6 needs --window 3" -- id --traj "$tmp/qonly.csv" --degree 6 --window 2
head -6 "$tmp/qonly.csv" >"$tmp/short.csv"
expect 2 "needs at least 9" -- id --traj "$tmp/short.csv"
{ head -3 "$tmp/qonly.csv"; sed -n 3p "$tmp/qonly.csv"; sed -n '4,40p' "$tmp/qonly.csv"; } >"$tmp/rep.csv"
expect 2 "row 3: time" -- id --traj "$tmp/rep.csv"
"$PRRU" id --traj "$tmp/exact.csv" --differentiate --out "$tmp/id_d.csv" 2>/dev/null \
  && grep -q "^# qd, qdd from q(t)" "$tmp/id_d.csv" && ok || bad "id --differentiate ignored"

# ---- prru track ----
trk() { "$PRRU" track "$@" --out "$tmp/tr.csv" --summary "$tmp/sum.json" 2>"$tmp/err"; }
trk --waypoints "$WP" --durations 1,1 && ok || bad "track: $(cat "$tmp/err")"
jcheck "$tmp/sum.json" "d['model'] == model and d['samples'] == 2001 and max(d['max_error']) <= 1e-9 and d['status'] == 'complete' and d['any_saturated_fraction'] == 0" \
  "track, exact model: not on the reference to 1e-9"
head -1 "$tmp/tr.csv" | grep -qxF "$csv_comment" && ok || bad "track: no model line"
# The CSV reference (prru traj's rows, quintic interpolation) is the same reference.
"$PRRU" track --ref "$tmp/t.csv" --mismatch mass=1.1 --out "$tmp/tr_ref.csv" --summary "$tmp/s_ref.json" 2>"$tmp/err" || bad "track --ref: $(cat "$tmp/err")"
"$PRRU" track --waypoints "$WP" --durations 1,1 --mismatch mass=1.1 --out "$tmp/tr_wp.csv" --summary "$tmp/s_wp.json" 2>"$tmp/err" || bad "track mismatch: $(cat "$tmp/err")"
python3 -c "
import json, sys
a = json.load(open(sys.argv[1])); b = json.load(open(sys.argv[2]))
assert max(abs(x - y) for x, y in zip(a['max_error'], b['max_error'])) <= 1e-12, (a['max_error'], b['max_error'])
" "$tmp/s_ref.json" "$tmp/s_wp.json" && ok || bad "track --ref of traj's CSV differs from --waypoints"
# Mismatch: the error falls with the bandwidth (about as 1/W^2).
for w in 10 40; do
  "$PRRU" track --waypoints "$WP" --durations 1,1 --mismatch mass=1.1 --bandwidth $w --out "$tmp/m$w.csv" \
    --summary "$tmp/m$w.json" 2>"$tmp/err" || bad "track --bandwidth $w: $(cat "$tmp/err")"
done
python3 -c "
import json, sys
a = max(json.load(open(sys.argv[1]))['max_error']); b = max(json.load(open(sys.argv[2]))['max_error'])
print('track mass x 1.1: max error %.3g (W = 10), %.3g (W = 40)' % (a, b))
assert 1e-6 < a < 0.05 and a / b > 9, (a, b)
" "$tmp/m10.json" "$tmp/m40.json" && ok || bad "track: mismatch error does not fall with the gains"
# Saturation: a limit below the feed-forward peak.
# (At 0.9 of it the platform sinks under gravity until the controller
# meets a singularity: a run that stops, rows kept.)
lim=$(json "$tmp/s_wp.json" "0.97 * d['feedforward_peak']")
trk --waypoints "$WP" --durations 1,1 --fmax "$lim" || bad "track --fmax: $(cat "$tmp/err")"
jcheck "$tmp/sum.json" "d['any_saturated_fraction'] > 0 and max(d['max_fd']) <= $lim" "track: saturation not reported"
python3 -c "$PYCSV
h, r = cols(sys.argv[1]); n = int(sys.argv[2]); lim = float(sys.argv[3]); ix = {c: i for i, c in enumerate(h)}
for row in r:
    for i in range(1, n + 1):
        sat = abs(row[ix['fdc%d' % i]]) > lim
        assert row[ix['sat%d' % i]] == sat and abs(row[ix['fd%d' % i]]) <= lim
        assert row[ix['fd%d' % i]] == (row[ix['fdc%d' % i]] if not sat else (lim if row[ix['fdc%d' % i]] > 0 else -lim))
" "$tmp/tr.csv" "$nact" "$lim" && ok || bad "track: saturation flags or clipping wrong in the CSV"
# Seeded noise with a sampled controller: same seed, same bytes.
for s in 1 1b 2; do
  "$PRRU" track --waypoints "$WP" --durations 1,1 --period 0.002 --noise 1e-5,1e-3 --seed "${s%b}" \
    --out "$tmp/n$s.csv" --summary "$tmp/n$s.json" 2>"$tmp/err" || bad "track --noise: $(cat "$tmp/err")"
done
cmp -s "$tmp/n1.csv" "$tmp/n1b.csv" && ! cmp -s "$tmp/n1.csv" "$tmp/n2.csv" && ok || bad "track noise not reproducible per seed"
jcheck "$tmp/n1.json" "d['control'] == 'zero-order hold' and d['samples'] == 1001 and 1e-7 < max(d['max_error']) < 1e-3" \
  "track --period: wrong sampling or error"
# --controller lqr: the time-varying LQR at the same period as computed
# torque. Exact plant: both errors are the zero-order hold's, at most
# a / W^2 with a the acceleration a held force lacks over a tick
# (test_control.c derives and checks it for the build's model): without
# drives a = jerk Tc, so 6 rad/s^3 * 2 ms / (20 rad/s)^2 = 3e-5 (the
# quintic's peak jerk 60 |dq| / T^3 = 6 on this move). Damping and
# Coulomb friction add their rate to a (steep for a small smoothing
# velocity), which only the library's test computes: with drives the LQR
# is held to 4x computed torque's error here instead (the two share the
# bound; on the prototype LQR's is the smaller). The same feed-forward
# peak forces (0.1 %); the weights used in the summary, the given ones as
# given.
"$PRRU" track --waypoints "$WP" --durations 1,1 --period 0.002 --out "$tmp/ct2.csv" --summary "$tmp/ct2.json" \
  2>"$tmp/err" || bad "track --period 0.002: $(cat "$tmp/err")"
"$PRRU" track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --out "$tmp/lqr.csv" \
  --summary "$tmp/lqr.json" 2>"$tmp/err" && ok || bad "track --controller lqr: $(cat "$tmp/err")"
python3 -c "
import json, sys
c, l = (json.load(open(p)) for p in sys.argv[1:3])
n = int(sys.argv[3])
m = json.load(open(sys.argv[4]))
def drives(k):  # format 2 under actuators, format 1 at the top
    a = m.get('actuators', {}).get(k, m.get(k, 0))
    return any(x != 0 for x in (a if isinstance(a, list) else [a]))
friction = drives('damping') or drives('coulomb')
assert l['controller'] == 'lqr' and c['controller'] == 'computed_torque', (l.get('controller'), c.get('controller'))
# Each summary names only its controller's gains (the LQR uses no kp, kd).
assert len(c['kp']) == len(c['kd']) == 3 and 'kp' not in l and 'kd' not in l and 'lqr_q' not in c, (c, l)
assert len(l['lqr_q']) == 6 and len(l['lqr_r']) == n and min(l['lqr_q']) > 0 and min(l['lqr_r']) > 0, l
assert l['samples'] == c['samples'] == 1001 and l['status'] == 'complete', l
if friction:
    assert max(l['max_error']) <= 4 * max(c['max_error']) and max(c['max_error']) < 1e-3, (c['max_error'], l['max_error'])
else:
    assert max(c['max_error']) <= 3e-5 and max(l['max_error']) <= 3e-5, (c['max_error'], l['max_error'])
assert abs(max(l['max_fd']) - max(c['max_fd'])) <= 1e-3 * max(c['max_fd']), (l['max_fd'], c['max_fd'])
print('track 2 ms: max error CT %.3g, LQR %.3g' % (max(c['max_error']), max(l['max_error'])))
" "$tmp/ct2.json" "$tmp/lqr.json" "$nact" "$PRRU_MODEL" && ok || bad "track --controller lqr: not tracking like computed torque"
sed -n 2p "$tmp/lqr.csv" | grep -q "^# LQR (time-varying" && ok || bad "track lqr: no controller line"
[ "$(grep -v '^#' "$tmp/lqr.csv" | head -1)" = "$(grep -v '^#' "$tmp/ct2.csv" | head -1)" ] && ok \
  || bad "track lqr: columns differ from computed torque's"
"$PRRU" track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-q 1e4,1e4,1e4,10,10,10 \
  --lqr-r "$(nlist 0.001)" --mismatch mass=1.2 --out "$tmp/lqrw.csv" --summary "$tmp/lqrw.json" 2>"$tmp/err" \
  || bad "track lqr with weights: $(cat "$tmp/err")"
jcheck "$tmp/lqrw.json" "d['lqr_q'] == [1e4, 1e4, 1e4, 10, 10, 10] and d['lqr_r'] == [0.001] * $nact and d['status'] == 'complete' and max(d['max_error']) > 1e-5" \
  "track lqr: given weights not used or mismatch not seen"
rzero=$(nlist 1 | sed 's/[^,]*$/0/')
expect 2 "--controller lqr needs --period" -- track --waypoints "$WP" --durations 1,1 --controller lqr --out "$tmp/x.csv"
expect 2 "--controller lqr needs --period" -- track --waypoints "$WP" --durations 1,1 --controller lqr --period 0 --out "$tmp/x.csv"
expect 2 "--controller: 'pid'" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller pid --out "$tmp/x.csv"
expect 2 "--lqr-q: '1,1,1,1,1' is not 6" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-q 1,1,1,1,1 --out "$tmp/x.csv"
expect 2 "--lqr-q: weight 4 is -1" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-q 1,1,1,-1,1,1 --out "$tmp/x.csv"
# All weights 0 is the library's rule for "the default" (prru_control.h):
# the same run, to the byte, as leaving --lqr-q and --lqr-r out.
"$PRRU" track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-q 0,0,0,0,0,0 \
  --lqr-r "$(nlist 0)" --out "$tmp/lqr0.csv" --summary "$tmp/lqr0.json" 2>"$tmp/err" \
  || bad "track lqr with all weights 0: $(cat "$tmp/err")"
cmp -s "$tmp/lqr.csv" "$tmp/lqr0.csv" && cmp -s "$tmp/lqr.json" "$tmp/lqr0.json" && ok \
  || bad "track lqr: all weights 0 is not the default run"
expect 2 "--lqr-q: 'inf,1,1,1,1,1' is not 6" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-q inf,1,1,1,1,1 --out "$tmp/x.csv"
expect 2 "--lqr-r: weight $nact is 0, not > 0" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-r "$rzero" --out "$tmp/x.csv"
expect 2 "--lqr-r: '$(nlist 1),1' is not $nact" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-r "$(nlist 1),1" --out "$tmp/x.csv"
expect 2 "--lqr-r: 'nan" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller lqr --lqr-r "nan${rzero#1}" --out "$tmp/x.csv"
expect 2 "--lqr-q belongs to --controller lqr" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --lqr-q 1,1,1,1,1,1 --out "$tmp/x.csv"
expect 2 "--lqr-r belongs to --controller lqr" -- track --waypoints "$WP" --durations 1,1 --period 0.002 --controller ct --lqr-r "$(nlist 1)" --out "$tmp/x.csv"
[ -e "$tmp/x.csv" ] && bad "a refused track --controller lqr wrote its CSV" || ok
# Bad input: exit 2, nothing written.
rm -f "$tmp/x.csv"
"$PRRU" track --waypoints '0,0,0;0.02,0,0;1.5,0,0' --durations 1,1 --dt 1 --out "$tmp/x.csv" 2>"$tmp/err"
st=$?
[ $st -eq 2 ] && grep -q -E "reference at sample [0-9]+ \(t = .*(outside the workspace|crosses a singularity).*nothing written" "$tmp/err" \
  && ok || bad "track with an unreachable reference: exit $st, $(cat "$tmp/err")"
dmax=$(grep -v '^#' "$tmp/t.csv" | sed -n 2p | cut -d, -f11)
expect 2 "outside its stroke" -- track --waypoints "$WP" --durations 1,1 --stroke -10,"$dmax" --out "$tmp/x.csv"
expect 2 "needs --period > 0" -- track --waypoints "$WP" --durations 1,1 --noise 1e-5,0 --out "$tmp/x.csv"
expect 2 "unknown key 'masses'" -- track --waypoints "$WP" --durations 1,1 --mismatch masses=2 --out "$tmp/x.csv"
expect 2 "is not a number > 0" -- track --waypoints "$WP" --durations 1,1 --mismatch mass=0 --out "$tmp/x.csv"
expect 2 "--fmax: '0' is not a positive number" -- track --waypoints "$WP" --durations 1,1 --fmax 0 --out "$tmp/x.csv"
expect 2 "is empty" -- track --waypoints "$WP" --durations 1,1 --stroke 1,0 --out "$tmp/x.csv"
expect 2 "--plot needs --out" -- track --waypoints "$WP" --durations 1,1 --plot "$tmp/x.png"
expect 2 "one of them" -- track --ref "$tmp/t.csv" --waypoints "$WP" --durations 1,1
expect 2 "missing column 'qd1'" -- track --ref "$tmp/qonly.csv" --out "$tmp/x.csv"
expect 2 "--bandwidth excludes" -- track --waypoints "$WP" --durations 1,1 --bandwidth 5 --kp 1,1,1
[ -e "$tmp/x.csv" ] && bad "a refused track wrote its CSV" || ok
# Issue 30 item 4: id and track wrote their output over their input when
# the two options named one file. Refused (exit 2, both options named),
# the file as it was, whatever the spelling: ./f, a symbolic link.
cp "$tmp/t.csv" "$tmp/same.csv"
ln -s same.csv "$tmp/same_link.csv"
for o in "$tmp/same.csv" "$tmp/./same.csv" "$tmp/same_link.csv"; do
  expect 2 "--traj $tmp/same.csv and --out $o are the same file" -- id --traj "$tmp/same.csv" --out "$o"
  expect 2 "--ref $tmp/same.csv and --out $o are the same file" -- track --ref "$tmp/same.csv" --out "$o"
done
expect 2 "--ref $tmp/same.csv and --summary $tmp/./same.csv are the same file" -- \
  track --ref "$tmp/same.csv" --out "$tmp/x.csv" --summary "$tmp/./same.csv"
cmp -s "$tmp/t.csv" "$tmp/same.csv" && ok || bad "id/track changed their input file"
[ -e "$tmp/x.csv" ] && bad "a refused track wrote its CSV" || ok
# Issue 30 item 2: a failure in an integrator's trial state (gains far too
# stiff for the step) or in a noisy measurement was blamed on the run's
# regular state, "not reachable ... at q = (0, 0, 0)". The message names
# what failed: the trial state and its time, or the measurement and the
# noise; exit 1 either way.
for args in "--bandwidth 1e6" "--noise 1e300,0 --period 0.001" "--noise 0,1e300 --period 0.001"; do
  # shellcheck disable=SC2086
  expect 1 "" -- track --waypoints '0,0,0;0.1,-0.08,0.02' --durations 0.5 $args --out "$tmp/stiff.csv" \
    --summary "$tmp/stiff.json"
  grep -q "at q = (0, 0, 0)" "$tmp/err" && bad "track $args blamed the regular q = 0: $(cat "$tmp/err")" || ok
  case $args in
    --bandwidth*) want="trial state at t = " ;;
    *) want="the sensor noise (q " ;;
  esac
  grep -qF "$want" "$tmp/err" && ok || bad "track $args: no '$want': $(cat "$tmp/err")"
done
# SIGTERM during a long run (a background job ignores SIGINT): exit 143,
# whole rows kept, the summary says why.
"$PRRU" track --waypoints "$WP" --durations 200,200 --out "$tmp/sig.csv" --summary "$tmp/sig.json" 2>"$tmp/sig.err" &
pid=$!
for _ in $(seq 200); do
  [ -n "$(find "$tmp" -name '*sig.csv.partial-*' -size +100k)" ] && break
  sleep 0.05
done
kill -TERM $pid
wait $pid
st=$?
[ $st -eq 143 ] && grep -q "interrupted.*SIGTERM" "$tmp/sig.err" && ok || bad "track SIGTERM: exit $st, $(cat "$tmp/sig.err")"
python3 -c "$PYCSV
h, r = cols(sys.argv[1])
assert 100 < len(r) < 400001 and all(len(x) == len(h) for x in r), len(r)
assert all(math.isfinite(v) for row in r for v in row)
" "$tmp/sig.csv" && jcheck "$tmp/sig.json" "'interrupted' in d['status'] and d['samples'] > 100" "track SIGTERM: rows or summary"

# ---- prru traj --time-optimal ----
# The static load at the start, from the refusal of a force limit far below
# it (which names it); limits a few times that are reached at accelerations
# of a few g on every model.
"$PRRU" traj --time-optimal --waypoints "$WP" --force-max 1e-3 --out "$tmp/to.csv" 2>"$tmp/err"
st=$?
[ $st -eq 1 ] && grep -qF "infeasible at segment 1 (waypoint 1 to 2), s = 0 (grid point 0 of 400): no acceleration holds the forces within force_max at rest; force_max of actuator" "$tmp/err" \
  && grep -qF "nothing written" "$tmp/err" && [ ! -e "$tmp/to.csv" ] && ok \
  || bad "time-optimal below the static load: exit $st, $(cat "$tmp/err")"
load=$(sed -n 's/.*its static load there is \(-\?[0-9.e+-]*\) N.*/\1/p' "$tmp/err" | tr -d -)
FLIM=$(python3 -c "print(2.5 * $load)")
# PYTOPP: checks a time-optimal CSV (argv 1) against prru id's exact
# inverse dynamics of its rows (argv 2), the limits F, V (argv 3, 4; 'inf'
# for none) and the waypoints: every row within 1e-6 of the limits (the
# library checks 9 points per grid interval to 1e-9, and the forces vary
# smoothly in between: test_topp.c); its forces are id's (the same
# computation, to 1e-9 of the limit); the duration is below the scaled
# quintic's and the active share >= 95 %; at rest at both ends.
PYTOPP="$PYCSV
F, V = float(sys.argv[3]), float(sys.argv[4])
h, r = cols(sys.argv[1])
hi, ri = cols(sys.argv[2])
n = $nact
ix = {c: i for i, c in enumerate(h)}
jx = {c: i for i, c in enumerate(hi)}
assert len(r) == len(ri) > 10, (len(r), len(ri))
worst = 0
for a, b in zip(r, ri):
    assert a[0] == b[0]
    for i in range(1, n + 1):
        f, v = b[jx['fd%d' % i]], b[jx['dd%d' % i]]
        worst = max(worst, abs(f) / F, abs(v) / V)
        assert abs(a[ix['fd%d' % i]] - f) <= 1e-9 * F, ('fd differs from id', a[0], i)
assert worst <= 1 + 1e-6, ('a limit exceeded', worst)
com = [l for l in open(sys.argv[1]) if l.startswith('#')]
dur = float([l for l in com if 'time-optimal (reachability' in l][0].split(' waypoints, ')[1].split(' s;')[0])
act = float([l for l in com if 'a limit active on' in l][0].split('active on ')[1].split('%')[0])
qt = float([l for l in com if 'scaled quintic' in l][0].split('limits: ')[1].split(' s ')[0])
# The summary's 9 significant digits: 5e-9 relative.
assert abs(r[-1][0] - dur) <= 5e-9 * dur and r[-1][0] < qt, (r[-1][0], dur, qt)
assert act >= 95, act
wp = [float(x) for x in sys.argv[5].replace(';', ',').split(',')]
for row, k in ((r[0], 0), (r[-1], len(wp) // 3 - 1)):
    assert max(abs(row[1 + c] - wp[3 * k + c]) for c in range(3)) < 1e-14, ('waypoint', k, row[:4])
    assert max(abs(v) for v in row[4:7]) < 1e-12, ('not at rest', k, row[4:7])
assert all(math.isfinite(v) for row in r for v in row)
print('%.6g %.6g %.2f' % (dur, qt, act))
"
topp_case() { # NAME MODEL-ARGS... -- TRAJ-ARGS... (F and V as FLIM and VLIM)
  local name=$1 margs=() targs=()
  shift
  while [ "$1" != -- ]; do margs+=("$1"); shift; done
  shift
  "$PRRU" "${margs[@]}" traj --time-optimal --waypoints "$WP" "$@" --out "$tmp/to.csv" 2>"$tmp/err" \
    || { bad "time-optimal $name: $(cat "$tmp/err")"; return; }
  "$PRRU" "${margs[@]}" id --traj "$tmp/to.csv" --rates --out "$tmp/toid.csv" 2>"$tmp/err" \
    || { bad "time-optimal $name: id: $(cat "$tmp/err")"; return; }
  python3 -c "$PYTOPP" "$tmp/to.csv" "$tmp/toid.csv" "$FLIM" "$VLIM" "$WP" >"$tmp/to.out" 2>&1 \
    && ok || bad "time-optimal $name: $(tail -3 "$tmp/to.out")"
}
VLIM=inf
topp_case "force limit" -- --force-max "$FLIM"
topp_case "force limit, rows at the grid" -- --fmax "$(nlist "$FLIM")" --dt grid
VLIM=0.05
topp_case "force and speed limits" -- --fd-max "$FLIM" --speed-max "$VLIM" --dt 2e-3
if [ "$nact" -eq 3 ]; then
  # The prototype: drives with damping and (smoothed) Coulomb friction.
  proto="$PRRU_SOURCE_DIR/models/prototype_example.json"
  VLIM=inf
  topp_case "prototype, force limit" --model "$proto" -- --force-max "$FLIM"
  VLIM=0.1
  topp_case "prototype, force and speed limits" --model "$proto" -- --force-max "$FLIM" --speed-max "$VLIM"
fi
# The summary on stderr with --out FILE, on the paper numbers.
"$PRRU" traj --time-optimal --waypoints "$WP" --force-max "$FLIM" --out "$tmp/to.csv" 2>"$tmp/err" \
  && grep -q "^prru traj: time-optimal (reachability analysis): 3 waypoints, " "$tmp/err" \
  && grep -q "^prru traj: fastest uniformly time-scaled quintic" "$tmp/err" \
  && grep -q "^prru traj: peak |fd| (N) .*, of force_max .*1" "$tmp/err" && ok \
  || bad "time-optimal summary on stderr: $(cat "$tmp/err")"
# Infeasible limits: exit 1 naming the grid point and the limit, an
# existing output unchanged.
echo keep >"$tmp/keep.csv"
# A stroke of +-1 nm around the first waypoint's sliders: left at once.
"$PRRU" ik --q 0,0,0 >"$tmp/ik0.json" 2>"$tmp/err" || bad "ik at q = 0: $(cat "$tmp/err")"
stroke=$(python3 -c "import json, sys; d = json.load(open(sys.argv[1]))['d']
print(','.join('%r,%r' % (x - 1e-9, x + 1e-9) for x in d))" "$tmp/ik0.json")
expect 1 "segment 1 (waypoint 1 to 2), s = 0.0025 (grid point 1 of 400): slider" -- traj --time-optimal \
  --waypoints "$WP" --force-max "$FLIM" --stroke "$stroke" --out "$tmp/keep.csv"
[ "$(cat "$tmp/keep.csv")" = keep ] && ok || bad "a refused time-optimal run changed its output file"
# The model file's limits (spec 13) act unless --no-limits: a model with
# torque_max and motor_speed_max plans within their rail equivalents, tau
# 2 pi gear / lead and rpm / 60 lead / gear, without limit options.
# The file: the committed format-2 model of the build's number of limbs
# with those keys added (its own numbers: the parameter kernels).
python3 - "$PRRU_MODEL" "$PRRU_SOURCE_DIR" "$tmp/lim.json" <<'PY'
import json, sys
sys.path.insert(0, sys.argv[2] + '/gen')
from prrugen import model
n = model.parse(open(sys.argv[1]).read(), sys.argv[1]).nlimb
m = json.load(open(sys.argv[2] + ('/models/prototype_example.json' if n == 3 else '/models/4prru.json')))
m.setdefault('actuators', {}).update({'lead': 0.02, 'gear': 2, 'torque_max': 0.5, 'motor_speed_max': 3000})
json.dump(m, open(sys.argv[3], 'w'))
PY
"$PRRU" --model "$tmp/lim.json" traj --time-optimal --waypoints "$WP" --out "$tmp/lim.csv" 2>"$tmp/err" \
  && grep -q "^# limits: force_max (N) 314.159.*; speed_max (m/s) 0.5,0.5" "$tmp/lim.csv" && ok \
  || bad "time-optimal with the model's limits: $(cat "$tmp/err") $(grep '^# limits' "$tmp/lim.csv")"
expect 2 "neither the options nor the model file give one" -- --model "$tmp/lim.json" traj --time-optimal \
  --waypoints "$WP" --no-limits
# track on the same model: its force limit clips (a line and the summary
# name the limits), --units motor adds tau = f lead / (2 pi gear) per
# actuator, and the plant's slider speeds are reported against speed_max.
"$PRRU" --model "$tmp/lim.json" track --waypoints "$WP" --durations 0.3,0.3 --units motor --out "$tmp/limt.csv" \
  --summary "$tmp/limt.json" 2>"$tmp/err" && python3 - "$tmp/limt.csv" "$tmp/limt.json" "$nact" <<'PY' \
  && ok || bad "track with the model's limits and --units motor: $(cat "$tmp/err")"
import csv, json, math, sys
lines = open(sys.argv[1]).read().splitlines()
assert any(l.startswith('# limits: force_max 314.159') for l in lines), [l for l in lines if l.startswith('#')]
rows = list(csv.DictReader(l for l in lines if not l.startswith('#')))
n = int(sys.argv[3])
for r in rows:
    for i in range(1, n + 1):
        f, tau = float(r['fd%d' % i]), float(r['tau%d' % i])
        assert abs(f) <= 314.16 and abs(tau - f * 0.02 / (2 * math.pi * 2)) <= 1e-12 * (1 + abs(tau)), (r['t'], i)
s = json.load(open(sys.argv[2]))
assert s['limits'].startswith('force_max 314.159') and len(s['max_dd']) == n and 0 <= s['over_speed_fraction'] <= 1, s
PY
expect 2 "--units" -- track --waypoints "$WP" --durations 1,1 --units motor --out "$tmp/x.csv"
"$PRRU" --model "$tmp/lim.json" traj --time-optimal --waypoints "$WP" --units motor --out "$tmp/limm.csv" \
  2>"$tmp/err" && python3 - "$tmp/limm.csv" "$nact" <<'PY' && ok || bad "traj --time-optimal --units motor: $(cat "$tmp/err")"
import csv, math, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#')))
for r in rows:
    for i in range(1, int(sys.argv[2]) + 1):
        f, tau = float(r['fd%d' % i]), float(r['tau%d' % i])
        assert abs(tau - f * 0.02 / (2 * math.pi * 2)) <= 1e-12 * (1 + abs(tau)), (r['t'], i)
        assert abs(tau) <= 0.5 * (1 + 1e-6), (r['t'], i, tau)  # torque_max
PY
expect 2 "--units" -- traj --time-optimal --waypoints "$WP" --force-max 100 --units motor
# Bad options: exit 2.
expect 2 "needs at least one force or speed limit, and neither the options nor the model file give one" -- traj --time-optimal --waypoints "$WP"
expect 2 "needs at least one force or speed limit" -- traj --time-optimal --waypoints "$WP" --no-limits
expect 2 "--speed-max alone leaves the accelerations unbounded" -- traj --time-optimal --waypoints "$WP" --speed-max 1
expect 2 "--durations does not apply with --time-optimal" -- traj --time-optimal --waypoints "$WP" --durations 1,1 --fmax 100
expect 2 "--fmax and --fd-max are the same limit: give one" -- traj --time-optimal --waypoints "$WP" --fmax 100 --fd-max 100
expect 2 "--fmax: '0' is not a positive number" -- traj --time-optimal --waypoints "$WP" --fmax 0
expect 2 "--speed-max: '1,2' is not one number or $nact comma-separated numbers" -- traj --time-optimal --waypoints "$WP" --fmax 100 --speed-max 1,2
expect 2 "--stroke: slider 1's range" -- traj --time-optimal --waypoints "$WP" --fmax 100 --stroke 0.3,0.2
expect 2 "--grid: '1' is not a whole number" -- traj --time-optimal --waypoints "$WP" --fmax 100 --grid 1
expect 2 "--grid: '2.5' is not a whole number" -- traj --time-optimal --waypoints "$WP" --fmax 100 --grid 2.5
expect 2 "--dt: 'x' is not a positive time step (s) or 'grid'" -- traj --time-optimal --waypoints "$WP" --fmax 100 --dt x
expect 2 "waypoints 1 and 2 coincide" -- traj --time-optimal --waypoints '0,0,0;0,0,0' --fmax 100
expect 2 "apply only with --time-optimal" -- traj --waypoints "$WP" --durations 1,1 --fmax 100
expect 2 "two profiles" -- traj --quintic --time-optimal --waypoints "$WP" --fmax 100
"$PRRU" traj --time-optimal --help >"$tmp/help_topp.txt" && grep -qF "$(act_names fd)" "$tmp/help_topp.txt" \
  && awk 'length > 80 { bad = 1 } END { exit bad }' "$tmp/help_topp.txt" \
  && ! grep -q -i -E "gsl|kernel|runtime|prru_[a-z]|PRRU_" "$tmp/help_topp.txt" && ok \
  || bad "traj --time-optimal --help: $(head -c 300 "$tmp/help_topp.txt")"

# The figure, where gnuplot is installed.
if command -v gnuplot >/dev/null; then
  "$PRRU" track --waypoints "$WP" --durations 1,1 --fmax "$lim" --out "$tmp/p.csv" --plot "$tmp/p.png" \
    >/dev/null 2>"$tmp/err" && [ "$(head -c 4 "$tmp/p.png" | tail -c 3)" = PNG ] && ok \
    || bad "track --plot: $(cat "$tmp/err")"
fi

echo "test_cli_traj: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
