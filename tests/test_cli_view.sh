#!/usr/bin/env bash
# prru view: the HTML page of a run, for any model. Without a browser: the
# exit statuses and messages of bad input, the page built aside (an old one
# kept on failure), user text (a hostile path and CSV comment lines) escaped
# for HTML and for the JSON inside <script>, the embedded three.js being the
# npm registry's three@0.170.0. In Debian's chromium, headless, driven by
# playwright-core (tests/view_browser.js): the page loads offline with no
# console error, the 3-D canvas is not blank and changes when the slider is
# moved, Play advances, the reaction arrows draw, the hostile text stays
# text, and the poses the page holds and draws are the pose kernel's.
#
# The browser part needs /usr/bin/chromium (or $PRRU_CHROMIUM), node and
# web/node_modules/playwright-core (`make test` runs `npm ci` in web/):
# when one is missing it is reported as SKIPPED, and with CI=true or
# PRRU_VIEW_REQUIRE_BROWSER=1 a skip is a failure.

. "$(dirname "$0")/cli_lib.sh"

web="$PRRU_SOURCE_DIR/web"
run="$tmp/run.csv"
"$PRRU" simulate --scenario paper --t-end 0.4 --dt 0.01 --out "$run" 2>"$tmp/err" ||
  { echo "FAIL: prru simulate: $(cat "$tmp/err")"; exit 1; }
"$PRRU" map --q1 -0.3:0.3:13 --q2 0.1:0.7:13 --q3 -0.8 --out "$tmp/map.csv" >/dev/null 2>"$tmp/err" ||
  { echo "FAIL: prru map: $(cat "$tmp/err")"; exit 1; }

# ---- arguments and input ----
"$PRRU" view --help >"$tmp/out" 2>&1 && grep -q "usage: prru view" "$tmp/out" && ok || bad "view --help"
expect 2 "a run CSV is required" -- view
expect 2 "--frames '1'" -- view "$run" --frames 1
expect 2 "--frames 'x'" -- view "$run" --frames x
expect 2 "unknown option" -- view "$run" --bogus
expect 2 "$tmp/none.csv" -- view "$tmp/none.csv"
expect 2 "map.csv:" -- view "$tmp/map.csv" --out "$tmp/x.html"
expect 2 "not a CSV of prru map" -- view "$run" --map "$run" --out "$tmp/x.html"
expect 2 "same file" -- view "$run" --out "$run"
expect 2 "same file" -- view "$run" --map "$tmp/map.csv" --out "$tmp/map.csv"
# A map that is not a grid (a row dropped from the middle).
{ head -n 5 "$tmp/map.csv"; tail -n +7 "$tmp/map.csv"; } >"$tmp/holey.csv"
expect 2 "holey.csv:" -- view "$run" --map "$tmp/holey.csv" --out "$tmp/x.html"
# Another model's run (its first line names another sha256).
sed '1s/sha256 [0-9a-f]*/sha256 0000000000000000000000000000000000000000000000000000000000000000/' "$run" >"$tmp/other.csv"
expect 2 "another model" -- view "$tmp/other.csv" --out "$tmp/x.html"
# A row out of reach: exit 1, naming the row; an existing page is kept.
# The pose: the first of a few extreme ones that prru ik finds unreachable.
qfar=""
for qq in 1.5,0,-0.8 3,0,-0.8 0,1.5,-0.8 0,3,-0.8 3,3,-0.8; do
  "$PRRU" ik --q "$qq" >/dev/null 2>&1
  [ $? -eq 1 ] && { qfar=$qq; break; }
done
[ -n "$qfar" ] || bad "no unreachable pose among the candidates"
python3 - "$run" "$tmp/far.csv" "${qfar:-0,0,0}" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
head = lines[1].split(',')
row = lines[5].split(',')
for n, v in zip(('q1', 'q2', 'q3'), sys.argv[3].split(',')):
    row[head.index(n)] = v
lines[5] = ','.join(row)
open(sys.argv[2], 'w').write('\n'.join(lines) + '\n')
PY
echo old >"$tmp/keep.html"
expect 1 "row 4 (t = 0.03 s)" -- view "$tmp/far.csv" --out "$tmp/keep.html"
[ "$(cat "$tmp/keep.html")" = old ] && ok || bad "a failed view replaced the old page"
ls "$tmp"/keep.html.* >/dev/null 2>&1 && bad "a partial page was left beside keep.html" || ok
expect 1 "" -- view "$run" --out "$tmp/no/such/dir/x.html"

