#!/usr/bin/env bash
# End to end, for any model: prru optimize writes a model file; the kernels
# regenerated from it (a separate CMake build of prru with -DPRRU_MODEL=
# that file, ~40 s) map the same rectangle to the global index the
# optimiser reported, to 1e-12, point for point, with no singular or
# unreachable point. This is the independent re-evaluation: the optimiser
# evaluated the design through the runtime-parameter kernels, the new build
# through constant kernels generated from the written numbers.
. "$(dirname "$0")/cli_lib.sh"

Q1="-0.3:0.3:21" Q2="-0.35:0.25:19" RC=4e-3
"$PRRU" optimize --vars b12,b3,l1,l2,a --range 10 --q1 "$Q1" --q2 "$Q2" --rcond-min $RC --max-iter 80 \
  --out "$tmp/opt.json" --report "$tmp/rep" >"$tmp/opt.out" 2>"$tmp/opt.err" \
  || bad "optimize failed: $(head -c 400 "$tmp/opt.err")"
after=$(sed -n 's/^after_index: //p' "$tmp/rep/report.txt")
before=$(sed -n 's/^before_index: //p' "$tmp/rep/report.txt")
below "$after" "$before" "the optimised index is lower than the start's"

# The regenerated build (only the prru target; no tests, bench, validation).
if cmake -S "$PRRU_SOURCE_DIR" -B "$tmp/build" -DCMAKE_BUILD_TYPE=Release -DPRRU_BUILD_TESTS=OFF \
     -DPRRU_MODEL="$tmp/opt.json" >"$tmp/cmake.log" 2>&1 &&
   cmake --build "$tmp/build" --target prru -j 2 >>"$tmp/cmake.log" 2>&1; then
  ok
else
  bad "building prru from the optimised model failed: $(tail -c 600 "$tmp/cmake.log")"
fi
new="$tmp/build/cli/prru"
"$new" --version | grep -q "^model: ${model_name:0:12}_opt$" && ok \
  || bad "the new build is not the optimised model: $("$new" --version | head -3)"
"$new" map --q1 "$Q1" --q2 "$Q2" --rcond-min $RC --out "$tmp/map.csv" >"$tmp/map.out" \
  || bad "map on the new build failed"
python3 - "$tmp/map.csv" "$tmp/rep/after_map.csv" "$after" "$tmp/map.out" <<'PY' && ok || bad "regenerated map differs from the optimiser's after design"
import sys
def rows(path):
    r = [l.rstrip('\n').split(',') for l in open(path) if not l.startswith('#')]
    return r[1:]
new, opt, after = rows(sys.argv[1]), rows(sys.argv[2]), float(sys.argv[3])
err = []
if len(new) != len(opt):
    err.append('row counts %d vs %d' % (len(new), len(opt)))
if any(r[4] != 'ok' for r in new):
    err.append('%d grid points not ok' % sum(r[4] != 'ok' for r in new))
worst = max(abs(float(a[3]) - float(b[3])) / float(b[3]) for a, b in zip(new, opt))
if not worst <= 1e-12:
    err.append('w_R per point differs by %.3g' % worst)
s = 0.0
for r in new:
    s += float(r[3]) - 1.0
index = s / len(new)
if not abs(index - after) <= 1e-12 * after:
    err.append('index %.17g vs reported %.17g' % (index, after))
printed = [l for l in open(sys.argv[4]) if l.startswith('global_index:')]
if not printed or abs(float(printed[0].split()[1]) - after) > 1e-9 * after:
    err.append('printed %s' % printed)
print('regenerated: index %.17g, optimiser %.17g, worst w_R %.3g' % (index, after, worst))
if err:
    print('; '.join(err), file=sys.stderr)
sys.exit(1 if err else 0)
PY

echo "test_design_regen: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
