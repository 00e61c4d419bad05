#!/usr/bin/env bash
# prru plot and prru animate: pictures of the CSVs prru writes, recognised
# by their headers; bad files are exit 2 with the line and the reason, and
# leave no output behind.
. "$(dirname "$0")/cli_lib.sh"

# png_size FILE: "WIDTH HEIGHT" from the IHDR chunk, or "not a PNG".
png_size() {
  python3 - "$1" <<'PY'
import struct, sys
b = open(sys.argv[1], 'rb').read(24)
print('%d %d' % struct.unpack('>II', b[16:24]) if b[:8] == b'\x89PNG\r\n\x1a\n' and b[12:16] == b'IHDR' else 'not a PNG')
PY
}
# gif_frames FILE: the number of images of a GIF and whether the first and
# the last differ ("N differ" / "N same"), or "not a GIF".
gif_frames() {
  python3 - "$1" <<'PY'
import struct, sys
b = open(sys.argv[1], 'rb').read()
if b[:6] != b'GIF89a': print('not a GIF'); sys.exit()
flags = b[10]; p = 13 + (3 * (2 << (flags & 7)) if flags & 0x80 else 0)
images = []
while p < len(b) and b[p] != 0x3B:
    t = b[p]; p += 1
    if t == 0x21:
        p += 1
        while b[p]: p += 1 + b[p]
        p += 1
    elif t == 0x2C:
        fl = b[p + 8]; p += 9
        if fl & 0x80: p += 3 * (2 << (fl & 7))
        p += 1; start = p
        while b[p]: p += 1 + b[p]
        p += 1
        images.append(b[start:p])
    else: print('bad block'); sys.exit()
print(len(images), 'differ' if images[0] != images[-1] else 'same')
PY
}

if ! command -v gnuplot >/dev/null; then
  echo "test_cli_plot: gnuplot not installed, pictures not checked"
  expect 1 "gnuplot not found" -- plot "$PRRU_SOURCE_DIR/tests/test_cli_plot.sh"
  finish test_cli_plot
  exit
fi

"$PRRU" simulate --scenario paper --t-end 0.2 --dt 0.01 --out "$tmp/run.csv" || bad "simulate failed"
"$PRRU" map --q1 -pi/6:pi/6:41 --q2 -pi/4:pi/6:31 --out "$tmp/map.csv" >/dev/null || bad "map failed"

# ---- plot: the natural figure by the header ----
"$PRRU" plot "$tmp/run.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/run.png")" = "1000 1000" ] && [ ! -s "$tmp/err" ] \
  && ok || bad "plot of a simulation CSV: $(png_size "$tmp/run.png") $(head -c 300 "$tmp/err")"
"$PRRU" plot "$tmp/map.csv" --out "$tmp/m.png" 2>"$tmp/err" && [ "$(png_size "$tmp/m.png")" = "1000 850" ] \
  && ok || bad "plot of a map CSV: $(png_size "$tmp/m.png") $(head -c 300 "$tmp/err")"
[ ! -e "$tmp/map.png" ] && ok || bad "plot --out also wrote the default name"
"$PRRU" plot "$tmp/map.csv" --out - >"$tmp/dash.png" && [ "$(png_size "$tmp/dash.png")" = "1000 850" ] \
  && ok || bad "plot --out -: no PNG on stdout"
"$PRRU" plot "$tmp/run.csv" --out - >/dev/full 2>"$tmp/err"
[ $? -eq 1 ] && grep -q "stdout: write error" "$tmp/err" && ok || bad "plot --out - >/dev/full: $(head -c 200 "$tmp/err")"
# A map of the 4-limb kind (no singular point) and one with only one status.
awk -F, 'BEGIN { OFS = "," } /^#/ || NR == 2 { print; next } { if ($5 != "ok") { $4 = 1.5; $5 = "ok" } print }' \
  "$tmp/map.csv" >"$tmp/allok.csv"
"$PRRU" plot "$tmp/allok.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/allok.png")" = "1000 850" ] && [ ! -s "$tmp/err" ] \
  && ok || bad "plot of an all-ok map: $(head -c 300 "$tmp/err")"

