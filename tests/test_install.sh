#!/usr/bin/env bash
# The installed library as another project uses it:
#  1. `cmake --install` of this build into a temporary prefix: the CLI, the
#     libraries, the headers, the CMake package and prru.pc are there, and
#     the installed `prru` is this build's (same --version);
#  2. a separate project finds it with find_package(prru) and builds one
#     program per exported target (prru::prru shared, prru::prru_static,
#     prru::kernels); another builds with `pkg-config --cflags --libs prru`,
#     and one links fully static with `pkg-config --static` (libprru.a);
#     the prefix has a space in it, which prru.pc must escape;
#  3. a parent project builds prru with add_subdirectory(prru) and links
#     prru::prru, without taking prru's tests into its own;
# and every program computes slider positions and a forward-dynamics
# acceleration that must agree with `prru eval` of this build
# to 1e-12 relative (the same code, so only rounding in printing could
# differ), and names the model this build was generated from.
#
# Env (set by ctest): PRRU (the CLI), PRRU_SOURCE_DIR, PRRU_BUILD_DIR,
# PRRU_MODEL. Consumers are compiled with this build's compiler and flags
# (the sanitizer build's instrumented libraries need an instrumented program).
set -u
: "${PRRU:?}" "${PRRU_SOURCE_DIR:?}" "${PRRU_BUILD_DIR:?}" "${PRRU_MODEL:?}"
# prru reads PRRU_MODEL from its environment as a model to load (prru
# --help): kept for this script, not for the binaries it runs, which are
# checked with their built-in model.
export -n PRRU_MODEL
tmp=$(mktemp -d "${TMPDIR:-/tmp}/prru-install.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
fails=0
ok() { echo "ok   $1"; }
fail() { echo "FAIL $1"; fails=$((fails + 1)); }
# Prints a log's tail and fails the whole test: later steps need this one.
die() { echo "FAIL $1"; [ -n "${2:-}" ] && tail -n 30 "$2"; exit 1; }

cache() { # VAR: its value in the build's CMakeCache.txt
  sed -n "s/^$1:[A-Z]*=//p" "$PRRU_BUILD_DIR/CMakeCache.txt" | head -n 1
}
CC_BUILD=$(cache CMAKE_C_COMPILER)
BUILD_TYPE=$(cache CMAKE_BUILD_TYPE)
C_FLAGS=$(cache CMAKE_C_FLAGS)
LD_FLAGS=$(cache CMAKE_EXE_LINKER_FLAGS)
consumer_cmake=(-DCMAKE_C_COMPILER="$CC_BUILD" -DCMAKE_C_FLAGS="$C_FLAGS"
                -DCMAKE_EXE_LINKER_FLAGS="$LD_FLAGS")

# ---- 1. install ----
# A prefix with a space: every consumer below must cope (prru.pc escapes it
# as pkg-config reads it).
prefix="$tmp/my prefix"
cmake --install "$PRRU_BUILD_DIR" --prefix "$prefix" >"$tmp/install.log" 2>&1 ||
  die "cmake --install $PRRU_BUILD_DIR --prefix $prefix" "$tmp/install.log"
libdir=$(cache CMAKE_INSTALL_LIBDIR)
libdir=${libdir:-lib}
model_base=$(basename "$PRRU_MODEL")
missing=""
for f in bin/prru "$libdir/libprru.so" "$libdir/libprru.a" "$libdir/libprru_runtime.a" "$libdir/libprru_kernels.a" \
         include/prru/prru.h include/prru/prru_dme.h include/prru/prru_kernels.h \
         include/prru/prru_mechanism.h "$libdir/cmake/prru/prruConfig.cmake" \
         "$libdir/cmake/prru/prruConfigVersion.cmake" "$libdir/cmake/prru/prruTargets.cmake" \
         "$libdir/pkgconfig/prru.pc" "share/prru/$model_base"; do
  [ -e "$prefix/$f" ] || missing="$missing $f"
done
# Every header of the build's generated/ (a new generated file pair too).
for h in "$PRRU_BUILD_DIR"/generated/*.h; do
  [ -e "$prefix/include/prru/$(basename "$h")" ] || missing="$missing include/prru/$(basename "$h")"
done
[ -z "$missing" ] && ok "install: CLI, libraries, headers, CMake package, prru.pc, model" ||
  fail "install: missing$missing"
if cmp -s "$PRRU_MODEL" "$prefix/share/prru/$model_base"; then ok "install: the model file"
else fail "install: share/prru/$model_base is not $PRRU_MODEL"; fi
if "$PRRU" --version >"$tmp/v.build" 2>&1 && "$prefix/bin/prru" --version >"$tmp/v.inst" 2>&1 &&
   cmp -s "$tmp/v.build" "$tmp/v.inst"; then
  ok "installed prru --version is the build's"
else
  fail "installed prru --version differs:"; diff "$tmp/v.build" "$tmp/v.inst" | head
fi
# The generator installed for `prru gen` runs on its own (its templates
# beside it, in share/prru) and writes what the source tree's writes;
# the installed prru gen (which takes the generator installed beside it)
# too. Every set, so that every template is found.
gen_model="$PRRU_SOURCE_DIR/models/prototype_example.json"
sets=(--derivatives --regressor)
if env -i PATH="$PATH" python3 "$prefix/share/prru/gen/prru_gen.py" "$gen_model" "${sets[@]}" --out "$tmp/gen_inst" --quiet &&
   "$prefix/bin/prru" gen "$gen_model" "${sets[@]}" --out "$tmp/gen_inst_cli" --quiet &&
   python3 "$PRRU_SOURCE_DIR/gen/prru_gen.py" "$gen_model" "${sets[@]}" --out "$tmp/gen_src" --quiet &&
   [ -e "$tmp/gen_inst/proto_derivs.c" ] && [ -e "$tmp/gen_inst/proto_regressor.c" ] &&
   diff -r "$tmp/gen_inst" "$tmp/gen_src" >/dev/null && diff -r "$tmp/gen_inst_cli" "$tmp/gen_src" >/dev/null; then
  ok "install: the generator (share/prru/gen) and prru gen write the source tree's kernels"
else
  fail "install: the installed generator or prru gen differs from the source tree's"
fi
[ ! -e "$prefix/share/prru/gen/tests" ] && ok "install: the generator's tests stay behind" ||
  fail "install: share/prru/gen/tests installed"
# ---- 1b. the Python package, importable from the prefix alone ----
# A clean environment (env -i): only PATH and PYTHONPATH, the installed
# package's directory; the binding must load the installed libprru.so
# (found through prru/_installed.py), not the build's or the source tree's.
pydir=$(cache PRRU_INSTALL_PYTHONDIR)
pydir=${pydir:-lib/python3/dist-packages}
[ "${pydir#/}" = "$pydir" ] && pydir="$prefix/$pydir"
# A sanitizer build's libprru.so cannot load into an uninstrumented
# python3 (the runtime must come first), as tests/CMakeLists.txt says of
# python_prru: the Release build's run of this test covers it.
case "$C_FLAGS $LD_FLAGS" in
*-fsanitize*) sanitized=1 ;;
*) sanitized=0 ;;
esac
if [ "$sanitized" = 1 ]; then
  ok "python: import from the prefix not tried (sanitizer build)"
elif command -v python3 >/dev/null 2>&1; then
  if (cd / && env -i PATH="$PATH" PYTHONPATH="$pydir" python3 -c '
import os, sys, prru
m = prru.Model()
w = m.w_R([0.0, 0.0, 0.0])
print(os.path.realpath(prru.__file__)); print(os.path.realpath(m.lib.path)); print(repr(w))
' >"$tmp/py.out" 2>&1); then
    py_pkg=$(sed -n 1p "$tmp/py.out") py_lib=$(sed -n 2p "$tmp/py.out") py_w=$(sed -n 3p "$tmp/py.out")
    real_prefix=$(realpath "$prefix")
    case "$py_pkg|$py_lib" in
    "$real_prefix"/*"|$real_prefix"/*) ok "python: import prru from $pydir, w_R(0) = $py_w with the installed library" ;;
    *) fail "python: the package or library is not the installed one: $py_pkg, $py_lib" ;;
    esac
    [ "$py_w" = "$("$PRRU" dme --q 0,0,0 | python3 -c 'import json, sys; print(repr(json.load(sys.stdin)["w_R"]))')" ] &&
      ok "python: w_R(0) is prru dme's" || fail "python: w_R(0) = $py_w differs from prru dme's"
  else
    fail "python: import prru from $pydir in a clean environment:"; cat "$tmp/py.out"
  fi
else
  fail "python3 not installed"
fi

# ---- 1c. man pages: prru.1 and one per command, rendered ----
mandir=$(cache CMAKE_INSTALL_MANDIR)
mandir=${mandir:-share/man}
[ "${mandir#/}" = "$mandir" ] && mandir="$prefix/$mandir"
render() { if command -v man >/dev/null 2>&1; then MANWIDTH=80 man -l "$1"; else groff -man -Tutf8 "$1"; fi 2>&1; }
man_bad=""
for cmd in "" $("$PRRU" --help | sed -n '/^commands:/,/^$/s/^  \([a-z][a-z0-9-]*\) .*/\1/p' ); do
  page="$mandir/man1/prru${cmd:+-$cmd}.1"
  if [ ! -s "$page" ]; then man_bad="$man_bad missing:${page#"$prefix"/}"; continue; fi
  # The page renders, with its name and the command's usage line (spaces
  # squeezed: help2man fills a usage line that runs into its paragraph,
  # and man justifies it with double spaces).
  render "$page" | tr -s ' ' >"$tmp/man.txt"
  grep -q "usage: prru${cmd:+ $cmd}" "$tmp/man.txt" && grep -q "^NAME" "$tmp/man.txt" ||
    man_bad="$man_bad bad:${page#"$prefix"/}"
done
[ -z "$man_bad" ] && ok "man pages: prru.1 and prru-COMMAND.1 for every command, rendered" ||
  fail "man pages:$man_bad"

nact=$(sed -n 's/^model actuators: //p' "$tmp/v.build")
sha=$(sed -n 's/^model sha256: //p' "$tmp/v.build")
[ -n "$nact" ] && [ -n "$sha" ] || die "prru --version: no actuator count or sha256"
[ "$sha" = "$(sha256sum "$PRRU_MODEL" | cut -d' ' -f1)" ] || die "prru --version: sha256 is not $PRRU_MODEL's"

# ---- the numbers every consumer must reproduce ----
q=0.1,0.2,-0.8
qd=0.3,-0.4,0.5
fd=$(seq -s, 50 -10 $((60 - 10 * nact)))   # 50,40,30[,20]: one per actuator
"$PRRU" eval --q "$q" --qd "$qd" --fd "$fd" >"$tmp/eval.json" 2>"$tmp/eval.err" ||
  die "prru eval" "$tmp/eval.err"

cat >"$tmp/consumer.c" <<'EOF'
/* Slider positions and qdd at the test's state, through the runtime (or,
 * with KERNELS_ONLY, the slider positions by the kernel alone). */
#include <stdio.h>
#include <stdlib.h>
#include "prru_kernels.h"
#include "prru_mechanism.h"
#ifndef KERNELS_ONLY
#include "prru.h"
#endif

int main(void) {
  const double q[3] = {0.1, 0.2, -0.8}, qd[3] = {0.3, -0.4, 0.5};
  double d[PRRU_NACT];
  int i;
#ifdef KERNELS_ONLY
  (void)qd;
  prru_ik(q, d);
#else
  prru_model m;
  prru_data *data = malloc(sizeof *data);
  prru_loads l = {{0}, {0, 0, 0}, {0, 0, 0}};
  double qdd[3];
  if (!data) return 1;
  prru_model_default(&m);
  for (i = 0; i < PRRU_NACT; i++) l.fd[i] = 50.0 - 10.0 * i;
  if (prru_actuators(&m, data, q, d) != PRRU_OK ||
      prru_forward_dynamics(&m, data, q, qd, &l, qdd) != PRRU_OK) {
    fprintf(stderr, "consumer: %s\n", prru_strerror(PRRU_EUNREACHABLE));
    return 1;
  }
  printf("qdd %.17g %.17g %.17g\n", qdd[0], qdd[1], qdd[2]);
  free(data);
#endif
  printf("sha256 %s\nd", prru_mech.sha256);
  for (i = 0; i < PRRU_NACT; i++) printf(" %.17g", d[i]);
  printf("\n");
  return 0;
}
EOF

check() { # NAME OUTPUT-FILE [kernels]: the program's numbers against prru's
  if python3 - "$tmp/eval.json" "$2" "$sha" "${3:-}" <<'PY'
import json, sys
ref = json.load(open(sys.argv[1]))
got = {}
for line in open(sys.argv[2]):
    key, *vals = line.split()
    got[key] = vals
if got.get("sha256") != [sys.argv[3]]:
    sys.exit("model sha256 %s, expected %s" % (got.get("sha256"), sys.argv[3]))
keys = ["d"] if sys.argv[4] == "kernels" else ["d", "qdd"]
for key in keys:
    vals = [float(v) for v in got.get(key, [])]
    if len(vals) != len(ref[key]):
        sys.exit("%s: %d values, prru eval has %d" % (key, len(vals), len(ref[key])))
    for a, b in zip(vals, ref[key]):
        if abs(a - b) > 1e-12 * max(abs(a), abs(b)):
            sys.exit("%s: %r, prru eval %r" % (key, vals, ref[key]))
PY
  then ok "$1: $([ "${3:-}" = kernels ] && echo "d agrees" || echo "d and qdd agree") with prru eval, model $model_base"
  else fail "$1"; fi
}

# ---- 2a. find_package(prru) ----
mkdir -p "$tmp/fp"
cp "$tmp/consumer.c" "$tmp/fp/consumer.c"
# The version the consumer asks for: this source's major.minor (before
# 1.0 the package accepts the same minor version only: SameMinorVersion).
abi_version=$(sed -n 's/^project(prru VERSION \([0-9]*\.[0-9]*\).*/\1/p' "$PRRU_SOURCE_DIR/CMakeLists.txt")
[ -n "$abi_version" ] || die "no project version in $PRRU_SOURCE_DIR/CMakeLists.txt"
cat >"$tmp/fp/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.16)
project(prru_consumer C)
set(CMAKE_C_STANDARD 99)
set(CMAKE_C_EXTENSIONS OFF)
find_package(prru ABI_VERSION REQUIRED)
if(NOT prru_MODEL_SHA256 STREQUAL EXPECTED_SHA256)
  message(FATAL_ERROR "prru_MODEL_SHA256 ${prru_MODEL_SHA256}, expected ${EXPECTED_SHA256}")
endif()
add_compile_options(-Wall -Wextra -Wpedantic -Werror)
add_executable(use_shared consumer.c)
target_link_libraries(use_shared PRIVATE prru::prru)
add_executable(use_static consumer.c)
target_link_libraries(use_static PRIVATE prru::prru_static)
add_executable(use_kernels consumer.c)
target_compile_definitions(use_kernels PRIVATE KERNELS_ONLY)
target_link_libraries(use_kernels PRIVATE prru::kernels)
EOF
sed -i "s/ABI_VERSION/$abi_version/" "$tmp/fp/CMakeLists.txt"
# No package registry, no system prru: only the temporary prefix.
if cmake -S "$tmp/fp" -B "$tmp/fp/build" "${consumer_cmake[@]}" -DCMAKE_BUILD_TYPE="$BUILD_TYPE" \
     -DCMAKE_PREFIX_PATH="$prefix" \
     -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DEXPECTED_SHA256="$sha" >"$tmp/fp.log" 2>&1 &&
   cmake --build "$tmp/fp/build" >>"$tmp/fp.log" 2>&1; then
  ok "find_package(prru): configured, three programs built"
  grep -q "prru_DIR:PATH=$prefix/" "$tmp/fp/build/CMakeCache.txt" ||
    fail "find_package(prru) did not take the installed package: $(grep prru_DIR "$tmp/fp/build/CMakeCache.txt")"
  for prog in use_shared use_static use_kernels; do
    if "$tmp/fp/build/$prog" >"$tmp/$prog.out" 2>&1; then
      check "find_package: $prog" "$tmp/$prog.out" "$([ $prog = use_kernels ] && echo kernels)"
    else
      fail "find_package: $prog exits $?"; cat "$tmp/$prog.out"
    fi
  done
  # The shared program loads the installed libprru.so, not the build's.
  if ldd "$tmp/fp/build/use_shared" | grep -q "libprru.so.* => $prefix/"; then
    ok "find_package: use_shared loads $prefix/.../libprru.so"
  else
    fail "find_package: use_shared loads another libprru:"; ldd "$tmp/fp/build/use_shared" | grep prru
  fi
else
  fail "find_package(prru) project"; tail -n 30 "$tmp/fp.log"
fi

# ---- 2b. pkg-config ----
if ! command -v pkg-config >/dev/null 2>&1; then
  fail "pkg-config not installed (Debian package: pkg-config)"
else
  export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
  pc_version=$(pkg-config --modversion prru 2>&1)
  [ "prru $pc_version" = "$(head -n 1 "$tmp/v.build")" ] && ok "pkg-config: prru $pc_version" ||
    fail "pkg-config --modversion prru: '$pc_version', prru --version: '$(head -n 1 "$tmp/v.build")'"
  [ "$(pkg-config --variable=model_sha256 prru)" = "$sha" ] && ok "pkg-config: model_sha256" ||
    fail "pkg-config --variable=model_sha256 prru: $(pkg-config --variable=model_sha256 prru)"
  # pkg-config prints a space in a path escaped with a backslash, for the
  # shell that runs the compiler (a Makefile's recipe): eval reads it so.
  pc_flags() { eval "pc=($(pkg-config "$@" prru))"; }
  pc_flags --cflags
  [ ${#pc[@]} = 1 ] && [ "${pc[0]}" = "-I$prefix/include/prru" ] && ok "pkg-config --cflags: -I with the prefix's space kept" ||
    fail "pkg-config --cflags prru: $(pkg-config --cflags prru)"
  pc_flags --cflags --libs
  # shellcheck disable=SC2086  # word splitting of the build's flags is meant
  if "$CC_BUILD" -std=c99 -Wall -Wextra -Wpedantic -Werror $C_FLAGS "$tmp/consumer.c" \
       -o "$tmp/use_pc" "${pc[@]}" $LD_FLAGS >"$tmp/pc.log" 2>&1; then
    if LD_LIBRARY_PATH="$prefix/$libdir" "$tmp/use_pc" >"$tmp/use_pc.out" 2>&1; then
      check "pkg-config: cc \$(pkg-config --cflags --libs prru)" "$tmp/use_pc.out"
    else
      fail "pkg-config: use_pc exits $?"; cat "$tmp/use_pc.out"
    fi
  else
    fail "pkg-config: compile and link"; tail -n 30 "$tmp/pc.log"
  fi
  # --static: -lprru is libprru.a, and the private libraries (GSL, libm,
  # libpthread) complete a fully static link. A sanitizer build cannot link
  # -static (its runtime is shared).
  case "$C_FLAGS $LD_FLAGS" in
  *-fsanitize*) ok "pkg-config --static: not tried (sanitizer build)" ;;
  *)
    pc_flags --static --cflags --libs
    if "$CC_BUILD" -std=c99 -static "$tmp/consumer.c" -o "$tmp/use_pc_static" "${pc[@]}" \
         >"$tmp/pcs.log" 2>&1 && ! ldd "$tmp/use_pc_static" >/dev/null 2>&1; then
      if "$tmp/use_pc_static" >"$tmp/use_pc_static.out" 2>&1; then
        check "pkg-config: cc -static \$(pkg-config --static --cflags --libs prru)" "$tmp/use_pc_static.out"
      else
        fail "pkg-config --static: use_pc_static exits $?"; cat "$tmp/use_pc_static.out"
      fi
    else
      fail "pkg-config --static: a static link"; tail -n 30 "$tmp/pcs.log"
    fi ;;
  esac
fi

# ---- 3. add_subdirectory(prru) ----
# No build type: the parent's choice, which prru must leave alone (and no
# optimisation keeps the kernels' compilation short).
mkdir -p "$tmp/sub"
cp "$tmp/consumer.c" "$tmp/sub/consumer.c"
cat >"$tmp/sub/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.16)
project(prru_parent C)
enable_testing()
add_subdirectory("$PRRU_SOURCE_DIR" prru)
add_executable(use_sub consumer.c)
target_link_libraries(use_sub PRIVATE prru::prru)
EOF
if cmake -S "$tmp/sub" -B "$tmp/sub/build" "${consumer_cmake[@]}" -DPRRU_MODEL="$PRRU_MODEL" \
     >"$tmp/sub.log" 2>&1 &&
   cmake --build "$tmp/sub/build" --target use_sub -j 2 >>"$tmp/sub.log" 2>&1; then
  ok "add_subdirectory(prru): configured, use_sub built"
  if "$tmp/sub/build/use_sub" >"$tmp/use_sub.out" 2>&1; then
    check "add_subdirectory: use_sub" "$tmp/use_sub.out"
  else
    fail "add_subdirectory: use_sub exits $?"; cat "$tmp/use_sub.out"
  fi
  bt=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$tmp/sub/build/CMakeCache.txt")
  [ -z "$bt" ] && ok "add_subdirectory: the parent's build type left unset" ||
    fail "add_subdirectory: prru set the parent's CMAKE_BUILD_TYPE to $bt"
  # prru's tests stay out of the parent's ctest unless asked for.
  ntests=$(cd "$tmp/sub/build" && ctest -N | sed -n 's/^Total Tests: //p')
  [ "$ntests" = 0 ] && ok "add_subdirectory: the parent's ctest has none of prru's tests" ||
    fail "add_subdirectory: the parent's ctest lists $ntests tests"
else
  fail "add_subdirectory(prru) parent project"; tail -n 30 "$tmp/sub.log"
fi

[ $fails = 0 ] && echo "test_install: all passed" || echo "test_install: $fails failure(s)"
[ $fails = 0 ]
