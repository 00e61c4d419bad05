#!/usr/bin/env bash
# Drop-in quality of the committed generated kernels: a user copies
# generated/ (the kernels, the descriptor, the runtime-parameter kernels,
# the opt-in derivative and regressor sets,
# the topology kernels prru_p3_*, prru_p4_*)
# into their own controller and builds it with their compiler and
# their warning flags. So copy ONLY generated/ (plus tests/dropin_main.c as
# main.c) into an empty directory, build with nothing but -lm under strict
# warnings as C99 and C11 with gcc and clang and as C++ with g++, and run
# each binary against the spec's section 10 reference point.
# The kernels carry the model's name (paper3prru_*): the library's prru_
# API is never met. The single-precision controller set (gen/prru_gen.py
# --precision float, paper3prru_f_*) is generated here from the paper's
# model (it is not committed) and built the same ways with
# tests/dropin_float_main.c, linked beside the double set in one program,
# with the float batches (paper3prru_f_batch.c).
#
# A missing clang or g++ is reported as SKIPPED (nothing is installed here);
# set PRRU_DROPIN_REQUIRE_ALL=1 (CI does) to make a skipped compiler a failure.
set -u

SRC=${PRRU_SOURCE_DIR:-$(cd "$(dirname "$0")/.." && pwd)}
FLAGS=(-O2 -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wfloat-conversion -Wdouble-promotion -Werror)

work=$(mktemp -d "${TMPDIR:-/tmp}/prru-dropin.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT
cp -R "$SRC/generated/." "$work/" || { echo "FAIL: cannot copy $SRC/generated"; exit 1; }
cp "$SRC/tests/dropin_main.c" "$work/main.c" || exit 1
cp "$SRC/tests/dropin_float_main.c" "$work/float_main.c" || exit 1
"${PYTHON:-python3}" "$SRC/gen/prru_gen.py" "$SRC/models/3prru_paper.json" --precision float \
  --out "$work" --quiet || { echo "FAIL: cannot generate the float set"; exit 1; }
cd "$work" || exit 1

fail=0
skipped=()

# The header promises "depends only on <math.h>" (the descriptor and the
# runtime-parameter kernels only on the kernels' header): any other include would be a dependency the user has to
# discover by a failed build.
for f in ./*.c ./*.h; do
  allowed='<math\.h>|"paper3prru_kernels\.h"|"paper3prru_mechanism\.h"|"paper3prru_param_kernels\.h"|"paper3prru_regressor\.h"|"paper3prru_derivs\.h"|"prru_p[34]s?_kernels\.h"'
  [ "$f" = ./main.c ] && allowed="$allowed|<stdio\.h>|<string\.h>"
  case "$f" in ./paper3prru_f_kernels.*) allowed='<math\.h>|<float\.h>|"paper3prru_f_kernels\.h"' ;; esac
  case "$f" in ./paper3prru_f_batch.*) allowed='<math\.h>|<float\.h>|"paper3prru_f_batch\.h"' ;; esac
  [ "$f" = ./float_main.c ] && allowed='<math\.h>|<stdio\.h>|"paper3prru_kernels\.h"|"paper3prru_f_kernels\.h"'
  bad=$(grep -nE '^[[:space:]]*#[[:space:]]*include' "$f" | grep -vE "$allowed" || true)
  if [ -n "$bad" ]; then
    echo "FAIL: $f includes more than <math.h> and its own header:"
    echo "$bad"
    fail=1
  fi
done

# Single precision throughout: no double in the float set's text at all.
if grep -nw double paper3prru_f_kernels.c paper3prru_f_kernels.h paper3prru_f_batch.c paper3prru_f_batch.h; then
  echo "FAIL: the float set names double (above)"
  fail=1
fi

kernels=()
for f in ./*.c; do
  case "$f" in ./main.c | ./float_main.c | ./paper3prru_f_kernels.c | ./paper3prru_f_batch.c | ./prru_p[34]*_kernels.c) ;;
    *) kernels+=("$f") ;;
  esac
done

# The topology kernels (prru_p3_*, prru_p4_*: 12 and 15 thousand lines,
# most of this test's time, and their simple variants prru_p3s_*,
# prru_p4s_*) are compiled once per compiler, in its first mode (C99, or
# C++), under the same flags, and those objects are linked into its other
# mode (C11): the C11 builds then recompile only the model's own files.
# The paper's program links prru_p3 (its parameter kernels); the others
# are compiled for their warnings alone.
topology_objects() { # compiler args...: sets topo to the objects, 1 on a failure
  local cc=$1 key=${1//[^a-z0-9]/_}
  shift
  topo=("./topo_${key}_p3.o")
  [ -f "./topo_${key}_p3.o" ] && return 0
  for n in 3 4 3s 4s; do
    if ! "$cc" "$@" "${FLAGS[@]}" -I. -c "./prru_p${n}_kernels.c" -o "./topo_${key}_p${n}.o" \
      >"./topo_${key}_p${n}.log" 2>&1 || [ -s "./topo_${key}_p${n}.log" ]; then
      echo "FAIL $cc: prru_p${n}_kernels.c does not compile cleanly:"
      cat "./topo_${key}_p${n}.log"
      return 1
    fi
  done
}

build_and_run() { # label compiler args...
  build_and_run_main main.c "$@"
  build_and_run_main float_main.c "$1 float" "${@:2}"
}

build_and_run_main() { # main label compiler args...
  local main=$1 label=$2 cc=$3
  shift 3
  local sources=("${kernels[@]}")
  # The float program needs only the two controller sets (the rest of
  # generated/ is built with main.c already), and the float batches (the
  # maps' --precision float) are built with it under the same flags.
  [ "$main" = float_main.c ] && sources=(./paper3prru_kernels.c ./paper3prru_f_kernels.c ./paper3prru_f_batch.c)
  if ! command -v "$cc" >/dev/null 2>&1; then
    echo "SKIPPED $label: $cc not installed"
    skipped+=("$label")
    return
  fi
  local exe="./dropin_${label//[^a-z0-9]/_}"
  if [ "$main" = main.c ]; then
    topology_objects "$cc" "$@" || { fail=1; return; }
    sources+=(-x none "${topo[@]}") # (after -x c++: objects are not sources)
  fi
  if ! "$cc" "$@" "${FLAGS[@]}" -I. "$main" "${sources[@]}" -o "$exe" -lm >"$exe.log" 2>&1; then
    echo "FAIL $label: compile"
    cat "$exe.log"
    fail=1
    return
  fi
  if [ -s "$exe.log" ]; then
    echo "FAIL $label: compiler output with -Werror build:"
    cat "$exe.log"
    fail=1
  fi
  if "$exe" >"$exe.out" 2>&1; then
    echo "ok   $label: $(tail -n 1 "$exe.out")"
  else
    echo "FAIL $label: run"
    cat "$exe.out"
    fail=1
  fi
}

build_and_run "gcc c99" gcc -std=c99
build_and_run "gcc c11" gcc -std=c11
build_and_run "clang c99" clang -std=c99
build_and_run "clang c11" clang -std=c11
build_and_run "g++ c++" g++ -x c++

if [ ${#skipped[@]} -gt 0 ]; then
  echo "skipped: ${skipped[*]}"
  if [ "${PRRU_DROPIN_REQUIRE_ALL:-0}" = 1 ]; then
    echo "FAIL: PRRU_DROPIN_REQUIRE_ALL=1 and a compiler is missing"
    fail=1
  fi
fi
# The gcc C99 build is the floor: without it nothing was tested.
case " ${skipped[*]:-} " in *" gcc c99 "*) fail=1 ;; esac
exit $fail
