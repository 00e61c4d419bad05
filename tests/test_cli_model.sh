#!/usr/bin/env bash
# prru --model FILE and PRRU_MODEL (issue 25, "one build, any model"): a
# model file of the build's number of limbs read at run time, evaluated by
# the specialised kernels when its numbers are the build's, else by the
# parameter kernels; its identity in every output; the refusals.
. "$(dirname "$0")/cli_lib.sh"

q=0.1,0.2,-0.8
qd=0.3,-0.4,0.5
fd=$(fdlist 50 40 30)
# model_edit IN OUT PYTHON: OUT is IN's JSON with the statement PYTHON
# applied to it as d (indented, so that the bytes differ from IN's).
model_edit() {
  python3 - "$1" "$2" "$3" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
exec(sys.argv[3])
open(sys.argv[2], "w").write(json.dumps(d, indent=3) + "\n")
PY
}
# without_model JSON: the file's JSON without its "model" member, sorted.
without_model() { python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); d.pop("model"); print(json.dumps(d, sort_keys=True))' "$1"; }
first_body=$(python3 -c 'import json, sys; print(next(iter(json.load(open(sys.argv[1]))["bodies"])))' "$PRRU_MODEL")

# ---- the build's model with whitespace added: the specialised kernels ----
# The same robot (every number equal), another file (another sha256): the
# identity names the file given and the fast path; the numbers are the
# built-in model's, bit for bit (the same kernels run).
{ cat "$PRRU_MODEL"; printf '\n\n   \n'; } >"$tmp/ws.json"
ws_sha=$(sha256sum "$tmp/ws.json" | cut -d' ' -f1)
"$PRRU" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/e0.json" || bad "eval, built-in model"
"$PRRU" --model "$tmp/ws.json" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/e1.json" 2>"$tmp/e1.err" \
  || bad "--model (whitespace copy) eval: $(cat "$tmp/e1.err")"
python3 - "$tmp/e1.json" "$tmp/ws.json" "$ws_sha" "$model_name" <<'PY' && ok || bad "--model whitespace copy: model object $(head -c 300 "$tmp/e1.json")"
import json, sys
m = json.load(open(sys.argv[1]))["model"]
assert m == {"name": sys.argv[4], "file": sys.argv[2], "sha256": sys.argv[3], "kernels": "specialised"}, m
PY
[ "$(without_model "$tmp/e0.json")" = "$(without_model "$tmp/e1.json")" ] && ok \
  || bad "--model whitespace copy: eval's numbers differ from the built-in model's"
"$PRRU" --model "$tmp/ws.json" version >"$tmp/v1.txt" && grep -qx "model kernels: specialised" "$tmp/v1.txt" \
  && grep -qxF "model file: $tmp/ws.json" "$tmp/v1.txt" && grep -qx "model sha256: $ws_sha" "$tmp/v1.txt" \
  && ok || bad "prru --model (whitespace copy) version: $(cat "$tmp/v1.txt")"
"$PRRU" --model "$tmp/ws.json" simulate --t-end 0.01 --out "$tmp/s1.csv" 2>/dev/null || bad "--model simulate"
[ "$(head -1 "$tmp/s1.csv")" = "# prru $prru_version model $model_name ($tmp/ws.json, sha256 $ws_sha, specialised kernels)" ] \
  && ok || bad "--model: CSV model line '$(head -1 "$tmp/s1.csv")'"

# ---- one mass changed: the parameter kernels ----
model_edit "$PRRU_MODEL" "$tmp/heavy.json" "d['bodies']['$first_body']['mass'] *= 1.25"
heavy_sha=$(sha256sum "$tmp/heavy.json" | cut -d' ' -f1)
F="$tmp/heavy.json"
"$PRRU" --model "$F" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/h1.json" 2>"$tmp/h1.err" \
  || bad "--model (heavier $first_body) eval: $(cat "$tmp/h1.err")"
