#!/usr/bin/env bash
# Hostile numbers on the prru command line: NaN/inf/overflowing text, values
# that overflow inside the dynamics, singular and unreachable states. Every
# case must end with the documented exit status (0 ok, 1 failure, 2 usage;
# never a signal or a sanitizer abort), a message naming the option or the
# reason, and no NaN/inf/null in any JSON or CSV it writes (test_cli.sh
# covers the ordinary bad arguments; this file the extreme ones). Holds for
# any model, with 3 or 4 actuators; the paper's singular pose and a run
# across it are in paper_cli.sh.

. "$(dirname "$0")/cli_lib.sh"

# Outputs that must never carry a non-finite number (case-insensitive:
# printf's nan/inf, JSON null from prru_cli_json_number).
nonfinite() { grep -qiE '(^|[^a-z_])(-?nan|-?inf(inity)?|null)([^a-z_]|$)' "$@"; }

# check STATUS NEEDLE -- ARGS...: exit status, a stderr substring (empty:
# any), stdout free of non-finite numbers when it succeeded, and every
# file written under $tmp/out* free of them too.
check() {
  local want=$1 needle=$2
  shift 3
  rm -f "$tmp"/out*
  "$PRRU" "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  local got=$? what="prru $*"
  what=${what:0:160}
  if [ "$got" -ge 128 ] && [ "$got" -ne 130 ]; then
    bad "$what: killed by signal $((got - 128)): $(tail -c 400 "$tmp/stderr")"; return; fi
  if [ "$got" -ne "$want" ]; then
    bad "$what: exit $got, want $want: $(head -c 300 "$tmp/stderr")"; return; fi
  if [ -n "$needle" ] && ! grep -qF -- "$needle" "$tmp/stderr"; then
    bad "$what: stderr lacks '$needle': $(head -c 300 "$tmp/stderr")"; return; fi
  if [ "$got" -ne 0 ] && [ ! -s "$tmp/stderr" ]; then
    bad "$what: failed without a message"; return; fi
  if [ "$got" -eq 0 ] && nonfinite "$tmp/stdout"; then
    bad "$what: non-finite value on stdout: $(grep -oiE '.{0,40}(nan|inf|null).{0,20}' "$tmp/stdout" | head -n 2)"; return; fi
  for f in "$tmp"/out*; do
    [ -e "$f" ] || continue
    if nonfinite "$f"; then
      bad "$what: non-finite value in $(basename "$f"): $(grep -iE 'nan|inf' "$f" | head -n 1 | cut -c1-200)"; return; fi
  done
  ok
}

# A regular pose (reached by every model in models/) and a singular one of
# the model under test. With three actuators: det J_d = 0 to about 1e-16,
# found by bisection on the J_d that `prru ik` prints, along q2 at q3 = 0
# (the paper's model: q2 = -0.80611414893222655 at q1 = 0, see
# paper_cli.sh). With a redundant fourth actuator that pose (where limbs
# 1 to 3 are singular, QSING3) is regular, and J_d (4x3) keeps rank 3 over
# the workspace; it loses it at the edge, where a limb is stretched out and
# dd/dq grows without bound: QSING is then the last reachable q1 at
# q2 = q3 = 0, found by bisection.
Q=0.1,0.2,-0.8
QSING3=$(python3 - "$PRRU" <<'PY'
import json, subprocess, sys
def det(q):
    r = subprocess.run([sys.argv[1], 'ik', '--q', ','.join(repr(x) for x in q)], capture_output=True, text=True)
    if r.returncode:
        return None
    J = [x for row in json.loads(r.stdout)['Jd'] for x in row]
    return (J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6])
            + J[2] * (J[3] * J[7] - J[4] * J[6]))
for q1 in (0.0, 0.3, -0.3, 0.5, -0.5):
    for sign in (-1, 1):
        prev = None
        for k in range(151):
            q2 = sign * 0.01 * k
            dk = det([q1, q2, 0.0])
            if dk is None:
                break
            if prev is not None and (dk > 0) != (prev[1] > 0):
                a, da, b = prev[0], prev[1], q2
                while True:
                    m = 0.5 * (a + b)
                    if m in (a, b):
                        break
                    dm = det([q1, m, 0.0])
                    if dm is None:
                        break
                    if (dm > 0) == (da > 0):
                        a, da = m, dm
                    else:
                        b = m
                print('%r,%r,0' % (q1, a))
                sys.exit(0)
            prev = (q2, dk)
