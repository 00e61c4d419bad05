#!/usr/bin/env bash
# The Makefile's package step: installs the Debian packages one make target
# needs, and only those.
#
#   cmake/debian_deps.sh TARGET PACKAGE...
#
# The package "clang-runtime" stands for the sanitizer and libFuzzer
# runtime of the installed clang's major version N (libclang-rt-N-dev, or
# libclang-common-N-dev before LLVM 14, which shipped it there), so that no
# Debian release is pinned; it is resolved after clang itself is installed.
#
# Missing packages are installed with apt-get as root, or through sudo.
# Without either, the missing packages and the command that installs them
# are printed, and the exit status is 2; installed packages are never
# touched, and nothing is asked of apt when nothing is missing.
#   PRRU_DEPS_DRY_RUN=1  print what is missing and what would run; install nothing
#   PRRU_SKIP_DEPS=1     do nothing (not Debian: install the equivalents by hand)
# Exit status: 0 ready, 1 apt-get failed, 2 cannot install (no privileges,
# not a Debian system) or a usage error.
set -u
if [ $# -lt 1 ]; then
  echo "usage: cmake/debian_deps.sh TARGET PACKAGE..." >&2
  exit 2
fi
target=$1
shift
[ "${PRRU_SKIP_DEPS:-}" = 1 ] && exit 0
dry_run=${PRRU_DEPS_DRY_RUN:-}

say() { echo "make $target: $*" >&2; }

is_installed() { # PACKAGE
  case "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" in
    *" installed") return 0 ;;
    *) return 1 ;;
  esac
}

# The runtime package that matches `clang`, from its version line
# ("Debian clang version 14.0.6", "Ubuntu clang version 18.1.3 (1)", ...).
clang_runtime_package() {
  local major
  major=$(clang --version 2>/dev/null | sed -n 's/.*clang version \([0-9][0-9]*\)\..*/\1/p' | head -n 1)
  if [ -z "$major" ]; then
    say "cannot read clang's version from 'clang --version'"
    exit 2
  fi
  if [ "$major" -ge 14 ]; then echo "libclang-rt-$major-dev"; else echo "libclang-common-$major-dev"; fi
}

install_packages() { # PACKAGE...: those not installed yet
  local missing=() p
  for p; do is_installed "$p" || missing+=("$p"); done
  [ ${#missing[@]} -eq 0 ] && return 0
  any_missing=1
  local sudo=()
  if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
      sudo=(sudo)
    else
      say "these Debian packages are missing: ${missing[*]}"
      echo "  Install them as root, then run 'make $target' again:" >&2
      echo "    apt-get update && apt-get install --no-install-recommends ${missing[*]}" >&2
      echo "  (or run make as root, or with sudo installed; SKIP_DEPS=1 skips this step)" >&2
      exit 2
    fi
  fi
  if [ -n "$dry_run" ]; then
    say "would run: ${sudo[*]}${sudo:+ }apt-get install --no-install-recommends ${missing[*]}"
    return 0
  fi
  say "installing ${missing[*]}${sudo:+ (with sudo)}"
  if ! "${sudo[@]}" apt-get update -qq ||
     ! DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"; then
    say "apt-get could not install ${missing[*]}"
    exit 1
  fi
}

if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
  say "not a Debian system (no dpkg-query or apt-get); install the equivalents of these"
  echo "  Debian packages yourself, then run 'make $target SKIP_DEPS=1': $*" >&2
  exit 2
fi

plain=()
runtime=0
any_missing=0
for p; do
  if [ "$p" = clang-runtime ]; then runtime=1; else plain+=("$p"); fi
done
if [ -n "$dry_run" ]; then
  if [ $runtime = 1 ]; then say "needs $* (clang's runtime: libclang-rt-N-dev for clang N)"
  else say "needs $*"; fi
fi
install_packages "${plain[@]}"
if [ $runtime = 1 ]; then
  if command -v clang >/dev/null 2>&1; then
    rt=$(clang_runtime_package) || exit 2
    [ -n "$dry_run" ] && say "clang's runtime for $(command -v clang): $rt"
    install_packages "$rt"
  elif [ -n "$dry_run" ]; then
    say "would then install clang's runtime (libclang-rt-N-dev for the installed clang N)"
  else
    say "clang is not on PATH after installing it; its runtime package cannot be chosen"
    exit 1
  fi
fi
if [ -n "$dry_run" ]; then
  if [ $any_missing = 0 ]; then say "all installed"; else say "nothing installed (dry run)"; fi
fi
exit 0