# ---- plot: bad files, exit 2 with the reason, no picture ----
bad_file() { # NAME CONTENT NEEDLE
  printf '%b' "$2" >"$tmp/$1.csv"
  expect 2 "$3" -- plot "$tmp/$1.csv"
  [ ! -e "$tmp/$1.png" ] && ok || bad "plot of the bad $1.csv left $1.png"
}
bad_file empty "" "empty.csv: no header line (empty)"
bad_file comments "# prru\n# more\n" "comments.csv: no header line (only comments)"
bad_file other "# x\na,b\n1,2\n" "$tmp/other.csv:2: not a CSV of prru simulate"
bad_file maprow "q1,q2,q3,w_R,status\n0,0,0,1.5,ok\n0,1,0,x,ok\n" "$tmp/maprow.csv:3: expected q1,q2,q3,w_R,status"
bad_file mapnan "q1,q2,q3,w_R,status\n0,0,0,NaN,ok\n" "$tmp/mapnan.csv:2:"
bad_file mapstatus "q1,q2,q3,w_R,status\n0,0,0,NaN,broken\n" "$tmp/mapstatus.csv:2:"
bad_file mapgrid "q1,q2,q3,w_R,status\n0,0,0,1.5,ok\n0,1,0,1.5,ok\n1,0,0,1.5,ok\n1,2,0,1.5,ok\n" "q2 values differ"
bad_file mapshort "q1,q2,q3,w_R,status\n0,0,0,1.5,ok\n0,1,0,1.5,ok\n1,0,0,1.5,ok\n" "the last q1 block is short"
bad_file mapq3 "q1,q2,q3,w_R,status\n0,0,0,1.5,ok\n0,1,0.1,1.5,ok\n" "q3 differs"
bad_file mapone "q1,q2,q3,w_R,status\n0,0,0,1.5,ok\n0,1,0,1.5,ok\n" "not a complete grid"
bad_file simshort "t,q1,q2,q3,qd1,qd2,qd3,d1,d2,d3\n0,0,0,-0.8,0,0,0,-0.6,-0.6,-0.6\n1,0,0\n" "simshort.csv:3"
bad_file simone "t,q1,q2,q3,qd1,qd2,qd3,d1,d2,d3\n0,0,0,-0.8,0,0,0,-0.6,-0.6,-0.6\n" "fewer than 2 rows"
expect 2 "cannot open: No such file or directory" -- plot "$tmp/none.csv"
expect 2 "a CSV file is required" -- plot
expect 2 "unexpected argument" -- plot "$tmp/run.csv" "$tmp/map.csv"
expect 2 "that is the input file" -- plot "$tmp/run.csv" --out "$tmp/run.csv"
# An existing picture is replaced only by a complete new one.
echo "old" >"$tmp/keep.png"
cp "$tmp/maprow.csv" "$tmp/keep.csv"
expect 2 "keep.csv:3" -- plot "$tmp/keep.csv"
[ "$(cat "$tmp/keep.png")" = old ] && ok || bad "a failed plot changed the old picture"
# Without gnuplot: exit 1 and the package to install.
PATH=/nonexistent "$PRRU" plot "$tmp/run.csv" --out "$tmp/ng.png" 2>"$tmp/err"
[ $? -eq 1 ] && grep -q "gnuplot not found: install gnuplot-nox" "$tmp/err" && [ ! -e "$tmp/ng.png" ] \
  && ok || bad "plot without gnuplot: $(head -c 200 "$tmp/err")"

# ---- plot: the CSVs of track, traj, excite and id ----
WP='0,0,-0.8;0.1,0.05,-0.78'
"$PRRU" traj --waypoints "$WP" --durations 0.3 --dt 0.005 --out "$tmp/traj.csv" || bad "traj failed"
# A force limit the run reaches on any model, so that the track CSV holds
# it (sat = 1 rows): half the largest force the motion needs (prru id),
# to two digits (the paper's model: 40 N).
"$PRRU" id --traj "$tmp/traj.csv" --out "$tmp/id_fmax.csv" || bad "id failed"
FMAX=$(python3 -c '
import csv, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith("#"))]
cols = [i for i, n in enumerate(rows[0]) if n.startswith("fd")]
peak = max(abs(float(r[i])) for r in rows[1:] for i in cols)
print("%.17g" % float("%.2g" % (0.5 * peak)))' "$tmp/id_fmax.csv")
"$PRRU" track --ref "$tmp/traj.csv" --dt 0.005 --fmax "$FMAX" --q0-offset 0.01,0,0 --out "$tmp/track.csv" \
  --summary "$tmp/track.json" || bad "track failed"
"$PRRU" id --traj "$tmp/traj.csv" --out "$tmp/id.csv" || bad "id failed"
"$PRRU" excite --period 1 --harmonics 1 --evals 20 --samples 50 --dt 0.01 --out "$tmp/excite.csv" 2>/dev/null \
  || bad "excite failed"