PY
)
[ -n "$QSING3" ] && ok || bad "no singular pose found (det J_d changes sign nowhere along q2 at q3 = 0)"
: "${QSING3:=0,0,0}"
if [ "$nact" -gt 3 ]; then
  QSING=$(python3 - "$PRRU" <<'PY'
import json, subprocess, sys
def ik(q):
    r = subprocess.run([sys.argv[1], 'ik', '--q', ','.join(repr(x) for x in q)], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else None
a, b = 0.0, 2.0
if ik([a, 0.0, 0.0]) and not ik([b, 0.0, 0.0]):
    while True:
        m = 0.5 * (a + b)
        if m in (a, b):
            break
        if ik([m, 0.0, 0.0]):
            a = m
        else:
            b = m
    if ik([a, 0.0, 0.0])['singular']:
        print('%r,0,0' % a)
PY
)
  [ -n "$QSING" ] && ok || bad "no singular pose at the edge of the workspace along q1"
  : "${QSING:=0,0,0}"
else
  QSING=$QSING3
fi
# Lists of actuator values: pad appends a 0 for every actuator beyond three.
pad=$(nlist 0 | cut -d, -f4-)
pad=${pad:+,$pad}
huge_digits=$(printf '9%.0s' $(seq 1 400))     # 1e400 written out: overflows
tiny=$(printf '1e-%s' 400)

# ---- Number syntax: exit 2 naming the option, for every vector option ----
for opt in q qd fd fp mp; do
  base=(eval --q "$Q")
  [ "$opt" = q ] && base=(eval)
  for v in nan,0,0 0,NaN,0 0,0,-nan inf,0,0 0,-Infinity,0 1e309,0,0 0,-1e309,0 \
           0x1p3,0,0 "$huge_digits,0,0" 1e5x,0,0 "0 0 0" "0;0;0" 0,,0 "0,0,0," ",0,0" \
           "" "+,0,0" "1e,0,0" "--1,0,0" "0,0,0,nan" $'0,0,0\n1'; do
    [ "$opt" = fd ] && v="$v$pad"
    check 2 "--$opt" -- "${base[@]}" --"$opt" "$v"
  done
done
check 2 "--q" -- eval --q=inf,inf,inf
check 2 "--q" -- ik --q 0,0,nan
check 2 "--d" -- fk --d "nan,0,0$pad"
check 2 "--seed" -- fk --d "$(nlist 0.2)" --seed 0,inf,0
check 2 "--q" -- dme --q 0,0,1e999

# ---- simulate: non-finite and degenerate settings are usage errors ----
for a in "--t-end nan" "--t-end inf" "--t-end 1e309" "--t-end 0" "--t-end -0" \
         "--dt 0 --t-end 1" "--dt -1e-3" "--dt 2 --t-end 1" "--dt 1e-300 --t-end 1e300" \
         "--atol nan" "--atol -1" "--rtol inf" "--atol 0 --rtol 0" "--h0 0" "--h0 inf" \
         "--harmonic nan,1" "--harmonic 1" "--harmonic 1,inf" "--q0 inf,0,0" \
         "--qd0 0,nan,0" "--fd 1e400,0,0$pad"; do
  # shellcheck disable=SC2086
  check 2 "" -- simulate $a --out "$tmp/out.csv"
done
printf 'q0 = 0, 0, inf\n' >"$tmp/s_inf.txt"
check 2 "q0" -- simulate --scenario "$tmp/s_inf.txt" --out "$tmp/out.csv"
printf 'harmonic = 50, nan\n' >"$tmp/s_nan.txt"
check 2 "harmonic" -- simulate --scenario "$tmp/s_nan.txt" --out "$tmp/out.csv"
fdh=$(act_names fd)
printf 't,%s\n0,1,1e999,1%s\n' "$fdh" "$pad" >"$tmp/l_ovf.csv"
check 2 "fd2" -- simulate --loads "$tmp/l_ovf.csv" --out "$tmp/out.csv"
printf 't,%s\n0,%s\n0,%s\n' "$fdh" "$(nlist 1)" "$(nlist 2)" >"$tmp/l_time.csv"
check 2 "does not increase" -- simulate --loads "$tmp/l_time.csv" --out "$tmp/out.csv"

# ---- map and dme ranges ----
check 2 "--q1" -- map --q1 nan:1:3 --q2 0:1:3 --out "$tmp/out.csv"
check 2 "--q2" -- map --q1 0:1:3 --q2 0:inf:3 --out "$tmp/out.csv"
check 2 "COUNT" -- map --q1 0:1:1e20 --q2 0:1:3 --out "$tmp/out.csv"
check 2 "limit" -- map --q1 0:1:100000 --q2 0:1:100000 --out "$tmp/out.csv"
check 2 "--threads" -- map --q1 0:1:3 --q2 0:1:3 --threads 100000 --out "$tmp/out.csv"
check 2 "--rcond-min" -- dme --q 0,0,0 --rcond-min nan
check 2 "--rcond-min" -- dme --q 0,0,0 --rcond-min 1

# ---- Singular and unreachable states: exit 1 with the reason ----
check 1 "singular" -- eval --q "$QSING"
check 1 "singular" -- eval --q "$QSING" --qd 0.3,-0.4,0.5 --fd "$(fdlist 50 40 25)"
check 1 "singular" -- fk --d "$(nlist 0.2)" --seed "$QSING"
check 1 "singular" -- simulate --q0 "$QSING" --t-end 0.01 --out "$tmp/out.csv"
check 1 "not reachable" -- eval --q 0,1.5,-0.8 --qd 1e300,1e300,1e300
check 1 "" -- fk --d "$(nlist 1e308)"
check 1 "" -- fk --d "$(nlist 0.2)" --seed 1e308,0,0
check 1 "" -- fk --d "$(nlist 1e308)" --lsq
check 1 "" -- fk --d "$(nlist -1e308)" --lsq --seed "$Q"
printf 't,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,%s,0,0,0,0,0,0\n' "$QSING" >"$tmp/traj_sing.csv"
check 1 "singular" -- id --traj "$tmp/traj_sing.csv" --out "$tmp/out.csv"
# dme's documented answer at a singular pose is status "singular" with null
# fields and exit 0: only check that it says so.
"$PRRU" dme --q "$QSING" >"$tmp/dme.json" 2>&1
grep -q '"singular"' "$tmp/dme.json" && ok || bad "dme at $QSING: $(head -c 200 "$tmp/dme.json")"
# The redundant actuator keeps J_d regular where limbs 1 to 3 alone are
# singular: everything works there.
if [ "$nact" -gt 3 ]; then
  check 0 "" -- eval --q "$QSING3" --qd 0.3,-0.4,0.5 --fd "$(fdlist 50 40 25)"
  check 0 "" -- ik --q "$QSING3"
  grep -q '"singular": false' "$tmp/stdout" && grep -q actuator_null "$tmp/stdout" && ok || bad "ik at $QSING3: $(head -c 300 "$tmp/stdout")"
  check 0 "" -- simulate --q0 "$QSING3" --t-end 0.01 --out "$tmp/out.csv"
  printf 't,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,%s,0,0,0,0,0,0\n' "$QSING3" >"$tmp/traj_sing3.csv"
  check 0 "" -- id --traj "$tmp/traj_sing3.csv" --preload 20 --null-vector --out "$tmp/out.csv"
  "$PRRU" dme --q "$QSING3" >"$tmp/dme.json" 2>&1
  grep -q '"ok"' "$tmp/dme.json" && ok || bad "dme at $QSING3: $(head -c 200 "$tmp/dme.json")"
  # Preloads at the limits of double precision (|n_i| <= 1): finite.
  check 0 "" -- id --traj "$tmp/traj_sing3.csv" --preload 1e308 --out "$tmp/out.csv"
  check 0 "" -- id --traj "$tmp/traj_sing3.csv" --preload -1.7e308 --out "$tmp/out.csv"
  check 2 "--preload" -- id --traj "$tmp/traj_sing3.csv" --preload inf --out "$tmp/out.csv"
  check 2 "--preload" -- id --traj "$tmp/traj_sing3.csv" --preload 1e999 --out "$tmp/out.csv"
else
  check 2 "no internal preload" -- id --traj "$tmp/traj_sing.csv" --preload 1 --out "$tmp/out.csv"
fi

# ---- Finite inputs whose dynamics overflow: exit 1, never non-finite output ----
# A trajectory runs out of the workspace fast; rows before the stop are kept.
check 1 "stopped at t" -- simulate --q0 0,0,-0.8 --qd0 1e6,0,0 --t-end 0.1 --dt 0.01 --out "$tmp/out.csv"
printf 't,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,0.1,0.2,-0.8,0,0,0,1e308,1e308,1e308\n' >"$tmp/traj_acc.csv"
check 1 "invalid input" -- id --traj "$tmp/traj_acc.csv" --out "$tmp/out.csv"
printf 't,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,0.1,0.2,-0.8,1e200,1e200,0,0,0,0\n' >"$tmp/traj_vel.csv"
check 1 "invalid input" -- id --traj "$tmp/traj_vel.csv" --out "$tmp/out.csv"
# Extreme but finite and representable: must just work.
check 0 "" -- eval --q 0,0,1e308
check 0 "" -- eval --q "$Q" --qd 1e100,1e100,0
check 0 "" -- eval --q "$Q" --fd "1e300,0,0$pad"
check 0 "" -- ik --q 0,0,1.7e308
check 0 "" -- simulate --q0 "$Q" --h0 1e-300 --t-end 0.01 --no-reactions --out "$tmp/out.csv"

# Regressions: each of these once crashed through the checks (exit 0 with
# NaN/inf in the output, or a wrong diagnosis).
# qd^2 overflows in h: the runtime classifies it as a singular J_d although
# q is the regular pose Q; the message must not claim singularity, nor
# blame q: it names the velocities or loads.
check 1 "the dynamics overflow at q = (0.1, 0.2, -0.8): the velocities qd = (1e+154, 1e+154, 0) or the loads are too large" -- eval --q "$Q" --qd 1e154,1e154,0
check 1 "or the loads are too large" -- eval --q "$Q" --fd "$(nlist 1e308)"
# b is finite, the Cholesky solve overflows: exit 0 with "qdd": [null, ...].
check 1 "" -- eval --q "$Q" --fp 1e308,1e308,1e308 --mp 1e308,1e308,1e308
# fp2 = -1e308 - 1e308 cos(t) = -inf does no work at this pose, so qdd stays
# finite: the run "succeeds" and writes -inf in the fp2 column.
check 1 "" -- simulate --harmonic 1e308,1 --fp 0,-1e308,0 --t-end 0.01 --out "$tmp/out.csv"
# The reaction solve overflows under 1e308 N and prru_reactions
# returns PRRU_OK: eval prints "lambda": [null, ...] with exit 0, and
# simulate writes a row of -nan reactions before it stops.
check 1 "" -- eval --q 0,0,0 --fd "1e308,0,0$pad"
# A load table of finite values whose interpolation overflows (fuzz finding,
# fuzz/regressions/schedule/), and whose first row already has 1e308 N.
printf 't,%s\n0,1e308,0,0%s\n1,-1e308,0,0%s\n' "$fdh" "$pad" "$pad" >"$tmp/l_interp.csv"
check 1 "" -- simulate --loads "$tmp/l_interp.csv" --t-end 1 --dt 0.1 --out "$tmp/out.csv"
# Grid spacing (1e308 - -1e308)/2 overflows: q1 = -inf rows in the CSV.
check 2 "--q1" -- map --q1 -1e308:1e308:3 --q2 0:1:3 --out "$tmp/out.csv"
# Table fuzz finding at a time between rows: (t - t0)/(t1 - t0) was inf/inf;
# the loads (about 0.5 N) are harmless, so the run must simply succeed.
printf 't,%s\n-1.7e308,%s\n1.7e308,%s\n' "$fdh" "$(nlist 0)" "$(nlist 1)" >"$tmp/l_span.csv"
check 0 "" -- simulate --loads "$tmp/l_span.csv" --t-end 0.01 --out "$tmp/out.csv"
# Underflowing decimals are finite numbers; rejecting them is acceptable, but
# not with the claim that they are not finite.
"$PRRU" eval --q "$Q" --qd "$tiny,0,0" >/dev/null 2>"$tmp/stderr"
if [ $? -eq 0 ] || ! grep -q "not 3 comma-separated finite" "$tmp/stderr"; then ok
else bad "eval --qd $tiny,0,0: $(cat "$tmp/stderr")"; fi

# ---- User text in CSV comment lines ----
# optimize names its --out file in the after map's "# design:" comment: a
# path with a line break, a quote and a fake data row must stay in that
# one comment line (the map keeps its 13 x 11 rows of 5 fields).
mkdir "$tmp/opt_hostile"
hostile_out="$tmp/opt_hostile/m$(printf '\n0,0,0,1,ok\r\n"\\')x.json"
"$PRRU" optimize --vars l2 --range 5 --q1 -0.2:0.2:13 --q2 -0.25:0.15:11 --max-iter 5 \
  --out "$hostile_out" --report "$tmp/opt_hostile/rep" >"$tmp/stdout" 2>"$tmp/stderr" \
  || bad "optimize --out with a line break: $(head -c 300 "$tmp/stderr")"
for m in before after; do
  python3 - "$tmp/opt_hostile/rep/${m}_map.csv" <<'PY' && ok || bad "$m map: user text broke a comment line"
import sys
lines = open(sys.argv[1], "rb").read().split(b"\n")
assert lines[-1] == b"", "no final newline"
body = [l for l in lines[:-1] if not l.startswith(b"#")]
assert body[0] == b"q1,q2,q3,w_R,status", body[0]
assert len(body) == 1 + 13 * 11, len(body)
assert all(len(l.split(b",")) == 5 and b"\r" not in l for l in body[1:])
PY
done
grep -q "^# design: optimised, .*m?0,0,0,1,ok??\"\\\\x.json (name " "$tmp/opt_hostile/rep/after_map.csv" \
  && ok || bad "after map: the design line lost the file name: $(grep '^# design' "$tmp/opt_hostile/rep/after_map.csv")"

finish test_cli_hostile