# ---- the page, from a hostile path and hostile comment lines ----
evil='x</script><script>window.pwned=1</script><!--&amp;"'"'"
hdir="$tmp/$evil"
mkdir -p "$hdir"
hrun="$hdir/run.csv"
{ head -n 1 "$run"
  printf '# note </SCRIPT ><script>window.pwned=2</script> <!-- & \xe2\x80\xa8 \xff end\n'
  tail -n +2 "$run"; } >"$hrun"
page="$tmp/page.html"
"$PRRU" view "$hrun" --map "$tmp/map.csv" --frames 30 --out "$page" 2>"$tmp/err" && ok ||
  bad "prru view on the hostile path: $(cat "$tmp/err")"
# Default output name: beside the CSV.
"$PRRU" view "$run" --frames 5 2>"$tmp/err" && [ -s "$tmp/run.html" ] && ok || bad "view without --out: $(cat "$tmp/err")"
# The page has the template's three script elements and nothing else that
# opens or closes one, and no comment opener; the JSON data parses.
python3 - "$page" "$evil" "$PRRU_MODEL" <<'PY' && ok || bad "page structure: see above"
import json, re, sys
html = open(sys.argv[1], encoding='utf-8').read()
low = html.lower()
opens, closes = low.count('<script'), low.count('</script')
assert opens == 3 and closes == 3, 'script tags: %d open, %d close' % (opens, closes)
assert '<!--' not in html, 'a comment opener in the page'
title = re.search(r'<title>(.*?)</title>', html, re.S).group(1)
assert '<' not in title and '&lt;/script&gt;' in title, 'title not escaped: ' + title
data = html.split('<script type="application/json" id="prru-data">')[1].split('</script>')[0]
d = json.loads(data)
assert d['source']['file'].endswith(sys.argv[2] + '/run.csv'), d['source']['file']
assert any('window.pwned=2' in c for c in d['source']['comments']), d['source']['comments']
assert '\u2028' not in data and '\u2029' not in data
# The model's own text (a model with a hostile description, built with
# `make test MODEL=...`, gets the checks above through it) comes back as is.
model = json.load(open(sys.argv[3], encoding='utf-8'))
assert d['model']['description'] == model['description'], d['model']['description']
assert d['model']['name'] == model['name'], d['model']['name']
PY
# The embedded three.js is the registry's three@0.170.0 (when npm fetched it).
if [ -f "$web/node_modules/three/package.json" ]; then
  cmp -s "$web/vendor/three.module.min.js" "$web/node_modules/three/build/three.module.min.js" && ok ||
    bad "web/vendor/three.module.min.js differs from the npm package's build/three.module.min.js"
  grep -q "\"version\": \"0.170.0\"" "$web/node_modules/three/package.json" && ok || bad "three is not 0.170.0 in web/node_modules"
fi
grep -q "const t=\"170\"" "$web/vendor/three.module.min.js" && ok || bad "web/vendor three.js is not r170"
grep -q "SPDX-License-Identifier: MIT" "$page" && ok || bad "three.js licence header missing from the page"

# ---- in the browser ----
chromium_bin=${PRRU_CHROMIUM:-/usr/bin/chromium}
skip=""
[ -x "$chromium_bin" ] || skip="$chromium_bin not found (Debian: apt-get install chromium, or make deps-test)"
command -v node >/dev/null 2>&1 || skip="${skip:+$skip; }node not found (Debian: nodejs)"
[ -f "$web/node_modules/playwright-core/package.json" ] ||
  skip="${skip:+$skip; }web/node_modules/playwright-core missing (run 'make web-deps': npm ci in web/)"
if [ -n "$skip" ]; then
  echo "SKIPPED the browser part of prru view's test: $skip"
  if [ "${CI:-}" = true ] || [ "${PRRU_VIEW_REQUIRE_BROWSER:-0}" = 1 ]; then
    bad "CI=true or PRRU_VIEW_REQUIRE_BROWSER=1: the browser test must run"
  fi
  echo "test_cli_view: $pass passed, $fail failed"
  [ "$fail" -eq 0 ]
  exit
fi
PRRU_CHROMIUM="$chromium_bin" NODE_PATH="$web/node_modules" \
  node "$PRRU_SOURCE_DIR/tests/view_browser.js" "$page" "$tmp/seen.json" ${PRRU_VIEW_SCREENSHOT:+"$PRRU_VIEW_SCREENSHOT"} \
  >"$tmp/node.log" 2>&1 || bad "view_browser.js: $(tail -c 600 "$tmp/node.log")"
