#!/usr/bin/env bash
# Memory and undefined-behaviour checks of the runtime, the CLI and the tests:
#  1. a Debug build with -fsanitize=address,undefined (every report fatal) in
#     its own build directory, and ctest there;
#  2. the fuzz harnesses' seed corpus and committed crash regressions
#     replayed through the same sanitizers (gcc, fuzz/replay.c: no clang
#     needed);
#  3. valgrind --error-exitcode=1 --leak-check=full on one `prru paper` run
#     of a Release build (the binary users run; ASan and valgrind cannot be
#     combined, so this is the uninstrumented one).
#
#   tests/sanitize.sh
#   SANITIZE_BUILD   ASan build directory   (default: a fresh temporary one)
#   RELEASE_BUILD    Release build directory with cli/prru (default: build/
#                    if it has one, else a fresh temporary Release build)
#   SANITIZE_SKIP_VALGRIND=1   stages 1-2 only
#   VALGRIND_TIMEOUT seconds (default 600; the run takes ~15 s on one core)
#
# Not run under the sanitizers: the label independent (gen_unittest, Python
# only; the package list; the random model generator; the drop-in build,
# compiled uninstrumented by its own compilers), the MuJoCo
# validation (MuJoCo's own code, and too slow instrumented) and the docs'
# checks (paper_doc_commands: the docs' 51 commands, the slow ones excite
# and paper, which the CLI tests run instrumented already; paper_cli_doc:
# help texts); all run in the ordinary `make test`.
set -u
here=$(cd "$(dirname "$0")" && pwd)
SRC=${PRRU_SOURCE_DIR:-$(dirname "$here")}
JOBS=${JOBS:-2}
status=0
tmpdirs=()
cleanup() { [ ${#tmpdirs[@]} -gt 0 ] && rm -rf "${tmpdirs[@]}"; }
trap cleanup EXIT
newtmp() { local d; d=$(mktemp -d "${TMPDIR:-/tmp}/prru-$1.XXXXXX") || exit 2; tmpdirs+=("$d"); echo "$d"; }

san_flags='-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all'
# detect_leaks: LeakSanitizer is part of ASan on Linux; keep it on.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

# ---- 1. ASan + UBSan build and ctest ----
asan=${SANITIZE_BUILD:-$(newtmp asan)}
mkdir -p "$asan" || exit 2
echo "== ASan/UBSan build in $asan"
if ! cmake -S "$SRC" -B "$asan" -DCMAKE_BUILD_TYPE=Debug \
      -DCMAKE_C_FLAGS="$san_flags" \
      -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >"$asan/configure.log" 2>&1 ||
   ! cmake --build "$asan" -j "$JOBS" >"$asan/build.log" 2>&1; then
  tail -n 40 "$asan/configure.log" "$asan/build.log" 2>/dev/null
  echo "FAIL: sanitizer build"
  exit 1
fi
echo "== ctest under ASan/UBSan"
if ! (cd "$asan" && ctest --output-on-failure -j "$JOBS" -LE independent -E '^(validate_mujoco|paper_doc_commands|paper_cli_doc)$'); then
  echo "FAIL: ctest under the sanitizers"
  status=1
fi

# ---- 2. fuzz corpus and regressions replayed under the sanitizers ----
echo "== fuzz corpus and regression replay (gcc, ASan/UBSan)"
# The runtime and the kernels as stage 1 built them, instrumented (its
# generated/ also holds the single-precision sets the maps call, which the
# source tree does not): compiling them again would double the stage.
rt_objs=("$asan/runtime/libprru_runtime.a" "$asan/libprru_kernels.a")
for lib in "${rt_objs[@]}"; do
  [ -f "$lib" ] || { echo "FAIL: $lib missing from the sanitizer build"; exit 1; }
done
for h in "$SRC"/fuzz/fuzz_*.c; do
  name=$(basename "$h" .c)
  name=${name#fuzz_}
  exe="$asan/replay_$name"
  # shellcheck disable=SC2086
  gcc -std=c99 -O1 -g $san_flags -I"$asan/generated" -I"$SRC/runtime/include" \
    "$h" "$SRC/fuzz/replay.c" "${rt_objs[@]}" -lgsl -lgslcblas -ljansson -lm -lpthread -o "$exe" ||
    { echo "FAIL: compile replay_$name"; exit 1; }
  inputs=()
  for f in "$SRC/fuzz/corpus/$name"/* "$SRC/fuzz/regressions/$name"/*; do
    [ -f "$f" ] && inputs+=("$f")
  done
  [ ${#inputs[@]} -gt 0 ] || continue
  # One process per input: a failure names its input.
  bad=0
  for f in "${inputs[@]}"; do
    if ! "$exe" "$f" >"$asan/replay.log" 2>&1; then
      tail -n 25 "$asan/replay.log"
      echo "FAIL replay_$name: ${f#$SRC/}"
      bad=1
    fi
  done
  if [ $bad = 0 ]; then echo "ok   replay_$name: ${#inputs[@]} input(s)"; else status=1; fi
done

# ---- 3. valgrind on one `prru paper` run of the release binary ----
if [ "${SANITIZE_SKIP_VALGRIND:-0}" != 1 ]; then
  if ! command -v valgrind >/dev/null 2>&1; then
    echo "FAIL: valgrind not installed (Debian package: valgrind)"
    exit 1
  fi
  rel=${RELEASE_BUILD:-}
  if [ -z "$rel" ] && [ -x "$SRC/build/cli/prru" ]; then rel="$SRC/build"; fi
  if [ -z "$rel" ] || [ ! -x "$rel/cli/prru" ]; then
    rel=${rel:-$(newtmp release)}
    echo "== Release build in $rel"
    if ! cmake -S "$SRC" -B "$rel" -DCMAKE_BUILD_TYPE=Release >"$rel/configure.log" 2>&1 ||
       ! cmake --build "$rel" -j "$JOBS" --target prru >"$rel/build.log" 2>&1; then
      tail -n 40 "$rel/build.log"
      echo "FAIL: release build"
      exit 1
    fi
  fi
  out=$(newtmp paper)
  echo "== valgrind $rel/cli/prru paper --out $out"
  # Unset the sanitizer options: they mean nothing to an uninstrumented binary.
  if env -u ASAN_OPTIONS -u UBSAN_OPTIONS timeout "${VALGRIND_TIMEOUT:-600}" \
       valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,possible \
       --track-origins=yes --quiet "$rel/cli/prru" paper --out "$out" \
       >"$out.stdout" 2>"$out.valgrind"; then
    if [ -s "$out/paper_sim.csv" ] && ! grep -v '^#' "$out/paper_sim.csv" | grep -qiE 'nan|inf'; then
      echo "ok   valgrind: no errors, no leaks, $(wc -l <"$out/paper_sim.csv") CSV lines"
    else
      echo "FAIL: valgrind run wrote no paper_sim.csv, or one with NaN/inf"
      status=1
    fi
  else
    rc=$?
    tail -n 40 "$out.valgrind"
    [ $rc = 124 ] && echo "FAIL: valgrind run exceeded ${VALGRIND_TIMEOUT:-600} s" ||
      echo "FAIL: valgrind reported errors or prru failed (exit $rc)"
    status=1
  fi
  rm -f "$out.stdout" "$out.valgrind"
fi

[ $status = 0 ] && echo "sanitize.sh: all clean"
exit $status
