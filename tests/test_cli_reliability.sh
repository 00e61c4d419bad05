#!/usr/bin/env bash
# Nothing lost on write errors, signals or failed re-runs (issue 16, items
# 1, 2, 3, 5 and 8), for any model:
#  - a write error (/dev/full, a file-size limit) is an I/O error: exit 1
#    with the errno reason, never "interrupted", and the old file is kept;
#  - stdout is checked after it is flushed and closed (JSON, summaries);
#  - SIGINT, SIGTERM and SIGHUP stop simulate, map and paper with exit 130,
#    143 and 129; the rows computed so far are kept, every file ends with a
#    whole row (as many fields as the header), no FILE.partial-* is left,
#    a second signal changes nothing; paper leaves its directory as it was;
#  - a re-run that fails before its first row keeps the old file; map checks
#    --out before it computes; messages give the reason (strerror) and do
#    not call an overflow "not reachable".
# Signals are sent once the output has rows (polling, no fixed delays), and
# every background run has a watchdog, so a loaded machine only slows this.

. "$(dirname "$0")/cli_lib.sh"

# Every non-comment line has the header's field count; the file ends with
# a newline.
whole_rows() {
  local f=$1
  [ -s "$f" ] || return 1
  [ -z "$(tail -c 1 "$f")" ] || return 1
  awk -F, '/^#/ { next } !h { h = NF; next } NF != h { exit 1 }' "$f"
}
# Data rows: lines after the comment and the header.
data_rows() { grep -vc '^#' "$1" | awk '{ print $1 - 1 }'; }
# No FILE.partial-* anywhere under $tmp.
no_partials() {
  local left
  left=$(find "$tmp" -name '*.partial-*' | head -n 3)
  [ -z "$left" ] && ok || bad "$1: partial files left: $left"
}
# wait_lines GLOB N SECONDS: until a file matching GLOB has N lines.
wait_lines() {
  local glob=$1 n=$2 i f
  for ((i = 0; i < $3 * 50; i++)); do
    for f in $glob; do
      [ -f "$f" ] && [ "$(wc -l <"$f")" -ge "$n" ] && return 0
    done
    sleep 0.02
  done
  return 1
}
# wait_file GLOB SECONDS: until something matches GLOB.
wait_file() {
  local glob=$1 i f
  for ((i = 0; i < $2 * 50; i++)); do
    for f in $glob; do [ -e "$f" ] && return 0; done
    sleep 0.02
  done
  return 1
}
# catch_stage GLOB SECONDS: runs the background prru ($pid) in slices of
# about a millisecond (SIGCONT, sleep, SIGSTOP) until GLOB exists, and
# leaves it stopped there (return 0; 1 when GLOB never appeared or prru
# ended). A stage that lasts a few milliseconds (the paper's simulation
# file) falls between two polls of a free-running process; not between
# two slices.
catch_stage() {
  local glob=$1 i f
  for ((i = 0; i < $2 * 500; i++)); do
    kill -STOP "$pid" 2>/dev/null || return 1
    for f in $glob; do [ -e "$f" ] && return 0; done
    kill -CONT "$pid"
    sleep 0.001
  done
  kill -CONT "$pid" 2>/dev/null
  return 1
}
# start CMD...: runs prru in the background (pid in $pid) with its own
# default SIGINT (job control on: without it bash ignores SIGINT in
# background commands, and prru keeps signals it finds ignored), stderr in
# $tmp/bg.err, stdout in $bg_out (default /dev/null). A watchdog kills it
# after 120 s.
bg_out=/dev/null
start() {
  set -m
  "$PRRU" "$@" >"$bg_out" 2>"$tmp/bg.err" &
  pid=$!
  set +m
  (trap 'kill $s 2>/dev/null; exit 0' TERM; sleep 120 & s=$!; wait $s; kill -KILL "$pid") >/dev/null 2>&1 &
  watchdog=$!
}
# finish_bg: the exit status of the background run in $rc.
finish_bg() {
  wait "$pid" 2>/dev/null
  rc=$?
  kill "$watchdog" 2>/dev/null
  wait "$watchdog" 2>/dev/null
  bg_out=/dev/null
}

