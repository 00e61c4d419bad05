#!/usr/bin/env bash
# The package step of `make demo` / `make test` (cmake/debian_deps.sh and
# the Makefile's per-target lists), in a sandbox: dpkg-query, apt-get, id,
# sudo and clang are stand-ins on a PATH that holds nothing else but sed and
# head, so the cases below (root, sudo, neither, a newer clang, not Debian)
# run on any machine and never install anything.
#
# Env (set by ctest): PRRU_SOURCE_DIR.
set -u
: "${PRRU_SOURCE_DIR:?}"
script="$PRRU_SOURCE_DIR/cmake/debian_deps.sh"
BASH_BIN=$(command -v bash)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/prru-deps.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
fails=0
ok() { echo "ok   $1"; }
fail() { echo "FAIL $1"; fails=$((fails + 1)); }

# A fresh sandbox: $tmp/bin (the whole PATH), the installed-package list,
# the log of every apt-get call. new_sandbox UID [sudo] [clang-version-line]
new_sandbox() {
  rm -rf "$tmp/sb"
  mkdir -p "$tmp/sb/bin"
  sb="$tmp/sb"
  : >"$sb/installed"
  : >"$sb/apt.log"
  ln -s "$(command -v sed)" "$sb/bin/sed"
  ln -s "$(command -v head)" "$sb/bin/head"
  cat >"$sb/bin/id" <<EOF
#!$BASH_BIN
[ "\$1" = -u ] && echo $1
EOF
  cat >"$sb/bin/dpkg-query" <<EOF
#!$BASH_BIN
pkg=\${@: -1}
while read -r p; do
  [ "\$p" = "\$pkg" ] && { printf 'install ok installed'; exit 0; }
done <"$sb/installed"
echo "dpkg-query: no packages found matching \$pkg" >&2
exit 1
EOF
  # apt-get "installs" by listing the packages; installing clang puts a
  # clang on PATH that prints the version line in $sb/clang.version.
  cat >"$sb/bin/apt-get" <<EOF
#!$BASH_BIN
echo "\$*" >>"$sb/apt.log"
[ -e "$sb/apt.fail" ] && exit 100
[ "\$1" = install ] || exit 0
for a in "\$@"; do
  case "\$a" in
    -*|install) ;;
    *) echo "\$a" >>"$sb/installed"
       if [ "\$a" = clang ]; then
         printf '#!$BASH_BIN\\nread -r v <"$sb/clang.version"; echo "\$v"\\n' >"$sb/bin/clang"
         $(command -v chmod) +x "$sb/bin/clang"
       fi ;;
  esac
done
exit 0
EOF
  if [ "${2:-}" = sudo ]; then
    cat >"$sb/bin/sudo" <<EOF