"$PRRU" eval --q "$q" --model "$F" --qd "$qd" --fd "$fd" >"$tmp/h2.json" || bad "eval --model F"
"$PRRU" eval --q "$q" --qd "$qd" --fd "$fd" --model="$F" >"$tmp/h3.json" || bad "eval --model=F"
PRRU_MODEL="$F" "$PRRU" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/h4.json" || bad "PRRU_MODEL=F eval"
cmp -s "$tmp/h1.json" "$tmp/h2.json" && cmp -s "$tmp/h1.json" "$tmp/h3.json" && cmp -s "$tmp/h1.json" "$tmp/h4.json" \
  && ok || bad "prru --model F eval, prru eval --model F, --model=F and PRRU_MODEL=F differ"
# The option wins over the environment; an empty PRRU_MODEL is no model.
# --precision float needs the float batched kernels, which only the
# build's own numbers have: refused (exit 2, the reason) on the parameter
# kernels, accepted on the whitespace copy (the specialised kernels).
expect 2 "--precision float: model $model_name ($F, sha256 $heavy_sha, parameter kernels) has no single-precision kernels" \
  -- --model "$F" map --q1 0:0.2:3 --q2 0:0.2:3 --precision float --out "$tmp/pf.csv"
[ ! -e "$tmp/pf.csv" ] && ok || bad "a refused --precision float map wrote its output"
expect 0 "" -- --model "$tmp/ws.json" map --q1 0:0.2:3 --q2 0:0.2:3 --precision float --out "$tmp/pf.csv"
PRRU_MODEL="$tmp/ws.json" "$PRRU" --model "$F" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/h5.json" \
  && cmp -s "$tmp/h1.json" "$tmp/h5.json" && ok || bad "--model does not win over PRRU_MODEL"
PRRU_MODEL= "$PRRU" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/e2.json" && cmp -s "$tmp/e0.json" "$tmp/e2.json" \
  && ok || bad "an empty PRRU_MODEL is not the built-in model"
python3 - "$tmp/h1.json" "$F" "$heavy_sha" "$tmp/e0.json" <<'PY' && ok || bad "--model heavier body: $(head -c 400 "$tmp/h1.json")"
import json, sys
h, e = json.load(open(sys.argv[1])), json.load(open(sys.argv[4]))
assert h["model"]["kernels"] == "parameter" and h["model"]["file"] == sys.argv[2], h["model"]
assert h["model"]["sha256"] == sys.argv[3], h["model"]
# A heavier body: another mass matrix (its change is of the order of the
# body's share, far above rounding), the same kinematics bit for bit (the
# geometry is unchanged: the parameter kernels compute d and J_d alike to
# rounding; 1e-13 of the unit-size entries).
dM = max(abs(a - b) for ra, rb in zip(h["M"], e["M"]) for a, b in zip(ra, rb))
assert dM > 1e-6 * max(abs(a) for r in e["M"] for a in r), dM
assert max(abs(a - b) for a, b in zip(h["d"], e["d"])) <= 1e-13, (h["d"], e["d"])
PY
"$PRRU" --model "$F" version | grep -qx "model kernels: parameter" && ok || bad "version: parameter kernels"

# ---- identify -> --model -> track, no rebuild (issue 25's loop) ----
# The true robot: every mass and inertia x1.05 (--mismatch mass=1.05, the
# common CAD error), tracking a short excitation under the built-in
# model's computed torque; its log is the identification data. The
# identified model, loaded with --model, drives the same true robot
# (--plant, the same numbers as the mismatch: checked row for row) with a
# far smaller error: its base parameters are the truth's to the fit's
# rounding (residual sigma ~1e-13 N), so what is left is the integrator's
# tolerance (1e-12), while the built-in model's 5 % error leaves ~1e-3.
"$PRRU" excite --evals 300 --period 4 --out "$tmp/ex.csv" 2>"$tmp/ex.err" || bad "excite: $(cat "$tmp/ex.err")"
"$PRRU" track --ref "$tmp/ex.csv" --mismatch mass=1.05 --out "$tmp/robot.csv" --summary "$tmp/s0.json" \
  2>"$tmp/t0.err" || bad "track --mismatch mass=1.05: $(cat "$tmp/t0.err")"
