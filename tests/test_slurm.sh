#!/usr/bin/env bash
# The Slurm example of docs/studies.md ("Sweeps on a cluster: shards") on a
# real single-node cluster that this test starts in its scratch directory
# and stops again: Debian's slurm-wlm (slurmctld, slurmd) and munge, with
# their own configuration, key, ports, state and logs. The docs' job script
# and submission commands are read from the docs and run as written, but on
# an 11 x 11 grid so that it takes seconds: a 16-task array of
# `prru sensitivity --shard`, then a dependent `prru merge` job; beside it
# the map array the docs mention (`prru map --shard ... --threads 1`, 8
# tasks) and its merge. Every array task must end COMPLETED with exit code
# 0, and each merged file (and what the merge job printed) must equal, byte
# for byte, one unsharded run of the same command.
#
# Needs the packages slurm-wlm and munge (`make test` installs them), not
# root: every daemon runs as the user running the test (SlurmUser and
# SlurmdUser), who also owns the jobs, so slurmd never has to switch users
# (seen to pass as root and as nobody). Where the packages are missing, or
# the daemons do not start or cannot run a trivial job, the test says
# SKIPPED with the reason (and the daemons' log tails); with CI=true or
# PRRU_SLURM_REQUIRE=1 a skip is a failure. The daemons are stopped on
# every exit (scontrol shutdown, then munged), each waited for.

. "$(dirname "$0")/cli_lib.sh"

node=$(hostname -s)
user=$(id -un)
conf="$tmp/slurm.conf"
work="$tmp/work"
ctld_pid="" slurmd_pid="" munged_pid=""

# ---- stopping the cluster, on every exit ----
# stop_pid PID: waits up to 15 s for PID to exit, then TERM, then KILL.
stop_pid() {
  local i
  for ((i = 0; i < 30; i++)); do kill -0 "$1" 2>/dev/null || break; sleep 0.5; done
  if kill -0 "$1" 2>/dev/null; then
    kill -TERM "$1" 2>/dev/null
    for ((i = 0; i < 10; i++)); do kill -0 "$1" 2>/dev/null || break; sleep 0.5; done
    kill -KILL "$1" 2>/dev/null
  fi
  wait "$1" 2>/dev/null
}
stop_cluster() {
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    # Jobs still running (a failed or timed-out run) are cancelled first,
    # so that no slurmstepd outlives its slurmd.
    scancel --quiet --user="$user" 2>/dev/null
    local i
    for ((i = 0; i < 20; i++)); do
      scontrol -o show job 2>/dev/null | grep -qE 'JobState=(RUNNING|COMPLETING|CONFIGURING)' || break
      sleep 0.5
    done
    scontrol shutdown >/dev/null 2>&1
  fi
  [ -n "$ctld_pid" ] && stop_pid "$ctld_pid"
  [ -n "$slurmd_pid" ] && stop_pid "$slurmd_pid"
  [ -n "$munged_pid" ] && { kill -TERM "$munged_pid" 2>/dev/null; stop_pid "$munged_pid"; }
  ctld_pid="" slurmd_pid="" munged_pid=""
}
trap 'stop_cluster; rm -rf "$tmp"' EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM

# tails: the last lines of the daemons' logs (a Slurm daemon's stderr,
# which repeats its log in the foreground, where it has no log file yet:
# a configuration it could not read).
tails() {
  local f
  for f in munged.log slurmctld.log slurmd.log; do
    [ -s "$tmp/$f" ] || f=${f%.log}.err
    [ -s "$tmp/$f" ] && { echo "--- last lines of $f:"; tail -n 15 "$tmp/$f"; }
  done
}
# skip REASON: Slurm cannot run here; a failure under CI or PRRU_SLURM_REQUIRE=1.
skip() {
  echo "SKIPPED the Slurm test: $1"
  tails
  if [ "${CI:-}" = true ] || [ "${PRRU_SLURM_REQUIRE:-0}" = 1 ]; then
    bad "CI=true or PRRU_SLURM_REQUIRE=1: the Slurm test must run"
  fi
  finish test_slurm
  exit
}

# ---- what it needs ----
missing=""
for c in munged slurmctld slurmd sbatch scontrol scancel sinfo; do
  command -v "$c" >/dev/null 2>&1 || missing="$missing $c"