# Each by its header, at its own size (track 2 panels, traj and excite 4,
# id 1), with nothing said on stderr.
for c in "track 1000 1300" "traj 1000 1000" "excite 1000 1000" "id 1000 600"; do
  set -- $c
  "$PRRU" plot "$tmp/$1.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/$1.png")" = "$2 $3" ] && [ ! -s "$tmp/err" ] \
    && ok || bad "plot of a $1 CSV: $(png_size "$tmp/$1.png") $(head -c 300 "$tmp/err")"
done
# A time-optimal trajectory: the slider velocities and the forces with
# their limits, read from its '# limits:' line (the gnuplot script kept).
# Limits any model meets: twice the largest force the quintic needs (so
# the path is feasible), half its largest slider speed (so that limit acts).
LIMS=$(python3 -c '
import csv, sys
def peak(f, p):
    rows = [r for r in csv.reader(l for l in open(f) if not l.startswith("#"))]
    cols = [i for i, n in enumerate(rows[0]) if n.startswith(p) and n[len(p):].isdigit()]
    return max(abs(float(r[i])) for r in rows[1:] for i in cols)
print("--force-max %.6g --speed-max %.6g" % (2 * peak(sys.argv[1], "fd"), 0.5 * peak(sys.argv[2], "dd")))' \
  "$tmp/id_fmax.csv" "$tmp/traj.csv")
# shellcheck disable=SC2086
"$PRRU" traj --time-optimal --waypoints "$WP" $LIMS --out "$tmp/topp.csv" 2>"$tmp/err" \
  || bad "traj --time-optimal $LIMS: $(cat "$tmp/err")"
rm -f "$tmp"/gp.*
mkdir -p "$tmp/keepbin0"
printf '#!/bin/sh\ncp "$1" "%s/topp.gp"\nexec "%s" "$@"\n' "$tmp" "$(command -v gnuplot)" >"$tmp/keepbin0/gnuplot"
chmod +x "$tmp/keepbin0/gnuplot"
PATH="$tmp/keepbin0:$PATH" "$PRRU" plot "$tmp/topp.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/topp.png")" = "1000 1000" ] \
  && [ ! -s "$tmp/err" ] && grep -q "title sprintf('limit .*%.4g m/s', " "$tmp/topp.gp" \
  && grep -q "title sprintf('limit .*%.4g N', " "$tmp/topp.gp" && grep -q "Time-optimal trajectory" "$tmp/topp.gp" \
  && ok || bad "plot of a time-optimal trajectory: $(png_size "$tmp/topp.png") $(head -c 300 "$tmp/err")"
# identify's report (its format, rows written here): one tick per base
# parameter, 1000 x 650 for a few.
{ echo "# prru $prru_version model prru (x.json, sha256 $(printf '0%.0s' $(seq 64)), parameter kernels)"
  echo "index,parameter,estimate,se,prior,resolution,model,t,combination"
  echo "1,P.m,1.86,0.01,1.77,0.5,1.859,-0.1,P.m + 1 L1.m - 0.25 S1.m"
  echo "2,armature1,0.001,0.002,0,0.01,0.0009,-0.05,armature1"; } >"$tmp/ident.csv"
"$PRRU" plot "$tmp/ident.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/ident.png")" = "1000 650" ] && [ ! -s "$tmp/err" ] \
  && ok || bad "plot of an identify report: $(png_size "$tmp/ident.png") $(head -c 300 "$tmp/err")"
h_ident="index,parameter,estimate,se,prior,resolution,model,t,combination"
bad_file identskip "$h_ident\n1,P.m,1,0.1,1,1,1,0,P.m\n3,L1.m,1,0.1,1,1,1,0,L1.m\n" "identskip.csv:3: the index is not the row's number"
bad_file identnan "$h_ident\n1,P.m,nan,0.1,1,1,1,0,P.m\n" "identnan.csv:2: estimate, se, prior, resolution, model and t must be finite"
bad_file identname "$h_ident\n1,P m;x,1,0.1,1,1,1,0,P.m\n" "identname.csv:2: the parameter name is not a name"
bad_file identnone "# x\n$h_ident\n" "identnone.csv: no base parameters"
# track --plot still makes its figure, the size of prru plot's.
"$PRRU" track --ref "$tmp/traj.csv" --dt 0.005 --fmax "$FMAX" --q0-offset 0.01,0,0 --out "$tmp/track2.csv" \
  --summary "$tmp/track2.json" --plot "$tmp/track2.png" 2>"$tmp/err" \
  && [ "$(png_size "$tmp/track2.png")" = "1000 1300" ] && cmp -s "$tmp/track.csv" "$tmp/track2.csv" \
  && ok || bad "track --plot: $(png_size "$tmp/track2.png") $(head -c 300 "$tmp/err")"
# Titles keep quotes whatever their neighbours: the track CSV's settings
# line says mismatch '' (gnuplot misreads doubled quotes side by side).
grep -q "mismatch ''" "$tmp/track.csv" && ok || bad "the track CSV no longer says mismatch '' (test input changed)"
sed "1s/\$/ it's '''' quoted/" "$tmp/traj.csv" >"$tmp/quotes.csv"
"$PRRU" plot "$tmp/quotes.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/quotes.png")" = "1000 1000" ] \
  && ok || bad "plot of a CSV with quotes in its comments: $(head -c 300 "$tmp/err")"