"$PRRU" identify --data "$tmp/robot.csv" --out "$tmp/id.json" --report "$tmp/idrep.csv" 2>"$tmp/id.err" \
  || bad "identify: $(cat "$tmp/id.err")"
model_edit "$PRRU_MODEL" "$tmp/true.json" "
for b in d['bodies'].values():
    b['mass'] *= 1.05
    b['inertia'] = [x * 1.05 for x in b['inertia']]"
"$PRRU" track --ref "$tmp/ex.csv" --plant "$tmp/true.json" --out "$tmp/robot2.csv" >/dev/null 2>&1 \
  && cmp -s <(tail -n +3 "$tmp/robot.csv") <(tail -n +3 "$tmp/robot2.csv") && ok \
  || bad "track --plant (masses x1.05 in the file) differs from --mismatch mass=1.05"
"$PRRU" --model "$tmp/id.json" track --ref "$tmp/ex.csv" --plant "$tmp/true.json" --out "$tmp/t1.csv" \
  --summary "$tmp/s1.json" 2>"$tmp/t1.err" || bad "prru --model id.json track: $(cat "$tmp/t1.err")"
python3 - "$tmp/s0.json" "$tmp/s1.json" "$tmp/id.json" <<'PY' && ok || bad "the identified model does not track the true robot better: $(cat "$tmp/s0.json" "$tmp/s1.json" | head -c 600)"
import json, sys
s0, s1 = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert s1["model"]["file"] == sys.argv[3] and s1["model"]["kernels"] == "parameter", s1["model"]
e0, e1 = max(s0["rms_error"]), max(s1["rms_error"])
print("rms tracking error: built-in model %.3g, identified model %.3g" % (e0, e1))
# The built-in model's error is the 5 % mismatch's (1e-3 here); the
# identified model's is the integrator's (atol 1e-12 on ~1 s of motion):
# 1e-9 leaves three orders of magnitude of margin above it.
assert e0 > 1e-5 and e1 < 1e-9, (e0, e1)
PY
head -1 "$tmp/t1.csv" | grep -qF "model ${model_name:0:13}_id ($tmp/id.json, sha256 $(sha256sum "$tmp/id.json" | cut -d' ' -f1), parameter kernels)" \
  && ok || bad "track --model id.json: model line '$(head -1 "$tmp/t1.csv")'"
# With --model, track's plant is that model: the controller knows it exactly.
"$PRRU" --model "$tmp/true.json" track --ref "$tmp/ex.csv" --summary "$tmp/s2.json" --out /dev/null 2>/dev/null \
  && python3 -c 'import json, sys; sys.exit(0 if max(json.load(open(sys.argv[1]))["rms_error"]) < 1e-9 else 1)' "$tmp/s2.json" \
  && ok || bad "--model true.json track: the plant is not the loaded model"
# identify's prior is the loaded model: identifying the true robot's own
# exact log from the truth leaves its masses as they were.
"$PRRU" --model "$tmp/true.json" identify --data "$tmp/robot.csv" --out "$tmp/id2.json" --report "$tmp/id2rep.csv" \
  2>/dev/null || bad "--model true.json identify"
python3 - "$tmp/id2.json" "$tmp/true.json" <<'PY' && ok || bad "identify's prior is not the loaded model"
import json, sys
a, t = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
# The masses to the consistent fit's accuracy (test_cli_ident.sh: 1e-7 of
# the body's mass).
for name, body in t["bodies"].items():
    assert abs(a["bodies"][name]["mass"] - body["mass"]) <= 1e-7 * body["mass"], name
PY