done
[ -z "$missing" ] || skip "not found:$missing (Debian: apt-get install slurm-wlm munge, or make deps-test)"

# The client commands and the jobs see this cluster only: no SLURM_* or
# SBATCH_* variables from a surrounding job or shell, SLURM_CONF ours; and
# `prru` is the build's binary.
while read -r v; do unset "$v"; done < <(compgen -e | grep -E '^(SLURM|SBATCH|SALLOC|SRUN|SQUEUE|SINFO|SCONTROL|SCANCEL)_')
export SLURM_CONF="$conf"
mkdir -p "$tmp/bin" "$work" "$tmp/state" "$tmp/spool" "$tmp/one"
ln -s "$(cd "$(dirname "$PRRU")" && pwd)/$(basename "$PRRU")" "$tmp/bin/prru"
export PATH="$tmp/bin:$PATH"

# ---- munge: its own key and socket ----
# munged takes its key, socket, pid, seed and log paths on the command line,
# and the Slurm daemons, commands and job steps find that socket through
# AuthInfo=socket=... in slurm.conf (read by both auth/munge and
# cred/munge), so the system's munged (/run/munge/munge.socket.2 and
# /etc/munge/munge.key), running or not, is neither used nor disturbed.
# munged refuses a socket in a directory that is not searchable by all, and
# a key readable by others: the scratch directory becomes 0711, the socket's
# 0755, the key 0400.
chmod 0711 "$tmp"
mkdir -m 0755 "$tmp/munge"
if command -v mungekey >/dev/null 2>&1; then
  mungekey --create --keyfile="$tmp/munge.key" >/dev/null 2>&1
else
  dd if=/dev/urandom of="$tmp/munge.key" bs=1024 count=1 2>/dev/null
fi
chmod 0400 "$tmp/munge.key"
msock="$tmp/munge/munge.sock"
munged --foreground --socket="$msock" --key-file="$tmp/munge.key" --pid-file="$tmp/munged.pid" \
  --seed-file="$tmp/munged.seed" --log-file="$tmp/munged.log" >"$tmp/munged.log" 2>&1 &
munged_pid=$!
for ((i = 0; i < 40; i++)); do [ -S "$msock" ] && break; kill -0 "$munged_pid" 2>/dev/null || break; sleep 0.25; done
[ -S "$msock" ] || skip "munged did not create its socket $msock"

# ---- slurm.conf ----
# Two free TCP ports (a system Slurm uses 6817 and 6818), the CPUs this
# process may use and 90 % of the memory (slurmd drains a node configured with more
# than it finds). No cgroups (proctrack/linuxproc, task/none), no
# accounting; jobs started as soon as resources free up (batch_sched_delay=0,
# default 3 s per start).
read -r ctld_port slurmd_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("", 0))
print(*(x.getsockname()[1] for x in s))')
cpus=$(nproc)
mem=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
cat >"$conf" <<EOF
ClusterName=prrutest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$user
SlurmdUser=$user
MailProg=/bin/true
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$msock
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=batch_sched_delay=0
MpiDefault=none
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF

# ---- the daemons, in the foreground as children of this shell ----
slurmctld -D -c -f "$conf" >"$tmp/slurmctld.err" 2>&1 &
ctld_pid=$!
slurmd -D -N "$node" -f "$conf" >"$tmp/slurmd.err" 2>&1 &
slurmd_pid=$!
state=""
for ((i = 0; i < 120; i++)); do
  kill -0 "$ctld_pid" 2>/dev/null || skip "slurmctld exited"
  kill -0 "$slurmd_pid" 2>/dev/null || skip "slurmd exited"
  state=$(sinfo -h -N -n "$node" -o %T 2>/dev/null)
  case "$state" in
    idle) break ;;
    inval|drain*) skip "slurmctld refused node $node ($state; the reason in its log)" ;;
  esac
  sleep 0.5
done
[ "$state" = idle ] || skip "node $node not idle after 60 s (sinfo: '${state:-no answer}')"