# The poses against the kernel, called here through the Python binding
# (libprru.so's prru_poses, in double) at the q of the CSV rows the page
# names. Tolerance 1e-9 (m, and for the rotation entries): the page's
# numbers are the kernel's written with 17 digits, which read back as the
# same doubles (0 difference, unless the library and the binary round
# differently, at 1e-16); a copy of them in float32, as WebGL buffers
# have them, is off by up to 2^-24 |x| ~ 1e-8 for the positions of about
# 0.2 m here, and a recomputation of the kinematics in the page would not
# match the row's q either: both fail this check.
# A sanitizer build's libprru.so cannot load into an uninstrumented python3
# (tests/CMakeLists.txt, python_prru): there the poses are not compared, and
# the Release build's run of this test compares them.
case "$(sed -n 's/^CMAKE_C_FLAGS:[A-Z]*=//p' "$PRRU_BUILD_DIR/CMakeCache.txt" | head -n 1)" in
*-fsanitize*) with_lib=0 ;;
*) with_lib=1 ;;
esac
PRRU_LIB="$PRRU_BUILD_DIR/runtime/libprru.so" PYTHONPATH="$PRRU_SOURCE_DIR/python" \
python3 - "$tmp/seen.json" "$hrun" "$evil" "$with_lib" <<'PY' && ok || bad "the browser's view: see above"
import csv, json, sys
r = json.load(open(sys.argv[1]))
fails = []
def need(cond, what):
    if not cond:
        fails.append(what)
need(not r['errors'], 'console or page errors: %s' % r['errors'][:5])
if 'nframes' not in r:
    print('FAIL:', fails); sys.exit(1)
need(r['nframes'] == 30, 'frames: %s' % r['nframes'])
need(r['non_background'] > 0.01 * r['pixels'], 'blank canvas: %d of %d pixels drawn' % (r['non_background'], r['pixels']))
need(r['frame_after_scrub'] == r['nframes'] - 1, 'End on the slider gave frame %s' % r['frame_after_scrub'])
need(r['changed'] > 100, 'scrubbing to the last frame changed %d pixels' % r['changed'])
need(r['frame_after_play'] > 0, 'Play did not advance the frame')
need(r['arrows'] and r['arrow_pixels'] > 20, 'reaction arrows: %s, %s pixels' % (r['arrows'], r.get('arrow_pixels')))
need(r['map_shown'], 'the map panel is hidden')
need(r.get('pwned') is None, 'injected script ran: window.pwned = %s' % r.get('pwned'))
need(sys.argv[3] in r['title'] and sys.argv[3] in r['info'] and 'window.pwned=2' in r['info'],
     'hostile text not shown as text: %r' % r['title'])
rows = [row for row in csv.reader(l for l in open(sys.argv[2], encoding='latin-1') if not l.startswith('#'))]
head, rows = rows[0], rows[1:]
ix = {n: head.index(n) for n in ('t', 'q1', 'q2', 'q3')}
if sys.argv[4] != '1':
    print('poses: not compared with the kernel (sanitizer build: libprru.so cannot load into python3)')
    for w in fails:
        print('FAIL:', w)
    sys.exit(1 if fails else 0)
import prru
m = prru.Model()
worst = 0.0
for f in r['poses']:
    row = rows[f['row']]
    q = [float(row[ix[n]]) for n in ('q1', 'q2', 'q3')]
    need(f['q'] == q and f['t'] == float(row[ix['t']]), 'frame %d: q or t differ from row %d' % (f['k'], f['row']))
    need(f['is_array'], 'frame %d: poses not a plain Array of doubles' % f['k'])
    R, p = m.poses(q)
    need(len(f['R']) == 9 * m.nbody and len(f['p']) == 3 * m.nbody, 'frame %d: pose sizes' % f['k'])
    for b in range(m.nbody):
        el = f['drawn'][b]  # column-major 4x4: R row i col j at el[4 j + i]
        for i in range(3):
            o = p[b][i] - sum(R[b][i][j] * m.com[b][j] for j in range(3))
            worst = max(worst, abs(f['p'][3 * b + i] - p[b][i]), abs(el[12 + i] - o))
            for j in range(3):
                worst = max(worst, abs(f['R'][9 * b + 3 * i + j] - R[b][i][j]), abs(el[4 * j + i] - R[b][i][j]))
need(worst <= 1e-9, 'poses differ from the kernel by %.3g (> 1e-9)' % worst)
print('poses: largest difference from the kernel %.3g; %d of %d pixels drawn, %d changed by scrubbing'
      % (worst, r['non_background'], r['pixels'], r['changed']))
for w in fails:
    print('FAIL:', w)
sys.exit(1 if fails else 0)
PY

echo "test_cli_view: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