# ---- refusals: exit 2, the reason, nothing computed or written ----
echo old >"$tmp/keep.csv"
refused() { # NEEDLE ARGS...: exit 2, "prru: " and NEEDLE on stderr, keep.csv unchanged
  local needle=$1; shift
  "$PRRU" "$@" simulate --t-end 0.01 --out "$tmp/keep.csv" >"$tmp/out" 2>"$tmp/err"
  local st=$?
  [ "$st" = 2 ] && grep -qF -- "$needle" "$tmp/err" && [ "$(cat "$tmp/keep.csv")" = old ] && [ ! -s "$tmp/out" ] \
    && ok || bad "prru $* simulate: exit $st, stderr '$(head -c 300 "$tmp/err")', keep.csv '$(head -c 80 "$tmp/keep.csv")'"
}
refused "prru: $tmp/missing.json: " --model "$tmp/missing.json"
model_edit "$PRRU_MODEL" "$tmp/neg.json" "d['bodies']['$first_body']['mass'] = -1.0"
refused "prru: $tmp/neg.json: bodies.$first_body.mass: must be positive" --model "$tmp/neg.json"
if [ "$nact" = 3 ]; then other="$PRRU_SOURCE_DIR/models/4prru.json" other_limbs=4
else other="$PRRU_SOURCE_DIR/models/3prru_paper.json" other_limbs=3; fi
# identifies_itself MODEL TAG WHAT: excite then identify on MODEL without
# a build of its own (the topology's regressor reads geometry and gravity
# at run time): its own exact forces give back its base parameters, to
# 1e-8 of each one's resolution (the report's column; the issue's bound
# for exact data).
identifies_itself() {
  local m=$1 t=$2 what=$3
  "$PRRU" --model "$m" excite --evals 40 --period 4 --out "$tmp/${t}ex.csv" 2>"$tmp/err" &&
    "$PRRU" --model "$m" identify --data "$tmp/${t}ex.csv" --out "$tmp/${t}id.json" \
      --report "$tmp/${t}rep.csv" 2>"$tmp/err" && ok || bad "excite and identify $what: $(cat "$tmp/err")"
  python3 - "$tmp/${t}rep.csv" <<'PY' && ok || bad "identify $what: base parameters"
import csv, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#')))
worst = max(abs(float(r['estimate']) - float(r['prior'])) / float(r['resolution']) for r in rows)
assert rows and worst <= 1e-8, worst
PY
}
# The other topology on this build, no rebuild: eval sizes its outputs by
# the file's actuators on the parameter kernels (--model and PRRU_MODEL
# alike), and excite then identify give back its own base parameters from
# its own exact forces, to 1e-8 of each one's resolution (as below).
"$PRRU" --model "$other" eval --q 0,0,-0.36 >"$tmp/oe.json" 2>"$tmp/err" &&
  PRRU_MODEL="$other" "$PRRU" eval --q 0,0,-0.36 >"$tmp/oe2.json" 2>>"$tmp/err" &&
  python3 - "$tmp/oe.json" "$tmp/oe2.json" "$other_limbs" <<'PY' && ok || bad "eval of the other topology ($other): $(cat "$tmp/err")"
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
n = int(sys.argv[3])
assert a == b, "--model and PRRU_MODEL differ"
assert a["model"]["kernels"] == "parameter", a["model"]
assert len(a["d"]) == n and len(a["Jd"]) == n and len(a["fd"]) == n and len(a["lambda"]) == 19 * n
PY
identifies_itself "$other" o "on the other topology"
expect 2 "prru: --model needs a model file" -- eval --q "$q" --model
expect 2 "prru: --model needs a model file" -- --model= eval --q "$q"
expect 2 "prru: --model given twice" -- --model "$F" eval --q "$q" --model "$F"
# identify and excite on a model of another geometry (identifies_itself).
model_edit "$PRRU_MODEL" "$tmp/geo.json" "
g = d['geometry']
g['l1'] = [g['l1'][0] * 1.01] + g['l1'][1:] if isinstance(g['l1'], list) else g['l1'] * 1.01"
"$PRRU" --model "$tmp/geo.json" eval --q "$q" >/dev/null 2>&1 && ok || bad "eval with another geometry"
identifies_itself "$tmp/geo.json" g "with another geometry"
# A heavier body keeps the geometry: identification works from it.
"$PRRU" --model "$F" excite --evals 20 --period 4 --out "$tmp/hex.csv" 2>/dev/null && ok \
  || bad "excite with the build's geometry and another mass refused"