# ---- 1. A write error is an I/O error with its reason, not an interrupt ----
expect 1 "No space left on device" -- simulate --scenario paper --t-end 0.2 --out /dev/full
grep -qiE "interrupt|consumer" "$tmp/err" && bad "simulate > /dev/full called an interrupt: $(cat "$tmp/err")" || ok
"$PRRU" simulate --t-end 0.05 >/dev/full 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "No space left on device" "$tmp/err" && ok || bad "simulate to stdout on /dev/full: exit $rc: $(cat "$tmp/err")"
"$PRRU" simulate --t-end 0.02 --dt 0.01 --out "$tmp/traj.csv" || bad "a short run"
expect 1 "No space left on device" -- id --traj "$tmp/traj.csv" --out /dev/full
expect 1 "No space left on device" -- map --q1 -0.1:0.1:5 --q2 -0.1:0.1:5 --out /dev/full
# A full disk on a regular file (a file-size limit; SIGXFSZ ignored so the
# write fails with EFBIG): exit 1, the old file and no partial file.
echo "old contents" >"$tmp/keep.csv"
(trap '' XFSZ; ulimit -f 64; exec "$PRRU" simulate --scenario paper --out "$tmp/keep.csv") 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "File too large" "$tmp/err" && ok || bad "simulate over the size limit: exit $rc: $(cat "$tmp/err")"
[ "$(cat "$tmp/keep.csv")" = "old contents" ] && ok || bad "simulate over the size limit changed the old file"
no_partials "simulate over the size limit"
# prru paper on a full disk: exit 1 with the reason, the directory as it was.
mkdir -p "$tmp/pfull"
echo "old summary" >"$tmp/pfull/summary.txt"
echo "old csv" >"$tmp/pfull/paper_sim.csv"
(trap '' XFSZ; ulimit -f 256; exec "$PRRU" paper --out "$tmp/pfull" --skip-map) >/dev/null 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "File too large" "$tmp/err" && ! grep -qiE "interrupt|consumer" "$tmp/err" \
  && ok || bad "paper over the size limit: exit $rc: $(cat "$tmp/err")"
[ "$(ls "$tmp/pfull" | tr '\n' ' ')" = "paper_sim.csv summary.txt " ] && [ "$(cat "$tmp/pfull/summary.txt")" = "old summary" ] \
  && [ "$(cat "$tmp/pfull/paper_sim.csv")" = "old csv" ] && ok || bad "paper over the size limit changed $tmp/pfull: $(ls "$tmp/pfull")"

# ---- 2. stdout is checked after flush and close ----
"$PRRU" ik --q 0.1,0.2,-0.8 >"$tmp/ik.json" || bad "ik"
dlist=$(json "$tmp/ik.json" "','.join(repr(x) for x in d['d'])")
for args in "ik --q 0.1,0.2,-0.8" "fk --d $dlist" "eval --q 0.1,0.2,-0.8" "dme --q 0.1,0.2,-0.8" \
            "map --q1 -0.1:0.1:5 --q2 -0.1:0.1:5 --out $tmp/m_small.csv" "--version" "--help" "simulate --help"; do
  # shellcheck disable=SC2086
  "$PRRU" $args >/dev/full 2>"$tmp/err"
  rc=$?
  [ $rc -eq 1 ] && grep -q "stdout: write error: No space left on device" "$tmp/err" && ok \
    || bad "prru $args > /dev/full: exit $rc: $(cat "$tmp/err")"
done

