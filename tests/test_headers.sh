#!/usr/bin/env bash
# One ABI for every model (runtime/include/prru_sizes.h): the public
# headers stand alone, with no generated header and no model's sizes, so
# that a program compiled against them is compiled the same whatever
# model the library was built for.
#  1. every runtime/include/*.h compiles by itself as C99 and C++ with
#     only runtime/include on the include path (strict warnings, -Werror;
#     a generated header it included would not be found);
#  2. no public struct's size depends on the build: prru_struct_size of
#     this build's library equals sizeof of the same struct compiled here
#     from the headers alone, for every struct it names.
#
# Env (set by ctest): PRRU_SOURCE_DIR, PRRU_BUILD_DIR.
set -u
: "${PRRU_SOURCE_DIR:?}" "${PRRU_BUILD_DIR:?}"
inc="$PRRU_SOURCE_DIR/runtime/include"
lib="$PRRU_BUILD_DIR/runtime/libprru.so"
[ -f "$lib" ] || { echo "FAIL: $lib is missing (build the library first)"; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/prru-headers.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
fails=0
pass=0
CC=${CC:-cc}
CXX=${CXX:-c++}
for h in "$inc"/*.h; do
  name=$(basename "$h")
  printf '#include "%s"\ntypedef int prru_test_unit; /* a TU is never empty */\n' "$name" >"$tmp/one.c"
  if "$CC" -std=c99 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I"$inc" "$tmp/one.c" 2>"$tmp/err"; then
    pass=$((pass + 1))
  else
    echo "FAIL: $name does not compile alone as C99 with only runtime/include:"
    sed 's/^/  /' "$tmp/err" | head -5
    fails=$((fails + 1))
  fi
  if command -v "$CXX" >/dev/null 2>&1; then
    cp "$tmp/one.c" "$tmp/one.cc"
    if "$CXX" -std=c++11 -Wall -Wextra -Werror -fsyntax-only -I"$inc" "$tmp/one.cc" 2>"$tmp/err"; then
      pass=$((pass + 1))
    else
      echo "FAIL: $name does not compile alone as C++11:"
      sed 's/^/  /' "$tmp/err" | head -5
      fails=$((fails + 1))
    fi
  fi
done

# Every struct the library sizes, from its own table (runtime/src/abi.c).
structs=$(grep -o 'ENTRY(prru_[a-z0-9_]*)' "$PRRU_SOURCE_DIR/runtime/src/abi.c" | sed 's/ENTRY(\(.*\))/\1/')
[ -n "$structs" ] || { echo "FAIL: no ENTRY(...) in runtime/src/abi.c"; exit 1; }
{
  echo '#include <stdio.h>'
  echo '#include <dlfcn.h>'
  for h in "$inc"/*.h; do printf '#include "%s"\n' "$(basename "$h")"; done
  echo 'int main(int argc, char **argv) {'
  echo '  void *lib = argc > 1 ? dlopen(argv[1], RTLD_NOW) : NULL;'
  echo '  if (!lib) { printf("FAIL: dlopen: %s\n", dlerror()); return 1; }'
  echo '  size_t (*size)(const char *) = (size_t (*)(const char *))dlsym(lib, "prru_struct_size");'
  echo '  if (!size) { printf("FAIL: no prru_struct_size\n"); return 1; }'
  echo '  int bad = 0;'
  for s in $structs; do
    echo "  if (size(\"$s\") != sizeof($s)) printf(\"FAIL: sizeof($s): %zu here, %zu in the library\\n\", sizeof($s), size(\"$s\")), bad++;"
  done
  echo '  if (size("prru_no_such_struct") != 0) printf("FAIL: an unknown name has a size\n"), bad++;'
  echo '  return bad != 0;'
  echo '}'
} >"$tmp/sizes.c"
# The build's compiler and flags: a sanitizer build's library loads only
# into a program linked with the same runtime.
cache() { sed -n "s/^$1:[A-Z]*=//p" "$PRRU_BUILD_DIR/CMakeCache.txt" | head -n 1; }
CC_BUILD=$(cache CMAKE_C_COMPILER)
read -r -a C_FLAGS <<<"$(cache CMAKE_C_FLAGS)"
read -r -a LD_FLAGS <<<"$(cache CMAKE_EXE_LINKER_FLAGS)"
if "${CC_BUILD:-$CC}" -std=c99 -Wall -Wextra -Werror -Wno-pedantic "${C_FLAGS[@]}" -I"$inc" "$tmp/sizes.c" \
  "${LD_FLAGS[@]}" -o "$tmp/sizes" -ldl 2>"$tmp/err"; then
  if "$tmp/sizes" "$lib"; then
    pass=$((pass + 1))
    echo "ok   $(echo "$structs" | wc -w) structs: the headers alone give the library's sizes"
  else
    fails=$((fails + 1))
  fi
else
  echo "FAIL: the size check does not compile:"
  sed 's/^/  /' "$tmp/err" | head -5
  fails=$((fails + 1))
fi
echo "test_headers: $pass passed, $fails failed"
[ "$fails" = 0 ]