# ---- drives and limits (spec 13): the stroke bounds the workspace ----
# models/prototype_drives.json: stroke [-0.05, 0.45] m, sliders near
# d = 0.21 m at q = 0; q3 = 0.3 puts slider 1 at 0.512 m (beyond d_max),
# q3 = -0.2 falls under gravity to d_min within 0.13 s.
if [ "$nact" -eq 3 ]; then
  D="$PRRU_SOURCE_DIR/models/prototype_drives.json"
  E="$PRRU_SOURCE_DIR/models/prototype_example.json"
  expect 1 "q = (0, 0, 0.3): out_of_stroke: slider 1 at d = 0.512424928 m is outside its stroke [-0.05, 0.45] m" \
    -- --model "$D" eval --q 0,0,0.3
  "$PRRU" --model "$E" eval --q 0,0,0.3 >/dev/null 2>&1 && ok || bad "eval beyond the stroke of a model without one"
  "$PRRU" --model "$D" eval --q 0,0,0.2 >/dev/null 2>&1 && ok || bad "eval inside the stroke refused"
  "$PRRU" --model "$D" map --q1 -0.2:0.2:5 --q2 -0.2:0.2:5 --q3 0.235 --out "$tmp/smap.csv" >"$tmp/smap.txt" 2>&1 \
    || bad "map across the stroke end: $(cat "$tmp/smap.txt")"
  [ "$(grep -c ',NaN,out_of_stroke$' "$tmp/smap.csv")" -eq 22 ] && [ "$(grep -c ',ok$' "$tmp/smap.csv")" -eq 3 ] \
    && ok || bad "map: 22 points out_of_stroke, 3 ok expected: $(cut -d, -f5 "$tmp/smap.csv" | sort | uniq -c)"
  grep -qF "unreachable 22" "$tmp/smap.txt" && ok || bad "map summary: $(cat "$tmp/smap.txt")"
  "$PRRU" --model "$E" map --q1 -0.2:0.2:5 --q2 -0.2:0.2:5 --q3 0.235 --out "$tmp/emap.csv" >/dev/null 2>&1 \
    && ! grep -q out_of_stroke "$tmp/emap.csv" && ok || bad "map without a stroke reports out_of_stroke"
  printf 'q0 = 0, 0, -0.2\nt_end = 0.5\ndt = 0.01\n' >"$tmp/fall.scn"
  expect 1 "the motion reached the workspace boundary at t = " \
    -- --model "$D" simulate --scenario "$tmp/fall.scn" --out "$tmp/fall.csv"
  grep -qF "is out_of_stroke: slider 1 at d = -0.05" "$tmp/err" && ok || bad "simulate: $(cat "$tmp/err")"
  [ "$(tail -n 1 "$tmp/fall.csv" | cut -d, -f1)" = 0.12 ] && ok || bad "simulate: samples up to the stroke end kept"
  # --units motor: tau = fd lead / (2 pi gear), i = tau / k_t (lead 0.02 m,
  # gear 1, k_t 0.11 N m/A). Tolerance: each side a few correctly rounded
  # operations on the same doubles (the CLI's fd / (2 pi gear / lead), the
  # check's fd lead / (2 pi gear), both from the printed 17 digits): 8 u.
  "$PRRU" --model "$D" traj --waypoints "0,0,0;0.1,0,0.02" --durations 1 --dt 0.01 --out "$tmp/mt.csv" 2>/dev/null \
    || bad "traj for --units motor"
  "$PRRU" --model "$D" id --traj "$tmp/mt.csv" --units motor --out "$tmp/mid.csv" 2>"$tmp/mid.err" \
    || bad "id --units motor: $(cat "$tmp/mid.err")"
  python3 - "$tmp/mid.csv" <<'PY' && ok || bad "id --units motor: tau or i columns wrong"