# A footer made of long comment lines breaks into lines of about 150
# characters instead of running off the image: the script gnuplot gets
# (caught by a gnuplot on PATH that keeps a copy) has its footer in parts.
mkdir -p "$tmp/fakebin"
real_gnuplot=$(command -v gnuplot)
printf '#!/bin/sh\ncp "$1" "%s/script.gp"\nexec "%s" "$@"\n' "$tmp" "$real_gnuplot" >"$tmp/fakebin/gnuplot"
chmod +x "$tmp/fakebin/gnuplot"
long=$(printf 'word%.0s ' $(seq 1 60))
sed "1s/\$/ $long/" "$tmp/traj.csv" >"$tmp/long.csv"
PATH="$tmp/fakebin:$PATH" "$PRRU" plot "$tmp/long.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/long.png")" = "1000 1000" ] \
  && python3 - "$tmp/script.gp" <<'PY' && ok || bad "long title: $(head -c 300 "$tmp/err")"
import re, sys
sub = [l for l in open(sys.argv[1]) if l.startswith("footer = ")][0]
parts = sub[len("footer = "):].strip().split("'.\"\\n\".'")
assert len(parts) >= 2 and max(len(p) for p in parts) <= 170, [len(p) for p in parts]
PY
# gnuplot's work is checked, not only its exit status: a gnuplot that
# fails, or one that exits 0 with its pictures cut short (as on a full
# disk, where gnuplot 5.4 still exits 0) or empty, is exit 1 and leaves
# the previous picture as it was, for every command that draws.
fake_gnuplot() { # NAME SHELL-LINES-AFTER-THE-REAL-GNUPLOT
  mkdir -p "$tmp/$1"
  printf '#!/bin/sh\n"%s" "$@" || exit $?\n%s\n' "$real_gnuplot" "$2" >"$tmp/$1/gnuplot"
  chmod +x "$tmp/$1/gnuplot"
}
fake_gnuplot failbin 'exit 1'
fake_gnuplot cutbin 'for f in *.png *.gif; do [ -f "$f" ] && truncate -s 300 "$f"; done; exit 0'
fake_gnuplot emptybin 'for f in *.png *.gif; do [ -f "$f" ] && : >"$f"; done; exit 0'
keep_check() { # BIN WHAT NEEDLE FILE ARGS...: exit 1, the message, FILE as it was
  local bin=$1 what=$2 needle=$3 file=$4; shift 4
  echo "old picture" >"$file"
  PATH="$tmp/$bin:$PATH" "$PRRU" "$@" >/dev/null 2>"$tmp/err"
  local st=$?
  [ $st -eq 1 ] && grep -qF -- "$needle" "$tmp/err" && [ "$(cat "$file")" = "old picture" ] \
    && ok || bad "$what with $bin: exit $st, $(head -c 300 "$tmp/err")"
}
keep_check failbin "plot" "gnuplot failed" "$tmp/k.png" plot "$tmp/run.csv" --out "$tmp/k.png"
for b in cutbin emptybin; do
  keep_check $b "plot of a simulation" "plot.png: gnuplot exited 0 but the file is not complete" \
    "$tmp/k.png" plot "$tmp/run.csv" --out "$tmp/k.png"
  keep_check $b "plot of a map" "not complete" "$tmp/k.png" plot "$tmp/map.csv" --out "$tmp/k.png"
  keep_check $b "animate" "anim.gif: gnuplot exited 0 but the file is not complete" "$tmp/k.gif" \
    animate "$tmp/run.csv" --frames 3 --out "$tmp/k.gif"
  keep_check $b "track --plot" "not complete" "$tmp/k.png" track --ref "$tmp/traj.csv" --dt 0.005 \
    --out "$tmp/k.csv" --plot "$tmp/k.png"
