#!/usr/bin/env bash
# The paper's open question (its future work): does a fourth limb, mirroring
# limb 3 so that q2 is driven by two limbs, bring the rotational dynamic
# manipulability index w_R closer to 1?
#
# usage: studies/compare_designs.sh BUILD OUTDIR [--clip W]
#   BUILD: a build directory (any model: `make compare-designs` uses
#   build/); its prru evaluates both model files, models/3prru_paper.json
#   and models/4prru.json, with --model (the parameter kernels of each
#   file's topology, or the specialised ones for the build's own).
# Both models map w_R over the paper's fig. 7 rectangle (q1 in
# [-pi/6, pi/6], q2 in [-pi/4, pi/6], q3 = 0, 201 x 201) with the same
# practical singularity tolerance, and report w_R at q = 0. A grid point
# counts as regular only when J_d is regular there and the pose is in the
# home pose's assembly mode (prru map's status ok); singular, unreachable
# and other-assembly-mode points are left out of the index, reported as one
# share and drawn white. Writes
# OUTDIR/{3prru,4prru}_map.csv and _summary.txt, compare_wR.png (the two
# maps side by side on one viridis colour scale, clipped at --clip W or by
# default at the 99th percentile of both maps' w_R, as prru's own maps) and
# summary.txt.
set -euo pipefail
usage() { echo "usage: $0 BUILD OUTDIR [--clip W]" >&2; exit 2; }
[ $# -eq 2 ] || [ $# -eq 4 ] || usage
b=$1 out=$2 clip=
if [ $# -eq 4 ]; then
  [ "$3" = --clip ] || usage
  clip=$4
  python3 -c "import math, sys; v = float(sys.argv[1]); sys.exit(not (math.isfinite(v) and v > 1))" "$clip" 2>/dev/null ||
    { echo "$0: --clip '$clip': must be a number above 1" >&2; exit 2; }
fi
[ -x "$b/cli/prru" ] || { echo "$0: $b/cli/prru: not built" >&2; exit 2; }
mkdir -p "$out"
# From the source tree, so that outputs name the model files as
# models/NAME.json, wherever it is checked out.
b=$(cd "$b" && pwd) out=$(cd "$out" && pwd)
cd "$(dirname "$0")/.."
PI=3.141592653589793
Q1="-$(python3 -c "print(repr($PI/6))"):$(python3 -c "print(repr($PI/6))"):201"
Q2="-$(python3 -c "print(repr($PI/4))"):$(python3 -c "print(repr($PI/6))"):201"
RCOND=4e-3 # cond_1 > 250 of J_d with rotations in units of the upper link, as fig. 7

field() { grep "^$2:" "$1" | awk '{print $2}'; }
for n in 3 4; do
  model=models/3prru_paper.json; [ $n = 4 ] && model=models/4prru.json
  "$b/cli/prru" --model "$model" map --q1 "$Q1" --q2 "$Q2" --q3 0 --rcond-min "$RCOND" \
    --out "$out/${n}prru_map.csv" >"$out/${n}prru_summary.txt"
  "$b/cli/prru" --model "$model" dme --q 0,0,0 >"$out/${n}prru_dme0.json"
done
w0() { python3 -c "import json,sys; print('%.6f' % json.load(open(sys.argv[1]))['w_R'])" "$1"; }
w3=$(w0 "$out/3prru_dme0.json") w4=$(w0 "$out/4prru_dme0.json")
i3=$(field "$out/3prru_summary.txt" global_index) i4=$(field "$out/4prru_summary.txt" global_index)
s3=$(field "$out/3prru_summary.txt" singular_fraction) s4=$(field "$out/4prru_summary.txt" singular_fraction)
l3=$(field "$out/3prru_summary.txt" index_log) l4=$(field "$out/4prru_summary.txt" index_log)
{
  echo "Three vs four limbs: rotational dynamic manipulability w_R over the paper's"
  echo "fig. 7 rectangle (q1 in [-pi/6, pi/6], q2 in [-pi/4, pi/6], q3 = 0, 201 x 201),"
  echo "J_d singular where rcond < $RCOND (cond_1 > 250, rotations in units of l1);"
  echo "other assembly mode: regular, but cut off from the home pose by the singular locus."
  head -1 "$out/3prru_summary.txt" | sed 's/^model:/3 limbs, model:/'
  head -1 "$out/4prru_summary.txt" | sed 's/^model:/4 limbs, model:/'
  printf '%-34s %14s %14s\n' "" "3 limbs" "4 limbs"
  printf '%-34s %14s %14s\n' "w_R at q = 0" "$w3" "$w4"
  printf '%-34s %14.6f %14.6f\n' "global index (mean of w_R - 1)" "$i3" "$i4"
  printf '%-34s %14.6f %14.6f\n' "mean of ln w_R" "$l3" "$l4"
  printf '%-34s %13.3f%% %13.3f%%\n' "singular, unreachable, other mode" \
    "$(python3 -c "print(100*$s3)")" "$(python3 -c "print(100*$s4)")"
} >"$out/summary.txt"
cat "$out/summary.txt"

if command -v gnuplot >/dev/null 2>&1; then
  # The clip and its note (the colour key), the footer: from the maps.
  read -r CLIP CLIPNOTE <<<"$(python3 - "$out/3prru_map.csv" "$out/4prru_map.csv" "$clip" <<'PY'
import csv, sys
w = [float(r[3]) for f in sys.argv[1:3] for r in csv.reader(l for l in open(f) if l[:1] not in '#q') if r[4] == 'ok']
w.sort()
if sys.argv[3]:
    print(repr(float(sys.argv[3])), '(--clip)')
else:
    x = 0.99 * (len(w) - 1); i = int(x)
    c = w[i] + (x - i) * (w[min(i + 1, len(w) - 1)] - w[i])
    print(repr(max(c, 1.001)), '(the 99th percentile, --clip W sets it)')
print(end='')
PY
)"
  WMAX=$(python3 -c "import csv, sys; print(max(float(r[3]) for f in sys.argv[1:] for r in csv.reader(l for l in open(f) if l[:1] not in '#q') if r[4] == 'ok'))" "$out/3prru_map.csv" "$out/4prru_map.csv")
  FOOTER="studies/compare_designs.sh: $(head -1 "$out/3prru_map.csv" | sed -E 's/^# //; s/(sha256 [0-9a-f]{12})[0-9a-f]{52}/\1.../') vs $(head -1 "$out/4prru_map.csv" | sed -E 's/^# prru [^ ]+ //; s/(sha256 [0-9a-f]{12})[0-9a-f]{52}/\1.../')"
  # Text from files reaches gnuplot through the environment, never as code.
  (cd "$out" && CLIP="$CLIP" CLIPNOTE="$CLIPNOTE" WMAX="$WMAX" FOOTER="$FOOTER" gnuplot) <<'GP'
set datafile separator ','
set encoding utf8
set terminal pngcairo size 1400,640 enhanced font 'Sans,11'
set output 'compare_wR.png'
CLIP = real(system('printf %s "$CLIP"'))
WMAX = real(system('printf %s "$WMAX"'))
note = system('printf %s "$CLIPNOTE"')
footer = system('printf %s "$FOOTER"')
set label 1000 footer noenhanced at screen 0.005, screen 0.015 left font ',8' tc rgb '#505050' front
set multiplot layout 1,2 margins screen 0.06, 0.86, 0.12, 0.84 spacing screen 0.07, 0 title "w_R over the paper's fig. 7 rectangle, q_3 = 0 m: 3 limbs vs 4 limbs\nwhite: J_d singular (cond_1 > 250), unreachable or the other assembly mode; one colour scale"
set xlabel 'q_1 (rad)'
set ylabel 'q_2 (rad)'
set palette defined (0 '#440154', 0.125 '#472d7b', 0.25 '#3b528b', 0.375 '#2c728e', 0.5 '#21918c', 0.625 '#28ae80', 0.75 '#5ec962', 0.875 '#addc30', 1 '#fde725')
set cbrange [1:CLIP]
set cblabel (WMAX > CLIP ? sprintf("w_R (-), colours clipped at %.4g\n%s; max %.4g", CLIP, note, WMAX) : 'w_R (-)')
set xrange [-pi/6:pi/6]
set yrange [-pi/4:pi/6]
set size ratio -1
unset key
unset colorbox
ok(w) = (strcol(5) eq 'ok') ? (w > CLIP ? CLIP : w) : NaN
# image wants a blank line between scans (rows of constant q1)
scans(f) = sprintf("< awk -F, 'NR > 2 { if (NR > 3 && $1 != p) print \"\"; p = $1; print }' %s", f)
set title '3 limbs (the paper)'
plot scans('3prru_map.csv') using 1:2:(ok($4)) with image
unset label 1000
set colorbox user origin screen 0.8, screen 0.12 size screen 0.02, screen 0.72
set title '4 limbs (limb 4 mirrors limb 3)'
plot scans('4prru_map.csv') using 1:2:(ok($4)) with image
unset multiplot
GP
  echo "wrote $out/compare_wR.png"
else
  echo "gnuplot not found: compare_wR.png not drawn" >&2
fi
