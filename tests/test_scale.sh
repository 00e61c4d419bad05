#!/usr/bin/env bash
# Tolerances relative to the robot's size: the build's model with its
# geometry (every kinematic length) multiplied by 1e-7 and by 1e5 is
# generated and compiled with the runtime; at the same poses (q3 scaled
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
  python3 "$SRC/gen/prru_gen.py" "$tmp/model_$s.json" --out "$dir" --prefix prru --quiet || return 1
  # The topology kernels (any model's numbers at run time) are the
  # committed ones of every build; $dir comes first for the model's own.
  gcc -std=c99 -O2 -I"$dir" -I"$SRC/runtime/include" -I"$SRC/runtime/src" -I"$SRC/generated" \
    "$SRC/tests/scale_main.c" "$SRC"/runtime/src/*.c "$dir/prru_kernels.c" "$dir/prru_mechanism.c" \
    "$dir/prru_param_kernels.c" "$dir/prru_regressor.c" \
    "$SRC/generated/prru_p3_kernels.c" "$SRC/generated/prru_p4_kernels.c" \
    -lgsl -lgslcblas -ljansson -lm -lpthread -o "$tmp/scale_$s"
}

for s in 1 1e-7 1e5; do
  if build "$s" && "$tmp/scale_$s" "$s" >"$tmp/out_$s"; then ok; else bad "scale $s: build or FK(IK(q)) failed"; fi
done
for s in 1e-7 1e5; do
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