done
keep_check cutbin "animate" "a GIF cut short (no trailer 0x3B" "$tmp/k.gif" animate "$tmp/run.csv" --frames 3 --out "$tmp/k.gif"
keep_check cutbin "plot" "a PNG cut short (no IEND chunk" "$tmp/k.png" plot "$tmp/run.csv" --out "$tmp/k.png"
# prru paper: a figure cut short is exit 1 and DIR is not changed.
mkdir -p "$tmp/pd"
echo "old picture" >"$tmp/pd/fig_q.png"
PATH="$tmp/cutbin:$PATH" "$PRRU" paper --out "$tmp/pd" --skip-map >/dev/null 2>"$tmp/err"
st=$?
[ $st -eq 1 ] && grep -q "pd/fig_q.png: gnuplot exited 0 but the file is not complete" "$tmp/err" \
  && [ "$(cat "$tmp/pd/fig_q.png")" = "old picture" ] && [ "$(ls "$tmp/pd")" = fig_q.png ] \
  && ok || bad "paper with pictures cut short: exit $st, $(ls "$tmp/pd") $(head -c 300 "$tmp/err")"

# Text from users lands in gnuplot scripts escaped: a file name keeps every
# byte (quotes, backslashes, a newline, $), and a title from comment lines
# shows every character as itself in enhanced text (gnuplot's dumb
# terminal draws the script's own title string as the PNG would).
hostile="$tmp/it's a \"b\\101\"
\$HOME \`x\`.csv"
cp "$tmp/traj.csv" "$hostile"
PATH="$tmp/fakebin:$PATH" "$PRRU" plot "$hostile" --out "$tmp/hostile.png" 2>"$tmp/err" \
  && [ "$(png_size "$tmp/hostile.png")" = "1000 1000" ] && ok || bad "plot of a hostile file name: $(head -c 300 "$tmp/err")"
printf '%s\n' "$(grep '^f = ' "$tmp/script.gp")" 'set print "-"' 'print f' >"$tmp/name.gp"
[ "$("$real_gnuplot" "$tmp/name.gp" 2>&1)" = "$(realpath "$hostile")" ] && ok \
  || bad "the file name in the script is not the file's: $(head -c 300 "$tmp/name.gp")"
title='it'"'"'s "q" a\101 b\\c x_1 y^2 {z} @w &v ~u %s end'
{ echo "# $title"; grep -v '^#' "$tmp/traj.csv"; } >"$tmp/title.csv"
PATH="$tmp/fakebin:$PATH" "$PRRU" plot "$tmp/title.csv" 2>"$tmp/err" && [ "$(png_size "$tmp/title.png")" = "1000 1000" ] \
  && ok || bad "plot of a hostile title: $(head -c 300 "$tmp/err")"
# (w is set first: gnuplot's macro expansion must not see @w outside a string.)
printf '%s\n' "w = 'MACRO'" "$(grep '^footer = ' "$tmp/script.gp")" 'set term dumb enhanced size 200,5' 'set title footer' \
  'unset border; unset tics' 'plot [0:1][0:1] NaN notitle' >"$tmp/title.gp"
"$real_gnuplot" "$tmp/title.gp" 2>&1 | grep -qF -- "$title" && ok \
  || bad "the title is not drawn as written: $("$real_gnuplot" "$tmp/title.gp" 2>&1 | grep -v '^ *$' | head -c 300)"
# Bad files of these kinds: exit 2 naming the file and the reason.
h_track=$(grep -m1 '^t,' "$tmp/track.csv") h_traj=$(grep -m1 '^t,' "$tmp/traj.csv")
h_id=$(grep -m1 '^t,' "$tmp/id.csv") h_excite=$(grep -m1 '^t,' "$tmp/excite.csv")
row_traj=$(grep -m1 '^0,' "$tmp/traj.csv")
bad_file trackone "$h_track\n$(grep -m1 '^0,' "$tmp/track.csv")\n" "a tracking CSV with fewer than 2 rows"
# The track CSV without its sat columns: the limits cannot be told.
awk -F, 'BEGIN { OFS = "," } /^#/ { print; next }
  /^t,/ { for (i = 1; i <= NF; i++) drop[i] = $i ~ /^sat/ }
  { s = ""; for (i = 1; i <= NF; i++) if (!drop[i]) s = s (s == "" ? "" : ",") $i; print s }' \
  "$tmp/track.csv" >"$tmp/tracknosat.csv"
expect 2 "tracknosat.csv: a tracking CSV with $nact sliders needs the columns sat1..sat$nact" -- plot "$tmp/tracknosat.csv"
[ ! -e "$tmp/tracknosat.png" ] && ok || bad "plot of the bad tracknosat.csv left tracknosat.png"
bad_file trajshort "$h_traj\n$row_traj\n1,0,0\n" "trajshort.csv:3"
bad_file trajword "$h_traj\n$row_traj\n$(echo "$row_traj" | sed 's/^0,0,/0.1,x,/')\n" "trajword.csv:3"
bad_file idone "$h_id\n$(grep -m1 '^0,' "$tmp/id.csv")\n" "an inverse dynamics CSV with fewer than 2 rows"
bad_file exciteone "$h_excite\n$(grep -m1 '^0,' "$tmp/excite.csv")\n" "an excitation CSV with fewer than 2 rows"
# traj's and excite's columns begin alike: the columns after d decide.
bad_file motionother "$(echo "$h_traj" | sed 's/,dd[0-9]*//g'),x1\n" \
  "not a CSV of prru simulate, map, track, traj, excite, id or an identify report"

# ---- figures fit for a paper (issue 31) ----
# picture_ok FILE...: each non-empty and whole (a PNG's signature and its
# IEND chunk last, a GIF's signature and trailer), else the first bad one.
picture_ok() {
  python3 - "$@" <<'PY'
import sys
for p in sys.argv[1:]:
    b = open(p, 'rb').read()
    good = len(b) > 0 and (
        b[:8] == b'\x89PNG\r\n\x1a\n' and b[-12:] == b'\0\0\0\0IEND\xaeB`\x82' if p.endswith('.png') else
        b[:6] in (b'GIF89a', b'GIF87a') and b[-1:] == b';')
    if not good: print(p); sys.exit()
