#!/usr/bin/env bash
# Random valid models loaded at run time, no rebuild: PRRU_RANDOM_LOADED
# (default 20) seeded models of the build's number of limbs, and half as
# many of the other
# (tests/random_model.py, seeds PRRU_RANDOM_LOADED_BASE, default 2000, on)
# each pass test_model_load's checks on the parameter kernels: forward and
# inverse dynamics and the reactions against the GSL reference built from
# the loaded numbers, ID(FD) = the applied forces, and the work-energy
# balance; test_derivs's checks of the closed-form derivatives. Then one
# of them through the CLI (`prru --model`): eval at the
# home pose and a short simulate. Every seed is printed; a failing model is
# kept in $PRRU_RANDOM_KEEP (default random-models/ in the build directory)
# with the command that reproduces it. tests/random_models.sh builds a model
# into its own kernels instead (minutes per model).
. "$(dirname "$0")/cli_lib.sh"

n=${PRRU_RANDOM_LOADED:-20}
base=${PRRU_RANDOM_LOADED_BASE:-2000}
keep=${PRRU_RANDOM_KEEP:-$PRRU_BUILD_DIR/random-models}
check=$PRRU_BUILD_DIR/tests/test_model_load
limbs=$(python3 - "$PRRU_SOURCE_DIR" "$PRRU_MODEL" <<'PY'
import sys
sys.path.insert(0, sys.argv[1] + '/gen')
from prrugen import model
print(model.parse(open(sys.argv[2]).read(), sys.argv[2]).nlimb)
PY
) || { bad "the build's model $PRRU_MODEL does not parse"; finish test_random_loaded; }

# random_models COUNT BASE LIMBS: COUNT random models of LIMBS limbs from
# seed BASE on, their paths into the array models.
random_models() {
  models=()
  local k seed f
  for ((k = 0; k < $1; k++)); do
    seed=$(($2 + k))
    f="$tmp/rand_${3}_$seed.json"
    python3 "$PRRU_SOURCE_DIR/tests/random_model.py" --seed "$seed" --limbs "$3" --out "$f" >/dev/null ||
      bad "random_model.py --seed $seed --limbs $3"
    models+=("$f")
  done
  echo "random models: $1 of $3 limbs, seeds $2..$(($2 + $1 - 1))"
}

# check_models OUT WHAT FILE...: test_model_load on the files (output in
# $tmp/OUT); a failing file is kept in $keep with the command that
# reproduces it.
check_models() {
  local out=$tmp/$1 what=$2
  shift 2
  "$check" "$@" >"$out" 2>&1
  local st=$?
  cat "$out"
  if [ $st = 0 ]; then
    ok
  else
    mkdir -p "$keep"
    for f in $(sed -n 's/^FAILED: //p' "$out"); do
      cp "$f" "$keep/" && echo "kept $keep/$(basename "$f"); reproduce:" \
        "$check $keep/$(basename "$f")" >&2
    done
    bad "test_model_load on $what (seeds above; FAILED lines name the files)"
  fi
}

random_models "$n" "$base" "$limbs"
files=("${models[@]}")
check_models out "random models" "${files[@]}"

# The other topology on this build (no rebuild): half as many random
# models of the other number of limbs through test_model_load's checks
# (the reference evaluates either topology). test_derivs, below, sizes its
# checks by the build's model.
random_models $(((n + 1) / 2)) $((base + 1000)) $((7 - limbs))
check_models out_other "random models of the other topology" "${models[@]}"

# The closed-form derivatives (prru_linearize, the topology kernels) on
# the same models against the reference's Richardson differences.
"$PRRU_BUILD_DIR/tests/test_derivs" "${files[@]}" >"$tmp/derivs" 2>&1 && ok ||
  bad "test_derivs on random models: $(grep -E 'FAIL' "$tmp/derivs" | head -c 600)"

# The CLI on the first random model (`--model`, no rebuild): eval at the
# most regular home pose test_model_load found names the parameter kernels
# and the file's SHA-256, and simulate from there starts with eval's qdd
# (one model, two commands, the same numbers).
f=${files[0]}
home=$(sed -n "s|^home $f ||p" "$tmp/out")
if [ -z "$home" ]; then
  bad "test_model_load printed no home pose for $f"
else
  sha=$(sha256sum "$f" | cut -d' ' -f1)
  "$PRRU" --model "$f" eval --q "$home" >"$tmp/eval.json" 2>"$tmp/err" &&
    "$PRRU" simulate --model "$f" --q0 "$home" --t-end 0.01 --dt 0.005 --no-reactions --out "$tmp/sim.csv" 2>>"$tmp/err" &&
    python3 - "$tmp/eval.json" "$tmp/sim.csv" "$sha" <<'PY' && ok || bad "the CLI on $f (home $home): $(cat "$tmp/err")"
import csv, json, sys
e = json.load(open(sys.argv[1]))
lines = open(sys.argv[2]).read().splitlines()
assert 'parameter kernels' in lines[0] and sys.argv[3] in lines[0], lines[0]
assert e['model']['sha256'] == sys.argv[3], e['model']
rows = list(csv.DictReader(lines[1:]))
assert len(rows) == 3, len(rows)
for k in range(3):
    a, b = float(rows[0]['qdd%d' % (k + 1)]), e['qdd'][k]
    assert a == b, ('qdd%d' % (k + 1), a, b)
PY
fi
finish test_random_loaded
