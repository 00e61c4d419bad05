# Shared by the tests/{test,paper}_cli*.sh scripts (sourced): a scratch
# directory, pass/fail counting, `expect`, JSON checks and the identity of
# the model the binary was built from. Needs $PRRU (path to the binary);
# $PRRU_MODEL (the model file, default the paper's) and $PRRU_SOURCE_DIR
# (default: this file's parent directory) as ctest sets them.
set -u
: "${PRRU:?set PRRU to the prru binary}"
: "${PRRU_SOURCE_DIR:=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}"
: "${PRRU_MODEL:=$PRRU_SOURCE_DIR/models/3prru_paper.json}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
ok()  { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*" >&2; }

# The model's identity as the CLI must print it: name, file name, format,
# SHA-256 of the file, the program version (CMake project version) and the
# comment line every CSV starts with.
model_name=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["name"])' "$PRRU_MODEL")
model_format=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("format", 1))' "$PRRU_MODEL")
model_file=$(basename "$PRRU_MODEL")
model_sha=$(sha256sum "$PRRU_MODEL" | cut -d' ' -f1)
paper_sha=$(sha256sum "$PRRU_SOURCE_DIR/models/3prru_paper.json" | cut -d' ' -f1)
prru_version=$(sed -n 's/^project(prru VERSION \([0-9][0-9.]*\).*/\1/p' "$PRRU_SOURCE_DIR/CMakeLists.txt")
# model_id: the model as every output names it (the built-in model, so its
# specialised kernels; prru_model_identity without its leading "model ").
model_kernels=specialised
model_id="$model_name ($model_file, sha256 $model_sha, $model_kernels kernels)"
csv_comment="# prru $prru_version model $model_id"
export model_name model_file model_sha model_kernels
# PRRU_MODEL names the build's model file for the scripts (ctest sets it);
# prru itself reads a PRRU_MODEL in its environment as the model to load
# (prru --help): unexported, so that every run computes with the built-in
# model unless a test says otherwise.
export -n PRRU_MODEL

# The number of actuators (sliders) of the model the binary computes, as
# `prru --version` says it; 3 for the 3-PRRU, 4 for a redundantly actuated
# model (spec section 12). Lists of actuator forces and displacements, load
# tables and CSV columns have that many entries.
nact=$("$PRRU" --version 2>/dev/null | sed -n 's/^model actuators: //p')
: "${nact:=3}"
export nact
# fdlist A B C: the list A,B,C for the first three actuators, every further
# (redundant) one getting C, limb 4 mirroring limb 3 as in the paper
# scenario of `prru paper` (fd = 50,40,25,25 on four sliders).
fdlist() {
  local s="$1,$2,$3" i
  for ((i = 3; i < nact; i++)); do s="$s,$3"; done
  echo "$s"
}
# nlist X: X repeated once per actuator (X,X,X or X,X,X,X).
nlist() {
  local s=$1 i
  for ((i = 1; i < nact; i++)); do s="$s,$1"; done
  echo "$s"
}
# act_names PREFIX: PREFIX1,...,PREFIXn, one per actuator (fd1,fd2,fd3[,fd4]).
act_names() {
  local s="" i
  for ((i = 1; i <= nact; i++)); do s="$s${s:+,}$1$i"; done
  echo "$s"
}

# expect STATUS NEEDLE -- ARGS...: exit status and a stderr substring.
expect() {
  local want=$1 needle=$2; shift 3
  "$PRRU" "$@" >"$tmp/out" 2>"$tmp/err"
  local got=$?
  if [ "$got" -ne "$want" ]; then bad "prru $* exited $got, want $want: $(head -c 300 "$tmp/err")"; return; fi
  if [ -n "$needle" ] && ! grep -qF -- "$needle" "$tmp/err"; then
    bad "prru $*: stderr lacks '$needle': $(head -c 300 "$tmp/err")"; return; fi
  ok
}

# json FILE EXPR: prints a python expression over d (the parsed JSON).
json() { python3 -c "import json, math, sys; d = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }
# jcheck FILE EXPR WHAT: the python expression over d (and math, the model
# identity `model` as the CLI prints it) must be true.
jcheck() {
  python3 -c "
import json, math, os, sys
d = json.load(open(sys.argv[1]))
model = {'name': os.environ['model_name'], 'file': os.environ['model_file'], 'sha256': os.environ['model_sha'],
         'kernels': os.environ['model_kernels']}
sys.exit(0 if eval(sys.argv[2]) else 1)" "$1" "$2" && ok || bad "$3: $(head -c 400 "$1")"
}
# below X LIMIT WHAT: the number X is below LIMIT.
below() {
  python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < float(sys.argv[2]) else 1)" "$1" "$2" \
    && ok || bad "$3: $1 (limit $2)"
}

# finish NAME: the summary line and the exit status.
finish() {
  echo "$1: $pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}