# ---- 3. Signals: exit 128 + signal, whole rows kept, nothing partial ----
for sig in INT:130 TERM:143 HUP:129; do
  name=${sig%%:*} want=${sig##*:}
  out="$tmp/sig_$name.csv"
  start simulate --scenario paper --dt 1e-5 --t-end 1 --out "$out"
  wait_lines "$out.partial-*" 200 60 || bad "SIG$name: no rows appeared"
  kill -"$name" "$pid"
  finish_bg
  [ $rc -eq "$want" ] && ok || bad "simulate stopped by SIG$name: exit $rc, want $want: $(cat "$tmp/bg.err")"
  grep -q "SIG$name" "$tmp/bg.err" && grep -q "samples written to" "$tmp/bg.err" && ok || bad "SIG$name message: $(cat "$tmp/bg.err")"
  whole_rows "$out" && ok || bad "SIG$name: $out does not end with whole rows: $(tail -c 200 "$out" 2>/dev/null)"
  [ "$(head -1 "$out")" = "$csv_comment" ] && ok || bad "SIG$name: comment line"
  n=$(data_rows "$out")
  [ "$n" -ge 200 ] && [ "$n" -lt 100001 ] && ok || bad "SIG$name: $n rows kept"
done
no_partials "simulate stopped by signals"
# Two signals at once: the second one changes nothing.
out="$tmp/sig_twice.csv"
start simulate --scenario paper --dt 1e-5 --t-end 1 --out "$out"
wait_lines "$out.partial-*" 200 60 || bad "twice: no rows appeared"
kill -INT "$pid"; kill -INT "$pid"; kill -TERM "$pid"
finish_bg
{ [ $rc -eq 130 ] || [ $rc -eq 143 ]; } && whole_rows "$out" && ok || bad "simulate, three signals: exit $rc, rows whole? $(cat "$tmp/bg.err")"
no_partials "simulate, three signals"
# SIGINT while a write to a pipe is blocked (the reader starts reading only
# afterwards): the rows that reach the reader are all whole.
mkfifo "$tmp/fifo"
{ while [ ! -e "$tmp/go" ]; do sleep 0.02; done; cat; } <"$tmp/fifo" >"$tmp/fifo.csv" &
reader=$!
bg_out="$tmp/fifo"
start simulate --scenario paper --dt 1e-5 --t-end 1
# Blocked in write(2) once the pipe is full (the wait channel says so; where
# /proc does not tell, 10 s is long enough to fill it).
for ((i = 0; i < 500; i++)); do
  grep -q pipe_write "/proc/$pid/wchan" 2>/dev/null && break
  sleep 0.02
done
kill -INT "$pid"
sleep 0.1
touch "$tmp/go"
finish_bg
wait "$reader"
[ $rc -eq 130 ] && ok || bad "simulate to a blocked pipe, SIGINT: exit $rc: $(cat "$tmp/bg.err")"
whole_rows "$tmp/fifo.csv" && ok || bad "rows through a blocked pipe are not whole: $(awk -F, '!/^#/ { print NF }' "$tmp/fifo.csv" | sort | uniq -c | head)"

# map: a signal during the computation keeps the complete q1 rows, no
# summary; stdout gets nothing.
out="$tmp/map_sig.csv"
echo "old map" >"$out"
bg_out="$tmp/map_sig.out"
start map --q1 -0.5:0.5:3000 --q2 -0.5:0.5:400 --progress --out "$out"
wait_file "$out.partial-*" 30 && for ((i = 0; i < 3000; i++)); do grep -q '%' "$tmp/bg.err" && break; sleep 0.02; done
kill -TERM "$pid"
finish_bg
[ $rc -eq 143 ] && ok || bad "map stopped by SIGTERM: exit $rc: $(tail -c 300 "$tmp/bg.err")"
if [ "$(cat "$out")" = "old map" ]; then
  grep -q "nothing written" "$tmp/bg.err" && ok || bad "map kept the old file but says: $(tail -c 300 "$tmp/bg.err")"
else
  whole_rows "$out" && ok || bad "map stopped by SIGTERM: rows not whole"
  n=$(data_rows "$out")
  [ "$n" -gt 0 ] && [ $((n % 400)) -eq 0 ] && [ "$n" -lt 1200000 ] && ok || bad "map stopped by SIGTERM: $n rows, not whole q1 rows"
fi
[ -s "$tmp/map_sig.out" ] && bad "map stopped by SIGTERM printed a summary: $(cat "$tmp/map_sig.out")" || ok
# Two signals: the second one may stop the writing too, still at a row.
out="$tmp/map_sig2.csv"
start map --q1 -0.5:0.5:3000 --q2 -0.5:0.5:400 --progress --out "$out"
wait_file "$out.partial-*" 30 && for ((i = 0; i < 3000; i++)); do grep -q '%' "$tmp/bg.err" && break; sleep 0.02; done
kill -HUP "$pid"; sleep 0.05; kill -HUP "$pid"
finish_bg
[ $rc -eq 129 ] && { [ ! -e "$out" ] || whole_rows "$out"; } && ok || bad "map, two SIGHUPs: exit $rc: $(tail -c 300 "$tmp/bg.err")"
no_partials "map stopped by signals"

# paper: stopped during the simulation, or later (gnuplot, fig. 7 map),
# the directory keeps exactly what it had.
for stage_file in "paper_sim.csv.partial-*" "fig_q.png"; do
  [ "$stage_file" = fig_q.png ] && ! command -v gnuplot >/dev/null && continue
  pd="$tmp/pdir"
  rm -rf "$pd"; mkdir -p "$pd"
  echo "old summary" >"$pd/summary.txt"
  echo "old png" >"$pd/fig_q.png"
  start paper --out "$pd"
  catch_stage "$pd/paper.partial-*/$stage_file" 60 || bad "paper: $stage_file never appeared"
  kill -INT "$pid"
  kill -CONT "$pid"
  finish_bg
  [ $rc -eq 130 ] && grep -q "is not changed" "$tmp/bg.err" && ok || bad "paper stopped at $stage_file: exit $rc: $(tail -c 300 "$tmp/bg.err")"
  [ "$(ls -A "$pd" | tr '\n' ' ')" = "fig_q.png summary.txt " ] && [ "$(cat "$pd/summary.txt")" = "old summary" ] \
    && [ "$(cat "$pd/fig_q.png")" = "old png" ] && ok || bad "paper stopped at $stage_file changed $pd: $(ls -A "$pd" | tr '\n' ' ')"
done
# A new directory that a stopped run created is removed again.
start paper --out "$tmp/pnew"
catch_stage "$tmp/pnew/paper.partial-*/paper_sim.csv.partial-*" 60 || bad "paper: the simulation file never appeared"
kill -TERM "$pid"
kill -CONT "$pid"
finish_bg
[ $rc -eq 143 ] && [ ! -e "$tmp/pnew" ] && ok || bad "paper stopped in a new directory: exit $rc, left $(ls -A "$tmp/pnew" 2>&1)"

# Issue 30 item 5: a signal while id or identify reads a large input
# killed them (exit 130/143) with no message. The input comes through a
# FIFO whose writer stays open, so the signal lands while the file is
# still being read: the message names the option and file, exit 128 +
# signal, no output written.
"$PRRU" traj --waypoints '0,0,0;0.1,0,0' --durations 2 --dt 1e-4 --out "$tmp/big.csv" || bad "traj for the big input"
mkfifo "$tmp/in.fifo"
for run in "id:traj:INT:130" "identify:data:TERM:143"; do
  IFS=: read -r cmd opt sig want <<<"$run"
  rm -f "$tmp/rd.out"
  start "$cmd" --"$opt" "$tmp/in.fifo" --out "$tmp/rd.out"
  exec 7<>"$tmp/in.fifo"
  timeout 60 cat "$tmp/big.csv" >&7
  # Blocked reading the FIFO for more (where /proc does not say, 2 s).
  for ((i = 0; i < 100; i++)); do
    grep -q pipe_read "/proc/$pid/wchan" 2>/dev/null && break
    sleep 0.02
  done
  kill -"$sig" "$pid"
  sleep 0.1
  exec 7>&-
  finish_bg
  [ "$rc" -eq "$want" ] && grep -qF "interrupted (SIG$sig) while reading --$opt $tmp/in.fifo; nothing written" "$tmp/bg.err" \
    && ok || bad "$cmd stopped by SIG$sig while reading: exit $rc: $(cat "$tmp/bg.err")"
  [ -e "$tmp/rd.out" ] && bad "$cmd stopped while reading wrote $tmp/rd.out" || ok
done
no_partials "id and identify stopped while reading"

# ---- 5. Outputs are replaced only by a run that has rows ----
echo "old contents" >"$tmp/old.csv"
chmod 640 "$tmp/old.csv"
expect 1 "not reachable" -- simulate --q0 0,1.5,0 --t-end 0.01 --out "$tmp/old.csv"
expect 1 "overflow" -- simulate --qd0 1e160,0,0 --t-end 0.01 --out "$tmp/old.csv"
printf 't,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,0,1.5,0,0,0,0,0,0,0\n' >"$tmp/traj_bad.csv"
expect 1 "not reachable" -- id --traj "$tmp/traj_bad.csv" --out "$tmp/old.csv"
[ "$(cat "$tmp/old.csv")" = "old contents" ] && ok || bad "a failed re-run changed the old file: $(head -c 200 "$tmp/old.csv")"
# A run with rows replaces it, keeping its permissions.
"$PRRU" simulate --t-end 0.01 --out "$tmp/old.csv" || bad "re-run"
[ "$(head -1 "$tmp/old.csv")" = "$csv_comment" ] && [ "$(stat -c %a "$tmp/old.csv")" = 640 ] && ok \
  || bad "re-run: $(head -1 "$tmp/old.csv"), mode $(stat -c %a "$tmp/old.csv")"
# A symbolic link is written through and stays a link.
echo "old" >"$tmp/target.csv"
ln -s target.csv "$tmp/link.csv"
"$PRRU" simulate --t-end 0.01 --out "$tmp/link.csv" || bad "simulate through a link"
[ -L "$tmp/link.csv" ] && [ "$(head -1 "$tmp/target.csv")" = "$csv_comment" ] && ok || bad "link replaced or target not written"
# --out - and no --out write stdout, the same bytes as a file.
"$PRRU" simulate --t-end 0.01 --out - >"$tmp/dash.csv" && "$PRRU" simulate --t-end 0.01 >"$tmp/none.csv" \
  && cmp -s "$tmp/dash.csv" "$tmp/old.csv" && cmp -s "$tmp/none.csv" "$tmp/old.csv" && ok || bad "--out - differs from --out FILE"
# map checks --out before computing (no progress bar is drawn).
expect 1 "No such file or directory" -- map --q1 0:1:2000 --q2 0:1:2000 --progress --out "$tmp/nodir/m.csv"
grep -q "map \[" "$tmp/err" && bad "map computed before finding that --out cannot be written" || ok
expect 1 "Is a directory" -- map --q1 0:1:5 --q2 0:1:5 --out "$tmp"
# map --out -: the CSV is stdout (checked on content in test_cli_dme.sh);
# a write error there is exit 1 with the reason.
"$PRRU" map --q1 0:1:5 --q2 0:1:5 --out - >/dev/full 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "stdout: write error: No space left on device" "$tmp/err" && ok \
  || bad "map --out - >/dev/full: exit $rc: $(head -c 300 "$tmp/err")"
no_partials "failed re-runs"

# ---- 8. Messages ----
# Huge qd0 at q0 = 0 was reported as "not reachable at q = (0, 0, 0)".
# Depending on the model and the size, the initial checks find the
# dynamics or T overflowing, the first sample's reactions overflow, or the
# run gets through t = 0 and its first step leaves the workspace; never
# with the claim that q0 = 0 is at fault. For the paper's model, 1e155
# overflows the dynamics at t = 0 and 1e154 the first sample's reactions.
for v in 1e153 1e154 1e155; do
  expect 1 "" -- simulate --qd0 $v,0,0 --t-end 0.01
  grep -q "at q = (0, 0, 0)" "$tmp/err" && bad "qd0 = $v blamed on q = 0: $(cat "$tmp/err")" || ok
  if [ "$model_sha" = "$paper_sha" ] && [ $v != 1e153 ]; then
    grep -q "overflow" "$tmp/err" && ! grep -q "not reachable" "$tmp/err" && ok \
      || bad "qd0 = $v: $(cat "$tmp/err")"
  fi
done
expect 1 "No such file or directory" -- simulate --t-end 0.01 --out "$tmp/nodir/x.csv"
expect 1 "No such file or directory" -- id --traj "$tmp/traj.csv" --out "$tmp/nodir/x.csv"
expect 2 "No such file or directory" -- id --traj "$tmp/nonexistent.csv"
expect 2 "No such file or directory" -- simulate --scenario "$tmp/nonexistent.txt"
expect 2 "No such file or directory" -- simulate --loads "$tmp/nonexistent.csv"
expect 2 "Is a directory" -- simulate --scenario "$tmp"
# Issue 30 item 6: a bad loads file of a scenario was reported as if it
# were the scenario ("--scenario /dev/zero"): the message names the
# scenario file and line, then the loads file and its fault.
printf '# loads from a device\nloads = /dev/zero\n' >"$tmp/zero.scn"
expect 2 "--scenario $tmp/zero.scn:2: loads: /dev/zero: larger than" -- simulate --scenario "$tmp/zero.scn"
printf 't,fd1\n0,1\n' >"$tmp/short_loads.csv"
printf 'loads = short_loads.csv\n' >"$tmp/short.scn"
expect 2 "--scenario $tmp/short.scn:1: loads: $tmp/short_loads.csv:1: missing column 'fd2'" -- simulate --scenario "$tmp/short.scn"
expect 1 "Not a directory" -- paper --out "$tmp/keep.csv"
expect 1 "Not a directory" -- simulate --t-end 0.01 --out "$tmp/keep.csv/x.csv"

# Runaway integrations (issue item 4): impossible tolerances are usage
# errors; a step budget stops a run, keeping its rows.
for t in "--atol 1e-25" "--rtol 1e-25" "--rtol 1e-16 --atol 1e-10"; do
  expect 2 "no double-precision" -- simulate --t-end 0.01 $t
done
expect 2 "does not work with msbdf" -- simulate --t-end 0.01 --stepper msbdf --atol 0 --rtol 1e-8
expect 2 "--max-steps '2.5'" -- simulate --t-end 0.01 --max-steps 2.5
expect 1 "step budget of 3 steps exhausted" -- simulate --q0 0,0,-0.8 --fd "$(nlist 40)" --harmonic 50,200 \
  --max-steps 3 --dt 0.05 --t-end 0.5 --atol 1e-13 --rtol 1e-13 --out "$tmp/budget.csv"
[ "$(grep -vc '^#' "$tmp/budget.csv")" -ge 2 ] && ok || bad "step budget: rows before the stop not kept"

finish test_cli_reliability
