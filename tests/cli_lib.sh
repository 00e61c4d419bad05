# Shared by the tests/test_cli*.sh scripts (sourced): a scratch directory,
# pass/fail counting and `expect`. Needs $PRRU (path to the binary).
set -u
: "${PRRU:?set PRRU to the prru binary}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
ok()  { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*" >&2; }

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

# finish NAME: the summary line and the exit status.
finish() {
  echo "$1: $pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}
