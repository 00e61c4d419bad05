#!/usr/bin/env bash
# What libprru.so exports is its API and nothing else: the functions the
# public headers (runtime/include) declare with PRRU_API, and the
# generated kernels and descriptor (the drop-in API, compiled into it
# whole). Helpers shared between the library's files (prru_fail,
# prru_rcond3, ...) stay hidden (-fvisibility=hidden), so that no program
# comes to depend on them; and every PRRU_API declaration has a
# definition, so that a program linking against a header never meets an
# undefined symbol.
#
# Env (set by ctest): PRRU_SOURCE_DIR, PRRU_BUILD_DIR.
set -u
: "${PRRU_SOURCE_DIR:?}" "${PRRU_BUILD_DIR:?}"
lib="$PRRU_BUILD_DIR/runtime/libprru.so"
kernels="$PRRU_BUILD_DIR/libprru_kernels.a"
for f in "$lib" "$kernels"; do
  [ -f "$f" ] || { echo "FAIL: $f is missing (build the library first)"; exit 1; }
done
tmp=$(mktemp -d "${TMPDIR:-/tmp}/prru-exports.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
# Global symbols the library defines (T text, D/B/R data).
nm -D --defined-only "$lib" | awk '$2 ~ /^[TDBR]$/ {print $3}' | sort -u >"$tmp/exported"
# The headers' PRRU_API names (a declaration starts its line with PRRU_API).
sed -n 's/^PRRU_API [^(]*[^a-z0-9_]\(prru_[a-z0-9_]*\)(.*/\1/p' "$PRRU_SOURCE_DIR"/runtime/include/*.h |
  sort -u >"$tmp/api"
# The generated sources' global symbols.
nm --defined-only "$kernels" | awk '$2 ~ /^[TDBR]$/ {print $3}' | sort -u >"$tmp/generated"
sort -u "$tmp/api" "$tmp/generated" >"$tmp/expected"
fails=0
extra=$(comm -23 "$tmp/exported" "$tmp/expected")
missing=$(comm -13 "$tmp/exported" "$tmp/expected")
if [ -n "$extra" ]; then
  echo "FAIL: exported but neither PRRU_API in a header nor generated:"; echo "$extra" | sed 's/^/  /'
  fails=1
fi
if [ -n "$missing" ]; then
  echo "FAIL: declared PRRU_API (or generated) but not exported:"; echo "$missing" | sed 's/^/  /'
  fails=1
fi
# A declaration of the API without PRRU_API would be hidden from the
# shared library: every function a public header declares at the start of
# a line carries it.
bare=$(grep -n '^[a-z][a-z0-9_ ]*[ *]prru_[a-z0-9_]*(' "$PRRU_SOURCE_DIR"/runtime/include/*.h | grep -v ':typedef ')
if [ -n "$bare" ]; then
  echo "FAIL: public declarations without PRRU_API:"; echo "$bare" | sed 's/^/  /'
  fails=1
fi
# The check itself must see something: the API and the hidden helpers.
napi=$(wc -l <"$tmp/api")
if [ "$napi" -lt 100 ]; then echo "FAIL: only $napi PRRU_API declarations found"; fails=1; fi
for hidden in prru_fail prru_read_file prru_rcond3 prru_gsl_init; do
  if grep -qx "$hidden" "$tmp/exported"; then echo "FAIL: internal $hidden is exported"; fails=1; fi
done
echo "libprru.so exports $(wc -l <"$tmp/exported") symbols: $napi of the API, $(wc -l <"$tmp/generated") generated"
[ $fails = 0 ] && echo "test_exports: passed"
exit $fails