#!$BASH_BIN
echo "sudo \$*" >>"$sb/sudo.log"
exec "\$@"
EOF
  fi
  echo "${3:-Debian clang version 14.0.6}" >"$sb/clang.version"
  chmod +x "$sb"/bin/*
}
installed() { printf '%s\n' "$@" >>"$sb/installed"; }
add_clang() {
  # shellcheck disable=SC2016  # $v belongs to the stand-in
  printf '#!%s\nread -r v <"%s/clang.version"; echo "$v"\n' "$BASH_BIN" "$sb" >"$sb/bin/clang"
  chmod +x "$sb/bin/clang"
}
run() { # TARGET PACKAGE...: the script in the sandbox; $rc, $sb/out, $sb/err
  env -i PATH="$sb/bin" HOME="$tmp" ${DRY:+PRRU_DEPS_DRY_RUN=1} ${SKIP:+PRRU_SKIP_DEPS=1} \
    "$BASH_BIN" "$script" "$@" >"$sb/out" 2>"$sb/err"
  rc=$?
}
expect_apt() { # NAME EXPECTED-LOG: apt-get's calls, exactly
  if [ "$(cat "$sb/apt.log")" = "$2" ]; then ok "$1"
  else fail "$1: apt-get calls were:"; cat "$sb/apt.log"; echo "expected:"; echo "$2"; cat "$sb/err"; fi
}

# 1. Everything there: no apt-get call, no output, exit 0.
new_sandbox 1000
installed cmake gcc python3
run demo cmake gcc python3
[ $rc = 0 ] && [ ! -s "$sb/err" ] && [ ! -s "$sb/out" ] && ok "all installed: exit 0, silent" ||
  fail "all installed: exit $rc, $(cat "$sb/err")"
expect_apt "all installed: apt-get not called" ""

# 2. Root: apt-get update, then exactly the missing packages.
new_sandbox 0
installed cmake
run demo cmake gcc gnuplot-nox
[ $rc = 0 ] && ok "root: exit 0" || fail "root: exit $rc: $(cat "$sb/err")"
expect_apt "root: installs only the missing ones" \
  "update -qq
install -y -qq --no-install-recommends gcc gnuplot-nox"

# 3. Not root, sudo present: through sudo.
new_sandbox 1000 sudo
run demo cmake
[ $rc = 0 ] && grep -q "sudo apt-get install -y -qq --no-install-recommends cmake" "$sb/sudo.log" &&
  ok "not root, sudo: apt-get through sudo" || fail "not root, sudo: exit $rc, $(cat "$sb/sudo.log" "$sb/err")"

# 4. Not root, no sudo: the packages and the command, exit 2, nothing run.
new_sandbox 1000
installed cmake
run demo cmake gcc libgsl-dev
if [ $rc = 2 ] && grep -q "make demo: these Debian packages are missing: gcc libgsl-dev" "$sb/err" &&
   grep -q "apt-get update && apt-get install --no-install-recommends gcc libgsl-dev" "$sb/err"; then
  ok "not root, no sudo: exit 2 with the packages and the command"
else
  fail "not root, no sudo: exit $rc:"; cat "$sb/err"
fi
expect_apt "not root, no sudo: apt-get not called" ""

# 5. clang's runtime follows the clang that is installed (no release pinned).
for case in "Debian clang version 19.1.7 (3+b1)|libclang-rt-19-dev" \
            "Ubuntu clang version 14.0.0-1ubuntu1.1|libclang-rt-14-dev" \
            "Debian clang version 13.0.1-6~deb11u1|libclang-common-13-dev"; do
  new_sandbox 0 "" "${case%|*}"
  installed clang libgsl-dev
  add_clang
  run fuzz clang clang-runtime libgsl-dev
  expect_apt "clang runtime for '${case%|*}': ${case#*|}" \
    "update -qq
install -y -qq --no-install-recommends ${case#*|}"
done
# clang missing: installed first, its runtime chosen from the new clang.
new_sandbox 0 "" "Debian clang version 16.0.6 (15~deb12u1)"
run fuzz clang clang-runtime libgsl-dev
expect_apt "clang missing: clang first, then its runtime" \
  "update -qq
install -y -qq --no-install-recommends clang libgsl-dev
update -qq
install -y -qq --no-install-recommends libclang-rt-16-dev"
# A clang whose version line cannot be read: exit 2, nothing guessed.
new_sandbox 0 "" "clang: error: something else"
installed clang
add_clang
run fuzz clang clang-runtime
[ $rc = 2 ] && grep -q "cannot read clang's version" "$sb/err" &&
  ok "clang's version unreadable: exit 2" || fail "clang's version unreadable: exit $rc: $(cat "$sb/err")"
expect_apt "clang's version unreadable: apt-get not called" ""
# Its runtime already there: nothing.
new_sandbox 0
installed clang libclang-rt-14-dev
add_clang
run fuzz clang clang-runtime
expect_apt "clang and its runtime installed: apt-get not called" ""

# 6. Dry run: says what it would run, runs nothing.
new_sandbox 0
installed cmake
DRY=1 run demo cmake gcc
if [ $rc = 0 ] && grep -q "would run: apt-get install --no-install-recommends gcc" "$sb/err" &&
   grep -q "nothing installed (dry run)" "$sb/err"; then
  ok "dry run: names the command"
else fail "dry run: exit $rc: $(cat "$sb/err")"; fi
expect_apt "dry run: apt-get not called" ""

# 7. Not Debian, apt-get failing, SKIP_DEPS, no arguments.
new_sandbox 0
rm "$sb/bin/dpkg-query"
run demo cmake
[ $rc = 2 ] && grep -q "not a Debian system" "$sb/err" && grep -q "SKIP_DEPS=1" "$sb/err" &&
  ok "not Debian: exit 2, names SKIP_DEPS" || fail "not Debian: exit $rc: $(cat "$sb/err")"
new_sandbox 0
touch "$sb/apt.fail"
run demo cmake
[ $rc = 1 ] && grep -q "apt-get could not install cmake" "$sb/err" &&
  ok "apt-get fails: exit 1 with the packages" || fail "apt-get fails: exit $rc: $(cat "$sb/err")"
new_sandbox 1000
SKIP=1 run demo cmake
[ $rc = 0 ] && [ ! -s "$sb/err" ] && ok "SKIP_DEPS: nothing checked" || fail "SKIP_DEPS: exit $rc"
run
[ $rc = 2 ] && grep -q usage "$sb/err" && ok "no arguments: usage, exit 2" || fail "no arguments: exit $rc"

# 8. The Makefile asks each target's list and no other: every package step
# `make -n TARGET` would run, with its package list.
deps_of() { # TARGET: the distinct package lists make -n TARGET passes
  make -n -s -C "$PRRU_SOURCE_DIR" "$1" BUILD="$tmp/never-built" RESULTS="$tmp/never" 2>/dev/null |
    sed -n 's/.*debian_deps.sh [a-z-]* //p' | sort -u
}
# help2man: the man pages; npm only where no npm command is found
# (NodeSource's nodejs has one); slurm-wlm and munge: tests/test_slurm.sh;
# the Arm cross compiler, newlib and QEMU: tests/test_mcu.sh.
demo_list="cmake gcc make python3 libgsl-dev libjansson-dev pkg-config gnuplot-nox help2man"
test_list="$demo_list g++ clang libmujoco-dev python3-numpy python3-sympy chromium nodejs"
command -v npm >/dev/null 2>&1 || test_list="$test_list npm"
test_list="$test_list slurm-wlm munge gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm"
for case in "demo|$demo_list" "deps|$demo_list" "bench|$demo_list" \
            "test|$demo_list
$test_list" "test-asan|$demo_list
$test_list valgrind" "fuzz|clang clang-runtime libgsl-dev libjansson-dev pkg-config
$demo_list"; do
  target=${case%%|*}
  got=$(deps_of "$target")
  want=$(printf '%s\n' "${case#*|}" | sort -u)
  if [ "$got" = "$want" ]; then ok "make -n $target: packages $(echo "$want" | tail -n 1)"
  else fail "make -n $target: package lists"; echo "$got"; echo "expected:"; echo "$want"; fi
done

[ $fails = 0 ] && echo "test_deps: all passed" || echo "test_deps: $fails failure(s)"
[ $fails = 0 ]