print('ok')
PY
}
# scripts of: prru ARGS..., each gnuplot script it runs kept in $tmp/gp.N.
mkdir -p "$tmp/keepbin"
printf '#!/bin/sh\nn=$(ls "%s"/gp.* 2>/dev/null | wc -l)\ncp "$1" "%s/gp.$n"\nexec "%s" "$@"\n' "$tmp" "$tmp" \
  "$real_gnuplot" >"$tmp/keepbin/gnuplot"
chmod +x "$tmp/keepbin/gnuplot"
scripts() { rm -f "$tmp"/gp.*; PATH="$tmp/keepbin:$PATH" "$PRRU" "$@"; }
# Every figure kind, each file checked.
scripts paper --out "$tmp/fig" >/dev/null 2>"$tmp/err" || bad "paper: $(head -c 300 "$tmp/err")"
cat "$tmp"/gp.* >"$tmp/paper.gp"
"$PRRU" animate "$tmp/run.csv" --frames 3 --out "$tmp/kinds.gif" || bad "animate"
r=$(picture_ok "$tmp"/{run,m,track,traj,excite,id,ident,topp,track2}.png "$tmp/kinds.gif" "$tmp"/fig/*.png)
[ "$r" = ok ] && [ "$(ls "$tmp"/fig/*.png | wc -l)" = 8 ] && ok || bad "a figure is not a whole picture: $r"
# One perceptually uniform colour map (viridis) for every map, and the
# clip said in the colour key: by default the 99th percentile of w_R.
grep -q "#440154.*#fde725" "$tmp/paper.gp" && ! grep -q rgbformulae "$tmp/paper.gp" && ok || bad "fig. 7 not in viridis"
grep -q "cblabel.*colours clipped at.*99th percentile" "$tmp/paper.gp" && ok || bad "fig. 7's key does not say the clip"
# No fake wall: the surface is cut at the z range, never flattened there.
grep -q "pm3d depthorder clip z" "$tmp/paper.gp" && ! grep -q "capped(" "$tmp/paper.gp" && ok \
  || bad "fig. 7's surface is clipped flat"
# --clip on each map-drawing command; bad values are exit 2.
# A clip below the map's largest w_R (the key says it only then): the
# largest of 1.5, 1.25, 1.125 under it (exact binary fractions, which the
# script's %.17g prints as written; the 4-limb model's map stays below 1.6).
wmax=$(grep -v '^#' "$tmp/map.csv" | awk -F, 'NR > 1 && $5 == "ok" && $4 > m { m = $4 } END { print m + 0 }')
clip=$(awk -v m="$wmax" 'BEGIN { c = 1.0625; if (m > 1.125) c = 1.125; if (m > 1.25) c = 1.25; if (m > 1.5) c = 1.5; print c }')
scripts plot "$tmp/map.csv" --clip "$clip" --out "$tmp/clip.png" 2>"$tmp/err" && grep -q "CLIP = $clip\$" "$tmp"/gp.* \
  && grep -q "cblabel.*(--clip)" "$tmp"/gp.* && [ "$(picture_ok "$tmp/clip.png")" = ok ] && ok \
  || bad "plot --clip $clip (largest w_R $wmax): $(head -c 300 "$tmp/err")"
scripts paper --out "$tmp/fig2" --clip 2.5 >/dev/null 2>"$tmp/err" && grep -q "CLIP = 2.5$" "$tmp"/gp.* && ok \
  || bad "paper --clip 2.5: $(head -c 300 "$tmp/err")"
for v in 1 0.5 x nan inf; do expect 2 "--clip '$v': must be a number above 1" -- plot "$tmp/map.csv" --clip "$v"; done
expect 2 "--clip '0.9': must be a number above 1" -- paper --out "$tmp/fig3" --clip 0.9
expect 2 "--clip '1': must be a number above 1" -- optimize --clip 1
expect 2 "--clip: only for a map CSV" -- plot "$tmp/run.csv" --clip 2
# Short titles, provenance in the footer: no whole SHA-256 and no 17-digit
# number in any label of any figure (the CSV comment lines keep them).
scripts plot "$tmp/traj.csv" --out "$tmp/t.png" && cat "$tmp"/gp.* >>"$tmp/paper.gp"
scripts plot "$tmp/excite.csv" --out "$tmp/t.png" && cat "$tmp"/gp.* >>"$tmp/paper.gp"
grep -q "0.29999999999999999" "$tmp/traj.csv" && ok || bad "the traj CSV no longer keeps 17 digits (test input changed)"
python3 - "$tmp/paper.gp" <<'PY' && ok || bad "a figure's text has a long number or a whole hash"
import re, sys
text = [l for l in open(sys.argv[1]) if re.match(r'(footer|model|sub|opt) = |set (title|label|cblabel|multiplot)', l)]
assert any(l.startswith('footer = ') and 'sha256 ' in l and 'paper; model' in l for l in text), 'no footer'
# (sprintf's arguments keep full precision: its format prints them %.4g.)
shown = [re.sub(r'(["\'])\s*,[^"\']*\)\s*$', r'\1', l) if 'sprintf(' in l else l for l in text]
bad = [l for l in shown if re.search(r'[0-9a-f]{64}|\d\.\d{9,}', l)]
assert not bad, bad[:2]
PY
# Lines survive greyscale: every line type has its own dash pattern.
grep -c "^set linetype [0-9] .* dt " "$tmp/gp.0" | grep -qx 6 && ok || bad "line types without dash patterns"
# The track figure: the reference drawn, rad and m on separate axes, the
# limits labelled with their value.
scripts plot "$tmp/track.csv" --out "$tmp/t.png"
grep -q "'qr1' with lines.*title 'reference'" "$tmp/gp.0" && grep -q "title sprintf('limit .*%.4g N', $FMAX)" "$tmp/gp.0" \
  && ! grep -q "rad, m" "$tmp/gp.0" && ok || bad "track figure: reference, limits or units"
# Panels aligned (fixed margins), the time axis the run's span.
grep -q "layout 5,1 margins screen" "$tmp/gp.0" && grep -q "autoscale xfix" "$tmp/gp.0" && ok || bad "track panels"
# Fig. 5 says why f_z is not there.
grep -q "f_z is not shown: z is the drive axis" "$tmp/paper.gp" && ok || bad "fig. 5 does not say why f_z is missing"

# ---- animate: a GIF of the mechanism moving ----
"$PRRU" animate "$tmp/run.csv" --frames 7 --fps 10 2>"$tmp/err" && [ "$(gif_frames "$tmp/run.gif")" = "7 differ" ] \
  && [ ! -s "$tmp/err" ] && ok || bad "animate --frames 7: $(gif_frames "$tmp/run.gif") $(head -c 300 "$tmp/err")"
"$PRRU" animate "$tmp/run.csv" --out - --frames 3 >"$tmp/dash.gif" && [ "$(gif_frames "$tmp/dash.gif")" = "3 differ" ] \
  && ok || bad "animate --out -: $(gif_frames "$tmp/dash.gif")"
# More frames than rows: one per row (21 rows).
"$PRRU" animate "$tmp/run.csv" --out "$tmp/all.gif" --frames 500 && [ "$(gif_frames "$tmp/all.gif" | cut -d' ' -f1)" = 21 ] \
  && ok || bad "animate --frames 500 of 21 rows: $(gif_frames "$tmp/all.gif")"
# What is drawn is the mechanism: per limb (as many as actuators) a
# vertical rail where the model file puts it, the slider on it, the upper
# link from the slider of the model's length l1, the lower link from there
# of length l2, the platform's arm to it of length a (limbs 1, 2) or 0.
"$PRRU" animate "$tmp/run.csv" --frames 5 --out "$tmp/seg.gif" --segments "$tmp/seg.dat" || bad "animate --segments"
r=$(python3 - "$tmp/seg.dat" "$PRRU_MODEL" "$nact" <<'PY'
import json, math, sys
g = json.load(open(sys.argv[2]))['geometry']; n = int(sys.argv[3])
per = lambda v, k: v[k] if isinstance(v, list) else v
if 'b' in g: b = g['b']
else: b = [g['b12'], g['b12'], g['b3']]
a = [per(g['a'], k) if k < 2 else 0.0 for k in range(n)]
rail = [(0, -b[0]), (0, b[1]), (b[2], 0), (-b[3] if n > 3 else 0, 0)][:n]
frames, errs = [], []
for line in open(sys.argv[1]):
    if line.startswith('# frame'): frames.append([])
    elif line.strip() and not line.startswith('#'): frames[-1].append([float(x) for x in line.split()])
if len(frames) != 5: errs.append('%d frames' % len(frames))
close = lambda u, v: abs(u - v) <= 1e-9 * (1 + abs(v))
length = lambda r: math.sqrt(r[3] ** 2 + r[4] ** 2 + r[5] ** 2)
for f in frames:
    for k in range(n):
        rl, sl, up, lo, arm = f[5 * k:5 * k + 5]
        if [r[6] for r in (rl, sl, up, lo, arm)] != [1, 2, 3, 4, 5]: errs.append('limb %d: bodies %s' % (k, [r[6] for r in (rl, sl, up, lo, arm)]))
        if not (close(rl[0], rail[k][0]) and close(rl[1], rail[k][1]) and rl[3] == rl[4] == 0): errs.append('limb %d: rail %s' % (k, rl[:3]))
        if not (close(sl[0], rl[0]) and close(sl[1], rl[1]) and close(sl[2] + sl[5] / 2, up[2])): errs.append('limb %d: slider off its rail or the link' % k)
        if not close(length(up), per(g['l1'], k)): errs.append('limb %d: upper link %.12g' % (k, length(up)))
        if not all(close(lo[c], up[c] + up[c + 3]) for c in range(3)): errs.append('limb %d: links not joined' % k)
        if not close(length(lo), per(g['l2'], k)): errs.append('limb %d: lower link %.12g' % (k, length(lo)))
        if not (all(close(arm[c] + arm[c + 3], lo[c] + lo[c + 3]) for c in range(3)) and abs(length(arm) - a[k]) <= 1e-9): errs.append('limb %d: arm %.12g' % (k, length(arm)))
    # The plate (4 edges and its normal), then its outline through the U joints.
    if len(f) != 6 * n + 5: errs.append('%d segments' % len(f))
    for k in range(n):
        e, lo_k, lo_n = f[5 * n + 5 + k], f[5 * k + 3], f[5 * ((k + 1) % n) + 3]
        if not all(close(e[c], lo_k[c] + lo_k[c + 3]) and close(e[c] + e[c + 3], lo_n[c] + lo_n[c + 3]) for c in range(3)):
            errs.append('outline edge %d' % k)
print('; '.join(errs[:3]) if errs else 'ok')
PY
)
[ "$r" = ok ] && ok || bad "animate draws something else than the model's mechanism: $r"
expect 2 "--segments $tmp/run.csv: that is the input file" -- animate "$tmp/run.csv" --segments "$tmp/run.csv"
expect 2 "--frames '1': must be an integer from 2 to 1000" -- animate "$tmp/run.csv" --frames 1
expect 2 "--fps '0'" -- animate "$tmp/run.csv" --fps 0
expect 2 "no column 't': not a CSV of prru simulate" -- animate "$tmp/other.csv"
expect 2 "fewer than 2 rows" -- animate "$tmp/simone.csv"
# A run of another model is refused: the poses would be this model's.
sed '1s/sha256 [0-9a-f]*/sha256 0000000000000000000000000000000000000000000000000000000000000000/' "$tmp/run.csv" >"$tmp/alien.csv"
expect 2 "was computed with another model" -- animate "$tmp/alien.csv"
[ ! -e "$tmp/alien.gif" ] && ok || bad "animate of another model's run wrote a GIF"
# A pose out of reach (q2 = 1.5 rad tilts the platform beyond the links'
# reach) is exit 1, no GIF.
awk -F, 'BEGIN { OFS = "," } /^#/ || /^t,/ { print; next } { $3 = 1.5; print }' "$tmp/run.csv" >"$tmp/far.csv"
expect 1 "out of reach" -- animate "$tmp/far.csv"
[ ! -e "$tmp/far.gif" ] && ok || bad "animate of unreachable poses wrote a GIF"

finish test_cli_plot
