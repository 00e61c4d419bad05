#!/usr/bin/env bash
# The paper's purpose for w_R (section 5): optimise the geometry so that the
# w_R surface drops toward 1 over the workspace. Over fig. 7's rectangle
# (q1 in [-pi/6, pi/6], q2 in [-pi/4, pi/6], q3 = 0, 201 x 201, J_d regular
# where cond_1 <= 250 at every grid point), each length within +-20 % of
# the paper's Table 1:
#   paper5  the paper's five lengths b12, b3, l1, l2, a (every limb's l2 tied);
#   stroke  the same with the sliders kept within the paper's own travel;
#   limb3   the same with limb 3's lower link free of limbs 1 and 2's
#           (l2_12, l2_3), which the sensitivities at paper5 point to.
# Each written model is re-evaluated independently: the kernels are
# regenerated from it (a separate build) and that build's `prru map` must
# give the optimiser's index and no singular point. Also the sensitivity of
# the index to every parameter, at the paper's design and at paper5's.
#   studies/optimize_paper.sh BUILD OUTDIR      (BUILD: the paper model's build)
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 BUILD OUTDIR" >&2; exit 2; }
build=$1 out=$2
prru="$build/cli/prru"
[ -x "$prru" ] || { echo "$0: $prru: not built" >&2; exit 2; }
src=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
PI=3.141592653589793
Q1="$(python3 -c "print(repr(-$PI/6))"):$(python3 -c "print(repr($PI/6))"):201"
Q2="$(python3 -c "print(repr(-$PI/4))"):$(python3 -c "print(repr($PI/6))"):201"
RCOND=4e-3
GRID=(--q1 "$Q1" --q2 "$Q2" --rcond-min $RCOND)

run_case() { # NAME VARS [OPTIONS...]
  local name=$1 vars=$2; shift 2
  local dir="$out/$name"
  rm -rf "$dir"; mkdir -p "$dir"
  echo "== $name: optimising $vars (+-20 %) $*"
  "$prru" optimize --vars "$vars" --range 20 "${GRID[@]}" "$@" --name "prru_$name" \
    --out "$dir/prru_$name.json" --report "$dir/report" >"$dir/optimize.txt"
  cat "$dir/optimize.txt"
  echo "== $name: regenerating the kernels from $dir/prru_$name.json (separate build)"
  cmake -S "$src" -B "$dir/build" -DCMAKE_BUILD_TYPE=Release -DPRRU_BUILD_TESTS=OFF \
    -DPRRU_MODEL="$dir/prru_$name.json" >"$dir/build.log"
  cmake --build "$dir/build" --target prru -j 2 >>"$dir/build.log"
  "$dir/build/cli/prru" map "${GRID[@]}" --out "$dir/map.csv" >"$dir/map.txt"
  local after
  after=$(sed -n 's/^after_index: //p' "$dir/report/report.txt")
  python3 - "$dir/map.csv" "$after" <<'PY' | tee "$dir/reevaluation.txt"
import sys
rows = [l.split(',') for l in open(sys.argv[1]) if not l.startswith('#')][1:]
bad = sum(r[4].strip() != 'ok' for r in rows)
s = 0.0
for r in rows:
    if r[4].strip() == 'ok':
        s += float(r[3]) - 1.0
index = s / (len(rows) - bad)
after = float(sys.argv[2])
print('re-evaluated from the regenerated kernels: global index %.12f, optimiser %.12f, '
      'relative difference %.2g, %d of %d grid points not regular' %
      (index, after, abs(index - after) / after, bad, len(rows)))
sys.exit(0 if abs(index - after) <= 1e-12 * after and bad == 0 else 1)
PY
}

run_case paper5 b12,b3,l1,l2,a
travel=$(sed -n 's/^slider heights d (m) *\([0-9.]*\)\.\.\([0-9.]*\) .*/\1:\2/p' "$out/paper5/report/report.txt")
run_case stroke b12,b3,l1,l2,a --stroke "$travel"
run_case limb3 b12,b3,l1,l2_12,l2_3,a

echo "== sensitivity of the global index: the paper's design and paper5's"
"$prru" sensitivity "${GRID[@]}" --out "$out/sensitivity_paper.csv" --plot "$out/sensitivity_paper.png" \
  >"$out/sensitivity_paper.txt"
"$out/paper5/build/cli/prru" sensitivity "${GRID[@]}" --out "$out/sensitivity_paper5.csv" \
  --plot "$out/sensitivity_paper5.png" >"$out/sensitivity_paper5.txt"
head -10 "$out/sensitivity_paper5.txt"

field() { sed -n "s/^$2: //p" "$out/$1/report/report.txt"; }
# The variables of a case: the rows of its report's variable table.
variables() { awk '/^variable /{f=1; next} f && NF == 0 {exit} f {printf "%s%s", s, $1; s=","}' \
  "$out/$1/report/report.txt"; }
{
  echo "Optimising the paper's geometry for w_R over fig. 7's rectangle (201 x 201, q3 = 0,"
  echo "every point regular: cond_1 <= 250), each length within +-20 % of Table 1."
  printf '%-7s %-26s %13s %13s %9s  %s\n' case variables "index before" "index after" "max w_R" \
    "re-evaluated from regenerated kernels"
  for c in paper5 stroke limb3; do
    printf '%-7s %-26s %13.6f %13.6f %9.4f  %s\n' $c "$(variables $c)" "$(field $c before_index)" \
      "$(field $c after_index)" "$(field $c after_max_w_R)" \
      "$(sed 's/.*relative difference \([^,]*\), \(.*\)/\1 apart, \2/' "$out/$c/reevaluation.txt")"
  done
  echo "stroke: the sliders kept within $travel m, the paper's travel over the rectangle"
} | tee "$out/summary.txt"
echo "wrote $out/ (*/report/optimize_maps.png, sensitivity_*.png, summary.txt)"