# job_state JOBID: the state of one job, "DependencyNeverSatisfied" for a
# job that waits on a failed one.
job_state() {
  local line
  line=$(scontrol -o show job "$1" 2>/dev/null | head -n 1)
  case "$line" in
    *"Reason=DependencyNeverSatisfied"*) echo DependencyNeverSatisfied ;;
    *) sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' <<<"$line" ;;
  esac
}
# wait_jobs SECONDS JOBID...: until every job is in a final state.
wait_jobs() {
  local limit=$1 i j st busy
  shift
  for ((i = 0; i < limit * 4; i++)); do
    busy=0
    for j; do
      st=$(job_state "$j")
      case "$st" in
        COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED|DependencyNeverSatisfied) ;;
        *) busy=1 ;;
      esac
    done
    [ $busy = 0 ] && return 0
    sleep 0.25
  done
  return 1
}

# A trivial job first: a cluster that cannot run one is a skip, not a
# failure of prru's example.
smoke=$(cd "$work" && sbatch --parsable --output=/dev/null --wrap true 2>"$tmp/err")
[ -n "$smoke" ] || skip "sbatch: $(head -c 300 "$tmp/err")"
wait_jobs 30 "$smoke" && [ "$(job_state "$smoke")" = COMPLETED ] ||
  skip "a trivial job (sbatch --wrap true) did not complete: $(job_state "$smoke")"

# ---- the docs' example ----
# The two sh blocks of the section: the job script, the submission.
docs="$PRRU_SOURCE_DIR/docs/studies.md"
awk '/^### Sweeps on a cluster: shards/ { on = 1; next }
     on && /^#/ && !inblock { exit }
     on && /^```sh$/ { n++; inblock = 1; next }
     on && /^```$/ { inblock = 0; next }
     on && inblock { print > (dir "/block" n) }' dir="$tmp" "$docs"
[ -s "$tmp/block1" ] && [ -s "$tmp/block2" ] && ok ||
  { bad "docs/studies.md: the shards section's two sh blocks (job script, submission) not found"; finish test_slurm; exit; }
# The grid made small: every --q1/--q2 START:STOP:COUNT gets COUNT 11.
sed -E 's/(--q[12] +[^ ]+:[^ ]+:)[0-9]+/\111/g' "$tmp/block1" >"$work/sens.sbatch"
grep -qE -- '--q1 [^ ]+:11 .*--q2 [^ ]+:11' "$work/sens.sbatch" && ok ||
  bad "docs/studies.md: the job script's --q1/--q2 grids not recognised: $(cat "$work/sens.sbatch")"
grep -q 'sbatch --parsable --array=1-16 sens.sbatch' "$tmp/block2" && ok ||
  bad "docs/studies.md: the submission no longer submits sens.sbatch as an array: $(cat "$tmp/block2")"
# The map array the docs mention after the example (21 rows in 8 shards).
map_grid="--q1 -pi/6:pi/6:21 --q2 -pi/4:pi/6:21"
cat >"$work/map.sbatch" <<EOF
#!/bin/bash
#SBATCH --job-name=prru-map --cpus-per-task=1 --time=00:10:00
prru map $map_grid --shard "\$SLURM_ARRAY_TASK_ID/8" \\
    --threads 1 --out "map_\$SLURM_ARRAY_TASK_ID.csv"
EOF

# Submitted from $work, which is thus every job's working directory
# (sbatch's default --chdir), as a user would from the directory of the
# job script; the docs' block runs as written, then says its array's id.
start=$SECONDS
(cd "$work" && bash -e -c "$(cat "$tmp/block2")"$'\necho "array $jid"') >"$tmp/submit.out" 2>&1 ||
  bad "the docs' submission failed: $(cat "$tmp/submit.out")"
sens_array=$(sed -n 's/^array \([0-9][0-9]*\)$/\1/p' "$tmp/submit.out")
sens_merge=$(sed -n 's/^Submitted batch job \([0-9][0-9]*\)$/\1/p' "$tmp/submit.out")
map_array=$(cd "$work" && sbatch --parsable --array=1-8 map.sbatch 2>"$tmp/err") || bad "sbatch map.sbatch: $(cat "$tmp/err")"
map_merge=$(cd "$work" && sbatch --parsable --dependency=afterok:"$map_array" --wrap \
  'prru merge --in "$(ls map_*.csv | paste -sd,)" --out map.csv' 2>"$tmp/err") || bad "sbatch the map's merge: $(cat "$tmp/err")"
