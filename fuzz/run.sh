#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang (address + undefined sanitizers,
# every finding fatal) and runs each for a bounded time from the committed
# seed corpus, after replaying every committed regression input once.
#
#   fuzz/run.sh [harness...]      default: parse parse_pi table schedule scenario model_file
#   FUZZ_SECONDS   seconds per harness (default 30)
#   FUZZ_BUILD     build/work directory (default: a fresh temporary one)
#   FUZZ_JOBS      libFuzzer -fork workers (default 1; the CI box has 2 cores)
#
# Needs clang and its fuzzer runtime (Debian: clang and libclang-rt-N-dev for
# clang N, which `make fuzz` installs) and GSL. Exit status: 0 clean, 1 a harness found a crash (the reproducer is
# copied to fuzz/findings/<harness>/ and its path printed: reproduce with
# fuzz/run.sh --repro <harness> <file>, then commit it to
# fuzz/regressions/<harness>/ once fixed), 2 set-up error.
#
# New inputs libFuzzer finds go to the work directory, never into the
# committed corpus, so a run leaves the source tree unchanged unless it finds
# a crash.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
seconds=${FUZZ_SECONDS:-30}
jobs=${FUZZ_JOBS:-1}
all=(parse parse_pi table schedule scenario model_file)

CC=${FUZZ_CC:-clang}
if ! command -v "$CC" >/dev/null 2>&1; then
  echo "fuzz/run.sh: $CC not found (Debian: clang, then libclang-rt-N-dev for clang N;" \
    "'make fuzz' installs both)" >&2
  exit 2
fi

# The Debian package holding the fuzzer runtime of this clang, read from its
# version line as cmake/debian_deps.sh does (clang-runtime), so the message
# names the package that fits rather than one release's.
runtime_package() {
  local major
  major=$("$CC" --version 2>/dev/null | sed -n 's/.*clang version \([0-9][0-9]*\)\..*/\1/p' | head -n 1)
  if [ -z "$major" ]; then echo "the libclang-rt-N-dev matching '$CC --version'"
  elif [ "$major" -ge 14 ]; then echo "libclang-rt-$major-dev"
  else echo "libclang-common-$major-dev"; fi
}

work=${FUZZ_BUILD:-}
if [ -z "$work" ]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/prru-fuzz.XXXXXX") || exit 2
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work" || exit 2

# A missing runtime otherwise shows up as a link error inside the first
# harness's build; say which package it is instead.
printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n);\n%s\n' \
  'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }' \
  >"$work/probe.c"
if ! "$CC" -fsanitize=fuzzer,address,undefined "$work/probe.c" -o "$work/probe" >"$work/probe.log" 2>&1; then
  sed -n 1,5p "$work/probe.log" >&2
  echo "fuzz/run.sh: $CC cannot link a libFuzzer program: its runtime is missing" \
    "(Debian package $(runtime_package); 'make fuzz' installs it)" >&2
  exit 2
fi

# The runtime is compiled once into an object list shared by the harnesses,
# with the kernels a build generated (PRRU_GEN_DIR, `make fuzz` passes its
# build's: it also holds the single-precision sets the maps call, which
# the committed generated/ does not).
gen=${PRRU_GEN_DIR:-$root/build/generated}
if [ ! -f "$gen/prru_f_batch.c" ]; then
  echo "fuzz/run.sh: $gen holds no generated kernels: build first ('make build'), or set PRRU_GEN_DIR" >&2
  exit 2
fi
# shellcheck disable=SC2054  # the commas are inside one flag
sanitize=(-fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
          -fno-omit-frame-pointer)
cflags=(-std=c99 -O1 -g -Wall -Wextra -Wpedantic -Wshadow
        -I"$gen" -I"$root/runtime/include" -I"$root/runtime/src")
build() { # harness
  local name=$1 objs=() src obj
  if [ ! -f "$work/runtime.stamp" ]; then
    for src in "$root"/runtime/src/*.c "$gen"/*.c; do
      obj="$work/obj_$(basename "$src" .c).o"
      # fuzzer-no-link: coverage instrumentation without a second main()
      "$CC" "${cflags[@]}" -fsanitize=fuzzer-no-link,address,undefined \
        -fno-sanitize-recover=all -fno-omit-frame-pointer -c "$src" -o "$obj" || return 1
    done
    touch "$work/runtime.stamp"
  fi
  objs=("$work"/obj_*.o)
  "$CC" "${cflags[@]}" "${sanitize[@]}" "$here/fuzz_$name.c" "${objs[@]}" \
    -lgsl -lgslcblas -ljansson -lm -lpthread -o "$work/fuzz_$name"
}

if [ "${1:-}" = --repro ]; then
  [ $# -eq 3 ] || { echo "usage: fuzz/run.sh --repro HARNESS FILE" >&2; exit 2; }
  build "$2" || exit 2
  exec "$work/fuzz_$2" "$3"
fi

[ $# -gt 0 ] && all=("$@")
fork=()
[ "$jobs" -gt 1 ] && fork=(-fork="$jobs")
status=0
for name in "${all[@]}"; do
  if [ ! -f "$here/fuzz_$name.c" ]; then
    echo "fuzz/run.sh: no harness fuzz/fuzz_$name.c" >&2
    exit 2
  fi
  echo "== fuzz_$name: build"
  build "$name" || { echo "fuzz/run.sh: build of fuzz_$name failed" >&2; exit 2; }
  regs=("$here/regressions/$name"/*)
  if [ -e "${regs[0]}" ]; then
    echo "== fuzz_$name: replay ${#regs[@]} regression input(s)"
    if ! "$work/fuzz_$name" "${regs[@]}" >"$work/$name.replay.log" 2>&1; then
      tail -n 40 "$work/$name.replay.log"
      echo "FAIL fuzz_$name: a committed regression input fails again"
      status=1
      continue
    fi
  fi
  mkdir -p "$work/corpus_$name" "$work/artifacts_$name"
  echo "== fuzz_$name: fuzz ${seconds} s"
  # -max_len 4096: the line-oriented parsers gain nothing from a longer
  # input (it only repeats lines), and the committed model files, the
  # model_file seeds, are under 3.6 kB; -timeout 10: a single input taking
  # seconds is a hang.
  "$work/fuzz_$name" "$work/corpus_$name" "$here/corpus/$name" \
    -max_total_time="$seconds" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$work/artifacts_$name/" \
    "${fork[@]}" \
    >"$work/$name.log" 2>&1
  rc=$?
  grep -E '^(#[0-9]+.*DONE|stat::number_of_executed_units|stat::peak_rss_mb)' "$work/$name.log" | tail -n 3
  echo "   corpus: $(ls "$work/corpus_$name" | wc -l) new input(s) kept in $work/corpus_$name"
  arts=("$work/artifacts_$name"/*)
  if [ $rc -ne 0 ] || [ -e "${arts[0]}" ]; then
    status=1
    grep -E 'ERROR|SUMMARY|runtime error|==ABORTING|deadly signal' "$work/$name.log" | head -n 10
    mkdir -p "$here/findings/$name"
    for a in "${arts[@]}"; do
      [ -e "$a" ] || continue
      cp "$a" "$here/findings/$name/"
      echo "FAIL fuzz_$name: reproducer fuzz/findings/$name/$(basename "$a")"
    done
    [ -e "${arts[0]}" ] || { tail -n 30 "$work/$name.log"; echo "FAIL fuzz_$name: exit $rc"; }
  else
    echo "ok   fuzz_$name"
  fi
done
exit $status