import csv, math, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith("#"))]
h = rows[0]
assert h == ["t", "fd1", "fd2", "fd3", "tau1", "tau2", "tau3", "i1", "i2", "i3"], h
tol = 8 * 2.0 ** -52
for r in rows[1:]:
    v = dict(zip(h, map(float, r)))
    for k in "123":
        tau = v["fd" + k] * 0.02 / (2 * math.pi * 1)
        assert abs(v["tau" + k] - tau) <= tol * abs(tau), (v, k)
        assert abs(v["i" + k] - tau / 0.11) <= tol * abs(tau / 0.11), (v, k)
PY
  model_edit "$D" "$tmp/nokt.json" "del d['actuators']['torque_constant']"
  "$PRRU" --model "$tmp/nokt.json" id --traj "$tmp/mt.csv" --units motor --out - 2>/dev/null | grep -v '^#' | head -n 1 \
    | grep -qx "t,fd1,fd2,fd3,tau1,tau2,tau3" && ok || bad "id --units motor without torque_constant: no current columns"
  rm -f "$tmp/x.csv"
  expect 2 "--units motor: model proto has no screw lead (actuators.lead" \
    -- --model "$E" id --traj "$tmp/mt.csv" --units motor --out "$tmp/x.csv"
  [ ! -e "$tmp/x.csv" ] && ok || bad "id --units motor without a lead wrote its output"
  expect 2 "--units 'amps': one of rail, motor" -- --model "$D" id --traj "$tmp/mt.csv" --units amps

  # The prototype workflow on a user's model with drive keys, loaded at run
  # time on this build (another geometry; no rebuild): excite, the true
  # robot 5 % heavier tracked, 1 um encoders, 0.2 N force noise at 500 Hz,
  # identify with the window measure suggests, then track the true robot
  # with the identified model. Computed torque's tracking error is linear
  # in the controller's model error, which falls from the 5 % mass
  # mismatch to the fit's noise level (0.2 N of about 50 N peak forces,
  # 0.4 %): about 12 times smaller; asked for: 5 times.
  L="$tmp/loop" && mkdir -p "$L"
  if "$PRRU" --model "$D" excite --evals 400 --period 8 --harmonics 4 --amplitude 0.2,0.2,0.02 --periods 2 \
       --dt 0.002 --out "$L/ex.csv" 2>"$L/err" &&
     "$PRRU" --model "$D" track --ref "$L/ex.csv" --mismatch mass=1.05 --out "$L/tr.csv" --summary "$L/tr.json" \
       2>>"$L/err" &&
     "$PRRU" --model "$D" measure --run "$L/tr.csv" --out "$L/meas.csv" --rate 500 --d-resolution 1e-6 \
       --force-noise 0.2 2>>"$L/err"; then
    win=$(sed -n 's/^# for identify: \(--window [0-9]* --degree [0-9]* --d-resolution [0-9.e+-]*\) .*/\1/p' "$L/meas.csv")
    # shellcheck disable=SC2086
    "$PRRU" --model "$D" identify --data "$L/meas.csv" $win --out "$L/id.json" --report "$L/rep.csv" 2>>"$L/err" &&
      "$PRRU" --model "$L/id.json" track --ref "$L/ex.csv" --plant "$D" --mismatch mass=1.05 --out "$L/tid.csv" \
        --summary "$L/tid.json" 2>>"$L/err" &&
      python3 - "$L/tr.json" "$L/tid.json" <<'PY' && ok || bad "prototype loop: identified tracking (above): $(tail -3 "$L/err")"
import json, sys
cad, ident = (max(json.load(open(f))["rms_error"]) for f in sys.argv[1:])
print("prototype loop without a rebuild: RMS tracking error %.3g with the CAD model, %.3g identified" % (cad, ident))
assert ident <= cad / 5, (cad, ident)
PY
  else
    bad "prototype loop: $(tail -3 "$L/err")"
  fi
fi

finish test_cli_model