if [ -z "$sens_array" ] || [ -z "$sens_merge" ] || [ -z "$map_array" ] || [ -z "$map_merge" ]; then
  bad "job ids not found: $(cat "$tmp/submit.out")"; finish test_slurm; exit
fi
# 16 + 8 one-CPU tasks on this node's CPUs, then the merges: 13 s on 2
# CPUs (slurmctld starts jobs once a second, one per free CPU); 150 s
# leaves room for a loaded machine.
wait_jobs 150 "$sens_merge" "$map_merge" ||
  bad "the merge jobs not finished after 150 s: $(job_state "$sens_merge"), $(job_state "$map_merge")"
echo "the two arrays and their merges ran in $((SECONDS - start)) s"

# array_ok ARRAY_JOBID N NAME: tasks 1..N each COMPLETED with exit code
# 0:0; otherwise the tasks that were not, with what they printed.
array_ok() {
  local tasks done t
  tasks=$(scontrol -o show job "$1" 2>/dev/null |
    sed -n 's/.*ArrayTaskId=\([^ ]*\) .*JobState=\([^ ]*\) .*ExitCode=\([^ ]*\) .*/\1 \2 \3/p' | sort -n)
  done=$(awk '$2 == "COMPLETED" && $3 == "0:0" { print $1 }' <<<"$tasks" | paste -sd,)
  if [ "$done" = "$(seq -s, 1 "$2")" ]; then ok; return; fi
  bad "$3: array tasks completed with exit code 0: '$done', want 1..$2; the others:"
  awk '!($2 == "COMPLETED" && $3 == "0:0")' <<<"$tasks" | while read -r t _; do
    echo "  task $t: $(grep -F "ArrayTaskId=$t " <<<"$(scontrol -o show job "$1")" |
      sed -n 's/.*\(JobState=[^ ]*\) .*\(ExitCode=[^ ]*\) .*/\1 \2/p'): $(tail -n 5 "$work/slurm-$1_$t.out" 2>/dev/null)" >&2
  done
}
array_ok "$sens_array" 16 "sens.sbatch"
array_ok "$map_array" 8 "map.sbatch"

# ---- against one unsharded run of the same commands ----
# In $tmp/one: the job script's command without --shard, writing sens.csv
# (the merged file's name), and the map's alike.
sed -e '/^#/d' "$work/sens.sbatch" | sed -e ':a' -e '/\\$/{N;s/\\\n//;ba}' |
  sed -E -e 's/--shard +"[^"]*"//' -e 's/--out +"[^"]*"/--out sens.csv/' >"$tmp/one/sens.sh"
grep -q -- '--shard' "$tmp/one/sens.sh" && bad "the unsharded command still has --shard: $(cat "$tmp/one/sens.sh")"
echo "prru map $map_grid --threads 1 --out map.csv" >"$tmp/one/map.sh"
# merged NAME MERGE_JOBID: the merge job completed; NAME.csv equals the
# unsharded run's, and what the job printed (its slurm-JOBID.out: stdout
# and stderr) is what that run prints (the sensitivity table, the map's
# summary).
merged() {
  local st
  st=$(job_state "$2")
  if [ "$st" != COMPLETED ]; then
    bad "the $1 merge job $2: $st: $(tail -n 5 "$work/slurm-$2.out" 2>/dev/null)"; return; fi
  (cd "$tmp/one" && bash -e "$1.sh") >"$tmp/one/$1.out" 2>&1 ||
    { bad "the unsharded $1 run: $(cat "$tmp/one/$1.out")"; return; }
  cmp "$work/$1.csv" "$tmp/one/$1.csv" && ok || bad "the merged $1.csv differs from one unsharded run"
  cmp -s "$work/slurm-$2.out" "$tmp/one/$1.out" && ok ||
    bad "the $1 merge job printed other text than one run: $(diff "$work/slurm-$2.out" "$tmp/one/$1.out" | head -n 10)"
}
merged sens "$sens_merge"
merged map "$map_merge"
# The docs' merge also draws the chart (--plot sens.png).
[ "$(job_state "$sens_merge")" = COMPLETED ] &&
  { [ "$(head -c 8 "$work/sens.png" 2>/dev/null | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] && ok ||
    bad "the merge job's --plot sens.png is not a PNG"; }

[ "$fail" -eq 0 ] || tails
finish test_slurm
