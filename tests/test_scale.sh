#!/usr/bin/env bash
# Tolerances relative to the robot's size: the build's model with its
# geometry (every kinematic length) multiplied by 1e-7 and by 1e5 is
# generated and its kernels linked with the build's runtime; at the same poses (q3 scaled
# too) J_d must be regular exactly where it is for the model itself, with
# the same condition numbers, and FK(IK(q)) must recover q. Before the
# tolerances were relative, the 1e-7 robot was "singular" everywhere and
# FK did not converge for the 1e5 one.
. "$(dirname "$0")/cli_lib.sh"
SRC=${PRRU_SOURCE_DIR:?}
MODEL=${PRRU_MODEL:?}

build() { # factor -> $tmp/scale_<factor>
  local s=$1 dir="$tmp/gen_$1"
  python3 - "$MODEL" "$s" "$tmp/model_$s.json" <<'PY' || return 1
import json, sys
from decimal import Decimal
m = json.load(open(sys.argv[1]), parse_float=Decimal)
s = Decimal(sys.argv[2])
scale = lambda v: [x * s for x in v] if isinstance(v, list) else v * s
m["geometry"] = {k: scale(v) for k, v in m["geometry"].items()}
json.dump(m, open(sys.argv[3], "w"), default=str)
PY
  # json.dump of Decimal as strings: turn them back into numbers.
  sed -i -E 's/"(-?[0-9.]+(E[-+]?[0-9]+)?)"/\1/g' "$tmp/model_$s.json"
  python3 "$SRC/gen/prru_gen.py" "$tmp/model_$s.json" --out "$dir" --prefix prru \
    --types prru_descriptor.h --derivatives --regressor --quiet || return 1
  # Only the model's own kernels are compiled: the build's runtime
  # (compiled against headers that differ from these in their comments
  # and operation counts alone, checked: constants that fold at one scale
  # and not at another change the counts, which nothing compiles against)
  # and its topology kernels come from its archives, whose model-kernel
  # member the objects given first leave unused (a clash would fail the
  # link, not pass silently).
  body() { sed "1,/\*\//d" "$1" | grep -v -E '^#define PRRU_(ARITH|OPS)_'; }
  for h in prru_kernels.h prru_mechanism.h prru_param_kernels.h prru_regressor.h prru_derivs.h; do
    diff <(body "$dir/$h") <(body "$BUILD/generated/$h") >/dev/null || {
      echo "scale $s: $h differs from the build's beyond its comment"; return 1; }
  done
  local objs=()
  for c in prru_kernels prru_mechanism prru_param_kernels prru_regressor prru_derivs; do
    # The build's generated/ after the model's own: prru_param_kernels.h
    # names the topology kernels (prru_p3_kernels.h), which no model's
    # generation writes.
    cc -I"$dir" -I"$BUILD/generated" -I"$SRC/runtime/include" -c "$dir/$c.c" -o "$dir/$c.o" || return 1
    objs+=("$dir/$c.o")
  done
  link "$tmp/scale_$s" "${objs[@]}"
}

BUILD=${PRRU_BUILD_DIR:?}
# The build's compiler and flags (a sanitizer build's archives need them).
cache() { sed -n "s/^$1:[A-Z]*=//p" "$BUILD/CMakeCache.txt" | head -n 1; }
CC_BUILD=$(cache CMAKE_C_COMPILER)
read -r -a C_FLAGS <<<"$(cache CMAKE_C_FLAGS)"
read -r -a LD_FLAGS <<<"$(cache CMAKE_EXE_LINKER_FLAGS)"
cc() { "$CC_BUILD" -std=c99 -O2 "${C_FLAGS[@]}" "$@"; }
scale_main_o="$tmp/scale_main.o"
cc -I"$BUILD/generated" -I"$SRC/runtime/include" -c "$SRC/tests/scale_main.c" -o "$scale_main_o" ||
  bad "scale_main.c does not compile"
link() { # out objects... : scale_main with the objects, then the build's archives
  local out=$1
  shift
  "$CC_BUILD" "${LD_FLAGS[@]}" "${C_FLAGS[@]}" "$scale_main_o" "$@" "$BUILD/runtime/libprru_runtime.a" \
    "$BUILD/libprru_kernels.a" -lgsl -lgslcblas -ljansson -lm -lpthread -o "$out"
}

# The model itself: the build's own kernels.
if link "$tmp/scale_1" && "$tmp/scale_1" 1 >"$tmp/out_1"; then ok; else bad "scale 1: build or FK(IK(q)) failed"; fi
for s in 1e-7 1e5; do
  if build "$s" && "$tmp/scale_$s" "$s" >"$tmp/out_$s"; then ok; else bad "scale $s: build or FK(IK(q)) failed"; fi
done
for s in 1e-7 1e5; do
  [ -f "$tmp/out_$s" ] || continue # its failure is reported above
  r=$(python3 - "$tmp/out_1" "$tmp/out_$s" <<'PY'
import sys
a = [l.split() for l in open(sys.argv[1])]
b = [l.split() for l in open(sys.argv[2])]
bad = [(x, y) for x, y in zip(a, b) if x[0] != y[0] or abs(float(x[1]) - float(y[1])) > 1e-9 * float(x[1])]
print("ok" if len(a) == len(b) == 81 and not bad else "%d of %d differ, e.g. %s" % (len(bad), len(a), bad[:2]))
PY
)
  [ "$r" = ok ] && ok || bad "lengths x $s: statuses or condition numbers differ from the model's: $r"
done
finish test_scale
